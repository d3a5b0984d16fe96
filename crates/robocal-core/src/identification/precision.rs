//! Practical identifiability: a parameter that is independent of the others in principle (it
//! passes the rank test of [`super::identifiability`]) may still be one the data cannot pin, when
//! its effect on the points is tiny compared with the measurement error: a wrist parameter seen
//! only through a reflector 0.2 mm off the flange axis. Identifying it lets the solver move it by
//! tens of millimetres or degrees to fit noise, and the plausibility gate then (rightly) rejects
//! the fit.
//!
//! Before identification, at the starting model, the covariance of the identified parameters is
//! predicted as `sigma0^2 (J^T W J)^-1` with `sigma0` the per-axis RMS error of the nominal
//! geometry with the fitted tools (an upper bound of the noise: it still contains the geometric
//! errors, so the prediction is conservative). A parameter whose predicted standard deviation
//! exceeds a third of the largest move the plausibility gate accepts (3 sigma beyond it: its
//! family's plausible move, [`crate::model::family::plausible`]: 5% of the reach for lengths, 10
//! degrees for angles, one degree of joint deflection for compliances and transmission errors)
//! is fixed, the worst first, and the others are
//! predicted again without it, until every identified parameter is within its limit. The pass
//! is skipped when the nominal model misses the data by more than the gate's nominal-error limit
//! (wrong units, another robot): the bound then means nothing and the gate names the cause.

use crate::identification::objective::Loss;
use crate::identification::system::{Accumulated, Level, Problem};
use crate::model::family::plausible;
use crate::model::{Param, Robot};
use nalgebra::DMatrix;

/// The limit of a parameter's predicted standard deviation (display unit): a third of its
/// family's plausible move ([`plausible::Plausible::max_move`]), for every family: lengths,
/// angles, compliances, transmission harmonics, reflector offsets.
pub fn std_limit(robot: &Robot, p: Param) -> Option<f64> {
    let m = plausible::of(robot, p).max_move;
    (m.is_finite() && m > 0.0).then_some(m / 3.0)
}

/// A parameter the data cannot pin, with its predicted standard deviation and the limit (display
/// unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Undetermined {
    /// The parameter.
    pub param: Param,
    /// Its predicted standard deviation.
    pub std: f64,
    /// The limit it exceeds ([`std_limit`]).
    pub limit: f64,
}

/// The identified parameters of `problem` that its data cannot pin (see the module docs), the
/// worst first; `sigma0_mm` is the per-axis noise bound. Parameters in `keep` are never chosen.
pub fn undetermined(
    start: &Robot,
    problem: &Problem,
    sigma0_mm: f64,
    keep_always: &[Param],
) -> Vec<Undetermined> {
    undetermined_keeping(start, problem, sigma0_mm, keep_always).0
}

/// [`undetermined`], also returning its pass: the full pass ([`Level::Full`]) of `problem` at
/// `start` with the squared loss, which a least-squares solve from `start` starts with.
pub(crate) fn undetermined_keeping(
    start: &Robot,
    problem: &Problem,
    sigma0_mm: f64,
    keep_always: &[Param],
) -> (Vec<Undetermined>, Option<Accumulated>) {
    let params = problem.params();
    if !(sigma0_mm > 0.0 && sigma0_mm.is_finite()) || params.is_empty() {
        return (Vec::new(), None);
    }
    let acc = problem.accumulate(start, &Loss::Squared, Level::Full);
    let out = undetermined_from(start, params, &acc, sigma0_mm, keep_always);
    (out, Some(acc))
}

/// [`undetermined`] from the pass `acc` over `params`.
pub(crate) fn undetermined_from(
    start: &Robot,
    params: &[Param],
    acc: &Accumulated,
    sigma0_mm: f64,
    keep_always: &[Param],
) -> Vec<Undetermined> {
    let Some(s) = &acc.s else { return Vec::new() };
    let mut keep: Vec<usize> = (0..params.len()).collect();
    let mut out = Vec::new();
    while !keep.is_empty() {
        let k = keep.len();
        let sub = DMatrix::from_fn(k, k, |r, c| s[(keep[r], keep[c])]);
        let Some(ch) = sub.cholesky() else { break };
        let inv = ch.inverse();
        let worst = (0..k)
            .filter(|&r| !keep_always.contains(&params[keep[r]]))
            .filter_map(|r| {
                let p = params[keep[r]];
                let std = sigma0_mm * inv[(r, r)].max(0.0).sqrt() * p.unit().from_internal(1.0);
                std_limit(start, p).map(|limit| (r, std, limit))
            })
            .filter(|(_, std, limit)| std > limit)
            .max_by(|a, b| (a.1 / a.2).total_cmp(&(b.1 / b.2)));
        let Some((r, std, limit)) = worst else { break };
        out.push(Undetermined {
            param: params[keep[r]],
            std,
            limit,
        });
        keep.remove(r);
    }
    out
}
