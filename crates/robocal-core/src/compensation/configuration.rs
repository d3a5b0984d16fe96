//! The configuration (branch) of a 6R arm: shoulder, elbow and wrist flags, and how close a pose
//! is to the singularity between two branches.
//!
//! A 6-joint arm reaches most tool poses in up to eight ways (shoulder front/back, elbow up/down,
//! wrist flipped or not). Compensation must stay on the branch of the desired joints: a flipped
//! wrist puts the tool point at the target with the tool turned by tens of degrees. The flags are
//! defined generically from the joint axes, for any chain whose last six joints are revolute
//! (a 6R arm, possibly on prismatic axes such as a linear track), with `z_k`, `o_k` the unit
//! direction of arm joint `k` (1..6) and a point on it, and `c` the *wrist point*, the point of
//! axis 5 closest to axis 4 (the wrist centre of a spherical wrist):
//!
//! - **shoulder** `s = (c - o1) . unit(z1 x z2)`: on which side of axis 1 the wrist point lies,
//!   along the arm's forward direction (KUKA: the basic versus the overhead area);
//! - **elbow** `e = z2 . ((c - o2) x (c - o3)) / (|c - o2| |c - o3|)`: the sine of the angle at
//!   the elbow between the upper arm and the forearm (sign: elbow up or down);
//! - **wrist** `w = z4 . (z5 x z6)`: the sine of the angle between axes 4 and 6 about axis 5
//!   (for a spherical wrist, `sin q5` up to a constant sign: the sign of the KUKA A5).
//!
//! Each flag is the sign of its factor (bit set when negative). A factor crosses zero exactly at
//! the singularity between two branches (shoulder: the wrist point on axis 1; elbow: the arm
//! stretched or folded; wrist: axes 4 and 6 aligned), so the size of the smallest factor is a
//! margin to the nearest branch boundary: `|s| / reach`, `|e|`, `|w|`.
//!
//! Robots with fewer than six joints, a prismatic joint among the last six or more than six
//! revolute joints (redundant arms such as a 7-joint WAM: their self-motion has no discrete
//! branches of this kind) have no configuration: [`configuration`] returns `None`, and
//! compensation does not check branches for them.

use crate::model::{JointType, Robot};
use nalgebra::Vector3;

/// Bit of [`Configuration::flags`]: shoulder factor negative.
pub const SHOULDER: u8 = 1;
/// Bit of [`Configuration::flags`]: elbow factor negative.
pub const ELBOW: u8 = 2;
/// Bit of [`Configuration::flags`]: wrist factor negative.
pub const WRIST: u8 = 4;

/// The branch of a 6R arm at some joint values (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Configuration {
    /// [`SHOULDER`], [`ELBOW`], [`WRIST`]: set when that factor is negative.
    pub flags: u8,
    /// The normalized factors `[s / reach, e, w]`.
    pub factors: [f64; 3],
}

impl Configuration {
    /// The distance to the nearest branch boundary: the smallest normalized factor's magnitude
    /// (0 at a singularity, about 1 far from all).
    pub fn margin(&self) -> f64 {
        self.factors
            .iter()
            .fold(f64::INFINITY, |m, f| m.min(f.abs()))
    }

    /// The names of the flags that differ between `self` and `other` (`shoulder`, `elbow`,
    /// `wrist`).
    pub fn changes(&self, other: &Configuration) -> Vec<&'static str> {
        let d = self.flags ^ other.flags;
        [(SHOULDER, "shoulder"), (ELBOW, "elbow"), (WRIST, "wrist")]
            .into_iter()
            .filter(|(b, _)| d & b != 0)
            .map(|(_, n)| n)
            .collect()
    }
}

/// Whether `robot` has a configuration: its last six joints are revolute and no other is.
pub fn has_configuration(robot: &Robot) -> bool {
    let t = robot.joint_types();
    t.len() >= 6
        && t.iter().filter(|j| **j == JointType::Revolute).count() == 6
        && t[t.len() - 6..].iter().all(|j| *j == JointType::Revolute)
}

/// The configuration of `robot` at joint values `q` (rad), or `None` when the robot has none
/// (see [`has_configuration`]). Allocation-free.
pub fn configuration(robot: &Robot, q: &[f64]) -> Option<Configuration> {
    if !has_configuration(robot) {
        return None;
    }
    let frames = robot.pose_frames(q);
    let k0 = robot.dof() - 6;
    let ax = |k: usize| -> (Vector3<f64>, Vector3<f64>) {
        let f = &frames.axis[k0 + k];
        (f.rotation.matrix().column(2).into(), f.translation.vector)
    };
    let (z1, o1) = ax(0);
    let (z2, o2) = ax(1);
    let (_, o3) = ax(2);
    let (z4, o4) = ax(3);
    let (z5, o5) = ax(4);
    let (z6, _) = ax(5);
    let c = closest_point_on(o5, z5, o4, z4);
    let fwd = z1.cross(&z2);
    let s = if fwd.norm() > 1e-9 {
        (c - o1).dot(&fwd.normalize()) / robot.reach_mm().max(1e-9)
    } else {
        0.0
    };
    let (u, v) = (c - o2, c - o3);
    let uv = u.norm() * v.norm();
    let e = if uv > 1e-12 {
        z2.dot(&u.cross(&v)) / uv
    } else {
        0.0
    };
    let w = z4.dot(&z5.cross(&z6));
    let mut flags = 0;
    for (f, b) in [(s, SHOULDER), (e, ELBOW), (w, WRIST)] {
        if f < 0.0 {
            flags |= b;
        }
    }
    Some(Configuration {
        flags,
        factors: [s, e, w],
    })
}

/// The point of the line `(p, u)` closest to the line `(r, v)` (unit directions); `p` when the
/// lines are parallel.
fn closest_point_on(
    p: Vector3<f64>,
    u: Vector3<f64>,
    r: Vector3<f64>,
    v: Vector3<f64>,
) -> Vector3<f64> {
    let w0 = p - r;
    let b = u.dot(&v);
    let den = 1.0 - b * b;
    if den < 1e-12 {
        return p;
    }
    let (d, e) = (u.dot(&w0), v.dot(&w0));
    p + u * ((b * e - d) / den)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;

    #[test]
    fn kuka_flags_follow_the_joints_that_define_them() {
        let r = preset("kuka-kr480-r3330").unwrap();
        let base = [0.2, -1.2, 1.4, 0.3, 0.8, -0.4];
        let c0 = configuration(&r, &base).unwrap();
        // Wrist: the sign of q5 flips the wrist flag only.
        let mut q = base;
        q[4] = -0.8;
        let c1 = configuration(&r, &q).unwrap();
        assert_eq!(c0.changes(&c1), vec!["wrist"]);
        assert!((c0.factors[2].abs() - 0.8f64.sin()).abs() < 1e-9);
        // The wrist singularity: q5 = 0 gives a zero margin.
        q[4] = 0.0;
        assert!(configuration(&r, &q).unwrap().margin() < 1e-9);
        // Shoulder: leaning the upper arm back past the vertical puts the wrist point behind
        // axis 1; the shoulder flag changes.
        let front = configuration(&r, &[0.0, -0.5, 0.5, 0.0, 0.5, 0.0]).unwrap();
        let back = configuration(&r, &[0.0, -2.8, 0.3, 0.0, 0.5, 0.0]).unwrap();
        assert!(
            front.changes(&back).contains(&"shoulder"),
            "{front:?} {back:?}"
        );
        // Elbow: the two elbow solutions of the same wrist point differ in the elbow flag.
        let up = configuration(&r, &[0.0, -1.0, 1.0, 0.0, 0.5, 0.0]).unwrap();
        let down = configuration(&r, &[0.0, -1.0, -2.5, 0.0, 0.5, 0.0]).unwrap();
        assert!(up.changes(&down).contains(&"elbow"), "{up:?} {down:?}");
    }

    #[test]
    fn redundant_and_short_robots_have_no_configuration() {
        let r = preset("kuka-kr480-r3330").unwrap();
        assert!(has_configuration(&r));
        let toml = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/wam.toml"
        ))
        .unwrap();
        let wam =
            crate::model::robot_file::parse_robot_toml(&toml, std::path::Path::new("wam.toml"))
                .unwrap();
        assert_eq!(wam.dof(), 7);
        assert!(!has_configuration(&wam));
        assert!(configuration(&wam, &[0.0; 7]).is_none());
    }
}
