//! Constraint calibration on simulated KR 480 cells: derivatives against finite differences,
//! exact recovery on noise-free data in each mode, the Monte Carlo accuracy of the issue's
//! fixed-point set-up, and the refusals.

use super::*;
use crate::model::presets::preset;
use crate::observations::constraint::ConstraintKind;
use crate::simulation::constraint::{
    aligned_model_error, simulate_constraints, ConstraintSimulation, SimulatedConstraints,
};
use crate::simulation::{random_poses, GeometricErrors, PoseSampler};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::path::Path;

pub(super) fn nominal() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn sampler() -> PoseSampler {
    PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    }
}

pub(super) fn truth(seed: u64) -> Robot {
    let mut rng = ChaCha8Rng::seed_from_u64(1000 + seed);
    GeometricErrors::default()
        .apply(&nominal(), &mut rng)
        .unwrap()
}

pub(super) fn simulate(truth: &Robot, spec: &ConstraintSimulation) -> SimulatedConstraints {
    simulate_constraints(truth, &sampler(), spec).unwrap()
}

pub(super) fn spec(kind: ConstraintKind, noise_mm: f64, seed: u64) -> ConstraintSimulation {
    ConstraintSimulation {
        kind,
        noise_mm,
        seed,
        ..ConstraintSimulation::default()
    }
}

/// 300 random poses of the robot (the validation of every figure).
pub(super) fn check_poses(seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(7000 + seed);
    random_poses(&nominal(), 300, &sampler(), &mut rng).unwrap()
}

#[test]
fn analytic_derivatives_match_finite_differences() {
    // Every kind of row and a distance, at a point away from the solution.
    let t = truth(1);
    let mut data = simulate(&t, &spec(ConstraintKind::Point, 0.01, 1)).data;
    for (kind, radius_known) in [
        (ConstraintKind::Sphere, false),
        (ConstraintKind::Plane, false),
    ] {
        let extra = simulate(
            &t,
            &ConstraintSimulation {
                kind,
                features: 1,
                per_feature: 6,
                radius_known,
                seed: 2,
                ..ConstraintSimulation::default()
            },
        )
        .data;
        let f = data
            .feature_index(kind, &format!("extra{}", kind.key()), None, 0)
            .unwrap();
        for r in extra.rows {
            data.push(r.q, f, 0).unwrap();
        }
    }
    let robot = nominal();
    let features = start_values(&robot, &data).unwrap();
    let params: Vec<Param> = robot
        .param_list()
        .iter()
        .filter(|p| p.family_id() != Param::base(0).family_id())
        .copied()
        .collect();
    let layout = Layout::new(&robot, &params, &features);
    let (_, j) = fit::evaluate(&robot, &layout, &data, &features, None, true);
    let j = j.unwrap();
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for c in 0..layout.n {
        let shifted = |s: f64| {
            let mut r = robot.clone();
            let mut f = features.clone();
            if c < params.len() {
                r.set(params[c], r.get(params[c]) + s);
            } else {
                let k = layout.feature_col.iter().rposition(|&c0| c0 <= c).unwrap();
                let mut dx = vec![0.0; f[k].param_count()];
                dx[c - layout.feature_col[k]] = s;
                f[k].apply(&dx);
            }
            fit::evaluate(&r, &layout, &data, &f, None, false).0
        };
        let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
        let scale = fd.amax().max(1.0);
        worst = worst.max((&fd - j.column(c)).amax() / scale);
    }
    assert!(worst < 1e-5, "largest relative derivative error {worst:e}");
}

/// Calibrates noise-free data of a truth that differs from the nominal only in what the data
/// can identify (the fixed parameters, found by a first calibration, set to nominal in the
/// truth): the identified parameters and the features must come back exactly.
fn exact_recovery(kind: ConstraintKind, opts: &ConstraintOptions, s: ConstraintSimulation) {
    let nom = nominal();
    let mut t = truth(3);
    let first = calibrate_constraints(&nom, &simulate(&t, &s).data, opts).unwrap();
    for f in &first.fixed {
        t.set(f.param, nom.get(f.param));
    }
    let sim = simulate(&t, &s);
    let cal = calibrate_constraints(&nom, &sim.data, opts).unwrap();
    assert!(cal.fit.converged, "{kind:?}");
    assert!(
        cal.residual_rms_mm < 1e-7,
        "{kind:?}: rms {}",
        cal.residual_rms_mm
    );
    for p in &cal.identified {
        let (got, want) = (cal.robot.get(*p), t.get(*p));
        assert!(
            (got - want).abs() < 1e-6,
            "{kind:?} {}: {got} against {want}",
            p.name()
        );
    }
    for (k, (f, want)) in cal.features.iter().zip(&sim.true_positions).enumerate() {
        match kind {
            ConstraintKind::Plane => {
                let n = f.normal.unwrap();
                let tn = sim.true_normals[k].unwrap();
                assert!(n.cross(&tn).norm() < 1e-9, "plane normal {n} against {tn}");
                assert!((n.dot(want) - f.offset_mm.unwrap()).abs() < 1e-6);
            }
            _ => assert!((f.position - want).norm() < 1e-6, "{}", f.label()),
        }
    }
    // The base is always named; nothing of the base is identified.
    assert!(cal.unseen[0].contains("base pose"));
    assert!(cal
        .identified
        .iter()
        .all(|p| p.family_id() != Param::base(0).family_id()));
    let (mean, _) = aligned_model_error(&cal.robot, &t, &check_poses(1)).unwrap();
    assert!(mean < 1e-6, "{kind:?}: aligned model error {mean}");
}

#[test]
fn noise_free_fixed_points_with_distances_are_recovered_exactly() {
    exact_recovery(
        ConstraintKind::Point,
        &ConstraintOptions::default(),
        spec(ConstraintKind::Point, 0.0, 3),
    );
}

#[test]
fn noise_free_spheres_of_known_radius_are_recovered_exactly() {
    let s = ConstraintSimulation {
        distances: false,
        ..spec(ConstraintKind::Sphere, 0.0, 4)
    };
    exact_recovery(ConstraintKind::Sphere, &ConstraintOptions::default(), s);
}

#[test]
fn noise_free_spheres_of_unknown_radius_with_distances_are_recovered_exactly() {
    let s = ConstraintSimulation {
        radius_known: false,
        ..spec(ConstraintKind::Sphere, 0.0, 5)
    };
    exact_recovery(ConstraintKind::Sphere, &ConstraintOptions::default(), s);
}

#[test]
fn noise_free_planes_up_to_scale_are_recovered_exactly_and_say_so() {
    let opts = ConstraintOptions {
        accept_unknown_scale: true,
        ..ConstraintOptions::default()
    };
    let s = ConstraintSimulation {
        features: 3,
        per_feature: 40,
        ..spec(ConstraintKind::Plane, 0.0, 6)
    };
    exact_recovery(ConstraintKind::Plane, &opts, s.clone());
    let cal = calibrate_constraints(&nominal(), &simulate(&truth(3), &s).data, &opts).unwrap();
    assert!(matches!(cal.scale, Scale::Assumed { .. }));
    assert!(
        cal.unseen.iter().any(|u| u.contains("scale")),
        "{:?}",
        cal.unseen
    );
}

#[test]
fn without_a_known_length_the_scale_is_refused() {
    let t = truth(1);
    let s = ConstraintSimulation {
        distances: false,
        ..spec(ConstraintKind::Point, 0.01, 1)
    };
    let e = calibrate_constraints(
        &nominal(),
        &simulate(&t, &s).data,
        &ConstraintOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("scale is not determined") && e.contains("known distance"),
        "{e}"
    );
    // Accepted explicitly: the residuals look perfect, the model is off.
    let opts = ConstraintOptions {
        accept_unknown_scale: true,
        ..ConstraintOptions::default()
    };
    let cal = calibrate_constraints(&nominal(), &simulate(&t, &s).data, &opts).unwrap();
    let (mean, _) = aligned_model_error(&cal.robot, &t, &check_poses(1)).unwrap();
    eprintln!(
        "fixed points without distances: residual rms {:.4} mm, model error {mean:.3} mm mean",
        cal.residual_rms_mm
    );
    assert!(cal.residual_rms_mm < 0.03);
}

#[test]
fn a_plane_whose_points_are_collinear_is_an_error() {
    let mut data = ConstraintData::new(6);
    let robot = nominal();
    let f = data
        .feature_index(ConstraintKind::Plane, "F", None, 2)
        .unwrap();
    // Joint 1 only moves: the tool points lie on a circle, not a line; joint 2 alone near
    // the stretched arm moves them on a near-line. Use the tool point moved along one line by
    // joint 2 and 3 together instead: collinear by construction, through IK of the nominal.
    let ik =
        crate::compensation::Compensator::new(&robot, &robot, crate::DampedLeastSquares::default())
            .unwrap();
    let start = vec![
        0.0,
        -90f64.to_radians(),
        90f64.to_radians(),
        0.0,
        30f64.to_radians(),
        0.0,
    ];
    let p0 = robot.tool_position(&start);
    for k in 0..5 {
        let mut q = vec![0.0; 6];
        let target = p0 + nalgebra::Vector3::new(100.0 * k as f64, 0.0, 0.0);
        ik.reach(&target, Some(&start), &mut q);
        data.push(q, f, k + 2).unwrap();
    }
    let e = calibrate_constraints(
        &robot,
        &data,
        &ConstraintOptions {
            accept_unknown_scale: true,
            ..ConstraintOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("collinear") && e.contains(":2:") && e.contains("plane `F`"),
        "{e}"
    );
}

/// The set-up: KR 480, 4 fixed points x 20 configurations, the 6 distances known,
/// 0.01 mm noise; model error against the truth over 300 random poses after the best rigid
/// alignment, over ten seeds (the configurations are random: 0.012 to 0.046 mm per seed
/// measured, 0.026 mm on average; the tool tilted up to 60 degrees about its reference
/// orientation).
#[test]
fn kr480_fixed_points_with_distances_reach_three_hundredths() {
    let mut means = Vec::new();
    for seed in 1..=10 {
        let t = truth(seed);
        let sim = simulate(&t, &spec(ConstraintKind::Point, 0.01, seed));
        assert_eq!(sim.data.rows.len(), 80);
        assert_eq!(sim.data.distances.len(), 6);
        let cal =
            calibrate_constraints(&nominal(), &sim.data, &ConstraintOptions::default()).unwrap();
        let (mean, max) = aligned_model_error(&cal.robot, &t, &check_poses(seed)).unwrap();
        let (before, _) = aligned_model_error(&nominal(), &t, &check_poses(seed)).unwrap();
        eprintln!(
            "seed {seed}: nominal {before:.3} mm -> calibrated {mean:.4} mm mean, {max:.4} mm max \
             (residual rms {:.4} mm, {} parameters identified, condition {:.0})",
            cal.residual_rms_mm,
            cal.identified.len(),
            cal.condition_number
        );
        means.push(mean);
    }
    let avg = means.iter().sum::<f64>() / means.len() as f64;
    assert!(
        avg <= 0.03,
        "mean model error over seeds {avg:.4} mm ({means:?})"
    );
    // Random configurations vary: no seed far off.
    assert!(means.iter().all(|m| *m <= 0.06), "{means:?}");
}

/// The tracker's figure at `n` random poses, 0.01 mm noise per axis: the pipeline's calibration
/// of the geometric model, error against the truth after the same rigid alignment.
fn tracker_error(t: &Robot, n: usize, seed: u64) -> f64 {
    use crate::frame::{pose, TrackerFrame};
    use crate::identification::{calibrate, CalibrationData, CalibrationSettings};
    let tr = crate::simulation::Tracker::new(
        TrackerFrame::new(pose(&[3900.0, -2200.0, -350.0, 2.6, 0.007, -0.012])),
        0.01,
        0.0,
    )
    .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(9000 + seed);
    let qs = random_poses(t, n, &sampler(), &mut rng).unwrap();
    let mut obs = crate::observations::Observations::new(6);
    for (i, q) in qs.iter().enumerate() {
        obs.push(q, tr.measure(&t.tool_position(q), &mut rng), i + 2)
            .unwrap();
    }
    let cal = calibrate(
        &nominal(),
        CalibrationData {
            calibration: &obs,
            plane: None,
            validation: None,
        },
        &CalibrationSettings::default(),
        &(),
    )
    .unwrap();
    aligned_model_error(&cal.calibrated, t, &check_poses(seed))
        .unwrap()
        .0
}

/// Sphere (known radius) and plane data beside the tracker's at the same number of poses
/// (80: 4 features x 20), 0.01 mm noise, three seeds. The figures are printed (`--nocapture`)
/// for the note; the bounds only guard against a regression. A sphere's radius is a
/// short ruler: with 25 mm the scale is known to about 0.01 / 25 / sqrt(80), some 0.1 mm at
/// the KR 480's reach, so a larger sphere or known distances between centres do better.
#[test]
fn spheres_and_planes_beside_the_tracker_at_80_poses() {
    let up_to_scale = ConstraintOptions {
        accept_unknown_scale: true,
        ..ConstraintOptions::default()
    };
    let mut rows = Vec::new();
    for seed in 1..=3 {
        let t = truth(seed);
        let poses = check_poses(seed);
        let error = |s: ConstraintSimulation, o: &ConstraintOptions| {
            let cal = calibrate_constraints(&nominal(), &simulate(&t, &s).data, o).unwrap();
            aligned_model_error(&cal.robot, &t, &poses).unwrap().0
        };
        let sphere = |radius_mm: f64, distances: bool| ConstraintSimulation {
            radius_mm,
            distances,
            ..spec(ConstraintKind::Sphere, 0.01, seed)
        };
        let r25 = error(sphere(25.0, false), &Default::default());
        let r150 = error(sphere(150.0, false), &Default::default());
        let r25d = error(sphere(25.0, true), &Default::default());
        let plane = error(
            ConstraintSimulation {
                span_mm: 400.0,
                ..spec(ConstraintKind::Plane, 0.01, seed)
            },
            &up_to_scale,
        );
        let tracker = tracker_error(&t, 80, seed);
        let nom = aligned_model_error(&nominal(), &t, &poses).unwrap().0;
        eprintln!(
            "seed {seed}: nominal {nom:.3} mm; tracker {tracker:.4}; spheres r=25 {r25:.4}, \
             r=150 {r150:.4}, r=25 + 6 distances {r25d:.4}; planes (scale held) {plane:.4} mm"
        );
        rows.push([tracker, r25, r150, r25d, plane, nom]);
    }
    for [tracker, r25, r150, r25d, plane, nom] in rows {
        assert!(tracker < 0.02, "tracker {tracker}");
        assert!(
            r150 < r25 && r25 < 0.25 * nom,
            "spheres r=25 {r25}, r=150 {r150}"
        );
        assert!(r25d < 0.06, "spheres with distances {r25d}");
        // Planes hold the scale at a nominal length (0.5 mm errors): better than nominal,
        // worse than the rest.
        assert!(plane < 0.6 * nom, "planes {plane} against nominal {nom}");
    }
}

#[test]
fn the_gate_flags_a_parameter_moved_beyond_its_plausible_range() {
    // The truth's a2 5% of the reach longer than the nominal's: a wrong robot, not an error.
    let nom = nominal();
    let mut t = truth(2);
    let a2 = Param::a(1);
    t.set(a2, t.get(a2) + 0.06 * nom.reach_mm());
    let sim = simulate(&t, &spec(ConstraintKind::Point, 0.01, 2));
    let cal = calibrate_constraints(&nom, &sim.data, &ConstraintOptions::default()).unwrap();
    assert!(
        cal.implausible.iter().any(|m| m.starts_with("a2 moved")),
        "{:?}",
        cal.implausible
    );
    let good = calibrate_constraints(
        &nom,
        &simulate(&truth(2), &spec(ConstraintKind::Point, 0.01, 2)).data,
        &ConstraintOptions::default(),
    )
    .unwrap();
    assert!(good.implausible.is_empty(), "{:?}", good.implausible);
}

/// Tracker rows of the true robot `t` at `n` random poses, measured from the tracker frame
/// `frame` (a base point `p` reads `frame^-1 p`), noise-free.
fn tracker_rows(
    t: &Robot,
    frame: &crate::frame::Frame,
    n: usize,
    seed: u64,
) -> Vec<crate::observations::constraint::TrackerRow> {
    let mut rng = ChaCha8Rng::seed_from_u64(9500 + seed);
    random_poses(&nominal(), n, &sampler(), &mut rng)
        .unwrap()
        .into_iter()
        .enumerate()
        .map(|(i, q)| crate::observations::constraint::TrackerRow {
            m: (frame.inverse() * nalgebra::Point3::from(t.tool_position(&q))).coords,
            q,
            line: 1000 + i,
            conditions: Default::default(),
        })
        .collect()
}

fn some_frame() -> crate::frame::Frame {
    crate::frame::pose(&[2500.0, -800.0, 300.0, 0.4, -0.02, 0.03])
}

#[test]
fn the_tracker_frame_derivatives_match_finite_differences() {
    let t = truth(2);
    let mut data = simulate(&t, &spec(ConstraintKind::Point, 0.0, 2)).data;
    data.tracker = tracker_rows(&t, &some_frame(), 10, 2);
    let robot = nominal();
    let features = start_values(&robot, &data).unwrap();
    let frame = start_frame(&robot, &data).unwrap().unwrap();
    let params = vec![Param::a(1), Param::d(3)];
    let layout = Layout::new(&robot, &params, &features).with_frame();
    let (_, j) = fit::evaluate(&robot, &layout, &data, &features, Some(&frame), true);
    let j = j.unwrap();
    let c0 = layout.frame_col.unwrap();
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for c in (c0..c0 + 6).chain(0..params.len()) {
        let shifted = |s: f64| {
            let mut dx = vec![0.0; layout.n];
            dx[c] = s;
            let mut f = frame;
            fit::apply_frame(&mut f, &layout, &dx);
            let mut r = robot.clone();
            if c < params.len() {
                r.set(params[c], r.get(params[c]) + s);
            }
            fit::evaluate(&r, &layout, &data, &features, Some(&f), false).0
        };
        let fd = (shifted(h) - shifted(-h)) / (2.0 * h);
        let scale = fd.amax().max(1.0);
        worst = worst.max((&fd - j.column(c)).amax() / scale);
    }
    assert!(worst < 1e-5, "largest relative derivative error {worst:e}");
}

#[test]
fn mixed_noise_free_data_recover_the_truth_without_a_known_distance() {
    // Fixed points without distances (alone: the scale refused) and 30 tracker rows: the
    // tracker rows give the scale and register the base; the model comes back exactly.
    let t = truth(4);
    let s = ConstraintSimulation {
        distances: false,
        ..spec(ConstraintKind::Point, 0.0, 4)
    };
    let mut data = simulate(&t, &s).data;
    assert!(calibrate_constraints(&nominal(), &data, &ConstraintOptions::default()).is_err());
    let frame = some_frame();
    data.tracker = tracker_rows(&t, &frame, 30, 4);
    let cal = calibrate_constraints(&nominal(), &data, &ConstraintOptions::default()).unwrap();
    assert!(cal.fit.converged);
    assert!(
        matches!(&cal.scale, Scale::Known { from } if from.contains("30 tracker row")),
        "{:?}",
        cal.scale
    );
    assert!(cal.residual_rms_mm < 1e-7, "rms {}", cal.residual_rms_mm);
    let worst = cal.tracker_residuals_mm.iter().cloned().fold(0.0, f64::max);
    assert!(worst < 1e-7, "tracker residual {worst}");
    let (mean, _) = aligned_model_error(&cal.robot, &t, &check_poses(4)).unwrap();
    assert!(mean < 1e-6, "aligned model error {mean}");
    // The registered frame maps the readings onto the calibrated model: with the truth's base
    // error taken up by the frame, the calibrated model at a reading's joints is the reading.
    let f = cal.frame.unwrap();
    for r in &data.tracker {
        let w = f * nalgebra::Point3::from(r.m);
        assert!((w.coords - cal.robot.tool_position(&r.q)).norm() < 1e-6);
    }
    assert!(
        !cal.unseen[0].contains("up to the base pose"),
        "{:?}",
        cal.unseen
    );
    // The result file says the base pose is registered, and records the frame.
    let res = cal.to_result(&nominal(), &data).unwrap();
    let section = crate::io::result_constraint::ConstraintSection::of(&res, Path::new("r.json"))
        .unwrap()
        .unwrap();
    assert!(section.base_pose_known);
    assert_eq!(section.tracker_rows, 30);
    let back = res.tracker_frame().pose().translation.vector;
    assert!((back - f.translation.vector).norm() < 1e-9);
}
