//! The checks of a parsed robot file's fields, one function per field or section, in the order
//! [`super::build`] runs them (which decides which error a file with several gets).

use super::{line_of, unit_word, FrameEntry, JointEntry, DEFAULT_LIMIT_DEG};
use crate::error::{Error, Result};
use crate::model::controller::Controller;
use crate::model::{Convention, JointLimit, JointType, Link, Robot};
use crate::ranges;
use std::path::Path;
use toml::Spanned;

/// A robot file's text and path, for errors that name the line and the field.
pub(super) struct FileText<'a> {
    /// The file's text (empty for a description, whose values are all at an empty span).
    pub(super) text: &'a str,
    /// The file, named in errors.
    pub(super) path: &'a Path,
}

impl FileText<'_> {
    /// The parse error `msg` about `field`, on the line where `span` starts.
    pub(super) fn error(&self, span: std::ops::Range<usize>, field: String, msg: String) -> Error {
        Error::Parse {
            path: self.path.to_owned(),
            line: Some(line_of(self.text, span.start)),
            field: Some(field),
            message: msg,
        }
    }

    /// The number `v` if it is within `range`, else an error naming `field`.
    // Every number must be finite and within the plausible range of its kind (crate::ranges).
    pub(super) fn value(
        &self,
        v: &Spanned<f64>,
        field: String,
        range: &ranges::Range,
    ) -> Result<f64> {
        range
            .check(*v.get_ref())
            .map_err(|msg| self.error(v.span(), field, msg))
    }

    /// The length `v` (mm), checked as [`FileText::value`] does.
    fn length(&self, v: &Spanned<f64>, field: String) -> Result<f64> {
        self.value(v, field, &ranges::LENGTH)
    }

    /// The angle `v` (deg), checked as [`FileText::value`] does.
    fn angle(&self, v: &Spanned<f64>, field: String) -> Result<f64> {
        self.value(v, field, &ranges::ANGLE)
    }

    /// The frame vector `v` named `name` (x, y, z in mm, A, B, C in deg) with its angles in
    /// radians; zero if it is absent.
    pub(super) fn frame_vector(
        &self,
        v: &Option<Spanned<Vec<Spanned<f64>>>>,
        name: &str,
    ) -> Result<[f64; 6]> {
        let Some(v) = v else { return Ok([0.0; 6]) };
        if v.get_ref().len() != 6 {
            return Err(self.error(
                v.span(),
                name.into(),
                format!(
                    "expected 6 numbers [x, y, z, A, B, C] (mm, deg), got {}",
                    v.get_ref().len()
                ),
            ));
        }
        let mut out = [0.0; 6];
        for (k, x) in v.get_ref().iter().enumerate() {
            let range = if k < 3 {
                &ranges::LENGTH
            } else {
                &ranges::ANGLE
            };
            out[k] = self.value(x, format!("{name}[{k}]"), range)?;
        }
        Ok(crate::frame::vec_deg_to_rad(&out))
    }
}

/// The `convention` field's convention, or an error if it names none.
pub(super) fn convention(c: &Spanned<String>, at: &FileText) -> Result<Convention> {
    match c.get_ref().as_str() {
        "mdh" => Ok(Convention::Mdh),
        "dh" => Ok(Convention::Dh),
        other => Err(at.error(
            c.span(),
            "convention".into(),
            format!("`{other}` is not a convention: use \"mdh\" (modified DH, Craig) or \"dh\" (standard DH)"),
        )),
    }
}

/// An error unless the file has 1 to [`crate::model::MAX_JOINTS`] `[[joints]]` tables.
pub(super) fn check_joint_count(joints: &[JointEntry], path: &Path) -> Result<()> {
    if joints.is_empty() {
        return Err(Error::parse(
            path,
            None,
            Some("joints"),
            "no [[joints]] table: a robot needs at least one joint",
        ));
    }
    if joints.len() > crate::model::MAX_JOINTS {
        return Err(Error::parse(
            path,
            None,
            Some("joints"),
            format!(
                "{} joints; at most {} are supported",
                joints.len(),
                crate::model::MAX_JOINTS
            ),
        ));
    }
    Ok(())
}

/// The nominal tool vector T0 and the targets' tool vectors (empty without `tools`): `tool`
/// (zero if absent), or the first of `tools`, which must then equal `tool` if both are given.
pub(super) fn tools(
    tool: &Option<Spanned<Vec<Spanned<f64>>>>,
    list: &Option<Spanned<Vec<FrameEntry>>>,
    at: &FileText,
) -> Result<([f64; 6], Vec<[f64; 6]>)> {
    let mut tool0 = at.frame_vector(tool, "tool")?;
    let mut tools = Vec::new();
    if let Some(list) = list {
        if list.get_ref().is_empty() || list.get_ref().len() > crate::observations::MAX_TARGETS {
            return Err(at.error(
                list.span(),
                "tools".into(),
                format!(
                    "expected 1 to {} tool vectors, got {}",
                    crate::observations::MAX_TARGETS,
                    list.get_ref().len()
                ),
            ));
        }
        for (k, v) in list.get_ref().iter().enumerate() {
            tools.push(at.frame_vector(&Some(v.clone()), &format!("tools[{k}]"))?);
        }
        if tool.is_some() && tools[0] != tool0 {
            return Err(at.error(
                list.span(),
                "tools".into(),
                "the first of `tools` is the tool of target 1 and must equal `tool` (or leave \
                 `tool` out)"
                    .into(),
            ));
        }
        tool0 = tools[0];
    }
    Ok((tool0, tools))
}

/// The `[[joints]]` tables, checked: one link, limit and type per joint, and the joints that
/// give `beta` (0-based).
pub(super) struct JointTables {
    /// The links (rad, mm).
    pub(super) links: Vec<Link>,
    /// The limits in internal units (rad, mm).
    pub(super) limits: Vec<JointLimit>,
    /// The joint types.
    pub(super) types: Vec<JointType>,
    /// The joints whose Hayati tilt is a parameter.
    pub(super) betas: Vec<usize>,
}

impl JointTables {
    /// The checked tables, or the first error, joint by joint, field by field (type, phi,
    /// beta, alpha, d, a, limits).
    pub(super) fn check(joints: &[JointEntry], at: &FileText) -> Result<JointTables> {
        let mut tables = JointTables {
            links: Vec::with_capacity(joints.len()),
            limits: Vec::with_capacity(joints.len()),
            types: Vec::with_capacity(joints.len()),
            betas: Vec::new(),
        };
        for (i, j) in joints.iter().enumerate() {
            tables.push_joint(i, j, at)?;
        }
        Ok(tables)
    }

    /// Checks joint `i`'s table `j` and adds its type, link, limits (and beta).
    fn push_joint(&mut self, i: usize, j: &JointEntry, at: &FileText) -> Result<()> {
        let kind = joint_type(i, j, at)?;
        self.types.push(kind);
        let phi = match &j.phi {
            Some(v) => at.angle(v, joint_field(i, "phi"))?,
            None => 0.0,
        };
        let beta = match &j.beta {
            Some(v) => {
                self.betas.push(i);
                at.angle(v, joint_field(i, "beta"))?
            }
            None => 0.0,
        };
        self.links.push(Link {
            alpha: at.angle(&j.alpha, joint_field(i, "alpha"))?.to_radians(),
            d: at.length(&j.d, joint_field(i, "d"))?,
            a: at.length(&j.a, joint_field(i, "a"))?,
            phi: phi.to_radians(),
            beta: beta.to_radians(),
        });
        self.limits.push(joint_limits(i, j, kind, at)?);
        Ok(())
    }
}

/// The name of field `name` of joint `i` (0-based) in errors: `joints[2].alpha` (1-based).
fn joint_field(i: usize, name: &str) -> String {
    format!("joints[{}].{name}", i + 1)
}

/// Joint `i`'s type (default revolute), or an error if its `type` names none.
fn joint_type(i: usize, j: &JointEntry, at: &FileText) -> Result<JointType> {
    Ok(match &j.kind {
        None => JointType::Revolute,
        Some(k) => JointType::parse(k.get_ref()).ok_or_else(|| {
            at.error(
                k.span(),
                joint_field(i, "type"),
                format!(
                    "`{}` is not a joint type: use \"revolute\" or \"prismatic\"",
                    k.get_ref()
                ),
            )
        })?,
    })
}

/// Joint `i`'s limits in internal units: its `limits` (deg, or mm for a prismatic joint),
/// checked, or the default range of a revolute joint; a prismatic joint must give them.
fn joint_limits(i: usize, j: &JointEntry, kind: JointType, at: &FileText) -> Result<JointLimit> {
    let unit = kind.unit();
    let (min, max) = match &j.limits {
        None if kind == JointType::Prismatic => {
            return Err(Error::parse(
                at.path,
                j.kind.as_ref().map(|k| line_of(at.text, k.span().start)),
                Some(&joint_field(i, "limits")),
                "a prismatic joint needs its travel: limits = [min, max] in mm",
            ))
        }
        None => (-DEFAULT_LIMIT_DEG, DEFAULT_LIMIT_DEG),
        Some(l) => {
            if l.get_ref().len() != 2 {
                return Err(at.error(
                    l.span(),
                    joint_field(i, "limits"),
                    format!(
                        "expected [min, max] in {}, got {} numbers",
                        unit_word(kind),
                        l.get_ref().len()
                    ),
                ));
            }
            // Angles (deg, multi-turn axes allowed) or, for a prismatic joint, lengths (mm).
            let range = match kind {
                JointType::Revolute => &ranges::JOINT,
                JointType::Prismatic => &ranges::LENGTH,
            };
            let min = at.value(&l.get_ref()[0], joint_field(i, "limits"), range)?;
            let max = at.value(&l.get_ref()[1], joint_field(i, "limits"), range)?;
            if min > max {
                return Err(at.error(
                    l.span(),
                    joint_field(i, "limits"),
                    format!(
                        "min {min} {u} is greater than max {max} {u}",
                        u = unit.as_str()
                    ),
                ));
            }
            (min, max)
        }
    };
    Ok(JointLimit {
        min: unit.to_internal(min),
        max: unit.to_internal(max),
    })
}

/// The robot's name: `name`, else the file's stem, else "robot".
pub(super) fn robot_name(name: Option<String>, path: &Path) -> String {
    name.unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "robot".into())
    })
}

/// The robot of the checked fields: its table, limits, base and tool, joint types, controller
/// map and beta parameters (errors of the model's own checks name the file).
pub(super) fn nominal_robot(
    name: String,
    convention: Convention,
    joints: JointTables,
    base: [f64; 6],
    tool0: [f64; 6],
    controller: Option<Controller>,
    path: &Path,
) -> Result<Robot> {
    let mut robot = Robot::new(name, convention, joints.links, joints.limits, base, tool0)
        .map_err(|e| Error::parse(path, None, None, e.to_string()))?;
    robot
        .set_joint_types(joints.types)
        .and_then(|()| robot.set_controller(controller))
        .map_err(|e| Error::parse(path, None, None, e.to_string()))?;
    for i in joints.betas {
        robot.enable_beta(i)?;
    }
    Ok(robot)
}

/// Sets the robot's direction of gravity from the `gravity` field `g`, or an error on its line.
pub(super) fn set_gravity(
    robot: &mut Robot,
    g: &Spanned<Vec<Spanned<f64>>>,
    at: &FileText,
) -> Result<()> {
    let v: Vec<f64> = g.get_ref().iter().map(|x| *x.get_ref()).collect();
    let bad = |msg: String| at.error(g.span(), "gravity".to_owned(), msg);
    let g3: [f64; 3] = v.as_slice().try_into().map_err(|_| {
        bad(format!(
            "expected [gx, gy, gz], the direction of gravity in the base frame, got {} numbers",
            v.len()
        ))
    })?;
    robot.set_gravity(g3).map_err(|e| match e {
        Error::Invalid { message, .. } => bad(message),
        other => bad(other.to_string()),
    })
}
