//! Screw-theory forward kinematics, the paper's eq. 6:
//! `g(q) = exp(xi_1 q_1) ... exp(xi_n q_n) g(0)`.
//!
//! The twists `xi_i = (v_i, w_i)` and `g(0)` are derived from the parameter table, in the ACS (the
//! base frame B is part of the chain), at q = 0: a revolute joint's `w_i` is its unit axis and
//! `v_i = -w_i x o_i` for a point `o_i` on it; a prismatic joint's twist is a pure translation,
//! `v_i` its unit axis and `w_i = 0` (Murray, Li & Sastry, section 3.2). `g(0)` is the tool frame
//! at q = 0.

use crate::frame::{frame, Frame};
use crate::model::{JointType, Robot};
use nalgebra::{Matrix3, Vector3};

/// A unit twist: of a revolute joint (`v = -w x o`, `|w| = 1`) or of a prismatic joint
/// (`|v| = 1`, `w = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    /// Linear part v (mm per unit of the joint value).
    pub v: Vector3<f64>,
    /// Angular part w (unit vector, or zero for a prismatic joint).
    pub w: Vector3<f64>,
}

impl Twist {
    /// The twist of a revolute joint about the unit axis `w` through the point `o`.
    pub fn revolute(w: Vector3<f64>, o: Vector3<f64>) -> Twist {
        Twist { v: -w.cross(&o), w }
    }

    /// The twist of a prismatic joint along the unit direction `v`.
    pub fn prismatic(v: Vector3<f64>) -> Twist {
        Twist {
            v,
            w: Vector3::zeros(),
        }
    }

    /// The rigid motion `exp(xi^ theta)`: for `w != 0` Rodrigues' formula for the rotation and
    /// `(I - R)(w x v) + w w^T v theta` for the translation (Murray, Li & Sastry eq. 2.36); for
    /// `w = 0` the translation `v theta` (eq. 2.32).
    #[inline]
    pub fn exp(&self, theta: f64) -> Frame {
        let w = self.w;
        if w.x == 0.0 && w.y == 0.0 && w.z == 0.0 {
            return self.translation(theta);
        }
        let (s, c) = theta.sin_cos();
        let k = Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0);
        let r = Matrix3::identity() + k * s + k * k * (1.0 - c);
        let p = (Matrix3::identity() - r) * w.cross(&self.v) + w * w.dot(&self.v) * theta;
        frame(r, p)
    }
}

impl Twist {
    #[cold]
    fn translation(&self, theta: f64) -> Frame {
        frame(Matrix3::identity(), self.v * theta)
    }
}

/// The product-of-exponentials form of a robot (eq. 6).
#[derive(Debug, Clone, PartialEq)]
pub struct Poe {
    /// One twist per joint, in the ACS.
    pub twists: Vec<Twist>,
    /// The tool frame at q = 0, `g_bt(0)`.
    pub g0: Frame,
}

impl Poe {
    /// Derives the twists and `g(0)` from the robot's parameter table.
    pub fn from_robot(robot: &Robot) -> Poe {
        let zero = vec![0.0; robot.dof()];
        let twists = robot
            .joint_axes(&zero)
            .iter()
            .zip(robot.joint_types())
            .map(|((w, o), t)| match t {
                JointType::Revolute => Twist::revolute(*w, *o),
                JointType::Prismatic => Twist::prismatic(*w),
            })
            .collect();
        Poe {
            twists,
            g0: robot.tool_pose(&zero),
        }
    }

    /// The tool frame at joint values `q` (rad, or mm for a prismatic joint).
    pub fn tool_pose(&self, q: &[f64]) -> Frame {
        assert_eq!(q.len(), self.twists.len(), "joint vector length");
        let mut g = Frame::identity();
        for (t, &qi) in self.twists.iter().zip(q) {
            g *= t.exp(qi);
        }
        g * self.g0
    }
}
