//! `robocal.calibrate_files` on constraint data with the model options of tracker data (issue
//! 31): `model` ("auto", the default, or "geometric") and the families `compliance`,
//! `payload_kg`, `harmonics`, `backlash`, `thermal`, parsed as for tracker data
//! ([`crate::options::parse`]) and fitted by the constraint calibration; with `model="auto"`
//! the families not given are chosen by cross-validation by configuration
//! ([`calibrate_constraints_auto`]) and the result has `model_selection`, as the CLI's
//! `robocal calibrate --data CONSTRAINTS.csv`. The CLI's refusals as
//! [`crate::constraints::calibrate_constraint_file`]'s.

use crate::constraints::calibrate_data;
use crate::errors::{input, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::identification::constraint::ConstraintOptions;
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
    let mut inputs = Inputs::new();
    inputs.insert("data".into(), InputFile::of(&data).py_err()?);
    if let Some(d) = &distances {
        inputs.insert("distances".into(), InputFile::of(d).py_err()?);
    }
    calibrate_data(
        py,
        &nominal,
        &cdata,
        &copts,
        Some(opts.settings.model),
        opts.accept_implausible,
        &data.display().to_string(),
        Some(inputs),
        warnings,
    )
}
