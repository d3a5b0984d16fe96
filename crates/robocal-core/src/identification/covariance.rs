//! Uncertainty of the identified parameters.
//!
//! For the objective `f = sum l(|e_i|)` the estimate is an M-estimator; its covariance is the
//! sandwich `H^-1 B H^-1` with `H` the objective's Hessian (Gauss–Newton part,
//! `sum J^T (w (I - u u^T) + l'' u u^T) J`) and `B` the covariance of the gradient. Assuming
//! isotropic measurement errors, `B = (sum |l'(r_i)|^2 / m) sum J^T J` over the m residual rows
//! (3N for N points), and a factor `m / (m - k)` corrects for the k fitted parameters. For least
//! squares this is the textbook `sigma^2 (J^T J)^-1` with `sigma^2 = sum r^2 / (m - k)`; for the sum of norms and the robust
//! losses it accounts for their weights (the plain `(J^T W J)^-1` formula would understate the
//! spread of a sum-of-norms estimate by about a third).

use crate::identification::system::Accumulated;
use crate::model::Param;
use nalgebra::DMatrix;

/// The covariance of the identified parameters (internal units: mm, rad).
#[derive(Debug, Clone, PartialEq)]
pub struct Covariance {
    /// The parameters, in the order of the matrix.
    pub params: Vec<Param>,
    /// The covariance matrix (NaN when the Hessian is singular).
    pub matrix: DMatrix<f64>,
    /// Estimated per-axis standard deviation of the measurement errors, `sqrt(B/S)` with the
    /// degrees-of-freedom correction (mm): for least squares the residual RMS per axis.
    pub sigma_mm: f64,
    /// Why the standard deviations are unavailable, when they are: an ill-conditioned problem
    /// (see [`crate::identification::MAX_CONDITION_NUMBER`]) or a Hessian that is not positive
    /// definite. Then [`Covariance::std_of`] gives `None` for every parameter rather than a
    /// number without meaning.
    pub unavailable: Option<String>,
}

/// A pair of parameters and the correlation of their estimates.
#[derive(Debug, Clone, PartialEq)]
pub struct Correlation {
    /// First parameter.
    pub a: Param,
    /// Second parameter.
    pub b: Param,
    /// Correlation coefficient in [-1, 1].
    pub rho: f64,
}

impl Covariance {
    /// The covariance from a full accumulation pass at the solution (its residual rows counted
    /// in [`Accumulated::rows`]).
    pub fn from_accumulated(params: &[Param], acc: &Accumulated) -> Covariance {
        let k = params.len();
        let m = acc.rows;
        let dof_factor = if m > k {
            m as f64 / (m - k) as f64
        } else {
            f64::NAN
        };
        let psi_var = acc.psi_sq / m.max(1) as f64 * dof_factor;
        let nan = || DMatrix::from_element(k, k, f64::NAN);
        let (Some(h), Some(s)) = (&acc.h, &acc.s) else {
            return Covariance {
                params: params.to_vec(),
                matrix: nan(),
                sigma_mm: f64::NAN,
                unavailable: Some("no second-order pass at the solution".into()),
            };
        };
        let (matrix, mut unavailable) = match h.clone().cholesky() {
            Some(ch) => {
                let hinv_s = ch.solve(s);
                let mut c = ch.solve(&hinv_s.transpose()) * psi_var;
                // Symmetrize rounding.
                c = (&c + c.transpose()) * 0.5;
                (c, None)
            }
            None => (
                nan(),
                Some(
                    "the objective's Hessian is not positive definite at the solution".to_string(),
                ),
            ),
        };
        if unavailable.is_none() {
            if let Some(j) =
                (0..k).find(|&j| !(matrix[(j, j)] >= 0.0 && matrix[(j, j)].is_finite()))
            {
                unavailable = Some(format!(
                    "the computed variance of {} is {:e}: rounding dominates the covariance",
                    params[j].name(),
                    matrix[(j, j)]
                ));
            }
        }
        // For least squares psi = r, so psi_var is the residual variance per axis.
        Covariance {
            params: params.to_vec(),
            matrix,
            sigma_mm: psi_var.sqrt(),
            unavailable,
        }
    }

    /// Marks every standard deviation unavailable, with the reason.
    pub fn mark_unavailable(&mut self, reason: impl Into<String>) {
        self.unavailable = Some(reason.into());
    }

    /// Whether `p` is one of the identified parameters.
    pub fn identifies(&self, p: Param) -> bool {
        self.params.contains(&p)
    }

    /// Standard deviation of each parameter (internal units); NaN for every parameter when they
    /// are unavailable (see [`Covariance::unavailable`]).
    pub fn std(&self) -> Vec<f64> {
        (0..self.params.len()).map(|j| self.std_at(j)).collect()
    }

    fn std_at(&self, j: usize) -> f64 {
        if self.unavailable.is_some() {
            f64::NAN
        } else {
            self.matrix[(j, j)].sqrt()
        }
    }

    /// The standard deviation of one parameter, if it is identified and the standard deviations
    /// are available.
    pub fn std_of(&self, p: Param) -> Option<f64> {
        self.params
            .iter()
            .position(|q| *q == p)
            .map(|j| self.std_at(j))
            .filter(|v| v.is_finite())
    }

    /// The `count` most correlated pairs, strongest first.
    pub fn most_correlated(&self, count: usize) -> Vec<Correlation> {
        let k = self.params.len();
        let sd = self.std();
        let mut out = Vec::new();
        for a in 0..k {
            for b in a + 1..k {
                let den = sd[a] * sd[b];
                if den > 0.0 && den.is_finite() {
                    out.push(Correlation {
                        a: self.params[a],
                        b: self.params[b],
                        rho: (self.matrix[(a, b)] / den).clamp(-1.0, 1.0),
                    });
                }
            }
        }
        out.sort_by(|x, y| y.rho.abs().total_cmp(&x.rho.abs()));
        out.truncate(count);
        out
    }
}
