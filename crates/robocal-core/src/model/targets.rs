//! Several targets on one flange (DESIGN.md, `tools = [...]`): a cell that measures each pose
//! through k reflectors (or a probe's several points) sees k tool points. Target 1 is the tool of
//! the paper (`T0 + T`, [`crate::model::family::tool`]); targets 2..k each have their own nominal
//! tool vector and correction (the [`crate::model::family::reflector`] family, `tool{j}_{axis}`),
//! and every other parameter is shared: the robot is identified once.

use super::Robot;
use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use nalgebra::Vector3;

/// A target beyond the first: its nominal tool vector, its correction, and the frame and Euler
/// axes kept from their sum.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TargetTool {
    pub nominal: [f64; 6],
    pub correction: [f64; 6],
    pub frame: Frame,
    /// The Euler axes of its angles ([`frame::euler_axes`]).
    pub axes: [Vector3<f64>; 3],
}

impl TargetTool {
    fn new(nominal: [f64; 6]) -> TargetTool {
        let mut t = TargetTool {
            nominal,
            correction: [0.0; 6],
            frame: Frame::identity(),
            axes: [Vector3::zeros(); 3],
        };
        t.refresh();
        t
    }

    pub(crate) fn refresh(&mut self) {
        let mut v = self.nominal;
        for (x, c) in v.iter_mut().zip(&self.correction) {
            *x += c;
        }
        self.frame = frame::pose(&v);
        self.axes = frame::euler_axes(v[3], v[4]);
    }
}

impl Robot {
    /// Number of targets (reflectors) the robot carries: 1 plus the further targets.
    pub fn target_count(&self) -> usize {
        1 + self.targets.len()
    }

    /// Sets the nominal tool vectors of every target (mm, rad; target 1 first, which becomes
    /// [`Robot::tool0`]). Corrections of targets that stay keep their values. Needs at least one
    /// vector of finite numbers.
    pub fn set_target_tools(&mut self, tools: &[[f64; 6]]) -> Result<()> {
        let Some((first, rest)) = tools.split_first() else {
            return Err(Error::invalid(
                "tools",
                "at least one tool vector is needed",
            ));
        };
        for (k, t) in tools.iter().enumerate() {
            if t.iter().any(|x| !x.is_finite()) {
                return Err(Error::invalid(
                    format!("tools[{}]", k + 1),
                    "not a finite number",
                ));
            }
        }
        self.tool0 = *first;
        self.refresh_tool();
        let old = std::mem::take(&mut self.targets);
        self.targets = rest
            .iter()
            .enumerate()
            .map(|(k, n)| {
                let mut t = TargetTool::new(*n);
                if let Some(o) = old.get(k) {
                    t.correction = o.correction;
                    t.refresh();
                }
                t
            })
            .collect();
        self.refresh_params();
        Ok(())
    }

    /// The nominal tool vector of target `t` (0-based; target 0 is [`Robot::tool0`]).
    /// Panics if the robot has no such target.
    pub fn target_tool0(&self, t: usize) -> &[f64; 6] {
        match t {
            0 => &self.tool0,
            _ => &self.targets[t - 1].nominal,
        }
    }

    /// The correction of target `t`'s tool vector (0-based; target 0's is
    /// [`Robot::tool_correction`]).
    pub fn target_tool_correction(&self, t: usize) -> &[f64; 6] {
        match t {
            0 => &self.tool,
            _ => &self.targets[t - 1].correction,
        }
    }

    /// Target `t`'s tool frame relative to the flange, `pose(T0_t + T_t)` (0-based).
    #[inline]
    pub fn target_tool_frame(&self, t: usize) -> &Frame {
        match t {
            0 => &self.tool_frame,
            _ => &self.targets[t - 1].frame,
        }
    }

    /// The Euler axes of target `t`'s tool angles (`T0_t + T_t`, 0-based), about which its
    /// angular corrections turn it ([`frame::euler_axes`]); kept with its frame.
    #[inline]
    pub(crate) fn target_euler_axes(&self, t: usize) -> &[Vector3<f64>; 3] {
        let axes = match t {
            0 => &self.tool_axes,
            _ => &self.targets[t - 1].axes,
        };
        // Every mutator of a tool refreshes them (`refresh_tool`, `TargetTool::refresh`); a
        // debug build checks.
        debug_assert!(
            {
                let (n, c) = (self.target_tool0(t), self.target_tool_correction(t));
                *axes == frame::euler_axes(n[3] + c[3], n[4] + c[4])
            },
            "target {t}'s kept Euler axes"
        );
        axes
    }

    /// Sets component `k` of the correction of target `t >= 1` (internal units).
    pub(crate) fn set_target_correction(&mut self, t: usize, k: usize, value: f64) {
        let tt = &mut self.targets[t - 1];
        tt.correction[k] = value;
        tt.refresh();
    }

    /// The nominal tool vectors of every target (target 1 first).
    pub fn target_tools0(&self) -> Vec<[f64; 6]> {
        (0..self.target_count())
            .map(|t| *self.target_tool0(t))
            .collect()
    }
}
