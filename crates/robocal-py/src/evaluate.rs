//! `robocal.evaluate`: the errors of measured points under a result's nominal and calibrated
//! models (validation, the paper's Table IV on new points), through the library's
//! `evaluate_framed` as `robocal evaluate --against model` calls it.

use crate::errors::{input, IntoPy};
use crate::robot::PyRobot;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::evaluation::{evaluate_framed, Against};
use robocal_core::io::joint_limits::OutsideLimits;
use robocal_core::io::{CalibrationResult, Measurement, MeasurementSet};
use std::path::{Path, PathBuf};

/// Evaluates `q` (n, dof) and `xyz` (n, 3) under result JSON `text`: a dict per series
/// (`nominal`, `calibrated`) of `errors` (n, 3: measured minus model, mm, base frame), `norms`
/// (n,) and `stats` (n, mean_mm, std_mm, max_mm, rms_mm, p95_mm).
#[pyfunction]
#[pyo3(signature = (text, q, xyz, nominal = None, nominal_limits = false))]
pub fn evaluate_arrays<'py>(
    py: Python<'py>,
    text: &str,
    q: &Bound<'py, PyAny>,
    xyz: &Bound<'py, PyAny>,
    nominal: Option<&PyRobot>,
    nominal_limits: bool,
) -> PyResult<(Bound<'py, PyDict>, Vec<String>)> {
    let (nom, cal) = crate::result::result_robots(text, nominal)?;
    let res = CalibrationResult::parse(text, Path::new("<result json>")).py_err()?;
    let qm = nom.joints(q, "q")?;
    let xm = crate::arrays::matrix(xyz, "xyz", 3, "x, y, z in mm in the tracker frame")?;
    if qm.rows != xm.rows {
        return Err(input(format!(
            "q has {} row(s), xyz has {}: one measured point per pose",
            qm.rows, xm.rows
        )));
    }
    let path = PathBuf::from("arrays");
    let mut outside = OutsideLimits::new(&nom.inner, &path);
    let rows: Vec<Measurement> = (0..qm.rows)
        .map(|i| {
            outside.check(i + 1, qm.row(i));
            let m = xm.row(i);
            Measurement {
                line: i + 1,
                q: qm.row(i).to_vec(),
                p: Some(nalgebra::Vector3::new(m[0], m[1], m[2])),
                extra: Vec::new(),
            }
        })
        .collect();
    let mut warnings = Vec::new();
    if nominal_limits {
        if let Some(w) = outside.to_warning() {
            warnings.push(format!("{w} (used anyway: nominal_limits=True)"));
        }
    } else if let Some(e) = outside.to_error() {
        return Err(input(format!(
            "{}; if the robot's limits are only nominal, pass nominal_limits=True to use these \
             rows",
            crate::errors::message(&e)
        )));
    }
    let data = MeasurementSet {
        path,
        joints: nom.inner.joint_space().clone(),
        extra_columns: Vec::new(),
        rows,
        warnings: Vec::new(),
    };
    // A constraint calibration up to the base pose has no tracker frame: the points are
    // registered to it under each model, as the CLI's evaluate does.
    let section = robocal_core::io::result_constraint::ConstraintSection::of(
        &res,
        Path::new("<result json>"),
    )
    .py_err()?;
    let frames = if section.is_some_and(|s| !s.base_pose_known) {
        warnings.push(
            "the result is a constraint calibration, up to the base pose: the tracker frame is \
             registered to these points under each model (as the CLI's evaluate does), so the \
             errors are those after the best rigid alignment"
                .into(),
        );
        let (n, c) =
            robocal_core::evaluation::station_frames(&nom.inner, &cal.inner, &data).py_err()?;
        [n, c]
    } else {
        [res.nominal_frame(), res.tracker_frame()]
    };
    let ev = py
        .detach(|| {
            evaluate_framed(
                &nom.inner,
                &cal.inner,
                [&frames[0], &frames[1]],
                &data,
                Against::Model,
            )
        })
        .py_err()?;
    let out = PyDict::new(py);
    for s in &ev.series {
        let d = PyDict::new(py);
        let n = s.errors.len();
        let flat: Vec<f64> = s.errors.iter().flat_map(|e| [e.x, e.y, e.z]).collect();
        let errors = Array2::from_shape_vec((n, 3), flat)
            .expect("n x 3 values")
            .into_pyarray(py);
        let norms: Vec<f64> = s.errors.iter().map(|e| e.norm()).collect();
        d.set_item("errors", errors)?;
        d.set_item("norms", PyArray1::from_vec(py, norms))?;
        let st = PyDict::new(py);
        st.set_item("n", s.stats.n)?;
        st.set_item("mean_mm", s.stats.mean_mm)?;
        st.set_item("std_mm", s.stats.std_mm)?;
        st.set_item("max_mm", s.stats.max_mm)?;
        st.set_item("rms_mm", s.stats.rms_mm)?;
        st.set_item("p95_mm", s.stats.p95_mm)?;
        d.set_item("stats", st)?;
        out.set_item(s.name, d)?;
    }
    Ok((out, warnings))
}
