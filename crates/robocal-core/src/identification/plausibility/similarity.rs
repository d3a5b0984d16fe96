//! The best similarity transform between two point sets (Umeyama, 1991), with a rotation or a
//! reflection: the measure behind the unit and handedness checks. It is the registration's
//! Procrustes fit (`registration::procrustes`) with a free scale, and its RMS.

use crate::registration::procrustes::{fit_procrustes, Scale};
use nalgebra::Vector3;

pub use crate::registration::procrustes::Handedness;

/// The outcome of [`fit_similarity`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimilarityFit {
    /// The uniform scale `s` (1 when the scale was held).
    pub scale: f64,
    /// RMS of the residual norms `|s Q m_i + t - p_i|` (units of `target`).
    pub rms: f64,
}

/// The transform `p = s Q m + t` that fits `measured` onto `target` in least squares, with `Q` a
/// rotation or a reflection (`handedness`) and `s` free (`free_scale`) or 1. `None` when there
/// are fewer than three points, the counts differ, or the measured points coincide.
pub fn fit_similarity(
    measured: &[Vector3<f64>],
    target: &[Vector3<f64>],
    handedness: Handedness,
    free_scale: bool,
) -> Option<SimilarityFit> {
    let scale = if free_scale {
        Scale::Free
    } else {
        Scale::Fixed
    };
    let fit = fit_procrustes(measured, target, None, handedness, scale).ok()?;
    if fit.spread <= 0.0 {
        return None;
    }
    let sum_sq: f64 = measured
        .iter()
        .zip(target)
        .map(|(m, p)| (fit.apply(m) - p).norm_squared())
        .sum();
    let rms = (sum_sq / measured.len() as f64).sqrt();
    (fit.scale.is_finite() && rms.is_finite()).then_some(SimilarityFit {
        scale: fit.scale,
        rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn cloud() -> Vec<Vector3<f64>> {
        (0..20)
            .map(|i| {
                let t = i as f64;
                Vector3::new(
                    100.0 * t.sin(),
                    80.0 * (1.3 * t).cos(),
                    10.0 * t - 50.0 * t.cos(),
                )
            })
            .collect()
    }

    #[test]
    fn recovers_scale_rotation_and_reflection() {
        let r = Rotation3::from_euler_angles(0.3, -0.2, 1.1);
        let p = cloud();
        let t = Vector3::new(5.0, -7.0, 3.0);
        // measured = (R p - t) / 1000: p = 1000 R^T (m + t/1000)...
        let m: Vec<Vector3<f64>> = p.iter().map(|x| (r * x + t) / 1000.0).collect();
        let f = fit_similarity(&m, &p, Handedness::Rotation, true).unwrap();
        assert!((f.scale - 1000.0).abs() < 1e-9, "{f:?}");
        assert!(f.rms < 1e-9, "{f:?}");
        let rigid = fit_similarity(&m, &p, Handedness::Rotation, false).unwrap();
        assert_eq!(rigid.scale, 1.0);
        assert!(rigid.rms > 50.0, "{rigid:?}");
        // A mirrored cloud fits only with a reflection.
        let mirrored: Vec<Vector3<f64>> = p.iter().map(|x| Vector3::new(-x.x, x.y, x.z)).collect();
        let refl = fit_similarity(&mirrored, &p, Handedness::Reflection, true).unwrap();
        let rot = fit_similarity(&mirrored, &p, Handedness::Rotation, true).unwrap();
        assert!(
            refl.rms < 1e-9 && (refl.scale - 1.0).abs() < 1e-12,
            "{refl:?}"
        );
        assert!(rot.rms > 10.0, "{rot:?}");
        // Degenerate input.
        assert!(fit_similarity(&p[..2], &p[..2], Handedness::Rotation, true).is_none());
        let same = vec![Vector3::new(1.0, 2.0, 3.0); 5];
        assert!(fit_similarity(&same, &p[..5], Handedness::Rotation, true).is_none());
    }
}
