//! The tool points (and, for 6-DoF data, the tool orientations) fitted together with the
//! measurement frame to the nominal geometry, before identification: a user's nominal tool is a
//! guess (often zeros for a reflector nobody measured), and neither the identifiability
//! analysis nor the starting point of the identification should depend on it. With the frame F
//! and the flange poses `(o_i, R_i)` of the nominal chain, target k's point on the flange is
//! `t_k = mean R_i^T (F m_i - o_i)` over its observations, and F is the rigid fit of the measured
//! points to `o_i + R_i t_k`: the two least-squares steps alternate to convergence (each step
//! lowers the same sum of squares, so the alternation cannot diverge).

use super::rigid::fit_rigid;
use crate::error::Result;
use crate::frame::{self, Frame, TrackerFrame};
use crate::model::{Param, Robot};
use crate::observations::Observations;
use crate::stats::ErrorStats;
use nalgebra::{Matrix3, Vector3};

/// Most alternations of [`fit_tools`].
pub const MAX_ALTERNATIONS: usize = 2000;

/// Convergence of [`fit_tools`]: the largest change of a tool point in one alternation (mm).
pub const TOOL_TOLERANCE_MM: f64 = 1e-10;

/// The outcome of [`fit_tools`].
#[derive(Debug, Clone, PartialEq)]
pub struct ToolFit {
    /// The frame fitted with the tools.
    pub frame: TrackerFrame,
    /// Each target's fitted tool vector (mm, rad; the orientation is the nominal one unless the
    /// data are 6-DoF).
    pub tools: Vec<[f64; 6]>,
    /// Alternations run.
    pub iterations: usize,
    /// Whether the alternation converged to [`TOOL_TOLERANCE_MM`].
    pub converged: bool,
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
    let n = obs.len();
    let k = obs.target_count().max(1);
    let flanges: Vec<Frame> = (0..n).map(|i| robot.flange_pose(obs.q(i))).collect();
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
    let mut model = vec![Vector3::zeros(); n];
    let mut iterations = 0;
    let mut converged = false;
    while iterations < MAX_ALTERNATIONS {
        iterations += 1;
        let mut sum = vec![Vector3::zeros(); k];
        for (i, f) in flanges.iter().enumerate() {
            let b = frame.to_base(obs.m(i));
            sum[obs.target(i)] += f.rotation.inverse() * (b - f.translation.vector);
        }
        let mut change: f64 = 0.0;
        for t in 0..k {
            if count[t] > 0 {
                let new = sum[t] / count[t] as f64;
                change = change.max((new - tools[t]).norm());
                tools[t] = new;
            }
        }
        for (i, f) in flanges.iter().enumerate() {
            model[i] = f.rotation * tools[obs.target(i)] + f.translation.vector;
        }
        frame = fit_rigid(obs.measured(), &model, None)?;
        if change <= TOOL_TOLERANCE_MM {
            converged = true;
            break;
        }
    }
    // Orientations: for 6-DoF data, the rotation closest to the mean of R_i^T R_F R_meas,i.
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
    let residuals: Vec<f64> = (0..n)
        .map(|i| (frame.to_base(obs.m(i)) - model[i]).norm())
        .collect();
    let stats = ErrorStats::from_norms(&residuals);
    Ok(ToolFit {
        frame,
        tools: out,
        iterations,
        converged,
        residuals,
        stats,
    })
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
