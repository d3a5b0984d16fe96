//! Closed-form rigid fit (Kabsch/Horn, SVD) and its sum-of-norms refinement.

use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use nalgebra::{Matrix3, Point3, Vector3};

/// The rigid frame `F` minimizing `sum w_i |F m_i - p_i|^2` (Kabsch/Horn, closed form by SVD).
///
/// `measured` are points in the tracker frame, `target` the same points in the base frame (e.g.
/// the nominal tool positions of eq. 1); `weights` default to 1. The result maps tracker
/// coordinates into the base frame. Fails when the points are (nearly) collinear, where the
/// rotation about their line is undetermined.
pub fn fit_rigid(
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
    weights: Option<&[f64]>,
) -> Result<Frame> {
    let n = measured.len();
    if n != target.len() || weights.is_some_and(|w| w.len() != n) {
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
    let w = |i: usize| weights.map_or(1.0, |w| w[i]);
    let wsum: f64 = (0..n).map(w).sum();
    if !(wsum > 0.0 && wsum.is_finite()) {
        return Err(Error::Numerical("registration: weights sum to zero".into()));
    }
    let mut cm = Vector3::zeros();
    let mut cp = Vector3::zeros();
    for i in 0..n {
        cm += measured[i] * w(i);
        cp += target[i] * w(i);
    }
    cm /= wsum;
    cp /= wsum;
    // Cross-covariance H = sum w (m - cm)(p - cp)^T; the rotation maps m-space into p-space.
    let mut h = Matrix3::zeros();
    let mut spread = 0.0;
    for i in 0..n {
        let a = measured[i] - cm;
        h += (a * (target[i] - cp).transpose()) * w(i);
        spread += w(i) * a.norm_squared();
    }
    let svd = h.svd(true, true);
    let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
        return Err(Error::Numerical("registration: SVD failed".into()));
    };
    let s = svd.singular_values;
    // Rank test: the second singular value carries the spread across the points' main line.
    let smax = s.max();
    let mut sorted = [s[0], s[1], s[2]];
    sorted.sort_by(|a, b| b.total_cmp(a));
    if smax.is_nan() || smax <= 0.0 || sorted[1] <= 1e-10 * smax || spread <= 0.0 {
        return Err(Error::Numerical(
            "registration: the points are collinear (or coincide); the measurement frame is \
             undetermined"
                .into(),
        ));
    }
    let v = vt.transpose();
    let mut d = Matrix3::identity();
    if (v * u.transpose()).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    let r = v * d * u.transpose();
    let t = cp - r * cm;
    Ok(frame::frame(r, t))
}

/// Options of the iterative (IRLS) fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrlsOptions {
    /// Largest number of reweighting iterations.
    pub max_iterations: usize,
    /// Stop when no point moves by more than this between iterations (mm).
    pub tolerance_mm: f64,
    /// Norms below this are clamped when weighting (mm): weight `1 / max(|e|, floor)`.
    pub floor_mm: f64,
}

impl Default for IrlsOptions {
    fn default() -> Self {
        IrlsOptions {
            max_iterations: 1000,
            tolerance_mm: 1e-10,
            floor_mm: 1e-9,
        }
    }
}

/// Residual norms `|F m_i - p_i|` (mm).
pub fn residual_norms(f: &Frame, measured: &[Vector3<f64>], target: &[Vector3<f64>]) -> Vec<f64> {
    measured
        .iter()
        .zip(target)
        .map(|(m, p)| ((f * Point3::from(*m)).coords - p).norm())
        .collect()
}

/// The rigid frame minimizing the sum of error norms `sum |F m_i - p_i|` (the paper's eq. 11
/// restricted to rigid motions), by iteratively reweighted Kabsch fits with weights
/// `1 / max(|e_i|, floor)`, starting from `init`.
///
/// Each reweighted fit minimizes a quadratic majorizer of the objective (Weiszfeld's argument), so
/// the sum of norms never increases. Returns the frame and the number of iterations.
pub fn fit_rigid_sum_of_norms(
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
    init: &Frame,
    opts: &IrlsOptions,
) -> Result<(Frame, usize)> {
    let mut f = *init;
    let mut w = vec![0.0; measured.len()];
    for it in 1..=opts.max_iterations {
        let e = residual_norms(&f, measured, target);
        for (wi, ei) in w.iter_mut().zip(&e) {
            *wi = 1.0 / ei.max(opts.floor_mm);
        }
        let g = fit_rigid(measured, target, Some(&w))?;
        let moved = measured
            .iter()
            .map(|m| ((g * Point3::from(*m)) - (f * Point3::from(*m))).norm())
            .fold(0.0, f64::max);
        f = g;
        if moved <= opts.tolerance_mm {
            return Ok((f, it));
        }
    }
    Ok((f, opts.max_iterations))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::pose;

    fn cloud() -> Vec<Vector3<f64>> {
        (0..20)
            .map(|i| {
                let t = i as f64;
                Vector3::new(
                    1000.0 * (0.7 * t).sin(),
                    800.0 * (1.3 * t).cos(),
                    300.0 + 50.0 * t,
                )
            })
            .collect()
    }

    #[test]
    fn kabsch_recovers_a_frame_exactly() {
        let f = pose(&[3500.0, -1200.0, 40.0, 2.6, 0.02, -0.01]);
        let base = cloud();
        let meas: Vec<_> = base
            .iter()
            .map(|p| (f.inverse() * Point3::from(*p)).coords)
            .collect();
        let g = fit_rigid(&meas, &base, None).unwrap();
        let e = residual_norms(&g, &meas, &base);
        assert!(e.iter().all(|e| *e < 1e-9), "{e:?}");
        assert!((g.translation.vector - f.translation.vector).norm() < 1e-8);
    }

    #[test]
    fn sum_of_norms_ignores_one_gross_outlier() {
        let f = pose(&[100.0, 20.0, -30.0, 0.3, 0.1, -0.2]);
        let base = cloud();
        let mut meas: Vec<_> = base
            .iter()
            .map(|p| (f.inverse() * Point3::from(*p)).coords)
            .collect();
        meas[4] += Vector3::new(5.0, -3.0, 2.0);
        let ls = fit_rigid(&meas, &base, None).unwrap();
        let (l1, _) = fit_rigid_sum_of_norms(&meas, &base, &ls, &IrlsOptions::default()).unwrap();
        let e_ls = residual_norms(&ls, &meas, &base);
        let e_l1 = residual_norms(&l1, &meas, &base);
        // The least-squares fit spreads the outlier over every point; the sum of norms does not.
        assert!(e_ls[0] > 0.01, "{e_ls:?}");
        let clean_max = e_l1
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != 4)
            .map(|(_, e)| *e)
            .fold(0.0, f64::max);
        assert!(clean_max < 1e-5, "{e_l1:?}");
        assert!(e_l1.iter().sum::<f64>() < e_ls.iter().sum::<f64>());
    }

    #[test]
    fn collinear_points_are_rejected() {
        let m: Vec<_> = (0..5).map(|i| Vector3::new(i as f64, 0.0, 0.0)).collect();
        let e = fit_rigid(&m, &m, None).unwrap_err().to_string();
        assert!(e.contains("collinear"), "{e}");
    }
}
