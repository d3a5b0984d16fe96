//! The tool correction `tool_{axis}` (T, the paper's column T beside the nominal tool T0, eq. 7).
//! Its orientation turns the tool frame about the tool point: a point measurement cannot see it.

use super::{priority, put, FamilyId, ParameterFamily, PoseFrames};
use crate::model::{Param, Robot, Unit};
use nalgebra::Vector3;

/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(3);

/// Component `k` (x, y, z, a, b, c).
pub const fn param(k: usize) -> Param {
    Param::new(ID, 0, k as u16)
}

/// The tool-correction family.
pub struct Tool;

impl ParameterFamily for Tool {
    fn key(&self) -> &'static str {
        "tool"
    }

    fn symbol(&self) -> &'static str {
        "T"
    }

    fn templates(&self) -> &'static [&'static str] {
        &["tool_{axis}"]
    }

    fn unit(&self, p: Param) -> Unit {
        super::axis_unit(p.index())
    }

    fn params(&self, _robot: &Robot, out: &mut Vec<Param>) {
        out.extend((0..6).map(param));
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot.tool[p.index()]
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        robot.tool[p.index()] = value;
        robot.refresh_tool();
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        if p.index() < 3 {
            priority::TOOL_POSITION + p.index() as u32
        } else {
            priority::TOOL_ORIENTATION + p.index() as u32
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
        if pose.target != 0 {
            // Another target's point: this tool does not move it.
            for k in 0..6 {
                dp[k] = Vector3::zeros();
                put(&mut dw, k, Vector3::zeros());
            }
            return;
        }
        // Translations along the flange axes; the orientation turns the tool frame about the
        // tool point (the Euler axes of T0 + T, in the flange frame).
        let rn = pose.flange.rotation.matrix();
        for e in 0..3 {
            dp[e] = rn.column(e).into();
            put(&mut dw, e, Vector3::zeros());
            dp[3 + e] = Vector3::zeros();
        }
        if dw.is_some() {
            for (e, ax) in robot.target_euler_axes(0).iter().enumerate() {
                put(&mut dw, 3 + e, rn * ax);
            }
        }
    }
}
