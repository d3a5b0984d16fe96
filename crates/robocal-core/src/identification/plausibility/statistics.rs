//! The gate's statistical checks: what a fit did to the data, beyond where its parameters went.
//!
//! - **improvement**: the calibrated model must not miss the points clearly worse than the model
//!   it started from (the nominal geometry with the fitted tools): on the validation points, or,
//!   without them, by the prediction at new poses;
//! - **discarded points**: the robust loss may set aside a small share of the points (gross
//!   outliers), not a large part of the data, which then disagree with the rest;
//! - **residuals**: with a noise model (a tracker model or `sigma_mm`), the residuals must stay
//!   within a factor of what the measurement can explain (a geometric model of a real robot leaves
//!   3 to 10 times the tracker's noise; inconsistent data, far more);
//! - **weight share**: no single point may carry a dominant share of the total weight.
//!
//! The limits are the constants below, with the margins measured on good and bad data.

use super::{check, diagnosis::sig, Check, CheckKind, Fit};
use crate::stats::ErrorStats;

/// Improvement: the calibrated model may miss the points by at most this factor of the start's
/// error (and [`IMPROVEMENT_FLOOR_MM`] more). Calibrating a robot that is already accurate adds
/// the parameters' uncertainty to the noise, about 10% (simulated data of the nominal robot:
/// 1.11 on the prediction); a fit dragged by one heavy point: 1.52.
pub const IMPROVEMENT_LIMIT: f64 = 1.2;

/// Improvement: differences below this (mm) are no change (exact data: both near 0).
pub const IMPROVEMENT_FLOOR_MM: f64 = 1e-3;

/// Discarded points: at most this share of the calibration points may lie beyond the robust
/// loss's threshold. Good data: 0 (real UR5, WAM, the demo), about 5% with 5% simulated gross
/// outliers; inconsistent data (one of three reflectors with joint 1 off by 0.5 degree): 33%.
pub const DISCARD_SHARE_LIMIT: f64 = 0.2;

/// Residuals: the per-axis noise of the calibrated model's residuals, over the typical sigma of
/// the noise model, at most this. A geometric calibration of a real robot leaves 3 to 10 times a
/// tracker's noise (the paper: 0.17 mm after calibration against a tracker of about 0.03 mm per
/// axis); a sagging KR 480 calibrated without its compliance, about 8; one of three reflectors
/// with joint 1 off by 0.5 degree, about 28.
pub const RESIDUAL_RATIO_LIMIT: f64 = 20.0;

/// Weight share: no point may carry more than this share of the total weight (weights `1 /
/// sigma^2`). Equal weights give `1 / n`, 1.3% for 75 points; a point ten times more certain
/// than 74 others carries 57%.
pub const WEIGHT_SHARE_LIMIT: f64 = 0.2;

/// The `improvement` check (see the module docs).
pub(super) fn improvement(fit: &Fit) -> Check {
    let (before, after, basis) = match (fit.validation_before, fit.validation_after) {
        (Some(b), Some(a)) if !b.is_empty() && !a.is_empty() => (
            ErrorStats::from_norms(b).mean_mm,
            ErrorStats::from_norms(a).mean_mm,
            "the validation points",
        ),
        _ => match fit.prediction_mean_mm {
            Some(p) => (
                ErrorStats::from_norms(fit.calibration_before).mean_mm,
                p,
                "new poses (the prediction; the calibration points before)",
            ),
            None => {
                return check(
                    CheckKind::Improvement,
                    f64::NAN,
                    1.0,
                    "ratio",
                    true,
                    "not measurable: no validation points and no prediction".into(),
                )
            }
        },
    };
    let ratio = after / before;
    let worse = ratio > IMPROVEMENT_LIMIT && after - before > IMPROVEMENT_FLOOR_MM;
    check(
        CheckKind::Improvement,
        ratio,
        IMPROVEMENT_LIMIT,
        "ratio",
        !worse,
        format!(
            "on {basis} the calibrated model misses by {after:.4} mm on average, the model it \
             started from (nominal geometry, fitted tools) by {before:.4} mm (ratio {}); limit: \
             {IMPROVEMENT_LIMIT} times (the parameters' uncertainty added to an accurate robot)",
            sig(ratio)
        ),
    )
}

/// The `discarded_points` check (see the module docs).
pub(super) fn discarded(fit: &Fit) -> Check {
    let n = fit.calibration.len().max(1);
    let share = fit.downweighted as f64 / n as f64;
    check(
        CheckKind::DiscardedPoints,
        share,
        DISCARD_SHARE_LIMIT,
        "share",
        share <= DISCARD_SHARE_LIMIT,
        format!(
            "{} of {n} calibration points ({:.1}%) lie beyond the robust loss's threshold; limit: \
             {}%",
            fit.downweighted,
            100.0 * share,
            100.0 * DISCARD_SHARE_LIMIT
        ),
    )
}

/// The `residuals` check (see the module docs); passes, saying so, without a noise model.
pub(super) fn residuals(fit: &Fit) -> Check {
    let obs = fit.calibration;
    let sigmas: Vec<f64> = (0..obs.len()).filter_map(|i| obs.sigma_mm(i)).collect();
    let noise = fit.noise_sigma_mm.filter(|s| s.is_finite());
    let (Some(noise), false) = (noise, sigmas.is_empty()) else {
        return check(
            CheckKind::Residuals,
            f64::NAN,
            RESIDUAL_RATIO_LIMIT,
            "ratio",
            true,
            "not measured: the points carry no uncertainty (no tracker model, no sigma_mm)".into(),
        );
    };
    let typical = crate::stats::percentile(&sigmas, 0.5);
    let ratio = noise / typical;
    check(
        CheckKind::Residuals,
        ratio,
        RESIDUAL_RATIO_LIMIT,
        "ratio",
        ratio <= RESIDUAL_RATIO_LIMIT,
        format!(
            "the residuals' noise is {noise:.4} mm per axis, {} times the points' typical \
             uncertainty of {typical:.4} mm; limit: {RESIDUAL_RATIO_LIMIT} times",
            sig(ratio)
        ),
    )
}

/// The `weight_share` check (see the module docs).
pub(super) fn weight_share(fit: &Fit) -> Check {
    let obs = fit.calibration;
    let weights: Vec<f64> = (0..obs.len()).map(|i| obs.weight(i).powi(2)).collect();
    let total: f64 = weights.iter().sum();
    let (i, w) = weights
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, 0.0));
    let share = if total > 0.0 { w / total } else { 0.0 };
    let passed = share <= WEIGHT_SHARE_LIMIT;
    check(
        CheckKind::WeightShare,
        share,
        WEIGHT_SHARE_LIMIT,
        "share",
        passed,
        format!(
            "the heaviest point (calibration point {}) carries {:.1}% of the total weight; \
             limit: {}%",
            i + 1,
            100.0 * share,
            100.0 * WEIGHT_SHARE_LIMIT
        ),
    )
}
