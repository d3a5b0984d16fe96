//! Expected norms of Gaussian errors (the prediction's `E|e|`), by quadrature over the sphere.

use super::QUADRATURE_NODES;
use nalgebra::Matrix3;

/// Expected norms of zero-mean Gaussian vectors of given covariances, by quadrature.
///
/// For `e ~ N(0, Sigma)` with eigenvalues `l` of `Sigma`, `e = r u` in `Sigma`'s eigenbasis with
/// `r ~ chi(3)` and `u` uniform on the sphere, independent (in the whitened coordinates), so
/// `E|e| = E[r] E_u sqrt(l_0 u_0^2 + l_1 u_1^2 + l_2 u_2^2)`, `E[r] = 2 sqrt(2/pi)`. The integrand is
/// even in every coordinate: the mean over the sphere is the mean over one octant, where it is
/// smooth (no kink at `u_i = 0`), and a product Gauss-Legendre rule in the polar angle and the
/// azimuth (area element `sin(theta) dtheta dphi`) integrates it to about 1e-6 relative.
pub(super) struct NormExpectation {
    /// Nodes `u_0^2`, `u_1^2`, `u_2^2` and weights (summing to `E[r]`), each in its own array
    /// (so the sum runs in vector lanes), padded with zero weights to a multiple of
    /// [`LANES`].
    u0: Vec<f64>,
    u1: Vec<f64>,
    u2: Vec<f64>,
    w: Vec<f64>,
}

/// Partial sums kept apart in [`NormExpectation::mean_norm`] (one AVX register of doubles).
const LANES: usize = 4;

impl NormExpectation {
    pub(super) fn new() -> Self {
        let er = 2.0 * (2.0 / std::f64::consts::PI).sqrt();
        let (x, w) = gauss_legendre(QUADRATURE_NODES);
        let len = (x.len() * x.len()).next_multiple_of(LANES);
        let mut out = NormExpectation {
            u0: Vec::with_capacity(len),
            u1: Vec::with_capacity(len),
            u2: Vec::with_capacity(len),
            w: Vec::with_capacity(len),
        };
        let quarter_pi = 0.25 * std::f64::consts::PI;
        for (&xt, &wt) in x.iter().zip(&w) {
            // Polar angle theta and azimuth phi, both in [0, pi/2].
            let (st, ct) = (quarter_pi * (xt + 1.0)).sin_cos();
            for (&xp, &wp) in x.iter().zip(&w) {
                let (sp, cp) = (quarter_pi * (xp + 1.0)).sin_cos();
                // The octant's mean: (2 / pi) of the integral of f sin(theta), each rule
                // scaled by pi / 4.
                out.w.push(er * 0.125 * std::f64::consts::PI * wt * wp * st);
                out.u0.push(st * st * cp * cp);
                out.u1.push(st * st * sp * sp);
                out.u2.push(ct * ct);
            }
        }
        for v in [&mut out.u0, &mut out.u1, &mut out.u2, &mut out.w] {
            v.resize(len, 0.0);
        }
        out
    }

    /// `E|e|` for `e ~ N(0, s)`.
    pub(super) fn mean_norm(&self, s: &Matrix3<f64>) -> f64 {
        let ev = sym3_eigenvalues(s);
        let l = [ev[0].max(0.0), ev[1].max(0.0), ev[2].max(0.0)];
        let mut lanes = [0.0; LANES];
        let chunks = self
            .u0
            .chunks_exact(LANES)
            .zip(self.u1.chunks_exact(LANES))
            .zip(self.u2.chunks_exact(LANES))
            .zip(self.w.chunks_exact(LANES));
        for (((u0, u1), u2), w) in chunks {
            for k in 0..LANES {
                lanes[k] += w[k] * (l[0] * u0[k] + l[1] * u1[k] + l[2] * u2[k]).sqrt();
            }
        }
        lanes.iter().sum()
    }
}

/// Nodes and weights of the `n`-point Gauss-Legendre rule on [-1, 1] (Newton's iteration on the
/// Legendre polynomial from the usual cosine guesses; a dozen nodes, computed once per
/// prediction: a quadrature crate would be a dependency for twenty lines).
pub(super) fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(z) and its derivative by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, z);
            for m in 2..=n {
                let m = m as f64;
                let p2 = ((2.0 * m - 1.0) * z * p1 - (m - 1.0) * p0) / m;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pm = if n <= 1 { 1.0 } else { p0 };
            dp = n as f64 * (z * pn - pm) / (z * z - 1.0);
            let dz = pn / dp;
            z -= dz;
            if dz.abs() < 1e-15 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// Eigenvalues of a symmetric 3 x 3 matrix in closed form (the trigonometric solution of the
/// characteristic cubic), largest first. Absolute accuracy about 1e-15 of the matrix's norm,
/// which is what the expected norms need; nalgebra's iterative solver took a tenth of a
/// prediction's time.
pub(super) fn sym3_eigenvalues(m: &Matrix3<f64>) -> [f64; 3] {
    let p1 = m[(0, 1)].powi(2) + m[(0, 2)].powi(2) + m[(1, 2)].powi(2);
    let q = m.trace() / 3.0;
    let d = [m[(0, 0)] - q, m[(1, 1)] - q, m[(2, 2)] - q];
    let p2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + 2.0 * p1;
    if p2 <= f64::MIN_POSITIVE {
        return [q, q, q];
    }
    let p = (p2 / 6.0).sqrt();
    let b = (m - Matrix3::identity() * q) / p;
    let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
    let phi = r.acos() / 3.0;
    let e1 = q + 2.0 * p * phi.cos();
    let e3 = q + 2.0 * p * (phi + 2.0 * std::f64::consts::PI / 3.0).cos();
    [e1, 3.0 * q - e1 - e3, e3]
}
