//! Where an inverse-kinematics run stopped ([`super::damped`], for both solvers: the tool point's
//! [`super::DampedLeastSquares`] and the full pose's [`super::PoseNewton`]): which joints sit at a
//! limit, which of those block the way to the target, and how far the residual is from
//! orthogonal to the free joints' columns (a stationary point of the distance).

use crate::model::JointLimit;
use nalgebra::SVector;

/// The stopping point of a run.
pub(crate) struct StopPoint {
    /// Joints at a limit whose column points the residual beyond it (bit i: joint i).
    pub blocking: u32,
    /// Joints at a limit.
    pub at_limit: u32,
    /// The largest |cosine| between the residual and a column free to move towards it.
    pub max_cosine: f64,
}

/// Classifies the stopping point `q` from the joints' columns `cols` (first `q.len()`), the
/// residual `e` of norm `r` and the limits (checked only when `limits`); a joint at a limit
/// blocks when its cosine with the residual beyond the limit exceeds `stationary_cosine`.
pub(crate) fn stop_point<const D: usize>(
    cols: &[SVector<f64, D>],
    e: &SVector<f64, D>,
    r: f64,
    q: &[f64],
    lim: &[JointLimit],
    limits: bool,
    stationary_cosine: f64,
) -> StopPoint {
    let mut out = StopPoint {
        blocking: 0,
        at_limit: 0,
        max_cosine: 0.0,
    };
    for i in 0..q.len() {
        let cn = cols[i].norm();
        let cos = if cn > 0.0 && r > 0.0 {
            cols[i].dot(e) / (cn * r)
        } else {
            0.0
        };
        let low = limits && q[i] <= lim[i].min;
        let high = limits && q[i] >= lim[i].max;
        if low || high {
            out.at_limit |= 1 << i;
        }
        if (low && cos < -stationary_cosine) || (high && cos > stationary_cosine) {
            out.blocking |= 1 << i;
        } else if !((low && cos < 0.0) || (high && cos > 0.0)) {
            out.max_cosine = out.max_cosine.max(cos.abs());
        }
    }
    out
}
