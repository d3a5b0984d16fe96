//! `robocal.iso9283_plan` and `robocal.iso9283_evaluate`: the ISO 9283 test as `robocal
//! iso9283 plan` and `evaluate` run it, through the library's `make_plan`, `plan_csv`,
//! `plan_program`, `read_plan`, `read_test_data` and `evaluate`, with the library's settings
//! checks (errors name this module's keywords).

use crate::arrays::out2;
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use pyo3::prelude::*;
use robocal_core::io::{write_all_atomic, CalibrationResult};
use robocal_core::iso9283::{
    evaluate, make_plan, plan_csv, plan_program, read_plan, read_test_data, Plan, PlanSettings,
    Spec, TrackerMpe, DEFAULT_CYCLES, DEFAULT_DWELL_S,
};
use robocal_core::programs::Format;
use robocal_core::{Robot, TrackerFrame};
use std::path::{Path, PathBuf};

/// A test plan: what `robocal iso9283 plan` writes and prints.
#[pyclass(name = "Iso9283Plan", module = "robocal", frozen)]
pub struct PyIsoPlan {
    plan: Plan,
    nominal: Robot,
    csv: Vec<u8>,
}

fn triple(v: Option<Vec<f64>>, name: &str) -> PyResult<Option<[f64; 3]>> {
    match v {
        None => Ok(None),
        Some(v) => <[f64; 3]>::try_from(v.as_slice())
            .map(Some)
            .map_err(|_| usage(format!("{name}: expected 3 values, got {}", v.len()))),
    }
}

fn format_of(name: &str) -> PyResult<Format> {
    match name {
        "krl" => Ok(Format::Krl),
        "rapid" => Ok(Format::Rapid),
        "urscript" => Ok(Format::UrScript),
        other => Err(usage(format!(
            "program_format: `{other}` is not krl, rapid or urscript"
        ))),
    }
}

/// Plans the test: see `robocal.iso9283_plan` (python/robocal/__init__.py) for the arguments.
#[pyfunction]
#[pyo3(signature = (
    robot = None, result = None, *, cycles = DEFAULT_CYCLES, cube_mm = None, center = None,
    orientation = None, floor_mm = 0.0, footprint_mm = None, poses_from = None
))]
#[allow(clippy::too_many_arguments)]
pub fn iso9283_plan(
    py: Python<'_>,
    robot: Option<&PyRobot>,
    result: Option<&str>,
    cycles: usize,
    cube_mm: Option<f64>,
    center: Option<Vec<f64>>,
    orientation: Option<Vec<f64>>,
    floor_mm: f64,
    footprint_mm: Option<f64>,
    poses_from: Option<PyRef<'_, PyIsoPlan>>,
) -> PyResult<PyIsoPlan> {
    let mut settings = PlanSettings {
        cycles,
        edge_mm: cube_mm,
        centre_mm: triple(center, "center")?,
        orientation_deg: triple(orientation, "orientation")?,
        floor_z_mm: floor_mm,
        footprint_radius_mm: footprint_mm,
        ..PlanSettings::default()
    };
    if let Some(p) = &poses_from {
        if cube_mm.is_some() || settings.centre_mm.is_some() || settings.orientation_deg.is_some() {
            return Err(usage(
                "poses_from: the earlier plan gives the cube, the centre and the orientation \
                 (not cube_mm, center or orientation)",
            ));
        }
        let v = p.plan.pose_vector_deg(1);
        settings.centre_mm = Some(p.plan.cube.centre.into());
        settings.edge_mm = Some(p.plan.cube.edge_mm);
        settings.orientation_deg = Some([v[3], v[4], v[5]]);
    }
    settings.validate().py_err()?;
    let (nominal, calibrated) = match (result, robot) {
        (Some(text), r) => {
            let (n, c) = crate::result::result_robots(text, r)?;
            (n.inner, Some(c.inner))
        }
        (None, Some(r)) => (r.inner.clone(), None),
        (None, None) => return Err(usage("give the robot, or a result (its robot)")),
    };
    let plan = py
        .detach(|| make_plan(&nominal, calibrated.as_ref(), &settings))
        .py_err()?;
    let csv = plan_csv(&plan, &nominal);
    Ok(PyIsoPlan { plan, nominal, csv })
}

#[pymethods]
impl PyIsoPlan {
    /// The cube's edge (mm).
    #[getter]
    fn edge_mm(&self) -> f64 {
        self.plan.cube.edge_mm
    }

    /// The cube's centre (x, y, z) in mm, base frame: P1.
    #[getter]
    fn centre(&self) -> (f64, f64, f64) {
        let c = self.plan.cube.centre;
        (c.x, c.y, c.z)
    }

    /// The commanded poses P1..P5 (5, 6): x, y, z (mm) and A, B, C (deg) in the base frame.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let data = (1..=5).flat_map(|k| self.plan.pose_vector_deg(k)).collect();
        out2(py, data, 5, 6, false)
    }

    /// The joints sent to the robot for P1..P5 (5, dof) in degrees (mm for a prismatic joint):
    /// the compensated ones with a result, else the nominal ones.
    #[getter]
    fn joints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.rows(py, &self.plan.joints)
    }

    /// The joints that reach P1..P5 on the nominal model (5, dof), in degrees.
    #[getter]
    fn nominal_joints<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.rows(py, &self.plan.nominal_joints)
    }

    /// Whether `joints` are compensated on a result's calibrated model.
    #[getter]
    fn compensated(&self) -> bool {
        self.plan.compensated
    }

    /// The number of cycles (P1, P5, P4, P3, P2 each).
    #[getter]
    fn cycles(&self) -> usize {
        self.plan.cycles
    }

    /// The plan CSV `robocal iso9283 plan --out` writes (cycle, pose, q1..qn, x_c..c_c).
    fn to_csv(&self) -> PyResult<String> {
        String::from_utf8(self.csv.clone()).map_err(|e| raise(1, format!("internal: {e}")))
    }

    /// Writes the plan CSV to `path` as `robocal iso9283 plan --out` does (atomically).
    fn write(&self, path: PathBuf) -> PyResult<()> {
        write_all_atomic(&[(path.as_path(), self.csv.as_slice())]).py_err()
    }

    /// The plan as a robot program (`program_format`: "krl", "rapid" or "urscript"), as
    /// `robocal iso9283 plan --program` writes it, with a dwell of `dwell_s` at each pose.
    #[pyo3(signature = (program_format, dwell_s = DEFAULT_DWELL_S))]
    fn program(&self, program_format: &str, dwell_s: f64) -> PyResult<String> {
        let f = format_of(program_format)?;
        Ok(plan_program(&self.plan, &self.nominal, f, dwell_s)
            .py_err()?
            .text)
    }

    fn __repr__(&self) -> String {
        let c = self.plan.cube.centre;
        format!(
            "Iso9283Plan(cube of {:.1} mm centred at ({:.1}, {:.1}, {:.1}) mm, {} cycles, {} \
             joints)",
            self.plan.cube.edge_mm,
            c.x,
            c.y,
            c.z,
            self.plan.cycles,
            if self.plan.compensated {
                "compensated"
            } else {
                "nominal"
            }
        )
    }
}

impl PyIsoPlan {
    fn rows<'py>(&self, py: Python<'py>, q: &[Vec<f64>]) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.nominal.dof();
        let data = q
            .iter()
            .flat_map(|r| self.nominal.joints_to_display(r))
            .collect();
        out2(py, data, q.len(), dof, false)
    }
}

/// Evaluates a measured test: see `robocal.iso9283_evaluate` (python/robocal/__init__.py).
/// Returns the JSON text `robocal iso9283 evaluate --json` prints.
#[pyfunction]
#[pyo3(signature = (plan, data, result = None, *, robot = None, frame = None, spec = None, tracker_mpe = None))]
#[allow(clippy::too_many_arguments)]
pub fn iso9283_evaluate(
    py: Python<'_>,
    plan: PathBuf,
    data: PathBuf,
    result: Option<&str>,
    robot: Option<&PyRobot>,
    frame: Option<&str>,
    spec: Option<&str>,
    tracker_mpe: Option<&str>,
) -> PyResult<String> {
    let spec = spec.map(Spec::parse).transpose().py_err()?;
    let tracker = match tracker_mpe {
        Some(s) => TrackerMpe::parse(s).py_err()?,
        None => TrackerMpe::default(),
    };
    let (nominal, calibrated, tf) =
        match (result, frame) {
            (Some(_), Some(_)) => {
                return Err(usage(
                    "frame: give a result (its tracker frame) or frame=\"base\", not both",
                ))
            }
            (Some(text), None) => {
                let res = CalibrationResult::parse(text, Path::new("<result json>")).py_err()?;
                let (n, c) = crate::result::result_robots(text, robot)?;
                (n.inner, Some(c.inner), res.tracker_frame.to_tracker_frame())
            }
            (None, Some("base")) => match robot {
                Some(r) => (r.inner.clone(), None, TrackerFrame::identity()),
                None => return Err(usage("frame=\"base\" needs the robot")),
            },
            (None, Some(other)) => {
                return Err(usage(format!("frame: `{other}` is not \"base\"")));
            }
            (None, None) => return Err(usage(
                "give a result (its tracker frame maps the data) or frame=\"base\" with the robot",
            )),
        };
    let ev = py
        .detach(|| -> robocal_core::Result<_> {
            let p = read_plan(&plan, &nominal, calibrated.as_ref())?;
            let poses = read_test_data(&data, &p, &nominal, &tf)?;
            evaluate(&poses, &tracker, &tf.origin(), spec.as_ref())
        })
        .py_err()?;
    serde_json::to_string(&ev).map_err(|e| raise(1, format!("internal: {e}")))
}
