//! The tool vectors of the targets beyond the first (`tool{j}_{axis}`, j = 2..k): a cell that
//! measures every pose through several reflectors identifies each reflector's offset on the
//! flange, and the robot once (DESIGN.md, `tools = [...]` and the `target` column). Target 1 is
//! the paper's tool ([`super::tool`]). A target's columns are zero at another target's point; its
//! orientation turns its frame about its point, which only a 6-DoF measurement sees.

use super::{priority, put, FamilyId, ParameterFamily, PoseFrames};
use crate::model::{Param, Robot, Unit};
use nalgebra::Vector3;

/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(4);

/// Component `k` (x, y, z, a, b, c) of target `t`'s tool correction (0-based target, `t >= 1`).
pub const fn param(t: usize, k: usize) -> Param {
    Param::new(ID, k as u8, t as u16)
}

/// The further targets' tool corrections.
pub struct Reflector;

impl ParameterFamily for Reflector {
    fn key(&self) -> &'static str {
        "reflector"
    }

    fn symbol(&self) -> &'static str {
        "Tk"
    }

    fn templates(&self) -> &'static [&'static str] {
        &[
            "tool{j}_x",
            "tool{j}_y",
            "tool{j}_z",
            "tool{j}_a",
            "tool{j}_b",
            "tool{j}_c",
        ]
    }

    fn unit(&self, p: Param) -> Unit {
        super::axis_unit(p.template())
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        // Model order is (template, index): every target's x, then every target's y, ...
        let k = robot.target_count();
        for c in 0..6 {
            out.extend((1..k).map(|t| param(t, c)));
        }
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot.target_tool_correction(p.index())[p.template()]
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        robot.set_target_correction(p.index(), p.template(), value);
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        if p.template() < 3 {
            priority::TOOL_POSITION + 10 * p.index() as u32 + p.template() as u32
        } else {
            priority::TOOL_ORIENTATION + 10 * p.index() as u32 + p.template() as u32
        }
    }

    #[inline]
    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let k = robot.target_count();
        let n = k - 1;
        for (c, v) in dp.iter_mut().enumerate() {
            *v = Vector3::zeros();
            put(&mut dw, c, Vector3::zeros());
        }
        let t = pose.target;
        if t == 0 || t >= k {
            return;
        }
        // Column of (component c, target t) is c * n + (t - 1) (model order above).
        let col = |c: usize| c * n + (t - 1);
        let rn = pose.flange.rotation.matrix();
        for e in 0..3 {
            dp[col(e)] = rn.column(e).into();
        }
        if dw.is_some() {
            for (e, ax) in robot.target_euler_axes(t).iter().enumerate() {
                put(&mut dw, col(3 + e), rn * ax);
            }
        }
    }
}
