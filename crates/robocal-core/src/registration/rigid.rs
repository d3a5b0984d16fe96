//! The rigid fit of the tracker frame: closed form (Kabsch/Horn, [`super::procrustes`]) and its
//! sum-of-norms refinement.

use super::procrustes::{
    check_counts, fit_procrustes, solve_from_sums, CentroidSums, Handedness, Scale,
};
use crate::error::{Error, Result};
use crate::frame::{self, TrackerFrame};
use nalgebra::Vector3;

/// The tracker frame `F` minimizing `sum w_i |F m_i - p_i|^2` (Kabsch/Horn: [`fit_procrustes`]
/// with a rotation and scale 1).
///
/// `measured` are points in the tracker frame, `target` the same points in the base frame (e.g.
/// the nominal tool positions of eq. 1); `weights` default to 1. Fails when the points are
/// (nearly) collinear, where the rotation about their line is undetermined.
pub fn fit_rigid(
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
    weights: Option<&[f64]>,
) -> Result<TrackerFrame> {
    rigid_frame(fit_procrustes(
        measured,
        target,
        weights,
        Handedness::Rotation,
        Scale::Fixed,
    )?)
}

/// The tracker frame of a rotation fit, failing when the points leave it undetermined.
fn rigid_frame(fit: super::procrustes::Procrustes) -> Result<TrackerFrame> {
    if !fit.is_determined() {
        return Err(Error::Numerical(
            "registration: the points are collinear (or coincide); the measurement frame is \
             undetermined"
                .into(),
        ));
    }
    Ok(TrackerFrame::new(frame::frame(
        fit.orthogonal,
        fit.translation(),
    )))
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
pub fn residual_norms(
    f: &TrackerFrame,
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
) -> Vec<f64> {
    measured
        .iter()
        .zip(target)
        .map(|(m, p)| (f.to_base(m) - p).norm())
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
    init: &TrackerFrame,
    opts: &IrlsOptions,
) -> Result<(TrackerFrame, usize)> {
    check_counts(measured, target, None)?;
    let weight = |f: &TrackerFrame, m: &Vector3<f64>, p: &Vector3<f64>| {
        1.0 / (f.to_base(m) - p).norm().max(opts.floor_mm)
    };
    // Each iteration's weights and their sums (the Kabsch fit's first pass) are computed in the
    // pass that measures how far the previous iteration moved the points: two passes over the
    // points an iteration instead of four, the same numbers in the same order.
    let mut f = *init;
    let mut w = vec![0.0; measured.len()];
    let mut sums = CentroidSums::default();
    for ((m, p), wi) in measured.iter().zip(target).zip(w.iter_mut()) {
        *wi = weight(&f, m, p);
        sums.add(m, p, *wi);
    }
    for it in 1..=opts.max_iterations {
        let g = rigid_frame(solve_from_sums(
            measured,
            target,
            Some(&w),
            sums,
            Handedness::Rotation,
            Scale::Fixed,
        )?)?;
        // How far each point moved, `(R_g - R_f) m + (t_g - t_f)`: one product a point.
        let (pg, pf) = (g.pose(), f.pose());
        let dr = pg.rotation.matrix() - pf.rotation.matrix();
        let dt = pg.translation.vector - pf.translation.vector;
        let mut moved = 0.0;
        let mut next = CentroidSums::default();
        if it < opts.max_iterations {
            for ((m, p), wi) in measured.iter().zip(target).zip(w.iter_mut()) {
                moved = f64::max(moved, (dr * m + dt).norm());
                *wi = weight(&g, m, p);
                next.add(m, p, *wi);
            }
        } else {
            for m in measured {
                moved = f64::max(moved, (dr * m + dt).norm());
            }
        }
        f = g;
        if moved <= opts.tolerance_mm {
            return Ok((f, it));
        }
        sums = next;
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
        let f = TrackerFrame::new(pose(&[3500.0, -1200.0, 40.0, 2.6, 0.02, -0.01]));
        let base = cloud();
        let meas: Vec<_> = base.iter().map(|p| f.to_tracker(p)).collect();
        let g = fit_rigid(&meas, &base, None).unwrap();
        let e = residual_norms(&g, &meas, &base);
        assert!(e.iter().all(|e| *e < 1e-9), "{e:?}");
        assert!((g.origin() - f.origin()).norm() < 1e-8);
    }

    #[test]
    fn sum_of_norms_ignores_one_gross_outlier() {
        let f = TrackerFrame::new(pose(&[100.0, 20.0, -30.0, 0.3, 0.1, -0.2]));
        let base = cloud();
        let mut meas: Vec<_> = base.iter().map(|p| f.to_tracker(p)).collect();
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
