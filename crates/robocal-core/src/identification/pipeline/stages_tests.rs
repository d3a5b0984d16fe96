//! Tests of the parent module (`identification::pipeline::stages`).

use crate::identification::pipeline::{calibrate_model, Calibration, CalibrationData};
use crate::identification::CalibrationSettings;
use crate::model::presets::preset;
use crate::observations::Observations;
use crate::simulation::{random_poses, PoseSampler};
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

/// Noisy points of the paper's true robot, each a gross outlier with probability `outliers`
/// (which the adaptive objective's reweighting must down-weight on the subsample as on every
/// point).
fn data(n: usize, seed: u64, outliers: f64) -> Observations {
    let truth = preset("kuka-kr480-r3330-table3").unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let qs = random_poses(&truth, n, &PoseSampler::default(), &mut rng).unwrap();
    let noise = Normal::new(0.0, 0.03).unwrap();
    let mut obs = Observations::new(6);
    for (i, q) in qs.iter().enumerate() {
        let mut m = truth.tool_position(q);
        m.iter_mut().for_each(|v| *v += noise.sample(&mut rng));
        if rng.gen_bool(outliers) {
            m.x += 3.0;
        }
        obs.push(q, m, i + 2).unwrap();
    }
    obs
}

fn fit(obs: &Observations, settings: &CalibrationSettings) -> Calibration {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let data = CalibrationData {
        calibration: obs,
        plane: None,
        validation: None,
    };
    calibrate_model(&nominal, data, settings, &()).unwrap()
}

/// A solve started on a subsample reaches the minimum of the solve on every point from the
/// start: the mean error to 1e-6 mm and every parameter to 1e-3 of its standard deviation (the solver's own tolerance, far inside the estimate's uncertainty),
/// for each objective; the warm start's runs say how many points they used, and the runs on
/// every point are short.
#[test]
fn a_warm_start_on_a_subsample_reaches_the_same_minimum() {
    use crate::identification::objective::Objective;
    let obs = data(6000, 7, 0.005);
    for objective in [Objective::Adaptive, Objective::LeastSquares] {
        let cold = CalibrationSettings {
            objective,
            ..Default::default()
        };
        assert!(cold.solver.warm_start_min_points > obs.len());
        let mut warm = cold.clone();
        warm.solver.warm_start_min_points = 5000;
        warm.solver.warm_start_points = 1000;
        let (a, b) = (fit(&obs, &cold), fit(&obs, &warm));
        assert!(a.stages.iter().all(|s| s.points.is_none()));
        let sub: Vec<_> = b.stages.iter().filter(|s| s.points.is_some()).collect();
        assert!(!sub.is_empty(), "{objective:?}: no warm start");
        assert!(sub.iter().all(|s| s.points == Some(1000)), "{:?}", b.stages);
        let whole: usize = b
            .stages
            .iter()
            .filter(|s| s.points.is_none())
            .map(|s| s.report.evaluations)
            .sum();
        let before: usize = a.stages.iter().map(|s| s.report.evaluations).sum();
        assert!(
            whole < before,
            "{objective:?}: {whole} passes over every point after the warm start, {before} without"
        );
        let (ma, mb) = (
            a.calibration.after_stats().mean_mm,
            b.calibration.after_stats().mean_mm,
        );
        assert!((ma - mb).abs() < 1e-6, "{objective:?}: {ma} vs {mb}");
        for p in &a.identifiability.identified {
            let std = a.covariance.std_of(*p).unwrap();
            let (va, vb) = (a.calibrated.get(*p), b.calibrated.get(*p));
            assert!(
                (va - vb).abs() < 1e-3 * std,
                "{objective:?} {}: {va} vs {vb} (std {std})",
                p.name()
            );
        }
    }
}

/// A subsample outside its bounds is refused before any work.
#[test]
fn warm_start_settings_are_checked() {
    let obs = data(200, 1, 0.005);
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let data = CalibrationData {
        calibration: &obs,
        plane: None,
        validation: None,
    };
    for (min, points) in [(100_000, 10), (5000, 5000)] {
        let mut s = CalibrationSettings::default();
        s.solver.warm_start_min_points = min;
        s.solver.warm_start_points = points;
        let e = calibrate_model(&nominal, data, &s, &())
            .unwrap_err()
            .to_string();
        assert!(e.contains("solver.warm_start_points"), "{e}");
    }
}

/// The adaptive run after a least-squares fit without outliers takes that fit's last pass (the
/// same bits: `system`'s tests) and stops at its minimum without a step: one evaluation, its
/// objective the least-squares fit's to the bit, nothing down-weighted, and the model the one
/// the least-squares objective gives.
#[test]
fn an_adaptive_run_without_outliers_stops_at_the_least_squares_minimum() {
    use crate::identification::objective::{Loss, Objective};
    let obs = data(300, 3, 0.0);
    let adaptive = fit(&obs, &CalibrationSettings::default());
    let least_squares = fit(
        &obs,
        &CalibrationSettings {
            objective: Objective::LeastSquares,
            ..Default::default()
        },
    );
    assert!(adaptive.downweighted.is_empty());
    let [first, last] = &adaptive.stages[..] else {
        panic!("{} runs", adaptive.stages.len())
    };
    assert_eq!(first.loss, Loss::Squared);
    assert!(
        matches!(last.loss, Loss::Adaptive { .. }),
        "{:?}",
        last.loss
    );
    assert_eq!(last.report.evaluations, 1);
    assert!(last.report.termination.converged());
    assert!(
        last.report.last_step_mm.is_nan(),
        "a step of {}",
        last.report.last_step_mm
    );
    for objective in [last.report.initial_objective, last.report.final_objective] {
        assert_eq!(objective.to_bits(), first.report.final_objective.to_bits());
    }
    for p in &adaptive.identifiability.identified {
        let (a, b) = (
            adaptive.calibrated.get(*p),
            least_squares.calibrated.get(*p),
        );
        let std = adaptive.covariance.std_of(*p).unwrap();
        assert!((a - b).abs() <= 1e-6 * std, "{}: {a} against {b}", p.name());
    }
}
