//! Several reflectors per pose, 6-DoF measurements, weighted fitting and unknown tools
//! (DESIGN.md, "Measurement CSV additions"), end to end on simulated data.

use super::Observations;
use super::{calibrate, CalibrationData, CalibrationSettings};
use crate::identification::objective::Objective;
use crate::model::family::reflector;
use crate::model::presets::preset;
use crate::model::{Param, Robot};
use crate::observations::{RowExtras, TrackerSigma, Weighting};
use crate::simulation::{random_poses, Tracker};
use nalgebra::{Matrix3, Rotation3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

use super::tests::{sampler, tracker};

/// Three reflectors on the KUKA's tool plate (nominal tool vectors, mm and rad).
fn tools(robot: &Robot) -> Vec<[f64; 6]> {
    let t0 = *robot.tool0();
    let shifted = |dx: f64, dy: f64, dz: f64| {
        let mut t = t0;
        t[0] += dx;
        t[1] += dy;
        t[2] += dz;
        t
    };
    vec![t0, shifted(180.0, 0.0, -40.0), shifted(-20.0, 160.0, -70.0)]
}

/// The paper's calibrated KUKA (Table III) with d6 and phi6 at their nominal values: the tool
/// vectors absorb both (they are never identified), so the truth's tool parameters are then the
/// ones a calibration must find.
fn table3() -> Robot {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let mut truth = preset("kuka-kr480-r3330-table3").unwrap();
    for p in [Param::d(5), Param::phi(5)] {
        truth.set(p, nominal.get(p));
    }
    truth
}

/// The nominal KUKA with three targets, and the truth (the paper's Table III) whose reflectors
/// sit a little off their nominal places.
fn robots() -> (Robot, Robot) {
    let mut nominal = preset("kuka-kr480-r3330").unwrap();
    nominal.set_target_tools(&tools(&nominal)).unwrap();
    let mut truth = table3();
    truth.set_target_tools(&tools(&nominal)).unwrap();
    for (t, off) in [(1, [1.3, -0.7, 0.9]), (2, [-0.6, 1.1, -1.4])] {
        for (k, v) in off.iter().enumerate() {
            truth.set(reflector::param(t, k), *v);
        }
    }
    (nominal, truth)
}

/// Every target of `truth` measured at each pose (noise per `tr`).
fn measure_all(
    truth: &Robot,
    tr: &Tracker,
    qs: &[Vec<f64>],
    targets: &[usize],
    rng: &mut ChaCha8Rng,
) -> Observations {
    let mut obs = Observations::new(truth.dof());
    for (i, q) in qs.iter().enumerate() {
        for &t in targets {
            let m = tr.measure(&truth.target_position(q, t), rng);
            let extras = RowExtras {
                target: t,
                ..Default::default()
            };
            obs.push_with(q, m, extras, i + 2).unwrap();
        }
    }
    obs
}

/// Calibrates `nominal` on `cal`, validated on `val`.
fn run(
    nominal: &Robot,
    cal: &Observations,
    val: &Observations,
    settings: &CalibrationSettings,
) -> super::pipeline::Calibration {
    let data = CalibrationData {
        calibration: cal,
        plane: None,
        validation: Some(val),
    };
    calibrate(nominal, data, settings, &()).unwrap()
}

fn ls() -> CalibrationSettings {
    CalibrationSettings {
        objective: Objective::LeastSquares,
        ..Default::default()
    }
}

/// Mean distance between the calibrated model (with its tracker frame) and the measurements.
fn validation_mean(c: &super::pipeline::Calibration) -> f64 {
    c.validation.as_ref().unwrap().after_stats().mean_mm
}

#[test]
fn three_reflectors_noise_free_are_recovered_exactly() {
    let (nominal, truth) = robots();
    let tr = tracker(0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let qs = random_poses(&truth, 40, &sampler(), &mut rng).unwrap();
    let vq = random_poses(&truth, 20, &sampler(), &mut rng).unwrap();
    let cal = measure_all(&truth, &tr, &qs, &[0, 1, 2], &mut rng);
    let val = measure_all(&truth, &tr, &vq, &[0, 1, 2], &mut rng);
    // Stacked targets are one pose seen three times, not duplicated poses.
    cal.check_no_duplicate_poses().unwrap();
    let c = run(&nominal, &cal, &val, &ls());
    let v = c.validation.as_ref().unwrap().after_stats();
    assert!(v.max_mm < 1e-6, "validation max {} mm", v.max_mm);
    for t in 1..3 {
        for k in 0..3 {
            let p = reflector::param(t, k);
            let (got, want) = (c.calibrated.get(p), truth.get(p));
            assert!((got - want).abs() < 1e-6, "{p}: {got} vs {want}");
        }
    }
    // The names and units of the new family.
    assert_eq!(reflector::param(2, 1).name(), "tool3_y");
    assert_eq!(Param::parse("tool2_c"), Some(reflector::param(1, 5)));
}

#[test]
fn three_reflectors_beat_single_reflector_calibrations() {
    let (nominal, truth) = robots();
    let tr = tracker(0.02, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let qs = random_poses(&truth, 50, &sampler(), &mut rng).unwrap();
    let vq = random_poses(&truth, 60, &sampler(), &mut rng).unwrap();
    let cal = measure_all(&truth, &tr, &qs, &[0, 1, 2], &mut rng);
    let val = measure_all(&truth, &tr, &vq, &[0, 1, 2], &mut rng);
    let joint = run(&nominal, &cal, &val, &ls());
    // Each reflector on its own: a one-target robot whose tool is that reflector's.
    let mut singles = Vec::new();
    for t in 0..3 {
        let mut one = preset("kuka-kr480-r3330").unwrap();
        one.set_target_tools(&[tools(&nominal)[t]]).unwrap();
        let pick = |o: &Observations| {
            let mut out = Observations::new(o.dof());
            for i in (0..o.len()).filter(|&i| o.target(i) == t) {
                out.push(o.q(i), *o.m(i), o.line(i)).unwrap();
            }
            out
        };
        let (c1, v1) = (pick(&cal), pick(&val));
        let c = run(&one, &c1, &v1, &ls());
        singles.push(validation_mean(&c));
    }
    let mean_single = singles.iter().sum::<f64>() / 3.0;
    let j = validation_mean(&joint);
    eprintln!("three reflectors: joint {j:.5} mm, single {singles:.5?} mm");
    assert!(
        j < mean_single,
        "joint {j:.5} mm against single-reflector {singles:?} (mean {mean_single:.5})"
    );
    // Every reflector offset within 3 standard deviations of the truth.
    for t in 0..3 {
        for k in 0..3 {
            let p = if t == 0 {
                Param::tool(k)
            } else {
                reflector::param(t, k)
            };
            let std = joint.covariance.std_of(p).expect("identified");
            let (got, want) = (joint.calibrated.get(p), truth.get(p));
            assert!(
                (got - want).abs() <= 3.0 * std,
                "{p}: {got:.4} vs truth {want:.4} (std {std:.4})"
            );
        }
    }
}

/// 6-DoF readings of target 0: the tracker's point noise, and the orientation turned by a
/// random rotation of `sigma_deg` per axis.
fn measure_frames(
    truth: &Robot,
    tr: &Tracker,
    qs: &[Vec<f64>],
    sigma_deg: f64,
    rng: &mut ChaCha8Rng,
) -> Observations {
    let mut obs = Observations::new(truth.dof());
    let rf = tr.frame.pose().rotation;
    for (i, q) in qs.iter().enumerate() {
        let f = truth.tool_pose(q);
        let m = tr.measure(&f.translation.vector, rng);
        let mut v = Vector3::zeros();
        for k in 0..3 {
            let z: f64 = StandardNormal.sample(rng);
            v[k] = sigma_deg.to_radians() * z;
        }
        let r: Matrix3<f64> = *(Rotation3::new(v) * rf.inverse() * f.rotation).matrix();
        let extras = RowExtras {
            rotation: Some(r),
            ..Default::default()
        };
        obs.push_with(q, m, extras, i + 2).unwrap();
    }
    obs
}

fn positions_only(o: &Observations) -> Observations {
    let mut out = Observations::new(o.dof());
    for i in 0..o.len() {
        out.push(o.q(i), *o.m(i), o.line(i)).unwrap();
    }
    out
}

#[test]
fn six_dof_recovers_the_tool_orientation() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let mut truth = table3();
    // The tool frame turned off its nominal orientation (deg): only orientation data see it.
    for (k, v) in [(3, 0.8), (4, -0.5), (5, 1.2)] {
        truth.set(
            Param::tool(k),
            truth.get(Param::tool(k)) + f64::to_radians(v),
        );
    }
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let qs = random_poses(&truth, 40, &sampler(), &mut rng).unwrap();
    let vq = random_poses(&truth, 30, &sampler(), &mut rng).unwrap();
    // Noise-free: exact.
    let tr0 = tracker(0.0, 0.0);
    let cal = measure_frames(&truth, &tr0, &qs, 0.0, &mut rng);
    let val = measure_frames(&truth, &tr0, &vq, 0.0, &mut rng);
    assert_eq!(cal.kind().key(), "pose6");
    let c = run(&nominal, &cal, &val, &ls());
    for k in 3..6 {
        let p = Param::tool(k);
        assert!(
            c.identifiability.fixed_reason(p).is_none(),
            "{p} fixed: {:?}",
            c.identifiability.fixed
        );
        let d = (c.calibrated.get(p) - truth.get(p)).to_degrees();
        assert!(d.abs() < 1e-6, "{p}: off by {d:e} deg");
    }
    let v = c.validation.as_ref().unwrap();
    assert!(v.after_stats().max_mm < 1e-6);
    let (_, after) = v.orientation_deg.as_ref().expect("orientation errors");
    assert!(
        after.iter().all(|e| *e < 1e-6),
        "orientation after {after:?}"
    );

    // Noisy: within 3 std, and the position validation no worse than position-only.
    let tr = tracker(0.02, 0.005);
    let cal = measure_frames(&truth, &tr, &qs, 0.005, &mut rng);
    let val = measure_frames(&truth, &tr, &vq, 0.005, &mut rng);
    let data = |c, v| CalibrationData {
        calibration: c,
        plane: None,
        validation: Some(v),
    };
    let six = calibrate(&nominal, data(&cal, &val), &ls(), &()).unwrap();
    for k in 3..6 {
        let p = Param::tool(k);
        let std = six.covariance.std_of(p).unwrap();
        let d = six.calibrated.get(p) - truth.get(p);
        assert!(d.abs() <= 3.0 * std, "{p}: off by {d:e} rad, std {std:e}");
    }
    let (pc, pv) = (positions_only(&cal), positions_only(&val));
    let three = calibrate(&nominal, data(&pc, &pv), &ls(), &()).unwrap();
    let (a, b) = (validation_mean(&six), validation_mean(&three));
    eprintln!("6-DoF: validation {a:.5} mm, position-only {b:.5} mm");
    assert!(
        a <= b * 1.02,
        "6-DoF {a:.5} mm against position-only {b:.5} mm"
    );
}

#[test]
fn a_zero_nominal_tool_gives_the_same_calibration_as_a_good_one() {
    let good = preset("kuka-kr480-r3330").unwrap();
    let mut zero = good.clone();
    zero.set_target_tools(&[[0.0; 6]]).unwrap();
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let tr = tracker(0.02, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    let qs = random_poses(&truth, 75, &sampler(), &mut rng).unwrap();
    let vq = random_poses(&truth, 40, &sampler(), &mut rng).unwrap();
    let cal = measure_all(&truth, &tr, &qs, &[0], &mut rng);
    let val = measure_all(&truth, &tr, &vq, &[0], &mut rng);
    let data = CalibrationData {
        calibration: &cal,
        plane: None,
        validation: Some(&val),
    };
    let settings = CalibrationSettings::default();
    let a = calibrate(&good, data, &settings, &()).unwrap();
    let b = calibrate(&zero, data, &settings, &()).unwrap();
    assert_eq!(a.identifiability.identified, b.identifiability.identified);
    let (va, vb) = (
        &a.validation.as_ref().unwrap().after,
        &b.validation.as_ref().unwrap().after,
    );
    let worst = va
        .iter()
        .zip(vb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    eprintln!("zero nominal tool: validation differs by at most {worst:.2e} mm");
    assert!(worst < 1e-3, "validation differs by {worst} mm");
    // The fitted tool is the good one, whatever the guess.
    for k in 0..3 {
        let t = b.tool_fit.tools[0][k];
        assert!((t - good.tool0()[k]).abs() < 5.0, "tool {k}: {t}");
    }
}

/// Weighted least squares with distance-dependent noise: validation no worse than unweighted,
/// and the standard deviations agree with the spread of the estimates over seeds.
#[test]
fn weighting_by_the_tracker_model_is_efficient_and_honest() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    // Strongly distance-dependent noise: 5 um + 40 um/m (the tracker is 2-7 m away).
    let tr = tracker(0.005, 0.04);
    let weighted = CalibrationSettings {
        objective: Objective::LeastSquares,
        weighting: Weighting {
            tracker: Some(TrackerSigma::new(0.005, 0.04).unwrap()),
            ..Default::default()
        },
        ..Default::default()
    };
    let seeds = 40;
    let (mut vw, mut vu) = (0.0, 0.0);
    let probe = Param::a(1);
    let mut est = Vec::new();
    let mut stds = Vec::new();
    for seed in 0..seeds {
        let mut rng = ChaCha8Rng::seed_from_u64(100 + seed);
        let qs = random_poses(&truth, 75, &sampler(), &mut rng).unwrap();
        let vq = random_poses(&truth, 60, &sampler(), &mut rng).unwrap();
        let cal = measure_all(&truth, &tr, &qs, &[0], &mut rng);
        let val = measure_all(&truth, &tr, &vq, &[0], &mut rng);
        let data = CalibrationData {
            calibration: &cal,
            plane: None,
            validation: Some(&val),
        };
        let w = calibrate(&nominal, data, &weighted, &()).unwrap();
        let u = calibrate(&nominal, data, &ls(), &()).unwrap();
        // Validation against the truth itself (noise-free), so the comparison is the models'.
        let exact = |c: &super::pipeline::Calibration| {
            vq.iter()
                .map(|q| {
                    let f = c.tracker_frame().pose() * tr.frame.pose().inverse();
                    (f * nalgebra::Point3::from(truth.tool_position(q))
                        - nalgebra::Point3::from(c.calibrated.tool_position(q)))
                    .norm()
                })
                .sum::<f64>()
                / vq.len() as f64
        };
        vw += exact(&w);
        vu += exact(&u);
        est.push(w.calibrated.get(probe));
        stds.push(w.covariance.std_of(probe).unwrap());
    }
    let (vw, vu) = (vw / seeds as f64, vu / seeds as f64);
    assert!(
        vw <= vu,
        "weighted {vw:.5} mm against unweighted {vu:.5} mm"
    );
    let mean = est.iter().sum::<f64>() / seeds as f64;
    let spread =
        (est.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (seeds as f64 - 1.0)).sqrt();
    let predicted = stds.iter().sum::<f64>() / seeds as f64;
    // 40 seeds: the sample std's own relative uncertainty is 1/sqrt(2*39) = 11%; 20% is about
    // two of those.
    let ratio = predicted / spread;
    eprintln!(
        "weighting: weighted {vw:.5} mm, unweighted {vu:.5} mm against the truth; std of a2 \
         predicted {predicted:.3e}, Monte Carlo {spread:.3e} (ratio {ratio:.3})"
    );
    assert!(
        (0.8..1.25).contains(&ratio),
        "predicted std {predicted:e} against Monte Carlo spread {spread:e} (ratio {ratio:.3})"
    );
}
