//! The lighter prediction a model selection's candidate gets (its plausibility gate reads the
//! expected mean at new poses and the noise; nothing else sees it: the chosen candidate's result
//! is completed with the full prediction, [`super::predict`]).
//!
//! Two simplifications, each far inside the gate's margins (the improvement limit is 1.2 times
//! the start's error, the residual limit 20 times the noise model's):
//! - the noise by one degrees-of-freedom correction for the whole set, `sqrt(sum r_i^2 / (rows
//!   n - k))` over the points kept, instead of each point's own by its leverage (the same when
//!   the noise is alike over the poses; no Jacobian at all);
//! - the mean over at most [`CANDIDATE_POSES`] poses spread evenly, instead of
//!   [`super::MAX_POSES`].
//!
//! A test holds both within 1% of the full prediction (measured: 0.03% at 75 poses, 0.006% at
//! 1500).

use super::{averaged_poses_up_to, kept_points, Prediction, Predictor, Scratch};
use crate::identification::covariance::Covariance;
use crate::identification::simd::with_avx;
use crate::model::Robot;
use crate::observations::Observations;

/// Most poses a candidate's prediction averages over.
pub const CANDIDATE_POSES: usize = 256;

/// The prediction of a model selection's candidate (see the module docs); `None` as
/// [`super::predict`] gives it.
pub(crate) fn predict_for_candidate(
    calibrated: &Robot,
    covariance: &Covariance,
    calibration: &Observations,
    residual_norms: &[f64],
    threshold_mm: Option<f64>,
) -> Option<Prediction> {
    let rows = 3;
    let pred = Predictor::new(calibrated, covariance, 0.0)?;
    let k = pred.index.len();
    let kept = kept_points(residual_norms, threshold_mm);
    let dof = (rows * kept.len()) as f64 - k as f64;
    if dof <= 0.0 {
        return None;
    }
    let sum_sq: f64 = kept.iter().map(|&i| residual_norms[i].powi(2)).sum();
    let sigma = (sum_sq / dof).sqrt();
    if !sigma.is_finite() {
        return None;
    }
    let picked = averaged_poses_up_to(calibration.len(), CANDIDATE_POSES);
    let mut s: Scratch = pred.scratch();
    let models: Vec<_> = picked
        .iter()
        .map(|&i| {
            with_avx(
                #[inline(always)]
                || {
                    let c = calibration.conditions(i);
                    pred.model_at(&mut s, calibration.q(i), calibration.target(i), &c)
                        .1
                },
            )
        })
        .collect();
    let pred = Predictor { sigma, ..pred };
    Some(pred.predict_from(&models, f64::NEG_INFINITY, false))
}
