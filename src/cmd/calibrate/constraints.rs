//! `calibrate` on constraint data (issue 31): a measurement file with a `constraint` column
//! (fixed points, spheres, planes; no `x,y,z`) and, with `--distances`, known distances between
//! points or sphere centres. The robot's model (its geometry and the families of `--compliance`,
//! `--harmonics`, `--backlash`, `--thermal`, or with `--model auto` the families the data
//! support, chosen by cross-validation by configuration) and the features are fitted together
//! in the robot's base frame ([`robocal_core::identification::constraint`]); the result is up
//! to the base pose, and says so.

use super::Settings;
use crate::cmd::common;
use crate::exit;
use robocal_core::identification::constraint::{
    calibrate_constraints, calibrate_constraints_auto, ConstraintCalibration, ConstraintOptions,
    Scale,
};
use robocal_core::identification::ModelChoice;
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::measurements::MeasurementReader;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::model::family::thermal;
use robocal_core::model::Robot;
use robocal_core::observations::constraint::{
    read_distances, ConstraintData, ConstraintKind, CONSTRAINT_COLUMN,
};
use std::path::Path;

/// Whether the measurement file at `path` holds constraint rows (its header has a
/// `constraint` column).
pub(crate) fn is_constraint_file(path: &Path, robot: &Robot) -> anyhow::Result<bool> {
    let r = MeasurementReader::open(path, robot.joint_space(), Positions::Ignored)?;
    Ok(has_constraint_column(r.extra_columns()))
}

/// Whether a measurement file's extra columns (its header beyond the joint columns) hold the
/// `constraint` column.
pub(super) fn has_constraint_column(extra_columns: &[String]) -> bool {
    extra_columns
        .iter()
        .any(|c| c.eq_ignore_ascii_case(CONSTRAINT_COLUMN))
}

/// Reads, calibrates, prints and writes a constraint calibration.
pub(super) fn run(
    s: &Settings,
    distances: Option<&Path>,
    accept_unknown_scale: bool,
) -> anyhow::Result<()> {
    if s.validate.is_some() {
        return Err(exit::usage(
            "--validate: constraint data have no tracker points to validate against (not \
             supported with a constraint file)",
        ));
    }
    let robot = &s.robot;
    let set = read_measurements(&s.data, robot.joint_space(), Positions::Ignored)?;
    for w in &set.warnings {
        errln!("warning: {w}")?;
    }
    let mut o = OutsideLimits::new(robot, &s.data);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    common::check_limits(o, s.nominal_limits, &mut Vec::new())?;
    let mut data = ConstraintData::from_measurements(&set)?;
    if let Some(d) = distances {
        data.distances = read_distances(d, &data)?;
    }
    let count = |k: ConstraintKind| data.features.iter().filter(|f| f.kind == k).count();
    outln!(
        "robot {} ({} joints); {} constraint row(s): {} fixed point(s), {} sphere(s), {} \
         plane(s); {} known distance(s){}",
        robot.name(),
        robot.dof(),
        data.rows.len(),
        count(ConstraintKind::Point),
        count(ConstraintKind::Sphere),
        count(ConstraintKind::Plane),
        data.distances.len(),
        if data.tracker.is_empty() {
            String::new()
        } else {
            format!("; {} tracker row(s)", data.tracker.len())
        }
    )?;
    let opts = ConstraintOptions {
        accept_unknown_scale,
        rank_tolerance: s.calibration.identifiability.rank_tolerance,
        ..ConstraintOptions::default()
    };
    let cal = match s.calibration.model {
        ModelChoice::Auto(auto) => calibrate_constraints_auto(robot, &data, &opts, auto),
        ModelChoice::Given => calibrate_constraints(robot, &data, &opts),
    };
    let cal = cal.map_err(|e| {
        let hint = if data.has_known_length() {
            ""
        } else {
            " (--distances FILE with from,to,distance_mm; or radius_mm on a sphere's rows; or \
             --accept-unknown-scale)"
        };
        anyhow::Error::new(e).context(format!("calibrating from {}{hint}", s.data.display()))
    })?;
    if let Some(sel) = &cal.model_selection {
        super::print_selection(sel)?;
        outln!()?;
    }
    if let Some(t) = thermal::reference_c(&cal.robot) {
        errln!("thermal expansion referred to {t:.1} deg C (the rows' mean)")?;
    }
    print(&cal.nominal, &cal)?;
    if !cal.fit.converged {
        return Err(exit::numerical(format!(
            "the constraint fit did not converge in {} iterations; nothing written to {}",
            cal.fit.iterations,
            s.out.display()
        )));
    }
    let mut res = cal.to_result(robot, &data)?;
    res.inputs = Some(record_inputs(s, distances)?);
    if !cal.implausible.is_empty() {
        let summary = common::indent(&cal.implausible.join("\n"));
        if !s.accept_implausible {
            return Err(exit::implausible(format!(
                "implausible fit: the constraint fit converged, but the result cannot be a \
                 calibration; nothing written to {}. Failed checks:\n{summary}\n(fix the data \
                 or the robot; --accept-implausible writes it anyway, marked \"status\": \
                 \"implausible\")",
                s.out.display()
            )));
        }
        errln!(
            "WARNING: IMPLAUSIBLE FIT WRITTEN (--accept-implausible): failed checks:\n{summary}"
        )?;
    }
    res.write(&s.out)?;
    outln!("result written to {}", s.out.display())?;
    Ok(())
}

/// The table of parameters, the features and what the data cannot see.
fn print(nominal: &Robot, cal: &ConstraintCalibration) -> anyhow::Result<()> {
    outln!(
        "fit: {} iteration(s), residual RMS {:.4} mm, max {:.4} mm, condition number {:.0}",
        cal.fit.iterations,
        cal.residual_rms_mm,
        cal.residual_max_mm,
        cal.condition_number
    )?;
    outln!(
        "{:<10} {:>14} {:>14} {:>12}",
        "parameter",
        "nominal",
        "calibrated",
        "change"
    )?;
    for p in &cal.identified {
        let u = p.unit().as_str();
        let (was, now) = (nominal.get_display(*p), cal.robot.get_display(*p));
        outln!(
            "{:<10} {:>14.6} {:>14.6} {:>9.6} {u}",
            p.name(),
            was,
            now,
            now - was
        )?;
    }
    outln!("features (base frame of the calibrated model):")?;
    for (f, rms) in cal.features.iter().zip(&cal.feature_rms_mm) {
        let p = f.position;
        let extra = match (f.kind, f.radius_mm, f.normal) {
            (ConstraintKind::Sphere, Some(r), _) => format!(
                ", radius {r:.4} mm{}",
                if f.radius_known { " (given)" } else { "" }
            ),
            (ConstraintKind::Plane, _, Some(n)) => format!(
                ", normal ({:.6}, {:.6}, {:.6}), offset {:.4} mm",
                n.x,
                n.y,
                n.z,
                f.offset_mm.unwrap_or(0.0)
            ),
            _ => String::new(),
        };
        outln!(
            "  {:<16} ({:.4}, {:.4}, {:.4}) mm{extra}; residual RMS {rms:.4} mm",
            f.label(),
            p.x,
            p.y,
            p.z
        )?;
    }
    for d in &cal.distance_residuals_mm {
        outln!("  known distance residual {d:+.4} mm")?;
    }
    if let Some(f) = &cal.frame {
        let v = robocal_core::frame::TrackerFrame::new(*f).vector_deg();
        let n = cal.tracker_residuals_mm.len().max(1) as f64;
        let rms = (cal.tracker_residuals_mm.iter().map(|x| x * x).sum::<f64>() / n).sqrt();
        outln!(
            "tracker frame registered by {} tracker row(s): x={:.3} y={:.3} z={:.3} mm, A={:.4} \
             B={:.4} C={:.4} deg; tracker rows' residual RMS {rms:.4} mm",
            cal.tracker_residuals_mm.len(),
            v[0],
            v[1],
            v[2],
            v[3],
            v[4],
            v[5]
        )?;
    }
    match &cal.scale {
        Scale::Known { from } => outln!("scale: from {from}")?,
        Scale::Assumed { held } => errln!(
            "WARNING: the robot's scale is not determined by these data; {} is held at its \
                 nominal value (--accept-unknown-scale): lengths may be off in proportion",
            held.name()
        )?,
    }
    outln!("not identifiable from these data:")?;
    for u in &cal.unseen {
        outln!("  - {u}")?;
    }
    for f in &cal.fixed {
        outln!("  {:<10} held: {}", f.param.name(), f.reason)?;
    }
    Ok(())
}

/// The result's `inputs`: the robot file (not a preset), the data and the distances file, each
/// with its path and SHA-256.
fn record_inputs(
    s: &Settings,
    distances: Option<&Path>,
) -> anyhow::Result<robocal_core::io::inputs::Inputs> {
    use robocal_core::io::inputs::{InputFile, Inputs};
    let mut inputs = Inputs::new();
    let robot = Path::new(&s.robot_arg);
    if robot.is_file() {
        inputs.insert("robot".into(), InputFile::of(robot)?);
    }
    inputs.insert("data".into(), InputFile::of(&s.data)?);
    if let Some(d) = distances {
        inputs.insert("distances".into(), InputFile::of(d)?);
    }
    Ok(inputs)
}
