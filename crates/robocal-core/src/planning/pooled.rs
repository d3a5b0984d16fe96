//! Greedy selection over many candidates: fresh scores of every candidate at checkpoints, the
//! eager selector's updates within a pool of the best between them.
//!
//! The eager selector of [`super::design`] updates every candidate's `D_i` after each chosen
//! pose: `O(n k)` per pose, `O(poses n k)` in all, hours for 2,000 of 200,000 candidates. Here
//! every candidate is scored afresh only at checkpoints (with the Cholesky factor `L` of `M`,
//! `y = L^-1 J_i^T` gives `D_i = y^T y` and `E_i = y^T (L^-1 W L^-T) y` in `O(k^2)`, in
//! parallel), after 0, 1, 2, 3, 4, 6, 9... poses (each interval half the poses chosen so far);
//! between two checkpoints the poses are chosen greedily by the eager selector from a pool of
//! the best-scoring candidates, ten times as many as the interval's poses and at least
//! [`POOL_MIN`]. A pose's score changes little within an interval once a few poses are chosen,
//! so the pool holds the poses the eager greedy over all candidates would take; the test
//! compares the final criterion with it. Cost: `O(n k^2 log(poses) + poses^2 k)` instead of
//! `O(poses n k)`, and fresh factors at every checkpoint keep the updates' rounding small.

use super::design::{Blocks, Criterion, Selector, ROWS};
use crate::progress::{Observer, Stage};
use nalgebra::{Cholesky, DMatrix, Matrix3};
use rayon::prelude::*;

/// Smallest pool of candidates between two checkpoints.
pub const POOL_MIN: usize = 1000;

/// Pool candidates per pose chosen between two checkpoints.
const POOL_PER_POSE: usize = 10;

/// Fresh scores of every candidate for a set: `M`, its Cholesky factor and (I-optimality)
/// `L^-1 W L^-T`, row-major.
pub struct Fresh<'a> {
    blocks: &'a Blocks,
    criterion: Criterion,
    info: DMatrix<f64>,
    w: DMatrix<f64>,
    /// Row-major `L` (lower triangular).
    l: Vec<f64>,
    /// Row-major `L^-1 W L^-T` (I-optimality).
    wt: Vec<f64>,
    /// `tr(W M^-1)` (I-optimality).
    trace: f64,
}

impl<'a> Fresh<'a> {
    /// A selection whose information starts at `base` (the included poses and the ridge); `w`
    /// is I-optimality's workspace weight (ignored for D-optimality).
    pub fn new(
        blocks: &'a Blocks,
        base: DMatrix<f64>,
        criterion: Criterion,
        w: DMatrix<f64>,
    ) -> Self {
        let mut s = Fresh {
            blocks,
            criterion,
            info: base,
            w,
            l: Vec::new(),
            wt: Vec::new(),
            trace: 0.0,
        };
        s.factor();
        s
    }

    fn factor(&mut self) {
        let k = self.blocks.k();
        let ch = Cholesky::new(self.info.clone()).expect("the ridge keeps M positive definite");
        let l = ch.l();
        self.l = (0..k * k).map(|x| l[(x / k, x % k)]).collect();
        if self.criterion == Criterion::IOptimal {
            let mut a = self.w.clone();
            l.solve_lower_triangular_mut(&mut a);
            let mut b = a.transpose();
            l.solve_lower_triangular_mut(&mut b);
            self.trace = b.trace();
            self.wt = (0..k * k).map(|x| b[(x / k, x % k)]).collect();
        }
    }

    /// Candidate i's score now (as [`super::design::Selector::score`]); `y` is scratch space
    /// of `2 ROWS k` numbers.
    pub fn score(&self, i: usize, y: &mut [f64]) -> f64 {
        let k = self.blocks.k();
        let b = self.blocks.block(i);
        let (y, z) = y.split_at_mut(ROWS * k);
        // y_r = L^-1 j_r, forward substitution.
        for r in 0..ROWS {
            let (j, yr) = (&b[r * k..(r + 1) * k], &mut y[r * k..(r + 1) * k]);
            for a in 0..k {
                let row = &self.l[a * k..a * k + a];
                let s: f64 = row.iter().zip(&yr[..a]).map(|(l, v)| l * v).sum();
                yr[a] = (j[a] - s) / self.l[a * k + a];
            }
        }
        let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let d = Matrix3::from_fn(|r, t| dot(&y[r * k..(r + 1) * k], &y[t * k..(t + 1) * k]));
        let ipd = Matrix3::identity() + d;
        match self.criterion {
            Criterion::DOptimal => ipd.determinant(),
            Criterion::IOptimal => {
                for t in 0..ROWS {
                    let yt = &y[t * k..(t + 1) * k];
                    for a in 0..k {
                        z[t * k + a] = dot(&self.wt[a * k..(a + 1) * k], yt);
                    }
                }
                let e =
                    Matrix3::from_fn(|r, t| dot(&y[r * k..(r + 1) * k], &z[t * k..(t + 1) * k]));
                match ipd.try_inverse() {
                    Some(si) => (si * e).trace(),
                    None => 0.0,
                }
            }
        }
    }

    /// Every candidate's score now, in parallel.
    pub fn scores(&self) -> Vec<f64> {
        let k = self.blocks.k();
        (0..self.blocks.len())
            .into_par_iter()
            .map_init(|| vec![0.0; 2 * ROWS * k], |y, i| self.score(i, y))
            .collect()
    }

    /// The criterion's value: `ln det M` (D) or `tr(W M^-1)` (I), ridge included.
    pub fn value(&self) -> f64 {
        let k = self.blocks.k();
        match self.criterion {
            Criterion::DOptimal => 2.0 * (0..k).map(|a| self.l[a * k + a].ln()).sum::<f64>(),
            Criterion::IOptimal => self.trace,
        }
    }
}

/// Chooses `n` candidates greedily, the information starting at `base` (see the module docs),
/// reporting `(Stage::PoseSelection, chosen, n)`; returns them in the order chosen (fewer when
/// the candidates run out) with the criterion's value.
pub fn greedy(
    blocks: &Blocks,
    base: &DMatrix<f64>,
    criterion: Criterion,
    w: &DMatrix<f64>,
    n: usize,
    observer: &dyn Observer,
) -> (Vec<usize>, f64) {
    let mut chosen: Vec<usize> = Vec::with_capacity(n);
    let mut taken = vec![false; blocks.len()];
    let mut info = base.clone();
    observer.progress(Stage::PoseSelection, 0, n);
    loop {
        let fresh = Fresh::new(blocks, info.clone(), criterion, w.clone());
        let free = blocks.len() - chosen.len();
        if chosen.len() >= n || free == 0 {
            return (chosen, fresh.value());
        }
        let steps = (n - chosen.len()).min((chosen.len() / 2).max(1)).min(free);
        let scores = fresh.scores();
        let mut pool: Vec<usize> = (0..blocks.len()).filter(|&i| !taken[i]).collect();
        let size = (steps * POOL_PER_POSE).max(POOL_MIN).min(pool.len());
        let by_score = |a: &usize, b: &usize| scores[*b].total_cmp(&scores[*a]).then(a.cmp(b));
        if size < pool.len() {
            pool.select_nth_unstable_by(size, by_score);
            pool.truncate(size);
        }
        pool.sort_unstable();
        let sub = blocks.subset(&pool);
        let mut sel = Selector::new(&sub, info.clone(), criterion, Some(w.clone()));
        sel.greedy(steps);
        for &i in sel.selected() {
            chosen.push(pool[i]);
            taken[pool[i]] = true;
        }
        info = base + blocks.information(&chosen);
        observer.progress(Stage::PoseSelection, chosen.len(), n);
    }
}
