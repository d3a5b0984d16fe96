//! What constraint data cannot see: the structural analysis on the nominal tool points (the
//! base frame and what duplicates it, and per family beyond geometry the parameters the
//! constraints do not determine), and the fit's weakest direction with its names.

use super::fit::Layout;
use super::{ConstraintOptions, FeatureEstimate, Fixed};
use crate::error::Result;
use crate::identification::identifiability::{analyze, IdentifiabilityOptions};
use crate::model::family::{backlash, compliance, thermal, transmission};
use crate::model::{Param, Robot};
use crate::observations::constraint::ConstraintData;
use crate::observations::{Observations, RowExtras};
use nalgebra::DMatrix;

/// The structural analysis: the parameters tool points could identify (linearized at zero
/// residual), less the base frame and what duplicates it.
pub(super) fn structural(
    robot: &Robot,
    data: &ConstraintData,
    opts: &ConstraintOptions,
) -> Result<(Vec<Param>, Vec<Fixed>)> {
    let mut obs = Observations::new(robot.dof());
    let rows = data.rows.iter().map(|r| (&r.q, &r.conditions, r.line));
    let tracker = data.tracker.iter().map(|t| (&t.q, &t.conditions, t.line));
    for (q, c, line) in rows.chain(tracker) {
        let extras = RowExtras {
            conditions: Some(*c),
            ..RowExtras::default()
        };
        obs.push_with(q, robot.target_position_in(q, 0, c), extras, line)?;
    }
    let id = analyze(
        robot,
        &obs,
        &IdentifiabilityOptions {
            rank_tolerance: opts.rank_tolerance,
            ..IdentifiabilityOptions::default()
        },
    )?;
    let base = Param::base(0).family_id();
    let mut fixed: Vec<Fixed> = Vec::new();
    let mut identified = Vec::new();
    for p in &id.identified {
        if p.family_id() == base {
            fixed.push(Fixed {
                param: *p,
                reason: "base frame: no reference in constraint data (the result is up to the \
                         base pose)"
                    .into(),
            });
        } else {
            identified.push(*p);
        }
    }
    for f in &id.fixed {
        let mut reason = f.describe();
        if let crate::identification::identifiability::FixReason::Duplicate { of, .. } = &f.reason {
            if of.iter().any(|(q, _)| q.family_id() == base) {
                reason.push_str(" (moves like the base frame, which constraint data cannot see)");
            }
        }
        fixed.push(Fixed {
            param: f.param,
            reason,
        });
    }
    Ok((identified, fixed))
}

/// The families beyond geometry and their names in messages.
const FAMILIES: [(&str, &str); 4] = [
    (compliance::KEY, "joint compliance"),
    (transmission::KEY, "transmission harmonics"),
    (backlash::KEY, "backlash"),
    (thermal::KEY, "thermal expansion"),
];

/// For each family beyond geometry with parameters the structural analysis fixed, what the
/// constraints cannot see of it.
pub(super) fn unseen_family_parameters(fixed: &[Fixed]) -> Vec<String> {
    FAMILIES
        .iter()
        .filter_map(|(key, name)| {
            let of: Vec<String> = fixed
                .iter()
                .filter(|f| f.param.family().key() == *key)
                .map(|f| f.param.name())
                .collect();
            (!of.is_empty()).then(|| {
                format!(
                    "{name}: {} not determined by these constraints (each held at its nominal \
                     value; the reason is beside each)",
                    of.join(", ")
                )
            })
        })
        .collect()
}

/// The condition number of `j` with unit columns and, when its smallest singular value is below
/// `tol` times the largest, that direction (in the unscaled unknowns' columns order, unit norm
/// in scaled units).
pub(super) fn weakest(j: &DMatrix<f64>, tol: f64) -> (f64, Option<Vec<f64>>) {
    let n = j.ncols();
    let norms: Vec<f64> = (0..n).map(|c| j.column(c).norm()).collect();
    let js = DMatrix::from_fn(j.nrows(), n, |r, c| {
        if norms[c] > 0.0 {
            j[(r, c)] / norms[c]
        } else {
            0.0
        }
    });
    let svd = js.svd(false, true);
    let s = &svd.singular_values;
    let (imin, smin) = s.argmin();
    let smax = s.max();
    let cond = if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    };
    if smin > tol * smax {
        return (cond, None);
    }
    let vt = svd.v_t.expect("asked for");
    (cond, Some(vt.row(imin).iter().copied().collect()))
}

/// The name of unknown `k` of a fit.
pub(super) fn column_name(layout: &Layout, features: &[FeatureEstimate], k: usize) -> String {
    if k < layout.params.len() {
        return layout.params[k].name();
    }
    for (f, &c0) in features.iter().zip(&layout.feature_col) {
        if (c0..c0 + f.param_count()).contains(&k) {
            return f.param_names()[k - c0].clone();
        }
    }
    if let Some(c0) = layout.frame_col.filter(|c0| (*c0..c0 + 6).contains(&k)) {
        return format!("tracker frame {}", ["a", "b", "c", "x", "y", "z"][k - c0]);
    }
    format!("unknown {k}")
}

/// What to change when the features themselves are undetermined.
pub(super) fn feature_advice(features: &[FeatureEstimate]) -> String {
    let kinds: Vec<&str> = features.iter().map(|f| f.kind.key()).collect();
    format!(
        "the data's features ({}) need configurations that differ in orientation as well as in \
         position",
        kinds.join(", ")
    )
}
