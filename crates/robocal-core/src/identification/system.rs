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
//! on any number of threads (`chunked`).

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
    /// The group of each observation and the number of groups, when a pass also sums each
    /// group's share of the objective's Hessian and gradient ([`Accumulated::groups`]).
    groups: Option<(&'a [usize], usize)>,
    /// Whether a pass also keeps each observation's residual norm ([`Accumulated::norms`]).
    keep_norms: bool,
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
    /// For a `Problem::grouped` problem at [`Level::Newton`] and above: each group's share of
    /// the objective's Hessian `H` and of `b` (they sum to the whole's, up to rounding).
    pub groups: Option<Vec<(DMatrix<f64>, DVector<f64>)>>,
    /// For a problem `Problem::keeping_norms`: each observation's weighted residual norm at
    /// the pass's model (its [`Problem::fit_norms`], to rounding).
    pub norms: Option<Vec<f64>>,
}

impl Accumulated {
    /// This pass as it would have been over the parameters at positions `cols` of its own
    /// (ascending or not): the sums of each pair of columns do not depend on the others.
    pub(crate) fn restricted(&self, cols: &[usize]) -> Accumulated {
        let m = cols.len();
        let sub = |x: &DMatrix<f64>| DMatrix::from_fn(m, m, |r, c| x[(cols[r], cols[c])]);
        Accumulated {
            objective: self.objective,
            weighted_sq: self.weighted_sq,
            a: sub(&self.a),
            b: DVector::from_fn(m, |r, _| self.b[cols[r]]),
            s: self.s.as_ref().map(sub),
            h: self.h.as_ref().map(sub),
            psi_sq: self.psi_sq,
            rows: self.rows,
            groups: None,
            norms: None,
        }
    }
}

#[path = "system_acc.rs"]
mod acc;
pub(crate) use acc::add_gram;

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
            groups: None,
            keep_norms: false,
        }
    }

    /// This problem with its passes also keeping each observation's residual norm
    /// ([`Accumulated::norms`]: the pass's [`Problem::fit_norms`], not computed again).
    pub(crate) fn keeping_norms(mut self) -> Self {
        self.keep_norms = true;
        self
    }

    /// This problem with its observations in groups (`group[i]` of observation `i`, below
    /// `count`): its passes at [`Level::Newton`] and above then also give each group's share
    /// ([`Accumulated::groups`]), the cross-validation's folds for one pass over the data.
    pub(crate) fn grouped(mut self, group: &'a [usize], count: usize) -> Self {
        assert_eq!(group.len(), self.obs.len(), "a group per observation");
        assert!(group.iter().all(|&g| g < count), "groups below their count");
        self.groups = Some((group, count));
        self
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
                    robot.pose_frames_in_into(q, t, &self.obs.conditions(i), pose);
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

    /// The observations.
    pub(crate) fn observations(&self) -> &'a Observations {
        self.obs
    }

    /// This problem on `sub`, the observations `kept` of this problem's (ascending): the same
    /// parameters, kind and targets.
    pub(crate) fn restricted<'b>(&self, sub: &'b Observations, kept: &[usize]) -> Problem<'b> {
        let tl = self.kind.target_len();
        let mut targets = Vec::with_capacity(tl * kept.len());
        for &i in kept {
            targets.extend_from_slice(&self.targets[tl * i..tl * (i + 1)]);
        }
        Problem {
            params: self.params.clone(),
            index: self.index.clone(),
            obs: sub,
            kind: self.kind,
            targets,
            angular: self.angular,
            groups: None,
            keep_norms: self.keep_norms,
        }
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
            (None, robot.target_point_on(&f, t))
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
}

#[cfg(test)]
#[path = "system_tests.rs"]
mod tests;
