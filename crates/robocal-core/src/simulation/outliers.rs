//! Gross outliers: a fraction of the readings displaced by a few millimetres, as when the
//! tracker's beam is interrupted or the reflector is knocked in its nest.

use crate::error::{Error, Result};
use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, UnitSphere};
use serde::{Deserialize, Serialize};

/// Which readings become outliers and by how much they move.
///
/// Of every batch of `n` readings, `round(fraction * n)` distinct ones, chosen at random, are
/// displaced in a uniformly random direction by a distance drawn uniformly from
/// `[min_mm, max_mm]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutlierModel {
    /// Fraction of the readings that are outliers, in [0, 1].
    pub fraction: f64,
    /// Smallest displacement (mm).
    pub min_mm: f64,
    /// Largest displacement (mm).
    pub max_mm: f64,
}

impl Default for OutlierModel {
    /// No outliers; displacements of 2 to 5 mm once a fraction is set.
    fn default() -> Self {
        OutlierModel {
            fraction: 0.0,
            min_mm: 2.0,
            max_mm: 5.0,
        }
    }
}

/// One displaced reading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Outlier {
    /// Index of the reading in its batch (0-based).
    pub index: usize,
    /// The displacement added to the reading (mm, tracker frame).
    pub displacement_mm: [f64; 3],
}

impl OutlierModel {
    /// Rejects a fraction outside [0, 1] and negative, non-finite or unordered distances.
    pub fn validate(&self) -> Result<()> {
        if !self.fraction.is_finite() || !(0.0..=1.0).contains(&self.fraction) {
            return Err(Error::invalid(
                "outliers.fraction",
                format!("{} is not a fraction in [0, 1]", self.fraction),
            ));
        }
        for (name, v) in [
            ("outliers.min_mm", self.min_mm),
            ("outliers.max_mm", self.max_mm),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(Error::invalid(
                    name,
                    format!("{v} must be a finite distance >= 0"),
                ));
            }
            crate::ranges::in_range(name, v, &crate::ranges::SIZE_MM)?;
        }
        if self.min_mm > self.max_mm {
            return Err(Error::invalid(
                "outliers.min_mm",
                format!(
                    "{} is greater than `outliers.max_mm` {}",
                    self.min_mm, self.max_mm
                ),
            ));
        }
        Ok(())
    }

    /// Chooses the outliers of a batch of `n` readings (sorted by index).
    pub fn draw<R: Rng + ?Sized>(&self, n: usize, rng: &mut R) -> Vec<Outlier> {
        let k = ((self.fraction * n as f64).round() as usize).min(n);
        if k == 0 {
            return Vec::new();
        }
        let mut idx = rand::seq::index::sample(rng, n, k).into_vec();
        idx.sort_unstable();
        idx.into_iter()
            .map(|index| {
                let dir: [f64; 3] = UnitSphere.sample(rng);
                let mag = if self.max_mm > self.min_mm {
                    rng.gen_range(self.min_mm..=self.max_mm)
                } else {
                    self.min_mm
                };
                let d = Vector3::from(dir) * mag;
                Outlier {
                    index,
                    displacement_mm: [d.x, d.y, d.z],
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn draws_the_requested_count_and_size() {
        let m = OutlierModel {
            fraction: 0.1,
            min_mm: 2.0,
            max_mm: 5.0,
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let o = m.draw(75, &mut rng);
        assert_eq!(o.len(), 8); // round(7.5)
        assert!(o.windows(2).all(|w| w[0].index < w[1].index));
        for x in &o {
            let d = Vector3::from(x.displacement_mm).norm();
            assert!((2.0..=5.0).contains(&d), "{d}");
            assert!(x.index < 75);
        }
        let all = OutlierModel { fraction: 1.0, ..m };
        assert_eq!(all.draw(5, &mut rng).len(), 5);
        assert!(OutlierModel::default().draw(100, &mut rng).is_empty());
    }

    #[test]
    fn validation() {
        for f in [-0.1, 1.5, f64::NAN] {
            let m = OutlierModel {
                fraction: f,
                ..OutlierModel::default()
            };
            let e = m.validate().unwrap_err().to_string();
            assert!(e.contains("outliers.fraction"), "{e}");
        }
        let m = OutlierModel {
            fraction: 0.1,
            min_mm: 6.0,
            max_mm: 5.0,
        };
        assert!(m.validate().is_err());
    }
}
