//! `robocal.simulate`: a virtual robot measured by a virtual laser tracker (paper, section IV),
//! through the library calls of `robocal simulate` (`simulation::simulate`,
//! `simulation::simulate_joints`, `Simulation::measure_targets`) with its settings checked as
//! the CLI checks its flags, so the same seed gives the CLI's numbers. It returns a
//! `Simulation` (`simulation`) whose arrays hold the values the CLI writes.

use crate::args::{count, frame, per_joint};
use crate::errors::{raise, usage, IntoPy};
use crate::robot::PyRobot;
use crate::simulation::PySimulation;
use crate::written::written;
use pyo3::prelude::*;
use robocal_core::io::measurements::{read_measurements, Measurement, MeasurementSet, Positions};
use robocal_core::io::result::FrameVec;
use robocal_core::simulation::{
    check_truth_matches, simulate, simulate_joints, BacklashModel, GeometricErrors, GravityModel,
    OutlierModel, RepeatabilityModel, Simulation, SimulationConfig, TargetMeasurement,
    ThermalModel, TruthFile, TruthSpec,
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

/// `repeatability_deg` (the CLI's `--repeatability-deg`): `"default"` (the class default) or
/// one standard deviation for all joints or one per joint (deg, mm for a prismatic joint).
fn repeatability_arg(
    v: Option<&Bound<'_, PyAny>>,
    nominal: &Robot,
) -> PyResult<Option<RepeatabilityModel>> {
    let Some(v) = v else { return Ok(None) };
    if let Ok(s) = v.extract::<String>() {
        return match s.as_str() {
            "default" => Ok(Some(RepeatabilityModel::default_for(nominal))),
            _ => Err(usage(format!(
                "repeatability_deg: {s:?}: expected \"default\", a number or one number per joint"
            ))),
        };
    }
    Ok(Some(RepeatabilityModel {
        std_deg: per_joint(v, "repeatability_deg", nominal.dof())?,
    }))
}

/// `backlash_deg` (the CLI's `--backlash-deg`): `"auto"` (the class default) or half the play of
/// all joints or of each (deg, mm for a prismatic joint).
fn backlash_arg(v: Option<&Bound<'_, PyAny>>, nominal: &Robot) -> PyResult<Option<BacklashModel>> {
    let Some(v) = v else { return Ok(None) };
    if let Ok(s) = v.extract::<String>() {
        return match s.as_str() {
            "auto" => Ok(Some(BacklashModel::for_robot(nominal))),
            _ => Err(usage(format!(
                "backlash_deg: {s:?}: expected \"auto\", a number or one number per joint"
            ))),
        };
    }
    Ok(Some(BacklashModel {
        half_play_deg: per_joint(v, "backlash_deg", nominal.dof())?,
    }))
}

/// `thermal` (the CLI's `--thermal auto|none`) and the settings that shape it, which need it
/// (as the CLI's flags require `--thermal`).
fn thermal_arg(
    thermal: Option<&str>,
    shape: [(&str, Option<f64>); 3],
    nominal: &Robot,
) -> PyResult<Option<ThermalModel>> {
    if thermal.is_none() {
        if let Some((name, _)) = shape.iter().find(|(_, v)| v.is_some()) {
            return Err(usage(format!(
                "{name} shapes the thermal growth: give thermal=\"auto\" too"
            )));
        }
    }
    match thermal {
        None | Some("none") => Ok(None),
        Some("auto") => {
            let d = ThermalModel::for_robot(nominal);
            let [(_, rise), (_, start), (_, per_pose)] = shape;
            Ok(Some(ThermalModel {
                rise_c: rise.unwrap_or(d.rise_c),
                start_s: start.unwrap_or(d.start_s),
                seconds_per_pose: per_pose.unwrap_or(d.seconds_per_pose),
                ..d
            }))
        }
        Some(other) => Err(usage(format!(
            "thermal: {other:?}: expected \"auto\" or \"none\""
        ))),
    }
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
    orientation_sigma_deg = None, repeatability_deg = None, backlash_deg = None, thermal = None,
    thermal_rise_c = None, thermal_start_s = None, seconds_per_pose = None, station = 0
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
    station: u32,
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
        repeatability: repeatability_arg(none(repeatability_deg), nominal)?,
        backlash: backlash_arg(none(backlash_deg), nominal)?,
        thermal: thermal_arg(
            thermal.as_deref(),
            [
                ("thermal_rise_c", thermal_rise_c),
                ("thermal_start_s", thermal_start_s),
                ("seconds_per_pose", seconds_per_pose),
            ],
            nominal,
        )?,
        station,
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
