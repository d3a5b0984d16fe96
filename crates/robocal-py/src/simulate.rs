//! `robocal.simulate`: a virtual robot measured by a virtual laser tracker (paper, section IV),
//! through the library calls of `robocal simulate` (`simulation::simulate`,
//! `simulation::simulate_joints`, `Simulation::measure_targets`) with its settings checked as
//! the CLI checks its flags, so the same seed gives the CLI's numbers. The arrays hold the values
//! the CLI writes (`written`); `Simulation.write` writes the CLI's very files.

use crate::args::{self, count, frame, per_joint};
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::written::{written, Written};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robocal_core::io::measurements::measurements_csv;
use robocal_core::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::io::result::FrameVec;
use robocal_core::io::write_all_atomic;
use robocal_core::simulation::{
    check_truth_matches, simulate, simulate_joints, GeometricErrors, GravityModel, OutlierModel,
    Simulation, SimulationConfig, TargetMeasurement, TruthFile, TruthSpec, SET_CALIBRATION,
    SET_PLANE, SET_VALIDATION,
};
use robocal_core::Robot;
use std::path::{Path, PathBuf};

/// Most poses of one session (calibration + validation), as the CLI's `limits::MAX_POSES`.
const MAX_POSES: u64 = 10_000_000;

/// Why the pose counts are limited (for messages).
const POSES_WHY: &str = "about 5 GB of memory at the limit; draw larger sets in several runs \
                         with different seeds";

/// The largest orientation noise of a simulated 6-DoF probe (deg), as the CLI.
const MAX_ORIENTATION_SIGMA_DEG: f64 = 10.0;

/// A simulated measurement session: the rows of the CSV `robocal simulate --out` writes (the
/// values as written: joint values to 1e-9 degree, readings to 1e-6 mm), the truth behind them
/// and what was injected.
#[pyclass(name = "Simulation", module = "robocal", frozen)]
pub struct PySimulation {
    sim: Simulation,
    rows: Written,
    dof: usize,
}

/// The truth robot and, for a truth file, its tracker frame (the CLI's `--truth`).
fn truth_arg(
    truth: &Bound<'_, PyAny>,
    nominal: &Robot,
    random: GeometricErrors,
    random_given: bool,
) -> PyResult<(TruthSpec, Option<FrameVec>)> {
    if let Ok(r) = truth.extract::<PyRef<'_, PyRobot>>() {
        if random_given {
            return Err(random_only());
        }
        return Ok((TruthSpec::Robot(r.inner.clone()), None));
    }
    let Ok(s) = truth
        .py()
        .import("os")?
        .call_method1("fspath", (truth,))
        .and_then(|p| p.extract::<String>())
    else {
        return Err(usage(format!(
            "truth: expected \"random\", a preset name, a robot file, a truth file or a Robot, \
             got {}",
            crate::options::describe(truth)
        )));
    };
    if s == "random" {
        random.validate().py_err()?;
        return Ok((TruthSpec::Random(random), None));
    }
    if random_given {
        return Err(random_only());
    }
    let in_truth = |e: robocal_core::Error| {
        raise(
            crate::errors::exit_code(&e),
            format!("truth: {}", crate::errors::message(&e)),
        )
    };
    if s.ends_with(".json") {
        let p = Path::new(&s);
        let tf = TruthFile::read(p).map_err(in_truth)?;
        let robot = tf.truth_robot(nominal, p).map_err(in_truth)?;
        return Ok((TruthSpec::Robot(robot), Some(tf.tracker_frame)));
    }
    let robot = robocal_core::load_robot(&s).map_err(in_truth)?;
    Ok((TruthSpec::Robot(robot), None))
}

fn random_only() -> PyErr {
    usage("length_error_mm, angle_error_deg and tilt_parallel_axes apply only to truth=\"random\"")
}

/// The joint values to measure: a joints or measurement CSV (read as the CLI reads `--joints`)
/// or an array (n, dof) in interface units.
fn joints_arg(robot: &PyRobot, joints: &Bound<'_, PyAny>) -> PyResult<MeasurementSet> {
    let path = joints
        .py()
        .import("os")?
        .call_method1("fspath", (joints,))
        .and_then(|p| p.extract::<PathBuf>());
    if let Ok(p) = path {
        let set = read_measurements(&p, robot.inner.joint_space(), Positions::Optional).py_err()?;
        return Ok(set);
    }
    let m = robot.joints(joints, "joints")?;
    let rows = (0..m.rows)
        .map(|i| Measurement {
            line: i + 1,
            q: m.row(i).to_vec(),
            p: None,
            extra: Vec::new(),
        })
        .collect();
    Ok(MeasurementSet {
        path: PathBuf::from("joints array"),
        joints: robot.inner.joint_space().clone(),
        extra_columns: Vec::new(),
        rows,
        warnings: Vec::new(),
    })
}

/// Simulates a session: see `robocal.simulate` (python/robocal/__init__.py) for the arguments.
#[pyfunction]
#[pyo3(signature = (
    robot, truth, poses = None, *, joints = None, seed = None, validation = None, plane = true,
    plane_z_mm = None, tracker = None,
    noise_mm = robocal_core::simulation::DEFAULT_NOISE_MM,
    noise_per_m = robocal_core::simulation::DEFAULT_NOISE_PER_M,
    length_error_mm = None, angle_error_deg = None, tilt_parallel_axes = false, floor_mm = 0.0,
    footprint_mm = None, compliance = None, link_masses_kg = None, payload_kg = None,
    outlier_fraction = None, outlier_min_mm = None, outlier_max_mm = None, all_targets = false,
    orientation_sigma_deg = None
))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_session(
    py: Python<'_>,
    robot: &PyRobot,
    truth: &Bound<'_, PyAny>,
    poses: Option<&Bound<'_, PyAny>>,
    joints: Option<&Bound<'_, PyAny>>,
    seed: Option<&Bound<'_, PyAny>>,
    validation: Option<&Bound<'_, PyAny>>,
    plane: bool,
    plane_z_mm: Option<f64>,
    tracker: Option<&Bound<'_, PyAny>>,
    noise_mm: f64,
    noise_per_m: f64,
    length_error_mm: Option<f64>,
    angle_error_deg: Option<f64>,
    tilt_parallel_axes: bool,
    floor_mm: f64,
    footprint_mm: Option<f64>,
    compliance: Option<&Bound<'_, PyAny>>,
    link_masses_kg: Option<&Bound<'_, PyAny>>,
    payload_kg: Option<f64>,
    outlier_fraction: Option<f64>,
    outlier_min_mm: Option<f64>,
    outlier_max_mm: Option<f64>,
    all_targets: bool,
    orientation_sigma_deg: Option<f64>,
) -> PyResult<PySimulation> {
    let nominal = &robot.inner;
    let dof = nominal.dof();
    let none = crate::args::given;
    let (poses, joints, seed, validation) =
        (none(poses), none(joints), none(seed), none(validation));
    let compliance = none(compliance);
    let link_masses_kg = none(link_masses_kg);
    let tracker = none(tracker);

    // Combinations the CLI refuses (clap's conflicts and requirements).
    if joints.is_some() {
        for (given, name) in [
            (poses.is_some(), "poses"),
            (
                validation.is_some_and(|v| v.extract::<i64>().map_or(true, |n| n != 0)),
                "validation",
            ),
            (plane_z_mm.is_some(), "plane_z_mm"),
        ] {
            if given {
                return Err(usage(format!(
                    "{name}: not with joints (the given joint values are measured as they are)"
                )));
            }
        }
    } else if poses.is_none() {
        return Err(usage(
            "give poses (the number of random calibration poses) or joints (the joint values \
             to measure)",
        ));
    }
    if compliance.is_none() && (link_masses_kg.is_some() || payload_kg.is_some()) {
        return Err(usage(
            "link_masses_kg and payload_kg model gravity deflection: give compliance too",
        ));
    }
    if outlier_fraction.is_none() && (outlier_min_mm.is_some() || outlier_max_mm.is_some()) {
        return Err(usage(
            "outlier_min_mm and outlier_max_mm shape the outliers: give outlier_fraction too",
        ));
    }
    if outlier_fraction.is_some() && (all_targets || orientation_sigma_deg.is_some()) {
        return Err(usage(
            "outlier_fraction: outliers are drawn for single points, not with all_targets or \
             orientation_sigma_deg",
        ));
    }

    // Counts within the CLI's limits.
    let poses = match poses {
        Some(v) => count(v, "poses", 0, MAX_POSES, POSES_WHY)? as usize,
        None => 0,
    };
    let validation = match validation {
        Some(v) => count(v, "validation", 0, MAX_POSES, POSES_WHY)? as usize,
        None => 0,
    };
    if (poses + validation) as u64 > MAX_POSES {
        return Err(usage(format!(
            "poses {poses} and validation {validation}: {} poses in all, at most {MAX_POSES} \
             ({POSES_WHY})",
            poses + validation
        )));
    }
    let seed = match seed {
        Some(v) => count(v, "seed", 0, u64::MAX, "a 64-bit seed")?,
        None => 1,
    };

    // The truth and the configuration, as the CLI's `Settings`.
    let d = GeometricErrors::default();
    let random_given = length_error_mm.is_some() || angle_error_deg.is_some() || tilt_parallel_axes;
    let errors = GeometricErrors {
        length_sigma_mm: length_error_mm.unwrap_or(d.length_sigma_mm),
        angle_sigma_deg: angle_error_deg.unwrap_or(d.angle_sigma_deg),
        tilt_parallel_axes,
    };
    let (truth, truth_tracker) = truth_arg(truth, nominal, errors, random_given)?;
    let gravity = match compliance {
        None => None,
        Some(c) => Some(GravityModel::new(
            per_joint(c, "compliance", dof)?,
            match link_masses_kg {
                Some(m) => per_joint(m, "link_masses_kg", dof)?,
                None => vec![0.0; dof],
            },
            payload_kg.unwrap_or(0.0),
        )),
    };
    let outliers = outlier_fraction.map(|fraction| {
        let o = OutlierModel::default();
        OutlierModel {
            fraction,
            min_mm: outlier_min_mm.unwrap_or(o.min_mm),
            max_mm: outlier_max_mm.unwrap_or(o.max_mm),
        }
    });
    let defaults = SimulationConfig::default();
    let tracker_frame = match tracker {
        Some(t) => frame(t, "tracker")?,
        None => truth_tracker.unwrap_or(defaults.tracker_frame),
    };
    let cfg = SimulationConfig {
        seed,
        poses,
        validation_poses: validation,
        plane_points: plane && joints.is_none(),
        plane_z_mm,
        floor_z_mm: floor_mm,
        footprint_radius_mm: footprint_mm,
        tracker_frame,
        noise_mm,
        noise_per_m,
        gravity,
        outliers,
    };
    cfg.validate(nominal).py_err()?;
    if let TruthSpec::Robot(t) = &truth {
        check_truth_matches(nominal, t).py_err()?;
    }
    if let Some(s) = orientation_sigma_deg {
        if !(0.0..=MAX_ORIENTATION_SIGMA_DEG).contains(&s) {
            return Err(usage(format!(
                "orientation_sigma_deg {s}: not an angle noise in [0, \
                 {MAX_ORIENTATION_SIGMA_DEG}] deg"
            )));
        }
    }
    if all_targets && nominal.target_count() < 2 {
        return Err(usage(format!(
            "all_targets: robot `{}` has one target; give its reflectors' nominal tools in the \
             robot file (`tools = [[x, y, z, a, b, c], ...]`)",
            nominal.name()
        )));
    }
    let targets = TargetMeasurement {
        all_targets,
        orientation_sigma_deg,
    };
    let joints = joints.map(|j| joints_arg(robot, j)).transpose()?;

    let sim = py
        .detach(|| -> robocal_core::Result<Simulation> {
            let mut sim = match &joints {
                Some(j) => simulate_joints(nominal, &truth, &cfg, j, &())?,
                None => simulate(nominal, &truth, &cfg, &())?,
            };
            sim.measure_targets(&targets)?;
            Ok(sim)
        })
        .py_err()?;
    let rows = py.detach(|| written(&sim.measurements))?;
    Ok(PySimulation { sim, rows, dof })
}

impl PySimulation {
    /// The rows of `set` (every row when `set` is None) as (q, xyz).
    fn rows_of<'py>(
        &self,
        py: Python<'py>,
        set: Option<&str>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let xyz = self.rows.xyz.as_deref().unwrap_or(&[]);
        let keep: Vec<usize> = match (set, self.rows.column("set")) {
            (None, _) => (0..self.rows.rows).collect(),
            (Some(s), Some(col)) => (0..self.rows.rows).filter(|&i| col[i] == s).collect(),
            (Some(_), None) => Vec::new(),
        };
        let dof = self.dof;
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
        Ok(self.rows_of(py, None)?.0)
    }

    /// The tracker's readings of every row (n, 3): mm in the tracker frame, as written.
    #[getter]
    fn xyz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.rows_of(py, None)?.1)
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
        self.rows_of(py, Some(SET_CALIBRATION))
    }

    /// The validation rows (set "validation") as (q, xyz): empty without `validation`.
    #[getter]
    fn validation<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.rows_of(py, Some(SET_VALIDATION))
    }

    /// The paper's three plane points (set "plane") as (q, xyz): empty with `plane=False`.
    #[getter]
    fn plane<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.rows_of(py, Some(SET_PLANE))
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
        String::from_utf8(self.rows.csv.clone()).map_err(|e| raise(1, format!("internal: {e}")))
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
