//! `robocal calibrate`: registration of the measurement frame and identification of the
//! calibrated parameters (paper, sections II.C and III).

use super::io_plan::IoPlan;
use super::{common, limits};
use crate::exit;
use anyhow::Context;
use clap::{Args, ValueEnum};
use robocal_core::identification::{
    calibrate, split_measurements, AutoFamilies, CalibrationData, CalibrationSettings,
    IdentifiabilityOptions, ModelChoice, Objective, Observations, RobustLoss, SolverOptions,
    DEFAULT_RANK_TOLERANCE, MIN_RANK_TOLERANCE,
};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::result_sections::RowsOutside;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::observations::{TrackerSigma, Weighting};
use robocal_core::{Param, Robot};
use std::path::{Path, PathBuf};

mod constraints;
mod print;
mod real_cell;
pub(crate) use print::print_selection;
use print::{print_plausibility, print_report};

#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// The nominal robot: a preset name, a TOML robot file or a URDF.
    #[arg(long)]
    robot: String,
    /// Calibration measurements (CSV: q1..qn in degrees (mm for a prismatic joint) or the
    /// controller's axis1..axisN, x,y,z in mm in the tracker frame).
    /// Rows with `set` = `plane` give the initial frame; rows with `set` = `validation` are
    /// validation points; any other label than these, `calibration` or empty is an error.
    #[arg(long)]
    data: PathBuf,
    /// Validation measurements (same format), evaluated with the fitted tracker frame. Must be
    /// another file than --data.
    #[arg(long)]
    validate: Option<PathBuf>,
    /// The robot's joint limits are only nominal: joint values outside them are a warning
    /// listing the lines (recorded in the result's settings) instead of an error (exit code 3).
    #[arg(long)]
    nominal_limits: bool,
    /// What to minimize. Default `adaptive`: least squares with outliers down-weighted beyond a
    /// threshold scaled from the data (efficient on clean data, robust to gross outliers);
    /// `sum-of-norms` is the paper's total displacement error (eq. 4).
    #[arg(long, value_enum, default_value_t = ObjectiveArg::Adaptive)]
    objective: ObjectiveArg,
    /// The robust loss of `--objective robust`.
    #[arg(long, value_enum, default_value_t = RobustArg::Cauchy)]
    robust_loss: RobustArg,
    /// Scale of the robust loss, or the adaptive objective's threshold, in mm (default: 4 sigma
    /// for the robust losses, 5 sigma for adaptive; sigma estimated from the median error after
    /// every reweighting).
    #[arg(long, value_name = "MM")]
    robust_scale: Option<f64>,
    /// Parameters to hold at their nominal values (comma-separated names, e.g. `a6,alpha6`).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    fix: Vec<String>,
    /// Parameters to identify in preference to those with the same effect (e.g. `--free d3`
    /// keeps d3 and fixes d2). An error if one cannot be identified at all.
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    free: Vec<String>,
    /// Which model to fit. `auto` (default): the families the data support, chosen by
    /// cross-validation over the calibration data (5 folds by pose) among the geometric model and
    /// the geometric model plus transmission harmonics (1, 2), joint compliance and their
    /// combinations; a family stays only when it lowers the cross-validated error by more than
    /// its standard error; backlash when the data have dir1..dirN, thermal expansion when they
    /// have temperature_c. `geometric`: the paper's model. An explicit --compliance,
    /// --harmonics, --backlash or --thermal fixes that family and skips its selection.
    #[arg(long, value_enum, default_value_t = ModelArg::Auto)]
    model: ModelArg,
    /// Hayati tilt parameters: `parallel` (every joint whose axis is parallel to the previous
    /// one), a list of joint numbers (e.g. `3`), or `none`.
    #[arg(long, default_value = "none", value_name = "parallel|none|J,..")]
    beta: String,
    /// Joint compliance under gravity (each joint turns by its compliance times the gravity
    /// torque about its axis, from lumped coefficients of the chain's geometry): `auto` (every
    /// revolute joint whose axis is not always parallel to the robot's `gravity`), a list of
    /// joint numbers (e.g. `2,3`), or `none`.
    /// [default: none, or chosen by --model auto]
    #[arg(long, value_name = "auto|none|J,..")]
    compliance: Option<String>,
    /// The payload (kg) the data were measured with: the compliances' payload part becomes a
    /// physical compliance (`compliance{j}`, µrad/(N·m)), so `evaluate` and `compensate` can
    /// predict another payload. Needs --compliance.
    #[arg(long, value_name = "KG")]
    payload_kg: Option<f64>,
    /// Joint transmission errors: the first N harmonics of every revolute joint's angle error
    /// (0 to 8) [default: 0, or chosen by --model auto].
    #[arg(long, value_name = "N")]
    harmonics: Option<usize>,
    /// Backlash: half the gear play of each joint, against the approach direction of each row
    /// (`dir1..dirN`, or derived from the row order): `auto` (every revolute joint), a list of
    /// joint numbers (e.g. `1,2,3`), or `none` [default: none, or chosen by --model auto when
    /// the data have dir1..dirN].
    #[arg(long, value_name = "auto|none|J,..")]
    backlash: Option<String>,
    /// Thermal expansion: `auto` fits one coefficient (`thermal_k`, ppm/K) by which the links'
    /// lengths and the base column grow with the data's `temperature_c`, referred to the
    /// calibration rows' mean temperature (the result's `reference_temperature_c`), or `none`
    /// [default: none, or chosen by --model auto when the data have temperature_c].
    #[arg(long, value_parser = ["auto", "none"])]
    thermal: Option<String>,
    /// Also fit the paper's 12-parameter affine Tr (eq. 8-11) and report it (the tracker frame
    /// stays rigid).
    #[arg(long)]
    affine: bool,
    /// Relative rank threshold of the identifiability analysis [default: 1e-6]; at least 1e-10.
    /// Given explicitly, an ill-conditioned identification (condition number above 1e7) is
    /// written with its standard deviations marked unavailable instead of failing (exit 5).
    #[arg(long, value_name = "TOL")]
    rank_tol: Option<f64>,
    /// Iteration limit of the solver (1 to 1000000). If the solver stops there without
    /// converging, the command fails (exit code 5) and writes nothing, unless --keep-partial is
    /// given.
    #[arg(long, default_value_t = 1000)]
    max_iterations: usize,
    /// When the solver does not converge, still write the result, marked `"status": "partial"`
    /// (the exit code stays 5; `compensate` refuses such a file, other commands warn).
    #[arg(long)]
    keep_partial: bool,
    /// Write a converged fit that fails the plausibility gate (units, handedness, nominal error,
    /// parameter moves) anyway, marked `"status": "implausible"` (exit code 0, with a warning).
    /// Without it such a fit exits with code 6 and writes nothing; `compensate` refuses the file
    /// unless given --accept-implausible too.
    #[arg(long)]
    accept_implausible: bool,
    /// Weighted fitting with a tracker uncertainty model: 1 sigma per axis = FIXED_MM +
    /// PER_M_MM per metre of distance from the tracker. Rows with a `sigma_mm` column keep their
    /// own. Without either, data in a tracker's frame (the registered tracker at least 500 mm
    /// from the base) are weighted by a typical tracker (0.010,0.005), other data not; `off`
    /// weighs every point the same.
    #[arg(long, value_name = "FIXED_MM,PER_M_MM|off", allow_hyphen_values = true)]
    tracker_sigma: Option<String>,
    /// 6-DoF data (a,b,c columns): how many mm of position error one degree of orientation
    /// error counts as in the fit [default: 3, a 6-DoF probe's typical 0.03 mm against 0.01 deg].
    #[arg(long, value_name = "MM_PER_DEG")]
    orientation_weight: Option<f64>,
    /// The validation points were measured after the tracker moved (another station): fit
    /// them a rigid frame of their own. Their errors then show the calibrated model's shape
    /// accuracy, not the tracker's move. Without it, such a set is an error (exit 3).
    #[arg(long)]
    validate_refit_frame: bool,
    /// Known distances between fixed points or sphere centres of constraint data (CSV
    /// `from,to,distance_mm`): they give the calibration its scale.
    #[arg(long, value_name = "FILE")]
    distances: Option<PathBuf>,
    /// Constraint data without a known distance or radius: write a result up to scale (the
    /// longest link length held at its nominal value) instead of refusing.
    #[arg(long)]
    accept_unknown_scale: bool,
    /// Where to write the result JSON.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
enum ObjectiveArg {
    /// Least squares, outliers down-weighted beyond a data-scaled threshold (default).
    Adaptive,
    /// Sum of error norms, the paper's eq. 4.
    SumOfNorms,
    /// Sum of squared errors.
    LeastSquares,
    /// Robust loss (see --robust-loss).
    Robust,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
enum ModelArg {
    /// The families the data support, by cross-validation (default).
    Auto,
    /// The robot's geometry (and the families given explicitly) only.
    Geometric,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, ValueEnum)]
enum RobustArg {
    /// Cauchy: gross outliers get almost no weight.
    Cauchy,
    /// Huber: bounded influence.
    Huber,
}

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
        if !(m > 0.0 && m.is_finite() && m <= 1e6) {
            return Err(exit::usage(format!(
                "--orientation-weight {m}: expected a positive number of mm per degree"
            )));
        }
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

/// A joint-family flag's joints (0-based, sorted, once each): `none` (or absent) none, `auto`
/// those `auto` gives, else a comma list of joint numbers 1..dof.
pub(super) fn joint_list(
    flag: &str,
    arg: Option<&str>,
    robot: &Robot,
    auto: impl FnOnce(&Robot) -> Vec<usize>,
) -> anyhow::Result<Vec<usize>> {
    let list = match arg.unwrap_or("none").trim() {
        "none" | "" => return Ok(Vec::new()),
        "auto" => return Ok(auto(robot)),
        list => list,
    };
    let mut out = Vec::new();
    for part in list.split(',') {
        let j: usize = part.trim().parse().map_err(|_| {
            exit::usage(format!(
                "{flag}: `{part}` is not `auto`, `none` or a joint number"
            ))
        })?;
        if j == 0 || j > robot.dof() {
            return Err(exit::usage(format!(
                "{flag}: joint {j} does not exist (robot `{}` has joints 1..{})",
                robot.name(),
                robot.dof()
            )));
        }
        if !out.contains(&(j - 1)) {
            out.push(j - 1);
        }
    }
    out.sort_unstable();
    Ok(out)
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
            .map_err(|e| exit::usage(super::flags::cli_text(&e)))?;
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
        .map_err(|e| exit::usage(super::flags::cli_text(&e)))?;
    Ok(joints)
}

/// Reads a measurement file and sorts its rows (see `split_measurements`). Rows outside the
/// robot's joint limits are an error, or with --nominal-limits a warning, and are added to
/// `outside`.
fn read(
    path: &Path,
    robot: &Robot,
    nominal_limits: bool,
    outside: &mut Vec<OutsideLimits>,
) -> anyhow::Result<robocal_core::identification::SplitData> {
    let set = read_measurements(path, robot.joint_space(), Positions::Required)?;
    for w in &set.warnings {
        errln!("warning: {w}")?;
    }
    let split = split_measurements(&set)?;
    let mut o = OutsideLimits::new(robot, path);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    common::check_limits(o, nominal_limits, outside)?;
    Ok(split)
}

/// Everything `calibrate` needs, checked completely before any work (ripgrep's high-level
/// arguments): ranges, parameter names, the robot, the files plan. The command body only reads
/// it.
struct Settings {
    /// The `--robot` argument as given (recorded in the result).
    robot_arg: String,
    /// The nominal robot, with the Hayati tilts of `--beta`.
    robot: Robot,
    /// The joints given a tilt parameter (0-based).
    betas: Vec<usize>,
    data: PathBuf,
    validate: Option<PathBuf>,
    nominal_limits: bool,
    /// The library's settings: objective, identifiability, solver.
    calibration: CalibrationSettings,
    keep_partial: bool,
    accept_implausible: bool,
    out: PathBuf,
}

impl TryFrom<&CalibrateArgs> for Settings {
    type Error = anyhow::Error;

    fn try_from(a: &CalibrateArgs) -> anyhow::Result<Settings> {
        limits::count(
            "--max-iterations",
            a.max_iterations,
            1,
            limits::MAX_CALIBRATION_ITERATIONS,
            "a solver that has not converged by then will not",
        )?;
        if let Some(s) = a.robust_scale {
            limits::magnitude("--robust-scale", s, limits::MAX_LENGTH_MM, "mm")?;
        }
        let mut robot = common::robot(&a.robot)?;
        let betas = apply_beta(&mut robot, &a.beta)?;
        let compliant = apply_joint_families(&mut robot, a)?;
        real_cell::apply(&mut robot, a.backlash.as_deref(), a.thermal.as_deref())?;
        if compliant.is_empty() && a.compliance.as_deref().map(str::trim) == Some("auto") {
            errln!(
                "note: --compliance auto: no joint of robot `{}` turns under gravity (every axis                  is parallel to its `gravity`); no compliance added",
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
        if fix.len() == robot.param_count() {
            return Err(exit::usage(format!(
                "--fix names every parameter of robot `{}` ({}): nothing is left to identify",
                robot.name(),
                robot.param_count()
            )));
        }
        if let Some(p) = fix.iter().find(|p| free.contains(p)) {
            // Exit code 3, as when the library finds it.
            return Err(exit::input(format!(
                "--fix: `{}` is given both to --fix and to --free",
                p.name()
            )));
        }
        let rank_tolerance = a.rank_tol.unwrap_or(DEFAULT_RANK_TOLERANCE);
        if !(MIN_RANK_TOLERANCE..1.0).contains(&rank_tolerance) {
            return Err(exit::usage(format!(
                "--rank-tol {rank_tolerance:?}: not in [{MIN_RANK_TOLERANCE:e}, 1); it is the \
                 smallest independence (sine of the angle between a parameter's effect and the \
                 others') accepted, and below {MIN_RANK_TOLERANCE:e} double precision cannot \
                 tell a parameter from an exact duplicate (whose independence computes as 1e-17 \
                 to 1e-14 from rounding)"
            )));
        }
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
            if super::io_plan::same_file(v, &a.data) {
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

pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    let s = Settings::try_from(&a)?;
    let Settings { robot, betas, .. } = &s;
    let rank_tolerance = s.calibration.identifiability.rank_tolerance;
    if constraints::is_constraint_file(&s.data, robot)? {
        return constraints::run(&s, a.distances.as_deref(), a.accept_unknown_scale);
    }
    if a.distances.is_some() || a.accept_unknown_scale {
        return Err(exit::usage(format!(
            "--distances and --accept-unknown-scale are for constraint data (a `constraint` \
             column); {} has none",
            s.data.display()
        )));
    }
    let mut outside = Vec::new();
    let mut data = read(&s.data, robot, s.nominal_limits, &mut outside)?;
    let robot = &real_cell::fit_to_data(robot, &mut data, &s.data)?;
    let mut validation = data.validation.clone();
    if let Some(v) = &s.validate {
        let vd = read(v, robot, s.nominal_limits, &mut outside)?;
        if !vd.plane.is_empty() {
            errln!(
                "note: {}: {} plane point(s) ignored in the validation set",
                v.display(),
                vd.plane.len()
            )?;
        }
        validation = merge(validation, &vd.calibration)?;
        validation = merge(validation, &vd.validation)?;
    }
    outln!(
        "robot {} ({} joints, {}){}; {} calibration point(s){}{}",
        robot.name(),
        robot.dof(),
        robot.convention().as_str(),
        if betas.is_empty() {
            String::new()
        } else {
            format!(
                ", Hayati tilt on {}",
                betas
                    .iter()
                    .map(|i| format!("beta{}", i + 1))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        },
        data.calibration.len(),
        if data.plane.is_empty() {
            String::new()
        } else {
            format!(", {} plane point(s)", data.plane.len())
        },
        if validation.is_empty() {
            String::new()
        } else {
            format!(", {} validation point(s)", validation.len())
        },
    )?;
    let bar = crate::progress::Bar::new("calibrating");
    let result = calibrate(
        robot,
        CalibrationData {
            calibration: &data.calibration,
            plane: Some(&data.plane),
            validation: Some(&validation),
        },
        &s.calibration,
        &bar,
    );
    bar.finish();
    let cal = result.with_context(|| format!("calibrating from {}", s.data.display()))?;
    let converged = cal.solver().termination.converged();
    let implausible = cal.plausibility.implausible();
    if let Some(sel) = &cal.model_selection {
        print_selection(sel)?;
    }
    print_report(&cal, converged, implausible)?;
    print_plausibility(&cal)?;
    if let Some(why) = &cal.covariance.unavailable {
        errln!(
            "warning: standard deviations unavailable (written as null): {why} (--rank-tol \
             {rank_tolerance:e} given explicitly)"
        )?;
    }
    let mut res = cal.to_result();
    res.inputs = Some(record_inputs(&s)?);
    if let Some(rs) = &mut res.settings {
        rs.robot_arg = Some(s.robot_arg.clone());
        rs.data = Some(s.data.display().to_string());
        rs.validate = s.validate.as_ref().map(|v| v.display().to_string());
        rs.nominal_limits = Some(s.nominal_limits);
        rs.rows_outside_limits = (!outside.is_empty()).then(|| {
            outside
                .iter()
                .map(|o| RowsOutside {
                    file: o.path().display().to_string(),
                    rows: o.count(),
                    lines: o.lines().to_vec(),
                })
                .collect()
        });
    }
    let failed_gate = if implausible {
        format!(
            "\nThe fit also FAILED the plausibility gate:\n{}",
            common::indent(&cal.plausibility.summary())
        )
    } else {
        String::new()
    };
    if converged && !implausible {
        res.write(&s.out)?;
        outln!("result written to {}", s.out.display())?;
        return Ok(());
    }
    if converged {
        // Converged but implausible: not a calibration. Fail; keep it only if asked, marked.
        let summary = common::indent(&cal.plausibility.summary());
        if s.accept_implausible {
            res.write(&s.out)?;
            outln!(
                "result written to {} marked \"status\": \"implausible\"",
                s.out.display()
            )?;
            errln!(
                "WARNING: IMPLAUSIBLE FIT WRITTEN (--accept-implausible): the fit failed the \
                 plausibility gate and is NOT a calibration:\n{summary}\n{} is marked \
                 \"status\": \"implausible\"; compensate refuses it unless given \
                 --accept-implausible too",
                s.out.display()
            )?;
            return Ok(());
        }
        return Err(exit::implausible(format!(
            "implausible fit: the solver converged, but the result cannot be a calibration; \
             nothing written to {}. Failed checks:\n{summary}\n(fix the data or the robot; \
             --accept-implausible writes it anyway, marked \"status\": \"implausible\")",
            s.out.display()
        )));
    }
    // Not converged: not a calibration. Fail; keep the partial result only if asked, marked.
    let why = format!(
        "the solver {} after {} iteration(s) (--max-iterations {})",
        cal.solver().termination.describe(),
        cal.stages
            .iter()
            .map(|s| s.report.iterations)
            .sum::<usize>(),
        s.calibration.solver.max_iterations
    );
    if s.keep_partial {
        res.partial_reason = Some(why.clone());
        res.write(&s.out)?;
        Err(exit::numerical(format!(
            "{why}: the parameters above are a partial result, not a calibration; written to {} \
             marked \"status\": \"partial\" (--keep-partial){failed_gate}",
            s.out.display()
        )))
    } else {
        Err(exit::numerical(format!(
            "{why}: the parameters above are a partial result, not a calibration; nothing \
             written to {} (raise --max-iterations, or use --keep-partial to \
             write the partial result, marked as such){failed_gate}",
            s.out.display()
        )))
    }
}

/// Appends the points of `b` to `a` (validation points from two sources).
fn merge(mut a: Observations, b: &Observations) -> anyhow::Result<Observations> {
    if a.is_empty() {
        return Ok(b.clone());
    }
    for i in 0..b.len() {
        a.push_with(b.q(i), *b.m(i), b.extras(i), b.line(i))?;
    }
    Ok(a)
}

/// The result's `inputs`: the robot file (not a preset), the data and the validation file, each
/// with its path and SHA-256.
fn record_inputs(s: &Settings) -> anyhow::Result<robocal_core::io::inputs::Inputs> {
    use robocal_core::io::inputs::{InputFile, Inputs};
    let mut inputs = Inputs::new();
    let robot = std::path::Path::new(&s.robot_arg);
    if robot.is_file() {
        inputs.insert("robot".into(), InputFile::of(robot)?);
    }
    inputs.insert("data".into(), InputFile::of(&s.data)?);
    if let Some(v) = &s.validate {
        inputs.insert("validation".into(), InputFile::of(v)?);
    }
    Ok(inputs)
}
