//! `robocal.plan`: the poses worth measuring, through the library's `planning::plan` with the
//! settings `robocal plan` builds from its flags (src/cmd/plan.rs), checked the same way; the
//! poses as the CLI writes them (`written`), so a plan made in Python is the CLI's file.

use crate::args::{count, frame, magnitude, range_mm as range_arg};
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::written::{csv_bytes, read_back, Written};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::io::write_all_atomic;
use robocal_core::planning::{
    plan, tracker_range, Criterion, Plan, PlanSettings, DEFAULT_CANDIDATES,
};
use robocal_core::simulation::{SimulationConfig, DEFAULT_NOISE_MM, DEFAULT_NOISE_PER_M};
use robocal_core::TrackerFrame;
use std::path::PathBuf;

/// Most candidates (and poses), as the CLI: 200,000 take about 150 MB for a six-joint robot.
const MAX_CANDIDATES: u64 = 200_000;

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
    // As the CLI's `Settings` (src/cmd/plan.rs), in its order.
    let poses = match none(poses) {
        Some(v) => count(
            v,
            "poses",
            1,
            MAX_CANDIDATES,
            "no calibration measures more",
        )?,
        None => 75,
    };
    let candidates = match none(candidates) {
        Some(v) => count(
            v,
            "candidates",
            poses,
            MAX_CANDIDATES,
            "memory and time grow with the candidates",
        )?,
        None => DEFAULT_CANDIDATES as u64,
    };
    let seed = match none(seed) {
        Some(v) => count(v, "seed", 0, u64::MAX, "a 64-bit seed")?,
        None => 1,
    };
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
    magnitude("floor_mm", floor_mm)?;
    if let Some(f) = footprint_mm {
        magnitude("footprint_mm", f)?;
    }
    if !(noise_mm > 0.0 && noise_mm <= 1000.0) {
        return Err(usage(format!(
            "noise_mm {noise_mm}: must be a positive length up to 1000 mm"
        )));
    }
    if !(0.0..=1000.0).contains(&noise_per_m) {
        return Err(usage(format!(
            "noise_per_m {noise_per_m}: must be within 0..1000 mm/m"
        )));
    }
    let cfg = SimulationConfig {
        floor_z_mm: floor_mm,
        footprint_radius_mm: footprint_mm,
        ..SimulationConfig::default()
    };
    cfg.validate(r).py_err()?;
    let tracker = none(tracker);
    let t = match tracker {
        Some(v) => frame(v, "tracker")?,
        None => cfg.tracker_frame,
    };
    let tf = TrackerFrame::from_vector_deg(&[t.x, t.y, t.z, t.a, t.b, t.c]);
    let tracker_range = match none(range_mm) {
        Some(v) => {
            let (min, max) = range_arg(v, "range_mm")?;
            Some(tracker_range(&tf, min, max).py_err()?)
        }
        None => None,
    };
    let (include, warnings) = match none(include) {
        Some(v) => include_arg(robot, v)?,
        None => (Vec::new(), Vec::new()),
    };
    let settings = PlanSettings {
        poses: poses as usize,
        candidates: candidates as usize,
        seed,
        sampler: cfg.sampler(r),
        tracker_range,
        include,
        noise_mm,
        noise_per_m,
        tracker_origin: tracker.is_some().then(|| tf.origin()),
        criterion,
    };
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
