//! `robocal.Simulation`: what `robocal.simulate` returns, a simulated session's rows as the CLI
//! writes them (`written`), the truth behind them and what was injected; `write` writes the
//! CLI's very files (as `src/cmd/simulate.rs` writes them).

use crate::args;
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::written::Written;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::io::measurements::measurements_csv;
use robocal_core::io::write_all_atomic;
use robocal_core::simulation::{Simulation, SET_CALIBRATION, SET_PLANE, SET_VALIDATION};
use std::path::{Path, PathBuf};

/// A simulated measurement session: the rows of the CSV `robocal simulate --out` writes (the
/// values as written: joint values to 1e-9 degree, readings to 1e-6 mm), the truth behind them
/// and what was injected.
#[pyclass(name = "Simulation", module = "robocal", frozen)]
pub struct PySimulation {
    /// The library's session.
    pub sim: Simulation,
    /// Its rows as written.
    pub rows: Written,
    /// Joints of the robot.
    pub dof: usize,
}

impl PySimulation {
    /// The rows of `set` as (q, xyz); none for a session without sets (measured joints).
    fn rows_of<'py>(
        &self,
        py: Python<'py>,
        set: &str,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let xyz = self.rows.xyz.as_deref().unwrap_or(&[]);
        let dof = self.dof;
        let keep: Vec<usize> = match self.rows.column("set") {
            Some(col) => (0..self.rows.rows).filter(|&i| col[i] == set).collect(),
            None => Vec::new(),
        };
        let q: Vec<f64> = keep
            .iter()
            .flat_map(|&i| self.rows.q[i * dof..(i + 1) * dof].iter().copied())
            .collect();
        let p: Vec<f64> = keep
            .iter()
            .flat_map(|&i| xyz[i * 3..i * 3 + 3].iter().copied())
            .collect();
        Ok((
            crate::arrays::out2(py, q, keep.len(), dof, false)?,
            crate::arrays::out2(py, p, keep.len(), 3, false)?,
        ))
    }
}

#[pymethods]
impl PySimulation {
    /// Joint values of every row (n, dof): degrees (mm for a prismatic joint), as written.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::arrays::out2(py, self.rows.q.clone(), self.rows.rows, self.dof, false)
    }

    /// The tracker's readings of every row (n, 3): mm in the tracker frame, as written.
    #[getter]
    fn xyz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let xyz = self.rows.xyz.clone().unwrap_or_default();
        crate::arrays::out2(py, xyz, self.rows.rows, 3, false)
    }

    /// The readings without noise or outliers (n, 3; mm, tracker frame), full precision.
    #[getter]
    fn exact<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let data: Vec<f64> = self
            .sim
            .exact
            .iter()
            .flat_map(|p| [p.x, p.y, p.z])
            .collect();
        crate::arrays::out2(py, data, self.sim.exact.len(), 3, false)
    }

    /// Each row's set: "plane", "calibration" or "validation" (None for measured joints).
    #[getter]
    fn sets(&self) -> Option<Vec<String>> {
        self.rows.column("set").map(<[String]>::to_vec)
    }

    /// Each row's id: "P1.." (plane), "C1.." (calibration), "V1.." (validation); None for
    /// measured joints.
    #[getter]
    fn ids(&self) -> Option<Vec<String>> {
        self.rows.column("id").map(<[String]>::to_vec)
    }

    /// Each row's target (reflector), 1-based, with `all_targets`; else None.
    #[getter]
    fn target<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray1<i64>>>> {
        let Some(col) = self.rows.column("target") else {
            return Ok(None);
        };
        let t: Vec<i64> = col
            .iter()
            .map(|s| {
                s.parse::<i64>()
                    .map_err(|_| raise(1, "internal: target column"))
            })
            .collect::<PyResult<_>>()?;
        Ok(Some(PyArray1::from_vec(py, t)))
    }

    /// The measured orientation of every row (n, 3): A, B, C in degrees in the tracker frame,
    /// with `orientation_sigma_deg`; else None.
    #[getter]
    fn abc<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        let (Some(a), Some(b), Some(c)) = (
            self.rows.numbers("a")?,
            self.rows.numbers("b")?,
            self.rows.numbers("c")?,
        ) else {
            return Ok(None);
        };
        let n = a.len();
        let data: Vec<f64> = (0..n).flat_map(|i| [a[i], b[i], c[i]]).collect();
        Ok(Some(crate::arrays::out2(py, data, n, 3, false)?))
    }

    /// The further columns of the written CSV by name (`id`, `set`, `target`, `a`, `b`, `c`,
    /// a joints file's own columns), as strings.
    #[getter]
    fn columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (name, col) in &self.rows.extra {
            d.set_item(name, col.clone())?;
        }
        Ok(d)
    }

    /// The calibration rows (set "calibration") as (q, xyz).
    #[getter]
    fn calibration<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.rows_of(py, SET_CALIBRATION)
    }

    /// The validation rows (set "validation") as (q, xyz): empty without `validation`.
    #[getter]
    fn validation<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.rows_of(py, SET_VALIDATION)
    }

    /// The paper's three plane points (set "plane") as (q, xyz): empty with `plane=False`.
    #[getter]
    fn plane<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.rows_of(py, SET_PLANE)
    }

    /// Height of the plane points' plane (mm, base frame), or None.
    #[getter]
    fn plane_z_mm(&self) -> Option<f64> {
        self.sim.plane_z_mm
    }

    /// The robot that really moved (the truth) as a Robot.
    #[getter]
    fn truth(&self) -> PyRobot {
        PyRobot::new(self.sim.cell.truth().clone(), None)
    }

    /// The nominal robot (what the controller believes).
    #[getter]
    fn nominal(&self) -> PyRobot {
        PyRobot::new(self.sim.cell.nominal().clone(), None)
    }

    /// The tracker frame's pose in the base frame: {x, y, z (mm), a, b, c (deg)}, the
    /// `tracker_frame` a calibration should find.
    #[getter]
    fn tracker_frame<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        args::frame_dict(py, &self.sim.config().tracker_frame)
    }

    /// The seed of the session.
    #[getter]
    fn seed(&self) -> u64 {
        self.sim.config().seed
    }

    /// Rows (0-based) given a gross outlier, sorted.
    #[getter]
    fn outlier_rows<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let r: Vec<i64> = self.sim.outliers.iter().map(|(i, _)| *i as i64).collect();
        PyArray1::from_vec(py, r)
    }

    /// The outliers' displacements (k, 3; mm, tracker frame), in the order of `outlier_rows`.
    #[getter]
    fn outlier_displacements<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d: Vec<f64> = self.sim.outliers.iter().flat_map(|(_, d)| *d).collect();
        crate::arrays::out2(py, d, self.sim.outliers.len(), 3, false)
    }

    /// How far gravity moved each row's tool point (n,; mm), with `compliance`; else None.
    #[getter]
    fn deflection_mm<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.sim
            .deflection_mm
            .as_ref()
            .map(|d| PyArray1::from_vec(py, d.clone()))
    }

    /// What the CLI prints as warnings (joint values outside the limits, ...).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.sim.warnings.clone()
    }

    /// The measurement CSV of every row, as `robocal simulate --out` writes it.
    fn to_csv(&self) -> PyResult<String> {
        let csv = crate::written::csv_bytes(&self.sim.measurements)?;
        String::from_utf8(csv).map_err(|e| raise(1, format!("internal: {e}")))
    }

    /// Writes the CLI's files: the measurement CSV `path`, the truth file beside it
    /// (`PATH.truth.json`, with the extension replaced) and, with `validation_path`, the
    /// validation rows to that CSV instead of `path` (`--validation-out`); all or nothing.
    /// Returns the truth file's path.
    #[pyo3(signature = (path, validation_path = None))]
    fn write(&self, path: PathBuf, validation_path: Option<PathBuf>) -> PyResult<PathBuf> {
        let sim = &self.sim;
        if validation_path.is_some() && sim.config().validation_poses == 0 {
            return Err(usage(
                "validation_path: the session has no validation rows (validation=0)",
            ));
        }
        let truth_out = path.with_extension("truth.json");
        for p in std::iter::once(&path).chain(validation_path.as_ref()) {
            if *p == truth_out {
                return Err(usage(format!(
                    "{}: the truth file is written beside the data as {}; give the data \
                     another extension",
                    p.display(),
                    truth_out.display()
                )));
            }
        }
        if validation_path.as_ref() == Some(&path) {
            return Err(usage("validation_path: the same file as path"));
        }
        // As `robocal simulate` writes them (src/cmd/simulate.rs).
        let split = validation_path.as_ref().map(|_| {
            (
                sim.select(SET_VALIDATION, false),
                sim.select(SET_VALIDATION, true),
            )
        });
        let m = &sim.measurements;
        let (main, val) = match &split {
            Some((a, v)) => (a, Some(v)),
            None => (m, None),
        };
        let set_col = m.extra_columns.iter().position(|c| c == "set");
        let files: Vec<&Path> = m
            .rows
            .iter()
            .map(|r| {
                let is_val = set_col.is_some_and(|k| r.extra[k] == SET_VALIDATION);
                match (&validation_path, is_val) {
                    (Some(v), true) => v.as_path(),
                    _ => path.as_path(),
                }
            })
            .collect();
        let truth_file = sim.truth_file(&files);
        let io = |p: &Path, e: std::io::Error| {
            crate::errors::to_py(robocal_core::Error::Io {
                path: p.to_owned(),
                source: e,
            })
        };
        let main_csv = measurements_csv(main).map_err(|e| io(&path, e))?;
        let json = truth_file.to_json().py_err()?;
        let mut writes: Vec<(&Path, Vec<u8>)> = vec![(path.as_path(), main_csv)];
        if let (Some(p), Some(v)) = (&validation_path, val) {
            writes.push((p.as_path(), measurements_csv(v).map_err(|e| io(p, e))?));
        }
        writes.push((truth_out.as_path(), json.into_bytes()));
        let refs: Vec<(&Path, &[u8])> = writes.iter().map(|(p, b)| (*p, b.as_slice())).collect();
        write_all_atomic(&refs).py_err()?;
        Ok(truth_out)
    }

    fn __len__(&self) -> usize {
        self.rows.rows
    }

    fn __repr__(&self) -> String {
        let sets = match self.rows.column("set") {
            Some(col) => {
                let mut counts: Vec<(String, usize)> = Vec::new();
                for s in col {
                    match counts.iter_mut().find(|(n, _)| n == s) {
                        Some((_, k)) => *k += 1,
                        None => counts.push((s.clone(), 1)),
                    }
                }
                counts
                    .iter()
                    .map(|(s, k)| format!("{k} {s}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
            None => format!("{} measured", self.rows.rows),
        };
        format!(
            "Simulation({} rows: {sets}; truth `{}`, seed {})",
            self.rows.rows,
            self.sim.cell.truth().name(),
            self.sim.config().seed
        )
    }
}
