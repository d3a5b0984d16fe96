//! `robocal.calibrate`: the CLI's `calibrate` on numpy arrays or on measurement files, through
//! the same library calls (`split_measurements`, `calibrate`, `Calibration::to_result`), so the
//! results are the CLI's to the last bit.

use crate::errors::{input, raise, IntoPy};
use crate::options::{self, Options};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::identification::{calibrate, selection, split_measurements, CalibrationData};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::result_sections::RowsOutside;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::model::family::{backlash, thermal};
use robocal_core::{Observations, Robot};
use std::path::{Path, PathBuf};

/// The measured points of one run.
struct Data {
    calibration: Observations,
    plane: Observations,
    validation: Observations,
    /// The measurement files, as given (recorded in the result's settings).
    data_file: Option<String>,
    validate_file: Option<String>,
}

/// What a calibration returns to Python: the result JSON (as the CLI writes it), its status,
/// the warnings the CLI would print, and the seconds spent in the library's `calibrate` (the
/// binding's overhead is the rest).
type Outcome = (String, String, Vec<String>, f64);

/// Rows outside the joint limits: an error, or with `nominal_limits` a warning recorded in the
/// result.
fn check_limits(
    o: OutsideLimits,
    opts: &Options,
    outside: &mut Vec<OutsideLimits>,
    warnings: &mut Vec<String>,
) -> PyResult<()> {
    if opts.nominal_limits {
        if let Some(w) = o.to_warning() {
            warnings.push(format!("{w} (used anyway: nominal_limits=True)"));
            outside.push(o);
        }
        return Ok(());
    }
    match o.to_error() {
        None => Ok(()),
        Some(e) => Err(input(format!(
            "{}; if the robot's limits are only nominal, pass nominal_limits=True to use these \
             rows",
            crate::errors::message(&e)
        ))),
    }
}

/// Observations from arrays `q` (n, dof; interface units) and `xyz` (n, 3; mm, tracker frame),
/// named `what` in messages (their rows numbered from 1 there, as a file's lines).
fn observations(
    robot: &PyRobot,
    q: &Bound<'_, PyAny>,
    xyz: &Bound<'_, PyAny>,
    what: &str,
    opts: &Options,
    outside: &mut Vec<OutsideLimits>,
    warnings: &mut Vec<String>,
) -> PyResult<Observations> {
    let qn = format!("{what} q");
    let xn = format!("{what} xyz");
    let qm = robot.joints(q, &qn)?;
    let xm = crate::arrays::matrix(xyz, &xn, 3, "x, y, z in mm in the tracker frame")?;
    if qm.rows != xm.rows {
        return Err(input(format!(
            "{what}: {qn} has {} row(s), {xn} has {}: one measured point per pose",
            qm.rows, xm.rows
        )));
    }
    let path = PathBuf::from(format!("{what} arrays"));
    let mut obs = Observations::with_source(robot.inner.dof(), &path);
    let mut o = OutsideLimits::new(&robot.inner, &path);
    for i in 0..qm.rows {
        let m = xm.row(i);
        obs.push(qm.row(i), nalgebra::Vector3::new(m[0], m[1], m[2]), i + 1)
            .py_err()?;
        o.check(i + 1, qm.row(i));
    }
    check_limits(o, opts, outside, warnings)?;
    Ok(obs)
}

/// An optional `(q, xyz)` pair.
fn pair<'py>(
    v: Option<&Bound<'py, PyAny>>,
    what: &str,
) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    v.extract::<(Bound<'py, PyAny>, Bound<'py, PyAny>)>()
        .map(Some)
        .map_err(|_| crate::errors::usage(format!("{what}: expected a pair (q, xyz) of arrays")))
}

/// Calibrates `robot` from arrays (see `robocal.calibrate`).
#[pyfunction]
#[pyo3(signature = (robot, q, xyz, plane, validate, options))]
pub fn calibrate_arrays(
    py: Python<'_>,
    robot: &PyRobot,
    q: &Bound<'_, PyAny>,
    xyz: &Bound<'_, PyAny>,
    plane: Option<&Bound<'_, PyAny>>,
    validate: Option<&Bound<'_, PyAny>>,
    options: &Bound<'_, PyDict>,
) -> PyResult<Outcome> {
    let mut nominal = robot.clone();
    let opts = options::parse(&mut nominal.inner, options)?;
    let mut warnings = opts.notes.clone();
    let mut outside = Vec::new();
    let calibration = observations(
        &nominal,
        q,
        xyz,
        "calibration",
        &opts,
        &mut outside,
        &mut warnings,
    )?;
    let dof = nominal.inner.dof();
    let plane = match pair(plane, "plane")? {
        Some((pq, px)) => observations(
            &nominal,
            &pq,
            &px,
            "plane",
            &opts,
            &mut outside,
            &mut warnings,
        )?,
        None => Observations::new(dof),
    };
    let validation = match pair(validate, "validate")? {
        Some((vq, vx)) => observations(
            &nominal,
            &vq,
            &vx,
            "validation",
            &opts,
            &mut outside,
            &mut warnings,
        )?,
        None => Observations::new(dof),
    };
    let data = Data {
        calibration,
        plane,
        validation,
        data_file: None,
        validate_file: None,
    };
    run(py, &nominal, data, &opts, outside, warnings)
}

/// Reads a measurement file as the CLI does: warnings kept, rows sorted by `set`, joint limits
/// checked.
fn read_file(
    path: &Path,
    robot: &Robot,
    opts: &Options,
    outside: &mut Vec<OutsideLimits>,
    warnings: &mut Vec<String>,
) -> PyResult<robocal_core::identification::SplitData> {
    let set = read_measurements(path, robot.joint_space(), Positions::Required).py_err()?;
    warnings.extend(set.warnings.iter().cloned());
    let split = split_measurements(&set).py_err()?;
    let mut o = OutsideLimits::new(robot, path);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    check_limits(o, opts, outside, warnings)?;
    Ok(split)
}

/// Appends the points of `b` to `a`.
fn merge(mut a: Observations, b: &Observations) -> PyResult<Observations> {
    if a.is_empty() {
        return Ok(b.clone());
    }
    for i in 0..b.len() {
        a.push(b.q(i), *b.m(i), b.line(i)).py_err()?;
    }
    Ok(a)
}

/// Calibrates `robot` from measurement files, as `robocal calibrate --data FILE [--validate
/// FILE]` (see `robocal.calibrate_files`).
#[pyfunction]
#[pyo3(signature = (robot, data, validate, options))]
pub fn calibrate_files(
    py: Python<'_>,
    robot: &PyRobot,
    data: PathBuf,
    validate: Option<PathBuf>,
    options: &Bound<'_, PyDict>,
) -> PyResult<Outcome> {
    let mut nominal = robot.clone();
    let opts = options::parse(&mut nominal.inner, options)?;
    let mut warnings = opts.notes.clone();
    let mut outside = Vec::new();
    if let Some(v) = &validate {
        if same_file(v, &data) {
            return Err(crate::errors::usage(format!(
                "validate {}: this is the data file {} (the same file); validation points must \
                 be points the calibration did not fit: give another file, or mark validation \
                 rows of the data with set = validation",
                v.display(),
                data.display()
            )));
        }
    }
    let d = read_file(&data, &nominal.inner, &opts, &mut outside, &mut warnings)?;
    let mut validation = d.validation.clone();
    if let Some(v) = &validate {
        let vd = read_file(v, &nominal.inner, &opts, &mut outside, &mut warnings)?;
        if !vd.plane.is_empty() {
            warnings.push(format!(
                "{}: {} plane point(s) ignored in the validation set",
                v.display(),
                vd.plane.len()
            ));
        }
        validation = merge(validation, &vd.calibration)?;
        validation = merge(validation, &vd.validation)?;
    }
    let data = Data {
        calibration: d.calibration,
        plane: d.plane,
        validation,
        data_file: Some(data.display().to_string()),
        validate_file: validate.map(|v| v.display().to_string()),
    };
    run(py, &nominal, data, &opts, outside, warnings)
}

/// The model fitted to `data`, as the CLI's: with thermal expansion its lengths referred to the
/// calibration rows' mean temperature (an `InputError` without temperatures); with backlash and
/// no approach directions, the directions derived from the row order (a warning).
fn fit_to_data(robot: &Robot, data: &mut Data, warnings: &mut Vec<String>) -> PyResult<Robot> {
    let mut r = robot.clone();
    let what = data
        .data_file
        .as_deref()
        .unwrap_or("the calibration points");
    if thermal::reference_c(&r).is_some() {
        let cd = CalibrationData {
            calibration: &data.calibration,
            plane: None,
            validation: None,
        };
        let Some(t) = selection::reference_temperature_c(&cd) else {
            return Err(input(format!(
                "thermal=\"auto\": {what} have no temperature_c (the arm's temperature at each \
                 row, deg C; give the data as a file with that column)"
            )));
        };
        thermal::set_reference_c(&mut r, t).py_err()?;
        warnings.push(format!(
            "thermal expansion referred to {t:.1} deg C (the calibration rows' mean)"
        ));
    }
    if !backlash::joints(&r).is_empty() && !data.calibration.has_directions() {
        data.calibration.derive_directions();
        warnings.push(format!(
            "{what} have no dir1..dirN: approach directions derived from the row order (the \
             motion from the previous calibration row; the first row's unknown)"
        ));
    }
    Ok(r)
}

/// Whether two paths name the same file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// The calibration itself, the GIL released; then the CLI's verdicts: a solver that did not
/// converge is a `NumericalError` unless `keep_partial`, a fit that failed the plausibility
/// gate an `ImplausibleError` unless `accept_implausible`.
fn run(
    py: Python<'_>,
    nominal: &PyRobot,
    data: Data,
    opts: &Options,
    outside: Vec<OutsideLimits>,
    mut warnings: Vec<String>,
) -> PyResult<Outcome> {
    let mut data = data;
    let robot = &fit_to_data(&nominal.inner, &mut data, &mut warnings)?;
    let settings = &opts.settings;
    let started = std::time::Instant::now();
    let cal = py
        .detach(|| {
            calibrate(
                robot,
                CalibrationData {
                    calibration: &data.calibration,
                    plane: Some(&data.plane),
                    validation: Some(&data.validation),
                },
                settings,
                &(),
            )
        })
        .py_err()?;
    let library_seconds = started.elapsed().as_secs_f64();
    let converged = cal.solver().termination.converged();
    let implausible = cal.plausibility.implausible();
    if let Some(why) = &cal.covariance.unavailable {
        warnings.push(format!(
            "standard deviations unavailable (None): {why} (rank_tol {:e} given explicitly)",
            settings.identifiability.rank_tolerance
        ));
    }
    if let Some(remark) = cal.model_selection.as_ref().and_then(|s| s.remark.as_ref()) {
        warnings.push(remark.clone());
    }
    let mut res = cal.to_result();
    if let Some(rs) = &mut res.settings {
        rs.robot_arg = nominal.source.clone();
        rs.data = data.data_file.clone();
        rs.validate = data.validate_file.clone();
        rs.nominal_limits = Some(opts.nominal_limits);
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
    let summary = || cal.plausibility.summary();
    if !converged {
        let why = format!(
            "the solver {} after {} iteration(s) (max_iterations {})",
            cal.solver().termination.describe(),
            cal.stages
                .iter()
                .map(|s| s.report.iterations)
                .sum::<usize>(),
            settings.solver.max_iterations
        );
        if !opts.keep_partial {
            return Err(raise(
                5,
                format!(
                    "{why}: a partial result, not a calibration (raise max_iterations, or pass \
                     keep_partial=True to get the partial result, marked as such)"
                ),
            ));
        }
        warnings.push(format!(
            "{why}: the result is PARTIAL, not a calibration (status \"partial\")"
        ));
        res.partial_reason = Some(why);
    } else if implausible {
        if !opts.accept_implausible {
            return Err(raise(
                6,
                format!(
                    "implausible fit: the solver converged, but the result cannot be a \
                     calibration. Failed checks:\n{}\n(fix the data or the robot; \
                     accept_implausible=True returns it anyway, marked \"status\": \
                     \"implausible\")",
                    summary()
                ),
            ));
        }
        warnings.push(format!(
            "IMPLAUSIBLE FIT (accept_implausible=True): the fit failed the plausibility gate and \
             is NOT a calibration:\n{}",
            summary()
        ));
    }
    let status = res.status().map_or("calibrated", |s| s.as_str()).to_owned();
    let text = res
        .to_text()
        .map_err(|e| raise(1, format!("cannot serialize the result: {e}")))?;
    Ok((text, status, warnings, library_seconds))
}
