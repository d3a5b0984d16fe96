//! The orthogonal Procrustes problem, solved once for every fit of one point set onto another:
//! `p_i ≈ s Q m_i + t` in weighted least squares, with `Q` a rotation or a reflection and the
//! uniform scale `s` free or 1 (Kabsch 1976, Horn 1987, Umeyama 1991; closed form by the SVD of
//! the 3x3 cross-covariance).
//!
//! The rigid registration ([`super::rigid::fit_rigid`]: rotation, scale 1, weights) and the
//! plausibility gate's similarity fits (units and handedness checks: free scale, reflection) are
//! both this one function. Written here rather than taken from a crate because it is a few lines
//! over nalgebra's SVD and the callers need the weights, the reflection variant and the singular
//! values (for their own degeneracy tests) together.

use crate::error::{Error, Result};
use nalgebra::{Matrix3, Vector3};

/// Whether the orthogonal part `Q` of a fit is a rotation or a reflection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Handedness {
    /// det = +1: a proper rotation (a tracker frame).
    Rotation,
    /// det = -1: a rotation combined with a mirror image.
    Reflection,
}

/// Whether the fit's uniform scale is fitted or held at 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// `s = 1`: a rigid motion (or a rigid motion with a mirror).
    Fixed,
    /// `s` free: a similarity transform.
    Free,
}

/// A solution of [`fit_procrustes`]: `p = s Q (m - c_m) + c_p`, i.e. `t = c_p - s Q c_m`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Procrustes {
    /// The orthogonal part `Q` (det +1 or -1 as asked).
    pub orthogonal: Matrix3<f64>,
    /// The uniform scale `s` (1 when held).
    pub scale: f64,
    /// Weighted centroid `c_m` of the points fitted.
    pub centroid_from: Vector3<f64>,
    /// Weighted centroid `c_p` of the points fitted onto.
    pub centroid_to: Vector3<f64>,
    /// Singular values of the weighted cross-covariance, largest first: the second is about zero
    /// when the points are collinear (the rotation about their line is then undetermined).
    pub singular_values: [f64; 3],
    /// Weighted spread `sum w_i |m_i - c_m|^2` of the points fitted: zero when they coincide.
    pub spread: f64,
}

impl Procrustes {
    /// The translation `t = c_p - s Q c_m`.
    pub fn translation(&self) -> Vector3<f64> {
        self.centroid_to - self.scale * (self.orthogonal * self.centroid_from)
    }

    /// The fitted image `s Q m + t` of a point.
    pub fn apply(&self, m: &Vector3<f64>) -> Vector3<f64> {
        self.scale * (self.orthogonal * (m - self.centroid_from)) + self.centroid_to
    }

    /// Whether the points span at least a line's worth of rotation: they neither coincide nor
    /// lie on one line (relative tolerance 1e-10 on the second singular value).
    pub fn is_determined(&self) -> bool {
        let [s0, s1, _] = self.singular_values;
        !(s0.is_nan() || s0 <= 0.0 || s1 <= 1e-10 * s0 || self.spread <= 0.0)
    }
}

/// Solves `min sum w_i |s Q m_i + t - p_i|^2` over `Q` of the wanted `handedness`, `t`, and `s`
/// when `scale` is [`Scale::Free`]; `weights` default to 1.
///
/// `Q = V D U^T` from the SVD `H = U S V^T` of the cross-covariance `H = sum w_i (m_i - c_m)
/// (p_i - c_p)^T` maximizes `tr(Q H) = tr(D S)` among orthogonal matrices of the wanted
/// determinant: `D` flips the direction of the smallest singular value when `V U^T` has the wrong
/// sign. The free scale is then `tr(D S) / spread`.
///
/// Fails when the counts differ, with fewer than three points, when the weights do not sum to a
/// positive number, on points that are not finite, or when the SVD fails. Degenerate point sets (coincident or collinear) are
/// not rejected here: the caller decides with [`Procrustes::spread`] and
/// [`Procrustes::is_determined`].
pub fn fit_procrustes(
    from: &[Vector3<f64>],
    to: &[Vector3<f64>],
    weights: Option<&[f64]>,
    handedness: Handedness,
    scale: Scale,
) -> Result<Procrustes> {
    check_counts(from, to, weights)?;
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    // The weights' sum and the weighted sums of the points in one pass (each sum in point
    // order, as in separate passes).
    let mut sums = CentroidSums::default();
    for i in 0..from.len() {
        sums.add(&from[i], &to[i], w(i));
    }
    solve_from_sums(from, to, weights, sums, handedness, scale)
}

/// Fails unless `from`, `to` (and `weights`, when given) have the same count, at least 3.
pub(crate) fn check_counts(
    from: &[Vector3<f64>],
    to: &[Vector3<f64>],
    weights: Option<&[f64]>,
) -> Result<()> {
    let n = from.len();
    if n != to.len() || weights.is_some_and(|w| w.len() != n) {
        return Err(Error::invalid(
            "registration",
            "measured and target point counts differ",
        ));
    }
    if n < 3 {
        return Err(Error::invalid(
            "registration",
            format!("a rigid fit needs at least 3 points, got {n}"),
        ));
    }
    Ok(())
}

/// The weights' sum and the weighted sums of the points, added point by point: the first pass
/// of [`fit_procrustes`], which a caller that computes the weights can make with its own.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CentroidSums {
    wsum: f64,
    cm: Vector3<f64>,
    cp: Vector3<f64>,
}

impl Default for CentroidSums {
    fn default() -> Self {
        CentroidSums {
            wsum: 0.0,
            cm: Vector3::zeros(),
            cp: Vector3::zeros(),
        }
    }
}

impl CentroidSums {
    /// Adds the pair `(m, p)` of weight `w`.
    #[inline(always)]
    pub(crate) fn add(&mut self, m: &Vector3<f64>, p: &Vector3<f64>, w: f64) {
        self.wsum += w;
        self.cm += m * w;
        self.cp += p * w;
    }
}

/// [`fit_procrustes`] after its first pass: `sums` of `from`, `to` and `weights` (whose counts
/// the caller checked, [`check_counts`]).
pub(crate) fn solve_from_sums(
    from: &[Vector3<f64>],
    to: &[Vector3<f64>],
    weights: Option<&[f64]>,
    sums: CentroidSums,
    handedness: Handedness,
    scale: Scale,
) -> Result<Procrustes> {
    let n = from.len();
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    let CentroidSums {
        wsum,
        mut cm,
        mut cp,
    } = sums;
    if !(wsum > 0.0 && wsum.is_finite()) {
        return Err(Error::Numerical("registration: weights sum to zero".into()));
    }
    cm /= wsum;
    cp /= wsum;
    // H = sum w (m - cm)(p - cp)^T: Q maps m-space into p-space.
    let mut h = Matrix3::zeros();
    let mut spread = 0.0;
    for i in 0..n {
        let a = from[i] - cm;
        h += (a * (to[i] - cp).transpose()) * w(i);
        spread += w(i) * a.norm_squared();
    }
    if !(spread.is_finite() && h.iter().all(|x| x.is_finite())) {
        return Err(Error::Numerical(
            "registration: the points are not finite numbers".into(),
        ));
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(Error::Numerical("registration: SVD failed".into()));
    };
    let s = svd.singular_values;
    let v = vt.transpose();
    let want = match handedness {
        Handedness::Rotation => 1.0,
        Handedness::Reflection => -1.0,
    };
    let mut d = Matrix3::identity();
    if (v * u.transpose()).determinant() * want < 0.0 {
        // The last of equal smallest values: nalgebra sorts them largest first, so index 2.
        let k = (0..3)
            .rev()
            .min_by(|&i, &j| s[i].total_cmp(&s[j]))
            .unwrap_or(2);
        d[(k, k)] = -1.0;
    }
    let orthogonal = v * d * u.transpose();
    let scale = match scale {
        Scale::Fixed => 1.0,
        Scale::Free => (d * Matrix3::from_diagonal(&s)).trace() / spread,
    };
    let mut singular_values = [s[0], s[1], s[2]];
    singular_values.sort_by(|a, b| b.total_cmp(a));
    Ok(Procrustes {
        orthogonal,
        scale,
        centroid_from: cm,
        centroid_to: cp,
        singular_values,
        spread,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn cloud() -> Vec<Vector3<f64>> {
        (0..12)
            .map(|i| {
                let t = i as f64;
                Vector3::new(50.0 * t.sin(), 40.0 * (0.7 * t).cos(), 3.0 * t)
            })
            .collect()
    }

    #[test]
    fn recovers_a_weighted_similarity_and_reports_degeneracy() {
        let r = Rotation3::from_euler_angles(-0.4, 0.25, 2.0);
        let t = Vector3::new(10.0, -4.0, 7.5);
        let m = cloud();
        let p: Vec<_> = m.iter().map(|x| 2.5 * (r * x) + t).collect();
        let w: Vec<f64> = (0..m.len()).map(|i| 1.0 + i as f64).collect();
        let f = fit_procrustes(&m, &p, Some(&w), Handedness::Rotation, Scale::Free).unwrap();
        assert!((f.scale - 2.5).abs() < 1e-12, "{f:?}");
        assert!((f.orthogonal - r.matrix()).norm() < 1e-12);
        assert!((f.translation() - t).norm() < 1e-9);
        assert!(m
            .iter()
            .zip(&p)
            .all(|(a, b)| (f.apply(a) - b).norm() < 1e-9));
        assert!(f.is_determined());
        // The reflection asked for has det -1.
        let g = fit_procrustes(&m, &p, None, Handedness::Reflection, Scale::Fixed).unwrap();
        assert!((g.orthogonal.determinant() + 1.0).abs() < 1e-12);
        assert_eq!(g.scale, 1.0);
        // Collinear and coincident points are solved but not determined.
        let line: Vec<_> = (0..5).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        let l = fit_procrustes(&line, &line, None, Handedness::Rotation, Scale::Fixed).unwrap();
        assert!(!l.is_determined() && l.spread > 0.0);
        let same = vec![Vector3::new(1.0, 2.0, 3.0); 4];
        let c = fit_procrustes(&same, &p[..4], None, Handedness::Rotation, Scale::Fixed).unwrap();
        assert!(!c.is_determined() && c.spread == 0.0);
        // Structural errors.
        assert!(fit_procrustes(&m[..2], &p[..2], None, Handedness::Rotation, Scale::Free).is_err());
        assert!(fit_procrustes(&m, &p[..5], None, Handedness::Rotation, Scale::Free).is_err());
        let zero = vec![0.0; m.len()];
        let e = fit_procrustes(&m, &p, Some(&zero), Handedness::Rotation, Scale::Free);
        assert!(e.unwrap_err().to_string().contains("weights sum to zero"));
    }
}
