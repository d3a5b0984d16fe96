//! A robot description as plain data: the schema of the TOML robot file ([`super::robot_file`])
//! without its source positions, for files that carry a robot inside them (the result JSON's
//! `robot`, DESIGN.md "Result JSON additions": a result is self-contained).
//!
//! [`RobotDescription::of`] writes a [`Robot`] in the robot file's units (degrees and mm), each
//! angle chosen so that it converts back to exactly the stored radians; [`RobotDescription::to_robot`]
//! builds the robot through the robot file's own parser, so both forms obey one set of rules and
//! the rebuilt robot equals the original.

use super::{Convention, JointType, Param, Robot};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// One joint, as a `[[joints]]` table of the robot file (degrees, mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Revolute or prismatic.
    #[serde(rename = "type", default)]
    pub kind: JointType,
    /// Twist alpha (deg).
    pub alpha: f64,
    /// Offset d (mm).
    pub d: f64,
    /// Length a (mm).
    pub a: f64,
    /// Joint offset phi (deg).
    #[serde(default)]
    pub phi: f64,
    /// Hayati tilt beta (deg); present exactly when beta is a parameter of the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub beta: Option<f64>,
    /// `[min, max]` in model joint values (deg, or mm for a prismatic joint).
    pub limits: [f64; 2],
}

/// The `[controller]` section: `q_i = sign_i axis_i + offset_i + sum of k axis_j` over the
/// coupling rows `[i, j, k]` (1-based joint numbers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerDescription {
    /// +1 or -1 per joint.
    pub sign: Vec<f64>,
    /// Offsets (deg, or mm for a prismatic joint), one per joint.
    pub offset: Vec<f64>,
    /// Rows `[i, j, k]`: joint i gets k times axis j (1-based).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub coupling: Vec<(usize, usize, f64)>,
}

/// A whole robot description: the robot file's keys, plus `tool_correction` (the tool
/// correction T of a robot whose nominal model already carries one, such as the
/// `kuka-kr480-r3330-table3` preset).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotDescription {
    /// The robot's name.
    pub name: String,
    /// The parameter table's convention.
    pub convention: Convention,
    /// The base frame vector B (mm, deg).
    pub base: [f64; 6],
    /// The nominal tool vector T0 (mm, deg).
    pub tool: [f64; 6],
    /// The tool correction T (mm, deg), when not zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_correction: Option<[f64; 6]>,
    /// The nominal tool vectors of every target (mm, deg; the first is `tool`), when the robot
    /// carries several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tools: Option<Vec<[f64; 6]>>,
    /// The direction of gravity in the base frame, when not the default `[0, 0, -1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// The joints, base to tip.
    pub joints: Vec<JointDescription>,
    /// The controller's axis map, if the robot has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerDescription>,
}

/// The degrees whose conversion to radians ([`f64::to_radians`], what every reader uses) gives
/// exactly `rad`, the shortest in decimal of those near `rad.to_degrees()` (so that -90 deg read
/// from a robot file is written as -90, not -89.99999999999999); `rad.to_degrees()` when none
/// converts back exactly (possible only for angles that were never read from degrees).
///
/// Degrees to radians is a multiplication by a constant below 1, so several doubles map to one
/// and some radians are the image of none: a search over a few neighbouring doubles settles it.
fn exact_degrees(rad: f64) -> f64 {
    let d = rad.to_degrees();
    if !d.is_finite() || d == 0.0 {
        return d;
    }
    let bits = d.to_bits();
    let mut best: Option<(usize, u64, f64)> = None;
    for k in 0..=8u64 {
        for b in [bits.wrapping_add(k), bits.wrapping_sub(k)] {
            let c = f64::from_bits(b);
            if c.to_radians() != rad {
                continue;
            }
            let key = (c.to_string().len(), k);
            match best {
                Some((len, dist, _)) if (len, dist) <= key => {}
                _ => best = Some((key.0, key.1, c)),
            }
        }
    }
    best.map_or(d, |(_, _, c)| c)
}

/// A frame vector (mm, rad) in mm and degrees, exactly invertible (see [`exact_degrees`]).
fn frame_degrees(v: &[f64; 6]) -> [f64; 6] {
    let mut out = *v;
    for x in &mut out[3..] {
        *x = exact_degrees(*x);
    }
    out
}

impl RobotDescription {
    /// The description of `robot` (its nominal state as it stands: table, betas, limits, base,
    /// tool T0 and correction T, controller map).
    pub fn of(robot: &Robot) -> RobotDescription {
        let joints = robot
            .links()
            .iter()
            .zip(robot.limits())
            .enumerate()
            .map(|(i, (l, lim))| {
                let kind = robot.joint_type(i);
                let limit = |v: f64| match kind {
                    JointType::Revolute => exact_degrees(v),
                    JointType::Prismatic => v,
                };
                JointDescription {
                    kind,
                    alpha: exact_degrees(l.alpha),
                    d: l.d,
                    a: l.a,
                    phi: exact_degrees(l.phi),
                    beta: robot.beta_enabled(i).then(|| exact_degrees(l.beta)),
                    limits: [limit(lim.min), limit(lim.max)],
                }
            })
            .collect();
        let correction = robot.tool_correction();
        RobotDescription {
            name: robot.name().to_owned(),
            convention: robot.convention(),
            base: frame_degrees(robot.base()),
            tool: frame_degrees(robot.tool0()),
            tool_correction: correction
                .iter()
                .any(|v| *v != 0.0)
                .then(|| frame_degrees(correction)),
            tools: (robot.target_count() > 1)
                .then(|| robot.target_tools0().iter().map(frame_degrees).collect()),
            gravity: {
                let g = robot.gravity();
                (g != nalgebra::Vector3::new(0.0, 0.0, -1.0)).then(|| [g.x, g.y, g.z])
            },
            joints,
            controller: robot.controller().map(|c| ControllerDescription {
                sign: c.sign().to_vec(),
                offset: c.offset().to_vec(),
                coupling: c
                    .coupling()
                    .iter()
                    .map(|k| (k.joint + 1, k.axis + 1, k.factor))
                    .collect(),
            }),
        }
    }

    /// The description as the text of a TOML robot file.
    pub fn to_toml(&self) -> Result<String> {
        toml::to_string(self)
            .map_err(|e| Error::invalid("robot", format!("cannot write as TOML: {e}")))
    }
}

/// How far two nominal values (mm or degrees) may differ in [`nominal_difference`]: descriptions
/// round-trip exactly, so this only forgives the last digits of a hand-written robot file.
pub const NOMINAL_TOLERANCE: f64 = 1e-9;

/// The first difference between two nominal robots that makes a result of one wrong for the
/// other, or `None`: joint count, joint types, convention, every nominal parameter (and the
/// nominal tool T0) within [`NOMINAL_TOLERANCE`] (mm or degrees), the gravity direction, the
/// controller map. Names and
/// joint limits may differ.
pub fn nominal_difference(a: &Robot, b: &Robot) -> Option<String> {
    if a.dof() != b.dof() {
        return Some(format!("{} joints against {}", a.dof(), b.dof()));
    }
    if let Some(i) = (0..a.dof()).find(|&i| a.joint_type(i) != b.joint_type(i)) {
        return Some(format!(
            "joint {} is {} against {}",
            i + 1,
            a.joint_type(i).as_str(),
            b.joint_type(i).as_str()
        ));
    }
    if a.convention() != b.convention() {
        return Some(format!(
            "convention {} against {}",
            a.convention().as_str(),
            b.convention().as_str()
        ));
    }
    let close = |x: f64, y: f64| (x - y).abs() <= NOMINAL_TOLERANCE;
    let mut params = a.params();
    params.extend(b.params().into_iter().filter(|p| !a.has_param(*p)));
    for p in params {
        let (x, y) = (a.get_display_or_zero(p), b.get_display_or_zero(p));
        if !close(x, y) {
            let u = p.unit().as_str();
            return Some(format!("nominal {} = {x} {u} against {y} {u}", p.name()));
        }
    }
    let (ga, gb) = (a.gravity(), b.gravity());
    if (ga - gb).amax() > NOMINAL_TOLERANCE {
        return Some(format!(
            "gravity [{}, {}, {}] against [{}, {}, {}]",
            ga.x, ga.y, ga.z, gb.x, gb.y, gb.z
        ));
    }
    if a.target_count() != b.target_count() {
        return Some(format!(
            "{} targets (tool vectors) against {}",
            a.target_count(),
            b.target_count()
        ));
    }
    for t in 0..a.target_count() {
        let (ta, tb) = (
            frame_degrees(a.target_tool0(t)),
            frame_degrees(b.target_tool0(t)),
        );
        for (k, axis) in ["x", "y", "z", "a", "b", "c"].iter().enumerate() {
            if !close(ta[k], tb[k]) {
                let u = Param::tool(k).unit().as_str();
                let which = if t == 0 {
                    "tool T0".to_string()
                } else {
                    format!("tool of target {}", t + 1)
                };
                return Some(format!(
                    "nominal {which} {axis} = {} {u} against {} {u}",
                    ta[k], tb[k]
                ));
            }
        }
    }
    let map = |r: &Robot| {
        r.controller()
            .cloned()
            .unwrap_or_else(|| super::Controller::identity(r.dof()))
    };
    let (ca, cb) = (map(a), map(b));
    for i in 0..a.dof() {
        if ca.sign()[i] != cb.sign()[i] {
            return Some(format!(
                "controller sign of joint {} is {} against {}",
                i + 1,
                ca.sign()[i],
                cb.sign()[i]
            ));
        }
        if !close(ca.offset()[i], cb.offset()[i]) {
            return Some(format!(
                "controller offset of joint {} is {} against {}",
                i + 1,
                ca.offset()[i],
                cb.offset()[i]
            ));
        }
    }
    let (ma, mb) = (ca.matrix(), cb.matrix());
    for i in 0..a.dof() {
        for j in 0..a.dof() {
            if i != j && !close(ma[(i, j)], mb[(i, j)]) {
                return Some(format!(
                    "controller coupling of joint {} with axis {} is {} against {}",
                    i + 1,
                    j + 1,
                    ma[(i, j)],
                    mb[(i, j)]
                ));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests;
