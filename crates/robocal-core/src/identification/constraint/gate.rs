//! The plausibility gate on constraint data (issue 31): the checks of the tracker path adapted
//! to a fit without a tracker. A result that fails one cannot be right, and `calibrate` refuses
//! to write it (unless accepted explicitly, marked "implausible").
//!
//! - each identified parameter's move within its family's plausible range
//!   ([`crate::model::family::plausible`]);
//! - each feature within twice the robot's reach of the base, each sphere's radius between 0
//!   and the reach;
//! - the scale: the robot's link lengths taken together changed by no more than
//!   [`MAX_SCALE_CHANGE`] (a known distance or radius in another unit, or a wrong one, scales
//!   the whole robot, and the residuals stay small);
//! - each known distance met within [`MAX_DISTANCE_RESIDUAL_MM`] plus [`MAX_DISTANCE_RESIDUAL`]
//!   of the distance (one distance that contradicts the others).

use super::features::FeatureEstimate;
use crate::model::{Param, Robot, Unit};
use crate::observations::constraint::ConstraintData;

/// Largest relative change of the robot's summed link lengths.
pub const MAX_SCALE_CHANGE: f64 = 0.005;
/// Largest absolute part of a known distance's residual (mm).
pub const MAX_DISTANCE_RESIDUAL_MM: f64 = 0.5;
/// Largest relative part of a known distance's residual.
pub const MAX_DISTANCE_RESIDUAL: f64 = 1e-3;

/// The summed absolute link lengths (`a`, `d`; mm) of `robot`.
fn length_sum(robot: &Robot) -> f64 {
    robot
        .param_list()
        .iter()
        .filter(|p| p.family_id() == Param::d(0).family_id() && p.unit() == Unit::Mm)
        .map(|p| robot.get(*p).abs())
        .sum()
}

/// The plausibility gate on constraint data: each identified parameter's move within its
/// family's plausible range, each feature within twice the robot's reach of the base, each
/// sphere's radius below the reach.
pub(super) fn checks(
    start: &Robot,
    robot: &Robot,
    features: &[FeatureEstimate],
    data: &ConstraintData,
    distance_residuals_mm: &[f64],
) -> Vec<String> {
    let mut out = Vec::new();
    for &p in start.param_list() {
        let (was, now) = (start.get_display(p), robot.get_display(p));
        let range = crate::model::family::plausible::of(start, p);
        let u = p.unit().as_str();
        if (now - was).abs() > range.max_move || !range.contains(now) {
            out.push(format!(
                "{} moved from {was:.4} to {now:.4} {u}, beyond its plausible range ({})",
                p.name(),
                range.why
            ));
        }
    }
    let reach = robot.reach_mm();
    for f in features {
        if f.position.norm() > 2.0 * reach {
            out.push(format!(
                "{} is {:.0} mm from the base, beyond twice the robot's reach ({reach:.0} mm)",
                f.label(),
                f.position.norm()
            ));
        }
        if let Some(r) = f
            .radius_mm
            .filter(|r| r.is_nan() || *r <= 0.0 || *r >= reach)
        {
            out.push(format!(
                "{}'s radius {r:.3} mm is not between 0 and the robot's reach",
                f.label()
            ));
        }
    }
    let (was, now) = (length_sum(start), length_sum(robot));
    if was > 0.0 && ((now - was) / was).abs() > MAX_SCALE_CHANGE {
        out.push(format!(
            "the robot's link lengths changed together by {:+.2}% (beyond {:.1}%): the whole robot \
             was scaled, which means a known distance or radius is wrong or in another unit \
             (they are mm)",
            100.0 * (now - was) / was,
            100.0 * MAX_SCALE_CHANGE
        ));
    }
    for (d, r) in data.distances.iter().zip(distance_residuals_mm) {
        let limit = MAX_DISTANCE_RESIDUAL_MM + MAX_DISTANCE_RESIDUAL * d.distance_mm;
        if r.is_nan() || r.abs() > limit {
            out.push(format!(
                "the known distance {}-{} ({} mm, line {} of the distances file) is not met: \
                 the fitted features are {r:+.3} mm off it (beyond {limit:.3} mm), so it \
                 contradicts the rows or the other distances",
                data.features[d.from].name, data.features[d.to].name, d.distance_mm, d.line
            ));
        }
    }
    out
}
