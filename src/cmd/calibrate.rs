//! `robocal calibrate`: registration of the measurement frame and identification of the
//! calibrated parameters (paper, sections II.C and III).

use super::common;
use crate::exit;
use anyhow::Context;
use clap::{Args, ValueEnum};
use robocal_core::identification::{calibrate, CalibrationData, Observations, SplitData};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::result_sections::RowsOutside;
use robocal_core::io::CalibrationResult;
use robocal_core::Robot;
use std::path::PathBuf;

mod constraints;
pub(crate) use constraints::is_constraint_file;
mod joint_list;
mod print;
mod real_cell;
mod settings;
pub(crate) use print::print_selection;
use print::{print_plausibility, print_report};
use robocal_core::io::{MeasurementReader, Positions};
use settings::{read, read_from, Settings};

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
    /// calibration rows' mean temperature (the result's `reference_temperature_c`); `per-link`
    /// one coefficient per link (`thermal_k1`..), for an arm that warms unevenly; or `none`
    /// [default: none, or chosen by --model auto (lumped) when the data have temperature_c].
    #[arg(long, value_parser = ["auto", "per-link", "none"])]
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

pub fn run(a: CalibrateArgs) -> anyhow::Result<()> {
    let s = Settings::try_from(&a)?;
    // The data file is opened once as measurements; only a header those refuse is read again
    // to tell whether it holds constraint rows (whose header needs no x,y,z), in the order of
    // checks of a file sniffed first: its header's errors, constraint data, then measurements.
    let opened = MeasurementReader::open(&s.data, s.robot.joint_space(), Positions::Required);
    let constraint = match &opened {
        Ok(r) => constraints::has_constraint_column(r.extra_columns()),
        Err(_) => constraints::is_constraint_file(&s.data, &s.robot)?,
    };
    if constraint {
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
    let mut data = read_from(opened?, &s.data, &s.robot, s.nominal_limits, &mut outside)?;
    let robot = &real_cell::fit_to_data(&s.robot, &mut data, &s.data)?;
    let validation = read_validation(&s, robot, &data, &mut outside)?;
    print_sets(&s, robot, &data, &validation)?;
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
    let verdict = Verdict {
        converged: cal.solver().termination.converged(),
        implausible: cal.plausibility.implausible(),
        summary: common::indent(&cal.plausibility.summary()),
        why: format!(
            "the solver {} after {} iteration(s) (--max-iterations {})",
            cal.solver().termination.describe(),
            cal.stages
                .iter()
                .map(|s| s.report.iterations)
                .sum::<usize>(),
            s.calibration.solver.max_iterations
        ),
    };
    if let Some(sel) = &cal.model_selection {
        print_selection(sel)?;
    }
    print_report(&cal, verdict.converged, verdict.implausible)?;
    print_plausibility(&cal)?;
    if let Some(why) = &cal.covariance.unavailable {
        errln!(
            "warning: standard deviations unavailable (written as null): {why} (--rank-tol \
             {:e} given explicitly)",
            s.calibration.identifiability.rank_tolerance
        )?;
    }
    let mut res = cal.to_result();
    res.inputs = Some(record_inputs(&s)?);
    if let Some(rs) = &mut res.settings {
        record_settings(rs, &s, &outside);
    }
    // The fit and its data are not needed to write the result: free them before its text is
    // built, the largest allocation of a large calibration (about 90 bytes a point).
    drop(cal);
    drop(data);
    drop(validation);
    write_or_refuse(res, &s, &verdict)
}

/// The validation points: the data's own `validation` rows and, with `--validate`, every point
/// of that file but its plane points (ignored with a note).
fn read_validation(
    s: &Settings,
    robot: &Robot,
    data: &SplitData,
    outside: &mut Vec<OutsideLimits>,
) -> anyhow::Result<Observations> {
    let mut validation = data.validation.clone();
    if let Some(v) = &s.validate {
        let vd = read(v, robot, s.nominal_limits, outside)?;
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
    Ok(validation)
}

/// The first line: the robot and how many points of each kind calibrate and validate it.
fn print_sets(
    s: &Settings,
    robot: &Robot,
    data: &SplitData,
    validation: &Observations,
) -> anyhow::Result<()> {
    outln!(
        "robot {} ({} joints, {}){}; {} calibration point(s){}{}",
        robot.name(),
        robot.dof(),
        robot.convention().as_str(),
        if s.betas.is_empty() {
            String::new()
        } else {
            format!(
                ", Hayati tilt on {}",
                s.betas
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
    Ok(())
}

/// The result's `settings` as the command line gave them: the robot, the files, the joint
/// limits and the rows outside them.
fn record_settings(
    rs: &mut robocal_core::io::result_sections::Settings,
    s: &Settings,
    outside: &[OutsideLimits],
) {
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

/// Whether the fit is a calibration, and the words for when it is not.
struct Verdict {
    converged: bool,
    implausible: bool,
    /// The plausibility gate's summary, indented.
    summary: String,
    /// How the solver ended.
    why: String,
}

/// Writes the result when it is a calibration. When it is not, fails (exit 6 for an implausible
/// fit, 4 for one that did not converge), writing it marked only when asked
/// (`--accept-implausible`, `--keep-partial`).
fn write_or_refuse(mut res: CalibrationResult, s: &Settings, v: &Verdict) -> anyhow::Result<()> {
    let Verdict { summary, why, .. } = v;
    if v.converged && !v.implausible {
        res.write(&s.out)?;
        outln!("result written to {}", s.out.display())?;
        return Ok(());
    }
    if v.converged {
        // Converged but implausible: not a calibration. Fail; keep it only if asked, marked.
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
    let failed_gate = if v.implausible {
        format!("\nThe fit also FAILED the plausibility gate:\n{summary}")
    } else {
        String::new()
    };
    // Not converged: not a calibration. Fail; keep the partial result only if asked, marked.
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
