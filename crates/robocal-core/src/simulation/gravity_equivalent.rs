//! The simulator's gravity physics as the identified model's joint compliance family: where the
//! two describe the same physics they must agree (a test holds them equal to rounding).
//!
//! The simulator puts each link's mass at the midpoint of two points fixed in the link (a point
//! on its joint's axis and the next axis frame's origin, or the tool point for the last link);
//! a point mass at a midpoint is half the mass at each end, so the weights are lumped masses
//! `M_k = (m_{k-1} + m_k) / 2` at the origin of axis frame k and `m_n / 2 + payload` at the tool
//! point, shared by every joint. The family's coefficient of joint j and point k is then
//! `c_j M_k g / 1000` (rad per mm of lever), or, for a physical compliance, `c_j` itself with the
//! payload's weight at the tool point (the last link's half mass there is lumped into
//! `compliance{j}` times the payload, `c_j (1 + m_n / (2 payload))`).

use super::gravity::GravityModel;
use crate::error::{Error, Result};
use crate::model::family::compliance;
use crate::model::{JointType, Robot};

impl GravityModel {
    /// `robot` with the joint compliance family set to this model's physics (see the module
    /// docs): compliant joints are the revolute joints with a non-zero compliance; with
    /// `physical`, the tool-point coefficients are compliances at this model's payload. The
    /// gravity direction of this model becomes the robot's. Needs a robot with revolute joints
    /// only (the simulator moves a prismatic joint's link start with the joint).
    pub fn equivalent(&self, robot: &Robot, physical: bool) -> Result<Robot> {
        self.validate(robot.dof())?;
        if robot.joint_space().any_prismatic() {
            return Err(Error::invalid(
                "gravity",
                "the compliance family's equivalent of the gravity model needs revolute joints",
            ));
        }
        let n = robot.dof();
        let g = nalgebra::Vector3::from(self.gravity_m_s2);
        let g_norm = g.norm();
        let mut r = robot.clone();
        r.set_gravity(self.gravity_m_s2)?;
        let joints: Vec<usize> = (0..n)
            .filter(|&i| {
                self.compliance_rad_per_nm[i] != 0.0 && robot.joint_type(i) == JointType::Revolute
            })
            .collect();
        compliance::enable(&mut r, &joints, physical.then_some(self.payload_kg))?;
        let m = &self.link_masses_kg;
        for &i in &joints {
            let c = self.compliance_rad_per_nm[i];
            for k in i + 1..n {
                let lumped = 0.5 * (m[k - 1] + m[k]);
                compliance::set_coefficient(&mut r, i, k, c * lumped * g_norm * 1e-3);
            }
            let tool_mass = 0.5 * m[n - 1] + self.payload_kg;
            let tool = if physical {
                c * tool_mass / self.payload_kg * g_norm / compliance::G0
            } else {
                c * tool_mass * g_norm * 1e-3
            };
            compliance::set_coefficient(&mut r, i, n, tool);
        }
        Ok(r)
    }
}
