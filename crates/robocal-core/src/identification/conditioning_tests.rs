//! Tests of the limits of the identification: nothing left to identify, rank tolerances below
//! what double precision resolves, and ill-conditioned problems (no fake standard deviations).

use super::*;
use crate::error::Error;
use crate::frame::{pose, TrackerFrame};
use crate::model::presets::preset;
use crate::model::{Param, Robot};
use crate::simulation::{random_poses, PoseSampler, Tracker};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn kuka() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

/// `n` random poses of `robot` measured exactly by a tracker 4 m away.
fn exact(robot: &Robot, n: usize, seed: u64) -> Observations {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sampler = PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    };
    let tr = Tracker::new(
        TrackerFrame::new(pose(&[3900.0, -2200.0, 0.0, 2.6, 0.0, 0.0])),
        0.0,
        0.0,
    )
    .unwrap();
    let mut obs = Observations::new(robot.dof());
    for (i, q) in random_poses(robot, n, &sampler, &mut rng)
        .unwrap()
        .iter()
        .enumerate()
    {
        obs.push(q, tr.measure(&robot.tool_position(q), &mut rng), i + 2)
            .unwrap();
    }
    obs
}

fn run(
    robot: &Robot,
    obs: &Observations,
    id: IdentifiabilityOptions,
) -> crate::Result<Calibration> {
    calibrate(
        robot,
        CalibrationData {
            calibration: obs,
            plane: None,
            validation: None,
        },
        &CalibrationSettings {
            identifiability: id,
            ..Default::default()
        },
        &(),
    )
}

#[test]
fn nothing_left_to_identify_is_an_error_not_a_panic() {
    let robot = kuka();
    let obs = exact(&robot, 40, 1);
    let all = robot.params();
    let e = run(
        &robot,
        &obs,
        IdentifiabilityOptions {
            fix: all.clone(),
            ..Default::default()
        },
    )
    .unwrap_err();
    // Refused with the settings, before any work, naming the setting.
    assert!(
        matches!(&e, Error::Usage { field, .. } if field == "identifiability.fix"),
        "{e:?}"
    );
    assert!(e.to_string().contains("nothing is left to identify"), "{e}");
    // Everything but the tool orientation, which has no effect on a point.
    let effective: Vec<Param> = all
        .iter()
        .copied()
        .filter(|p| !(3..6).map(Param::tool).any(|t| t == *p))
        .collect();
    let e = run(
        &robot,
        &obs,
        IdentifiabilityOptions {
            fix: effective,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, Error::Numerical(_)), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("nothing to identify") && msg.contains("tool_a, tool_b, tool_c"),
        "{msg}"
    );
}

#[test]
fn rank_tolerances_below_double_precision_are_refused() {
    let robot = kuka();
    let obs = exact(&robot, 40, 2);
    for tol in [1e-11, 1e-15, 1e-17, 0.0, -1.0, 1.0, f64::NAN] {
        let e = run(
            &robot,
            &obs,
            IdentifiabilityOptions {
                rank_tolerance: tol,
                ..Default::default()
            },
        )
        .unwrap_err();
        // A value out of its range, as a bad flag's: a usage error naming the setting.
        assert!(
            matches!(&e, Error::Usage { field, .. } if field == "identifiability.rank_tolerance"),
            "{tol}: {e:?}"
        );
        assert!(e.to_string().contains("double precision"), "{e}");
    }
    // The floor itself is accepted, and the exact duplicates stay fixed there.
    let c = run(
        &robot,
        &obs,
        IdentifiabilityOptions {
            rank_tolerance: MIN_RANK_TOLERANCE,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(c.identifiability.identified.len(), 26);
    assert!(c.identifiability.fixed_reason(Param::d(0)).is_some());
    assert!(c.identifiability.fixed_reason(Param::d(2)).is_some());
}

/// The KR 480 with axes 2 and 3 tilted by 0.01 degrees: d3 is then barely independent of d2.
fn tilted() -> Robot {
    let mut r = kuka();
    r.set(Param::alpha(2), 0.01f64.to_radians());
    r
}

#[test]
fn an_ill_conditioned_identification_fails_unless_the_tolerance_was_chosen() {
    let robot = tilted();
    let obs = exact(&robot, 75, 3);
    // Default tolerance: d3 is fixed as a duplicate of d2, all is well conditioned.
    let c = run(&robot, &obs, IdentifiabilityOptions::default()).unwrap();
    assert!(c.identifiability.fixed_reason(Param::d(2)).is_some());
    assert!(!c.identifiability.ill_conditioned());
    assert!(c.covariance.unavailable.is_none());
    assert!(c.covariance.std_of(Param::a(1)).unwrap() >= 0.0);
    // At the floor d3 is kept and the condition number exceeds what double precision supports:
    // an error, naming the condition number and the culprit ...
    let low = IdentifiabilityOptions {
        rank_tolerance: MIN_RANK_TOLERANCE,
        ..Default::default()
    };
    let e = run(&robot, &obs, low.clone()).unwrap_err();
    assert!(matches!(e, Error::Numerical(_)), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("condition number") && msg.contains("d3") && msg.contains("rank tolerance"),
        "{msg}"
    );
    // ... unless that tolerance was asked for: then no standard deviation at all, with the reason.
    let c = run(
        &robot,
        &obs,
        IdentifiabilityOptions {
            allow_ill_conditioned: true,
            ..low
        },
    )
    .unwrap();
    let id = &c.identifiability;
    assert!(id.identified.contains(&Param::d(2)));
    assert!(id.ill_conditioned());
    assert!(id.condition_number.is_finite() && id.condition_number > MAX_CONDITION_NUMBER);
    let why = c.covariance.unavailable.as_deref().unwrap();
    assert!(why.contains("condition number"), "{why}");
    for p in &id.identified {
        assert!(c.covariance.identifies(*p));
        assert_eq!(c.covariance.std_of(*p), None, "{}", p.name());
    }
    assert!(c.covariance.std().iter().all(|v| v.is_nan()));
    let r = c.to_result();
    let json = serde_json::to_value(&r).unwrap();
    let d3 = &r.parameters["d3"];
    assert!(!d3.fixed && d3.std.is_none());
    assert!(d3
        .reason
        .as_deref()
        .unwrap()
        .contains("standard deviation unavailable"));
    let u = &json["uncertainty"];
    assert!(u["std"].as_object().unwrap().values().all(|v| v.is_null()));
    assert!(u["std_unavailable"]
        .as_str()
        .unwrap()
        .contains("condition number"));
    let j = &json["identifiability"];
    assert!(j["condition_number"].as_f64().unwrap() > MAX_CONDITION_NUMBER);
    assert_eq!(j["ill_conditioned"], true);
}
