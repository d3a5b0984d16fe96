//! D-optimal selection of measurement poses from candidates: a greedy start and Fedorov-style
//! exchange passes over the information matrix `M = ridge I + sum J_i^T J_i` of the selected
//! poses' (column-scaled) Jacobian blocks.
//!
//! Adding pose p multiplies `det M` by `det(I + J_p M^-1 J_p^T)`; removing it by
//! `det(I - J_p M^-1 J_p^T)`. The selector keeps, for every candidate i, the small matrix
//! `D_i = J_i M^-1 J_i^T` (its prediction variance, rows x rows) and updates all of them after
//! each change by the Woodbury identity (`9k` operations per candidate for point rows), so a
//! step costs `O(n k)` for n candidates instead of `O(n k^2)`. Rounding that these low-rank
//! updates accumulate is removed by recomputing `M^-1` and every `D_i` from `M` regularly.
//! (Written here rather than taken from a crate: the known experimental-design crates work on
//! single-row regressors; calibration poses are blocks of rows.)

use crate::progress::{Observer, Stage};
use nalgebra::{Cholesky, DMatrix, Matrix3};
use rayon::prelude::*;

/// One parallel work item: a chunk's index, its `D_i` and (I-optimality) its `E_i`.
type Work<'a> = (usize, &'a mut [f64], Option<&'a mut [f64]>);

/// Rows per candidate supported (point measurements: 3).
pub const ROWS: usize = 3;

/// Low-rank updates between two recomputations from scratch.
const REFRESH_EVERY: usize = 96;

/// Candidates per parallel work item.
const CHUNK: usize = 256;

/// The candidates' Jacobian blocks, `ROWS x k` each (row-major), already column-scaled.
#[derive(Debug, Clone)]
pub struct Blocks {
    k: usize,
    j: Vec<f64>,
}

impl Blocks {
    /// The blocks of candidates `idx`, in that order.
    pub fn subset(&self, idx: &[usize]) -> Blocks {
        Blocks {
            k: self.k,
            j: idx
                .iter()
                .flat_map(|&i| self.block(i).iter().copied())
                .collect(),
        }
    }

    /// Blocks of `k` columns from `j` (`n * ROWS * k` numbers).
    pub fn new(k: usize, j: Vec<f64>) -> Blocks {
        assert!(k > 0 && j.len() % (ROWS * k) == 0, "block layout");
        Blocks { k, j }
    }

    /// Number of columns (parameters).
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.j.len() / (ROWS * self.k)
    }

    /// Whether there are no candidates.
    pub fn is_empty(&self) -> bool {
        self.j.is_empty()
    }

    /// Candidate i's block.
    pub fn block(&self, i: usize) -> &[f64] {
        let s = ROWS * self.k;
        &self.j[i * s..(i + 1) * s]
    }

    /// `sum J_i^T J_i` over `idx`.
    pub fn information(&self, idx: &[usize]) -> DMatrix<f64> {
        let k = self.k;
        let mut m = DMatrix::zeros(k, k);
        for &i in idx {
            let b = self.block(i);
            for r in 0..ROWS {
                let row = &b[r * k..(r + 1) * k];
                for a in 0..k {
                    for c in a..k {
                        m[(a, c)] += row[a] * row[c];
                    }
                }
            }
        }
        for a in 0..k {
            for c in 0..a {
                m[(a, c)] = m[(c, a)];
            }
        }
        m
    }
}

/// `det(I + s D)` for a 3 x 3 `D` stored row-major.
fn det_plus(d: &[f64], s: f64) -> f64 {
    m3(d, s).determinant()
}

/// `I + s D` for a 3 x 3 `D` stored row-major.
fn m3(d: &[f64], s: f64) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| (if r == c { 1.0 } else { 0.0 }) + s * d[r * ROWS + c])
}

/// What the selection optimizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Criterion {
    /// Maximize `det M` (D-optimality): the smallest joint confidence region of the parameters.
    DOptimal,
    /// Minimize `tr(W M^-1)` with `W` the mean `J_i^T J_i` over the candidates (I-optimality):
    /// the mean squared model error the parameters' uncertainty leaves over the workspace the
    /// candidates sample.
    IOptimal,
}

/// The selector's state: the information matrix of a set and, for every candidate, `D_i` (and
/// for I-optimality `E_i = J_i M^-1 W M^-1 J_i^T`, whose trace is candidate i's share of the
/// criterion).
pub struct Selector<'a> {
    blocks: &'a Blocks,
    criterion: Criterion,
    /// `ridge I + fixed + selected`.
    info: DMatrix<f64>,
    minv: DMatrix<f64>,
    /// I-optimality's weight `W`.
    w: DMatrix<f64>,
    /// Row-major `ROWS x ROWS` per candidate.
    d: Vec<f64>,
    e: Vec<f64>,
    in_set: Vec<bool>,
    selected: Vec<usize>,
    updates: usize,
}

impl<'a> Selector<'a> {
    /// A selector whose information starts at `base` (included poses and the ridge). For
    /// I-optimality `w` is the workspace's mean `J^T J` (default: the candidates').
    pub fn new(
        blocks: &'a Blocks,
        base: DMatrix<f64>,
        criterion: Criterion,
        w: Option<DMatrix<f64>>,
    ) -> Selector<'a> {
        let n = blocks.len();
        let k = blocks.k;
        let w = match criterion {
            Criterion::DOptimal => DMatrix::zeros(0, 0),
            Criterion::IOptimal => w.unwrap_or_else(|| {
                let all: Vec<usize> = (0..n).collect();
                blocks.information(&all) / n.max(1) as f64
            }),
        };
        let e = match criterion {
            Criterion::DOptimal => Vec::new(),
            Criterion::IOptimal => vec![0.0; n * ROWS * ROWS],
        };
        let mut s = Selector {
            blocks,
            criterion,
            minv: DMatrix::zeros(k, k),
            info: base,
            w,
            d: vec![0.0; n * ROWS * ROWS],
            e,
            in_set: vec![false; n],
            selected: Vec::new(),
            updates: 0,
        };
        s.refresh();
        s
    }

    /// Takes candidates `idx` into the set at once (then recomputes).
    pub fn preselect(&mut self, idx: &[usize]) {
        self.info += self.blocks.information(idx);
        for &i in idx {
            self.in_set[i] = true;
            self.selected.push(i);
        }
        self.refresh();
    }

    /// Every candidate's score (see [`Selector::score`]).
    pub fn scores(&self) -> Vec<f64> {
        (0..self.blocks.len())
            .into_par_iter()
            .map(|i| self.score(i))
            .collect()
    }

    /// The selected candidates, in selection order.
    pub fn selected(&self) -> &[usize] {
        &self.selected
    }

    /// Recomputes `M^-1`, every `D_i` and `E_i` from `M`.
    fn refresh(&mut self) {
        let k = self.blocks.k;
        let ch = Cholesky::new(self.info.clone()).expect("the ridge keeps M positive definite");
        self.minv = ch.inverse();
        let l = ch.l();
        let blocks = self.blocks;
        let iopt = self.criterion == Criterion::IOptimal;
        // E_i = J_i M^-1 W M^-1 J_i^T = y^T (L^-1 W L^-T) y with y = L^-1 J_i^T.
        let wt = if iopt {
            let mut a = self.w.clone();
            l.solve_lower_triangular_mut(&mut a);
            let mut b = a.transpose();
            l.solve_lower_triangular_mut(&mut b);
            b
        } else {
            DMatrix::zeros(0, 0)
        };
        let wt = &wt;
        let sq = ROWS * ROWS;
        let mut e = std::mem::take(&mut self.e);
        let e_chunks: Vec<&mut [f64]> = if iopt {
            e.chunks_mut(CHUNK * sq).collect()
        } else {
            Vec::new()
        };
        let mut e_iter = e_chunks.into_iter();
        let work: Vec<Work> = self
            .d
            .chunks_mut(CHUNK * sq)
            .enumerate()
            .map(|(c, d)| (c, d, e_iter.next()))
            .collect();
        work.into_par_iter().for_each(|(c, out, eo)| {
            let mut y = DMatrix::zeros(k, ROWS);
            let mut wy = DMatrix::zeros(k, ROWS);
            let mut eo = eo;
            for (o, dd) in out.chunks_exact_mut(sq).enumerate() {
                let b = blocks.block(c * CHUNK + o);
                for r in 0..ROWS {
                    for a in 0..k {
                        y[(a, r)] = b[r * k + a];
                    }
                }
                l.solve_lower_triangular_mut(&mut y);
                for r in 0..ROWS {
                    for t in 0..ROWS {
                        dd[r * ROWS + t] = y.column(r).dot(&y.column(t));
                    }
                }
                if let Some(eo) = eo.as_deref_mut() {
                    wt.mul_to(&y, &mut wy);
                    for r in 0..ROWS {
                        for t in 0..ROWS {
                            eo[o * sq + r * ROWS + t] = y.column(r).dot(&wy.column(t));
                        }
                    }
                }
            }
        });
        self.e = e;
        self.updates = 0;
    }

    /// Candidate i's score for being added: for D-optimality `det(I + D_i)`, the factor by
    /// which it multiplies `det M`; for I-optimality `tr((I + D_i)^-1 E_i)`, by how much it
    /// lowers `tr(W M^-1)`.
    pub fn score(&self, i: usize) -> f64 {
        let sq = ROWS * ROWS;
        let d = &self.d[i * sq..(i + 1) * sq];
        match self.criterion {
            Criterion::DOptimal => det_plus(d, 1.0),
            Criterion::IOptimal => {
                let e = Matrix3::from_row_slice(&self.e[i * sq..(i + 1) * sq]);
                match m3(d, 1.0).try_inverse() {
                    Some(si) => (si * e).trace(),
                    None => 0.0,
                }
            }
        }
    }

    /// The candidate not in the set with the best score, with its score.
    fn best(&self) -> Option<(usize, f64)> {
        (0..self.blocks.len())
            .into_par_iter()
            .with_min_len(CHUNK)
            .filter(|&i| !self.in_set[i])
            .map(|i| (i, self.score(i)))
            .reduce_with(|a, b| {
                if b.1 > a.1 || (b.1 == a.1 && b.0 < a.0) {
                    b
                } else {
                    a
                }
            })
    }

    /// Adds (`s = 1`) or removes (`s = -1`) candidate p, updating `M^-1`, every `D_i` and
    /// `E_i` by the Woodbury identity: with `U = M^-1 J_p^T`, `S = I + s J_p U`,
    /// `M'^-1 = M^-1 - s U S^-1 U^T`, and with `G_i = J_i U`, `H_i = J_i M^-1 W U`,
    /// `Q = U^T W U`: `D_i' = D_i - s G S^-1 G^T`,
    /// `E_i' = E_i - s (H S^-1 G^T + G S^-1 H^T) + G S^-1 Q S^-1 G^T`.
    fn update(&mut self, p: usize, s: f64) {
        let k = self.blocks.k;
        let jp = DMatrix::from_row_slice(ROWS, k, self.blocks.block(p));
        let u = &self.minv * jp.transpose(); // k x ROWS
        let jpu = &jp * &u;
        let sm = Matrix3::from_fn(|r, c| (if r == c { 1.0 } else { 0.0 }) + s * jpu[(r, c)]);
        let Some(sinv) = sm.try_inverse() else {
            // A removal that would make M singular: the ridge prevents it; recompute anyway.
            self.apply_info(p, s);
            self.refresh();
            return;
        };
        let iopt = self.criterion == Criterion::IOptimal;
        // V = M^-1 W U and Q = U^T W U (I-optimality).
        let (v, q) = if iopt {
            let wu = &self.w * &u;
            let q = u.transpose() * &wu;
            (&self.minv * wu, Matrix3::from_fn(|r, c| q[(r, c)]))
        } else {
            (DMatrix::zeros(0, 0), Matrix3::zeros())
        };
        let s_sinv = sinv * s;
        let minv_delta = &u * DMatrix::from_fn(ROWS, ROWS, |r, c| s_sinv[(r, c)]) * u.transpose();
        self.minv -= minv_delta;
        // Row-major copies of U^T and V^T for the per-candidate dot products.
        let ur: Vec<f64> = (0..ROWS)
            .flat_map(|c| (0..k).map(move |a| (c, a)))
            .map(|(c, a)| u[(a, c)])
            .collect();
        let vr: Vec<f64> = if iopt {
            (0..ROWS)
                .flat_map(|c| (0..k).map(move |a| (c, a)))
                .map(|(c, a)| v[(a, c)])
                .collect()
        } else {
            Vec::new()
        };
        let blocks = self.blocks;
        let sq = ROWS * ROWS;
        let mut e = std::mem::take(&mut self.e);
        let mut e_iter = e.chunks_mut(CHUNK * sq);
        let work: Vec<Work> = self
            .d
            .chunks_mut(CHUNK * sq)
            .enumerate()
            .map(|(c, d)| (c, d, if iopt { e_iter.next() } else { None }))
            .collect();
        let gdot = |b: &[f64], x: &[f64]| {
            let mut g = Matrix3::zeros();
            for r in 0..ROWS {
                let row = &b[r * k..(r + 1) * k];
                for c in 0..ROWS {
                    let xc = &x[c * k..(c + 1) * k];
                    let mut acc = 0.0;
                    for a in 0..k {
                        acc += row[a] * xc[a];
                    }
                    g[(r, c)] = acc;
                }
            }
            g
        };
        work.into_par_iter().for_each(|(ci, out, eo)| {
            let mut eo = eo;
            for (o, dd) in out.chunks_exact_mut(sq).enumerate() {
                let b = blocks.block(ci * CHUNK + o);
                let g = gdot(b, &ur);
                let gs = g * sinv;
                let dd_delta = gs * g.transpose() * s;
                for r in 0..ROWS {
                    for c in 0..ROWS {
                        dd[r * ROWS + c] -= dd_delta[(r, c)];
                    }
                }
                if let Some(eo) = eo.as_deref_mut() {
                    let h = gdot(b, &vr);
                    let hsg = h * sinv * g.transpose();
                    let delta = (hsg + hsg.transpose()) * s - gs * q * gs.transpose();
                    for r in 0..ROWS {
                        for c in 0..ROWS {
                            eo[o * sq + r * ROWS + c] -= delta[(r, c)];
                        }
                    }
                }
            }
        });
        self.e = e;
        self.apply_info(p, s);
        self.updates += 1;
        if self.updates >= REFRESH_EVERY {
            self.refresh();
        }
    }

    fn apply_info(&mut self, p: usize, s: f64) {
        let k = self.blocks.k;
        let jp = self.blocks.block(p);
        for r in 0..ROWS {
            let row = &jp[r * k..(r + 1) * k];
            for a in 0..k {
                for b in 0..k {
                    self.info[(a, b)] += s * row[a] * row[b];
                }
            }
        }
    }

    fn add(&mut self, p: usize) {
        self.update(p, 1.0);
        self.in_set[p] = true;
        self.selected.push(p);
    }

    /// Greedy selection of `n` more candidates (each the one with the best score). Returns how
    /// many were added (fewer when the candidates run out).
    pub fn greedy(&mut self, n: usize) -> usize {
        let mut added = 0;
        while added < n {
            let Some((i, _)) = self.best() else { break };
            self.add(i);
            added += 1;
        }
        self.refresh();
        added
    }

    /// One exchange pass: each selected pose in turn is taken out and replaced by the candidate
    /// with the best score (possibly itself). Returns the number of replacements and the pass's
    /// improvement of the criterion (relative: of `ln det M`, or of `tr(W M^-1)` divided by its
    /// value). Reports `(Stage::Exchange, reconsidered, selected)`.
    pub fn exchange_pass(&mut self, observer: &dyn Observer) -> (usize, f64) {
        let mut swaps = 0;
        let before = self.value();
        let n = self.selected.len();
        observer.progress(Stage::Exchange, 0, n);
        for pos in 0..n {
            if pos % 16 == 15 {
                observer.progress(Stage::Exchange, pos + 1, n);
            }
            let j = self.selected[pos];
            // Kept (the usual case once the design is good): restoring the state is a copy,
            // cheaper than the update that would put j back.
            let saved = (
                self.d.clone(),
                self.e.clone(),
                self.minv.clone(),
                self.info.clone(),
                self.updates,
            );
            self.update(j, -1.0);
            self.in_set[j] = false;
            // Putting j back restores the criterion: its score is the one to beat.
            let back = self.score(j);
            let (i, g) = self.best().expect("j itself is a candidate");
            if g > back * (1.0 + 1e-9) && i != j {
                swaps += 1;
                self.update(i, 1.0);
                self.in_set[i] = true;
                self.selected[pos] = i;
            } else {
                (self.d, self.e, self.minv, self.info, self.updates) = saved;
                self.in_set[j] = true;
            }
        }
        self.refresh();
        let after = self.value();
        let gain = match self.criterion {
            Criterion::DOptimal => after - before,
            Criterion::IOptimal => (before - after) / before,
        };
        (swaps, gain)
    }

    /// The criterion's value: `ln det M` (D) or `tr(W M^-1)` (I), ridge included.
    pub fn value(&self) -> f64 {
        match self.criterion {
            Criterion::DOptimal => log_det(&self.info),
            Criterion::IOptimal => (&self.w * &self.minv).trace(),
        }
    }

    /// `ln det M` of the current set (ridge included).
    pub fn log_det(&self) -> f64 {
        log_det(&self.info)
    }

    /// `D_i = J_i M^-1 J_i^T` of candidate i (fresh after [`Selector::exchange_pass`]).
    pub fn variance(&self, i: usize) -> &[f64] {
        &self.d[i * ROWS * ROWS..(i + 1) * ROWS * ROWS]
    }

    /// `E_i` of candidate i (I-optimality only).
    pub fn weighted_variance(&self, i: usize) -> &[f64] {
        &self.e[i * ROWS * ROWS..(i + 1) * ROWS * ROWS]
    }
}

/// `ln det` of a symmetric positive definite matrix (`-inf` when it is not).
pub fn log_det(m: &DMatrix<f64>) -> f64 {
    match Cholesky::new(m.clone()) {
        Some(ch) => 2.0 * ch.l().diagonal().iter().map(|v| v.ln()).sum::<f64>(),
        None => f64::NEG_INFINITY,
    }
}

#[cfg(test)]
#[path = "design_tests.rs"]
mod tests;
