//! The base frame vector `base_{axis}` (B, paper eq. 7): the pose of the robot's base in the ACS.

use super::{priority, put, FamilyId, ParameterFamily, PoseFrames};
use crate::model::{Param, Robot, Unit};
use nalgebra::Vector3;

/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(2);

/// Component `k` (x, y, z, a, b, c).
pub const fn param(k: usize) -> Param {
    Param::new(ID, 0, k as u16)
}

/// The base-frame family.
pub struct Base;

impl ParameterFamily for Base {
    fn key(&self) -> &'static str {
        "base"
    }

    fn symbol(&self) -> &'static str {
        "B"
    }

    fn templates(&self) -> &'static [&'static str] {
        &["base_{axis}"]
    }

    fn unit(&self, p: Param) -> Unit {
        super::axis_unit(p.index())
    }

    fn params(&self, _robot: &Robot, out: &mut Vec<Param>) {
        out.extend((0..6).map(param));
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot.base[p.index()]
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        robot.base[p.index()] = value;
        robot.refresh_base();
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        priority::BASE + p.index() as u32
    }

    #[inline]
    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        // Translations along the ACS axes, rotations about the Euler axes through b.
        let b = robot.base();
        for e in 0..3 {
            dp[e] = Vector3::ith(e, 1.0);
            put(&mut dw, e, Vector3::zeros());
        }
        let o = Vector3::new(b[0], b[1], b[2]);

        for (e, ax) in robot.base_euler_axes().iter().enumerate() {
            let (v, w) = pose.rotation_screw(*ax, o);
            dp[3 + e] = v;
            put(&mut dw, 3 + e, w);
        }
    }
}
