//! Series cleaned for statistics and figures.

/// Finite values of `v`, and how many were not finite.
pub(crate) fn finite(v: impl IntoIterator<Item = f64>) -> (Vec<f64>, usize) {
    let mut out = Vec::new();
    let mut skipped = 0;
    for x in v {
        if x.is_finite() {
            out.push(x);
        } else {
            skipped += 1;
        }
    }
    (out, skipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_counts_skipped() {
        let (v, k) = finite([1.0, f64::NAN, 3.0, f64::NEG_INFINITY]);
        assert_eq!(v, vec![1.0, 3.0]);
        assert_eq!(k, 2);
    }
}
