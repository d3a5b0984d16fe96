//! `robocal.import_measurements`: a tracker export and a joint log into a measurement CSV, by
//! the library's `io::import` (what `robocal import` runs).

use crate::errors::{usage, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use robocal_core::io::import::{
    import_files, write_import, DwellSettings, ImportConfig, ImportLimits,
};
use std::path::PathBuf;

fn choice<T: std::str::FromStr<Err = String>>(name: &str, v: &str) -> PyResult<T> {
    v.parse().map_err(|e: String| usage(format!("{name}: {e}")))
}

/// Reads `points` and `joints`, pairs them by `match_by` (`name`, `order` or `time`) and gives
/// the measurement CSV's text and the report's lines; writes the CSV to `out` (atomically) when
/// given.
#[pyfunction]
#[pyo3(signature = (points, joints, match_by, out = None, points_format = "auto",
    joints_format = "auto", time_offset = None, length_unit = None, angle_unit = None,
    joint_columns = None, name_column = None, robot = None, still_deg = None, dwell_min_s = None,
    time_tolerance = 0.2, nominal_limits = false))]
#[allow(clippy::too_many_arguments)]
pub fn import_measurements(
    points: PathBuf,
    joints: PathBuf,
    match_by: &str,
    out: Option<PathBuf>,
    points_format: &str,
    joints_format: &str,
    time_offset: Option<f64>,
    length_unit: Option<&str>,
    angle_unit: Option<&str>,
    joint_columns: Option<Vec<String>>,
    name_column: Option<String>,
    robot: Option<&PyRobot>,
    still_deg: Option<f64>,
    dwell_min_s: Option<f64>,
    time_tolerance: f64,
    nominal_limits: bool,
) -> PyResult<(String, Vec<String>)> {
    let d = DwellSettings::default();
    let config = ImportConfig {
        points_format: choice("points_format", points_format)?,
        joints_format: choice("joints_format", joints_format)?,
        match_by: choice("match_by", match_by)?,
        time_offset_s: time_offset,
        length_unit: length_unit.map(|u| choice("length_unit", u)).transpose()?,
        angle_unit: angle_unit.map(|u| choice("angle_unit", u)).transpose()?,
        joint_columns,
        name_column,
        robot_limits: robot.map(|r| ImportLimits::new(&r.inner, nominal_limits)),
        dwell: DwellSettings {
            still_deg: still_deg.unwrap_or(d.still_deg),
            min_s: dwell_min_s.unwrap_or(d.min_s),
        },
        time_tolerance_s: time_tolerance,
    };
    let imported = import_files(&points, &joints, &config).py_err()?;
    if let Some(out) = out {
        write_import(&out, &imported).py_err()?;
    }
    let csv = String::from_utf8(imported.csv)
        .map_err(|_| usage("the imported CSV is not UTF-8 (a point name in another encoding)"))?;
    Ok((csv, imported.report.lines()))
}
