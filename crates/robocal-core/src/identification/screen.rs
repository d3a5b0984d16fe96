//! A model selection's candidate screened before it is fitted: its cross-validated error
//! estimated from the fit of the model it extends ([`screen`]), so that a family far from
//! lowering the error costs one pass over the data instead of a whole calibration.
//!
//! A candidate of the forward search is the current model with one family more. At the current
//! model's fit the new family's parameters are zero, a point one step of the size of the
//! family's effect from the candidate's own minimum. Each fold's refit is then one Newton step
//! from there on the other folds' normal equations (the whole pass's minus the fold's share), as
//! [`super::cross_validation::cross_validate`] steps from a full fit's minimum; the left-out
//! points are evaluated exactly under the stepped model. Where the family does not act (a
//! geometric robot), the step is of the order of the noise and the estimate is the full fit's
//! cross-validated error to second order; where it acts, the estimate shows a large gain and the
//! candidate is fitted.
//!
//! [`crate::identification::selection`] fits every candidate whose estimate comes within
//! [`SCREEN_MARGIN`] of its standard error of lowering the current model's error, and any
//! screened candidate the choice would pick: a screened candidate only ever loses, with its
//! estimate in the table.

use crate::error::Result;
use crate::identification::cross_validation::{
    pose_folds, stepped_errors, subset, summarize, weighted, CrossValidation,
};
use crate::identification::pipeline::Calibration;
use crate::identification::system::{Level, Problem};
use crate::model::{Param, Robot};
use crate::observations::Observations;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// How far (in the current model's standard errors) a candidate's estimate must stay from
/// lowering the current model's error for the candidate to go unfitted: it is fitted when its
/// estimated error plus its standard error is below the current model's error plus this many
/// of its standard errors. The estimate's own error is a small fraction of this: measured, at
/// most 3e-5 standard errors where the model fits the data, 0.03 to 0.06 where it misses them
/// by far (harmonics on a sagging arm; the real WAM's 2 mm), and the tests hold it.
pub const SCREEN_MARGIN: f64 = 0.5;

/// The cross-validated error of `candidate` (the model `current` was fitted with, one family
/// more, its parameters at zero: see the module docs), over `folds` folds by pose of
/// `calibration` (the points as given to the calibration), for its identified parameters
/// `params`. `None` when a fold's step cannot be solved (the candidate is then fitted).
pub fn screen(
    current: &Calibration,
    candidate: &Robot,
    params: &[Param],
    calibration: &Observations,
    folds: usize,
) -> Result<Option<CrossValidation>> {
    let weighted = weighted(current, calibration)?;
    let fold = pose_folds(&weighted, folds);
    let loss = current.stages.last().expect("at least one stage").loss;
    let robot = at_fit(candidate, &current.calibrated);
    let Some(shares) = Problem::new(&robot, params, &weighted, &current.frame)
        .grouped(&fold, folds)
        .accumulate(&robot, &loss, Level::Newton)
        .groups
    else {
        return Ok(None);
    };
    let k = params.len();
    let mut h = DMatrix::zeros(k, k);
    let mut b = DVector::zeros(k);
    for (hf, bf) in &shares {
        h += hf;
        b += bf;
    }
    // Each fold's left-out errors; `None` for a fold whose step cannot be solved.
    let runs: Vec<Result<Option<Vec<f64>>>> = shares
        .par_iter()
        .enumerate()
        .map(|(f, share)| {
            let test = subset(&weighted, |i| fold[i] == f)?;
            if test.is_empty() {
                return Ok(Some(Vec::new()));
            }
            Ok(stepped_errors(
                &robot,
                params,
                &current.frame,
                &test,
                (&h, &b),
                share,
            ))
        })
        .collect();
    let mut errors = Vec::with_capacity(runs.len());
    for r in runs {
        match r? {
            Some(e) => errors.push(Ok((e, true))),
            None => return Ok(None),
        }
    }
    summarize(errors).map(Some)
}

/// `candidate` with every parameter it shares with `fitted` at `fitted`'s value (its own
/// others, the new family's, as they are: zero).
fn at_fit(candidate: &Robot, fitted: &Robot) -> Robot {
    let mut robot = candidate.clone();
    let own = candidate.param_list();
    for &p in fitted.param_list() {
        if own.contains(&p) {
            robot.set(p, fitted.get(p));
        }
    }
    robot
}
