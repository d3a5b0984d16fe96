//! Histogram binning shared by all series of a histogram (same edges for "before" and "after",
//! as in the paper's Fig. 2), and "nice" axis steps.
//!
//! **The rule.** Each series with at least two values gets its Freedman–Diaconis bin width,
//! `h = 2 IQR n^(-1/3)` (IQR: interquartile range; `range / sqrt(n)` when the IQR is 0), the
//! width that shows the shape of a distribution of `n` values without drowning it in noise.
//! - **Linear bins** (from 0, or from the smallest value if it is negative): the narrowest
//!   series' width rounded up to 1, 2, 2.5 or 5 times a power of ten, and never fewer than
//!   [`MIN_BINS`] over the range. Every series is counted over the same edges.
//! - **Log-spaced bins** when the linear ones cannot show every series: when the narrowest width
//!   would need more than [`MAX_LINEAR_BINS`] bins over the pooled range, or when the series'
//!   medians differ by [`LOG_RATIO`] times or more (before and after a calibration often do).
//!   The bins are then equally wide in log10 of the error: the narrowest series' Freedman–
//!   Diaconis width of the log values, between [`MIN_BINS`] and [`MAX_LOG_BINS`] bins; still
//!   shared by all series, so the bars compare count for count. Values of exactly 0 go into the
//!   first bin.
//! - A few gross outliers (a failed point) are gathered in an overflow bin ([`outlier_cap`]).

use crate::values::finite;

/// Fewest regular bins a histogram gets (unless all values are equal).
pub const MIN_BINS: usize = 10;
/// Most linear bins before the histogram turns to log-spaced bins.
pub const MAX_LINEAR_BINS: usize = 60;
/// Most log-spaced bins.
pub const MAX_LOG_BINS: usize = 60;
/// Ratio of the largest to the smallest series median from which the bins are log-spaced.
pub const LOG_RATIO: f64 = 10.0;
/// Log bins start no lower than the smallest series median divided by this: a point a fit
/// passes through exactly (a sum-of-norms fit does so at some points, 1e-6 mm) does not stretch
/// the axis over decades where no other point lies; it is counted in the first bin.
pub const LOG_FLOOR: f64 = 100.0;

/// How the bin edges are spaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Equal widths in mm.
    Linear,
    /// Equal widths in log10(mm).
    Log,
}

/// Bins of several series over the same edges.
#[derive(Debug, Clone, PartialEq)]
pub struct Binning {
    /// Edges of the regular bins, ascending (mm): bin `i` is `[edges[i], edges[i+1])`. Without
    /// overflow the last edge lies above the largest value.
    pub edges: Vec<f64>,
    /// How the edges are spaced (equal steps in mm, or in log10 of mm).
    pub scale: Scale,
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
    /// Values per series below the first edge of log bins (exact fits far below the data's
    /// spread, see [`LOG_FLOOR`]), counted in the first bin.
    pub under: Vec<usize>,
}

impl Binning {
    /// Width of one regular bin in axis units (mm for linear bins, decades for log bins).
    pub fn width(&self) -> f64 {
        self.axis(self.edges[1]) - self.axis(self.edges[0])
    }

    /// Number of bins including the overflow bin.
    pub fn bins(&self) -> usize {
        self.edges.len() - 1 + usize::from(self.overflow)
    }

    /// Upper end of the regular bins.
    pub fn cap(&self) -> f64 {
        *self.edges.last().expect("at least two edges")
    }

    /// A value in axis units: itself (linear) or its log10 (log bins; 0 and below map to the
    /// first edge).
    pub fn axis(&self, x: f64) -> f64 {
        match self.scale {
            Scale::Linear => x,
            Scale::Log => x.max(self.edges[0]).log10(),
        }
    }

    /// Lower and upper end of bin `i` in axis units (the overflow bin is drawn one bin wide).
    pub fn bin_range(&self, i: usize) -> (f64, f64) {
        if i + 1 < self.edges.len() {
            (self.axis(self.edges[i]), self.axis(self.edges[i + 1]))
        } else {
            let c = self.axis(self.cap());
            (c, c + self.width())
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

    /// Bins of series `s` that hold at least one value.
    pub fn occupied(&self, s: usize) -> usize {
        self.counts[s].iter().filter(|&&c| c > 0).count()
    }

    /// The rule that chose the bins, in words (for a figure's caption).
    pub fn describe(&self) -> String {
        let nb = self.edges.len() - 1;
        match self.scale {
            Scale::Linear => format!(
                "{nb} bins of {} mm (Freedman–Diaconis width of the narrowest series)",
                crate::plot::axis_number(self.width(), decimals_for(self.width()).max(1) + 1)
            ),
            Scale::Log => format!(
                "{nb} log-spaced bins, {:.0} per decade, from {} mm (the series differ in scale, \
                 so equal widths in mm would put the smaller errors in a few bars)",
                1.0 / self.width(),
                crate::numfmt::magnitude(self.edges[0])
            ),
        }
    }
}

/// Freedman–Diaconis width of `v` (sorted, finite, at least two values), or `None` when all
/// values are equal.
fn fd_width(sorted: &[f64]) -> Option<f64> {
    let n = sorted.len();
    if n < 2 {
        return None;
    }
    let q = |p: f64| robocal_core::stats::percentile(sorted, p);
    let iqr = q(0.75) - q(0.25);
    let range = sorted[n - 1] - sorted[0];
    let h = if iqr > 0.0 {
        2.0 * iqr * (n as f64).powf(-1.0 / 3.0)
    } else {
        range / (n as f64).sqrt()
    };
    (h > 0.0 && h.is_finite()).then_some(h)
}

fn median(sorted: &[f64]) -> f64 {
    robocal_core::stats::percentile(sorted, 0.5)
}

/// Bins `series` over common edges by the rule of this module. Returns `None` when no series
/// has a finite value.
pub fn bin_series(series: &[&[f64]]) -> Option<Binning> {
    let cleaned: Vec<(Vec<f64>, usize)> = series
        .iter()
        .map(|s| {
            let (mut v, k) = finite(s.iter().copied());
            v.sort_by(f64::total_cmp);
            (v, k)
        })
        .collect();
    let mut pooled: Vec<f64> = cleaned
        .iter()
        .flat_map(|(v, _)| v.iter().copied())
        .collect();
    if pooled.is_empty() {
        return None;
    }
    pooled.sort_by(f64::total_cmp);
    let min = pooled[0];
    let max = pooled[pooled.len() - 1];
    let lo = min.min(0.0);

    // A few huge values (a failed point, a gross measurement error) would leave every other
    // value in the first bin: gather them in an overflow bin instead.
    let cap = outlier_cap(&pooled, lo);
    let hi = cap.unwrap_or(max);
    let overflow = cap.is_some();

    let widths: Vec<f64> = cleaned
        .iter()
        .filter_map(|(v, _)| {
            let v: Vec<f64> = v.iter().copied().filter(|&x| x <= hi).collect();
            fd_width(&v)
        })
        .collect();
    let narrowest = widths.iter().copied().fold(f64::INFINITY, f64::min);
    let medians: Vec<f64> = cleaned
        .iter()
        .filter(|(v, _)| !v.is_empty())
        .map(|(v, _)| median(v))
        .collect();
    let med_lo = medians.iter().copied().fold(f64::INFINITY, f64::min);
    let med_hi = medians.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let span = hi - lo;
    let linear_needs = if narrowest.is_finite() {
        span / nice_step(narrowest)
    } else {
        0.0
    };
    let want_log = min >= 0.0
        && max > 0.0
        && (linear_needs > MAX_LINEAR_BINS as f64
            || (med_lo > 0.0 && med_hi >= LOG_RATIO * med_lo));
    let edges = if want_log {
        log_edges(&cleaned, hi)
    } else {
        None
    };
    let (edges, scale) = match edges {
        Some(e) => (e, Scale::Log),
        None => (linear_edges(lo, hi, narrowest, overflow), Scale::Linear),
    };
    let nbins = edges.len() - 1;
    let cap = edges[nbins];
    let total_bins = nbins + usize::from(overflow);
    let index = |x: f64| -> usize {
        if overflow && x > cap * (1.0 + 1e-12) + 1e-300 {
            return nbins;
        }
        // The first edge above x, minus one; values on or beyond the last edge go into the
        // last regular bin.
        let i = edges.partition_point(|&e| e <= x);
        i.saturating_sub(1).min(nbins - 1)
    };

    let mut counts = Vec::with_capacity(cleaned.len());
    let mut n = Vec::with_capacity(cleaned.len());
    let mut skipped = Vec::with_capacity(cleaned.len());
    let mut mean = Vec::with_capacity(cleaned.len());
    let mut under = Vec::with_capacity(cleaned.len());
    for (values, k) in &cleaned {
        under.push(if scale == Scale::Log {
            values.iter().filter(|&&x| x < edges[0]).count()
        } else {
            0
        });
        let mut c = vec![0usize; total_bins];
        for &x in values {
            c[index(x)] += 1;
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
        scale,
        overflow,
        counts,
        n,
        skipped,
        mean,
        under,
    })
}

/// Linear edges from `lo` over `lo..hi`: the width `narrowest` rounded up to a nice step, at
/// least `MIN_BINS` bins (fewer only when all values are equal), at most `MAX_LINEAR_BINS`.
fn linear_edges(lo: f64, hi: f64, narrowest: f64, overflow: bool) -> Vec<f64> {
    let span = hi - lo;
    let span = if span > 1e-12 * lo.abs().max(1.0) && span.is_finite() {
        span
    } else if lo == 0.0 {
        1.0
    } else {
        lo.abs()
    };
    let mut width = if narrowest.is_finite() {
        nice_step(narrowest)
    } else {
        nice_step(span / MIN_BINS as f64)
    };
    // Not fewer than MIN_BINS bins...
    while span / width < MIN_BINS as f64 - 1.0 {
        let smaller = nice_step(width * 0.5);
        if smaller >= width {
            break;
        }
        width = smaller;
    }
    // ... nor more than MAX_LINEAR_BINS.
    if span / width > MAX_LINEAR_BINS as f64 {
        width = nice_step(span / MAX_LINEAR_BINS as f64);
    }
    // Half-open bins up to and including the one holding the largest value (or the cap).
    let nbins = if overflow {
        ((span / width) * (1.0 - 1e-12)).ceil().max(1.0) as usize
    } else {
        (span / width + 1e-9).floor() as usize + 1
    };
    (0..=nbins).map(|i| lo + i as f64 * width).collect()
}

/// Log-spaced edges up to `hi` (all values non-negative), or `None` when there is no positive
/// value to start from.
fn log_edges(cleaned: &[(Vec<f64>, usize)], hi: f64) -> Option<Vec<f64>> {
    let smallest = cleaned
        .iter()
        .flat_map(|(v, _)| v.iter().copied())
        .filter(|&x| x > 0.0)
        .fold(f64::INFINITY, f64::min);
    // The data's meaningful spread: no lower than the smallest median over LOG_FLOOR.
    let floor = cleaned
        .iter()
        .filter_map(|(v, _)| {
            let pos: Vec<f64> = v.iter().copied().filter(|&x| x > 0.0).collect();
            (!pos.is_empty()).then(|| median(&pos) / LOG_FLOOR)
        })
        .fold(f64::INFINITY, f64::min);
    let smallest = smallest.max(if floor.is_finite() { floor } else { 0.0 });
    if !smallest.is_finite() || hi <= smallest {
        return None;
    }
    let logs: Vec<Vec<f64>> = cleaned
        .iter()
        .map(|(v, _)| {
            v.iter()
                .copied()
                .filter(|&x| x > 0.0 && x <= hi)
                .map(f64::log10)
                .collect()
        })
        .collect();
    let narrowest = logs
        .iter()
        .filter_map(|l| fd_width(l))
        .fold(f64::INFINITY, f64::min);
    let (a, b) = (smallest.log10(), hi.log10());
    let decades = b - a;
    let mut width = if narrowest.is_finite() {
        narrowest
    } else {
        decades / MIN_BINS as f64
    };
    // Round to a whole number of bins per decade (1/width), clamp the bin count.
    width = 1.0 / (1.0 / width).round().max(1.0);
    if decades / width > MAX_LOG_BINS as f64 {
        width = 1.0 / (MAX_LOG_BINS as f64 / decades).floor().max(1.0);
    }
    while decades / width < MIN_BINS as f64 - 1.0 {
        width = 1.0 / (1.0 / width + 1.0);
    }
    // Start on a multiple of the width so that edges fall on round values (1, 10, 100...
    // are edges).
    let start = (a / width).floor() * width;
    let nbins = (((b - start) / width) + 1e-9).floor() as usize + 1;
    Some(
        (0..=nbins)
            .map(|i| 10f64.powf(start + i as f64 * width))
            .collect(),
    )
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

    /// `n` values spread like calibration errors: a Rayleigh-like shape of median `m`.
    fn spread(n: usize, m: f64) -> Vec<f64> {
        (0..n)
            .map(|i| {
                let u = (i as f64 + 0.5) / n as f64;
                m * (-2.0 * (1.0 - u).ln()).sqrt() / 1.1774
            })
            .collect()
    }

    #[test]
    fn before_and_after_of_a_real_calibration_both_show_their_shape() {
        // The UR5 case of issue 16: 1000 points, 0.8 mm before, 0.1 mm after. Fixed 0.2 mm bins
        // put 956 of the 1000 "after" points into one bar.
        for n in [1000, 20_000] {
            let before = spread(n, 0.8);
            let after = spread(n, 0.1);
            let b = bin_series(&[&before, &after]).unwrap();
            assert_eq!(b.scale, Scale::Log, "n = {n}");
            assert!(b.occupied(1) >= 8, "after: {} bins", b.occupied(1));
            assert!(b.occupied(0) >= 8, "before: {} bins", b.occupied(0));
            assert_eq!(sum(&b, 0), n);
            assert_eq!(sum(&b, 1), n);
            assert!(b.bins() <= MAX_LOG_BINS + 1, "{} bins", b.bins());
            // no bar holds more than a fifth of a series
            let top = b.counts[1].iter().max().unwrap();
            assert!(*top < n / 5, "{top} of {n} in one bar");
            assert!(b.describe().contains("log-spaced"));
        }
    }

    #[test]
    fn medians_ten_times_apart_give_log_bins_and_close_ones_linear() {
        let before = spread(50, 1.0);
        let after = spread(50, 0.09);
        assert_eq!(bin_series(&[&before, &after]).unwrap().scale, Scale::Log);
        let after = spread(50, 0.5);
        let b = bin_series(&[&before, &after]).unwrap();
        assert_eq!(b.scale, Scale::Linear);
        let nb = b.edges.len() - 1;
        assert!((MIN_BINS..=MAX_LINEAR_BINS).contains(&nb), "{nb} bins");
        // signed values (a per-axis error) stay linear, around zero
        let signed: Vec<f64> = (0..200).map(|i| (i as f64 - 100.0) * 0.003).collect();
        let b = bin_series(&[&signed]).unwrap();
        assert_eq!(b.scale, Scale::Linear);
        assert!(b.edges[0] <= -0.3);
        assert_eq!(sum(&b, 0), 200);
    }

    #[test]
    fn log_bins_count_zero_in_the_first_bin() {
        let mut after = spread(300, 0.05);
        after[0] = 0.0;
        let before = spread(300, 2.0);
        let b = bin_series(&[&before, &after]).unwrap();
        assert_eq!(b.scale, Scale::Log);
        assert_eq!(sum(&b, 1), 300);
        assert!(b.counts[1][0] >= 1);
        // edges ascend and are equally spaced in log10
        let w = b.width();
        for pair in b.edges.windows(2) {
            assert!(((pair[1] / pair[0]).log10() - w).abs() < 1e-9);
        }
    }

    /// A few exact-fit points (1e-6 mm) among errors of 0.01-0.1 mm do not start the log axis
    /// five decades low: it starts within two decades of the smallest median, and they are
    /// counted in the first bin.
    #[test]
    fn exact_fit_points_do_not_set_the_log_axis() {
        let before: Vec<f64> = (0..75).map(|i| 1.0 + 0.02 * i as f64).collect();
        let mut after: Vec<f64> = (0..75).map(|i| 0.05 + 0.002 * i as f64).collect();
        for v in after.iter_mut().take(8) {
            *v = 1e-6;
        }
        let b = bin_series(&[&before, &after]).unwrap();
        assert_eq!(b.scale, Scale::Log);
        let med = median(&{
            let mut a = after.clone();
            a.sort_by(f64::total_cmp);
            a
        });
        assert!(b.edges[0] >= med / LOG_FLOOR / 10.0, "{:?}", b.edges);
        assert!(b.edges[0] > 1e-4, "{:?}", b.edges);
        assert_eq!(b.under, [0, 8]);
        assert_eq!(b.counts[1].iter().sum::<usize>(), 75);
        assert!(b.counts[1][0] >= 8);
        // Without them the axis starts at the data.
        let b = bin_series(&[&before, &after[8..]]).unwrap();
        assert_eq!(b.under, [0, 0]);
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
