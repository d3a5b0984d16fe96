//! The identification problem's hot loop: residuals, IRLS normal equations and the curvature
//! terms the covariance needs, accumulated point by point.
//!
//! For point i, `e_i = pose(F) m_i - p(q_i; theta)` (eq. 3 with the measured point mapped into the
//! ACS). With `J_i = d p(q_i) / d theta` restricted to the identified parameters and the loss
//! weight `w_i` (see [`Loss`]), the solver needs `A = sum w_i J_i^T J_i` and
//! `b = sum w_i J_i^T e_i`. They are accumulated per point (k x k and k numbers; the 3N x k
//! Jacobian is never formed) with per-thread buffers allocated once per pass, so the per-point work
//! allocates nothing. Large point sets are split across threads with rayon.

use crate::frame::Frame;
use crate::identification::objective::Loss;
use crate::identification::Observations;
use crate::model::{Param, Robot, MAX_JOINTS};
use nalgebra::{DMatrix, DVector, Vector3};
use rayon::prelude::*;

/// Largest number of model parameters (all of `alpha, d, a, phi, beta` for [`MAX_JOINTS`] joints
/// plus base and tool).
pub const MAX_PARAMS: usize = 5 * MAX_JOINTS + 12;

/// Below this many points the passes run on one thread.
const PARALLEL_MIN_POINTS: usize = 2048;

/// The identification problem: which parameters are unknown and the measured points in the ACS.
#[derive(Debug, Clone)]
pub struct Problem<'a> {
    params: Vec<Param>,
    /// Position of each identified parameter in `robot.params()`.
    index: Vec<usize>,
    obs: &'a Observations,
    /// `pose(F) m_i`.
    targets: Vec<Vector3<f64>>,
}

/// How much a pass accumulates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Level {
    /// Objective, `A` and `b`.
    Normal,
    /// Also the objective's Hessian `H` (for Newton steps).
    Newton,
    /// Also the unweighted Gram matrix `S` and `sum l'^2` (for the covariance).
    Full,
}

/// What one pass accumulates.
#[derive(Debug, Clone)]
pub struct Accumulated {
    /// The objective `sum l(|e_i|)`.
    pub objective: f64,
    /// `sum w_i |e_i|^2`.
    pub weighted_sq: f64,
    /// `A = sum w J^T J` (k x k, symmetric).
    pub a: DMatrix<f64>,
    /// `b = sum w J^T e` (k).
    pub b: DVector<f64>,
    /// [`Level::Full`] only: `S = sum J^T J` (unweighted).
    pub s: Option<DMatrix<f64>>,
    /// [`Level::Newton`] and above: the Hessian of the objective (Gauss-Newton part):
    /// `H = sum J^T (w (I - u u^T) + l'' u u^T) J`, `u = e / |e|`.
    pub h: Option<DMatrix<f64>>,
    /// [`Level::Full`] only: `sum (l'(|e_i|))^2`.
    pub psi_sq: f64,
}

/// Per-thread state of a pass.
struct Acc {
    k: usize,
    full: bool,
    newton: bool,
    objective: f64,
    weighted_sq: f64,
    psi_sq: f64,
    a: Vec<f64>,
    b: Vec<f64>,
    s: Vec<f64>,
    h: Vec<f64>,
    jp: Vec<Vector3<f64>>,
    jx: Vec<f64>,
    jy: Vec<f64>,
    jz: Vec<f64>,
    u: Vec<f64>,
}

impl Acc {
    fn new(k: usize, n_params: usize, level: Level) -> Acc {
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
            jx: vec![0.0; k],
            jy: vec![0.0; k],
            jz: vec![0.0; k],
            u: vec![0.0; if newton { k } else { 0 }],
        }
    }

    fn merge(mut self, o: Acc) -> Acc {
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

    /// Adds `c * v v^T` (upper triangle) for v given by the three rows `jx, jy, jz` weighted per
    /// axis: `sum_axes c_axis * row_axis row_axis^T`.
    #[inline]
    fn add_point(&mut self, p: &Problem, robot: &Robot, loss: &Loss, i: usize) {
        let pos = robot.tool_position_jacobians(p.obs.q(i), None, Some(&mut self.jp));
        let k = self.k;
        for (c, &j) in p.index.iter().enumerate() {
            let v = self.jp[j];
            self.jx[c] = v.x;
            self.jy[c] = v.y;
            self.jz[c] = v.z;
        }
        let e = p.targets[i] - pos;
        let r = e.norm();
        let w = loss.weight(r);
        self.objective += loss.value(r);
        self.weighted_sq += w * r * r;
        let (ex, ey, ez) = (w * e.x, w * e.y, w * e.z);
        for a in 0..k {
            let (xa, ya, za) = (self.jx[a], self.jy[a], self.jz[a]);
            self.b[a] += xa * ex + ya * ey + za * ez;
            let (wx, wy, wz) = (w * xa, w * ya, w * za);
            let row = &mut self.a[a * k..(a + 1) * k];
            for b in a..k {
                row[b] += wx * self.jx[b] + wy * self.jy[b] + wz * self.jz[b];
            }
        }
        if self.full {
            let psi = w * r;
            self.psi_sq += psi * psi;
            for a in 0..k {
                let (xa, ya, za) = (self.jx[a], self.jy[a], self.jz[a]);
                let row = &mut self.s[a * k..(a + 1) * k];
                for b in a..k {
                    row[b] += xa * self.jx[b] + ya * self.jy[b] + za * self.jz[b];
                }
            }
        }
        if self.newton {
            // Radial correction of the Hessian: (l'' - w) (J^T u)(J^T u)^T.
            if r > 0.0 {
                let c = loss.radial_curvature(r) - w;
                let (ux, uy, uz) = (e.x / r, e.y / r, e.z / r);
                for a in 0..k {
                    self.u[a] = self.jx[a] * ux + self.jy[a] * uy + self.jz[a] * uz;
                }
                for a in 0..k {
                    let ca = c * self.u[a];
                    let row = &mut self.h[a * k..(a + 1) * k];
                    for b in a..k {
                        row[b] += ca * self.u[b];
                    }
                }
            }
        }
    }
}

/// Fills the lower triangle of a k x k row-major upper-triangular accumulator.
fn symmetric(k: usize, upper: &[f64]) -> DMatrix<f64> {
    DMatrix::from_fn(k, k, |r, c| {
        if r <= c {
            upper[r * k + c]
        } else {
            upper[c * k + r]
        }
    })
}

impl<'a> Problem<'a> {
    /// The problem of identifying `params` of `robot` from `obs`, whose points map into the ACS
    /// by the tracker frame `frame`. Panics if a parameter is not one of the robot's (the callers
    /// take them from `robot.params()`).
    pub fn new(robot: &Robot, params: &[Param], obs: &'a Observations, frame: &Frame) -> Self {
        let all = robot.params();
        let index = params
            .iter()
            .map(|p| {
                all.iter()
                    .position(|q| q == p)
                    .expect("parameter of the robot")
            })
            .collect();
        let targets = crate::frame::TrackerFrame::new(*frame).points_to_base(obs.measured());
        Problem {
            params: params.to_vec(),
            index,
            obs,
            targets,
        }
    }

    /// The identified parameters.
    pub fn params(&self) -> &[Param] {
        &self.params
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.targets.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.targets.is_empty()
    }

    /// The identified parameters' current values (internal units).
    pub fn values(&self, robot: &Robot) -> DVector<f64> {
        DVector::from_iterator(self.params.len(), self.params.iter().map(|p| robot.get(*p)))
    }

    /// Sets the identified parameters from `x` (internal units).
    pub fn apply(&self, robot: &mut Robot, x: &DVector<f64>) {
        for (p, v) in self.params.iter().zip(x.iter()) {
            robot.set(*p, *v);
        }
    }

    /// The error vectors `e_i = pose(F) m_i - p(q_i)` (mm).
    pub fn errors(&self, robot: &Robot) -> Vec<Vector3<f64>> {
        (0..self.len())
            .map(|i| self.targets[i] - robot.tool_position(self.obs.q(i)))
            .collect()
    }

    /// The error norms `|e_i|` (mm).
    pub fn error_norms(&self, robot: &Robot) -> Vec<f64> {
        self.errors(robot).iter().map(|e| e.norm()).collect()
    }

    /// The objective `sum l(|e_i|)` (forward kinematics only).
    pub fn objective(&self, robot: &Robot, loss: &Loss) -> f64 {
        let f =
            |i: usize| loss.value((self.targets[i] - robot.tool_position(self.obs.q(i))).norm());
        if self.len() >= PARALLEL_MIN_POINTS {
            (0..self.len())
                .into_par_iter()
                .with_min_len(512)
                .map(f)
                .sum()
        } else {
            (0..self.len()).map(f).sum()
        }
    }

    /// One pass over the points: objective and IRLS normal equations, and what `level` adds.
    pub fn accumulate(&self, robot: &Robot, loss: &Loss, level: Level) -> Accumulated {
        let k = self.params.len();
        let np = robot.param_count();
        let acc = if self.len() >= PARALLEL_MIN_POINTS {
            (0..self.len())
                .into_par_iter()
                .with_min_len(512)
                .fold(
                    || Acc::new(k, np, level),
                    |mut acc, i| {
                        acc.add_point(self, robot, loss, i);
                        acc
                    },
                )
                .reduce(|| Acc::new(k, np, level), Acc::merge)
        } else {
            let mut acc = Acc::new(k, np, level);
            for i in 0..self.len() {
                acc.add_point(self, robot, loss, i);
            }
            acc
        };
        let a = symmetric(k, &acc.a);
        let s = (level == Level::Full).then(|| symmetric(k, &acc.s));
        let h = (level >= Level::Newton).then(|| &a + symmetric(k, &acc.h));
        Accumulated {
            objective: acc.objective,
            weighted_sq: acc.weighted_sq,
            b: DVector::from_vec(acc.b),
            a,
            s,
            h,
            psi_sq: acc.psi_sq,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;
    use crate::simulation::{random_poses, PoseSampler};
    use rand::SeedableRng;

    /// The normal-equation right-hand side is minus the objective's gradient: check it against
    /// central finite differences of the objective, for every loss.
    #[test]
    fn gradient_matches_finite_differences() {
        let truth = preset("kuka-kr480-r3330-table3").unwrap();
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let qs = random_poses(&truth, 30, &PoseSampler::default(), &mut rng).unwrap();
        let mut obs = Observations::new(6);
        for q in &qs {
            obs.push(q, truth.tool_position(q), 0).unwrap();
        }
        let params: Vec<Param> = nominal.params();
        let p = Problem::new(&nominal, &params, &obs, &Frame::identity());
        for loss in [
            Loss::SumOfNorms { delta: 1e-6 },
            Loss::Squared,
            Loss::Huber { k: 0.8 },
            Loss::Cauchy { c: 0.5 },
        ] {
            let acc = p.accumulate(&nominal, &loss, Level::Full);
            let x0 = p.values(&nominal);
            for (j, param) in params.iter().enumerate() {
                let h = if param.unit() == crate::model::Unit::Deg {
                    1e-7
                } else {
                    1e-5
                };
                let mut r = nominal.clone();
                let mut x = x0.clone();
                x[j] += h;
                p.apply(&mut r, &x);
                let fp = p.objective(&r, &loss);
                x[j] -= 2.0 * h;
                p.apply(&mut r, &x);
                let fm = p.objective(&r, &loss);
                let fd = (fp - fm) / (2.0 * h);
                let an = -acc.b[j];
                let scale = acc.a[(j, j)].sqrt() * acc.weighted_sq.sqrt() + 1e-12;
                assert!(
                    (fd - an).abs() <= 1e-6 * scale + 1e-9,
                    "{loss:?} {param}: fd {fd} vs analytic {an}"
                );
            }
            // The Hessian is symmetric positive semi-definite and never above A radially.
            let h = acc.h.unwrap();
            assert!((&h - h.transpose()).amax() <= 1e-9 * h.amax());
        }
    }
}
