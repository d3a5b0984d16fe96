//! `robocal.calibrate_files` on constraint data (issue 31): a measurement file with a
//! `constraint` column (fixed points, spheres, planes; no x,y,z), with known distances from a
//! distances file, through the CLI's library calls (`calibrate_constraints`,
//! `ConstraintCalibration::to_result`) and with the CLI's refusals: an undetermined scale
//! (`NumericalError`, unless `accept_unknown_scale`), a fit that did not converge
//! (`NumericalError`), a fit that failed the gate (`ImplausibleError`, unless
//! `accept_implausible`), rows outside the joint limits (`InputError`, unless `nominal_limits`).

use crate::errors::{input, raise, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use robocal_core::identification::constraint::{calibrate_constraints, ConstraintOptions};
use robocal_core::io::inputs::{InputFile, Inputs};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::observations::constraint::{read_distances, ConstraintData, CONSTRAINT_COLUMN};
use std::path::PathBuf;

/// Whether the measurement file at `path` has a `constraint` column.
#[pyfunction]
pub fn is_constraint_file(robot: &PyRobot, path: PathBuf) -> PyResult<bool> {
    let r = robocal_core::io::measurements::MeasurementReader::open(
        &path,
        robot.inner.joint_space(),
        Positions::Ignored,
    )
    .py_err()?;
    Ok(r.extra_columns()
        .iter()
        .any(|c| c.eq_ignore_ascii_case(CONSTRAINT_COLUMN)))
}

/// Calibrates `robot` from the constraint file `data` (see the module docs); returns the result
/// JSON, its status, the warnings and the library's seconds, as `calibrate_files`.
#[pyfunction]
#[pyo3(signature = (robot, data, distances = None, accept_unknown_scale = false,
                    accept_implausible = false, nominal_limits = false, rank_tol = None))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate_constraint_file(
    py: Python<'_>,
    robot: &PyRobot,
    data: PathBuf,
    distances: Option<PathBuf>,
    accept_unknown_scale: bool,
    accept_implausible: bool,
    nominal_limits: bool,
    rank_tol: Option<f64>,
) -> PyResult<(String, String, Vec<String>, f64)> {
    let nominal = &robot.inner;
    let mut warnings = Vec::new();
    let set = read_measurements(&data, nominal.joint_space(), Positions::Ignored).py_err()?;
    warnings.extend(set.warnings.iter().map(|w| w.to_string()));
    let mut o = OutsideLimits::new(nominal, &data);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    if nominal_limits {
        if let Some(w) = o.to_warning() {
            warnings.push(format!("{w} (used anyway: nominal_limits=True)"));
        }
    } else if let Some(e) = o.to_error() {
        return Err(input(format!(
            "{}; if the robot's limits are only nominal, pass nominal_limits=True to use these \
             rows",
            crate::errors::message(&e)
        )));
    }
    let mut cdata = ConstraintData::from_measurements(&set).py_err()?;
    if let Some(d) = &distances {
        cdata.distances = read_distances(d, &cdata).py_err()?;
    }
    let mut opts = ConstraintOptions {
        accept_unknown_scale,
        ..ConstraintOptions::default()
    };
    if let Some(t) = rank_tol {
        opts.rank_tolerance = t;
    }
    let started = std::time::Instant::now();
    let cal = py
        .detach(|| calibrate_constraints(nominal, &cdata, &opts))
        .map_err(|e| {
            let hint = if cdata.has_known_length() {
                ""
            } else {
                " (distances=FILE with from,to,distance_mm; or radius_mm on a sphere's rows; or \
                 accept_unknown_scale=True)"
            };
            raise(
                crate::errors::exit_code(&e),
                format!(
                    "calibrating from {}: {}{hint}",
                    data.display(),
                    crate::errors::message(&e)
                ),
            )
        })?;
    let seconds = started.elapsed().as_secs_f64();
    if !cal.fit.converged {
        return Err(raise(
            5,
            format!(
                "the constraint fit did not converge in {} iterations: not a calibration",
                cal.fit.iterations
            ),
        ));
    }
    if !cal.implausible.is_empty() {
        let summary = cal.implausible.join("\n");
        if !accept_implausible {
            return Err(raise(
                6,
                format!(
                    "implausible fit: the constraint fit converged, but the result cannot be a \
                     calibration. Failed checks:\n{summary}\n(fix the data or the robot; \
                     accept_implausible=True returns it anyway, marked \"status\": \
                     \"implausible\")"
                ),
            ));
        }
        warnings.push(format!(
            "IMPLAUSIBLE FIT (accept_implausible=True): the fit failed the plausibility gate and \
             is NOT a calibration:\n{summary}"
        ));
    }
    if let robocal_core::identification::constraint::Scale::Assumed { held } = &cal.scale {
        warnings.push(format!(
            "the robot's scale is not determined by these data; {} is held at its nominal value \
             (accept_unknown_scale=True): lengths may be off in proportion",
            held.name()
        ));
    }
    let mut res = cal.to_result(nominal, &cdata).py_err()?;
    let mut inputs = Inputs::new();
    inputs.insert("data".into(), InputFile::of(&data).py_err()?);
    if let Some(d) = &distances {
        inputs.insert("distances".into(), InputFile::of(d).py_err()?);
    }
    res.inputs = Some(inputs);
    let status = res.status().map_or("calibrated", |s| s.as_str()).to_owned();
    let mut text = serde_json::to_string_pretty(&res)
        .map_err(|e| raise(1, format!("cannot serialize the result: {e}")))?;
    text.push('\n');
    Ok((text, status, warnings, seconds))
}
