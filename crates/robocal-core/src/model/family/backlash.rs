//! Backlash: each modelled joint stops short of its commanded value by half its gear play, on
//! the side it came from:
//!
//! ```text
//! dq_j = -backlash{j} * dir_j          (backlash{j} in deg, dir_j = +1 or -1)
//! ```
//!
//! `dir_j` is the row's approach direction (`dir1..dirN`, or derived from the row order; see
//! [`crate::model::Conditions`]); a row whose direction is unknown (0) is taken at the
//! middle of the play. With every row approached from the same side the column equals the
//! joint's offset `phi` and the identifiability analysis fixes the parameter.

use super::{put, FamilyId, ParameterFamily, PoseFrames, RigidPose};
use crate::error::{Error, Result};
use crate::model::{JointType, Param, Robot, Unit};
use nalgebra::Vector3;

/// The family's key in the robot's family store.
pub const KEY: &str = "backlash";
/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(7);

/// The largest plausible half play (deg): a tenth of a degree on one side is a worn-out gear,
/// six times the lost motion of a robot's reducer.
pub const MAX_HALF_PLAY_DEG: f64 = 0.1;

// Store layout: [enabled flag per joint, then half play per joint (rad)].

/// The backlash family (see the module docs).
pub struct Backlash;

fn each_param(robot: &Robot, mut f: impl FnMut(Param, usize)) {
    let Some(v) = robot.family_values(KEY) else {
        return;
    };
    for i in (0..robot.dof()).filter(|&i| v[i] == 1.0) {
        f(Param::new(ID, 0, i as u16), i);
    }
}

impl ParameterFamily for Backlash {
    fn key(&self) -> &'static str {
        KEY
    }

    fn templates(&self) -> &'static [&'static str] {
        &["backlash{j}"]
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::Deg
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        each_param(robot, |p, _| out.push(p));
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot
            .family_values(KEY)
            .map_or(0.0, |v| v[robot.dof() + p.index()])
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        let k = robot.dof() + p.index();
        if let Some(v) = robot.family_values_mut(KEY) {
            v[k] = value;
        }
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        super::priority::NON_GEOMETRIC + 60_000 + p.index() as u32
    }

    /// At most [`MAX_HALF_PLAY_DEG`] either way (a negative value: the directions are the other
    /// way round, or the joint is pushed past its command, e.g. by gravity).
    fn plausible(&self, _robot: &Robot, _p: Param) -> super::plausible::Plausible {
        super::plausible::Plausible {
            min: -MAX_HALF_PLAY_DEG,
            max: MAX_HALF_PLAY_DEG,
            ..super::plausible::Plausible::moving(
                MAX_HALF_PLAY_DEG,
                "0.1 degree, six times a reducer's lost motion",
            )
        }
    }

    fn enable(&self, robot: &mut Robot, p: Param) -> Result<()> {
        let i = p.index();
        if i >= robot.dof() || robot.joint_type(i) != JointType::Revolute {
            return Ok(());
        }
        let n = robot.dof();
        let mut v = robot
            .family_values(KEY)
            .map_or_else(|| vec![0.0; 2 * n], <[f64]>::to_vec);
        v[i] = 1.0;
        robot.set_family_values(KEY, Some(v))
    }

    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let mut k = 0;
        each_param(robot, |_, i| {
            let d = -f64::from(pose.rigid.conditions.dir[i]);
            let (sv, sw) = pose.joint_screw(robot, i);
            dp[k] = sv * d;
            put(&mut dw, k, sw * d);
            k += 1;
        });
    }

    fn deflection_reads_axes(&self, _robot: &Robot) -> bool {
        false
    }

    fn deflects_joints(&self, robot: &Robot) -> bool {
        robot.family_values(KEY).is_some()
    }

    fn add_joint_deflection(&self, robot: &Robot, rigid: &RigidPose, dq: &mut [f64]) {
        let Some(v) = robot.family_values(KEY) else {
            return;
        };
        let n = robot.dof();
        for i in (0..n).filter(|&i| v[i] == 1.0) {
            dq[i] -= v[n + i] * f64::from(rigid.conditions.dir[i]);
        }
    }
}

/// Makes the half play of every revolute joint in `joints` (0-based) a parameter of `robot`, at
/// zero; an empty list removes the family.
pub fn enable(robot: &mut Robot, joints: &[usize]) -> Result<()> {
    if joints.is_empty() {
        return robot.set_family_values(KEY, None);
    }
    let n = robot.dof();
    let mut v = vec![0.0; 2 * n];
    for &i in joints {
        if i >= n {
            return Err(Error::invalid(
                "backlash",
                format!("joint {} does not exist (robot has {n})", i + 1),
            ));
        }
        if robot.joint_type(i) == JointType::Revolute {
            v[i] = 1.0;
        }
    }
    robot.set_family_values(KEY, Some(v))
}

/// The joints (0-based) whose backlash `robot` models.
pub fn joints(robot: &Robot) -> Vec<usize> {
    robot.family_values(KEY).map_or_else(Vec::new, |v| {
        (0..robot.dof()).filter(|&i| v[i] == 1.0).collect()
    })
}
