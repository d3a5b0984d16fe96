//! `robocal.compensate`: compensated joint commands (paper, eq. 12-14) for desired poses,
//! through the library's `Compensator` as `robocal compensate --joints` uses it, with its
//! refusals (a partial result; an implausible one unless accepted).

use crate::arrays::out2;
use crate::errors::{raise, usage, IntoPy};
use crate::robot::{per_pose, PyRobot};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::compensation::PoseNewton;
use robocal_core::io::CalibrationResult;
use robocal_core::{Compensator, DampedLeastSquares};
use std::path::Path;

/// The iteration limit's range (the CLI's `--max-iterations` of `compensate`).
const MAX_IK_ITERATIONS: usize = 100_000;

/// Compensates desired joint vectors `q` (n, dof; degrees) with result JSON `text`: a dict of
/// `commanded` (n, dof; degrees), `desired_position` (n, 3; mm, base frame: the nominal model's
/// tool at `q`, eq. 13), `status` (list of "converged", "joint_limit", "unreachable",
/// "not_converged"), `residual_mm` (n,) and `iterations` (n,); and the warnings.
#[pyfunction]
#[pyo3(signature = (text, q, nominal = None, tolerance_mm = 1e-6, max_iterations = 500, payload_kg = None, accept_implausible = false, position_only = false, tolerance_deg = 1e-6))]
#[allow(clippy::too_many_arguments)]
pub fn compensate_arrays<'py>(
    py: Python<'py>,
    text: &str,
    q: &Bound<'py, PyAny>,
    nominal: Option<&PyRobot>,
    tolerance_mm: f64,
    max_iterations: usize,
    payload_kg: Option<f64>,
    accept_implausible: bool,
    position_only: bool,
    tolerance_deg: f64,
) -> PyResult<(Bound<'py, PyDict>, Vec<String>)> {
    if !(1..=MAX_IK_ITERATIONS).contains(&max_iterations) {
        return Err(usage(format!(
            "max_iterations: {max_iterations} is not in 1..{MAX_IK_ITERATIONS} (per pose; a \
             solve converges in a handful)"
        )));
    }
    let solver = DampedLeastSquares {
        tolerance_mm,
        max_iterations,
        ..DampedLeastSquares::default()
    };
    solver
        .validate()
        .map_err(|e| usage(crate::errors::message(&e)))?;
    let pose_solver = PoseNewton {
        tolerance_mm,
        tolerance_deg,
        max_iterations,
        ..PoseNewton::default()
    };
    pose_solver
        .validate()
        .map_err(|e| usage(crate::errors::message(&e)))?;
    let res = CalibrationResult::parse(text, Path::new("<result json>")).py_err()?;
    let (nom, mut cal) = crate::result::result_robots(text, nominal)?;
    if let Some(m) = payload_kg {
        robocal_core::model::family::compliance::set_payload_kg(&mut cal.inner, m)
            .map_err(|e| usage(crate::errors::message(&e)))?;
    }
    let mut warnings = Vec::new();
    if let Some(why) = res.partial_reason() {
        return Err(raise(
            3,
            format!(
                "a partial result, not a calibration ({why}); compensation refuses it: calibrate \
                 again with a higher max_iterations"
            ),
        ));
    }
    if let Some(why) = res.implausible_reason() {
        if !accept_implausible {
            return Err(raise(
                6,
                format!(
                    "an IMPLAUSIBLE result, not a calibration: it failed the plausibility \
                     gate:\n{why}\ncompensation refuses it (fix the data or the robot and \
                     calibrate again, or pass accept_implausible=True to use it anyway)"
                ),
            ));
        }
        warnings.push(format!(
            "accept_implausible=True: compensating with a result that FAILED the plausibility \
             gate; the commanded joints may be far from right:\n{why}"
        ));
    }
    let m = nom.joints(q, "q")?;
    let outside: Vec<usize> = (0..m.rows)
        .filter(|&i| !nom.inner.joints_outside_limits(m.row(i)).is_empty())
        .collect();
    if !outside.is_empty() {
        warnings.push(format!(
            "{} desired pose(s) outside the robot's joint limits (rows {}{})",
            outside.len(),
            outside
                .iter()
                .take(10)
                .map(|i| i.to_string())
                .collect::<Vec<_>>()
                .join(", "),
            if outside.len() > 10 { ", ..." } else { "" }
        ));
    }
    let mut comp = Compensator::new(&nom.inner, &cal.inner, solver).py_err()?;
    comp.pose_solver = pose_solver;
    let dof = nom.inner.dof();
    // Per pose: commanded joints, desired position, status, residual (mm), iterations,
    // residual (deg).
    let width = dof + 3 + 4;
    let js = nom.inner.joint_space();
    let out = py.detach(|| {
        per_pose(&m, width, |q, o| {
            let (p, rep) = if position_only {
                comp.compensate(q, &mut o[..dof])
            } else {
                let (f, rep) = comp.compensate_pose(q, &mut o[..dof]);
                (f.translation.vector, rep)
            };
            for j in 0..dof {
                o[j] = js.to_display(j, o[j]);
            }
            o[dof..dof + 3].copy_from_slice(p.as_slice());
            let status = robocal_core::IkStatus::ALL
                .iter()
                .position(|s| *s == rep.status)
                .unwrap_or(0);
            o[dof + 3] = status as f64;
            o[dof + 4] = rep.residual_mm;
            o[dof + 5] = rep.iterations as f64;
            o[dof + 6] = rep.residual_deg;
        })
    });
    let col = |k: usize| -> Vec<f64> { out.chunks(width).map(|o| o[k]).collect() };
    let commanded: Vec<f64> = out.chunks(width).flat_map(|o| o[..dof].to_vec()).collect();
    let desired: Vec<f64> = out
        .chunks(width)
        .flat_map(|o| o[dof..dof + 3].to_vec())
        .collect();
    let d = PyDict::new(py);
    d.set_item("commanded", out2(py, commanded, m.rows, dof, m.single)?)?;
    d.set_item("desired_position", out2(py, desired, m.rows, 3, m.single)?)?;
    let status: Vec<&str> = col(dof + 3)
        .iter()
        .map(|s| robocal_core::IkStatus::ALL[*s as usize].as_str())
        .collect();
    d.set_item("status", status)?;
    d.set_item("residual_mm", PyArray1::from_vec(py, col(dof + 4)))?;
    let iterations: Vec<i64> = col(dof + 5).iter().map(|v| *v as i64).collect();
    d.set_item("iterations", PyArray1::from_vec(py, iterations))?;
    d.set_item("residual_deg", PyArray1::from_vec(py, col(dof + 6)))?;
    Ok((d, warnings))
}
