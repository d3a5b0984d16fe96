//! Error statistics of a set of displacement errors (the paper's Tables II, IV, V).

use serde::{Deserialize, Serialize};

/// Summary of error norms in mm. `std_mm` is the sample standard deviation (n - 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Number of points.
    pub n: usize,
    /// Mean error (mm).
    pub mean_mm: f64,
    /// Sample standard deviation (mm).
    pub std_mm: f64,
    /// Largest error (mm).
    pub max_mm: f64,
    /// Root mean square (mm).
    pub rms_mm: f64,
    /// 95th percentile (mm), linear interpolation between order statistics.
    #[serde(default)]
    pub p95_mm: f64,
}

impl ErrorStats {
    /// Statistics of the error norms `e` (mm). An empty slice gives n = 0 and NaN figures.
    pub fn from_norms(e: &[f64]) -> ErrorStats {
        let n = e.len();
        if n == 0 {
            return ErrorStats {
                n,
                mean_mm: f64::NAN,
                std_mm: f64::NAN,
                max_mm: f64::NAN,
                rms_mm: f64::NAN,
                p95_mm: f64::NAN,
            };
        }
        let nf = n as f64;
        let mean = e.iter().sum::<f64>() / nf;
        let var = if n > 1 {
            e.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (nf - 1.0)
        } else {
            0.0
        };
        let rms = (e.iter().map(|x| x * x).sum::<f64>() / nf).sqrt();
        let max = e.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        ErrorStats {
            n,
            mean_mm: mean,
            std_mm: var.sqrt(),
            max_mm: max,
            rms_mm: rms,
            p95_mm: percentile(e, 0.95),
        }
    }
}

/// The `p`-quantile (0..=1) of `v` with linear interpolation between order statistics.
pub fn percentile(v: &[f64], p: f64) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    // Two order statistics, found by selection (linear time) rather than a whole sort: a
    // million errors' p95 is taken several times per calibration.
    let mut s = v.to_vec();
    let h = p.clamp(0.0, 1.0) * (s.len() - 1) as f64;
    let lo = h.floor() as usize;
    let hi = h.ceil() as usize;
    let (_, &mut at_lo, above) = s.select_nth_unstable_by(lo, f64::total_cmp);
    let at_hi = if hi == lo {
        at_lo
    } else {
        // The next order statistic: the smallest of those above.
        above
            .iter()
            .copied()
            .min_by(f64::total_cmp)
            .unwrap_or(at_lo)
    };
    at_lo + (h - lo as f64) * (at_hi - at_lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        let s = ErrorStats::from_norms(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.n, 4);
        assert!((s.mean_mm - 2.5).abs() < 1e-15);
        assert!((s.std_mm - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert_eq!(s.max_mm, 4.0);
        assert!((s.rms_mm - 7.5f64.sqrt()).abs() < 1e-15);
        assert!((s.p95_mm - 3.85).abs() < 1e-12);
    }

    /// Selection gives the quantiles a sort gives, on unsorted data with ties.
    #[test]
    fn percentile_matches_the_sorted_order_statistics() {
        let v: Vec<f64> = (0..1001)
            .map(|i| ((i * 7919) % 1009) as f64 * 0.5 % 97.0)
            .collect();
        let mut sorted = v.clone();
        sorted.sort_by(f64::total_cmp);
        for p in [0.0, 0.01, 0.5, 0.95, 0.999, 1.0] {
            let h = p * (sorted.len() - 1) as f64;
            let (lo, hi) = (h.floor() as usize, h.ceil() as usize);
            let want = sorted[lo] + (h - lo as f64) * (sorted[hi] - sorted[lo]);
            assert_eq!(percentile(&v, p), want, "p {p}");
        }
        assert_eq!(percentile(&[3.0], 0.95), 3.0);
        assert!(percentile(&[], 0.5).is_nan());
    }
}
