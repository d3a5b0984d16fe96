//! One pass's accumulation of the normal equations (the hot loop of [`super::Problem`]): the
//! per-thread buffers, one observation's rows added, the Gram updates.

use super::{chunked, Accumulated, Level, Problem};
use crate::identification::kinds;
use crate::identification::objective::Loss;
use crate::model::family::PoseFrames;
use crate::model::Robot;
use nalgebra::{DMatrix, DVector, Vector3};

/// Per-thread state of a pass.
pub(super) struct Acc {
    pub(super) k: usize,
    pub(super) full: bool,
    pub(super) newton: bool,
    pub(super) objective: f64,
    pub(super) weighted_sq: f64,
    pub(super) psi_sq: f64,
    pub(super) a: Vec<f64>,
    pub(super) b: Vec<f64>,
    pub(super) s: Vec<f64>,
    pub(super) h: Vec<f64>,
    /// Parameter screws at the tool: linear and (when the kind sees orientation) angular parts.
    pub(super) jp: Vec<Vector3<f64>>,
    pub(super) jw: Vec<Vector3<f64>>,
    /// The observation's Jacobian rows, row-major (rows x k).
    pub(super) jr: Vec<f64>,
    pub(super) u: Vec<f64>,
    /// The last observation's forward pass, reused by the next when it is the same pose seen
    /// through another target.
    pub(super) frames: Option<(usize, Box<PoseFrames>)>,
}

impl Acc {
    pub(super) fn new(k: usize, rows: usize, n_params: usize, angular: bool, level: Level) -> Acc {
        let full = level == Level::Full;
        let newton = level >= Level::Newton;
        Acc {
            k,
            full,
            newton,
            objective: 0.0,
            weighted_sq: 0.0,
            psi_sq: 0.0,
            a: vec![0.0; k * k],
            b: vec![0.0; k],
            s: vec![0.0; if full { k * k } else { 0 }],
            h: vec![0.0; if newton { k * k } else { 0 }],
            jp: vec![Vector3::zeros(); n_params],
            jw: vec![Vector3::zeros(); if angular { n_params } else { 0 }],
            jr: vec![0.0; rows * k],
            u: vec![0.0; if newton { k } else { 0 }],
            frames: None,
        }
    }

    pub(super) fn merge(mut self, o: Acc) -> Acc {
        self.objective += o.objective;
        self.weighted_sq += o.weighted_sq;
        self.psi_sq += o.psi_sq;
        for (x, y) in self.a.iter_mut().zip(&o.a) {
            *x += y;
        }
        for (x, y) in self.b.iter_mut().zip(&o.b) {
            *x += y;
        }
        for (x, y) in self.s.iter_mut().zip(&o.s) {
            *x += y;
        }
        for (x, y) in self.h.iter_mut().zip(&o.h) {
            *x += y;
        }
        self
    }

    /// Adds observation `i`: its (weighted) residual rows and Jacobian rows
    /// ([`Problem::observation_rows`]), then `w J^T J`, `w J^T e` (upper triangles) and what the
    /// level adds.
    #[inline(always)]
    /// Returns the observation's weighted residual norm (its [`Problem::fit_norms`] entry).
    pub(super) fn add_observation(
        &mut self,
        p: &Problem,
        robot: &Robot,
        loss: &Loss,
        i: usize,
    ) -> f64 {
        let rows = p.kind.rows();
        let mut e = [0.0; kinds::MAX_ROWS];
        let angular = !self.jw.is_empty();
        p.observation_rows_cached(
            robot,
            i,
            &mut self.frames,
            &mut self.jp,
            angular.then_some(&mut self.jw[..]),
            &mut e[..rows],
            &mut self.jr,
        );
        // Point measurements (3 rows) take a copy of the loop the compiler unrolls.
        if rows == 3 {
            self.accumulate(3, &e[..3], loss)
        } else {
            self.accumulate(rows, &e[..rows], loss)
        }
    }

    /// The accumulation of one observation's rows (`self.jr`, `rows x k`) and residual `e`;
    /// returns the residual's norm.
    #[inline(always)]
    pub(super) fn accumulate(&mut self, rows: usize, e: &[f64], loss: &Loss) -> f64 {
        let k = self.k;
        let jr = &self.jr[..rows * k];
        let mut r2 = 0.0;
        for v in e {
            r2 += v * v;
        }
        let r = r2.sqrt();
        let w = loss.weight(r);
        self.objective += loss.value(r);
        self.weighted_sq += w * r * r;
        let mut we = [0.0; kinds::MAX_ROWS];
        for (x, v) in we.iter_mut().zip(e) {
            *x = w * v;
        }
        for a in 0..k {
            let mut s = 0.0;
            for rr in 0..rows {
                s += jr[rr * k + a] * we[rr];
            }
            self.b[a] += s;
        }
        add_gram(&mut self.a, jr, rows, k, w);
        if self.full {
            let psi = w * r;
            self.psi_sq += psi * psi;
            // `S = A + sum (1 - w) J^T J`: only the points the loss down-weights add work
            // (every point of a least-squares pass, and the inliers of the adaptive loss, have
            // w = 1 exactly).
            let cw = 1.0 - w;
            if cw != 0.0 {
                add_gram(&mut self.s, jr, rows, k, cw);
            }
        }
        // Radial correction of the Hessian: (l'' - w) (J^T u)(J^T u)^T; none where the loss
        // is quadratic (l'' = w).
        let c = if self.newton && r > 0.0 {
            loss.radial_curvature(r) - w
        } else {
            0.0
        };
        if c != 0.0 {
            let mut ue = [0.0; kinds::MAX_ROWS];
            for (x, v) in ue.iter_mut().zip(e) {
                *x = v / r;
            }
            for a in 0..k {
                let mut s = 0.0;
                for rr in 0..rows {
                    s += jr[rr * k + a] * ue[rr];
                }
                self.u[a] = s;
            }
            let u = &self.u[..k];
            for a in 0..k {
                let ca = c * u[a];
                let row = &mut self.h[a * k + a..(a + 1) * k];
                for (x, ub) in row.iter_mut().zip(&u[a..]) {
                    *x += ca * ub;
                }
            }
        }
        r
    }
}

/// Adds the upper triangle of `scale J^T J` to `m` (k x k, row-major), `J` being `rows x k`
/// row-major. Point rows (3) take a loop over contiguous row slices that the compiler
/// vectorizes; the sums are those of the general loop, in the same order.
#[inline(always)]
pub(crate) fn add_gram(m: &mut [f64], jr: &[f64], rows: usize, k: usize, scale: f64) {
    if rows == 3 {
        let (j0, rest) = jr.split_at(k);
        let (j1, j2) = rest.split_at(k);
        for a in 0..k {
            let (w0, w1, w2) = (scale * j0[a], scale * j1[a], scale * j2[a]);
            if w0 == 0.0 && w1 == 0.0 && w2 == 0.0 {
                continue;
            }
            let row = &mut m[a * k + a..(a + 1) * k];
            for (((x, y0), y1), y2) in row.iter_mut().zip(&j0[a..]).zip(&j1[a..]).zip(&j2[a..k]) {
                *x += w0 * y0 + w1 * y1 + w2 * y2;
            }
        }
        return;
    }
    let mut wa = [0.0; kinds::MAX_ROWS];
    for a in 0..k {
        for rr in 0..rows {
            wa[rr] = scale * jr[rr * k + a];
        }
        let row = &mut m[a * k..(a + 1) * k];
        for b in a..k {
            let mut s = 0.0;
            for rr in 0..rows {
                s += wa[rr] * jr[rr * k + b];
            }
            row[b] += s;
        }
    }
}

/// Fills the lower triangle of a k x k row-major upper-triangular accumulator.
pub(super) fn symmetric(k: usize, upper: &[f64]) -> DMatrix<f64> {
    // Column c (column-major): rows 0..=c are row r's entry c of the upper triangle (a stride
    // of k), rows below are row c's own entries past the diagonal (contiguous).
    let mut m = Vec::with_capacity(k * k);
    for c in 0..k {
        m.extend((0..=c).map(|r| upper[r * k + c]));
        m.extend_from_slice(&upper[c * k + c + 1..(c + 1) * k]);
    }
    DMatrix::from_vec(k, k, m)
}

impl Problem<'_> {
    /// One pass over the observations: objective and IRLS normal equations, and what `level`
    /// adds.
    pub fn accumulate(&self, robot: &Robot, loss: &Loss, level: Level) -> Accumulated {
        let k = self.params.len();
        let np = robot.param_count();
        let rows = self.kind.rows();
        let angular = self.angular;
        let new = || Acc::new(k, rows, np, angular, level);
        let keep = self.keep_norms;
        // Each chunk's norms in order, the chunks' in order.
        let join = |mut a: Vec<f64>, b: Vec<f64>| {
            a.extend(b);
            a
        };
        let (acc, groups, norms) = match self.groups.filter(|_| level >= Level::Newton) {
            None => {
                let (acc, norms) = chunked(
                    self.len(),
                    || (new(), Vec::new()),
                    #[inline(always)]
                    |(acc, norms), i| {
                        let r = acc.add_observation(self, robot, loss, i);
                        if keep {
                            norms.push(r);
                        }
                    },
                    |(a, na), (b, nb)| (a.merge(b), join(na, nb)),
                );
                (acc, None, norms)
            }
            Some((group, count)) => {
                let (parts, norms) = chunked(
                    self.len(),
                    || ((0..count).map(|_| new()).collect::<Vec<Acc>>(), Vec::new()),
                    #[inline(always)]
                    |(accs, norms), i| {
                        let r = accs[group[i]].add_observation(self, robot, loss, i);
                        if keep {
                            norms.push(r);
                        }
                    },
                    |(a, na), (b, nb)| {
                        let merged = a.into_iter().zip(b).map(|(x, y)| x.merge(y)).collect();
                        (merged, join(na, nb))
                    },
                );
                let shares = parts
                    .iter()
                    .map(|g| {
                        let a = symmetric(k, &g.a);
                        (&a + symmetric(k, &g.h), DVector::from_column_slice(&g.b))
                    })
                    .collect();
                let whole = parts.into_iter().reduce(Acc::merge).unwrap_or_else(new);
                (whole, Some(shares), norms)
            }
        };
        let a = symmetric(k, &acc.a);
        let s = (level == Level::Full).then(|| &a + symmetric(k, &acc.s));
        let h = (level >= Level::Newton).then(|| &a + symmetric(k, &acc.h));
        Accumulated {
            objective: acc.objective,
            weighted_sq: acc.weighted_sq,
            b: DVector::from_vec(acc.b),
            a,
            s,
            h,
            psi_sq: acc.psi_sq,
            rows: self.rows(),
            groups,
            norms: keep.then_some(norms),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::symmetric;

    /// The column copies fill every entry from the upper triangle, mirrored below it.
    #[test]
    fn symmetric_mirrors_the_upper_triangle() {
        for k in [1, 2, 5, 38] {
            // Distinct values everywhere, the lower triangle's never read.
            let upper: Vec<f64> = (0..k * k).map(|i| i as f64 + 0.5).collect();
            let m = symmetric(k, &upper);
            for r in 0..k {
                for c in 0..k {
                    let (a, b) = if r <= c { (r, c) } else { (c, r) };
                    assert_eq!(m[(r, c)], upper[a * k + b], "k {k}, ({r}, {c})");
                }
            }
        }
    }
}
