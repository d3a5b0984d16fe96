//! `robocal.simulate`: a virtual robot measured by a virtual laser tracker (paper, section IV),
//! through the library calls of `robocal simulate` (`simulation::simulate`,
//! `simulation::simulate_joints`, `Simulation::measure_targets`) with its settings checked by the library's
//! `SimulationBuilder`, as the CLI's flags are, so the same seed gives the CLI's numbers. It returns a
//! `Simulation` (`simulation`) whose arrays hold the values the CLI writes.

use crate::args::{count, frame, per_joint};
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::simulation::PySimulation;
use crate::written::written;
use pyo3::prelude::*;
use robocal_core::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::simulation::{
    simulate, simulate_joints, PerJoint, Simulation, SimulationBuilder, SimulationSettings,
    TruthSource,
};
use robocal_core::Robot;
use std::path::PathBuf;

/// The truth robot (`robocal simulate --truth`): a `Robot`, or a name the library reads
/// (`random`, a preset, a robot file, a truth file).
pub(crate) fn truth_arg(truth: &Bound<'_, PyAny>, nominal: &Robot) -> PyResult<TruthSource> {
    if let Ok(r) = truth.extract::<PyRef<'_, PyRobot>>() {
        return Ok(TruthSource::Robot(r.inner.clone()));
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
    TruthSource::from_arg(&s, nominal).map_err(|e| {
        raise(
            crate::errors::exit_code(&e),
            format!("truth: {}", crate::errors::message(&e)),
        )
    })
}

/// A per-joint setting of the real cell (the CLI's `--repeatability-deg`, `--backlash-deg`):
/// `keyword` (the robot class's default), a number for every joint or one per joint.
fn class_or_values(
    v: Option<&Bound<'_, PyAny>>,
    name: &str,
    keyword: &str,
) -> PyResult<Option<PerJoint>> {
    let Some(v) = v else { return Ok(None) };
    if let Ok(s) = v.extract::<String>() {
        return if s == keyword {
            Ok(Some(PerJoint::ClassDefault))
        } else {
            Err(usage(format!(
                "{name}: {s:?}: expected \"{keyword}\", a number or one number per joint"
            )))
        };
    }
    Ok(Some(PerJoint::Values(per_joint(v, name)?)))
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
    orientation_sigma_deg = None, repeatability_deg = None, backlash_deg = None, thermal = None,
    thermal_rise_c = None, thermal_start_s = None, seconds_per_pose = None,
    thermal_link_gain = None, station = 0
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
    repeatability_deg: Option<&Bound<'_, PyAny>>,
    backlash_deg: Option<&Bound<'_, PyAny>>,
    thermal: Option<String>,
    thermal_rise_c: Option<f64>,
    thermal_start_s: Option<f64>,
    seconds_per_pose: Option<f64>,
    thermal_link_gain: Option<&Bound<'_, PyAny>>,
    station: u32,
) -> PyResult<PySimulation> {
    let nominal = &robot.inner;
    let dof = nominal.dof();
    let none = crate::args::given;
    // Parsing only (Python types to numbers); the library's builder checks the settings, as it
    // does the CLI's flags.
    let counted = |v: Option<&Bound<'_, PyAny>>, name: &str| {
        none(v)
            .map(|v| count(v, name, 0, u64::MAX, "a 64-bit count"))
            .transpose()
    };
    let as_usize = |v: u64| usize::try_from(v).unwrap_or(usize::MAX);
    let list =
        |v: Option<&Bound<'_, PyAny>>, name: &str| none(v).map(|v| per_joint(v, name)).transpose();
    let builder = SimulationBuilder {
        seed: counted(seed, "seed")?.unwrap_or(1),
        poses: counted(poses, "poses")?.map(as_usize),
        validation_poses: counted(validation, "validation")?.map_or(0, as_usize),
        joints_given: none(joints).is_some(),
        plane_points: plane,
        plane_z_mm,
        tracker_frame: none(tracker).map(|t| frame(t, "tracker")).transpose()?,
        noise_mm,
        noise_per_m,
        length_sigma_mm: length_error_mm,
        angle_sigma_deg: angle_error_deg,
        tilt_parallel_axes,
        floor_z_mm: floor_mm,
        footprint_radius_mm: footprint_mm,
        compliance_rad_per_nm: list(compliance, "compliance")?,
        link_masses_kg: list(link_masses_kg, "link_masses_kg")?,
        payload_kg,
        outlier_fraction,
        outlier_min_mm,
        outlier_max_mm,
        all_targets,
        orientation_sigma_deg,
        repeatability: class_or_values(none(repeatability_deg), "repeatability_deg", "default")?,
        backlash: class_or_values(none(backlash_deg), "backlash_deg", "auto")?,
        thermal: match thermal.as_deref() {
            None | Some("none") => false,
            Some("auto") => true,
            Some(other) => {
                return Err(usage(format!(
                    "thermal: {other:?}: expected \"auto\" or \"none\""
                )))
            }
        },
        thermal_rise_c,
        thermal_start_s,
        seconds_per_pose,
        thermal_link_gain: list(thermal_link_gain, "thermal_link_gain")?,
        station,
    };
    let truth = truth_arg(truth, nominal)?;
    let SimulationSettings {
        truth,
        config: cfg,
        targets,
    } = builder.build(nominal, truth).py_err()?;
    let joints = none(joints);
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
