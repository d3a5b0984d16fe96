//! The library's messages about bad settings name the setting (a field of its settings structs),
//! never a command-line flag: the CLI maps setting names to its flags.

use crate::compensation::DampedLeastSquares;
use crate::frame::TrackerFrame;
use crate::identification::{
    analyze, calibrate, CalibrationData, CalibrationSettings, IdentifiabilityOptions, Observations,
};
use crate::model::presets::preset;
use crate::model::{Param, Robot};
use crate::simulation::{
    check_truth_matches, random_poses, simulate, GeometricErrors, GravityModel, OutlierModel,
    PoseSampler, SimulationConfig, Tracker, TruthSpec,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn kr480() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

/// Exact measurements of `n` random poses of `robot`, in its base frame.
fn exact(robot: &Robot, n: usize) -> Observations {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let sampler = PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    };
    let mut obs = Observations::new(robot.dof());
    for (i, q) in random_poses(robot, n, &sampler, &mut rng)
        .unwrap()
        .iter()
        .enumerate()
    {
        obs.push(q, robot.tool_position(q), i + 2).unwrap();
    }
    obs
}

/// Asserts that `e` is an error whose text names `setting` and no flag.
fn names_setting<T: std::fmt::Debug>(e: crate::Result<T>, setting: &str) {
    let msg = e.expect_err(setting).to_string();
    assert!(msg.contains(setting), "`{setting}` not in: {msg}");
    assert!(!msg.contains("--"), "a flag in: {msg}");
}

#[test]
fn bad_simulation_settings_name_the_setting_not_a_flag() {
    let nominal = kr480();
    let truth = TruthSpec::Robot(nominal.clone());
    let d = SimulationConfig::default;
    let sim = |c: SimulationConfig| simulate(&nominal, &truth, &c, &());
    names_setting(sim(SimulationConfig { poses: 0, ..d() }), "poses");
    names_setting(
        sim(SimulationConfig {
            noise_mm: -1.0,
            ..d()
        }),
        "noise_mm",
    );
    names_setting(
        sim(SimulationConfig {
            noise_per_m: 5e3,
            ..d()
        }),
        "noise_per_m",
    );
    let mut far = d();
    far.tracker_frame.x = 1e300;
    names_setting(sim(far), "tracker_frame");
    names_setting(
        sim(SimulationConfig {
            floor_z_mm: -1e9,
            ..d()
        }),
        "floor_z_mm",
    );
    names_setting(
        sim(SimulationConfig {
            footprint_radius_mm: Some(-1.0),
            ..d()
        }),
        "footprint_radius_mm",
    );
    names_setting(
        sim(SimulationConfig {
            plane_z_mm: Some(-1e5),
            ..d()
        }),
        "plane_z_mm",
    );
    let gravity = |c: Vec<f64>, m: Vec<f64>, p: f64| {
        let g = GravityModel::new(c, m, p);
        sim(SimulationConfig {
            gravity: Some(g),
            ..d()
        })
    };
    names_setting(
        gravity(vec![1e-7; 5], vec![0.0; 6], 10.0),
        "gravity.compliance_rad_per_nm",
    );
    names_setting(
        gravity(vec![1e-7; 6], vec![-1.0; 6], 10.0),
        "gravity.link_masses_kg",
    );
    names_setting(
        gravity(vec![1e-7; 6], vec![0.0; 6], 0.0),
        "gravity.payload_kg",
    );
    names_setting(
        gravity(vec![1e-7; 6], vec![0.0; 6], 1e300),
        "gravity.payload_kg",
    );
    let outliers = |fraction: f64, min_mm: f64, max_mm: f64| {
        sim(SimulationConfig {
            outliers: Some(OutlierModel {
                fraction,
                min_mm,
                max_mm,
            }),
            ..d()
        })
    };
    names_setting(outliers(1.5, 1.0, 2.0), "outliers.fraction");
    names_setting(outliers(0.1, -1.0, 2.0), "outliers.min_mm");
    names_setting(outliers(0.1, 1.0, 1e300), "outliers.max_mm");
    names_setting(outliers(0.1, 3.0, 2.0), "outliers.max_mm");
    for (errors, setting) in [
        (
            GeometricErrors {
                length_sigma_mm: -1.0,
                ..GeometricErrors::default()
            },
            "truth.length_sigma_mm",
        ),
        (
            GeometricErrors {
                angle_sigma_deg: 1e6,
                ..GeometricErrors::default()
            },
            "truth.angle_sigma_deg",
        ),
    ] {
        names_setting(
            simulate(&nominal, &TruthSpec::Random(errors), &d(), &()),
            setting,
        );
    }
    let one = crate::parse_robot_toml(
        "convention = \"mdh\"\n[[joints]]\nalpha = 0\nd = 0\na = 100\n",
        std::path::Path::new("one.toml"),
    )
    .unwrap();
    names_setting(check_truth_matches(&nominal, &one), "truth");
    names_setting(
        Tracker::new(TrackerFrame::identity(), -1.0, 0.0),
        "noise_mm",
    );
    names_setting(
        Tracker::new(TrackerFrame::identity(), 0.0, f64::NAN),
        "noise_per_m",
    );
}

#[test]
fn bad_calibration_and_compensation_settings_name_the_setting_not_a_flag() {
    let nominal = kr480();
    let obs = exact(&nominal, 60);
    let run = |s: CalibrationSettings| {
        calibrate(
            &nominal,
            CalibrationData {
                calibration: &obs,
                plane: None,
                validation: None,
            },
            &s,
            &(),
        )
    };
    let both = CalibrationSettings {
        identifiability: IdentifiabilityOptions {
            fix: vec![Param::d(2)],
            free: vec![Param::d(2)],
            ..Default::default()
        },
        ..Default::default()
    };
    names_setting(run(both), "identifiability.fix");
    let tol = CalibrationSettings {
        identifiability: IdentifiabilityOptions {
            rank_tolerance: 2.0,
            ..Default::default()
        },
        ..Default::default()
    };
    names_setting(run(tol), "identifiability.rank_tolerance");
    let scale = CalibrationSettings {
        robust_scale_mm: Some(-1.0),
        ..Default::default()
    };
    names_setting(run(scale), "robust_scale_mm");
    names_setting(
        run(CalibrationSettings {
            robust_scale_mm: Some(1e300),
            ..Default::default()
        }),
        "robust_scale_mm",
    );
    // d2 and d3 (axes 2 and 3 are parallel) have the same effect: only one can be freed.
    let free = IdentifiabilityOptions {
        free: vec![Param::d(1), Param::d(2)],
        ..Default::default()
    };
    names_setting(analyze(&nominal, &obs, &free), "identifiability.free");
    let fixed = IdentifiabilityOptions {
        fix: vec![Param::a(4)],
        ..Default::default()
    };
    let id = analyze(&nominal, &obs, &fixed).unwrap();
    let why = id.fixed_reason(Param::a(4)).unwrap().describe();
    assert!(why == "fixed on request" && !why.contains("--"), "{why}");
    let dls = |tolerance_mm: f64, max_iterations: usize| DampedLeastSquares {
        tolerance_mm,
        max_iterations,
        ..DampedLeastSquares::default()
    };
    names_setting(dls(-1.0, 10).validate(), "tolerance_mm");
    names_setting(dls(1e-3, 0).validate(), "max_iterations");
}

/// The calibration's settings are checked in one place, [`CalibrationSettings::check`], which the
/// CLI and the Python bindings call before reading data: each bad value names its setting, as a
/// usage error (a bad flag's value), and contradicting parameter lists as an invalid value.
#[test]
fn calibration_settings_are_checked_once_naming_each_setting() {
    use crate::Error;
    let robot = kr480();
    assert!(CalibrationSettings::default().check(&robot).is_ok());
    let d = CalibrationSettings::default;
    let ids = |fix: Vec<Param>, free: Vec<Param>, rank_tolerance: f64| IdentifiabilityOptions {
        fix,
        free,
        rank_tolerance,
        ..Default::default()
    };
    let tol = IdentifiabilityOptions::default().rank_tolerance;
    let mut heavy = d();
    heavy.weighting.mm_per_deg = 1e7;
    let mut weightless = d();
    weightless.weighting.mm_per_deg = 0.0;
    let cases: Vec<(CalibrationSettings, &str, bool)> = vec![
        (
            CalibrationSettings {
                solver: crate::identification::SolverOptions {
                    max_iterations: 0,
                    ..Default::default()
                },
                ..d()
            },
            "solver.max_iterations",
            true,
        ),
        (
            CalibrationSettings {
                solver: crate::identification::SolverOptions {
                    max_iterations: crate::identification::MAX_ITERATIONS + 1,
                    ..Default::default()
                },
                ..d()
            },
            "solver.max_iterations",
            true,
        ),
        (
            CalibrationSettings {
                identifiability: ids(robot.params(), vec![], tol),
                ..d()
            },
            "identifiability.fix",
            true,
        ),
        (
            CalibrationSettings {
                identifiability: ids(vec![Param::d(2)], vec![Param::d(2)], tol),
                ..d()
            },
            "identifiability.fix",
            false,
        ),
        (
            CalibrationSettings {
                identifiability: ids(vec![], vec![], 1e-15),
                ..d()
            },
            "identifiability.rank_tolerance",
            true,
        ),
        (
            CalibrationSettings {
                robust_scale_mm: Some(f64::NAN),
                ..d()
            },
            "robust_scale_mm",
            true,
        ),
        (
            CalibrationSettings {
                robust_scale_mm: Some(2e6),
                ..d()
            },
            "robust_scale_mm",
            true,
        ),
        (heavy, "weighting.mm_per_deg", true),
        (weightless, "weighting.mm_per_deg", true),
    ];
    for (settings, field, usage) in cases {
        match settings.check(&robot) {
            Err(Error::Usage { field: f, message }) if usage => {
                assert_eq!(f, field, "{message}");
                assert!(!message.contains("--"), "a flag in: {message}");
            }
            Err(Error::Invalid { field: f, message }) if !usage => {
                assert_eq!(f, field, "{message}");
            }
            other => panic!("{field}: {other:?}"),
        }
    }
}
