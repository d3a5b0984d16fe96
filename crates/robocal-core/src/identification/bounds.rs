//! Bounded parameters: a family whose values have a bound (a physical compliance is never
//! negative, [`crate::model::family::plausible`]) and whose nominal value is that bound.
//!
//! The identification is unconstrained. When it puts such a parameter beyond its bound by less
//! than 3 standard deviations, the data cannot tell it from the bound: the parameter is held at
//! the bound (its nominal value) and the fit repeated, and the result says so
//! ([`crate::identification::identifiability::FixReason::AtBound`]). Beyond 3 standard
//! deviations the data contradict the model, and the plausibility gate refuses the fit, naming
//! the parameter.

use crate::identification::covariance::Covariance;
use crate::model::family::plausible;
use crate::model::{Param, Robot};

/// How many standard deviations beyond its bound a value may lie and still be held at it.
pub const HOLD_SIGMAS: f64 = 3.0;

/// A parameter to hold at its bound (display units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Held {
    /// The parameter.
    pub param: Param,
    /// The value the fit gave.
    pub value: f64,
    /// Its standard deviation.
    pub std: f64,
    /// The bound.
    pub bound: f64,
}

/// The identified parameters of `calibrated` (started from `start`) that lie beyond a bound of
/// their plausible values equal to their starting value, by less than [`HOLD_SIGMAS`] standard
/// deviations.
pub fn to_hold(start: &Robot, calibrated: &Robot, covariance: &Covariance) -> Vec<Held> {
    covariance
        .params
        .iter()
        .filter_map(|&p| {
            let unit = p.unit();
            let range = plausible::of(start, p);
            let value = unit.from_internal(calibrated.get(p));
            let begin = unit.from_internal(if start.has_param(p) {
                start.get(p)
            } else {
                0.0
            });
            let bound = if value < range.min {
                range.min
            } else if value > range.max {
                range.max
            } else {
                return None;
            };
            // Only a bound the fit can be held at: the parameter's starting value.
            if (begin - bound).abs() > 1e-12 * bound.abs().max(1.0) {
                return None;
            }
            let std = unit.from_internal(covariance.std_of(p)?);
            ((value - bound).abs() <= HOLD_SIGMAS * std).then_some(Held {
                param: p,
                value,
                std,
                bound,
            })
        })
        .collect()
}
