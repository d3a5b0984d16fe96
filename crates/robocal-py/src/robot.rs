//! `robocal.Robot`: a nominal or calibrated model, with forward kinematics and Jacobians of
//! many poses at once from numpy arrays.
//!
//! Joint values and parameters are in the interface units of DESIGN.md: degrees (mm for a
//! prismatic joint) and millimetres. Work over many poses releases the GIL and runs on rayon's
//! threads.

use crate::arrays::{matrix, out2, out3, Matrix};
use crate::errors::{input, usage, IntoPy};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use robocal_core::{load_robot, load_robot_file, parse_robot_toml, preset, Robot, PRESETS};
use std::path::Path;

/// Poses below this count are computed on the calling thread (a thread pool costs more).
const PARALLEL_MIN_POSES: usize = 2048;

/// A robot model: the parameter table, base, tool, joint types and limits.
#[pyclass(name = "Robot", module = "robocal")]
#[derive(Clone)]
pub struct PyRobot {
    /// The model.
    pub inner: Robot,
    /// Where it came from (a preset name or a file), as the result's `settings.robot_arg`.
    pub source: Option<String>,
}

impl PyRobot {
    /// A wrapped robot.
    pub fn new(inner: Robot, source: Option<String>) -> PyRobot {
        PyRobot { inner, source }
    }

    /// `q` (n, dof) in interface units as a checked matrix in internal units (rad or mm).
    pub fn joints(&self, q: &Bound<'_, PyAny>, name: &str) -> PyResult<Matrix> {
        let dof = self.inner.dof();
        let mut m = matrix(q, name, dof, &self.joint_words())?;
        let js = self.inner.joint_space();
        // The plausible range of a joint value, as the CLI's `--joints` and files check it.
        let ranges: Vec<&robocal_core::ranges::Range> = (0..dof)
            .map(|j| match js.joint_type(j) {
                robocal_core::JointType::Prismatic => &robocal_core::ranges::LENGTH,
                _ => &robocal_core::ranges::JOINT,
            })
            .collect();
        for (i, row) in m.data.chunks_mut(dof).enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                if let Err(msg) = ranges[j].check(*v) {
                    return Err(input(format!("{name}: row {i}, column {j}: {msg}")));
                }
                *v = js.to_internal(j, *v);
            }
        }
        Ok(m)
    }

    /// "joint values q1..q6 in degrees", for messages.
    fn joint_words(&self) -> String {
        let prismatic = self.inner.joint_space().any_prismatic();
        format!(
            "joint values q1..q{} in degrees{}",
            self.inner.dof(),
            if prismatic {
                " (mm for a prismatic joint)"
            } else {
                ""
            }
        )
    }

    fn check_target(&self, target: usize) -> PyResult<()> {
        let n = self.inner.target_count();
        if target >= n {
            return Err(usage(format!(
                "target: robot `{}` has {n} target(s), numbered from 0; got {target}",
                self.inner.name()
            )));
        }
        Ok(())
    }
}

/// Runs `f(row, out)` for every pose, `width` outputs each, in parallel for many poses.
pub fn per_pose(
    q: &Matrix,
    width: usize,
    f: impl Fn(&[f64], &mut [f64]) + Sync + Send,
) -> Vec<f64> {
    let mut out = vec![0.0; q.rows * width];
    if q.rows >= PARALLEL_MIN_POSES {
        // Chunks of 256 poses: enough work per task, enough tasks to balance.
        out.par_chunks_mut(256 * width)
            .enumerate()
            .for_each(|(c, chunk)| {
                for (k, o) in chunk.chunks_mut(width).enumerate() {
                    f(q.row(c * 256 + k), o);
                }
            });
    } else {
        for (i, o) in out.chunks_mut(width).enumerate() {
            f(q.row(i), o);
        }
    }
    out
}

#[pymethods]
impl PyRobot {
    /// A built-in preset (`robocal.Robot.presets()` lists them), e.g. "kuka-kr480-r3330".
    #[staticmethod]
    fn preset(name: &str) -> PyResult<PyRobot> {
        Ok(PyRobot::new(preset(name).py_err()?, Some(name.to_owned())))
    }

    /// The names of the built-in presets.
    #[staticmethod]
    fn presets() -> Vec<&'static str> {
        PRESETS.to_vec()
    }

    /// A TOML robot description (README, "Robot files"), e.g. "examples/ur5.toml".
    #[staticmethod]
    fn from_file(path: std::path::PathBuf) -> PyResult<PyRobot> {
        let r = load_robot_file(&path).py_err()?;
        Ok(PyRobot::new(r, Some(path.display().to_string())))
    }

    /// A preset name or a robot file, as the CLI's `--robot NAME|FILE`.
    #[staticmethod]
    fn load(arg: &str) -> PyResult<PyRobot> {
        Ok(PyRobot::new(
            load_robot(arg).py_err()?,
            Some(arg.to_owned()),
        ))
    }

    /// A robot from the text of a TOML robot description; `name` names it in messages.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<robot toml>"))]
    fn from_toml(text: &str, name: &str) -> PyResult<PyRobot> {
        let r = parse_robot_toml(text, Path::new(name)).py_err()?;
        Ok(PyRobot::new(r, None))
    }

    /// The robot's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.name().to_owned()
    }

    /// Number of joints.
    #[getter]
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    /// "mdh" (modified DH, Craig) or "dh" (standard DH).
    #[getter]
    fn convention(&self) -> &'static str {
        self.inner.convention().as_str()
    }

    /// Each joint's type: "revolute" or "prismatic".
    #[getter]
    fn joint_types(&self) -> Vec<&'static str> {
        self.inner
            .joint_types()
            .iter()
            .map(|t| t.as_str())
            .collect()
    }

    /// The number of targets (reflectors): the tool and the robot file's further `tools`.
    #[getter]
    fn target_count(&self) -> usize {
        self.inner.target_count()
    }

    /// The joint limits, (dof, 2): min and max in degrees (mm for a prismatic joint).
    #[getter]
    fn limits<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let js = self.inner.joint_space();
        let mut data = Vec::new();
        for (j, l) in self.inner.limits().iter().enumerate() {
            data.push(js.to_display(j, l.min));
            data.push(js.to_display(j, l.max));
        }
        out2(py, data, self.inner.dof(), 2, false)
    }

    /// The model's parameter names in model order (`alpha1..`, `d1..`, ..., `tool_c`, and the
    /// families enabled: `beta{j}`, compliances, harmonics): the columns of `jacobian`.
    #[getter]
    fn parameter_names(&self) -> Vec<String> {
        self.inner.params().iter().map(|p| p.name()).collect()
    }

    /// Every parameter's value: {name: value} in mm or degrees (see `units`).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in self.inner.params() {
            d.set_item(p.name(), self.inner.get_display(p))?;
        }
        Ok(d)
    }

    /// Every parameter's unit: {name: "mm" | "deg" | ...}.
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in self.inner.params() {
            d.set_item(p.name(), p.unit().as_str())?;
        }
        Ok(d)
    }

    /// One parameter's value (mm or degrees).
    fn get(&self, name: &str) -> PyResult<f64> {
        let p = self.inner.param_by_name(name).py_err()?;
        Ok(self.inner.get_display(p))
    }

    /// Sets one parameter (mm or degrees; a finite number).
    fn set(&mut self, name: &str, value: f64) -> PyResult<()> {
        let p = self.inner.param_by_name(name).py_err()?;
        if !value.is_finite() {
            return Err(input(format!("{name}: {value} is not a finite number")));
        }
        self.inner.set_display(p, value);
        Ok(())
    }

    /// A copy that can be changed without changing this one.
    fn copy(&self) -> PyRobot {
        self.clone()
    }

    /// Tool positions (mm, base frame) at joint values `q`: (n, dof) in degrees (mm for a
    /// prismatic joint) -> (n, 3); a single pose (dof,) -> (3,). `target` picks a reflector of
    /// a robot with several `tools` (0: the tool).
    #[pyo3(signature = (q, target = 0))]
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        target: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.check_target(target)?;
        let m = self.joints(q, "q")?;
        let r = &self.inner;
        let out = py.detach(|| {
            per_pose(&m, 3, |q, o| {
                let p = if target == 0 {
                    r.tool_position(q)
                } else {
                    r.target_position(q, target)
                };
                o.copy_from_slice(p.as_slice());
            })
        });
        out2(py, out, m.rows, 3, m.single)
    }

    /// Tool frames as homogeneous matrices (rotation, and translation in mm) at joint values
    /// `q`: (n, dof) -> (n, 4, 4); (dof,) -> (4, 4).
    #[pyo3(signature = (q, target = 0))]
    fn fk_pose<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        target: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.check_target(target)?;
        let m = self.joints(q, "q")?;
        let r = &self.inner;
        let out = py.detach(|| {
            per_pose(&m, 16, |q, o| {
                let f = if target == 0 {
                    r.tool_pose(q)
                } else {
                    r.target_pose(q, target)
                };
                let h = f.to_homogeneous();
                for i in 0..4 {
                    for j in 0..4 {
                        o[4 * i + j] = h[(i, j)];
                    }
                }
            })
        });
        out3(py, out, (m.rows, 4, 4), m.single)
    }

    /// The identification Jacobian: d(tool position)/d(parameter) at joint values `q`,
    /// (n, dof) -> (n, 3, p) with p = len(parameter_names), in mm per unit of each parameter
    /// (mm/mm, or mm/deg for an angle); (dof,) -> (3, p). Analytic, as the calibration uses it.
    #[pyo3(signature = (q, target = 0))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        target: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.check_target(target)?;
        let m = self.joints(q, "q")?;
        let r = &self.inner;
        let params = r.params();
        let np = params.len();
        let scale: Vec<f64> = params.iter().map(|p| p.unit().to_internal(1.0)).collect();
        let out = py.detach(|| {
            per_pose(&m, 3 * np, |q, o| {
                let mut jp = vec![nalgebra::Vector3::zeros(); np];
                r.target_screws(q, target, None, Some(&mut jp), None);
                for (k, c) in jp.iter().enumerate() {
                    for i in 0..3 {
                        o[i * np + k] = c[i] * scale[k];
                    }
                }
            })
        });
        out3(py, out, (m.rows, 3, np), m.single)
    }

    /// The joint Jacobian: d(tool position)/d(joint value) at joint values `q`, (n, dof) ->
    /// (n, 3, dof) in mm/deg (mm/mm for a prismatic joint); (dof,) -> (3, dof).
    #[pyo3(signature = (q, target = 0))]
    fn joint_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        target: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.check_target(target)?;
        let m = self.joints(q, "q")?;
        let r = &self.inner;
        let n = r.dof();
        let scale: Vec<f64> = (0..n).map(|j| r.joint_unit(j).to_internal(1.0)).collect();
        let out = py.detach(|| {
            per_pose(&m, 3 * n, |q, o| {
                let mut jq = vec![nalgebra::Vector3::zeros(); n];
                r.target_screws(q, target, Some(&mut jq), None, None);
                for (j, c) in jq.iter().enumerate() {
                    for i in 0..3 {
                        o[i * n + j] = c[i] * scale[j];
                    }
                }
            })
        });
        out3(py, out, (m.rows, 3, n), m.single)
    }

    /// For each pose of `q` (n, dof), whether every joint is within the robot's limits.
    fn within_limits<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = self.joints(q, "q")?;
        let ok: Vec<bool> = (0..m.rows)
            .map(|i| self.inner.joints_outside_limits(m.row(i)).is_empty())
            .collect();
        let a = numpy::PyArray1::from_vec(py, ok);
        if m.single {
            Ok(a.get_item(0)?)
        } else {
            Ok(a.into_any())
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot({:?}, {} joints, {}, {} parameters)",
            self.inner.name(),
            self.inner.dof(),
            self.inner.convention().as_str(),
            self.inner.param_count()
        )
    }
}
