//! Result JSON in and out: the library's `CalibrationResult`, checked on reading exactly as the
//! CLI checks a `--params` file.

use crate::errors::{raise, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use robocal_core::io::CalibrationResult;
use std::path::Path;

/// The name results parsed from text carry in messages.
const TEXT: &str = "<result json>";

fn to_text(res: &CalibrationResult) -> PyResult<String> {
    res.to_text()
        .map_err(|e| raise(1, format!("cannot serialize the result: {e}")))
}

/// Checks result JSON `text` (as `robocal` reads a result file) and returns it as robocal
/// writes it.
#[pyfunction]
pub fn parse_result(text: &str) -> PyResult<String> {
    to_text(&CalibrationResult::parse(text, Path::new(TEXT)).py_err()?)
}

/// Reads a result file (`robocal calibrate --out`) and returns its text as robocal writes it.
#[pyfunction]
pub fn read_result(path: std::path::PathBuf) -> PyResult<String> {
    to_text(&CalibrationResult::read(&path).py_err()?)
}

/// Writes result JSON `text` to `path` atomically (checked first: nothing half-written).
#[pyfunction]
pub fn write_result(text: &str, path: std::path::PathBuf) -> PyResult<()> {
    let res = CalibrationResult::parse(text, Path::new(TEXT)).py_err()?;
    res.write(&path).py_err()
}

/// The nominal robot a result embeds (or `nominal` when given, checked to agree) and the
/// calibrated one.
#[pyfunction]
#[pyo3(signature = (text, nominal = None))]
pub fn result_robots(text: &str, nominal: Option<&PyRobot>) -> PyResult<(PyRobot, PyRobot)> {
    let path = Path::new(TEXT);
    let res = CalibrationResult::parse(text, path).py_err()?;
    let embedded = res.robot.nominal_robot(path, Some(text)).py_err()?;
    let nom = match (nominal, &embedded) {
        (Some(n), _) => n.inner.clone(),
        (None, Some(r)) => r.clone(),
        (None, None) => {
            return Err(crate::errors::usage(
                "the result does not embed its robot (written by an older robocal): give the \
                 nominal robot",
            ))
        }
    };
    let cal = res.calibrated_robot(&nom, path).py_err()?;
    robocal_core::evaluation::check_result_nominal(&res, &nom, path).py_err()?;
    if let (Some(n), Some(emb)) = (nominal, &embedded) {
        if let Some(diff) = robocal_core::model::description::nominal_difference(emb, &n.inner) {
            return Err(crate::errors::input(format!(
                "the robot embedded in the result (`{}`) and the nominal robot given (`{}`) \
                 disagree: {diff}",
                emb.name(),
                n.inner.name()
            )));
        }
    }
    let source = res.settings.as_ref().and_then(|s| s.robot_arg.clone());
    Ok((PyRobot::new(nom, source.clone()), PyRobot::new(cal, source)))
}
