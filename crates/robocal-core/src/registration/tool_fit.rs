//! The tool points (and, for 6-DoF data, the tool orientations) fitted together with the
//! measurement frame to the nominal geometry, before identification: a user's nominal tool is a
//! guess (often zeros for a reflector nobody measured), and neither the identifiability
//! analysis nor the starting point of the identification should depend on it. With the frame F
//! and the flange poses `(o_i, R_i)` of the nominal chain, target k's point on the flange is
//! `t_k`, the frame and the points are fitted together: `sum |F m_i - (o_i + R_i t_k)|^2` is
//! minimized by Gauss-Newton over F's rotation and translation and every `t_k` (6 + 3k unknowns,
//! linear but for F's rotation, so a few iterations converge from the registration's frame).

use crate::error::Result;
use crate::frame::{self, Frame, TrackerFrame};
use crate::model::{Param, Robot};
use crate::observations::Observations;
use crate::stats::ErrorStats;
use nalgebra::{DMatrix, DVector, Matrix3, SMatrix, SVector, Vector3};

/// Most Gauss-Newton iterations of [`fit_tools`].
pub const MAX_ALTERNATIONS: usize = 50;

/// Convergence of [`fit_tools`]: the largest change of a tool point or of the frame's origin in
/// one iteration (mm).
pub const TOOL_TOLERANCE_MM: f64 = 1e-9;

/// The outcome of [`fit_tools`].
#[derive(Debug, Clone, PartialEq)]
pub struct ToolFit {
    /// The frame fitted with the tools.
    pub frame: TrackerFrame,
    /// Each target's fitted tool vector (mm, rad; the orientation is the nominal one unless the
    /// data are 6-DoF).
    pub tools: Vec<[f64; 6]>,
    /// Gauss-Newton iterations run.
    pub iterations: usize,
    /// Whether the iterations converged to [`TOOL_TOLERANCE_MM`].
    pub converged: bool,
    /// Whether the calibration started from the fitted tools (set by the caller: the
    /// calibration does when the fit converged and fits the data as a calibration's start can).
    pub applied: bool,
    /// Error norms of the nominal geometry with the fitted tools and frame (mm).
    pub residuals: Vec<f64>,
    /// Their statistics (Table II with the fitted tool).
    pub stats: ErrorStats,
}

impl ToolFit {
    /// `robot` with its tool corrections set so that every target's tool is the fitted one.
    pub fn apply(&self, robot: &Robot) -> Robot {
        let mut r = robot.clone();
        for (t, tool) in self.tools.iter().enumerate() {
            let t0 = robot.target_tool0(t);
            for k in 0..6 {
                let mut c = tool[k] - t0[k];
                if k >= 3 {
                    // The smallest angle with the same effect.
                    c = (c + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI;
                }
                let p = if t == 0 {
                    Param::tool(k)
                } else {
                    crate::model::family::reflector::param(t, k)
                };
                r.set(p, c);
            }
        }
        r
    }
}

/// Fits the frame and every target's tool point (see the module docs), starting from `start`.
/// `robot`'s geometry is held; its tool vectors give the starting orientations.
pub fn fit_tools(robot: &Robot, obs: &Observations, start: &TrackerFrame) -> Result<ToolFit> {
    fit_tools_from(robot, obs, start, nominal_flanges(robot, obs))
}

/// `robot`'s flange frame at every observation's joints: what [`fit_tools_from`] holds fixed.
pub(crate) fn nominal_flanges(robot: &Robot, obs: &Observations) -> Vec<Frame> {
    (0..obs.len())
        .map(|i| robot.flange_pose(obs.q(i)))
        .collect()
}

/// The tool points of `flanges`' observations whose conditions are all unknown (the model's
/// tool point at each, [`Observations::model_positions`], from the flange already computed);
/// `None` when some row has conditions (a thermal or backlash model's point depends on them).
pub(crate) fn tool_points(
    robot: &Robot,
    obs: &Observations,
    flanges: &[Frame],
) -> Option<Vec<Vector3<f64>>> {
    if (0..obs.len()).any(|i| !obs.conditions(i).is_unknown()) {
        return None;
    }
    Some(
        flanges
            .iter()
            .enumerate()
            .map(|(i, f)| robot.target_point_on(f, obs.target(i)))
            .collect(),
    )
}

/// [`fit_tools`] given the nominal flange frames ([`nominal_flanges`]).
pub(crate) fn fit_tools_from(
    robot: &Robot,
    obs: &Observations,
    start: &TrackerFrame,
    flanges: Vec<Frame>,
) -> Result<ToolFit> {
    let n = obs.len();
    let k = obs.target_count().max(1);
    let mut count = vec![0usize; k];
    for i in 0..n {
        count[obs.target(i)] += 1;
    }
    let mut frame = *start;
    let mut tools: Vec<Vector3<f64>> = (0..k)
        .map(|t| {
            if t < robot.target_count() {
                robot.target_tool_frame(t).translation.vector
            } else {
                Vector3::zeros()
            }
        })
        .collect();
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ALTERNATIONS {
        iterations += 1;
        let (a, b) = normal_equations(obs, &flanges, &frame, &tools, &count);
        let step =
            match a.cholesky() {
                Some(ch) => ch.solve(&(-&b)),
                None => return Err(crate::error::Error::Numerical(
                    "the tool points cannot be fitted: the poses do not turn the flange enough \
                     to tell the tools from the tracker frame"
                        .into(),
                )),
            };
        if take_step(&step, &mut frame, &mut tools, &count) <= TOOL_TOLERANCE_MM {
            converged = true;
            break;
        }
    }
    let model: Vec<Vector3<f64>> = flanges
        .iter()
        .enumerate()
        .map(|(i, f)| f.rotation * tools[obs.target(i)] + f.translation.vector)
        .collect();
    let out = tool_vectors(robot, obs, &flanges, &frame, &tools, &count);
    let residuals: Vec<f64> = (0..n)
        .map(|i| (frame.to_base(obs.m(i)) - model[i]).norm())
        .collect();
    let stats = ErrorStats::from_norms(&residuals);
    Ok(ToolFit {
        frame,
        tools: out,
        iterations,
        converged,
        applied: false,
        residuals,
        stats,
    })
}

/// The normal equations of one Gauss-Newton step on the frame (rotation, then translation) and
/// the tools (three unknowns each): r_i = F m_i - (o_i + R_i t_k); d r / d(rotation of F) =
/// -[F m_i - t_F]x, d r / d t_F = I, d r / d t_k = -R_i. A target no observation measures
/// (`count` 0) keeps its tool.
fn normal_equations(
    obs: &Observations,
    flanges: &[Frame],
    frame: &TrackerFrame,
    tools: &[Vector3<f64>],
    count: &[usize],
) -> (DMatrix<f64>, DVector<f64>) {
    let k = tools.len();
    let np = 6 + 3 * k;
    // The normal equations by blocks, each summed over its points in point order (the frame's
    // block over every point, a target's blocks over its own): the sums a dense matrix indexed
    // per entry would hold, without the indexing.
    let mut frame_block = SMatrix::<f64, 6, 6>::zeros();
    let mut frame_b = SVector::<f64, 6>::zeros();
    let mut cross = vec![SMatrix::<f64, 6, 3>::zeros(); k];
    let mut tool_block = vec![Matrix3::<f64>::zeros(); k];
    let mut tool_b = vec![Vector3::<f64>::zeros(); k];
    let tf = frame.origin();
    for (i, f) in flanges.iter().enumerate() {
        let t = obs.target(i);
        let p = frame.to_base(obs.m(i));
        let r = p - (f.translation.vector + f.rotation * tools[t]);
        let mut j = nalgebra::SMatrix::<f64, 3, 9>::zeros();
        j.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(-(p - tf).cross_matrix()));
        j.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&Matrix3::identity());
        j.fixed_view_mut::<3, 3>(0, 6)
            .copy_from(&(-f.rotation.matrix()));
        let jtj = j.transpose() * j;
        let jtr = j.transpose() * r;
        frame_block += jtj.fixed_view::<6, 6>(0, 0);
        frame_b += jtr.fixed_rows::<6>(0);
        cross[t] += jtj.fixed_view::<6, 3>(0, 6);
        tool_block[t] += jtj.fixed_view::<3, 3>(6, 6);
        tool_b[t] += jtr.fixed_rows::<3>(6);
    }
    // `J^T J` is symmetric to the bit (each entry's products are the same, summed in the same
    // order), so the block below the frame's is the transpose of the one beside it.
    let mut a = DMatrix::<f64>::zeros(np, np);
    let mut b = DVector::<f64>::zeros(np);
    a.fixed_view_mut::<6, 6>(0, 0).copy_from(&frame_block);
    b.fixed_rows_mut::<6>(0).copy_from(&frame_b);
    for t in 0..k {
        let o = 6 + 3 * t;
        a.fixed_view_mut::<6, 3>(0, o).copy_from(&cross[t]);
        a.fixed_view_mut::<3, 6>(o, 0)
            .copy_from(&cross[t].transpose());
        a.fixed_view_mut::<3, 3>(o, o).copy_from(&tool_block[t]);
        b.fixed_rows_mut::<3>(o).copy_from(&tool_b[t]);
    }
    for (t, c) in count.iter().enumerate() {
        if *c == 0 {
            for x in 0..3 {
                a[(6 + 3 * t + x, 6 + 3 * t + x)] = 1.0;
            }
        }
    }
    (a, b)
}

/// Moves the frame and the measured targets' tools by `step`; returns the largest change (mm;
/// a rotation as the motion it causes 1 m away).
fn take_step(
    step: &DVector<f64>,
    frame: &mut TrackerFrame,
    tools: &mut [Vector3<f64>],
    count: &[usize],
) -> f64 {
    let tf = frame.origin();
    let rot = nalgebra::Rotation3::new(Vector3::new(step[0], step[1], step[2]));
    let origin = tf + Vector3::new(step[3], step[4], step[5]);
    let pose = frame.pose();
    let new_rot = rot * pose.rotation;
    // The origin moves by the step; the rotation turns about it.
    *frame = TrackerFrame::new(frame::frame(
        *new_rot.matrix(),
        origin + rot * (pose.translation.vector - tf),
    ));
    let mut change = Vector3::new(step[3], step[4], step[5]).norm();
    for (t, tool) in tools.iter_mut().enumerate() {
        let d = Vector3::new(step[6 + 3 * t], step[7 + 3 * t], step[8 + 3 * t]);
        if count[t] > 0 {
            *tool += d;
        }
        change = change.max(d.norm());
    }
    change.max(1e3 * rot.angle())
}

/// Each target's tool as a frame vector: the fitted point, with the robot's orientation, or for
/// 6-DoF data the rotation closest to the mean of R_i^T R_F R_meas,i.
fn tool_vectors(
    robot: &Robot,
    obs: &Observations,
    flanges: &[Frame],
    frame: &TrackerFrame,
    tools: &[Vector3<f64>],
    count: &[usize],
) -> Vec<[f64; 6]> {
    let k = tools.len();
    let mut out: Vec<[f64; 6]> = (0..k)
        .map(|t| {
            let mut v = if t < robot.target_count() {
                let mut v = *robot.target_tool0(t);
                let c = robot.target_tool_correction(t);
                for (x, y) in v.iter_mut().zip(c) {
                    *x += y;
                }
                v
            } else {
                [0.0; 6]
            };
            v[..3].copy_from_slice(tools[t].as_slice());
            v
        })
        .collect();
    if obs.has_orientation() {
        let rf = frame.pose().rotation.matrix();
        let mut sum = vec![Matrix3::zeros(); k];
        for (i, f) in flanges.iter().enumerate() {
            if let Some(rm) = obs.rotation(i) {
                sum[obs.target(i)] += f.rotation.matrix().transpose() * rf * rm;
            }
        }
        for t in 0..k {
            if count[t] > 0 {
                let r = nearest_rotation(&sum[t]);
                let v = frame::frame_vector(&frame::frame(r, tools[t]));
                out[t][3..].copy_from_slice(&v[3..]);
            }
        }
    }
    out
}

/// The rotation nearest to `m` (polar decomposition by SVD, determinant +1).
fn nearest_rotation(m: &Matrix3<f64>) -> Matrix3<f64> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u.expect("u"), svd.v_t.expect("v_t"));
    let mut d = Matrix3::identity();
    if (u * vt).determinant() < 0.0 {
        d[(2, 2)] = -1.0;
    }
    u * d * vt
}
