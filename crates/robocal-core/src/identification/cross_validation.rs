//! K-fold cross-validation of a calibration by pose: each fold's poses are left out, the model
//! refitted on the others, and the left-out points' position errors measured under that refit.
//!
//! [`cross_validate`] refits by one Newton step from the full fit: the full fit's normal
//! equations are accumulated once, fold by fold; a fold's refit solves the equations of the
//! other folds (the whole minus its own) at the full fit's minimum, which is a step of the
//! order of the noise away from the fold's own minimum, so that the step lands on it to second
//! order. The left-out points are then evaluated exactly (forward kinematics) under the stepped
//! model. The whole costs one pass over the data where refits cost several per fold, and none
//! when the fit's own last pass summed the folds' shares (a model selection's candidates,
//! `Calibration::fold_passes`).
//! [`cross_validate_refit`] iterates each fold's refit to convergence (warm-started from the full
//! fit: same identified parameters, tracker frame and final loss); the tests hold the two
//! together, and a fold whose step cannot be solved is refitted that way.

use crate::error::Result;
use crate::frame::TrackerFrame;
use crate::identification::objective::Loss;
use crate::identification::pipeline::Calibration;
use crate::identification::solver::{solve, undamped_step, SolverOptions};
use crate::identification::system::{Level, Problem};
use crate::model::{Param, Robot};
use crate::observations::{Observations, Weighting};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

pub use super::folds::pose_folds;

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

/// The observations `i` of `obs` for which `keep(i)`, with their extras and weights.
pub fn subset(obs: &Observations, keep: impl Fn(usize) -> bool) -> Result<Observations> {
    obs.rows_where(keep)
}

/// Cross-validates `cal` (fitted to `calibration`, the points as given to the calibration) over
/// `folds` folds by pose, each fold refitted until it converges (at most
/// [`FOLD_MAX_ITERATIONS`]), the folds in parallel. [`cross_validate`] gives the same to second
/// order in a fraction of the time.
pub fn cross_validate_refit(
    cal: &Calibration,
    calibration: &Observations,
    folds: usize,
) -> Result<CrossValidation> {
    let weighted = weighted(cal, calibration)?;
    let fold = pose_folds(&weighted, folds);
    let runs: Vec<Result<(Vec<f64>, bool)>> = (0..folds)
        .into_par_iter()
        .map(|f| {
            let test = subset(&weighted, |i| fold[i] == f)?;
            if test.is_empty() {
                return Ok((Vec::new(), true));
            }
            refit_fold(cal, &weighted, &fold, f, &test)
        })
        .collect();
    summarize(runs)
}

/// The calibration points with the weights the fit gave them.
pub(crate) fn weighted(cal: &Calibration, calibration: &Observations) -> Result<Observations> {
    Weighting {
        tracker: cal.weighting.tracker,
        ..cal.settings.weighting
    }
    .apply(calibration)
}

/// The left-out points' errors of fold `f` (its points `test`) under a refit on the other folds
/// iterated to convergence from the full fit, and whether it converged.
fn refit_fold(
    cal: &Calibration,
    weighted: &Observations,
    fold: &[usize],
    f: usize,
    test: &Observations,
) -> Result<(Vec<f64>, bool)> {
    let loss = cal.stages.last().expect("at least one stage").loss;
    let opts = SolverOptions {
        max_iterations: FOLD_MAX_ITERATIONS,
        ..cal.settings.solver
    };
    let train = subset(weighted, |i| fold[i] != f)?;
    let mut robot = cal.calibrated.clone();
    let problem = Problem::new(&robot, &cal.identifiability.identified, &train, &cal.frame);
    let report = solve(&problem, &mut robot, &loss, &opts, &());
    let errors = Problem::new(&robot, &[], test, &cal.frame).error_norms(&robot);
    Ok((errors, report.termination.converged()))
}

/// Cross-validates `cal` (fitted to `calibration`, the points as given to the calibration) over
/// `folds` folds by pose: each fold's refit is one Newton step from the full fit on the normal
/// equations of the other folds (see the module docs). Each fold's share of the normal equations
/// comes from the fit's last pass when it summed them (`Calibration::fold_passes`), else from a
/// pass of its own, the folds in parallel.
pub fn cross_validate(
    cal: &Calibration,
    calibration: &Observations,
    folds: usize,
) -> Result<CrossValidation> {
    let weighted = weighted(cal, calibration)?;
    let fold = pose_folds(&weighted, folds);
    let loss = cal.stages.last().expect("at least one stage").loss;
    let params = &cal.identifiability.identified;
    let robot = &cal.calibrated;
    // Each fold's share of the objective's Hessian and gradient at the full fit's minimum,
    // weighted as the fit weighted its points: from the fit's last pass when it summed them,
    // else from one pass of its own (a pass over a fold's points alone would weigh them by
    // their own mean uncertainty, not the whole set's).
    let shares = match cal
        .fold_passes
        .as_ref()
        .filter(|p| p.len() == folds && p.iter().all(|(h, _)| h.nrows() == params.len()))
    {
        Some(p) => p.clone(),
        None => newton_shares(robot, params, &weighted, &cal.frame, &fold, folds, &loss),
    };
    let cv = one_step_folds(
        robot,
        params,
        &cal.frame,
        &weighted,
        &fold,
        shares,
        // Not positive definite (a fold whose removal leaves a parameter undetermined, or a
        // loss whose curvature turns): the refit decides.
        |f, test| refit_fold(cal, &weighted, &fold, f, test).map(Some),
    )?;
    Ok(cv.expect("every fold's errors"))
}

/// Each fold's share of the objective's Newton Hessian and gradient at `robot` (over `params`,
/// the points of `weighted` weighted as they are, under `loss`): one grouped pass over the data.
pub(crate) fn newton_shares(
    robot: &Robot,
    params: &[Param],
    weighted: &Observations,
    frame: &TrackerFrame,
    fold: &[usize],
    folds: usize,
    loss: &Loss,
) -> Vec<(DMatrix<f64>, DVector<f64>)> {
    Problem::new(robot, params, weighted, frame)
        .grouped(fold, folds)
        .accumulate(robot, loss, Level::Newton)
        .groups
        .expect("a grouped Newton pass")
}

/// The cross-validation of one Newton step per fold from `robot` (over `params`): the points of
/// `weighted` in fold `f` (`fold[i] == f`) evaluated under the step on the normal equations of
/// the other folds (the sum of `shares`, each fold's, minus its own), the folds in parallel. A
/// fold whose step cannot be solved goes to `unsolved`: its errors and whether they converged,
/// or `None` to give the whole up (then `None`).
pub(crate) fn one_step_folds(
    robot: &Robot,
    params: &[Param],
    frame: &TrackerFrame,
    weighted: &Observations,
    fold: &[usize],
    shares: Vec<(DMatrix<f64>, DVector<f64>)>,
    unsolved: impl Fn(usize, &Observations) -> Result<Option<FoldErrors>> + Sync,
) -> Result<Option<CrossValidation>> {
    let parts: Vec<Result<Option<Part>>> = shares
        .into_par_iter()
        .enumerate()
        .map(|(f, share)| {
            let test = subset(weighted, |i| fold[i] == f)?;
            Ok((!test.is_empty()).then_some((f, test, share)))
        })
        .collect();
    let parts: Vec<Part> = parts
        .into_iter()
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .flatten()
        .collect();
    let k = params.len();
    let mut h = DMatrix::zeros(k, k);
    let mut b = DVector::zeros(k);
    for (_, _, (hf, bf)) in &parts {
        h += hf;
        b += bf;
    }
    let runs: Vec<Result<Option<FoldErrors>>> = (0..parts.len())
        .into_par_iter()
        .map(|p| {
            let (f, test, share) = &parts[p];
            match stepped_errors(robot, params, frame, test, (&h, &b), share) {
                Some(errors) => Ok(Some((errors, true))),
                None => unsolved(*f, test),
            }
        })
        .collect();
    let mut folds = Vec::with_capacity(runs.len());
    for r in runs {
        match r? {
            Some(e) => folds.push(Ok(e)),
            None => return Ok(None),
        }
    }
    summarize(folds).map(Some)
}

/// The position errors of a fold's points `test` under one Newton step from `robot` (over
/// `params`) on the normal equations of the other folds: the whole's `(h, b)` minus the fold's
/// `share`. `None` when the step cannot be solved (not positive definite).
fn stepped_errors(
    robot: &Robot,
    params: &[Param],
    frame: &TrackerFrame,
    test: &Observations,
    (h, b): (&DMatrix<f64>, &DVector<f64>),
    share: &(DMatrix<f64>, DVector<f64>),
) -> Option<Vec<f64>> {
    let step = undamped_step(&(h - &share.0), &(b - &share.1))?;
    let problem = Problem::new(robot, params, test, frame);
    let mut stepped: Robot = robot.clone();
    problem.apply(&mut stepped, &(problem.values(robot) + step));
    Some(Problem::new(&stepped, &[], test, frame).error_norms(&stepped))
}

/// A fold's left-out errors and whether its refit converged.
type FoldErrors = (Vec<f64>, bool);

/// A fold: its index, its points and their share of the objective's Hessian and gradient.
type Part = (usize, Observations, (DMatrix<f64>, DVector<f64>));

/// The cross-validated mean and its standard error from each fold's left-out errors (and
/// whether its refit converged).
pub(crate) fn summarize(runs: Vec<Result<(Vec<f64>, bool)>>) -> Result<CrossValidation> {
    let mut errors = Vec::new();
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
