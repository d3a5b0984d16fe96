//! Histogram binning shared by all series of a histogram (same edges for "before" and "after",
//! as in the paper's Fig. 2), and "nice" axis steps.

use crate::data::finite;

/// About how many bins a histogram gets (between `TARGET_BINS / 2.5` and `TARGET_BINS`).
const TARGET_BINS: f64 = 25.0;

/// Bins of several series over the same edges.
#[derive(Debug, Clone, PartialEq)]
pub struct Binning {
    /// Edges of the regular bins, ascending: bin `i` is `[edges[i], edges[i+1])`. Without
    /// overflow the last edge lies above the largest value.
    pub edges: Vec<f64>,
    /// Whether an extra last bin gathers the values above `edges.last()` (very large errors
    /// that would otherwise squeeze every other bin into one).
    pub overflow: bool,
    /// Counts per series and bin (`edges.len() - 1` bins, plus one if `overflow`).
    pub counts: Vec<Vec<usize>>,
    /// Finite values per series (the sum of its counts).
    pub n: Vec<usize>,
    /// Non-finite values skipped per series.
    pub skipped: Vec<usize>,
    /// Mean of the finite values per series (NaN for an empty series).
    pub mean: Vec<f64>,
}

impl Binning {
    /// Width of one regular bin.
    pub fn width(&self) -> f64 {
        self.edges[1] - self.edges[0]
    }

    /// Number of bins including the overflow bin.
    pub fn bins(&self) -> usize {
        self.edges.len() - 1 + usize::from(self.overflow)
    }

    /// Upper end of the regular bins.
    pub fn cap(&self) -> f64 {
        *self.edges.last().expect("at least two edges")
    }

    /// Lower and upper end of bin `i` (the overflow bin is drawn one bin wide).
    pub fn bin_range(&self, i: usize) -> (f64, f64) {
        let w = self.width();
        if i + 1 < self.edges.len() {
            (self.edges[i], self.edges[i + 1])
        } else {
            (self.cap(), self.cap() + w)
        }
    }

    /// The largest count of any series in any bin.
    pub fn max_count(&self) -> usize {
        self.counts
            .iter()
            .flat_map(|c| c.iter().copied())
            .max()
            .unwrap_or(0)
    }
}

/// Bins `series` over common edges starting at 0 (or at the smallest value if negative).
/// Returns `None` when no series has a finite value.
pub fn bin_series(series: &[&[f64]]) -> Option<Binning> {
    let cleaned: Vec<(Vec<f64>, usize)> =
        series.iter().map(|s| finite(s.iter().copied())).collect();
    let pooled: Vec<f64> = cleaned
        .iter()
        .flat_map(|(v, _)| v.iter().copied())
        .collect();
    if pooled.is_empty() {
        return None;
    }
    let min = pooled.iter().copied().fold(f64::INFINITY, f64::min);
    let max = pooled.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lo = min.min(0.0);

    // A few huge values (a failed point, a gross measurement error) would leave every other
    // value in the first bin: gather them in an overflow bin instead.
    let mut hi = max;
    let mut overflow = false;
    if let Some(cap) = outlier_cap(&pooled, lo) {
        hi = cap;
        overflow = true;
    }
    let span = hi - lo;
    let span = if span > 1e-12 * lo.abs().max(1.0) && span.is_finite() {
        span
    } else if lo == 0.0 {
        1.0
    } else {
        lo.abs()
    };
    let width = nice_step(span / TARGET_BINS);
    // Half-open bins up to and including the one holding the largest value (or the cap).
    let nbins = if overflow {
        ((span / width) * (1.0 - 1e-12)).ceil().max(1.0) as usize
    } else {
        (span / width + 1e-9).floor() as usize + 1
    };
    let edges: Vec<f64> = (0..=nbins).map(|i| lo + i as f64 * width).collect();
    let cap = edges[nbins];
    let total_bins = nbins + usize::from(overflow);

    let mut counts = Vec::with_capacity(cleaned.len());
    let mut n = Vec::with_capacity(cleaned.len());
    let mut skipped = Vec::with_capacity(cleaned.len());
    let mut mean = Vec::with_capacity(cleaned.len());
    for (values, k) in &cleaned {
        let mut c = vec![0usize; total_bins];
        for &x in values {
            let idx = ((x - lo) / width).floor();
            let i = if idx < nbins as f64 {
                idx.max(0.0) as usize
            } else if overflow && x > cap + 1e-9 * width {
                nbins
            } else {
                nbins - 1
            };
            c[i] += 1;
        }
        counts.push(c);
        n.push(values.len());
        skipped.push(*k);
        mean.push(if values.is_empty() {
            f64::NAN
        } else {
            values.iter().sum::<f64>() / values.len() as f64
        });
    }
    Some(Binning {
        edges,
        overflow,
        counts,
        n,
        skipped,
        mean,
    })
}

/// Where to cut an axis over `values` (all finite, at least `lo`) so that a few gross outliers do
/// not flatten the rest: `Some(lo + 2 * (p90 - lo))` when the largest value lies beyond
/// `lo + 4 * (p90 - lo)` (p90: 90th percentile) and there are at least 10 values; else `None`.
pub fn outlier_cap(values: &[f64], lo: f64) -> Option<f64> {
    if values.len() < 10 {
        return None;
    }
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let q = robocal_core::stats::percentile(values, 0.9);
    (q > lo && max - lo > 4.0 * (q - lo)).then_some(lo + 2.0 * (q - lo))
}

/// The smallest of 1, 2, 2.5, 5 times a power of ten that is at least `raw` (> 0).
pub fn nice_step(raw: f64) -> f64 {
    if raw.is_nan() || raw <= 0.0 || raw.is_infinite() {
        return 1.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if m * p >= raw * (1.0 - 1e-12) {
            return m * p;
        }
    }
    10.0 * p
}

/// A plot range `[lo, hi]` around `min..max` with a margin, never empty.
pub fn padded_range(min: f64, max: f64, from_zero: bool) -> (f64, f64) {
    let (mut lo, hi) = if min.is_finite() && max.is_finite() {
        (min, max)
    } else {
        (0.0, 1.0)
    };
    if from_zero {
        lo = lo.min(0.0);
    }
    if hi - lo <= 1e-12 * hi.abs().max(lo.abs()).max(1.0) {
        let pad = if hi == 0.0 { 1.0 } else { 0.1 * hi.abs() };
        return (if from_zero { lo.min(0.0) } else { lo - pad }, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (if from_zero && lo >= 0.0 { lo } else { lo - pad }, hi + pad)
}

/// Decimal places that show steps of `step` without noise (0 for steps of 1 or more).
pub fn decimals_for(step: f64) -> usize {
    if step.is_nan() || step <= 0.0 || step >= 1.0 {
        return 0;
    }
    let mut d = 0;
    let mut s = step;
    while d < 9 && (s - s.round()).abs() > 1e-9 * s.max(1.0) {
        s *= 10.0;
        d += 1;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(b: &Binning, s: usize) -> usize {
        b.counts[s].iter().sum()
    }

    #[test]
    fn counts_sum_to_n_and_share_edges() {
        let before: Vec<f64> = (0..75).map(|i| 1.0 + 0.017 * i as f64).collect();
        let after: Vec<f64> = (0..75).map(|i| 0.05 + 0.004 * i as f64).collect();
        let b = bin_series(&[&before, &after]).unwrap();
        assert_eq!(b.edges[0], 0.0);
        assert!(!b.overflow);
        assert_eq!(sum(&b, 0), 75);
        assert_eq!(sum(&b, 1), 75);
        assert_eq!(b.counts[0].len(), b.counts[1].len());
        assert!(b.cap() >= 1.0 + 0.017 * 74.0);
        let nb = b.edges.len() - 1;
        assert!((10..=25).contains(&nb), "{nb} bins");
        // the largest value lands in the last bin even when it sits on the edge
        let exact = bin_series(&[&[0.0, 0.5, 1.0]]).unwrap();
        assert_eq!(sum(&exact, 0), 3);
        assert_eq!(*exact.counts[0].last().unwrap(), 1);
    }

    #[test]
    fn nan_skipped_and_counted() {
        let b = bin_series(&[&[1.0, f64::NAN, 2.0, f64::INFINITY]]).unwrap();
        assert_eq!(b.n, vec![2]);
        assert_eq!(b.skipped, vec![2]);
        assert_eq!(sum(&b, 0), 2);
        assert!((b.mean[0] - 1.5).abs() < 1e-12);
    }

    #[test]
    fn degenerate_inputs() {
        assert!(bin_series(&[]).is_none());
        assert!(bin_series(&[&[], &[f64::NAN]]).is_none());
        for v in [
            vec![0.0],
            vec![0.7],
            vec![2.0; 40],
            vec![0.0; 5],
            vec![-1.0],
        ] {
            let b = bin_series(&[&v]).unwrap();
            assert_eq!(sum(&b, 0), v.len(), "{v:?}");
            assert!(b.width() > 0.0 && b.width().is_finite(), "{v:?}");
            assert!(b.edges.len() >= 2);
        }
        // one empty series beside a full one
        let b = bin_series(&[&[], &[1.0, 2.0]]).unwrap();
        assert_eq!(b.n, vec![0, 2]);
        assert!(b.mean[0].is_nan());
    }

    #[test]
    fn huge_values_go_to_an_overflow_bin() {
        let mut v: Vec<f64> = (0..60).map(|i| 0.1 + 0.02 * i as f64).collect();
        v.push(5.0e4);
        v.push(1.0e300);
        let b = bin_series(&[&v]).unwrap();
        assert!(b.overflow);
        assert_eq!(*b.counts[0].last().unwrap(), 2);
        assert_eq!(sum(&b, 0), 62);
        assert!(b.cap() < 5.0, "cap {}", b.cap());
    }

    #[test]
    fn steps() {
        assert_eq!(nice_step(0.07), 0.1);
        assert_eq!(nice_step(0.021), 0.025);
        assert_eq!(nice_step(3.0), 5.0);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(decimals_for(0.025), 3);
        assert_eq!(decimals_for(0.1), 1);
        assert_eq!(decimals_for(5.0), 0);
        assert_eq!(padded_range(2.0, 2.0, false), (1.8, 2.2));
        assert_eq!(padded_range(0.0, 0.0, true), (0.0, 1.0));
    }
}
