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
//! [`SCREEN_MARGIN`] of the current model's standard errors of lowering its error. A screened
//! candidate keeps its estimate in the table and takes part in the choice with it, as its fit
//! would with its cross-validated error; it is never the choice, and one whose fit could turn the
//! choice or the search (see `selection::search`) is fitted after all.

use crate::error::Result;
use crate::identification::cross_validation::{
    newton_shares, one_step_folds, pose_folds, weighted, CrossValidation,
};
use crate::identification::folds::FOLDS;
use crate::identification::model_choice::Candidate;
use crate::identification::pipeline::Calibration;
use crate::model::{Param, Robot};
use crate::observations::Observations;

/// How far (in the current model's standard errors) a candidate's estimate must stay from
/// lowering the current model's error for the candidate to go unfitted: it is fitted when its
/// estimated error plus its standard error is below the current model's error plus this many
/// of its standard errors. The estimate's own error is a small fraction of this: at most 3e-5
/// standard errors where the model fits the data and 0.03 where it misses their sag (harmonics
/// on a sagging arm), 0.033 on the real UR5 and 0.061 on the real WAM (a model 2 mm off); the
/// tests hold each.
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
    let shares = newton_shares(
        &robot,
        params,
        &weighted,
        &current.frame,
        &fold,
        folds,
        &loss,
    );
    one_step_folds(
        &robot,
        params,
        &current.frame,
        &weighted,
        &fold,
        shares,
        |_, _| Ok(None),
    )
}

/// `candidate` (identifying `params`) screened against `judged`, the candidate of the model it
/// extends, whose fit is `current`: the candidate with its estimate ([`screen`]) and
/// [`Candidate::screened`] when the estimate plus its standard error stays [`SCREEN_MARGIN`] of
/// `judged`'s standard errors above `judged`'s error; `None` when it is to be fitted (it may
/// lower that error, or the estimate cannot be made).
pub(crate) fn screen_candidate(
    current: &Calibration,
    judged: &Candidate,
    candidate: &Robot,
    params: &[Param],
    calibration: &Observations,
) -> Option<Candidate> {
    let (mean, se) = (judged.cv_mean_mm?, judged.cv_std_error_mm?);
    let cv = screen(current, candidate, params, calibration, FOLDS).ok()??;
    let far = cv.mean_mm + cv.std_error_mm >= mean + SCREEN_MARGIN * se;
    (far && cv.mean_mm.is_finite() && cv.std_error_mm.is_finite()).then(|| Candidate {
        identified: params.len(),
        cv_mean_mm: Some(cv.mean_mm),
        cv_std_error_mm: Some(cv.std_error_mm),
        screened: true,
        ..Candidate::new(candidate, false)
    })
}

/// `candidate` with every parameter it shares with `fitted` at `fitted`'s value (its own
/// others, the new family's, as they are: zero). Everything a calibration changes is a
/// parameter (the tool fit's corrections included); the frame is the fit's own.
fn at_fit(candidate: &Robot, fitted: &Robot) -> Robot {
    let mut robot = candidate.clone();
    for &p in fitted.param_list() {
        if candidate.has_param(p) {
            robot.set(p, fitted.get(p));
        }
    }
    robot
}
