//! Tests of the plausibility gate: each check on good data and on data with the mistake it is
//! meant to catch, the likely causes, and the gate on the demo's 30 seeds.

use super::*;
use crate::experiment::{run_experiment, ExperimentConfig};
use crate::frame::{pose, TrackerFrame};
use crate::identification::{
    calibrate, Calibration, CalibrationData, CalibrationSettings, SolverOptions,
};
use crate::io::result::{NotCalibrated, STATUS_IMPLAUSIBLE, STATUS_PARTIAL};
use crate::io::CalibrationResult;
use crate::model::presets::preset;
use crate::simulation::{random_poses, PoseSampler, Tracker};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn kuka() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn ur5() -> Robot {
    crate::parse_robot_toml(
        include_str!("../../../../../examples/ur5.toml"),
        Path::new("examples/ur5.toml"),
    )
    .unwrap()
}

/// `nominal` with seeded realistic errors (0.5 mm, 0.03 deg) on every parameter.
fn truth_of(nominal: &Robot, seed: u64) -> Robot {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut r = nominal.clone();
    for p in r.params() {
        let dv = match p.unit() {
            Unit::Mm => rng.gen_range(-0.5..0.5),
            Unit::Deg => rng.gen_range(-0.03f64..0.03).to_radians(),
            // The geometric robots of these tests have no other units.
            _ => 0.0,
        };
        r.set(p, r.get(p) + dv);
    }
    r
}

/// Joint vectors and their tracker readings (tracker about 4 m away, 0.01 mm noise).
struct Cell {
    qs: Vec<Vec<f64>>,
    ms: Vec<Vector3<f64>>,
}

fn measure(nominal: &Robot, truth: &Robot, n: usize, seed: u64) -> Cell {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let sampler = PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 0.15 * reach_mm(nominal),
        max_tries_per_pose: 10_000,
    };
    let qs = random_poses(nominal, n, &sampler, &mut rng).unwrap();
    let tr = Tracker::new(
        TrackerFrame::new(pose(&[
            3100.0,
            -2200.0,
            1200.0,
            125f64.to_radians(),
            0.0,
            0.0,
        ])),
        0.01,
        0.005,
    )
    .unwrap();
    let ms = qs
        .iter()
        .map(|q| tr.measure(&truth.tool_position(q), &mut rng))
        .collect();
    Cell { qs, ms }
}

impl Cell {
    /// The observations, with `q` and `m` changed by the mistakes to test.
    fn obs(
        &self,
        q_of: impl Fn(&[f64]) -> Vec<f64>,
        m_of: impl Fn(Vector3<f64>) -> Vector3<f64>,
    ) -> Observations {
        let mut o = Observations::new(self.qs[0].len());
        for (i, (q, m)) in self.qs.iter().zip(&self.ms).enumerate() {
            o.push(&q_of(q), m_of(*m), i + 2).unwrap();
        }
        o
    }

    fn good(&self) -> Observations {
        self.obs(|q| q.to_vec(), |m| m)
    }
}

fn fit(nominal: &Robot, cal: &Observations, val: Option<&Observations>) -> Calibration {
    fit_with(nominal, cal, val, &CalibrationSettings::default())
}

fn fit_with(
    nominal: &Robot,
    cal: &Observations,
    val: Option<&Observations>,
    s: &CalibrationSettings,
) -> Calibration {
    calibrate(
        nominal,
        CalibrationData {
            calibration: cal,
            plane: None,
            validation: val,
        },
        s,
        &(),
    )
    .unwrap()
}

fn check_of(c: &Calibration, kind: CheckKind) -> &Check {
    c.plausibility
        .checks
        .iter()
        .find(|k| k.kind == kind)
        .unwrap_or_else(|| panic!("no {} check", kind.name()))
}

/// Asserts that `kind` failed and that its cause contains `cause`.
fn fails(c: &Calibration, kind: CheckKind, cause: &str) {
    let k = check_of(c, kind);
    assert!(!k.passed, "{} passed: {}", kind.name(), k.detail);
    let why = k.cause.as_deref().unwrap_or_default();
    assert!(
        why.contains(cause),
        "{}: cause `{why}` lacks `{cause}`",
        kind.name()
    );
    assert!(c.plausibility.implausible());
}

fn kuka_cell() -> Cell {
    measure(&kuka(), &truth_of(&kuka(), 1), 75, 2)
}

#[test]
fn good_data_pass_every_check() {
    for (nominal, seed) in [(kuka(), 1), (ur5(), 2)] {
        let cell = measure(&nominal, &truth_of(&nominal, seed), 75, seed + 10);
        let val = measure(&nominal, &truth_of(&nominal, seed), 30, seed + 20);
        let c = fit(&nominal, &cell.good(), Some(&val.good()));
        let p = &c.plausibility;
        assert!(p.passed(), "{}: {}", nominal.name(), p.summary());
        assert_eq!(p.checks.len(), 12, "every check, validation included");
        assert!(p.explanations.is_empty() && p.checks.iter().all(|k| k.cause.is_none()));
        for k in &p.checks {
            assert!(k.measured.is_finite(), "{}: {}", k.kind.name(), k.detail);
        }
        // Realistic data stay far inside the limits.
        assert!(check_of(&c, CheckKind::Units).measured < 1.01);
        assert!(check_of(&c, CheckKind::Handedness).measured > 10.0);
        let reach = p.reach_mm;
        assert!(check_of(&c, CheckKind::NominalError).measured < 0.01 * reach);
        let r = c.to_result();
        let json = serde_json::to_value(&r).unwrap();
        assert_eq!(json["status"], "calibrated");
        assert_eq!(json["plausibility"]["passed"], true);
        assert!(r.not_calibrated().is_none());
    }
}

#[test]
fn reach_is_the_chains_length() {
    // KR 480: 1045 + 500 + 1300 + 55 + 1525 + 290 + |T0| (254 mm).
    assert!(
        (reach_mm(&kuka()) - 4968.0).abs() < 1.0,
        "{}",
        reach_mm(&kuka())
    );
    assert!(
        (reach_mm(&ur5()) - 1223.5).abs() < 0.1,
        "{}",
        reach_mm(&ur5())
    );
}

#[test]
fn units_check_names_metres_and_inches() {
    let cell = kuka_cell();
    for (factor, unit) in [(1000.0, "metres"), (25.4, "inches"), (10.0, "centimetres")] {
        let c = fit(&kuka(), &cell.obs(|q| q.to_vec(), |m| m / factor), None);
        fails(&c, CheckKind::Units, unit);
        let k = check_of(&c, CheckKind::Units);
        assert!((k.measured / factor - 1.0).abs() < 0.01, "{}", k.detail);
        assert!(
            k.detail.contains(&format!("the scale of {unit}")),
            "{}",
            k.detail
        );
        // The other checks that fail share the cause.
        fails(&c, CheckKind::NominalError, unit);
        let e = &c.plausibility.explanations[0];
        assert_eq!(e.unit.map(|u| u.0), Some(unit));
        assert!(!e.mirrored && e.joints.is_none() && e.rms_mm < 5.0, "{e:?}");
    }
}

#[test]
fn handedness_check_finds_a_mirrored_frame() {
    let cell = kuka_cell();
    let c = fit(
        &kuka(),
        &cell.obs(|q| q.to_vec(), |m| Vector3::new(m.x, -m.y, m.z)),
        None,
    );
    fails(&c, CheckKind::Handedness, "mirrored");
    assert!(check_of(&c, CheckKind::Handedness).measured < 0.05);
    assert!(c.plausibility.explanations[0].mirrored);
    // Mirrored and in metres: both named.
    let c = fit(
        &kuka(),
        &cell.obs(|q| q.to_vec(), |m| Vector3::new(-m.x, m.y, m.z) / 1000.0),
        None,
    );
    fails(&c, CheckKind::Handedness, "mirrored");
    fails(&c, CheckKind::Handedness, "metres");
}

#[test]
fn nominal_error_check_catches_a_wrong_robot() {
    // The KR 480 model on UR5 data: a 3.4 times smaller robot of another shape.
    let u = ur5();
    let cell = measure(&u, &truth_of(&u, 3), 75, 4);
    let c = fit(&kuka(), &cell.good(), None);
    fails(
        &c,
        CheckKind::NominalError,
        "robot description does not match",
    );
    assert!(c.plausibility.explanations.is_empty());
    let k = check_of(&c, CheckKind::NominalError);
    assert!(k.measured > 0.1 * reach_mm(&kuka()), "{}", k.detail);
    // The fit is not a calibration. (Parameter moves are measured from the nominal geometry
    // with the tools fitted to the data, so the huge tool a wrong robot needs is not counted as a
    // move: the nominal-error check is what names it.)
    assert!(c.plausibility.implausible());
}

#[test]
fn missing_coupling_radians_and_signs_are_named() {
    let cell = kuka_cell();
    // FANUC-style controller value J3 given where the model needs q3 = -(J2 + J3).
    let coupled = cell.obs(
        |q| {
            let mut v = q.to_vec();
            v[2] = -q[2] - q[1];
            v
        },
        |m| m,
    );
    let c = fit(&kuka(), &coupled, None);
    fails(
        &c,
        CheckKind::NominalError,
        "joint 3 is given without its coupling to joint 2",
    );
    let radians = cell.obs(|q| q.iter().map(|v| v.to_radians()).collect(), |m| m);
    let c = fit(&kuka(), &radians, None);
    fails(&c, CheckKind::NominalError, "radians");
    let sign2 = cell.obs(
        |q| {
            let mut v = q.to_vec();
            v[1] = -v[1];
            v
        },
        |m| m,
    );
    let c = fit(&kuka(), &sign2, None);
    fails(
        &c,
        CheckKind::NominalError,
        "the sign of joint 2 is reversed",
    );
}

#[test]
fn validation_points_in_another_unit_fail_their_own_check() {
    let cell = kuka_cell();
    let val = measure(&kuka(), &truth_of(&kuka(), 1), 30, 5);
    let c = fit(
        &kuka(),
        &cell.good(),
        Some(&val.obs(|q| q.to_vec(), |m| m / 1000.0)),
    );
    fails(
        &c,
        CheckKind::ValidationNominalError,
        "validation points do not match",
    );
    assert!(check_of(&c, CheckKind::NominalError).passed);
    assert!(check_of(&c, CheckKind::Units).passed);
}

#[test]
fn parameter_move_checks_catch_lengths_and_angles_beyond_calibration() {
    let cell = kuka_cell();
    let obs = cell.good();
    let c = fit(&kuka(), &obs, None);
    assert!(check_of(&c, CheckKind::LengthMoves).passed);
    assert!(check_of(&c, CheckKind::AngleMoves).passed);
    let assess_with = |cal: &Robot| {
        assess(&Fit {
            nominal: &c.nominal,
            start: &if c.tool_fit.applied {
                c.tool_fit.apply(&c.nominal)
            } else {
                c.nominal.clone()
            },
            calibrated: cal,
            identified: &c.identifiability.identified,
            calibration: &obs,
            registration: &c.registration,
            nominal_rms_mm: c.registration.stats.rms_mm,
            validation_before: None,
            validation_after: None,
            calibration_before: &c.calibration.before,
            downweighted: c.downweighted.len(),
            prediction_mean_mm: c.prediction.as_ref().map(|p| p.mean_mm),
            noise_sigma_mm: c.prediction.as_ref().map(|p| p.noise_sigma_mm),
            solver: c.solver(),
            max_iterations: 1000,
        })
    };
    let mut moved = c.calibrated.clone();
    moved.set(Param::a(2), moved.get(Param::a(2)) + 300.0);
    let p = assess_with(&moved);
    let k = p
        .checks
        .iter()
        .find(|k| k.kind == CheckKind::LengthMoves)
        .unwrap();
    assert!(!k.passed && k.detail.contains("a3"), "{}", k.detail);
    assert!(k.cause.as_deref().unwrap().contains("hardly determine"));
    let mut turned = c.calibrated.clone();
    turned.set(
        Param::phi(1),
        turned.get(Param::phi(1)) + 20f64.to_radians(),
    );
    let p = assess_with(&turned);
    let k = p
        .checks
        .iter()
        .find(|k| k.kind == CheckKind::AngleMoves)
        .unwrap();
    assert!(!k.passed && k.detail.contains("phi2"), "{}", k.detail);
    assert!((k.measured - 20.0).abs() < 0.5, "{}", k.measured);
    // A full turn is no move.
    let mut wrapped = c.calibrated.clone();
    wrapped.set(
        Param::phi(1),
        wrapped.get(Param::phi(1)) + std::f64::consts::TAU,
    );
    assert!(assess_with(&wrapped).passed());
}

#[test]
fn convergence_check_marks_a_partial_fit_not_an_implausible_one() {
    let cell = kuka_cell();
    let s = CalibrationSettings {
        solver: SolverOptions {
            max_iterations: 1,
            ..Default::default()
        },
        ..Default::default()
    };
    let c = fit_with(&kuka(), &cell.good(), None, &s);
    let k = check_of(&c, CheckKind::Convergence);
    assert!(!k.passed && k.limit == 1.0, "{}", k.detail);
    assert!(k.cause.as_deref().unwrap().contains("iteration limit (1)"));
    assert!(!c.plausibility.passed() && !c.plausibility.implausible());
    let r = serde_json::to_value(c.to_result()).unwrap();
    assert_eq!(r["status"], STATUS_PARTIAL);
    // And a converged fit passes it.
    let c = fit(&kuka(), &cell.good(), None);
    assert!(check_of(&c, CheckKind::Convergence).passed);
}

#[test]
fn an_implausible_fit_is_marked_in_the_result_and_read_back_as_such() {
    let cell = kuka_cell();
    let c = fit(&kuka(), &cell.obs(|q| q.to_vec(), |m| m / 1000.0), None);
    let r = c.to_result();
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["status"], STATUS_IMPLAUSIBLE);
    let p = &json["plausibility"];
    assert_eq!(p["passed"], false);
    let checks = p["checks"].as_array().unwrap();
    let units = checks.iter().find(|k| k["name"] == "units").unwrap();
    assert_eq!(units["passed"], false);
    assert!(units["measured"].as_f64().unwrap() > 900.0);
    assert_eq!(units["limit"], SCALE_LIMIT);
    assert!(units["cause"].as_str().unwrap().contains("metres"));
    assert!(p["likely_causes"][0]["cause"]
        .as_str()
        .unwrap()
        .contains("metres"));
    // Every check has its name, value, limit and outcome.
    for k in checks {
        for key in ["name", "measured", "limit", "unit", "passed", "detail"] {
            assert!(k.get(key).is_some(), "{key} missing in {k}");
        }
    }
    let text = serde_json::to_string(&r).unwrap();
    let back = CalibrationResult::parse(&text, Path::new("r.json")).unwrap();
    assert!(back.partial_reason().is_none());
    match back.not_calibrated() {
        Some(NotCalibrated::Implausible(why)) => {
            assert!(why.contains("units:") && why.contains("metres"), "{why}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_gate_passes_the_demo_for_seeds_1_to_30() {
    for seed in 1..=30 {
        let e = run_experiment(ExperimentConfig::paper(seed).unwrap(), &())
            .unwrap_or_else(|err| panic!("seed {seed}: {err}"));
        let p = &e.calibration.plausibility;
        assert!(p.passed(), "seed {seed}: {}", p.summary());
        // With a wide margin: Table II under a tenth of its limit, the scale within 0.1%.
        let nominal = check_of(&e.calibration, CheckKind::NominalError);
        assert!(
            nominal.measured < 0.1 * nominal.limit,
            "seed {seed}: {}",
            nominal.detail
        );
        assert!(check_of(&e.calibration, CheckKind::Units).measured < 1.001);
        assert_eq!(
            serde_json::to_value(&e.result).unwrap()["status"],
            "calibrated"
        );
    }
}

/// The statistical checks on a good fit pass; a calibrated model worse than its start on the
/// validation points, and residuals far beyond the points' uncertainty, fail with their causes.
#[test]
fn statistical_checks_catch_a_worse_model_and_unexplained_residuals() {
    let cell = kuka_cell();
    let obs = cell.good();
    let c = fit(&kuka(), &obs, None);
    for k in [
        CheckKind::Improvement,
        CheckKind::DiscardedPoints,
        CheckKind::Residuals,
        CheckKind::WeightShare,
        CheckKind::ParameterRanges,
    ] {
        assert!(
            check_of(&c, k).passed,
            "{:?}: {}",
            k,
            check_of(&c, k).detail
        );
    }
    let start = if c.tool_fit.applied {
        c.tool_fit.apply(&c.nominal)
    } else {
        c.nominal.clone()
    };
    let before = vec![1.0; 10];
    let after = vec![1.5; 10];
    let weighted = {
        let mut o = obs.clone();
        o.set_sigmas(Some(vec![0.001; o.len()])).unwrap();
        o
    };
    let p = assess(&Fit {
        nominal: &c.nominal,
        start: &start,
        calibrated: &c.calibrated,
        identified: &c.identifiability.identified,
        calibration: &weighted,
        registration: &c.registration,
        nominal_rms_mm: c.registration.stats.rms_mm,
        validation_before: Some(&before),
        validation_after: Some(&after),
        calibration_before: &c.calibration.before,
        downweighted: 0,
        prediction_mean_mm: None,
        noise_sigma_mm: Some(0.05),
        solver: c.solver(),
        max_iterations: 1000,
    });
    let imp = p
        .checks
        .iter()
        .find(|k| k.kind == CheckKind::Improvement)
        .unwrap();
    assert!(
        !imp.passed && (imp.measured - 1.5).abs() < 1e-12,
        "{}",
        imp.detail
    );
    assert!(imp.cause.as_deref().unwrap().contains("pulled away"));
    // 0.05 mm of residual noise against points claimed certain to 0.001 mm: 50 times.
    let res = p
        .checks
        .iter()
        .find(|k| k.kind == CheckKind::Residuals)
        .unwrap();
    assert!(
        !res.passed && (res.measured - 50.0).abs() < 1e-9,
        "{}",
        res.detail
    );
    assert!(p.implausible());
}
