//! Objectives of the identification: functions of the displacement error norms.
//!
//! Every objective is `f = sum_i l(|e_i|)` with `e_i = pose(F) m_i - p(q_i; theta)` (eq. 3) and a
//! per-point loss `l` of the error norm `r`. Each `l(sqrt(s))` is concave in `s = r^2`, so
//! `f` is majorized by the weighted least-squares surrogate with weights `w = l'(r) / r`; the
//! solver's iteratively reweighted steps therefore never increase `f` (majorize-minimize).

/// Which objective to minimize (the CLI's `--objective`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Objective {
    /// The paper's total displacement error, `sum |e_i|` (eq. 4). Default.
    SumOfNorms,
    /// `sum |e_i|^2`.
    LeastSquares,
    /// A robust loss whose scale comes from the residuals (see [`RobustLoss`]).
    Robust(RobustLoss),
}

impl Objective {
    /// The CLI name.
    pub fn name(&self) -> &'static str {
        match self {
            Objective::SumOfNorms => "sum-of-norms",
            Objective::LeastSquares => "least-squares",
            Objective::Robust(RobustLoss::Cauchy) => "robust (Cauchy)",
            Objective::Robust(RobustLoss::Huber) => "robust (Huber)",
        }
    }
}

/// The robust losses. Their scale `c` is set from the residuals of a sum-of-norms fit: with
/// `sigma = median(|e_i|) / 1.5382` (the per-axis standard deviation for isotropic Gaussian
/// errors, whose norms have median 1.5382 sigma), `c = ROBUST_SCALE_SIGMAS * sigma`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RobustLoss {
    /// `l(r) = c^2/2 ln(1 + r^2/c^2)`: gross outliers get almost no weight. Default.
    Cauchy,
    /// `l(r) = r^2/2` for `r <= c`, else `c r - c^2/2`: bounded influence, convex.
    Huber,
}

/// Median of the norm of a 3-D standard normal vector (chi distribution, 3 degrees of freedom).
pub const CHI3_MEDIAN: f64 = 1.538_172;

/// Robust scale `c` in units of the estimated per-axis sigma. At 4 sigma a clean point is past
/// the scale with probability 0.1% (chi-square, 3 degrees of freedom), so only real outliers are
/// down-weighted.
pub const ROBUST_SCALE_SIGMAS: f64 = 4.0;

/// Smoothing of the sum of norms (mm): `l(r) = sqrt(r^2 + delta^2) - delta`. Far below any
/// tracker's resolution, it only keeps the objective differentiable at a zero error.
pub const SUM_OF_NORMS_SMOOTHING_MM: f64 = 1e-6;

/// A per-point loss with its scale, as the solver uses it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Loss {
    /// `sqrt(r^2 + delta^2) - delta`.
    SumOfNorms {
        /// Smoothing delta (mm).
        delta: f64,
    },
    /// `r^2 / 2`.
    Squared,
    /// Huber with threshold `k` (mm).
    Huber {
        /// Threshold (mm).
        k: f64,
    },
    /// Cauchy with scale `c` (mm).
    Cauchy {
        /// Scale (mm).
        c: f64,
    },
}

impl Loss {
    /// The loss's name for progress reports and messages: `sum of norms`, `least squares`,
    /// `Huber` or `Cauchy`.
    pub fn name(&self) -> &'static str {
        match self {
            Loss::SumOfNorms { .. } => "sum of norms",
            Loss::Squared => "least squares",
            Loss::Huber { .. } => "Huber",
            Loss::Cauchy { .. } => "Cauchy",
        }
    }

    /// `l(r)`.
    #[inline]
    pub fn value(&self, r: f64) -> f64 {
        match *self {
            Loss::SumOfNorms { delta } => (r * r + delta * delta).sqrt() - delta,
            Loss::Squared => 0.5 * r * r,
            Loss::Huber { k } => {
                if r <= k {
                    0.5 * r * r
                } else {
                    k * r - 0.5 * k * k
                }
            }
            Loss::Cauchy { c } => 0.5 * c * c * (r * r / (c * c)).ln_1p(),
        }
    }

    /// The IRLS weight `w = l'(r) / r` (the gradient of `l(|e|)` is `w e`).
    #[inline]
    pub fn weight(&self, r: f64) -> f64 {
        match *self {
            Loss::SumOfNorms { delta } => 1.0 / (r * r + delta * delta).sqrt(),
            Loss::Squared => 1.0,
            Loss::Huber { k } => {
                if r <= k {
                    1.0
                } else {
                    k / r
                }
            }
            Loss::Cauchy { c } => 1.0 / (1.0 + r * r / (c * c)),
        }
    }

    /// The curvature of `l` along the error, `l''(r)`, clamped at zero: the Hessian of
    /// `l(|e|)` with respect to `e` is `w (I - u u^T) + l''(r) u u^T` with `u = e / |e|`.
    #[inline]
    pub fn radial_curvature(&self, r: f64) -> f64 {
        match *self {
            Loss::SumOfNorms { delta } => {
                let s = r * r + delta * delta;
                delta * delta / (s * s.sqrt())
            }
            Loss::Squared => 1.0,
            Loss::Huber { k } => {
                if r <= k {
                    1.0
                } else {
                    0.0
                }
            }
            Loss::Cauchy { c } => {
                let t = r * r / (c * c);
                ((1.0 - t) / ((1.0 + t) * (1.0 + t))).max(0.0)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_and_curvatures_match_finite_differences() {
        for loss in [
            Loss::SumOfNorms { delta: 1e-3 },
            Loss::Squared,
            Loss::Huber { k: 0.5 },
            Loss::Cauchy { c: 0.3 },
        ] {
            for r in [0.01, 0.2, 0.7, 2.0] {
                let h = 1e-6;
                let d1 = (loss.value(r + h) - loss.value(r - h)) / (2.0 * h);
                assert!((d1 / r - loss.weight(r)).abs() < 1e-6, "{loss:?} r={r}");
                let d2 = (loss.value(r + h) - 2.0 * loss.value(r) + loss.value(r - h)) / (h * h);
                assert!(
                    (d2.max(0.0) - loss.radial_curvature(r)).abs() < 1e-3,
                    "{loss:?} r={r}: {d2} vs {}",
                    loss.radial_curvature(r)
                );
            }
        }
    }
}
