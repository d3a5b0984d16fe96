//! The result's `robot` key: which robot a result belongs to, and, since results became
//! self-contained, its whole nominal description, with the checks that a robot given beside a
//! result is the one it was made for.

use crate::error::{Error, Result};
use crate::model::description::{ControllerDescription, JointDescription, RobotDescription};
use crate::model::{Convention, JointType, Robot};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Which robot a result belongs to (the `robot` key): its name, shape and, in results written
/// since results became self-contained, its whole nominal description (DESIGN.md "Result JSON
/// additions"): the robot file's keys `base`, `tool`, `tool_correction`, `joints` and
/// `controller` (see [`RobotDescription`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotInfo {
    /// The robot's name.
    pub name: String,
    /// Number of joints.
    pub dof: usize,
    /// `"mdh"` or `"dh"`.
    pub convention: String,
    /// Each joint's type, `"revolute"` or `"prismatic"`. Empty (absent) in files written before
    /// joint types existed: all revolute.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_types: Vec<JointType>,
    /// The base frame vector B (mm, deg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<[f64; 6]>,
    /// The nominal tool vector T0 (mm, deg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<[f64; 6]>,
    /// The nominal model's tool correction T (mm, deg), when not zero.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_correction: Option<[f64; 6]>,
    /// The nominal tool vectors of every target (mm, deg), when the robot carries several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tools: Option<Vec<[f64; 6]>>,
    /// The direction of gravity in the base frame, when not the default `[0, 0, -1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity: Option<[f64; 3]>,
    /// The joints as the robot file gives them; empty (absent) in results that do not embed
    /// their robot.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointDescription>,
    /// The controller's axis map, if the robot has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerDescription>,
}

impl RobotInfo {
    /// The name and shape of `robot` without its description (what a simulation's truth file
    /// records).
    pub fn shape_of(robot: &Robot) -> RobotInfo {
        RobotInfo {
            name: robot.name().to_owned(),
            dof: robot.dof(),
            convention: robot.convention().as_str().to_owned(),
            joint_types: robot.joint_types().to_vec(),
            base: None,
            tool: None,
            tool_correction: None,
            tools: None,
            gravity: None,
            joints: Vec::new(),
            controller: None,
        }
    }

    /// The description of `robot`, embedded whole.
    pub fn of(robot: &Robot) -> RobotInfo {
        let d = RobotDescription::of(robot);
        RobotInfo {
            name: d.name,
            dof: robot.dof(),
            convention: d.convention.as_str().to_owned(),
            joint_types: robot.joint_types().to_vec(),
            base: Some(d.base),
            tool: Some(d.tool),
            tool_correction: d.tool_correction,
            tools: d.tools,
            gravity: d.gravity,
            joints: d.joints,
            controller: d.controller,
        }
    }

    /// The embedded robot description, if the result has one (`joints` present).
    pub fn description(&self) -> Option<RobotDescription> {
        if self.joints.is_empty() {
            return None;
        }
        let convention = match self.convention.as_str() {
            "mdh" => Convention::Mdh,
            "dh" => Convention::Dh,
            _ => return None,
        };
        Some(RobotDescription {
            name: self.name.clone(),
            convention,
            base: self.base.unwrap_or_default(),
            tool: self.tool.unwrap_or_default(),
            tool_correction: self.tool_correction,
            tools: self.tools.clone(),
            gravity: self.gravity,
            joints: self.joints.clone(),
            controller: self.controller.clone(),
        })
    }

    /// The nominal robot the result embeds, if it does (`Ok(None)` for results written before
    /// results embedded their robot). The description is checked as a robot file would be;
    /// errors name `path`, the field under `robot` and, given the JSON `text`, the line of that
    /// field.
    pub fn nominal_robot(&self, path: &Path, text: Option<&str>) -> Result<Option<Robot>> {
        let line = |field: &str| text.and_then(|t| crate::io::json_keys::line_of_key(t, field));
        let bad = |field: &str, msg: String| Error::parse(path, line(field), Some(field), msg);
        if self.joints.is_empty() {
            return Ok(None);
        }
        let Some(d) = self.description() else {
            return Err(bad(
                "robot.convention",
                format!(
                    "`{}` is not a convention: use \"mdh\" or \"dh\"",
                    self.convention
                ),
            ));
        };
        // `dof` and `joint_types` are checked against the robot used, this one included, by
        // `calibrated_robot`.
        let robot = d.to_robot(path).map_err(|e| match e {
            Error::Parse {
                path,
                field,
                message,
                ..
            } => {
                let field = field.map_or("robot".to_owned(), |f| format!("robot.{f}"));
                // The robot file's 1-based joint and row numbers are 0-based in the key path.
                let line = line(&zero_based(&field)).or_else(|| line("robot"));
                Error::Parse {
                    path,
                    line,
                    field: Some(field),
                    message,
                }
            }
            other => other,
        })?;
        Ok(Some(robot))
    }

    /// Checks that the joint types match `robot`'s (an absent list means all revolute); `what`
    /// describes the file's robot in the message. The error names the field `robot.joint_types`.
    pub fn check_joint_types(&self, robot: &Robot, path: &Path, what: &str) -> Result<()> {
        let mine = robot.joint_types();
        let same = if self.joint_types.is_empty() {
            mine.iter().all(|t| *t == JointType::Revolute)
        } else {
            self.joint_types == mine
        };
        if same {
            return Ok(());
        }
        let list = |v: &[JointType]| v.iter().map(|t| t.as_str()).collect::<Vec<_>>().join(", ");
        let theirs = if self.joint_types.is_empty() {
            "all revolute".to_owned()
        } else {
            list(&self.joint_types)
        };
        Err(Error::parse(
            path,
            None,
            Some("robot.joint_types"),
            format!(
                "{what} has joints {theirs}; the robot given ({}) has {}",
                robot.name(),
                list(mine)
            ),
        ))
    }
}

/// A robot-file field (`robot.joints[2].alpha`, `robot.controller.sign[1]`) as a JSON key path
/// (`robot.joints[1].alpha`): the robot file counts joints and entries from 1, except in the
/// frame vectors (`base[3]`).
fn zero_based(field: &str) -> String {
    if field.starts_with("robot.base[")
        || field.starts_with("robot.tool[")
        || field.starts_with("robot.tool_correction[")
    {
        return field.to_owned();
    }
    let mut out = String::with_capacity(field.len());
    let mut rest = field;
    while let Some(open) = rest.find('[') {
        out.push_str(&rest[..=open]);
        rest = &rest[open + 1..];
        let close = rest.find(']').unwrap_or(rest.len());
        match rest[..close].parse::<usize>() {
            Ok(n) if n > 0 => out.push_str(&(n - 1).to_string()),
            _ => out.push_str(&rest[..close]),
        }
        rest = &rest[close..];
    }
    out.push_str(rest);
    out
}
