//! End-to-end tests of registration + identification on simulated cells.

use super::*;
use crate::frame::{pose, Frame, TrackerFrame};
use crate::model::presets::preset;
use crate::model::{Param, Robot};
use crate::simulation::{random_poses, PoseSampler, Tracker};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A tracker about 4 m from the base, turned about its vertical axis and slightly tilted.
pub(super) fn tracker(sigma_mm: f64, per_m: f64) -> Tracker {
    let deg = |v: f64| v.to_radians();
    Tracker::new(
        TrackerFrame::new(pose(&[
            3900.0,
            -2200.0,
            -350.0,
            deg(152.0),
            deg(0.4),
            deg(-0.7),
        ])),
        sigma_mm,
        per_m,
    )
    .unwrap()
}

pub(super) fn sampler() -> PoseSampler {
    PoseSampler {
        floor_z_mm: 0.0,
        footprint_radius_mm: 800.0,
        max_tries_per_pose: 10_000,
    }
}

/// Measures `n` random poses of `truth` (noise per `tr`), first line number `line0`.
fn measure(truth: &Robot, tr: &Tracker, n: usize, rng: &mut ChaCha8Rng) -> Observations {
    let qs = random_poses(truth, n, &sampler(), rng).unwrap();
    let mut obs = Observations::new(truth.dof());
    for (i, q) in qs.iter().enumerate() {
        obs.push(q, tr.measure(&truth.tool_position(q), rng), i + 2)
            .unwrap();
    }
    obs
}

/// The truth's own error on a set: measurement noise only (the noise floor).
fn floor(truth: &Robot, tr: &Tracker, obs: &Observations) -> f64 {
    let e: f64 = (0..obs.len())
        .map(|i| (tr.frame.to_base(obs.m(i)) - truth.tool_position(obs.q(i))).norm())
        .sum();
    e / obs.len() as f64
}

fn nominal() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn table3() -> Robot {
    preset("kuka-kr480-r3330-table3").unwrap()
}

fn run(
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

fn settings(objective: Objective) -> CalibrationSettings {
    CalibrationSettings {
        objective,
        ..Default::default()
    }
}

/// The nominal robot with seeded random errors on every parameter but `d3` (which the 26-parameter
/// MDH set cannot carry together with a tilted axis 3; see DESIGN.md on the 27th parameter).
fn random_truth(rng: &mut ChaCha8Rng) -> Robot {
    let mut r = nominal();
    for p in r.params() {
        if p == Param::d(2) {
            continue;
        }
        let (len, ang) = (1.0, 0.05f64.to_radians());
        let dv = match p.unit() {
            crate::model::Unit::Mm => rng.gen_range(-len..len),
            crate::model::Unit::Deg => rng.gen_range(-ang..ang),
            // The geometric robots of these tests have no other units.
            _ => 0.0,
        };
        r.set(p, r.get(p) + dv);
    }
    r
}

fn names(ps: &[Param]) -> Vec<String> {
    ps.iter().map(|p| p.name()).collect()
}

#[test]
fn kuka_with_75_random_poses_identifies_26_parameters_and_explains_the_rest() {
    let nom = nominal();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let obs = measure(&nom, &tracker(0.0, 0.0), 75, &mut rng);
    let id = analyze(&nom, &obs, &IdentifiabilityOptions::default()).unwrap();
    let want = [
        "alpha2", "alpha3", "alpha4", "alpha5", "alpha6", "d2", "d4", "d5", "a2", "a3", "a4", "a5",
        "a6", "phi2", "phi3", "phi4", "phi5", "base_x", "base_y", "base_z", "base_a", "base_b",
        "base_c", "tool_x", "tool_y", "tool_z",
    ];
    assert_eq!(names(&id.identified), want);
    let reason = |n: &str| {
        id.fixed_reason(nom.param_by_name(n).unwrap())
            .unwrap_or_else(|| panic!("{n} not fixed"))
            .describe()
    };
    assert_eq!(reason("alpha1"), "same effect as base_c");
    assert_eq!(reason("a1"), "same effect as base_x");
    assert_eq!(reason("d1"), "same effect as base_z");
    assert_eq!(reason("phi1"), "same effect as base_a");
    assert_eq!(reason("d3"), "same effect as d2");
    assert_eq!(reason("d6"), "same effect as tool_z");
    let phi6 = reason("phi6");
    assert!(
        phi6.contains("combination of") && phi6.contains("tool_x") && phi6.contains("tool_y"),
        "{phi6}"
    );
    for t in ["tool_a", "tool_b", "tool_c"] {
        assert!(reason(t).starts_with("no effect on the tool point"), "{t}");
    }
    assert_eq!(id.fixed.len(), 10);
    assert!(id.condition_number.is_finite() && id.condition_number > 1.0);
    // The coefficient of an exact duplicate is exact: d1 moves the tool like base_z, one to one.
    match &id.fixed_reason(Param::d(0)).unwrap().reason {
        FixReason::Duplicate { of, independence } => {
            assert!((of[0].1 - 1.0).abs() < 1e-9, "{of:?}");
            assert!(*independence < 1e-9);
        }
        r => panic!("{r:?}"),
    }
}

#[test]
fn fix_and_free_override_the_choice() {
    let nom = nominal();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let obs = measure(&nom, &tracker(0.0, 0.0), 75, &mut rng);
    let opts = IdentifiabilityOptions {
        free: vec![Param::d(2)],
        fix: vec![Param::a(4)],
        ..Default::default()
    };
    let id = analyze(&nom, &obs, &opts).unwrap();
    assert!(id.identified.contains(&Param::d(2)));
    assert!(!id.identified.contains(&Param::d(1)));
    assert_eq!(
        id.fixed_reason(Param::d(1)).unwrap().describe(),
        "same effect as d3"
    );
    assert_eq!(
        id.fixed_reason(Param::a(4)).unwrap().describe(),
        "fixed on request"
    );
    assert_eq!(id.identified.len(), 25);
    // Freeing a parameter that cannot be identified is an error naming it and why.
    let bad = IdentifiabilityOptions {
        free: vec![Param::d(1), Param::d(2)],
        ..Default::default()
    };
    let e = analyze(&nom, &obs, &bad).unwrap_err().to_string();
    assert!(
        e.contains("`identifiability.free`") && e.contains("d3: same effect as d2"),
        "{e}"
    );
    let bad = IdentifiabilityOptions {
        free: vec![Param::tool(4)],
        ..Default::default()
    };
    let e = analyze(&nom, &obs, &bad).unwrap_err().to_string();
    assert!(e.contains("tool_b: no effect"), "{e}");
}

#[test]
fn noise_free_table3_is_reproduced_exactly() {
    let truth = table3();
    let tr = tracker(0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let cal = measure(&truth, &tr, 75, &mut rng);
    let val = measure(&truth, &tr, 73, &mut rng);
    for obj in [Objective::SumOfNorms, Objective::LeastSquares] {
        let c = run(&nominal(), &cal, Some(&val), &settings(obj));
        let before = c.calibration.before_stats();
        let after = c.calibration.after_stats();
        let vafter = c.validation.as_ref().unwrap().after_stats();
        assert!(before.mean_mm > 0.3, "{obj:?}: before {before:?}");
        assert!(after.rms_mm < 1e-6, "{obj:?}: after {after:?}");
        assert!(vafter.rms_mm < 1e-6, "{obj:?}: validation {vafter:?}");
        assert!(c.solver().termination.converged(), "{:?}", c.solver());
        // The tracker frame comes out rigid and consistent with the calibrated base.
        let tf = c.tracker_frame();
        let m = *cal.m(0);
        let p = c.calibrated.tool_position(cal.q(0));
        assert!((tf.to_base(&m) - p).norm() < 1e-5);
    }
}

#[test]
fn noise_free_random_errors_are_reproduced_exactly() {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..3 {
        let truth = random_truth(&mut rng);
        let tr = tracker(0.0, 0.0);
        let cal = measure(&truth, &tr, 75, &mut rng);
        let val = measure(&truth, &tr, 73, &mut rng);
        let c = run(
            &nominal(),
            &cal,
            Some(&val),
            &CalibrationSettings::default(),
        );
        let after = c.calibration.after_stats();
        let vafter = c.validation.as_ref().unwrap().after_stats();
        assert!(c.calibration.before_stats().mean_mm > 1.0);
        assert!(after.rms_mm < 1e-6, "after {after:?} {:?}", c.stages);
        assert!(vafter.rms_mm < 1e-6, "validation {vafter:?}");
    }
}

#[test]
fn noisy_paper_like_data_validate_at_the_noise_floor() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    for seed in [21, 22, 23] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let cal = measure(&truth, &tr, 75, &mut rng);
        let val = measure(&truth, &tr, 73, &mut rng);
        let c = run(
            &nominal(),
            &cal,
            Some(&val),
            &CalibrationSettings::default(),
        );
        let v = c.validation.as_ref().unwrap();
        let fl = floor(&truth, &tr, &val);
        let after = v.after_stats().mean_mm;
        assert!(
            after <= 1.15 * fl,
            "seed {seed}: validation mean {after:.4} mm vs noise floor {fl:.4} mm"
        );
        // The paper's Table II order of magnitude before calibration.
        let before = c.calibration.before_stats();
        assert!(before.mean_mm > 0.5 && before.mean_mm < 3.0, "{before:?}");
    }
}

#[test]
fn robust_objective_survives_gross_outliers_where_least_squares_does_not() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut cal = measure(&truth, &tr, 75, &mut rng);
    let val = measure(&truth, &tr, 73, &mut rng);
    // Three beam interruptions: points displaced by 3-5 mm.
    let mut bad = Observations::new(6);
    let bad_lines = [10, 40, 70];
    for i in 0..cal.len() {
        let mut m = *cal.m(i);
        if bad_lines.contains(&cal.line(i)) {
            m += Vector3::new(3.0, -4.0, 2.5) * (1.0 + i as f64 / 75.0);
        }
        bad.push(cal.q(i), m, cal.line(i)).unwrap();
    }
    cal = bad;
    let fl = floor(&truth, &tr, &val);
    let ls = run(
        &nominal(),
        &cal,
        Some(&val),
        &settings(Objective::LeastSquares),
    );
    let rb = run(
        &nominal(),
        &cal,
        Some(&val),
        &settings(Objective::Robust(RobustLoss::Cauchy)),
    );
    let ls_v = ls.validation.as_ref().unwrap().after_stats().mean_mm;
    let rb_v = rb.validation.as_ref().unwrap().after_stats().mean_mm;
    assert!(rb_v <= 1.5 * fl, "robust {rb_v:.4} vs floor {fl:.4}");
    assert!(ls_v > 1.5 * fl, "least squares {ls_v:.4} vs floor {fl:.4}");
    let mut lines: Vec<usize> = rb.downweighted.iter().map(|d| d.line).collect();
    lines.sort();
    assert_eq!(lines, bad_lines, "{:?}", rb.downweighted);
    assert!(rb.downweighted.iter().all(|d| d.weight < 0.01));
    // Huber bounds the outliers' influence too.
    let hb = run(
        &nominal(),
        &cal,
        Some(&val),
        &settings(Objective::Robust(RobustLoss::Huber)),
    );
    let hb_v = hb.validation.as_ref().unwrap().after_stats().mean_mm;
    assert!(hb_v < ls_v, "huber {hb_v} vs least squares {ls_v}");
}

#[test]
fn sum_of_norms_solution_is_a_true_minimum() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let cal = measure(&truth, &tr, 75, &mut rng);
    // The paper's total displacement error, every point counting the same (the default would
    // weigh these data, in a tracker's frame, by the typical tracker).
    let unweighted = |o: Objective| {
        let mut s = settings(o);
        s.weighting.automatic = false;
        s
    };
    let c = run(&nominal(), &cal, None, &unweighted(Objective::SumOfNorms));
    assert_eq!(c.weighting.source, crate::observations::WeightSource::None);
    assert!(c.solver().termination.converged(), "{:?}", c.solver());
    let ps = c.identifiability.identified.clone();
    let problem = Problem::new(&c.nominal, &ps, &cal, c.tracker_frame());
    let tde = |r: &Robot| problem.error_norms(r).iter().sum::<f64>();
    let best = tde(&c.calibrated);
    let x0 = problem.values(&c.calibrated);
    // Random perturbations at several scales, each moving the tool by about `s` mm.
    let rms: Vec<f64> = ps
        .iter()
        .map(|p| {
            c.identifiability
                .column_rms
                .iter()
                .find(|(q, _)| q == p)
                .unwrap()
                .1
        })
        .collect();
    let mut r = c.calibrated.clone();
    for s in [1e-5, 1e-4, 1e-3, 1e-2] {
        for _ in 0..200 {
            let mut x = x0.clone();
            for j in 0..x.len() {
                x[j] += s * rng.gen_range(-1.0..1.0) / rms[j];
            }
            problem.apply(&mut r, &x);
            let f = tde(&r);
            assert!(
                f >= best - 1e-9 * best,
                "perturbation of {s} mm lowered the sum of norms: {f} < {best}"
            );
        }
    }
    // And the sum of norms is lower than the least-squares fit's.
    let ls = run(&nominal(), &cal, None, &unweighted(Objective::LeastSquares));
    assert!(best < tde(&ls.calibrated));
}

#[test]
fn hayati_beta_captures_the_tilt_between_parallel_axes() {
    // Truth: Table III plus a tilt of axis 3 about y (the 27th parameter MDH lacks).
    let mut truth = table3();
    truth.enable_beta(2).unwrap();
    truth.set_display(Param::beta(2), 0.02);
    let tr = tracker(0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(51);
    let cal = measure(&truth, &tr, 75, &mut rng);
    let val = measure(&truth, &tr, 73, &mut rng);
    let plain = run(
        &nominal(),
        &cal,
        Some(&val),
        &CalibrationSettings::default(),
    );
    assert_eq!(plain.identifiability.identified.len(), 26);
    assert!(
        plain.calibration.after_stats().rms_mm > 1e-3,
        "{:?}",
        plain.calibration.after_stats()
    );
    let mut nb = nominal();
    assert_eq!(nb.enable_beta_for_parallel_axes(), vec![2]);
    let beta = run(&nb, &cal, Some(&val), &CalibrationSettings::default());
    let id = &beta.identifiability;
    assert_eq!(id.identified.len(), 27);
    assert!(id.identified.contains(&Param::beta(2)));
    assert_eq!(
        id.fixed_reason(Param::d(2)).unwrap().describe(),
        "same effect as d2"
    );
    assert!(beta.calibration.after_stats().rms_mm < 1e-6);
    assert!(beta.validation.unwrap().after_stats().rms_mm < 1e-6);
    let b3 = beta.calibrated.get_display(Param::beta(2));
    assert!((b3 - 0.02).abs() < 1e-6, "beta3 = {b3}");
}

#[test]
fn standard_deviations_match_the_monte_carlo_spread() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(61);
    // Same poses every trial, fresh noise: the spread of the estimates is what std predicts.
    let qs = random_poses(&truth, 75, &sampler(), &mut rng).unwrap();
    let trials = 40;
    for obj in [Objective::LeastSquares, Objective::SumOfNorms] {
        let mut est: Vec<Vec<f64>> = Vec::new();
        let mut pred: Vec<Vec<f64>> = Vec::new();
        let mut params = Vec::new();
        for _ in 0..trials {
            let mut cal = Observations::new(6);
            for (i, q) in qs.iter().enumerate() {
                cal.push(q, tr.measure(&truth.tool_position(q), &mut rng), i + 2)
                    .unwrap();
            }
            let c = run(&nominal(), &cal, None, &settings(obj));
            params = c.covariance.params.clone();
            // The base frame is identified relative to the fitted tracker frame, which varies
            // with the noise too: compare the robot's base as seen from the tracker, expressed
            // in the true ACS, `F_true F^-1 pose(B)`.
            let b = crate::frame::frame_vector(
                &(tr.frame.pose()
                    * c.tracker_frame().pose().inverse()
                    * *c.calibrated.base_frame()),
            );
            est.push(
                params
                    .iter()
                    .map(|p| {
                        if p.family_id() == crate::model::family::base::ID {
                            b[p.index()]
                        } else {
                            c.calibrated.get(*p)
                        }
                    })
                    .collect(),
            );
            pred.push(c.covariance.std());
        }
        let k = params.len();
        let mut ratios = Vec::new();
        for j in 0..k {
            let mean = est.iter().map(|e| e[j]).sum::<f64>() / trials as f64;
            let emp = (est.iter().map(|e| (e[j] - mean).powi(2)).sum::<f64>()
                / (trials - 1) as f64)
                .sqrt();
            let p = pred.iter().map(|s| s[j]).sum::<f64>() / trials as f64;
            ratios.push(emp / p);
        }
        let named: Vec<String> = params
            .iter()
            .zip(&ratios)
            .map(|(p, r)| format!("{p}: {r:.2}"))
            .collect();
        ratios.sort_by(|a, b| a.total_cmp(b));
        let median = ratios[k / 2];
        assert!(
            (0.8..1.25).contains(&median),
            "{obj:?}: median empirical/predicted std {median}, all {named:?}"
        );
        assert!(
            ratios[0] > 0.55 && ratios[k - 1] < 1.6,
            "{obj:?}: {named:?}"
        );
    }
}

#[test]
fn plane_points_give_the_initial_frame() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(71);
    let cal = measure(&truth, &tr, 75, &mut rng);
    // Turning joint 1 alone moves the tool on a circle parallel to the base plane.
    let mut plane = Observations::new(6);
    for (k, a1) in [-40.0f64, 10.0, 55.0].iter().enumerate() {
        let q = [a1.to_radians(), -0.9, 0.6, 0.3, 0.8, -0.2];
        plane
            .push(&q, tr.measure(&truth.tool_position(&q), &mut rng), 100 + k)
            .unwrap();
    }
    let c = calibrate(
        &nominal(),
        CalibrationData {
            calibration: &cal,
            plane: Some(&plane),
            validation: None,
        },
        &CalibrationSettings::default(),
        &(),
    )
    .unwrap();
    match c.registration.initial {
        crate::registration::InitialFrame::Plane {
            n,
            tilt_deg,
            max_error_mm,
            ..
        } => {
            assert_eq!(n, 3);
            assert!(tilt_deg < 1e-6, "{tilt_deg}");
            // A few mm from the final frame at most (the model errors of Table III).
            assert!(max_error_mm < 20.0, "{max_error_mm}");
        }
        other => panic!("{other:?}"),
    }
    assert!(c.calibration.after_stats().mean_mm < 0.1);
}

#[test]
fn bad_input_is_rejected_with_reasons() {
    let truth = table3();
    let tr = tracker(0.0, 0.0);
    let mut rng = ChaCha8Rng::seed_from_u64(81);
    let few = measure(&truth, &tr, 20, &mut rng);
    let s = CalibrationSettings::default();
    fn data(c: &Observations) -> CalibrationData<'_> {
        CalibrationData {
            calibration: c,
            plane: None,
            validation: None,
        }
    }
    let err = |c: &Observations, s: &CalibrationSettings| {
        calibrate(&nominal(), data(c), s, &())
            .unwrap_err()
            .to_string()
    };
    let e = err(&few, &s);
    assert!(e.contains("20 calibration points for 26"), "{e}");
    let mut dup = measure(&truth, &tr, 40, &mut rng);
    let (q, m) = (dup.q(3).to_vec(), *dup.m(3));
    dup.push(&q, m, 99).unwrap();
    let e = err(&dup, &s);
    assert!(
        e.contains("line 99") && e.contains("duplicated pose") && e.contains("line 5"),
        "{e}"
    );
    let both = CalibrationSettings {
        identifiability: IdentifiabilityOptions {
            fix: vec![Param::d(1)],
            free: vec![Param::d(1)],
            ..Default::default()
        },
        ..Default::default()
    };
    let ok = measure(&truth, &tr, 40, &mut rng);
    let e = err(&ok, &both);
    assert!(
        e.contains("d2") && e.contains("identifiability.fix") && e.contains("identifiability.free"),
        "{e}"
    );
    let mut seven = Observations::new(7);
    seven.push(&[0.0; 7], Vector3::zeros(), 2).unwrap();
    let e = err(&seven, &s);
    assert!(e.contains("expected 6 joint values, got 7"), "{e}");
    let mut nan = Observations::new(6);
    let e = nan
        .push(&[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0], Vector3::zeros(), 7)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("line 7: q2") && e.contains("not a finite number"),
        "{e}"
    );
    let _ = Frame::identity();
}

#[test]
fn solver_reports_why_it_stopped() {
    let truth = table3();
    let tr = tracker(0.010, 0.005);
    let mut rng = ChaCha8Rng::seed_from_u64(91);
    let cal = measure(&truth, &tr, 75, &mut rng);
    let nom = nominal();
    let id = analyze(&nom, &cal, &IdentifiabilityOptions::default()).unwrap();
    let frame = crate::registration::register(
        &nom,
        &cal,
        None,
        &crate::registration::RegistrationOptions::default(),
    )
    .unwrap()
    .frame;
    let problem = Problem::new(&nom, &id.identified, &cal, &frame);
    let loss = Loss::SumOfNorms { delta: 1e-6 };
    // One iteration: stopped by the limit, objective lowered, progress called once.
    let mut r = nom.clone();
    let calls = std::sync::Mutex::new(Vec::new());
    let opts = SolverOptions {
        max_iterations: 1,
        ..Default::default()
    };
    let rep = solve(&problem, &mut r, &loss, &opts, &|s: crate::Stage, i, n| {
        calls.lock().unwrap().push((s, i, n))
    });
    assert_eq!(rep.termination, Termination::MaxIterations);
    assert!(!rep.termination.converged());
    assert_eq!(
        calls.into_inner().unwrap(),
        vec![(crate::Stage::Identification("sum of norms"), 1, 1)]
    );
    assert!(rep.final_objective < rep.initial_objective);
    // To convergence, then again from the solution: converged at once, nothing moves.
    let mut r = nom.clone();
    let rep = solve(&problem, &mut r, &loss, &SolverOptions::default(), &());
    assert!(rep.termination.converged(), "{rep:?}");
    let before = problem.values(&r);
    let again = solve(&problem, &mut r, &loss, &SolverOptions::default(), &());
    assert!(
        again.termination.converged() && again.iterations <= 2,
        "{again:?}"
    );
    assert!((problem.values(&r) - before).amax() < 1e-9);
    assert!(again.final_objective <= rep.final_objective * (1.0 + 1e-12));
    // Overflowing residuals make the solver fail, not loop.
    let far = pose(&[f64::MAX, f64::MAX, 0.0, 0.0, 0.0, 0.0]);
    let problem = Problem::new(&nom, &id.identified, &cal, &TrackerFrame::new(far));
    let mut r = nom.clone();
    let rep = solve(&problem, &mut r, &loss, &SolverOptions::default(), &());
    assert!(matches!(rep.termination, Termination::Failed(_)), "{rep:?}");
}

/// The KR 480 on a 4 m linear track (`examples/kr480-track.toml`): a prismatic joint and six
/// revolute ones.
fn track() -> Robot {
    crate::load_robot_file(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/kr480-track.toml"
    )))
    .unwrap()
}

/// Noise-free data of the tracked robot with random errors on every parameter are explained
/// exactly (to 1e-6 mm on calibration and validation points), as for the 6R arm: the prismatic
/// joint's column and its row's parameter columns are right. `d4` is left alone for the
/// reason `random_truth` leaves `d3` (axes 3 and 4 are the arm's parallel pair).
#[test]
fn noise_free_tracked_robot_with_random_errors_is_reproduced_exactly() {
    let nom = track();
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    for _ in 0..2 {
        let mut truth = nom.clone();
        for p in truth.params() {
            if p == Param::d(3) {
                continue;
            }
            let dv = match p.unit() {
                crate::model::Unit::Mm => rng.gen_range(-1.0..1.0),
                crate::model::Unit::Deg => rng.gen_range(-0.05f64..0.05).to_radians(),
                // The geometric robots of these tests have no other units.
                _ => 0.0,
            };
            truth.set(p, truth.get(p) + dv);
        }
        let tr = tracker(0.0, 0.0);
        let cal = measure(&truth, &tr, 100, &mut rng);
        let val = measure(&truth, &tr, 73, &mut rng);
        let c = run(&nom, &cal, Some(&val), &CalibrationSettings::default());
        let before = c.calibration.before_stats();
        let after = c.calibration.after_stats();
        let vafter = c.validation.as_ref().unwrap().after_stats();
        assert!(before.mean_mm > 1.0, "{before:?}");
        assert!(after.rms_mm < 1e-6, "after {after:?} {:?}", c.stages);
        assert!(vafter.rms_mm < 1e-6, "validation {vafter:?}");
        // The track's own row is absorbed by the base frame, as joint 1 of the arm is; the
        // track's direction against the arm is identified: two parameters more than the arm's
        // 26.
        let id = &c.identifiability;
        assert_eq!(id.identified.len(), 28, "{:?}", names(&id.identified));
        for p in [Param::alpha(0), Param::d(0), Param::a(0), Param::phi(0)] {
            assert!(id.fixed_reason(p).is_some(), "{p} identified");
        }
        assert!(id.identified.contains(&Param::alpha(1)));
        assert_eq!(
            id.fixed_reason(Param::d(0)).unwrap().describe(),
            "same effect as base_x"
        );
    }
}
