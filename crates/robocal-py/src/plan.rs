//! `robocal.plan`: the poses worth measuring, through the library's `planning::plan` with the
//! settings checked by the library's `PlanBuilder`, as `robocal plan`'s flags are; the
//! poses as the CLI writes them (`written`), so a plan made in Python is the CLI's file.

use crate::args::{count, frame, range_mm as range_arg};
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::written::{csv_bytes, read_back, Written};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::io::write_all_atomic;
use robocal_core::planning::{plan, Criterion, Plan, PlanBuilder, PlanSettings};
use robocal_core::simulation::{DEFAULT_NOISE_MM, DEFAULT_NOISE_PER_M};
use std::path::PathBuf;

/// How well a set of poses identifies the parameters (`planning::Quality`), in interface units.
#[pyclass(name = "PlanQuality", module = "robocal", frozen, get_all)]
pub struct PyQuality {
    /// Borm and Menq's observability index O1 of the scaled identification Jacobian (0 when
    /// it is singular).
    observability: f64,
    /// ln det(J^T J) of the scaled Jacobian (-inf when singular).
    log_det: f64,
    /// Predicted standard deviation of each identified parameter at the plan's noise (mm or
    /// deg, in the order of `Plan.parameters`; NaN when singular).
    std: Vec<f64>,
    /// Predicted RMS model error over the workspace (the candidates) at that noise (mm).
    workspace_rms_mm: f64,
}

#[pymethods]
impl PyQuality {
    fn __repr__(&self) -> String {
        format!(
            "PlanQuality(observability={:.4}, log_det={:.4}, workspace_rms_mm={:.5})",
            self.observability, self.log_det, self.workspace_rms_mm
        )
    }
}

/// A pose plan: what `robocal plan` writes and prints.
#[pyclass(name = "Plan", module = "robocal", frozen)]
pub struct PyPlan {
    plan: Plan,
    rows: Written,
    /// The CSV text `robocal plan --out` writes.
    csv: Vec<u8>,
    dof: usize,
    units: Vec<&'static str>,
    planned: Py<PyQuality>,
    random: Py<PyQuality>,
    settings: PlanSettings,
}

fn quality(
    py: Python<'_>,
    q: &robocal_core::planning::Quality,
    p: &Plan,
) -> PyResult<Py<PyQuality>> {
    let std = p
        .identified
        .iter()
        .zip(&q.std)
        .map(|(param, s)| param.unit().from_internal(*s))
        .collect();
    Py::new(
        py,
        PyQuality {
            observability: q.observability,
            log_det: q.log_det,
            std,
            workspace_rms_mm: q.workspace_rms_mm,
        },
    )
}

/// Poses measured anyway: a joints or measurement CSV (read as the CLI reads `--include`), or
/// an array (m, dof) in interface units. Returns the poses (internal units) and the warnings.
fn include_arg(robot: &PyRobot, v: &Bound<'_, PyAny>) -> PyResult<(Vec<Vec<f64>>, Vec<String>)> {
    let path = v
        .py()
        .import("os")?
        .call_method1("fspath", (v,))
        .and_then(|p| p.extract::<PathBuf>());
    if let Ok(p) = path {
        let set = read_measurements(&p, robot.inner.joint_space(), Positions::Optional).py_err()?;
        return Ok((set.rows.into_iter().map(|r| r.q).collect(), set.warnings));
    }
    let m = robot.joints(v, "include")?;
    Ok(((0..m.rows).map(|i| m.row(i).to_vec()).collect(), Vec::new()))
}

/// Plans poses: see `robocal.plan` (python/robocal/__init__.py) for the arguments.
#[pyfunction]
#[pyo3(signature = (
    robot, poses = None, *, candidates = None, seed = None, criterion = "workspace",
    tracker = None, range_mm = None, include = None, floor_mm = 0.0, footprint_mm = None,
    noise_mm = DEFAULT_NOISE_MM, noise_per_m = DEFAULT_NOISE_PER_M
))]
#[allow(clippy::too_many_arguments)]
pub fn plan_poses(
    py: Python<'_>,
    robot: &PyRobot,
    poses: Option<&Bound<'_, PyAny>>,
    candidates: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    criterion: &str,
    tracker: Option<&Bound<'_, PyAny>>,
    range_mm: Option<&Bound<'_, PyAny>>,
    include: Option<&Bound<'_, PyAny>>,
    floor_mm: f64,
    footprint_mm: Option<f64>,
    noise_mm: f64,
    noise_per_m: f64,
) -> PyResult<(PyPlan, Vec<String>)> {
    let none = crate::args::given;
    let r = &robot.inner;
    // Parsing only (Python types to numbers); the library's `PlanBuilder` checks the settings,
    // as it does the CLI's flags.
    let counted = |v: Option<&Bound<'_, PyAny>>, name: &str| {
        none(v)
            .map(|v| count(v, name, 0, u64::MAX, "a 64-bit count"))
            .transpose()
    };
    let as_usize = |v: u64| usize::try_from(v).unwrap_or(usize::MAX);
    let criterion = match criterion.replace('_', "-").as_str() {
        "workspace" => Criterion::IOptimal,
        "d-optimal" => Criterion::DOptimal,
        other => {
            return Err(usage(format!(
                "criterion: `{other}` is not `workspace` (the mean model error over the \
                 workspace) or `d-optimal`"
            )))
        }
    };
    let d = PlanBuilder::default();
    let mut builder = PlanBuilder {
        poses: counted(poses, "poses")?.map_or(d.poses, as_usize),
        candidates: counted(candidates, "candidates")?.map_or(d.candidates, as_usize),
        seed: counted(seed, "seed")?.unwrap_or(d.seed),
        criterion,
        tracker_frame: none(tracker).map(|t| frame(t, "tracker")).transpose()?,
        tracker_range: none(range_mm)
            .map(|v| range_arg(v, "range_mm"))
            .transpose()?,
        include: Vec::new(),
        floor_z_mm: floor_mm,
        footprint_radius_mm: footprint_mm,
        noise_mm,
        noise_per_m,
    };
    // The settings are checked before the included poses are read, as by the CLI.
    builder.clone().build(r).py_err()?;
    let warnings = match none(include) {
        Some(v) => {
            let (poses, warnings) = include_arg(robot, v)?;
            builder.include = poses;
            warnings
        }
        None => Vec::new(),
    };
    let settings = builder.build(r).py_err()?;
    let p = py.detach(|| plan(r, &settings)).py_err()?;
    // The poses as `robocal plan --out` writes them.
    let set = MeasurementSet {
        path: PathBuf::from("plan"),
        joints: r.joint_space().clone(),
        extra_columns: Vec::new(),
        warnings: Vec::new(),
        rows: p
            .poses
            .iter()
            .enumerate()
            .map(|(i, q)| Measurement {
                line: i + 2,
                q: q.clone(),
                p: None,
                extra: Vec::new(),
            })
            .collect(),
    };
    let csv = csv_bytes(&set)?;
    let rows = read_back(&csv, r.dof(), false)?;
    let planned = quality(py, &p.planned, &p)?;
    let random = quality(py, &p.random, &p)?;
    let units = p.identified.iter().map(|q| q.unit().as_str()).collect();
    Ok((
        PyPlan {
            dof: r.dof(),
            plan: p,
            rows,
            csv,
            units,
            planned,
            random,
            settings,
        },
        warnings,
    ))
}

#[pymethods]
impl PyPlan {
    /// The chosen poses (n, dof) in degrees (mm for a prismatic joint), in the order chosen, as
    /// `robocal plan --out` writes them (to 1e-9): a joints array for `simulate(joints=...)` or
    /// for measuring. The included poses are not among them.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::arrays::out2(py, self.rows.q.clone(), self.rows.rows, self.dof, false)
    }

    /// The parameters the candidates identify (the design's columns): names in model order.
    #[getter]
    fn parameters(&self) -> Vec<String> {
        self.plan.identified.iter().map(|p| p.name()).collect()
    }

    /// The unit of each of `parameters` ("mm" or "deg").
    #[getter]
    fn units(&self) -> Vec<&'static str> {
        self.units.clone()
    }

    /// The quality of the planned poses (with the included ones).
    #[getter]
    fn planned(&self, py: Python<'_>) -> Py<PyQuality> {
        self.planned.clone_ref(py)
    }

    /// The quality of as many random poses under the same rules (with the included ones): the
    /// comparison `robocal plan` prints.
    #[getter]
    fn random(&self, py: Python<'_>) -> Py<PyQuality> {
        self.random.clone_ref(py)
    }

    /// Predicted standard deviations {name: (planned, random)} in each parameter's unit.
    #[getter]
    fn stds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        let (a, b) = (self.planned.get(), self.random.get());
        for (i, p) in self.plan.identified.iter().enumerate() {
            d.set_item(p.name(), (a.std[i], b.std[i]))?;
        }
        Ok(d)
    }

    /// "workspace" (I-optimal) or "d-optimal".
    #[getter]
    fn criterion(&self) -> &'static str {
        match self.settings.criterion {
            Criterion::IOptimal => "workspace",
            Criterion::DOptimal => "d-optimal",
        }
    }

    /// The criterion after the greedy selection and after the exchange passes (ln det M, or
    /// tr(W M^-1)).
    #[getter]
    fn criterion_values(&self) -> (f64, f64) {
        (self.plan.greedy_value, self.plan.final_value)
    }

    /// Exchange passes run and poses they replaced.
    #[getter]
    fn exchanges(&self) -> (usize, usize) {
        (self.plan.exchange_passes, self.plan.exchanges)
    }

    /// Number of included poses (`include`).
    #[getter]
    fn included(&self) -> usize {
        self.settings.include.len()
    }

    /// The number of random candidates the poses were chosen from.
    #[getter]
    fn candidates(&self) -> usize {
        self.settings.candidates
    }

    /// The seed of the candidates.
    #[getter]
    fn seed(&self) -> u64 {
        self.settings.seed
    }

    /// The per-axis noise the standard deviations are predicted at: (noise_mm, noise_per_m).
    #[getter]
    fn noise(&self) -> (f64, f64) {
        (self.settings.noise_mm, self.settings.noise_per_m)
    }

    /// The poses as `robocal plan --out` writes them (CSV text).
    fn to_csv(&self) -> PyResult<String> {
        String::from_utf8(self.csv.clone()).map_err(|e| raise(1, format!("internal: {e}")))
    }

    /// Writes the poses to `path` as `robocal plan --out` does (atomically).
    fn write(&self, path: PathBuf) -> PyResult<()> {
        write_all_atomic(&[(path.as_path(), self.csv.as_slice())]).py_err()
    }

    fn __len__(&self) -> usize {
        self.rows.rows
    }

    fn __repr__(&self) -> String {
        let (a, b) = (self.planned.get(), self.random.get());
        format!(
            "Plan({} poses from {} candidates (seed {}), {}; {} identifiable parameters; \
             observability {:.4} (random {:.4}), workspace RMS {:.5} mm (random {:.5}))",
            self.rows.rows,
            self.settings.candidates,
            self.settings.seed,
            self.criterion(),
            self.plan.identified.len(),
            a.observability,
            b.observability,
            a.workspace_rms_mm,
            b.workspace_rms_mm
        )
    }
}
