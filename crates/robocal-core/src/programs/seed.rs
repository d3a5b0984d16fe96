//! The desired joints of a Cartesian program target: the nominal model's inverse kinematics on
//! the branch the target's configuration data name.
//!
//! A 6R arm reaches a pose in up to eight ways (shoulder, elbow, wrist), and each of those with
//! every axis that can turn more than a full turn in two or more ways (+-360 deg). Controllers
//! store which one a Cartesian target means beside the pose ([`Branch`]): KUKA's status `S` and
//! turn `T`, ABB's confdata `[cf1, cf4, cf6, cfx]`; a controller without such data (URScript)
//! takes the solution nearest its current joints.
//!
//! The search ([`branch_joints`]) solves the pose from many starts (the spread start
//! configurations of [`crate::compensation::default_seeds`] turned towards the target or half a
//! turn away from it, and the wrist-flipped variant of every solution found) and takes each solution's full-turn variants (+-360 deg on every revolute axis,
//! within the limits); it accepts the first variant whose configuration data equal the target's,
//! polished to rounding (the recovered joints of a pose written from joints equal them to about
//! 1e-10 deg).
//!
//! The configuration data of joints:
//! - KRL `T` ([`turn_of`]): bit i set when controller axis i+1 is negative (KUKA's definition).
//! - KRL `S` ([`krl_status`]): bit 0 the wrist point behind axis 1 (KUKA's overhead area), bit 1
//!   the elbow on the side of axis 3 KUKA calls `A3 >= phi`, bit 2 `A5 <= 0`. Bits 0 and 1 are
//!   the shoulder and elbow flags of [`crate::compensation::configuration`], signed so that the
//!   KUKA home position (A1..A6 = 0, -90, 90, 0, 45, 0) has `S = 'B010'`.
//! - RAPID confdata ([`rapid_conf`]): `cf1, cf4, cf6` the quadrants `floor(angle / 90 deg)` of
//!   axes 1, 4, 6 (ABB: 0 for 0..90, -1 for -90..0, ...); `cfx` bit 0 axis 5 negative, bit 1 the
//!   wrist centre behind the lower arm, bit 2 behind axis 1, signed so that the robot's zero
//!   position (axis 5 at 30 deg) has `cfx = 0` (the ABB zero position: upper arm up, forearm
//!   forward). A robot whose zero position is a singularity of the shoulder or elbow (the arm
//!   stretched) has no reference for bits 1 and 2: only bit 0 is checked.

use crate::compensation::configuration::{self, ELBOW, SHOULDER};
use crate::compensation::{IkStatus, PoseNewton};
use crate::frame::Frame;
use crate::model::{JointType, Robot};

/// What a program says about the joints of a Cartesian target.
#[derive(Debug, Clone, PartialEq)]
pub enum Branch {
    /// KUKA KRL status `S` and turn `T` (either may be missing: then not checked).
    Krl {
        /// `S`.
        status: Option<u32>,
        /// `T`.
        turn: Option<u32>,
    },
    /// ABB RAPID confdata `[cf1, cf4, cf6, cfx]`.
    Rapid([i64; 4]),
    /// No configuration data: the solution nearest these joints (model values, rad).
    Nearest(Vec<f64>),
    /// No configuration data and nothing to be near: the first solution found.
    Any,
}

/// How many start configurations the search tries at most.
const STARTS: usize = 64;

/// Axes within this of zero (deg) match either sign of a turn (and an axis 5 either sign of
/// `S` bit 2, `cfx` bit 0): a target written at axis 0 with its pose rounded to 3 decimals comes
/// back from inverse kinematics as +-1e-4. The solutions of a pose differ by far more in each
/// axis (a branch, or a full turn).
pub(crate) const ZERO_DEG: f64 = 0.01;

/// The turn `T` of joints `q`: bit i set when controller axis i+1 is negative.
pub fn turn_of(robot: &Robot, q: &[f64]) -> u32 {
    let axes = robot.joint_space().axes_from_joints(q);
    axes.iter()
        .enumerate()
        .filter(|(_, a)| **a < 0.0)
        .map(|(i, _)| 1u32 << i)
        .sum()
}

/// The configuration flags of `q` relative to those of the reference axis values `reference`
/// (bit set where they differ), or `None` when the robot has no configuration. `Some((flags,
/// false))` when the reference lies within `margin` of a singularity (its flags mean nothing).
fn relative_flags(robot: &Robot, q: &[f64], reference: &[f64]) -> Option<(u8, bool)> {
    let js = robot.joint_space();
    let r = configuration::configuration(robot, &js.joints_from_axes(reference))?;
    let c = configuration::configuration(robot, q)?;
    Some((c.flags ^ r.flags, r.margin() > 0.05))
}

/// KUKA's status `S` of joints `q` (see the module documentation), or `None` for a robot without
/// a configuration (not a 6R arm).
pub fn krl_status(robot: &Robot, q: &[f64]) -> Option<u32> {
    if robot.dof() != 6 {
        return None;
    }
    let (d, _) = relative_flags(robot, q, &[0.0, -90.0, 90.0, 0.0, 45.0, 0.0])?;
    let a5 = robot.joint_space().axes_from_joints(q)[4];
    let shoulder = u32::from(d & SHOULDER != 0);
    let elbow = u32::from(d & ELBOW == 0);
    let wrist = u32::from(a5 <= 0.0);
    Some(shoulder | elbow << 1 | wrist << 2)
}

/// The quadrant `floor(a / 90)` of an axis value (deg).
pub fn quadrant(a: f64) -> i64 {
    (a / 90.0).floor() as i64
}

/// An axis within this of a quadrant boundary (deg) matches the quadrants on both sides: a
/// target at axis 1 = 0 may need -0.002 after compensation, and the solutions of a pose differ
/// by far more than this in axes 1, 4 and 6 (half a turn, or a full one).
pub const QUADRANT_SLACK_DEG: f64 = 1.0;

fn in_quadrant(a: f64, w: i64) -> bool {
    quadrant(a) == w
        || quadrant(a + QUADRANT_SLACK_DEG) == w
        || quadrant(a - QUADRANT_SLACK_DEG) == w
}

/// ABB's confdata `[cf1, cf4, cf6, cfx]` of joints `q` (see the module documentation). `cfx`
/// holds only bit 0 when the robot's zero position is singular, and is 0 for a robot without a
/// configuration.
pub fn rapid_conf(robot: &Robot, q: &[f64]) -> [i64; 4] {
    let a = robot.joint_space().axes_from_joints(q);
    let mut cfx = i64::from(a.len() > 4 && a[4] < 0.0);
    if robot.dof() == 6 {
        if let Some((d, true)) = relative_flags(robot, q, &[0.0, 0.0, 0.0, 0.0, 30.0, 0.0]) {
            cfx |= i64::from(d & ELBOW != 0) << 1 | i64::from(d & SHOULDER != 0) << 2;
        }
    }
    let quad = |i: usize| a.get(i).map_or(0, |v| quadrant(*v));
    [quad(0), quad(3), quad(5), cfx]
}

/// Whether two confdata agree: cf1, cf4, cf6 equal (an axis within [`QUADRANT_SLACK_DEG`] of a
/// quadrant boundary matches both sides), cfx equal in the bits the robot defines.
fn rapid_matches(robot: &Robot, q: &[f64], want: &[i64; 4]) -> bool {
    let a = robot.joint_space().axes_from_joints(q);
    let have = rapid_conf(robot, q);
    let quad_ok = [0usize, 3, 5]
        .iter()
        .zip(want)
        .all(|(i, w)| in_quadrant(a[*i], *w));
    let full = robot.dof() == 6
        && relative_flags(robot, q, &[0.0, 0.0, 0.0, 0.0, 30.0, 0.0]).is_some_and(|(_, ok)| ok);
    let mask = if full { 7 } else { 1 };
    let a5_zero = a.len() > 4 && a[4].abs() < ZERO_DEG;
    let cfx_ok = (have[3] ^ want[3]) & mask & if a5_zero { 6 } else { 7 } == 0;
    quad_ok && cfx_ok
}

/// Whether the controller axes of `q` have the signs turn `t` gives; an axis within `zero_deg`
/// of 0 matches either sign.
pub(crate) fn matches_turn(robot: &Robot, q: &[f64], t: u32, zero_deg: f64) -> bool {
    let axes = robot.joint_space().axes_from_joints(q);
    axes.iter()
        .enumerate()
        .all(|(i, a)| a.abs() < zero_deg || (t & (1 << i) != 0) == (*a < 0.0))
}

/// Whether joints `q` have the configuration data of `branch` (always for `Nearest` and `Any`).
pub fn matches(robot: &Robot, q: &[f64], branch: &Branch) -> bool {
    match branch {
        Branch::Krl { status, turn } => {
            let t_ok = turn.map_or(true, |t| matches_turn(robot, q, t, ZERO_DEG));
            let a5_zero = robot.joint_space().axes_from_joints(q)[4].abs() < ZERO_DEG;
            let s_ok = match (status, krl_status(robot, q)) {
                (Some(want), Some(have)) => {
                    let mask = if a5_zero { 3 } else { 7 };
                    (want ^ have) & mask == 0
                }
                _ => true,
            };
            t_ok && s_ok
        }
        Branch::Rapid(conf) => rapid_matches(robot, q, conf),
        Branch::Nearest(_) | Branch::Any => true,
    }
}

/// The variants of a solution `q` (model values, rad) over full turns of its revolute axes within
/// the limits, the one `branch` asks for: per axis the turn whose sign (KRL) or quadrant (RAPID)
/// the data give, or the nearest to the reference (`Nearest`). `None` when no variant has the
/// data.
fn fit(robot: &Robot, q: &[f64], branch: &Branch) -> Option<Vec<f64>> {
    let js = robot.joint_space();
    let tau = std::f64::consts::TAU;
    let mut out = q.to_vec();
    for i in 0..q.len() {
        if robot.joint_type(i) != JointType::Revolute {
            continue;
        }
        let l = robot.limits()[i];
        let mut best: Option<(f64, f64)> = None;
        for k in -2..=2 {
            let mut v = out.clone();
            v[i] = q[i] + f64::from(k) * tau;
            if !l.contains(v[i]) {
                continue;
            }
            let a = js.axes_from_joints(&v)[i];
            let ok = match branch {
                Branch::Krl { turn: Some(t), .. } => {
                    a.abs() < ZERO_DEG || (t & (1 << i) != 0) == (a < 0.0)
                }
                Branch::Rapid(c) => match i {
                    0 | 3 | 5 => in_quadrant(a, c[[0, 0, 0, 1, 0, 2][i]]),
                    _ => true,
                },
                _ => true,
            };
            if !ok {
                continue;
            }
            let cost = match branch {
                Branch::Nearest(r) => (v[i] - r[i]).abs(),
                _ => f64::from(k).abs(),
            };
            if best.map_or(true, |(c, _)| cost < c) {
                best = Some((cost, v[i]));
            }
        }
        out[i] = best?.1;
    }
    matches(robot, &out, branch).then_some(out)
}

/// The wrist-flipped variant of `q` as a start configuration: axis 4 and 6 turned half a turn,
/// axis 5 mirrored (the same flange pose for a spherical wrist).
fn wrist_flip(robot: &Robot, q: &[f64]) -> Vec<f64> {
    let n = q.len();
    let mut v = q.to_vec();
    let pi = std::f64::consts::PI;
    v[n - 3] += if v[n - 3] > 0.0 { -pi } else { pi };
    v[n - 2] = -v[n - 2];
    v[n - 1] += if v[n - 1] > 0.0 { -pi } else { pi };
    for (x, l) in v.iter_mut().zip(robot.limits()) {
        *x = x.clamp(l.min, l.max);
    }
    v
}

/// The `k`-th start configuration: the spread seeds of [`crate::compensation::default_seeds`]
/// turned towards the target, each also turned half a turn about axis 1 (the wrist point behind
/// axis 1: KUKA's overhead area).
pub(crate) fn spread_start(
    robot: &Robot,
    seeds: &[Vec<f64>],
    target: &Frame,
    k: usize,
) -> Option<Vec<f64>> {
    let mut s = seeds.get(k / 2)?.clone();
    crate::compensation::turn_towards(robot, &target.translation.vector, &mut s);
    if k % 2 == 1 {
        let l = robot.limits()[0];
        let pi = std::f64::consts::PI;
        s[0] = [s[0] + pi, s[0] - pi]
            .into_iter()
            .find(|v| l.contains(*v))
            .unwrap_or(s[0]);
    }
    Some(s)
}

/// Whether two joint vectors (rad) are equal up to full turns (to 1e-6 rad).
fn same_modulo_turns(a: &[f64], b: &[f64]) -> bool {
    let tau = std::f64::consts::TAU;
    a.iter().zip(b).all(|(x, y)| {
        let d = (x - y).rem_euclid(tau);
        d.min(tau - d) < 1e-6
    })
}

/// The outcome of [`branch_joints`].
#[derive(Debug, Clone, PartialEq)]
pub enum BranchJoints {
    /// Joints (model values, rad) on the asked branch.
    Found(Vec<f64>),
    /// The pose is reachable, but not on the asked branch: the first solution found.
    Other(Vec<f64>),
    /// No start reached the pose.
    Unreachable,
}

/// The nominal model's joints at `target` (tool frame, base frame) on the branch the
/// configuration data `branch` give (see the module documentation).
pub fn branch_joints(
    nominal: &Robot,
    solver: &PoseNewton,
    target: &Frame,
    branch: &Branch,
) -> BranchJoints {
    let n = nominal.dof();
    let polish = PoseNewton {
        tolerance_mm: 1e-11,
        tolerance_deg: 1e-11,
        max_iterations: 20,
        ..*solver
    };
    let mut q = vec![0.0; n];
    let mut other = None;
    let mut visited: Vec<Vec<f64>> = Vec::new();
    let mut pending: Vec<Vec<f64>> = Vec::new();
    let mut halton = 0;
    if let Branch::Nearest(r) = branch {
        pending.push(r.clone());
    }
    let seeds = crate::compensation::default_seeds(nominal, STARTS / 2);
    for _ in 0..STARTS {
        let start = match pending.pop() {
            Some(s) => s,
            None => {
                let Some(s) = spread_start(nominal, &seeds, target, halton) else {
                    break;
                };
                halton += 1;
                s
            }
        };
        let rep = solver.solve(nominal, target, 0, &start, &mut q);
        if rep.status != IkStatus::Converged {
            continue;
        }
        if let Some(mut v) = fit(nominal, &q, branch) {
            let mut p = vec![0.0; n];
            if polish.solve(nominal, target, 0, &v, &mut p).status == IkStatus::Converged
                && matches(nominal, &p, branch)
            {
                v = p;
            }
            return BranchJoints::Found(v);
        }
        other.get_or_insert_with(|| q.clone());
        // The wrist-flipped variant of a solution not seen before (the flip of a flip is the
        // solution itself).
        let seen = visited.iter().any(|v: &Vec<f64>| same_modulo_turns(v, &q));
        if !seen {
            visited.push(q.clone());
            if n >= 6 {
                pending.insert(0, wrist_flip(nominal, &q));
            }
        }
    }
    match other {
        Some(o) => BranchJoints::Other(o),
        None => BranchJoints::Unreachable,
    }
}
