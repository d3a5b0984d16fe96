//! A simulated laser tracker: a pose in the robot's base frame and a noise model.

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// A laser tracker placed in the cell.
///
/// Noise: each coordinate of a measured point gets independent Gaussian noise of standard
/// deviation `sigma = sigma_fixed_mm + sigma_per_m * distance_m`, where `distance_m` is the distance
/// from the tracker to the point in metres (ASME B89.4.19-style figures: roughly
/// 0.010 mm + 0.005 mm/m).
#[derive(Debug, Clone, PartialEq)]
pub struct Tracker {
    /// The tracker's frame in the robot's base frame (the result JSON's `tracker_frame`).
    pub frame: TrackerFrame,
    /// Constant part of the per-axis standard deviation (mm).
    pub sigma_fixed_mm: f64,
    /// Distance-proportional part of the per-axis standard deviation (mm per metre).
    pub sigma_per_m: f64,
}

impl Tracker {
    /// A tracker at `frame` with the given noise; rejects negative or non-finite sigmas.
    pub fn new(frame: TrackerFrame, sigma_fixed_mm: f64, sigma_per_m: f64) -> Result<Tracker> {
        for (name, v) in [("noise_mm", sigma_fixed_mm), ("noise_per_m", sigma_per_m)] {
            if !v.is_finite() || v < 0.0 {
                return Err(Error::invalid(
                    name,
                    format!("{v} is not a valid standard deviation (must be >= 0)"),
                ));
            }
        }
        Ok(Tracker {
            frame,
            sigma_fixed_mm,
            sigma_per_m,
        })
    }

    /// The per-axis standard deviation (mm) for a point `p_base` given in the base frame.
    pub fn sigma_at(&self, p_base: &Vector3<f64>) -> f64 {
        let d_m = (p_base - self.frame.origin()).norm() / 1000.0;
        self.sigma_fixed_mm + self.sigma_per_m * d_m
    }

    /// The exact (noise-free) reading of a point given in the base frame: its coordinates in the
    /// tracker frame.
    pub fn exact(&self, p_base: &Vector3<f64>) -> Vector3<f64> {
        self.frame.to_tracker(p_base)
    }

    /// A noisy reading of a point given in the base frame.
    pub fn measure<R: Rng + ?Sized>(&self, p_base: &Vector3<f64>, rng: &mut R) -> Vector3<f64> {
        let s = self.sigma_at(p_base);
        let mut m = self.exact(p_base);
        if s > 0.0 {
            for k in 0..3 {
                let z: f64 = StandardNormal.sample(rng);
                m[k] += s * z;
            }
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::pose;
    use rand::SeedableRng;

    #[test]
    fn noise_spread_matches_sigma() {
        let t = Tracker::new(
            TrackerFrame::new(pose(&[4000.0, 500.0, 0.0, 2.5, 0.0, 0.0])),
            0.010,
            0.005,
        )
        .unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let p = Vector3::new(2000.0, -300.0, 1200.0);
        let exact = t.exact(&p);
        let n = 10_000;
        let mut ss = 0.0;
        for _ in 0..n {
            let d = t.measure(&p, &mut rng) - exact;
            ss += d.norm_squared();
        }
        let spread = (ss / (3.0 * n as f64)).sqrt();
        let sigma = t.sigma_at(&p);
        assert!(
            (spread / sigma - 1.0).abs() < 0.05,
            "spread {spread} vs sigma {sigma}"
        );
    }

    #[test]
    fn rejects_negative_sigma() {
        assert!(Tracker::new(TrackerFrame::identity(), -0.1, 0.0).is_err());
        assert!(Tracker::new(TrackerFrame::identity(), 0.0, f64::NAN).is_err());
    }
}
