//! The paper's 12-parameter transformation Tr (eq. 8-11): an affine map from the measurement
//! frame to the ACS fitted by minimizing the sum of error norms.

use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::registration::rigid::IrlsOptions;
use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

/// An affine map `p = A m + t` (the top three rows of the paper's Tr, eq. 8).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// The 3x3 part (t1..t9, column-major as in eq. 8).
    pub matrix: Matrix3<f64>,
    /// The translation (t10..t12, mm).
    pub translation: Vector3<f64>,
}

impl Affine {
    /// The affine map of a rigid frame.
    pub(crate) fn from_frame(f: &Frame) -> Affine {
        Affine {
            matrix: *f.rotation.matrix(),
            translation: f.translation.vector,
        }
    }

    /// Applies the map to a point.
    pub(crate) fn apply(&self, m: &Vector3<f64>) -> Vector3<f64> {
        self.matrix * m + self.translation
    }

    /// The singular values of the 3x3 part, largest first: all 1 for a rigid map; their spread
    /// is the scale and shear the fit needed.
    pub fn singular_values(&self) -> [f64; 3] {
        let s = self.matrix.singular_values();
        let mut v = [s[0], s[1], s[2]];
        v.sort_by(|a, b| b.total_cmp(a));
        v
    }

    /// The twelve parameters `t1..t12` of eq. 8 (column-major).
    pub(crate) fn parameters(&self) -> [f64; 12] {
        let m = &self.matrix;
        let t = &self.translation;
        [
            m[(0, 0)],
            m[(1, 0)],
            m[(2, 0)],
            m[(0, 1)],
            m[(1, 1)],
            m[(2, 1)],
            m[(0, 2)],
            m[(1, 2)],
            m[(2, 2)],
            t.x,
            t.y,
            t.z,
        ]
    }
}

/// Fits the affine Tr minimizing `sum |Tr m_i - p_i|` (eq. 11) by iteratively reweighted linear
/// least squares (weights `1 / max(|e_i|, floor)`), starting from `init` (e.g. the rigid fit).
/// Each reweighted solve minimizes a majorizer of the sum of norms, so it never increases.
/// Returns the map and the number of iterations.
pub fn fit_affine_sum_of_norms(
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
    init: &Affine,
    opts: &IrlsOptions,
) -> Result<(Affine, usize)> {
    let n = measured.len();
    if n < 4 || target.len() != n {
        return Err(Error::invalid(
            "registration",
            format!("an affine Tr needs at least 4 points, got {n}"),
        ));
    }
    let mut tr = *init;
    for it in 1..=opts.max_iterations {
        // Weighted normal equations in centred coordinates: [m - c; 1] x (A^T; t'^T).
        let mut wsum = 0.0;
        let mut c = Vector3::zeros();
        let w: Vec<f64> = measured
            .iter()
            .zip(target)
            .map(|(m, p)| 1.0 / (tr.apply(m) - p).norm().max(opts.floor_mm))
            .collect();
        for (m, wi) in measured.iter().zip(&w) {
            c += m * *wi;
            wsum += wi;
        }
        c /= wsum;
        let mut nm = Matrix4::zeros();
        let mut rhs = nalgebra::Matrix4x3::zeros();
        for i in 0..n {
            let d = measured[i] - c;
            let a = Vector4::new(d.x, d.y, d.z, 1.0);
            nm += a * a.transpose() * w[i];
            rhs += a * target[i].transpose() * w[i];
        }
        let Some(ch) = nm.cholesky() else {
            return Err(Error::Numerical(
                "registration: the points are coplanar; an affine Tr is undetermined".into(),
            ));
        };
        let x = ch.solve(&rhs);
        let a = x.fixed_rows::<3>(0).transpose();
        let t0: Vector3<f64> = x.row(3).transpose();
        let next = Affine {
            matrix: a,
            translation: t0 - a * c,
        };
        if !next.matrix.iter().all(|v| v.is_finite()) {
            return Err(Error::Numerical(
                "registration: the affine fit diverged".into(),
            ));
        }
        let moved = measured
            .iter()
            .map(|m| (next.apply(m) - tr.apply(m)).norm())
            .fold(0.0, f64::max);
        tr = next;
        if moved <= opts.tolerance_mm {
            return Ok((tr, it));
        }
    }
    Ok((tr, opts.max_iterations))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_affine_map() {
        let truth = Affine {
            matrix: Matrix3::new(1.001, 0.002, 0.0, -0.001, 0.999, 0.003, 0.0, 0.0, 1.0005),
            translation: Vector3::new(10.0, -20.0, 5.0),
        };
        let m: Vec<_> = (0..30)
            .map(|i| {
                let t = i as f64;
                Vector3::new(900.0 * (0.9 * t).sin(), 700.0 * (1.7 * t).cos(), 40.0 * t)
            })
            .collect();
        let p: Vec<_> = m.iter().map(|m| truth.apply(m)).collect();
        let init = Affine {
            matrix: Matrix3::identity(),
            translation: Vector3::zeros(),
        };
        let (fit, _) = fit_affine_sum_of_norms(&m, &p, &init, &IrlsOptions::default()).unwrap();
        for (a, b) in fit.parameters().iter().zip(truth.parameters()) {
            assert!((a - b).abs() < 1e-7, "{a} vs {b}");
        }
        let s = fit.singular_values();
        assert!(s[0] > 1.0 && s[2] < 1.0);
    }
}
