//! The R factor of a tall matrix given block by block: `R' = qr([R; B]).R`.
//!
//! The identifiability analysis needs an upper-triangular `R` with `R^T R = J^T J` for a stacked
//! Jacobian of thousands of rows and a few dozen columns ([`super::identifiability::jacobian_r`]).
//! Folding each block of rows into the running `R` by Householder reflections that know `R` is
//! triangular (the reflection of column j touches row j of `R` and the block's rows, never the
//! zeros below the diagonal) takes about half the work of a general QR of `[R; B]`, and its
//! loops over contiguous columns run with AVX where the processor has it. Written here rather
//! than taken from nalgebra for those two reasons: nalgebra's QR sees a dense matrix, and its
//! generic code runs two doubles per instruction.
//!
//! The factor is unique up to the signs of its rows; the analysis uses only inner products of
//! its columns, which the signs do not change.

use crate::identification::simd::with_avx;

/// Folds the `m x n` block `b` (column-major, `b[c * m + i]`) into the `n x n` upper-triangular
/// `r` (column-major, `r[c * n + i]`): afterwards `r^T r` is the old `r^T r + b^T b`. `b` is
/// scratch (overwritten).
pub(crate) fn fold_rows(r: &mut [f64], n: usize, b: &mut [f64], m: usize) {
    debug_assert_eq!(r.len(), n * n);
    debug_assert_eq!(b.len(), m * n);
    with_avx(
        #[inline(always)]
        || fold(r, n, b, m),
    )
}

#[inline(always)]
fn fold(r: &mut [f64], n: usize, b: &mut [f64], m: usize) {
    for j in 0..n {
        let (done, rest) = b.split_at_mut((j + 1) * m);
        let x = &done[j * m..];
        let sigma = dot(x, x);
        if sigma == 0.0 {
            // Nothing below the diagonal: column j is already reduced.
            continue;
        }
        let x0 = r[j * n + j];
        let norm = (x0 * x0 + sigma).sqrt();
        // The reflection maps [x0; x] to [alpha; 0], alpha of the sign opposite to x0's (no
        // cancellation in v0 = x0 - alpha).
        let alpha = if x0 >= 0.0 { -norm } else { norm };
        let v0 = x0 - alpha;
        let beta = 1.0 / (norm * (norm + x0.abs()));
        r[j * n + j] = alpha;
        for (c, col) in rest.chunks_exact_mut(m).enumerate() {
            let c = j + 1 + c;
            let rjc = r[c * n + j];
            let s = beta * (v0 * rjc + dot(x, col));
            r[c * n + j] = rjc - s * v0;
            for (y, xi) in col.iter_mut().zip(x) {
                *y -= s * xi;
            }
        }
    }
}

/// `sum a_i b_i` in four interleaved partial sums (a fixed order: the same bits on every
/// processor, and independent sums that vector units can run side by side).
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (a4, at) = a.split_at(a.len() / 4 * 4);
    let (b4, bt) = b.split_at(a4.len());
    for (u, v) in a4.chunks_exact(4).zip(b4.chunks_exact(4)) {
        for l in 0..4 {
            acc[l] += u[l] * v[l];
        }
    }
    let mut s = (acc[0] + acc[2]) + (acc[1] + acc[3]);
    for (u, v) in at.iter().zip(bt) {
        s += u * v;
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;
    use rand::{Rng, SeedableRng};

    fn random(rows: usize, cols: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        DMatrix::from_fn(rows, cols, |_, _| rng.gen_range(-1.0..1.0))
    }

    fn fold_all(j: &DMatrix<f64>, block: usize) -> DMatrix<f64> {
        let n = j.ncols();
        let mut r = vec![0.0; n * n];
        let mut top = 0;
        while top < j.nrows() {
            let m = block.min(j.nrows() - top);
            let mut b: Vec<f64> = (0..n)
                .flat_map(|c| (0..m).map(move |i| (i, c)))
                .map(|(i, c)| j[(top + i, c)])
                .collect();
            fold_rows(&mut r, n, &mut b, m);
            top += m;
        }
        DMatrix::from_column_slice(n, n, &r)
    }

    /// Folding blocks gives an upper-triangular R with R^T R = J^T J for blocks of every size
    /// (one row at a time included), also with a zero and a duplicated column; for a full-rank
    /// J it is nalgebra's R up to the signs of its rows. (With dependent columns the factor is
    /// not unique beyond R^T R, which is all the analysis uses.)
    #[test]
    fn folded_blocks_give_the_r_factor() {
        let (rows, n) = (301, 23);
        let full = random(rows, n, 7);
        let mut deficient = full.clone();
        deficient.column_mut(4).fill(0.0);
        let dup = deficient.column(2) * 3.0 - deficient.column(9);
        deficient.set_column(17, &dup);
        for (name, j) in [("full rank", &full), ("deficient", &deficient)] {
            let want = j.clone().qr().r();
            for block in [1, 5, 64, 128, rows] {
                let r = fold_all(j, block);
                for c in 0..n {
                    for i in c + 1..n {
                        assert_eq!(r[(i, c)], 0.0, "{name}, block {block}: below the diagonal");
                    }
                }
                let g = j.transpose() * j;
                let err = (r.transpose() * &r - &g).abs().max();
                assert!(
                    err <= 1e-12 * g.abs().max(),
                    "{name}, block {block}: R^T R off by {err}"
                );
                if name == "full rank" {
                    let diff = (r.abs() - want.abs()).abs().max();
                    assert!(diff <= 1e-12 * want.abs().max(), "block {block}: {diff}");
                }
            }
        }
    }

    /// Folding an R into another (as parallel parts are merged) equals folding all the rows.
    #[test]
    fn folding_two_factors_equals_folding_the_rows() {
        let n = 12;
        let j = random(200, n, 9);
        let a = fold_all(&j.rows(0, 120).into_owned(), 50);
        let b = fold_all(&j.rows(120, 80).into_owned(), 50);
        let mut r: Vec<f64> = a.as_slice().to_vec();
        let mut bt: Vec<f64> = b.as_slice().to_vec();
        fold_rows(&mut r, n, &mut bt, n);
        let merged = DMatrix::from_column_slice(n, n, &r);
        let g = j.transpose() * &j;
        let err = (merged.transpose() * &merged - &g).abs().max();
        assert!(err <= 1e-12 * g.abs().max(), "{err}");
    }
}
