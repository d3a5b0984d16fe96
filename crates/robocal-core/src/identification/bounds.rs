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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::family::compliance;
    use crate::model::presets::preset;
    use crate::model::Unit;
    use nalgebra::DMatrix;

    /// A physical compliance fitted at -2 +- 1 urad/(N·m) is held at 0; at -5 +- 1 (beyond 3
    /// standard deviations) it is not (the gate refuses it); a positive one is left alone.
    #[test]
    fn a_compliance_just_below_zero_is_held_at_zero() {
        let mut start = preset("kuka-kr480-r3330").unwrap();
        compliance::enable(&mut start, &[1, 2], Some(300.0)).unwrap();
        let ps: Vec<Param> = start
            .params()
            .into_iter()
            .filter(|p| p.name().starts_with("compliance"))
            .collect();
        assert_eq!(ps.len(), 2);
        let to = |v: f64| Unit::MicroradPerNm.to_internal(v);
        let cov = Covariance {
            params: ps.clone(),
            matrix: DMatrix::from_diagonal_element(2, 2, to(1.0).powi(2)),
            sigma_mm: 0.01,
            unavailable: None,
        };
        let mut cal = start.clone();
        cal.set(ps[0], to(-2.0));
        cal.set(ps[1], to(0.5));
        let held = to_hold(&start, &cal, &cov);
        assert_eq!(held.len(), 1);
        assert_eq!(held[0].param, ps[0]);
        assert!((held[0].value + 2.0).abs() < 1e-9 && held[0].bound == 0.0);
        cal.set(ps[0], to(-5.0));
        assert!(to_hold(&start, &cal, &cov).is_empty());
    }
}
