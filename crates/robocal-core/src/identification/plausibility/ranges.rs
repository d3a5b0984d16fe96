//! The gate's check of the families that act through the joints (compliance, transmission
//! errors): every identified parameter within its family's plausible range
//! ([`crate::model::family::plausible`]). The geometric families have their own checks (length and
//! angle moves), with the same limits.

use super::{check, diagnosis::sig, Check, CheckKind, Fit};
use crate::model::family::plausible;

/// How far one parameter is from its plausible range: its move over the largest plausible move,
/// or, when its value lies outside the range's values, above 1 by how far.
struct Excess {
    name: String,
    ratio: f64,
    detail: String,
}

fn excess(fit: &Fit, p: crate::model::Param) -> Excess {
    let range = plausible::of(fit.start, p);
    let unit = p.unit();
    let u = unit.as_str();
    let start = if fit.start.has_param(p) {
        unit.from_internal(fit.start.get(p))
    } else {
        0.0
    };
    let value = unit.from_internal(fit.calibrated.get(p));
    let moved = (value - start).abs();
    let mut ratio = moved / range.max_move;
    let mut detail = format!(
        "{} = {} {u}, moved by {} {u}; plausible move {} {u} ({})",
        p.name(),
        sig(value),
        sig(moved),
        sig(range.max_move),
        range.why
    );
    if !range.contains(value) {
        let (bound, side) = if value < range.min {
            (range.min, "below its plausible minimum")
        } else {
            (range.max, "above its plausible maximum")
        };
        let width = if range.max_move > 0.0 {
            range.max_move
        } else {
            1.0
        };
        ratio = ratio.max(1.0 + (value - bound).abs() / width);
        detail = format!(
            "{} = {} {u}, {side} {} {u} ({})",
            p.name(),
            sig(value),
            sig(bound),
            range.why
        );
    }
    Excess {
        name: p.name(),
        ratio,
        detail,
    }
}

/// The largest joint deflection (degrees) the calibrated model's families acting through the
/// joints give over the calibration poses, with the joint (0-based) and the point.
fn largest_deflection(fit: &Fit) -> Option<(f64, usize, usize)> {
    let robot = fit.calibrated;
    if !robot.deflects_joints() {
        return None;
    }
    let obs = fit.calibration;
    let mut buf = [0.0; crate::model::MAX_JOINTS];
    let mut worst: Option<(f64, usize, usize)> = None;
    for i in 0..obs.len() {
        let q = obs.q(i);
        let d = robot.deflected(q, &mut buf);
        for (j, (a, b)) in d.iter().zip(q).enumerate() {
            let deg = (a - b).abs().to_degrees();
            if worst.map_or(true, |w| deg > w.0) {
                worst = Some((deg, j, i));
            }
        }
    }
    worst
}

/// The `parameter_ranges` check: the worst identified parameter of a family acting through the
/// joints against its plausible range (its move over the plausible move, above 1 also when its
/// value lies outside the range), and the joint deflection those families give over the
/// calibration poses against [`plausible::JOINT_DEFLECTION_DEG`] (limit 1 for the ratio).
pub(super) fn check_non_geometric(fit: &Fit) -> Check {
    let mut worst = fit
        .identified
        .iter()
        .filter(|p| {
            p.family().deflects_joints(fit.start) && plausible::of(fit.start, **p).individual
        })
        .map(|&p| excess(fit, p))
        .max_by(|a, b| a.ratio.total_cmp(&b.ratio));
    let any = fit
        .identified
        .iter()
        .any(|p| p.family().deflects_joints(fit.start));
    if any {
        if let Some((deg, j, i)) = largest_deflection(fit) {
            let ratio = deg / plausible::JOINT_DEFLECTION_DEG;
            if worst.as_ref().map_or(true, |w| ratio > w.ratio) {
                worst = Some(Excess {
                    name: format!("the deflection of joint {}", j + 1),
                    ratio,
                    detail: format!(
                        "the compliance and transmission parameters turn joint {} by {} deg at \
                         calibration point {}; plausible: {} deg",
                        j + 1,
                        sig(deg),
                        i + 1,
                        plausible::JOINT_DEFLECTION_DEG
                    ),
                });
            }
        }
    }
    match worst.filter(|_| any) {
        None => check(
            CheckKind::ParameterRanges,
            0.0,
            1.0,
            "ratio",
            true,
            "no parameter of a family acting through the joints identified".into(),
        ),
        Some(w) => {
            let passed = w.ratio <= 1.0;
            check(
                CheckKind::ParameterRanges,
                w.ratio,
                1.0,
                "ratio",
                passed,
                if passed {
                    format!(
                        "every non-geometric parameter within its plausible range; the nearest \
                         to its limit: {}",
                        w.detail
                    )
                } else {
                    format!("{} is outside its plausible range: {}", w.name, w.detail)
                },
            )
        }
    }
}
