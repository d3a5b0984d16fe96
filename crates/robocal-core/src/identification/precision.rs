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
    let k = params.len();
    let mut out = Vec::new();
    let Some(ch) = DMatrix::from_fn(k, k, |r, c| s[(r, c)]).cholesky() else {
        return out;
    };
    // The inverse of the kept parameters' block, updated as each is dropped (the inverse of a
    // block without row and column i is the Schur complement of the full inverse's entry i:
    // `inv - inv[:, i] inv[i, :] / inv[i, i]` on the rest), one factorization in all.
    let mut inv = ch.inverse();
    let mut keep: Vec<usize> = (0..k).collect();
    while !keep.is_empty() {
        let worst = keep
            .iter()
            .enumerate()
            .filter(|(_, &i)| !keep_always.contains(&params[i]))
            .filter_map(|(r, &i)| {
                let p = params[i];
                let std = sigma0_mm * inv[(i, i)].max(0.0).sqrt() * p.unit().from_internal(1.0);
                std_limit(start, p).map(|limit| (r, std, limit))
            })
            .filter(|(_, std, limit)| std > limit)
            .max_by(|a, b| (a.1 / a.2).total_cmp(&(b.1 / b.2)));
        let Some((r, std, limit)) = worst else { break };
        let i = keep.remove(r);
        out.push(Undetermined {
            param: params[i],
            std,
            limit,
        });
        if !drop_from_inverse(&mut inv, &keep, i) {
            break;
        }
    }
    out
}

/// Turns the entries at rows and columns `keep` of `inv`, the inverse of a symmetric positive
/// definite block over `keep` and `i`, into the inverse of the block over `keep` alone (the
/// Schur complement of `inv[i, i]`: `inv - inv[:, i] inv[i, :] / inv[i, i]`). `false` when that
/// pivot is not positive (`inv` was no such inverse), leaving `inv` as it was.
fn drop_from_inverse(inv: &mut DMatrix<f64>, keep: &[usize], i: usize) -> bool {
    let pivot = inv[(i, i)];
    if pivot.is_nan() || pivot <= 0.0 {
        return false;
    }
    let column: Vec<f64> = keep.iter().map(|&a| inv[(a, i)]).collect();
    for (&b, &cb) in keep.iter().zip(&column) {
        for (&a, &ca) in keep.iter().zip(&column) {
            inv[(a, b)] -= ca * cb / pivot;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::drop_from_inverse;
    use nalgebra::DMatrix;

    /// Dropping parameters one by one from the inverse gives the inverse of what is left, as
    /// a factorization of that block gives it.
    #[test]
    fn dropping_from_the_inverse_gives_the_inverse_of_the_rest() {
        let n = 9;
        let m = DMatrix::from_fn(n, n, |r, c| {
            ((r * 7 + c * 3) % 11) as f64 - 5.0 + (r == c) as u8 as f64
        });
        let s = &m * m.transpose() + DMatrix::identity(n, n);
        let mut inv = s.clone().cholesky().unwrap().inverse();
        let mut keep: Vec<usize> = (0..n).collect();
        for i in [4, 0, 7] {
            keep.retain(|&a| a != i);
            assert!(drop_from_inverse(&mut inv, &keep, i));
            let k = keep.len();
            let sub = DMatrix::from_fn(k, k, |r, c| s[(keep[r], keep[c])]);
            let want = sub.cholesky().unwrap().inverse();
            for r in 0..k {
                for c in 0..k {
                    let got = inv[(keep[r], keep[c])];
                    assert!(
                        (got - want[(r, c)]).abs() <= 1e-12 * want[(r, r)].abs().max(1.0),
                        "{got} against {}",
                        want[(r, c)]
                    );
                }
            }
        }
        let mut broken = DMatrix::from_element(2, 2, -1.0);
        assert!(!drop_from_inverse(&mut broken, &[1], 0));
        assert_eq!(broken, DMatrix::from_element(2, 2, -1.0));
    }
}
