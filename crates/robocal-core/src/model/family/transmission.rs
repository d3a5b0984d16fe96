//! Joint transmission errors: the first harmonics of each joint's angle error, a periodic error
//! of the gear train (eccentric gears, encoder mounting) that no geometric parameter describes:
//!
//! ```text
//! dq_j = sum_{h = 1..N} tcos{j}_{h} cos(h q_j) + tsin{j}_{h} sin(h q_j)     (amplitudes in deg)
//! ```
//!
//! at the commanded joint value `q_j` (rad). A constant term is phi's; the first harmonic of the
//! first joint partly duplicates the base frame; the identifiability analysis fixes what the data
//! cannot tell apart, with reasons.

use super::{put, FamilyId, ParameterFamily, PoseFrames};
use crate::error::{Error, Result};
use crate::model::{JointType, Param, Robot, Unit};
use nalgebra::Vector3;

/// The family's key in the robot's family store.
pub const KEY: &str = "transmission";
/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(6);
/// The largest number of harmonics per joint.
pub const MAX_HARMONICS: usize = 8;

static TEMPLATES: [&str; 2 * MAX_HARMONICS] = [
    "tcos{j}_1",
    "tcos{j}_2",
    "tcos{j}_3",
    "tcos{j}_4",
    "tcos{j}_5",
    "tcos{j}_6",
    "tcos{j}_7",
    "tcos{j}_8",
    "tsin{j}_1",
    "tsin{j}_2",
    "tsin{j}_3",
    "tsin{j}_4",
    "tsin{j}_5",
    "tsin{j}_6",
    "tsin{j}_7",
    "tsin{j}_8",
];

// Store layout: [harmonics N, enabled flag per joint, then per joint i and harmonic h (0-based)
// the cosine and the sine amplitude (rad)].
const COUNT: usize = 0;
const FLAGS: usize = 1;

fn slot(n: usize, i: usize, h: usize, sine: bool) -> usize {
    FLAGS + n + (i * MAX_HARMONICS + h) * 2 + usize::from(sine)
}

fn store_len(n: usize) -> usize {
    FLAGS + n + n * MAX_HARMONICS * 2
}

/// `(sin(h q), cos(h q))` for `h = 1..=count`, from one `sin_cos` by the angle-addition
/// recurrence (a few ulps from the direct values for the few harmonics there are; the trigonometric
/// functions were a fifth of a fit's time when each harmonic called its own), that one the
/// forward kinematics' branch-free [`crate::trig::sin_cos`] (the C library's was
/// still 6% of the real UR5's calibration with harmonics).
#[inline]
fn harmonic_terms(q: f64, count: usize) -> [(f64, f64); MAX_HARMONICS] {
    let mut out = [(0.0, 0.0); MAX_HARMONICS];
    let (s1, c1) = crate::trig::sin_cos(q);
    let (mut s, mut c) = (s1, c1);
    for t in out.iter_mut().take(count) {
        *t = (s, c);
        (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
    }
    out
}

/// The transmission-error family (see the module docs).
pub struct Transmission;

/// Every parameter in [`Param`] order: (param, joint, harmonic 0-based, sine).
fn each_param(robot: &Robot, mut f: impl FnMut(Param, usize, usize, bool)) {
    let Some(v) = robot.family_values(KEY) else {
        return;
    };
    let n = robot.dof();
    let count = v[COUNT] as usize;
    for sine in [false, true] {
        for h in 0..count {
            for i in (0..n).filter(|&i| v[FLAGS + i] == 1.0) {
                let t = h + if sine { MAX_HARMONICS } else { 0 };
                f(Param::new(ID, t as u8, i as u16), i, h, sine);
            }
        }
    }
}

fn split(p: Param) -> (usize, bool) {
    (p.template() % MAX_HARMONICS, p.template() >= MAX_HARMONICS)
}

impl ParameterFamily for Transmission {
    fn key(&self) -> &'static str {
        KEY
    }

    fn templates(&self) -> &'static [&'static str] {
        &TEMPLATES
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::Deg
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        each_param(robot, |p, _, _, _| out.push(p));
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        let (h, s) = split(p);
        robot
            .family_values(KEY)
            .map_or(0.0, |v| v[slot(robot.dof(), p.index(), h, s)])
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        let (h, s) = split(p);
        let k = slot(robot.dof(), p.index(), h, s);
        if let Some(v) = robot.family_values_mut(KEY) {
            v[k] = value;
        }
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        super::priority::NON_GEOMETRIC + 50_000 + 100 * p.index() as u32 + p.template() as u32
    }

    /// An amplitude of at most [`super::plausible::JOINT_DEFLECTION_DEG`]: sixty times a robot
    /// gear's transmission error of about one arc minute.
    fn plausible(&self, _robot: &Robot, _p: Param) -> super::plausible::Plausible {
        super::plausible::Plausible::moving(
            super::plausible::JOINT_DEFLECTION_DEG,
            "1 degree, sixty times a gear's transmission error",
        )
    }

    fn enable(&self, robot: &mut Robot, p: Param) -> Result<()> {
        let i = p.index();
        if i >= robot.dof() || robot.joint_type(i) != JointType::Revolute {
            return Ok(());
        }
        let n = robot.dof();
        let mut v = robot
            .family_values(KEY)
            .map_or_else(|| vec![0.0; store_len(n)], <[f64]>::to_vec);
        v[FLAGS + i] = 1.0;
        v[COUNT] = v[COUNT].max((split(p).0 + 1) as f64);
        robot.set_family_values(KEY, Some(v))
    }

    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let count = harmonics(robot);
        let q = &pose.rigid.commanded;
        let mut terms = [[(0.0, 0.0); MAX_HARMONICS]; crate::model::MAX_JOINTS];
        for (t, &qi) in terms.iter_mut().zip(&q[..robot.dof()]) {
            *t = harmonic_terms(qi, count);
        }
        let mut k = 0;
        each_param(robot, |_, i, h, sine| {
            let (s, c) = terms[i][h];
            let b = if sine { s } else { c };
            let (sv, sw) = pose.joint_screw(robot, i);
            dp[k] = sv * b;
            put(&mut dw, k, sw * b);
            k += 1;
        });
    }

    fn deflection_reads_axes(&self, _robot: &Robot) -> bool {
        false
    }

    fn deflects_joints(&self, robot: &Robot) -> bool {
        robot.family_values(KEY).is_some()
    }

    fn add_joint_deflection(&self, robot: &Robot, rigid: &super::RigidPose, dq: &mut [f64]) {
        let Some(v) = robot.family_values(KEY) else {
            return;
        };
        let n = robot.dof();
        let q = &rigid.commanded;
        let count = v[COUNT] as usize;
        for i in (0..n).filter(|&i| v[FLAGS + i] == 1.0) {
            let terms = harmonic_terms(q[i], count);
            for (h, &(s, c)) in terms.iter().enumerate().take(count) {
                dq[i] += v[slot(n, i, h, false)] * c + v[slot(n, i, h, true)] * s;
            }
        }
    }
}

/// Makes the first `harmonics` harmonics (1..=[`MAX_HARMONICS`]; 0 removes the family) of the
/// angle error of every revolute joint in `joints` (0-based) parameters of `robot`, at zero.
pub fn enable(robot: &mut Robot, joints: &[usize], harmonics: usize) -> Result<()> {
    if harmonics == 0 || joints.is_empty() {
        return robot.set_family_values(KEY, None);
    }
    if harmonics > MAX_HARMONICS {
        return Err(Error::invalid(
            "harmonics",
            format!("{harmonics}: at most {MAX_HARMONICS} harmonics per joint"),
        ));
    }
    let n = robot.dof();
    let mut v = vec![0.0; store_len(n)];
    v[COUNT] = harmonics as f64;
    for &i in joints {
        if i >= n {
            return Err(Error::invalid(
                "harmonics",
                format!("joint {} does not exist (robot has {n})", i + 1),
            ));
        }
        if robot.joint_type(i) == JointType::Revolute {
            v[FLAGS + i] = 1.0;
        }
    }
    robot.set_family_values(KEY, Some(v))
}

/// The number of harmonics `robot` models (0 without the family).
pub fn harmonics(robot: &Robot) -> usize {
    robot.family_values(KEY).map_or(0, |v| v[COUNT] as usize)
}
