//! Joint compliance under gravity: each compliant joint turns by its compliance times the
//! gravity torque about its axis (an elasto-geometric model; the paper's introduction names
//! "joint and link deflections caused by gravity and payload" and leaves them out).
//!
//! # Model
//! The masses of the links are unknown to most users, so the torque is not computed from a mass
//! model: the weight of the arm is lumped at the origins of the joints' axis frames and at the
//! tool point, and the data identify, per compliant joint `j` and lumped point `k` beyond it,
//! one coefficient `grav{j}_o{k}` (compliance times lumped mass times g, µrad per metre of lever)
//! such that
//!
//! ```text
//! dq_j = sum_k grav{j}_o{k} * lever_jk(q) + grav{j}_tool * lever_j,tool(q)
//! lever_jk(q) = u_j . ((r_k - o_j) x g^)      (mm; u_j, o_j joint j's axis, r_k the point,
//!                                               g^ the robot's gravity direction)
//! ```
//!
//! with every point and axis taken at the commanded joints `q` of the robot's own geometry (the
//! torque changes with the deflection only at second order). A point mass between two such
//! points (the simulator's links, [`crate::simulation::GravityModel`]) is two lumped masses, so
//! this basis describes that physics exactly ([`crate::simulation::GravityModel::equivalent`]).
//!
//! Given the payload `M` (kg) the data were measured with, the tool-point coefficient becomes a
//! physical compliance `compliance{j}` (µrad/(N·m)): `dq_j += c_j * M * g * lever_j,tool / 1000`,
//! and the model predicts the deflection at another payload ([`set_payload_kg`]); the arm's own
//! share at the tool point is then folded into `c_j` (a few percent of a heavy payload).
//!
//! Prismatic joints are rigid along their axes (as in the simulator) and take no part. Which
//! coefficients the data can separate is the identifiability analysis's job: coincident points
//! (a spherical wrist), points on the joint's own axis and the tool point of a tool on the last
//! axis give duplicate or zero columns, fixed with their reasons.

use super::{put, FamilyId, ParameterFamily, PoseFrames, RigidPose};
use crate::error::{Error, Result};
use crate::model::{JointType, Param, Robot, Unit, MAX_JOINTS};
use nalgebra::Vector3;

/// The family's key in the robot's family store.
pub const KEY: &str = "compliance";
/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(5);
/// Standard gravity (m/s²), the `g` of the physical compliance.
pub const G0: f64 = 9.80665;

/// Template of the tool point's lumped coefficient (no payload given).
const TOOL: usize = MAX_JOINTS;
/// Template of the physical compliance (payload given).
const COMPLIANCE: usize = MAX_JOINTS + 1;

static TEMPLATES: [&str; MAX_JOINTS + 2] = [
    "grav{j}_o1",
    "grav{j}_o2",
    "grav{j}_o3",
    "grav{j}_o4",
    "grav{j}_o5",
    "grav{j}_o6",
    "grav{j}_o7",
    "grav{j}_o8",
    "grav{j}_o9",
    "grav{j}_o10",
    "grav{j}_o11",
    "grav{j}_o12",
    "grav{j}_o13",
    "grav{j}_o14",
    "grav{j}_o15",
    "grav{j}_o16",
    "grav{j}_tool",
    "compliance{j}",
];

// Store layout: [mode (0 lumped, 1 physical), payload kg, enabled flag per joint, then per joint
// i the n + 1 coefficient slots (origin of axis frame k = 0..n, then the tool point)].
const MODE: usize = 0;
const PAYLOAD: usize = 1;
const FLAGS: usize = 2;

fn slot(n: usize, i: usize, k: usize) -> usize {
    FLAGS + n + i * (n + 1) + k
}

fn store_len(n: usize) -> usize {
    FLAGS + n + n * (n + 1)
}

/// The joint compliance family (see the module docs).
pub struct Compliance;

/// Whether the payload is known (the tool-point slot is a physical compliance).
fn physical(v: &[f64]) -> bool {
    v[MODE] == 1.0
}

/// The coefficient slots that are parameters, in [`Param`] order: (param, joint, slot k).
fn each_param(robot: &Robot, mut f: impl FnMut(Param, usize, usize)) {
    let Some(v) = robot.family_values(KEY) else {
        return;
    };
    let n = robot.dof();
    let on = |i: usize| v[FLAGS + i] == 1.0;
    for k in 1..n {
        for i in (0..k).filter(|&i| on(i)) {
            f(Param::new(ID, k as u8, i as u16), i, k);
        }
    }
    let t = if physical(v) { COMPLIANCE } else { TOOL };
    for i in (0..n).filter(|&i| on(i)) {
        f(Param::new(ID, t as u8, i as u16), i, n);
    }
}

/// The store slot of parameter `p` on a robot with `n` joints.
fn slot_of(n: usize, p: Param) -> usize {
    let k = match p.template() {
        TOOL | COMPLIANCE => n,
        k => k,
    };
    slot(n, p.index(), k)
}

/// Joint `i`'s lever of every point (mm): `u_i . ((r - o_i) x g)`; entry `k` for the origin of
/// axis frame k (k < n), entry `n` for the tool point, at the commanded joints (the rigid axes
/// and point of `frames`).
fn levers_on(robot: &Robot, rigid: &RigidPose, i: usize) -> [f64; MAX_JOINTS + 1] {
    let n = robot.dof();
    let g = robot.gravity();
    let (u, o) = rigid.axes[i];
    let lever = |r: &Vector3<f64>| u.dot(&(r - o).cross(&g));
    let mut out = [0.0; MAX_JOINTS + 1];
    for k in i + 1..n {
        out[k] = lever(&rigid.axes[k].1);
    }
    out[n] = lever(&rigid.point);
    out
}

/// The longest lever (mm) lumped point `k` (the origin of axis frame k; `k = n`: the tool
/// point) can have about joint `i`: the lengths of the links between them (and the tool's), at
/// least 1 mm. A coefficient's plausible range is one degree of deflection at this lever.
pub fn lever_bound_mm(robot: &Robot, i: usize, k: usize) -> f64 {
    let n = robot.dof();
    let links: f64 = robot.links()[i.min(n)..(k + 1).min(n)]
        .iter()
        .map(|l| l.a.abs() + l.d.abs())
        .sum();
    let tool = if k >= n {
        let t = robot.target_tool0(0);
        (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt()
    } else {
        0.0
    };
    (links + tool).max(1.0)
}

/// N·m of torque per mm of lever of the payload's weight (physical mode), else 1.
fn tool_scale(v: &[f64]) -> f64 {
    if physical(v) {
        v[PAYLOAD] * G0 * 1e-3
    } else {
        1.0
    }
}

impl ParameterFamily for Compliance {
    fn key(&self) -> &'static str {
        KEY
    }

    fn templates(&self) -> &'static [&'static str] {
        &TEMPLATES
    }

    fn unit(&self, p: Param) -> Unit {
        if p.template() == COMPLIANCE {
            Unit::MicroradPerNm
        } else {
            Unit::MicroradPerM
        }
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        each_param(robot, |p, _, _| out.push(p));
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot
            .family_values(KEY)
            .map_or(0.0, |v| v[slot_of(robot.dof(), p)])
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        let s = slot_of(robot.dof(), p);
        if let Some(v) = robot.family_values_mut(KEY) {
            v[s] = value;
        }
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        super::priority::NON_GEOMETRIC + 100 * p.index() as u32 + p.template() as u32
    }

    /// One degree of joint deflection at the longest lever the coefficient's point can have
    /// about its joint ([`lever_bound_mm`]): a lumped coefficient of either sign (a
    /// counterbalance or a lumped point beyond a mass can turn the lever); a physical compliance,
    /// never negative, also at most [`super::plausible::COMPLIANCE_MAX_URAD_PER_NM`].
    fn plausible(&self, robot: &Robot, p: Param) -> super::plausible::Plausible {
        use super::plausible::{Plausible, COMPLIANCE_MAX_URAD_PER_NM, JOINT_DEFLECTION_DEG};
        let n = robot.dof();
        let k = match p.template() {
            TOOL | COMPLIANCE => n,
            k => k,
        };
        let lever_mm = lever_bound_mm(robot, p.index(), k);
        let deflection = JOINT_DEFLECTION_DEG.to_radians();
        if p.template() != COMPLIANCE {
            return Plausible {
                individual: false,
                ..Plausible::moving(
                    Unit::MicroradPerM.from_internal(deflection / lever_mm),
                    "1 degree of joint deflection at the longest lever of its point",
                )
            };
        }
        let torque_nm = payload_kg(robot).unwrap_or(0.0) * G0 * lever_mm / 1000.0;
        let by_deflection = Unit::MicroradPerNm.from_internal(deflection / torque_nm);
        let max = COMPLIANCE_MAX_URAD_PER_NM.min(by_deflection);
        Plausible {
            max_move: max,
            min: 0.0,
            max,
            why: if max < COMPLIANCE_MAX_URAD_PER_NM {
                "never negative, at most 1 degree of deflection under the payload"
            } else {
                "never negative, at most 1e-3 rad per N·m"
            },
            individual: true,
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
            .map_or_else(|| vec![0.0; store_len(n)], <[f64]>::to_vec);
        v[FLAGS + i] = 1.0;
        if p.template() == COMPLIANCE {
            v[MODE] = 1.0;
        }
        robot.set_family_values(KEY, Some(v))
    }

    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let Some(v) = robot.family_values(KEY) else {
            return;
        };
        let n = robot.dof();
        let scale = tool_scale(v);
        let mut cache: [Option<[f64; MAX_JOINTS + 1]>; MAX_JOINTS] = [None; MAX_JOINTS];
        let mut k_out = 0;
        each_param(robot, |_, i, k| {
            let l = *cache[i].get_or_insert_with(|| levers_on(robot, &pose.rigid, i));
            let b = if k == n { l[n] * scale } else { l[k] };
            let (sv, sw) = pose.joint_screw(robot, i);
            dp[k_out] = sv * b;
            put(&mut dw, k_out, sw * b);
            k_out += 1;
        });
    }

    fn deflects_joints(&self, robot: &Robot) -> bool {
        robot.family_values(KEY).is_some()
    }

    fn add_joint_deflection(&self, robot: &Robot, rigid: &RigidPose, dq: &mut [f64]) {
        let Some(v) = robot.family_values(KEY) else {
            return;
        };
        let n = robot.dof();
        let scale = tool_scale(v);
        for (i, d) in dq.iter_mut().enumerate().take(n) {
            if v[FLAGS + i] != 1.0 {
                continue;
            }
            let l = levers_on(robot, rigid, i);
            let mut s: f64 = (i + 1..n).map(|k| v[slot(n, i, k)] * l[k]).sum();
            s += v[slot(n, i, n)] * l[n] * scale;
            *d += s;
        }
    }
}

/// Makes joint compliance a part of `robot`'s model on `joints` (0-based, revolute; an empty
/// list removes it). With `payload_kg` (the payload the measurements were taken with, > 0) the
/// tool-point coefficients are physical compliances (`compliance{j}`); without, lumped
/// coefficients (`grav{j}_tool`). Every coefficient starts at zero.
pub fn enable(robot: &mut Robot, joints: &[usize], payload_kg: Option<f64>) -> Result<()> {
    let n = robot.dof();
    if joints.is_empty() {
        return robot.set_family_values(KEY, None);
    }
    let mut v = vec![0.0; store_len(n)];
    for &i in joints {
        if i >= n {
            return Err(Error::invalid(
                "compliance",
                format!("joint {} does not exist (robot has {n})", i + 1),
            ));
        }
        if robot.joint_type(i) != JointType::Revolute {
            return Err(Error::invalid(
                "compliance",
                format!(
                    "joint {} is prismatic: it is rigid along its axis (only revolute joints \
                     turn under a gravity torque)",
                    i + 1
                ),
            ));
        }
        v[FLAGS + i] = 1.0;
    }
    if let Some(m) = payload_kg {
        check_payload(m)?;
        v[MODE] = 1.0;
        v[PAYLOAD] = m;
    }
    robot.set_family_values(KEY, Some(v))
}

fn check_payload(m: f64) -> Result<()> {
    crate::ranges::in_range("payload_kg", m, &crate::ranges::MASS)?;
    if m <= 0.0 {
        return Err(Error::invalid(
            "payload_kg",
            format!(
                "{m} kg: a payload of 0 kg leaves the joint compliances unobservable; leave \
                 `payload_kg` out to identify lumped coefficients instead"
            ),
        ));
    }
    Ok(())
}

/// The joints (0-based) `robot` models as compliant.
pub fn joints(robot: &Robot) -> Vec<usize> {
    robot.family_values(KEY).map_or_else(Vec::new, |v| {
        (0..robot.dof()).filter(|&i| v[FLAGS + i] == 1.0).collect()
    })
}

/// The payload (kg) the model's deflection is evaluated at, when the tool-point coefficients are
/// physical compliances; `None` without the family or with lumped coefficients.
pub fn payload_kg(robot: &Robot) -> Option<f64> {
    robot
        .family_values(KEY)
        .filter(|v| physical(v))
        .map(|v| v[PAYLOAD])
}

/// Evaluates the model at another payload (kg, >= 0): the deflection of a calibration made with
/// its payload known at the payload now carried. An error when the model has no physical
/// compliances (a calibration that did not know its payload cannot tell the payload's share).
pub fn set_payload_kg(robot: &mut Robot, kg: f64) -> Result<()> {
    crate::ranges::in_range("payload_kg", kg, &crate::ranges::MASS)?;
    if kg < 0.0 {
        return Err(Error::invalid("payload_kg", format!("{kg} kg is negative")));
    }
    match robot.family_values_mut(KEY) {
        Some(v) if physical(v) => {
            v[PAYLOAD] = kg;
            Ok(())
        }
        _ => Err(Error::invalid(
            "payload_kg",
            format!(
                "robot `{}` has no joint compliance identified at a known payload: the payload \
                 can only be changed for a calibration given `payload_kg`",
                robot.name()
            ),
        )),
    }
}

/// The revolute joints (0-based) whose axis is not parallel to gravity in every configuration:
/// the joints a gravity torque can turn. Tested at a fixed set of configurations spread over the
/// joint limits (a joint whose axis is vertical at all of them, like a floor robot's first axis,
/// never carries a gravity torque).
pub fn auto_joints(robot: &Robot) -> Vec<usize> {
    let n = robot.dof();
    let g = robot.gravity();
    let mut tilted = vec![false; n];
    for s in 0..12 {
        let q: Vec<f64> = robot
            .limits()
            .iter()
            .enumerate()
            .map(|(i, l)| {
                // A low-discrepancy point per joint within the limits (at most one turn wide).
                let f = ((s as f64 + 0.5) * 0.618_033_988_75 * (i as f64 + 1.0)).fract();
                let lo = l.min.max(-std::f64::consts::PI);
                let hi = l.max.min(std::f64::consts::PI).max(lo);
                lo + f * (hi - lo)
            })
            .collect();
        for (i, (u, _)) in robot.joint_axes(&q).iter().enumerate() {
            if u.cross(&g).norm() > 1e-6 {
                tilted[i] = true;
            }
        }
    }
    (0..n)
        .filter(|&i| tilted[i] && robot.joint_type(i) == JointType::Revolute)
        .collect()
}

/// Joint `i`'s gravity lever of every lumped point at the commanded joints `q` (mm): entry `k`
/// for the origin of axis frame `k` (zero for `k <= i`), entry `dof` for the tool point.
pub fn lever_arms(robot: &Robot, q: &[f64], i: usize) -> Vec<f64> {
    levers_on(robot, &robot.rigid_pose(q), i)[..=robot.dof()].to_vec()
}

/// Sets the coefficient of joint `i` (0-based) for lumped point `k` (the origin of axis frame
/// `k`, or the tool point for `k = dof`) in internal units (rad per mm of lever; for the tool
/// point in physical mode, rad/(N·m)). For building a model of known physics.
pub fn set_coefficient(robot: &mut Robot, i: usize, k: usize, value: f64) {
    let n = robot.dof();
    if let Some(v) = robot.family_values_mut(KEY) {
        v[slot(n, i, k)] = value;
    }
}

#[cfg(test)]
#[path = "compliance_tests.rs"]
mod tests;
