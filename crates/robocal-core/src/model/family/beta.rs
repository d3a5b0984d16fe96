//! Hayati's tilts `beta{j}`: the rotation about the link's y axis that MDH lacks between
//! nominally parallel axes. A parameter only on the joints where it is enabled
//! ([`Robot::enable_beta`]).

use super::{priority, put, FamilyId, ParameterFamily, PoseFrames};
use crate::model::{Convention, Param, Robot, Unit};
use nalgebra::Vector3;

/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(1);

/// The tilt of joint `i`.
pub const fn param(i: usize) -> Param {
    Param::new(ID, 0, i as u16)
}

/// The Hayati-tilt family.
pub struct Beta;

impl ParameterFamily for Beta {
    fn key(&self) -> &'static str {
        "beta"
    }

    fn templates(&self) -> &'static [&'static str] {
        &["beta{j}"]
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::Deg
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        out.extend(
            (0..robot.dof())
                .filter(|&i| robot.beta_enabled(i))
                .map(param),
        );
    }

    fn enable(&self, robot: &mut Robot, p: Param) -> crate::error::Result<()> {
        if p.index() < robot.dof() && !robot.beta_enabled(p.index()) {
            robot.enable_beta(p.index())?;
        }
        Ok(())
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot.links[p.index()].beta
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        robot.links[p.index()].beta = value;
        robot.refresh_link(p.index());
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        priority::JOINT + priority::JOINT_STRIDE * p.index() as u32 + 2
    }

    #[inline]
    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let n = robot.dof();
        for (k, i) in (0..n).filter(|&i| robot.beta_enabled(i)).enumerate() {
            // Rotation about the y axis after Rx(alpha) Tx(a), through that frame's origin.
            let f = match robot.convention() {
                // M_i = F_{i-1} Rx Tx Ry: its y axis is unchanged by Ry; its origin is the pivot.
                Convention::Mdh => &pose.axis[i],
                // F_i = N Tx Rx Ry: likewise; F_i is the axis frame of joint i+1, or the flange
                // for the last joint.
                Convention::Dh if i + 1 < n => &pose.axis[i + 1],
                Convention::Dh => &pose.flange,
            };
            let y: Vector3<f64> = f.rotation.matrix().column(1).into();
            let (v, w) = pose.rotation_screw(y, f.translation.vector);
            dp[k] = v;
            put(&mut dw, k, w);
        }
    }
}
