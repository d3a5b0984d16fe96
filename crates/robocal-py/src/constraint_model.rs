//! `robocal.calibrate_files` on constraint data with the model options of tracker data (issue
//! 31): `model` ("auto", the default, or "geometric") and the families `compliance`,
//! `payload_kg`, `harmonics`, `backlash`, `thermal`, parsed as for tracker data
//! ([`crate::options::parse`]) and fitted by the constraint calibration; with `model="auto"`
//! the families not given are chosen by cross-validation by configuration
//! ([`calibrate_constraints_auto`]) and the result has `model_selection`, as the CLI's
//! `robocal calibrate --data CONSTRAINTS.csv`. The CLI's refusals as
//! [`crate::constraints::calibrate_constraint_file`]'s.

use crate::errors::{input, raise, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::identification::constraint::{
    calibrate_constraints, calibrate_constraints_auto, ConstraintOptions, Scale,
};
use robocal_core::identification::ModelChoice;
use robocal_core::io::inputs::{InputFile, Inputs};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::observations::constraint::{read_distances, ConstraintData};
use std::path::PathBuf;

/// Calibrates `robot` (with the families of `options`) from the constraint file `data`, the
/// model chosen as `options["model"]` says (see the module docs); returns the result JSON, its
/// status, the warnings and the library's seconds, as `calibrate_files`. Of `options` only the
/// model, the families, `accept_implausible`, `nominal_limits` and `rank_tol` apply (the Python
/// wrapper refuses the others).
#[pyfunction]
#[pyo3(signature = (robot, data, distances, accept_unknown_scale, options))]
pub fn calibrate_constraint_file_model(
    py: Python<'_>,
    robot: &PyRobot,
    data: PathBuf,
    distances: Option<PathBuf>,
    accept_unknown_scale: bool,
    options: &Bound<'_, PyDict>,
) -> PyResult<(String, String, Vec<String>, f64)> {
    let mut nominal = robot.inner.clone();
    let opts = crate::options::parse(&mut nominal, options)?;
    let mut warnings = opts.notes.clone();
    let set = read_measurements(&data, nominal.joint_space(), Positions::Ignored).py_err()?;
    warnings.extend(set.warnings.iter().map(|w| w.to_string()));
    let mut o = OutsideLimits::new(&nominal, &data);
    for r in &set.rows {
        o.check(r.line, &r.q);
    }
    if opts.nominal_limits {
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
    let copts = ConstraintOptions {
        accept_unknown_scale,
        rank_tolerance: opts.settings.identifiability.rank_tolerance,
        ..ConstraintOptions::default()
    };
    let started = std::time::Instant::now();
    let cal = py
        .detach(|| match opts.settings.model {
            ModelChoice::Auto(auto) => calibrate_constraints_auto(&nominal, &cdata, &copts, auto),
            ModelChoice::Given => calibrate_constraints(&nominal, &cdata, &copts),
        })
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
        if !opts.accept_implausible {
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
    if let Scale::Assumed { held } = &cal.scale {
        warnings.push(format!(
            "the robot's scale is not determined by these data; {} is held at its nominal value \
             (accept_unknown_scale=True): lengths may be off in proportion",
            held.name()
        ));
    }
    if let Some(remark) = cal.model_selection.as_ref().and_then(|s| s.remark.as_ref()) {
        warnings.push(remark.clone());
    }
    let mut res = cal.to_result(&nominal, &cdata).py_err()?;
    let mut inputs = Inputs::new();
    inputs.insert("data".into(), InputFile::of(&data).py_err()?);
    if let Some(d) = &distances {
        inputs.insert("distances".into(), InputFile::of(d).py_err()?);
    }
    res.inputs = Some(inputs);
    let status = res.status().map_or("calibrated", |s| s.as_str()).to_owned();
    let text = res
        .to_text()
        .map_err(|e| raise(1, format!("cannot serialize the result: {e}")))?;
    Ok((text, status, warnings, seconds))
}
