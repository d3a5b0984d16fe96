//! TOML robot descriptions, parsed from text (reading the file, and the `--robot NAME|FILE`
//! argument, are [`crate::io::robot`]'s).
//!
//! ```toml
//! name = "ur5"
//! convention = "dh"            # "mdh" (Craig, the paper's Table I) or "dh" (standard)
//! base = [0, 0, 0, 0, 0, 0]    # optional frame vector x, y, z (mm), A, B, C (deg)
//! tool = [0, 0, 31, 0, 0, 0]   # nominal tool vector T0, same units (optional, default zero)
//! tool_correction = [0, 0, 0, 0, 0, 0]  # the tool correction T already in the nominal model
//!                              # (optional, default zero; what a result's embedded robot carries)
//! tools = [[0, 0, 31, 0, 0, 0], [40, 0, 25, 0, 0, 0]]  # several targets (reflectors): one
//!                              # nominal tool vector per `target` of the data (optional; the
//!                              # first is `tool`, which may then be left out)
//! gravity = [0, 0, -1]         # direction of gravity in the base frame (optional, default
//!                              # floor mounted; used by the joint compliance family)
//!
//! [[joints]]                   # one table per joint, base to tip
//! type = "revolute"            # or "prismatic" (optional, default revolute)
//! alpha = 90                   # deg
//! d = 89.159                   # mm (a prismatic joint's value adds to it)
//! a = 0                        # mm
//! phi = 0                      # deg, offset added to the joint value (a constant for a
//!                              # prismatic joint) (optional, default 0)
//! limits = [-360, 360]         # model joint values: deg, or mm for a prismatic joint
//!                              # (optional for a revolute joint, default [-360, 360])
//! beta = 0                     # deg, Hayati tilt (optional; giving it makes beta a parameter)
//!
//! [controller]                 # optional: controller axes -> model joints (see `controller`)
//! sign = [1, 1, -1, 1, 1, 1]   # +1 or -1 per joint (default all +1)
//! offset = [0, 0, 0, 0, 0, 0]  # deg, or mm for a prismatic joint (default all 0)
//! coupling = [[3, 2, -1.0]]    # rows [i, j, k]: q_i gets k * axis_j (1-based; default none)
//! ```

use super::{JointType, Param, Robot};
use crate::error::{Error, Result};
use fields::{FileText, JointTables};
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

mod controller;
mod fields;

/// A frame vector as written, with the spans of the vector and of each number.
type FrameEntry = Spanned<Vec<Spanned<f64>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    name: Option<String>,
    convention: Spanned<String>,
    base: Option<Spanned<Vec<Spanned<f64>>>>,
    tool: Option<Spanned<Vec<Spanned<f64>>>>,
    tool_correction: Option<Spanned<Vec<Spanned<f64>>>>,
    tools: Option<Spanned<Vec<FrameEntry>>>,
    gravity: Option<Spanned<Vec<Spanned<f64>>>>,
    joints: Vec<JointEntry>,
    controller: Option<Spanned<ControllerEntry>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointEntry {
    #[serde(rename = "type")]
    kind: Option<Spanned<String>>,
    alpha: Spanned<f64>,
    d: Spanned<f64>,
    a: Spanned<f64>,
    phi: Option<Spanned<f64>>,
    beta: Option<Spanned<f64>>,
    limits: Option<Spanned<Vec<Spanned<f64>>>>,
}

type Numbers = Spanned<Vec<Spanned<f64>>>;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ControllerEntry {
    sign: Option<Numbers>,
    offset: Option<Numbers>,
    coupling: Option<Spanned<Vec<Numbers>>>,
}

/// Default joint range (degrees) when a robot file gives none.
pub const DEFAULT_LIMIT_DEG: f64 = 360.0;

/// The 1-based line of byte `offset` of `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
        + 1
}

/// Parses a TOML robot description; `path` is only used in error messages.
pub fn parse_robot_toml(text: &str, path: &Path) -> Result<Robot> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file: RobotFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        let field = e.span().and_then(|s| {
            let start = text.get(..s.start)?.rfind('\n').map_or(0, |p| p + 1);
            let end = text[s.start..]
                .find('\n')
                .map_or(text.len(), |p| s.start + p);
            let l = &text[start..end];
            l.split_once('=')
                .map(|(k, _)| k.trim().to_owned())
                .filter(|k| !k.is_empty() && !k.starts_with('['))
        });
        Error::Parse {
            path: path.to_owned(),
            line,
            field,
            message: e.message().trim().to_owned(),
        }
    })?;
    build(file, text, path)
}

impl super::description::RobotDescription {
    /// Builds the robot, checked by the robot file's parser (every value within its range,
    /// limits ordered, prismatic joints with limits, an invertible controller map). Errors name
    /// `path` and the field as the robot file would (`joints[2].alpha`, `controller.sign`).
    pub fn to_robot(&self, path: &Path) -> Result<Robot> {
        from_description(self, path).map_err(Error::without_line)
    }
}

/// The robot of a description ([`super::description::RobotDescription::to_robot`]), checked as
/// its robot file would be: the description is handed to the file's checks directly, as the
/// parsed file it would read back as (every value at an empty span; the caller drops the
/// lines).
pub(super) fn from_description(
    d: &super::description::RobotDescription,
    path: &Path,
) -> Result<Robot> {
    let at = |v: f64| Spanned::new(0..0, v);
    let list = |v: &[f64]| Spanned::new(0..0, v.iter().map(|x| at(*x)).collect());
    let file = RobotFile {
        name: Some(d.name.clone()),
        convention: Spanned::new(0..0, d.convention.as_str().to_owned()),
        base: Some(list(&d.base)),
        tool: Some(list(&d.tool)),
        tool_correction: d.tool_correction.as_ref().map(|v| list(v)),
        tools: d
            .tools
            .as_ref()
            .map(|t| Spanned::new(0..0, t.iter().map(|v| list(v)).collect())),
        gravity: d.gravity.as_ref().map(|v| list(v)),
        joints: d
            .joints
            .iter()
            .map(|j| JointEntry {
                kind: Some(Spanned::new(0..0, j.kind.as_str().to_owned())),
                alpha: at(j.alpha),
                d: at(j.d),
                a: at(j.a),
                phi: Some(at(j.phi)),
                beta: j.beta.map(at),
                limits: Some(list(&j.limits)),
            })
            .collect(),
        controller: d.controller.as_ref().map(|c| {
            Spanned::new(
                0..0,
                ControllerEntry {
                    sign: Some(list(&c.sign)),
                    offset: Some(list(&c.offset)),
                    coupling: (!c.coupling.is_empty()).then(|| {
                        Spanned::new(
                            0..0,
                            c.coupling
                                .iter()
                                .map(|(i, j, k)| list(&[*i as f64, *j as f64, *k]))
                                .collect(),
                        )
                    }),
                },
            )
        }),
    };
    build(file, "", path)
}

/// Checks a parsed robot file (`text` is its text, for the lines in errors) and builds the robot.
fn build(file: RobotFile, text: &str, path: &Path) -> Result<Robot> {
    let at = FileText { text, path };
    let convention = fields::convention(&file.convention, &at)?;
    fields::check_joint_count(&file.joints, path)?;
    let base = at.frame_vector(&file.base, "base")?;
    let (tool0, tools) = fields::tools(&file.tool, &file.tools, &at)?;
    let tool_correction = at.frame_vector(&file.tool_correction, "tool_correction")?;
    let joints = JointTables::check(&file.joints, &at)?;
    let controller = match &file.controller {
        None => None,
        Some(c) => Some(controller::section(c, joints.types.len(), &at)?),
    };
    let name = fields::robot_name(file.name, path);
    let mut robot = fields::nominal_robot(name, convention, joints, base, tool0, controller, path)?;
    if tools.len() > 1 {
        robot.set_target_tools(&tools)?;
    }
    for (k, v) in tool_correction.into_iter().enumerate() {
        robot.set(Param::tool(k), v);
    }
    if let Some(g) = &file.gravity {
        fields::set_gravity(&mut robot, g, &at)?;
    }
    Ok(robot)
}

/// The unit of a joint type's values in messages: "degrees" or "mm".
fn unit_word(t: JointType) -> &'static str {
    match t {
        JointType::Revolute => "degrees",
        JointType::Prismatic => "mm",
    }
}

#[cfg(test)]
mod tests;
