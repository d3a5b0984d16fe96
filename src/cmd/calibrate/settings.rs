//! `calibrate`'s flags turned into checked settings before any work (ripgrep's high-level
//! arguments): the robot with its Hayati tilts and joint families, parameter names, weighting,
//! the library's calibration settings, the files plan; and the reading of a measurement file.

use super::super::common;
use super::super::io_plan::IoPlan;
use super::joint_list::joint_list;
use super::{CalibrateArgs, ModelArg, ObjectiveArg, RobustArg};
use crate::exit;
use robocal_core::identification::{
    read_split, AutoFamilies, CalibrationSettings, IdentifiabilityOptions, ModelChoice, Objective,
    RobustLoss, SolverOptions, DEFAULT_RANK_TOLERANCE,
};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::{MeasurementReader, Positions};
use robocal_core::observations::{TrackerSigma, Weighting};
use robocal_core::{Param, Robot};
use std::path::{Path, PathBuf};

/// The weighting of `--tracker-sigma` and `--orientation-weight`.
pub(crate) fn weighting(
    tracker_sigma: Option<&str>,
    orientation_weight: Option<f64>,
) -> anyhow::Result<Weighting> {
    let mut w = Weighting::default();
    let tracker_sigma: Vec<f64> = match tracker_sigma.map(str::trim) {
        None => Vec::new(),
        Some("off") => {
            w.automatic = false;
            Vec::new()
        }
        Some(text) => {
            let v: Vec<f64> = text
                .split(',')
                .map(|t| t.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| {
                    exit::usage(format!(
                        "--tracker-sigma {text}: expected two numbers FIXED_MM,PER_M_MM (e.g. \
                         0.0075,0.003) or `off`"
                    ))
                })?;
            if v.len() != 2 {
                return Err(exit::usage(format!(
                    "--tracker-sigma: expected two numbers FIXED_MM,PER_M_MM (e.g. 0.0075,0.003), \
                     got {}",
                    v.len()
                )));
            }
            v
        }
    };
    if let [fixed, per_m] = tracker_sigma[..] {
        let (fixed, per_m) = (&fixed, &per_m);
        w.tracker = Some(TrackerSigma::new(*fixed, *per_m).map_err(|_| {
            exit::usage(format!(
                "--tracker-sigma {fixed},{per_m}: expected FIXED_MM,PER_M_MM, both non-negative \
                 and at most 1000, not both zero (e.g. 0.0075,0.003)"
            ))
        })?);
    }
    if let Some(m) = orientation_weight {
        w.mm_per_deg = m;
    }
    Ok(w)
}

/// Parses a list of parameter names, naming every unknown one at once.
fn param_list(robot: &Robot, names: &[String], flag: &str) -> anyhow::Result<Vec<Param>> {
    let mut out = Vec::new();
    let mut unknown = Vec::new();
    for n in names.iter().map(|n| n.trim()).filter(|n| !n.is_empty()) {
        match robot.param_by_name(n) {
            Ok(p) if !out.contains(&p) => out.push(p),
            Ok(_) => {}
            Err(_) => unknown.push(format!("`{n}`")),
        }
    }
    if !unknown.is_empty() {
        let known: Vec<String> = robot.params().iter().map(|p| p.name()).collect();
        return Err(exit::usage(format!(
            "{flag}: unknown parameter{} {} (robot `{}` has: {})",
            if unknown.len() > 1 { "s" } else { "" },
            unknown.join(", "),
            robot.name(),
            known.join(", ")
        )));
    }
    Ok(out)
}

/// Applies `--beta`.
fn apply_beta(robot: &mut Robot, arg: &str) -> anyhow::Result<Vec<usize>> {
    match arg.trim() {
        "none" | "" => Ok(Vec::new()),
        "parallel" => Ok(robot.enable_beta_for_parallel_axes()),
        list => {
            let mut out = Vec::new();
            for part in list.split(',') {
                let j: usize = part.trim().parse().map_err(|_| {
                    exit::usage(format!(
                        "--beta: `{part}` is not `parallel`, `none` or a joint number"
                    ))
                })?;
                if j == 0 || j > robot.dof() {
                    return Err(exit::usage(format!(
                        "--beta: joint {j} does not exist (robot `{}` has joints 1..{})",
                        robot.name(),
                        robot.dof()
                    )));
                }
                robot.enable_beta(j - 1)?;
                out.push(j - 1);
            }
            Ok(out)
        }
    }
}

/// Applies `--compliance`, `--payload-kg` and `--harmonics`; returns the compliant joints
/// (0-based).
fn apply_joint_families(robot: &mut Robot, a: &CalibrateArgs) -> anyhow::Result<Vec<usize>> {
    use robocal_core::model::family::{compliance, transmission};
    let joints = joint_list(
        "--compliance",
        a.compliance.as_deref(),
        robot,
        compliance::auto_joints,
    )?;
    if a.payload_kg.is_some() && joints.is_empty() {
        return Err(exit::usage(
            "--payload-kg: the payload makes the joint compliances physical; give --compliance              auto or a list of joints too",
        ));
    }
    if !joints.is_empty() {
        compliance::enable(robot, &joints, a.payload_kg)
            .map_err(|e| exit::usage(super::super::flags::cli_text(&e)))?;
    }
    let harmonics = a.harmonics.unwrap_or(0);
    if harmonics > transmission::MAX_HARMONICS {
        return Err(exit::usage(format!(
            "--harmonics {harmonics}: at most {} harmonics per joint",
            transmission::MAX_HARMONICS
        )));
    }
    let all: Vec<usize> = (0..robot.dof()).collect();
    transmission::enable(robot, &all, harmonics)
        .map_err(|e| exit::usage(super::super::flags::cli_text(&e)))?;
    Ok(joints)
}

/// Reads a measurement file and sorts its rows (see `split_measurements`). Rows outside the
/// robot's joint limits are an error, or with --nominal-limits a warning, and are added to
/// `outside`.
pub(super) fn read(
    path: &Path,
    robot: &Robot,
    nominal_limits: bool,
    outside: &mut Vec<OutsideLimits>,
) -> anyhow::Result<robocal_core::identification::SplitData> {
    // Row by row: a million rows are never held as text rows beside their observations.
    let reader = MeasurementReader::open(path, robot.joint_space(), Positions::Required)?;
    read_from(reader, path, robot, nominal_limits, outside)
}

/// [`read`] from the file at `path` opened already (its header checked).
pub(super) fn read_from<R: std::io::Read>(
    reader: MeasurementReader<R>,
    path: &Path,
    robot: &Robot,
    nominal_limits: bool,
    outside: &mut Vec<OutsideLimits>,
) -> anyhow::Result<robocal_core::identification::SplitData> {
    let mut o = OutsideLimits::new(robot, path);
    let (split, warnings) = read_split(reader, |r| o.check(r.line, &r.q))?;
    for w in &warnings {
        errln!("warning: {w}")?;
    }
    common::check_limits(o, nominal_limits, outside)?;
    Ok(split)
}

/// Everything `calibrate` needs, checked completely before any work (ripgrep's high-level
/// arguments): ranges, parameter names, the robot, the files plan. The command body only reads
/// it.
pub(super) struct Settings {
    /// The `--robot` argument as given (recorded in the result).
    pub(super) robot_arg: String,
    /// The nominal robot, with the Hayati tilts of `--beta`.
    pub(super) robot: Robot,
    /// The joints given a tilt parameter (0-based).
    pub(super) betas: Vec<usize>,
    pub(super) data: PathBuf,
    pub(super) validate: Option<PathBuf>,
    pub(super) nominal_limits: bool,
    /// The library's settings: objective, identifiability, solver.
    pub(super) calibration: CalibrationSettings,
    pub(super) keep_partial: bool,
    pub(super) accept_implausible: bool,
    pub(super) out: PathBuf,
}

impl TryFrom<&CalibrateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &CalibrateArgs) -> anyhow::Result<Settings> {
        let mut robot = common::robot(&a.robot)?;
        let betas = apply_beta(&mut robot, &a.beta)?;
        let compliant = apply_joint_families(&mut robot, a)?;
        super::real_cell::apply(&mut robot, a.backlash.as_deref(), a.thermal.as_deref())?;
        if compliant.is_empty() && a.compliance.as_deref().map(str::trim) == Some("auto") {
            errln!(
                "note: --compliance auto: no joint of robot `{}` turns under gravity (every axis \
                 is parallel to its `gravity`); no compliance added",
                robot.name()
            )?;
        }
        if betas.is_empty() && a.beta.trim() == "parallel" {
            errln!(
                "note: --beta parallel: robot `{}` has no pair of consecutive parallel axes; no \
                 tilt parameter added",
                robot.name()
            )?;
        }
        let fix = param_list(&robot, &a.fix, "--fix")?;
        let free = param_list(&robot, &a.free, "--free")?;
        let rank_tolerance = a.rank_tol.unwrap_or(DEFAULT_RANK_TOLERANCE);
        IoPlan::new()
            .robot("--robot", &a.robot)
            .input("--data", &a.data)
            .input_opt("--validate", a.validate.as_deref())
            .output(
                "--out",
                &a.out,
                "the result is a file that later commands read, and the tables go to standard \
                 output",
            )
            .check()?;
        if let Some(v) = &a.validate {
            if super::super::io_plan::same_file(v, &a.data) {
                return Err(exit::usage(format!(
                    "--validate {}: this is the --data file {} (the same file); validation \
                     points must be points the calibration did not fit: give another file, or \
                     mark validation rows of --data with set = validation",
                    v.display(),
                    a.data.display()
                )));
            }
        }
        let calibration = CalibrationSettings {
            objective: match a.objective {
                ObjectiveArg::Adaptive => Objective::Adaptive,
                ObjectiveArg::SumOfNorms => Objective::SumOfNorms,
                ObjectiveArg::LeastSquares => Objective::LeastSquares,
                ObjectiveArg::Robust => Objective::Robust(match a.robust_loss {
                    RobustArg::Cauchy => RobustLoss::Cauchy,
                    RobustArg::Huber => RobustLoss::Huber,
                }),
            },
            robust_scale_mm: a.robust_scale,
            affine_registration: a.affine,
            identifiability: IdentifiabilityOptions {
                rank_tolerance,
                fix,
                free,
                allow_ill_conditioned: a.rank_tol.is_some(),
            },
            solver: SolverOptions {
                max_iterations: a.max_iterations,
                ..Default::default()
            },
            weighting: weighting(a.tracker_sigma.as_deref(), a.orientation_weight)?,
            validation_refit_frame: a.validate_refit_frame,
            model: match a.model {
                ModelArg::Geometric => ModelChoice::Given,
                ModelArg::Auto => ModelChoice::Auto(AutoFamilies {
                    harmonics: a.harmonics.is_none(),
                    compliance: a.compliance.is_none(),
                    backlash: a.backlash.is_none(),
                    thermal: a.thermal.is_none(),
                }),
            },
        };
        // The library checks its settings (ranges, parameter sets) before any data are read.
        calibration.check(&robot)?;
        Ok(Settings {
            robot_arg: a.robot.clone(),
            robot,
            betas,
            data: a.data.clone(),
            validate: a.validate.clone(),
            nominal_limits: a.nominal_limits,
            calibration,
            keep_partial: a.keep_partial,
            accept_implausible: a.accept_implausible,
            out: a.out.clone(),
        })
    }
}
