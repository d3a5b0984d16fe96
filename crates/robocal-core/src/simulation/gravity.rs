//! Gravity-induced joint deflection: a small elastostatic model of a non-geometric error (the
//! paper's introduction: "joint and link deflections caused by gravity and payload").
//!
//! # Model
//! - Link j (the body moved by joint j) is a point mass `m_j` at the midpoint between a point on
//!   joint j's axis (the origin of its axis frame; for a prismatic joint, that origin moved along
//!   the axis by the joint's travel `d_j + q_j`) and the origin of joint j+1's axis frame; for
//!   the last link, between that point and the tool point. Both points are fixed in body j, so
//!   the mass moves rigidly with it.
//! - The payload `m_p` is a point mass at the tool point.
//! - Gravity `g` (default 9.80665 m/s² along −z of the base frame) pulls on every mass. The
//!   torque about joint j is the moment of the weights of all masses beyond it about its axis:
//!   `tau_j = sum_{k >= j} u_j . ((r_k - o_j) x m_k g)` (N·m; `u_j`, `o_j` from
//!   [`Robot::joint_axes`]). It equals `-dV/dq_j` for the potential energy `V = -sum m_k g . r_k`.
//! - Each joint is a torsion spring of compliance `c_j` (rad per N·m): `dq_j = c_j tau_j`. The
//!   robot really stands at `q + dq` while the controller reports `q`.
//! - First order: the torques are evaluated at the commanded `q` (the change of torque caused by
//!   `dq` is of second order for realistic stiffnesses).
//! - A prismatic joint (e.g. a linear track) has no torque-driven rotation. Its generalized force
//!   is the weight's component along its axis, `f_j = u_j . sum_{k >= j} m_k g` (N; equal to
//!   `-dV/dq_j` with `q_j` in metres), which [`GravityModel::torques`] reports in its place; the
//!   joint is taken as rigid along its axis (its position-controlled drive holds the carriage, and
//!   a horizontal track carries no axial weight at all), so it does not deflect and its
//!   compliance entry is not used. The masses beyond it still load the revolute joints.
//!
//! Link elasticity, gear backlash and the robot's own counterbalance are not modelled.

use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Standard gravity (m/s²).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Parameters of the gravity deflection model (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GravityModel {
    /// Compliance of each joint, rad per N·m (one value per joint; e.g. 2e-7 for the main axes
    /// of a 500 kg-class robot).
    pub compliance_rad_per_nm: Vec<f64>,
    /// Mass of each link, kg (one value per joint: link j is the body moved by joint j).
    pub link_masses_kg: Vec<f64>,
    /// Payload at the tool point, kg.
    pub payload_kg: f64,
    /// Gravitational acceleration in the base frame, m/s².
    #[serde(default = "default_gravity")]
    pub gravity_m_s2: [f64; 3],
}

fn default_gravity() -> [f64; 3] {
    [0.0, 0.0, -STANDARD_GRAVITY]
}

impl GravityModel {
    /// A model with the standard gravity along −z of the base frame.
    pub fn new(compliance_rad_per_nm: Vec<f64>, link_masses_kg: Vec<f64>, payload_kg: f64) -> Self {
        GravityModel {
            compliance_rad_per_nm,
            link_masses_kg,
            payload_kg,
            gravity_m_s2: default_gravity(),
        }
    }

    /// Checks the model against a robot with `dof` joints: one compliance and one mass per joint,
    /// all finite and non-negative, and some mass to deflect.
    pub fn validate(&self, dof: usize) -> Result<()> {
        for (name, v, range) in [
            (
                "gravity.compliance_rad_per_nm",
                &self.compliance_rad_per_nm,
                &crate::ranges::COMPLIANCE,
            ),
            (
                "gravity.link_masses_kg",
                &self.link_masses_kg,
                &crate::ranges::MASS,
            ),
        ] {
            if v.len() != dof {
                return Err(Error::invalid(
                    name,
                    format!("{} values for a robot with {dof} joints", v.len()),
                ));
            }
            if let Some((i, x)) = v
                .iter()
                .enumerate()
                .find(|(_, x)| !x.is_finite() || **x < 0.0)
            {
                return Err(Error::invalid(
                    name,
                    format!("value {} ({x}) must be a finite number >= 0", i + 1),
                ));
            }
            for (i, x) in v.iter().enumerate() {
                range
                    .check(*x)
                    .map_err(|msg| Error::invalid(name, format!("value {}: {msg}", i + 1)))?;
            }
        }
        if !self.payload_kg.is_finite() || self.payload_kg < 0.0 {
            return Err(Error::invalid(
                "gravity.payload_kg",
                format!("{} must be a finite number >= 0", self.payload_kg),
            ));
        }
        crate::ranges::in_range("gravity.payload_kg", self.payload_kg, &crate::ranges::MASS)?;
        if self.gravity_m_s2.iter().any(|g| !g.is_finite()) {
            return Err(Error::invalid(
                "gravity.gravity_m_s2",
                "not a finite vector",
            ));
        }
        if self.payload_kg == 0.0 && self.link_masses_kg.iter().all(|m| *m == 0.0) {
            return Err(Error::invalid(
                "gravity.payload_kg",
                "gravity deflection needs a mass: give `gravity.payload_kg` and/or `gravity.link_masses_kg`",
            ));
        }
        Ok(())
    }

    /// The point masses (kg) and their positions (mm, base frame) at joint values `q` (rad):
    /// one per link, then the payload.
    pub fn masses(&self, robot: &Robot, q: &[f64]) -> Vec<(f64, Vector3<f64>)> {
        self.masses_on(robot, q, &robot.joint_axes(q), robot.tool_position(q))
    }

    fn masses_on(
        &self,
        robot: &Robot,
        q: &[f64],
        axes: &[(Vector3<f64>, Vector3<f64>)],
        tool: Vector3<f64>,
    ) -> Vec<(f64, Vector3<f64>)> {
        let n = axes.len();
        let mut out = Vec::with_capacity(n + 1);
        for j in 0..n {
            let (u, o) = axes[j];
            let start = match robot.joint_type(j) {
                JointType::Revolute => o,
                JointType::Prismatic => o + u * (robot.links()[j].d + q[j]),
            };
            let next = if j + 1 < n { axes[j + 1].1 } else { tool };
            out.push((self.link_masses_kg[j], (start + next) * 0.5));
        }
        out.push((self.payload_kg, tool));
        out
    }

    /// The gravity torque about each joint axis (N·m) at joint values `q` (rad, or mm for a
    /// prismatic joint); for a prismatic joint, the axial force (N) instead.
    pub fn torques(&self, robot: &Robot, q: &[f64]) -> Vec<f64> {
        let axes = robot.joint_axes(q);
        let masses = self.masses_on(robot, q, &axes, robot.tool_position(q));
        let g = Vector3::from(self.gravity_m_s2);
        // Mass k (k < n) belongs to link k and hangs beyond joints 0..=k; the payload (k = n)
        // beyond all joints.
        axes.iter()
            .zip(robot.joint_types())
            .enumerate()
            .map(|(j, ((u, o), t))| {
                masses[j..]
                    .iter()
                    .map(|(m, r)| match t {
                        JointType::Revolute => u.dot(&((r - o) * 1e-3).cross(&(g * *m))),
                        JointType::Prismatic => u.dot(&(g * *m)),
                    })
                    .sum()
            })
            .collect()
    }

    /// The joint deflections `dq_j = c_j tau_j` (rad) at joint values `q` (rad or mm); zero for
    /// a prismatic joint (rigid along its axis, see the module documentation).
    pub fn deflection(&self, robot: &Robot, q: &[f64]) -> Vec<f64> {
        self.torques(robot, q)
            .iter()
            .zip(&self.compliance_rad_per_nm)
            .zip(robot.joint_types())
            .map(|((t, c), jt)| match jt {
                JointType::Revolute => t * c,
                JointType::Prismatic => 0.0,
            })
            .collect()
    }

    /// Where the robot really stands when commanded to `q`: `q + dq` (rad or mm).
    pub fn deflected(&self, robot: &Robot, q: &[f64]) -> Vec<f64> {
        self.deflection(robot, q)
            .iter()
            .zip(q)
            .map(|(d, v)| v + d)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;

    fn model() -> GravityModel {
        GravityModel::new(
            vec![2e-7, 3e-7, 3e-7, 1e-6, 1e-6, 2e-6],
            vec![700.0, 600.0, 300.0, 150.0, 60.0, 20.0],
            300.0,
        )
    }

    /// tau_j = -dV/dq_j with V = -sum m g . r (J = N·m per rad).
    #[test]
    fn torques_are_minus_the_gradient_of_potential_energy() {
        let r = preset("kuka-kr480-r3330").unwrap();
        let m = model();
        let potential = |q: &[f64]| -> f64 {
            let g = Vector3::from(m.gravity_m_s2);
            -m.masses(&r, q)
                .iter()
                .map(|(mass, p)| mass * g.dot(&(p * 1e-3)))
                .sum::<f64>()
        };
        let q = [0.3, -0.9, 0.4, 1.1, -0.7, 2.0];
        let tau = m.torques(&r, &q);
        for j in 0..6 {
            let h = 1e-6;
            let mut qp = q;
            qp[j] += h;
            let mut qm = q;
            qm[j] -= h;
            let fd = -(potential(&qp) - potential(&qm)) / (2.0 * h);
            assert!(
                (fd - tau[j]).abs() < 1e-6 * (1.0 + fd.abs()),
                "joint {}: {fd} vs {}",
                j + 1,
                tau[j]
            );
        }
        // Joint 1 is vertical: gravity has no moment about it.
        assert!(tau[0].abs() < 1e-6, "{}", tau[0]);
    }

    #[test]
    fn an_outstretched_arm_sags() {
        let r = preset("kuka-kr480-r3330").unwrap();
        let m = model();
        let q = [0.0, -0.2, 1.4, 0.0, 0.5, 0.0];
        let p0 = r.tool_position(&q);
        let p1 = r.tool_position(&m.deflected(&r, &q));
        let dz = p1.z - p0.z;
        assert!(dz < -0.1, "the tool should drop, dz = {dz} mm");
    }

    #[test]
    fn validation() {
        let mut m = model();
        m.validate(6).unwrap();
        assert!(m.validate(7).unwrap_err().to_string().contains("6 values"));
        m.compliance_rad_per_nm[2] = -1.0;
        assert!(m.validate(6).unwrap_err().to_string().contains("value 3"));
        let m = GravityModel::new(vec![1e-7; 6], vec![0.0; 6], 0.0);
        assert!(m
            .validate(6)
            .unwrap_err()
            .to_string()
            .contains("needs a mass"));
    }

    /// On the KR 480 on a track: the revolute joints' torques are still `-dV/dq`; the track's
    /// entry is the axial force `-dV/dq1` (q1 in metres), and the track does not deflect.
    #[test]
    fn a_prismatic_joint_carries_an_axial_force_and_does_not_deflect() {
        let r = crate::load_robot_file(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/kr480-track.toml"
        )))
        .unwrap();
        let mut m = GravityModel::new(
            vec![1e-6; 7],
            vec![900.0, 700.0, 600.0, 300.0, 150.0, 60.0, 20.0],
            300.0,
        );
        // Tilt gravity so that it has a component along the track (+x).
        m.gravity_m_s2 = [1.5, 0.0, -9.7];
        let potential = |q: &[f64]| -> f64 {
            let g = Vector3::from(m.gravity_m_s2);
            -m.masses(&r, q)
                .iter()
                .map(|(mass, p)| mass * g.dot(&(p * 1e-3)))
                .sum::<f64>()
        };
        let q = [1200.0, 0.3, -0.9, 0.4, 1.1, -0.7, 2.0];
        let tau = m.torques(&r, &q);
        for j in 0..7 {
            let (h, per_unit) = if j == 0 { (1e-3, 1e3) } else { (1e-6, 1.0) };
            let mut qp = q;
            qp[j] += h;
            let mut qm = q;
            qm[j] -= h;
            let fd = -(potential(&qp) - potential(&qm)) / (2.0 * h) * per_unit;
            assert!(
                (fd - tau[j]).abs() < 1e-5 * (1.0 + fd.abs()),
                "joint {}: {fd} vs {}",
                j + 1,
                tau[j]
            );
        }
        // The axial force is the whole weight's x component: 1.5 m/s² times all masses.
        let total: f64 = m.link_masses_kg.iter().sum::<f64>() + m.payload_kg;
        assert!((tau[0] - 1.5 * total).abs() < 1e-9, "{}", tau[0]);
        let dq = m.deflection(&r, &q);
        assert_eq!(dq[0], 0.0);
        assert!(dq[2].abs() > 0.0);
    }
}
