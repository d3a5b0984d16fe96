//! The identification problem's hot loop: residuals, IRLS normal equations and the curvature
//! terms the covariance needs, accumulated observation by observation.
//!
//! For observation i the measurement kind ([`kinds`]) gives its residual rows `e_i` (for a point,
//! `e_i = pose(F) m_i - p(q_i; theta)`, eq. 3 with the measured point mapped into the ACS) and,
//! from the parameter families' screws at the tool, the Jacobian rows `J_i` of the model with
//! respect to the identified parameters. With the loss weight `w_i` of `|e_i|` (see [`Loss`]),
//! the solver needs `A = sum w_i J_i^T J_i` and `b = sum w_i J_i^T e_i`. They are accumulated
//! per observation (k x k and k numbers; the stacked Jacobian is never formed) with per-thread
//! buffers allocated once per pass, so the per-observation work allocates nothing. Passes run in
//! fixed chunks, on several threads from a few hundred observations, with the same result bits
//! on any number of threads ([`chunked`]).

use crate::frame::TrackerFrame;
use crate::identification::kinds::{self, MeasurementKind, ToolState};
use crate::identification::objective::Loss;
use crate::identification::Observations;
use crate::model::family::PoseFrames;
use crate::model::{Param, Robot, MAX_JOINTS};
use nalgebra::{DMatrix, DVector, Vector3};
use rayon::prelude::*;

/// Largest number of model parameters (all of `alpha, d, a, phi, beta` for [`MAX_JOINTS`] joints
/// plus base and tool).
pub const MAX_PARAMS: usize = 5 * MAX_JOINTS + 12;

/// Observations per chunk of a pass: each chunk is summed on its own and the chunks' sums are
/// added in order, so a pass gives the same bits on any number of threads.
const CHUNK: usize = 256;

/// From this many observations the chunks of a pass run on several threads.
const PARALLEL_MIN_POINTS: usize = 2 * CHUNK;

/// One pass over observations `0..n`: `add` each into its chunk's state (from `new`), the
/// chunks in parallel from [`PARALLEL_MIN_POINTS`] on, then `merge` the chunks' states in order.
/// Deterministic: the grouping depends on `n` only, never on the threads (rayon's own `fold`
/// splits by work stealing, so its sums would differ in the last bits from run to run).
pub(crate) fn chunked<T: Send>(
    n: usize,
    new: impl Fn() -> T + Sync,
    add: impl Fn(&mut T, usize) + Sync,
    merge: impl Fn(T, T) -> T,
) -> T {
    // Each chunk runs with AVX where the processor has it (same bits, see `simd`).
    let chunk = |c: usize| {
        crate::identification::simd::with_avx(
            #[inline(always)]
            || {
                let mut t = new();
                for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                    add(&mut t, i);
                }
                t
            },
        )
    };
    let chunks = n.div_ceil(CHUNK);
    if n >= PARALLEL_MIN_POINTS {
        let parts: Vec<T> = (0..chunks).into_par_iter().map(chunk).collect();
        parts.into_iter().reduce(merge).unwrap_or_else(new)
    } else {
        (0..chunks).map(chunk).reduce(merge).unwrap_or_else(new)
    }
}

/// The identification problem: which parameters are unknown, the measurement kind and the
/// observations' measured values in the ACS.
#[derive(Clone)]
pub struct Problem<'a> {
    params: Vec<Param>,
    /// Position of each identified parameter in `robot.params()`.
    index: Vec<usize>,
    obs: &'a Observations,
    kind: &'static dyn MeasurementKind,
    /// The kind's targets, `target_len` numbers per observation (for points, `pose(F) m_i`).
    targets: Vec<f64>,
    /// Whether the kind needs the tool frame's angular screws and rotation.
    angular: bool,
}

impl std::fmt::Debug for Problem<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Problem")
            .field("params", &self.params)
            .field("kind", &self.kind.key())
            .field("observations", &self.obs.len())
            .finish()
    }
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
    /// The number of residual rows summed over (rows per observation times observations).
    pub rows: usize,
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
    /// Parameter screws at the tool: linear and (when the kind sees orientation) angular parts.
    jp: Vec<Vector3<f64>>,
    jw: Vec<Vector3<f64>>,
    /// The observation's Jacobian rows, row-major (rows x k).
    jr: Vec<f64>,
    u: Vec<f64>,
    /// The last observation's forward pass, reused by the next when it is the same pose seen
    /// through another target.
    frames: Option<(usize, Box<PoseFrames>)>,
}

impl Acc {
    fn new(k: usize, rows: usize, n_params: usize, angular: bool, level: Level) -> Acc {
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

    /// Adds observation `i`: its (weighted) residual rows and Jacobian rows
    /// ([`Problem::observation_rows`]), then `w J^T J`, `w J^T e` (upper triangles) and what the
    /// level adds.
    #[inline(always)]
    fn add_observation(&mut self, p: &Problem, robot: &Robot, loss: &Loss, i: usize) {
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
            self.accumulate(3, &e[..3], loss);
        } else {
            self.accumulate(rows, &e[..rows], loss);
        }
    }

    /// The accumulation of one observation's rows (`self.jr`, `rows x k`) and residual `e`.
    #[inline(always)]
    fn accumulate(&mut self, rows: usize, e: &[f64], loss: &Loss) {
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
    /// The problem of identifying `params` of `robot` from `obs` (of the observations' own
    /// measurement kind), whose measured values map into the ACS by the tracker frame `frame`.
    /// Panics if a parameter is not one of the robot's (the callers take them from
    /// `robot.params()`).
    pub fn new(
        robot: &Robot,
        params: &[Param],
        obs: &'a Observations,
        frame: &TrackerFrame,
    ) -> Self {
        let kind = obs.kind();
        let index = params
            .iter()
            .map(|p| robot.param_position(*p).expect("parameter of the robot"))
            .collect();
        let tl = kind.target_len();
        let mut targets = vec![0.0; tl * obs.len()];
        for (i, t) in targets.chunks_exact_mut(tl.max(1)).enumerate() {
            kind.target(obs, i, frame, t);
        }
        Problem {
            params: params.to_vec(),
            index,
            obs,
            kind,
            targets,
            angular: kind.measurability().orientation,
        }
    }

    /// Observation `i`'s residual rows `e` (measured minus model) and the model's Jacobian rows
    /// `jr` (row-major, `rows x params`), each row weighted as the fit weights it
    /// ([`Observations::weight`], orientation rows also by [`Observations::mm_per_rad`]). `jp`
    /// (and `jw` when the kind sees orientation) are scratch of `robot.param_count()` screws.
    #[cfg(test)]
    pub(crate) fn observation_rows(
        &self,
        robot: &Robot,
        i: usize,
        jp: &mut [Vector3<f64>],
        jw: Option<&mut [Vector3<f64>]>,
        e: &mut [f64],
        jr: &mut [f64],
    ) {
        self.observation_rows_cached(robot, i, &mut None, jp, jw, e, jr)
    }

    /// [`Problem::observation_rows`] reusing the forward pass in `frames` (observation index
    /// and pass) when observation `i` is the same pose, and leaving its own there.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn observation_rows_cached(
        &self,
        robot: &Robot,
        i: usize,
        frames: &mut Option<(usize, Box<PoseFrames>)>,
        jp: &mut [Vector3<f64>],
        mut jw: Option<&mut [Vector3<f64>]>,
        e: &mut [f64],
        jr: &mut [f64],
    ) {
        let rows = self.kind.rows();
        let t = self.obs.target(i);
        let q = self.obs.q(i);
        let (point, flange) = if robot.target_count() == 1 {
            // One target: nothing to share (and the pass is not worth copying).
            robot.target_screws_in(
                q,
                t,
                &self.obs.conditions(i),
                None,
                Some(&mut *jp),
                jw.as_deref_mut(),
            )
        } else {
            match frames {
                Some((j, pose))
                    if self.obs.q(*j) == q
                        && self.obs.conditions(*j).same(&self.obs.conditions(i)) =>
                {
                    robot.retarget(pose, t);
                    *j = i;
                }
                Some((j, pose)) => {
                    **pose = robot.pose_frames_in(q, t, &self.obs.conditions(i));
                    *j = i;
                }
                None => {
                    *frames = Some((
                        i,
                        Box::new(robot.pose_frames_in(q, t, &self.obs.conditions(i))),
                    ))
                }
            }
            let pose = &frames.as_ref().expect("set above").1;
            let out = robot.screws_at(pose, None, Some(&mut *jp), jw.as_deref_mut());
            robot.scale_grown_columns(&self.obs.conditions(i), jp);
            out
        };
        let tool = self.tool_state(robot, t, point, &flange);
        let target = self.target(i);
        self.kind.residual(target, &tool, &mut e[..rows]);
        self.kind
            .jacobian_rows(target, &tool, jp, jw.as_deref(), &self.index, jr);
        self.weigh(i, &mut e[..rows], &mut jr[..rows * self.index.len()]);
    }

    /// Observation `i`'s weighted Jacobian rows linearized at zero residual (the kind's
    /// [`MeasurementKind::model_target`]), as the identifiability analysis needs them; `jw` must
    /// be given (its screws are also returned there).
    pub(crate) fn model_rows(
        &self,
        robot: &Robot,
        i: usize,
        jp: &mut [Vector3<f64>],
        jw: &mut [Vector3<f64>],
        jr: &mut [f64],
    ) {
        let rows = self.kind.rows();
        let t = self.obs.target(i);
        let (point, flange) = robot.target_screws_in(
            self.obs.q(i),
            t,
            &self.obs.conditions(i),
            None,
            Some(&mut *jp),
            Some(&mut *jw),
        );
        let rotation =
            Some(flange.rotation.matrix() * robot.target_tool_frame(t).rotation.matrix());
        let tool = ToolState { point, rotation };
        let mut target = [0.0; 2 * kinds::MAX_ROWS];
        let target = &mut target[..self.kind.target_len()];
        self.kind.model_target(&tool, target);
        self.kind
            .jacobian_rows(target, &tool, jp, Some(jw), &self.index, jr);
        let mut e = [0.0; kinds::MAX_ROWS];
        self.weigh(i, &mut e[..rows], &mut jr[..rows * self.index.len()]);
    }

    /// Applies observation `i`'s row weights to its residual and Jacobian rows.
    #[inline]
    fn weigh(&self, i: usize, e: &mut [f64], jr: &mut [f64]) {
        let w = self.obs.weight(i);
        let rows = e.len();
        let ang = self.kind.orientation_rows();
        if w == 1.0 && ang == 0 {
            return;
        }
        let k = self.index.len();
        for r in 0..rows {
            let wr = if r >= rows - ang {
                w * self.obs.mm_per_rad()
            } else {
                w
            };
            e[r] *= wr;
            if let Some(row) = jr.get_mut(r * k..(r + 1) * k) {
                for v in row {
                    *v *= wr;
                }
            }
        }
    }

    /// The identified parameters.
    pub fn params(&self) -> &[Param] {
        &self.params
    }

    /// The measurement kind.
    pub fn kind(&self) -> &'static dyn MeasurementKind {
        self.kind
    }

    /// Number of observations.
    pub fn len(&self) -> usize {
        self.obs.len()
    }

    /// Whether there are no observations.
    pub fn is_empty(&self) -> bool {
        self.obs.is_empty()
    }

    /// Number of residual rows (rows per observation times observations).
    pub fn rows(&self) -> usize {
        self.kind.rows() * self.len()
    }

    fn target(&self, i: usize) -> &[f64] {
        let tl = self.kind.target_len();
        &self.targets[i * tl..(i + 1) * tl]
    }

    /// The model's tool for target `t`, given its point and the flange frame.
    #[inline]
    fn tool_state(
        &self,
        robot: &Robot,
        t: usize,
        point: Vector3<f64>,
        flange: &crate::frame::Frame,
    ) -> ToolState {
        let rotation = self
            .angular
            .then(|| flange.rotation.matrix() * robot.target_tool_frame(t).rotation.matrix());
        ToolState { point, rotation }
    }

    /// Observation i's unweighted residual rows (forward kinematics only), written to `e`.
    fn residual(&self, robot: &Robot, i: usize, e: &mut [f64]) {
        self.residual_cached(robot, i, &mut None, e)
    }

    /// [`Problem::residual`] reusing the flange frame in `flange` (observation index and
    /// frame) when observation `i` is the same pose (another target), and leaving its own there.
    fn residual_cached(
        &self,
        robot: &Robot,
        i: usize,
        flange: &mut Option<(usize, crate::frame::Frame)>,
        e: &mut [f64],
    ) {
        let t = self.obs.target(i);
        let q = self.obs.q(i);
        let c = self.obs.conditions(i);
        let f = match flange {
            Some((j, f)) if self.obs.q(*j) == q && self.obs.conditions(*j).same(&c) => {
                *j = i;
                *f
            }
            _ => {
                // The row's temperature and approach directions, for models that read them.
                let f = if c.is_unknown() {
                    robot.flange_pose(q)
                } else {
                    robot.pose_frames_in(q, t, &c).flange
                };
                *flange = Some((i, f));
                f
            }
        };
        let (tool, point) = if self.angular {
            let f = f * robot.target_tool_frame(t);
            (Some(*f.rotation.matrix()), f.translation.vector)
        } else {
            (
                None,
                f.rotation * robot.target_tool_frame(t).translation.vector + f.translation.vector,
            )
        };
        let tool = ToolState {
            point,
            rotation: tool,
        };
        self.kind.residual(self.target(i), &tool, e);
    }

    /// Observation i's residual norm as the fit sees it (weighted; forward kinematics only).
    fn fit_norm(
        &self,
        robot: &Robot,
        i: usize,
        flange: &mut Option<(usize, crate::frame::Frame)>,
    ) -> f64 {
        let rows = self.kind.rows();
        let mut e = [0.0; kinds::MAX_ROWS];
        self.residual_cached(robot, i, flange, &mut e[..rows]);
        self.weigh(i, &mut e[..rows], &mut []);
        e[..rows].iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// Observation i's position error `|E_i|` (mm, eq. 3; unweighted).
    fn position_error(&self, robot: &Robot, i: usize) -> f64 {
        let rows = self.kind.rows();
        let mut e = [0.0; kinds::MAX_ROWS];
        self.residual(robot, i, &mut e[..rows]);
        let pos = rows - self.kind.orientation_rows();
        e[..pos].iter().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// Observation i's orientation error (deg), for kinds that see orientation.
    fn orientation_error_deg(&self, robot: &Robot, i: usize) -> Option<f64> {
        let ang = self.kind.orientation_rows();
        if ang == 0 {
            return None;
        }
        let rows = self.kind.rows();
        let mut e = [0.0; kinds::MAX_ROWS];
        self.residual(robot, i, &mut e[..rows]);
        Some(
            e[rows - ang..rows]
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .sqrt()
                .to_degrees(),
        )
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

    /// The position errors `|E_i|` (mm, eq. 3), one per observation: what tables report.
    pub fn error_norms(&self, robot: &Robot) -> Vec<f64> {
        (0..self.len())
            .map(|i| self.position_error(robot, i))
            .collect()
    }

    /// The orientation errors (deg), one per observation, for kinds that see orientation.
    pub fn orientation_errors_deg(&self, robot: &Robot) -> Option<Vec<f64>> {
        (self.kind.orientation_rows() > 0).then(|| {
            (0..self.len())
                .map(|i| self.orientation_error_deg(robot, i).unwrap_or(f64::NAN))
                .collect()
        })
    }

    /// The residual norms the loss sees (weighted, see [`Observations::weight`]; mm of a
    /// typical point), one per observation.
    pub fn fit_norms(&self, robot: &Robot) -> Vec<f64> {
        let mut flange = None;
        (0..self.len())
            .map(|i| self.fit_norm(robot, i, &mut flange))
            .collect()
    }

    /// The objective `sum l(|e_i|)` (forward kinematics only).
    pub fn objective(&self, robot: &Robot, loss: &Loss) -> f64 {
        chunked(
            self.len(),
            || (0.0, None),
            |(sum, flange), i| *sum += loss.value(self.fit_norm(robot, i, flange)),
            |a, b| (a.0 + b.0, None),
        )
        .0
    }

    /// One pass over the observations: objective and IRLS normal equations, and what `level`
    /// adds.
    pub fn accumulate(&self, robot: &Robot, loss: &Loss, level: Level) -> Accumulated {
        let k = self.params.len();
        let np = robot.param_count();
        let rows = self.kind.rows();
        let angular = self.angular;
        let acc = chunked(
            self.len(),
            || Acc::new(k, rows, np, angular, level),
            #[inline(always)]
            |acc, i| acc.add_observation(self, robot, loss, i),
            Acc::merge,
        );
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
        let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
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

    fn kr480_problem_data(n: usize, noise_mm: f64) -> (Robot, Observations) {
        use rand_distr::{Distribution, Normal};
        let truth = preset("kuka-kr480-r3330-table3").unwrap();
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let qs = random_poses(&truth, n, &PoseSampler::default(), &mut rng).unwrap();
        let noise = Normal::new(0.0, noise_mm).unwrap();
        let mut obs = Observations::new(6);
        for q in &qs {
            let p = truth.tool_position(q);
            let m = p + Vector3::from_fn(|_, _| noise.sample(&mut rng));
            obs.push(q, m, 0).unwrap();
        }
        (nominal, obs)
    }

    /// `S` (the full pass's unweighted Gram matrix, accumulated as `A` plus the down-weighted
    /// points' share) equals `sum J^T J` formed directly, with a loss that leaves some points at
    /// full weight and down-weights the others.
    #[test]
    fn full_pass_gram_matrix_is_the_unweighted_sum() {
        let (nominal, obs) = kr480_problem_data(200, 0.0);
        let params = nominal.params();
        let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
        let norms = p.fit_norms(&nominal);
        let mut sorted = norms.clone();
        sorted.sort_by(f64::total_cmp);
        let loss = Loss::Huber {
            k: sorted[sorted.len() / 2],
        };
        let full_weight = norms.iter().filter(|&&r| loss.weight(r) == 1.0).count();
        assert!(full_weight > 50 && full_weight < 150, "{full_weight}");
        let acc = p.accumulate(&nominal, &loss, Level::Full);
        let k = params.len();
        let (mut jp, mut jr) = (
            vec![Vector3::zeros(); nominal.param_count()],
            vec![0.0; 3 * k],
        );
        let mut want = DMatrix::<f64>::zeros(k, k);
        for i in 0..obs.len() {
            let mut e = [0.0; 3];
            p.observation_rows(&nominal, i, &mut jp, None, &mut e, &mut jr);
            let j = DMatrix::from_row_slice(3, k, &jr);
            want += j.transpose() * j;
        }
        let s = acc.s.unwrap();
        assert!(
            (&s - &want).amax() <= 1e-10 * want.amax(),
            "{}",
            (&s - &want).amax()
        );
    }

    /// A pass gives the same bits on one thread and on four.
    #[test]
    fn passes_are_deterministic_across_thread_counts() {
        let (nominal, obs) = kr480_problem_data(3 * CHUNK + 17, 0.05);
        let params = nominal.params();
        let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| {
                let acc = p.accumulate(&nominal, &Loss::SumOfNorms { delta: 1e-6 }, Level::Full);
                let f = p.objective(&nominal, &Loss::Squared);
                (
                    acc.a,
                    acc.b,
                    acc.s.unwrap(),
                    acc.h.unwrap(),
                    acc.objective,
                    f,
                )
            })
        };
        let one = run(1);
        for _ in 0..3 {
            let four = run(4);
            assert!(one.0 == four.0 && one.1 == four.1 && one.2 == four.2 && one.3 == four.3);
            assert_eq!(one.4.to_bits(), four.4.to_bits());
            assert_eq!(one.5.to_bits(), four.5.to_bits());
        }
    }

    /// A pass gives the same bits with AVX as with the baseline instructions (on a processor
    /// without AVX both runs are the baseline). Fewer points than a parallel pass takes, so the
    /// chunks run on this thread, where the baseline is forced.
    #[test]
    fn passes_give_the_same_bits_with_and_without_avx() {
        let (nominal, obs) = kr480_problem_data(CHUNK + 45, 0.05);
        let params = nominal.params();
        let p = Problem::new(&nominal, &params, &obs, &TrackerFrame::identity());
        for loss in [
            Loss::SumOfNorms { delta: 1e-6 },
            Loss::Cauchy { c: 0.05 },
            Loss::Squared,
        ] {
            let run = |baseline: bool| {
                crate::identification::simd::force_baseline(baseline);
                let acc = p.accumulate(&nominal, &loss, Level::Full);
                let f = p.objective(&nominal, &loss);
                crate::identification::simd::force_baseline(false);
                (acc, f)
            };
            let (wide, fw) = run(false);
            let (base, fb) = run(true);
            assert!(wide.a == base.a && wide.b == base.b, "{loss:?}");
            assert!(wide.s == base.s && wide.h == base.h, "{loss:?}");
            assert_eq!(wide.objective.to_bits(), base.objective.to_bits());
            assert_eq!(fw.to_bits(), fb.to_bits());
        }
    }
}
