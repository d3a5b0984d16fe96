//! The damped least-squares iteration both inverse-kinematics solvers run: the tool point's
//! ([`super::DampedLeastSquares`], 3 residual rows) and the full pose's ([`super::PoseNewton`],
//! 6 rows). A solver gives the residual and the joints' scaled Jacobian columns at a joint
//! vector; this module steps, damps, keeps the joints within their limits and says where the
//! run stopped.
//!
//! Each step solves `(A + mu tr(A)/R I) y = e` with `A = sum c_i c_i^T` over the free joints
//! (those not held at a limit by the descent direction `c_i . e`), moves joint i by
//! `sc_i c_i . y` (its scaled unit `sc_i`: rad, or mm per [prismatic scale]), shrunk to the
//! trust region `max_step` and clamped to the limits, and accepts it when the residual
//! decreases; the damping `mu` follows the gain ratio (Nielsen's update) and grows until a step
//! is accepted or it passes [`MAX_DAMPING`] (stalled).

use super::stop::{stop_point, StopPoint};
use crate::model::{JointLimit, MAX_JOINTS};
use nalgebra::{SMatrix, SVector};

/// Largest relative damping before a solve is declared stalled.
const MAX_DAMPING: f64 = 1e8;
/// Smallest relative damping (keeps `A + mu I` positive definite).
const MIN_DAMPING: f64 = 1e-14;
/// Relative decrease of the residual over the second half of the iteration budget below which a
/// run that used it up counts as stopped on a plateau.
const PLATEAU: f64 = 1e-3;

/// The solver's settings the iteration uses.
pub(crate) struct Iteration {
    pub max_iterations: usize,
    pub max_step: f64,
    pub initial_damping: f64,
    pub stationary_cosine: f64,
}

/// Where a run stopped.
#[derive(Clone, Copy)]
pub(crate) struct Run<T> {
    /// What the solver's evaluation returned besides the residual, at the last joints.
    pub at: T,
    pub iterations: usize,
    /// Joints at a limit whose descent direction points out of the range (bit mask).
    pub blocking: u32,
    /// Joints at a limit (bit mask).
    pub at_limit: u32,
    /// Whether the run stopped at a stationary point of the distance: no step with any damping
    /// reduced the error, no free joint's column has a direction cosine with the error above
    /// the stationary cosine, or the residual reached a plateau.
    pub stationary: bool,
}

/// Runs the iteration on `q[..n]` (in place), `sc` the joints' scaled units. `eval(q, cols)`
/// returns the residual and the solver's own figures at `q` and writes the scaled columns;
/// `done` says from those figures whether the target is reached. With `limits`, the joints stay
/// within `lim`.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(crate) fn run<const R: usize, T: Copy>(
    n: usize,
    lim: &[JointLimit],
    sc: &[f64; MAX_JOINTS],
    q: &mut [f64],
    limits: bool,
    s: &Iteration,
    eval: impl Fn(&[f64], &mut [SVector<f64, R>; MAX_JOINTS]) -> (SVector<f64, R>, T),
    done: impl Fn(&T) -> bool,
) -> Run<T> {
    let mut cols = [SVector::<f64, R>::zeros(); MAX_JOINTS];
    let mut cols_t = [SVector::<f64, R>::zeros(); MAX_JOINTS];
    let mut qt = [0.0; MAX_JOINTS];
    let (mut e, mut at) = eval(q, &mut cols);
    let mut r = e.norm();
    let mut mu = s.initial_damping;
    let mut iterations = 1;
    let mut stalled = false;
    let mut r_half = f64::INFINITY;
    loop {
        if r_half.is_infinite() && 2 * iterations >= s.max_iterations {
            r_half = r;
        }
        // Free joints: those not held at a limit by the descent direction g_i = c_i . e.
        let mut free = 0u32;
        for i in 0..n {
            let g = cols[i].dot(&e);
            let blocked =
                limits && ((q[i] <= lim[i].min && g < 0.0) || (q[i] >= lim[i].max && g > 0.0));
            if !blocked {
                free |= 1 << i;
            }
        }
        if done(&at) || iterations >= s.max_iterations {
            break;
        }
        let mut a = SMatrix::<f64, R, R>::zeros();
        for i in (0..n).filter(|i| free & (1 << i) != 0) {
            a += cols[i] * cols[i].transpose();
        }
        let scale = a.trace() / R as f64;
        if scale <= 0.0 || !scale.is_finite() {
            stalled = true;
            break;
        }
        let mut accepted = false;
        let mut nu = 2.0;
        while mu <= MAX_DAMPING {
            let m = a + SMatrix::<f64, R, R>::identity() * (mu * scale);
            let Some(ch) = m.cholesky() else {
                mu *= nu;
                nu *= 2.0;
                continue;
            };
            let y = ch.solve(&e);
            // The step in scaled units u_i = c_i . y; the joints move by sc_i u_i.
            let mut largest = 0.0f64;
            for i in 0..n {
                qt[i] = if free & (1 << i) != 0 {
                    cols[i].dot(&y)
                } else {
                    0.0
                };
                largest = largest.max(qt[i].abs());
            }
            let shrink = if largest > s.max_step {
                s.max_step / largest
            } else {
                1.0
            };
            // The residual the linear model predicts after the step actually taken (shrunk and
            // clamped).
            let mut predicted = e;
            for i in 0..n {
                let mut v = q[i] + sc[i] * qt[i] * shrink;
                if limits {
                    v = v.clamp(lim[i].min, lim[i].max);
                }
                predicted -= cols[i] * ((v - q[i]) / sc[i]);
                qt[i] = v;
            }
            let (et, at_t) = eval(&qt[..n], &mut cols_t);
            iterations += 1;
            let rt = et.norm();
            if rt < r {
                let gain = (r * r - rt * rt) / (r * r - predicted.norm_squared()).max(1e-300);
                q.copy_from_slice(&qt[..n]);
                std::mem::swap(&mut cols, &mut cols_t);
                e = et;
                at = at_t;
                r = rt;
                mu = (mu * (1.0 / 3.0f64).max(1.0 - (2.0 * gain - 1.0).powi(3))).max(MIN_DAMPING);
                accepted = true;
                break;
            }
            mu *= nu;
            nu *= 2.0;
            if iterations >= s.max_iterations {
                break;
            }
        }
        if !accepted {
            stalled = mu > MAX_DAMPING;
            break;
        }
    }
    let StopPoint {
        blocking,
        at_limit,
        max_cosine,
    } = stop_point(&cols[..n], &e, r, &q[..n], lim, limits, s.stationary_cosine);
    let plateau = iterations >= s.max_iterations && r_half - r < PLATEAU * r_half;
    Run {
        at,
        iterations,
        blocking,
        at_limit,
        // With fewer joints than residual rows, every column orthogonal to the residual is the
        // least-squares optimum: stationary too.
        stationary: stalled || plateau || max_cosine < s.stationary_cosine,
    }
}
