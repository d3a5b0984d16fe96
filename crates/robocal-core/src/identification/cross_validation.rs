//! K-fold cross-validation of a calibration by pose: each fold's poses are left out, the model
//! refitted on the others (warm-started from the full fit: same identified parameters, tracker
//! frame and final loss), and the left-out points' position errors measured under that refit.

use crate::error::Result;
use crate::identification::pipeline::Calibration;
use crate::identification::solver::{solve, SolverOptions};
use crate::identification::system::Problem;
use crate::observations::{Observations, Weighting};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;
use std::collections::HashMap;

/// Iteration limit of a fold's refit. It starts at the full fit's minimum, a few Gauss-Newton
/// steps from its own; a refit still moving after this many (a model whose fit creeps) is taken
/// as it stands, and [`CrossValidation::converged`] says so.
pub const FOLD_MAX_ITERATIONS: usize = 10;

/// The outcome of [`cross_validate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrossValidation {
    /// Mean position error of every point under the refit that left it out (mm).
    pub mean_mm: f64,
    /// Standard error of that mean (sample standard deviation of the errors over the square
    /// root of their count, mm).
    pub std_error_mm: f64,
    /// Whether every fold's refit converged.
    pub converged: bool,
}

/// The fold (0..folds) of each observation: the distinct poses (joint values) in a seeded
/// random order, dealt out in turn, so that the rows of one pose share a fold.
pub fn pose_folds(obs: &Observations, folds: usize) -> Vec<usize> {
    let mut pose_of = Vec::with_capacity(obs.len());
    let mut index: HashMap<Vec<u64>, usize> = HashMap::new();
    for i in 0..obs.len() {
        let key: Vec<u64> = obs.q(i).iter().map(|v| v.to_bits()).collect();
        let n = index.len();
        pose_of.push(*index.entry(key).or_insert(n));
    }
    let mut order: Vec<usize> = (0..index.len()).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(0x5eed));
    let mut fold_of_pose = vec![0; order.len()];
    for (k, &p) in order.iter().enumerate() {
        fold_of_pose[p] = k % folds.max(1);
    }
    pose_of.into_iter().map(|p| fold_of_pose[p]).collect()
}

/// The observations `i` of `obs` for which `keep(i)`, with their extras and weights.
pub fn subset(obs: &Observations, keep: impl Fn(usize) -> bool) -> Result<Observations> {
    let mut out = Observations::new(obs.dof());
    out.set_mm_per_deg(obs.mm_per_rad().to_radians())?;
    for i in (0..obs.len()).filter(|&i| keep(i)) {
        out.push_with(obs.q(i), *obs.m(i), obs.extras(i), obs.line(i))?;
    }
    Ok(out)
}

/// Cross-validates `cal` (fitted to `calibration`, the points as given to the calibration) over
/// `folds` folds by pose, the folds in parallel.
pub fn cross_validate(
    cal: &Calibration,
    calibration: &Observations,
    folds: usize,
) -> Result<CrossValidation> {
    let weighted = Weighting {
        tracker: cal.weighting.tracker,
        ..cal.settings.weighting
    }
    .apply(calibration)?;
    let fold = pose_folds(&weighted, folds);
    let loss = cal.stages.last().expect("at least one stage").loss;
    let opts = SolverOptions {
        max_iterations: FOLD_MAX_ITERATIONS,
        ..cal.settings.solver
    };
    let frame = cal.frame;
    let params = &cal.identifiability.identified;
    let runs: Vec<Result<(Vec<f64>, bool)>> = (0..folds)
        .into_par_iter()
        .map(|f| {
            let test = subset(&weighted, |i| fold[i] == f)?;
            if test.is_empty() {
                return Ok((Vec::new(), true));
            }
            let train = subset(&weighted, |i| fold[i] != f)?;
            let mut robot = cal.calibrated.clone();
            let problem = Problem::new(&robot, params, &train, &frame);
            let report = solve(&problem, &mut robot, &loss, &opts, &());
            let errors = Problem::new(&robot, &[], &test, &frame).error_norms(&robot);
            Ok((errors, report.termination.converged()))
        })
        .collect();
    let mut errors = Vec::with_capacity(weighted.len());
    let mut converged = true;
    for r in runs {
        let (e, c) = r?;
        errors.extend(e);
        converged &= c;
    }
    let n = errors.len().max(1) as f64;
    let mean = errors.iter().sum::<f64>() / n;
    let var = errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    Ok(CrossValidation {
        mean_mm: mean,
        std_error_mm: (var / n).sqrt(),
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn rows_of_one_pose_share_a_fold_and_folds_are_balanced() {
        let mut obs = Observations::new(2);
        for p in 0..20 {
            for t in 0..3 {
                let q = [p as f64 * 0.1, 0.5];
                obs.push(&q, Vector3::new(t as f64, 0.0, 0.0), p * 3 + t + 2)
                    .unwrap();
            }
        }
        let f = pose_folds(&obs, 5);
        for p in 0..20 {
            assert_eq!(f[3 * p], f[3 * p + 1]);
            assert_eq!(f[3 * p], f[3 * p + 2]);
        }
        for k in 0..5 {
            assert_eq!(f.iter().filter(|&&x| x == k).count(), 12);
        }
        let s = subset(&obs, |i| f[i] == 2).unwrap();
        assert_eq!(s.len(), 12);
    }
}
