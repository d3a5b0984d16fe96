//! The serial chain of a URDF file: from its base link to its tip link, the joints' origins and
//! motions in robocal's units (mm, radians), and the URDF's own forward kinematics over it (the
//! product of the joint origins and joint motions, as ROS evaluates a URDF), against which the
//! imported model is checked.

use super::ChainSelection;
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::{JointLimit, JointType};
use nalgebra::{Rotation3, Translation3, Unit, Vector3};
use std::collections::BTreeMap;
use std::path::Path;

/// One step of the chain, base to tip.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    /// A constant transform: a joint's `<origin>` (or a whole fixed joint).
    Fixed(Frame),
    /// A joint's motion in its own frame: a rotation about `axis` by q (rad) or a translation
    /// along it by q (mm).
    Motion {
        /// The URDF joint's name.
        name: String,
        /// Revolute (URDF `revolute`, `continuous`) or prismatic.
        kind: JointType,
        /// The unit axis in the joint's frame.
        axis: Unit<Vector3<f64>>,
        /// The joint's range (rad or mm).
        limit: JointLimit,
    },
}

/// A URDF serial chain in robocal's units (mm, radians).
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfChain {
    /// The URDF robot's name.
    pub name: String,
    /// The link the chain starts at (its frame is the robot's base frame).
    pub base_link: String,
    /// The link the chain ends at (its frame is the tool frame).
    pub tip_link: String,
    /// The steps from the base link's frame to the tip link's frame.
    pub steps: Vec<Step>,
}

/// Range of a continuous joint, or of a revolute joint whose URDF (1.2) leaves its limits open:
/// robocal's default joint range.
const OPEN_LIMIT_RAD: f64 =
    crate::model::robot_file::DEFAULT_LIMIT_DEG * std::f64::consts::PI / 180.0;

impl UrdfChain {
    /// The movable joints, base to tip.
    pub fn motions(&self) -> impl Iterator<Item = &Step> {
        self.steps
            .iter()
            .filter(|s| matches!(s, Step::Motion { .. }))
    }

    /// Number of movable joints.
    pub fn dof(&self) -> usize {
        self.motions().count()
    }

    /// The tip link's frame in the base link's frame at joint values `q` (rad or mm, one per
    /// movable joint): the product of every joint origin and joint motion, as a URDF defines it.
    pub fn tip_pose(&self, q: &[f64]) -> Frame {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        let mut f = Frame::identity();
        let mut k = 0;
        for s in &self.steps {
            match s {
                Step::Fixed(t) => f *= t,
                Step::Motion { kind, axis, .. } => {
                    f *= motion(*kind, axis, q[k]);
                    k += 1;
                }
            }
        }
        f
    }
}

/// A joint's motion by `q`: rotation about, or translation along, `axis`.
fn motion(kind: JointType, axis: &Unit<Vector3<f64>>, q: f64) -> Frame {
    match kind {
        JointType::Revolute => Frame::from_parts(
            Translation3::identity(),
            Rotation3::from_axis_angle(axis, q),
        ),
        JointType::Prismatic => Frame::from_parts(
            Translation3::from(axis.into_inner() * q),
            Rotation3::identity(),
        ),
    }
}

/// A URDF `<origin xyz rpy>` (m, rad) as a frame in mm: `Trans(xyz) * Rz(yaw) Ry(pitch) Rx(roll)`
/// (the URDF's fixed-axis roll, pitch, yaw).
pub fn origin_frame(xyz: [f64; 3], rpy: [f64; 3]) -> Frame {
    let r = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    Frame::from_parts(
        Translation3::new(xyz[0] * 1000.0, xyz[1] * 1000.0, xyz[2] * 1000.0),
        r,
    )
}

/// The 1-based line of the element that carries `name="..."` for a `<joint` or `<link`
/// (`tag`), where the text shows it; for error messages.
pub(super) fn line_of_element(text: &str, tag: &str, name: &str) -> Option<usize> {
    let open = format!("<{tag}");
    for quoted in [format!("\"{name}\""), format!("'{name}'")] {
        let mut from = 0;
        while let Some(pos) = text[from..].find(&quoted).map(|p| p + from) {
            let start = text[..pos].rfind('<').unwrap_or(0);
            if text[start..].starts_with(&open) {
                return Some(text[..start].matches('\n').count() + 1);
            }
            from = pos + quoted.len();
        }
    }
    None
}

/// Selects the chain from `base` to `tip` of a parsed URDF (`text` and `path` for messages).
pub(super) fn select(
    robot: &urdf_rs::Robot,
    sel: &ChainSelection,
    text: &str,
    path: &Path,
) -> Result<UrdfChain> {
    let err = |line: Option<usize>, field: Option<&str>, msg: String| {
        Error::parse(path, line, field, msg)
    };
    let links: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
    // Looked up once per joint: a set, so that reading is linear in the file's size.
    let link_set: std::collections::HashSet<&str> = links.iter().copied().collect();
    // The joint that has each link as its child.
    let mut parent_joint: BTreeMap<&str, &urdf_rs::Joint> = BTreeMap::new();
    let mut children: BTreeMap<&str, Vec<&urdf_rs::Joint>> = BTreeMap::new();
    for j in &robot.joints {
        // Found in the text only for a message (a search per joint would be quadratic).
        let line = || line_of_element(text, "joint", &j.name);
        for l in [&j.parent.link, &j.child.link] {
            if !link_set.contains(l.as_str()) {
                return Err(err(
                    line(),
                    None,
                    format!(
                        "joint `{}` names link `{l}`, which the file does not define",
                        j.name
                    ),
                ));
            }
        }
        if parent_joint.insert(&j.child.link, j).is_some() {
            return Err(err(
                line(),
                None,
                format!(
                    "link `{}` is the child of two joints: a URDF is a tree",
                    j.child.link
                ),
            ));
        }
        children.entry(&j.parent.link).or_default().push(j);
    }
    let roots: Vec<&str> = links
        .iter()
        .copied()
        .filter(|l| !parent_joint.contains_key(l))
        .collect();
    let base = match &sel.base_link {
        Some(b) => {
            if !link_set.contains(b.as_str()) {
                return Err(err(
                    None,
                    None,
                    format!(
                        "base link `{b}` (the `base_link` setting) is not a link of this file \
                         (links: {})",
                        links.join(", ")
                    ),
                ));
            }
            b.clone()
        }
        None => match roots.as_slice() {
            [one] => (*one).to_owned(),
            [] => {
                return Err(err(
                    None,
                    None,
                    "the file has no root link (the joints form a loop, or there are no links)"
                        .into(),
                ))
            }
            many => {
                return Err(err(
                    None,
                    None,
                    format!(
                        "the file has several root links ({}): name the robot's base with the \
                         `base_link` setting",
                        many.join(", ")
                    ),
                ))
            }
        },
    };
    let tip = match &sel.tip_link {
        Some(t) => {
            if !link_set.contains(t.as_str()) {
                return Err(err(
                    None,
                    None,
                    format!(
                        "tip link `{t}` (the `tip_link` setting) is not a link of this file \
                         (links: {})",
                        links.join(", ")
                    ),
                ));
            }
            t.clone()
        }
        None => {
            // The leaves below the base that at least one movable joint leads to.
            let mut tips = Vec::new();
            let mut stack: Vec<(&str, bool)> = vec![(base.as_str(), false)];
            let mut seen = 0usize;
            while let Some((l, moved)) = stack.pop() {
                seen += 1;
                if seen > links.len() + 1 {
                    break;
                }
                match children.get(l) {
                    None => {
                        if moved {
                            tips.push(l.to_owned());
                        }
                    }
                    Some(js) => {
                        for j in js {
                            let m = moved || j.joint_type != urdf_rs::JointType::Fixed;
                            stack.push((&j.child.link, m));
                        }
                    }
                }
            }
            tips.sort();
            match tips.len() {
                1 => tips.remove(0),
                0 => {
                    return Err(err(
                        None,
                        None,
                        format!("no movable joint below the base link `{base}`"),
                    ))
                }
                _ => {
                    return Err(err(
                        None,
                        None,
                        format!(
                            "the file holds several chains below `{base}`, ending at the links \
                             {}: name the tip with the `tip_link` setting",
                            tips.iter()
                                .map(|t| format!("`{t}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ))
                }
            }
        }
    };
    // Walk up from the tip to the base.
    let mut path_joints = Vec::new();
    let mut at = tip.as_str();
    while at != base {
        let Some(j) = parent_joint.get(at) else {
            return Err(err(
                None,
                None,
                format!("the tip link `{tip}` does not hang below the base link `{base}`"),
            ));
        };
        path_joints.push(*j);
        at = &j.parent.link;
        if path_joints.len() > robot.joints.len() {
            return Err(err(None, None, "the joints form a loop".into()));
        }
    }
    path_joints.reverse();
    let mut steps = Vec::new();
    for j in path_joints {
        // The line is looked up only for a message: a search per joint would be quadratic.
        let jerr = |msg: String| {
            let line = line_of_element(text, "joint", &j.name);
            err(line, None, format!("joint `{}`: {msg}", j.name))
        };
        let o = &j.origin;
        if o.xyz.0.iter().chain(&o.rpy.0).any(|v| !v.is_finite()) {
            return Err(jerr("the origin is not finite".into()));
        }
        if o.xyz
            .0
            .iter()
            .any(|v| v.abs() * 1000.0 > crate::ranges::LENGTH.max)
        {
            return Err(jerr("the origin is farther than 1 km".into()));
        }
        steps.push(Step::Fixed(origin_frame(o.xyz.0, o.rpy.0)));
        let kind = match j.joint_type {
            urdf_rs::JointType::Fixed => continue,
            urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => JointType::Revolute,
            urdf_rs::JointType::Prismatic => JointType::Prismatic,
            ref other => {
                return Err(jerr(format!(
                    "a {} joint cannot be part of a serial robot (revolute, continuous, \
                     prismatic and fixed joints can)",
                    format!("{other:?}").to_lowercase()
                )))
            }
        };
        if j.mimic.is_some() {
            return Err(jerr(
                "mimic joints (coupled to another joint) are not supported".into(),
            ));
        }
        let a = Vector3::from(j.axis.xyz.0);
        let n = a.norm();
        if !n.is_finite() || n < 1e-9 {
            return Err(jerr(format!(
                "the axis {:?} is not a direction",
                j.axis.xyz.0
            )));
        }
        let axis = Unit::new_normalize(a);
        let (lo, hi) = (j.limit.lower, j.limit.upper);
        let limit = match (kind, j.joint_type == urdf_rs::JointType::Continuous) {
            (JointType::Revolute, true) => JointLimit {
                min: -OPEN_LIMIT_RAD,
                max: OPEN_LIMIT_RAD,
            },
            _ if lo.is_nan() || hi.is_nan() => {
                return Err(jerr("a limit is not a number".into()));
            }
            _ if lo > hi => {
                return Err(jerr(format!(
                    "lower limit {lo} is greater than upper limit {hi}"
                )));
            }
            _ if lo == hi => {
                return Err(jerr(format!(
                    "lower and upper limits are both {lo} (no <limit>?): a revolute or \
                     prismatic joint needs its range"
                )));
            }
            (JointType::Revolute, false) => JointLimit {
                min: if lo.is_finite() { lo } else { -OPEN_LIMIT_RAD },
                max: if hi.is_finite() { hi } else { OPEN_LIMIT_RAD },
            },
            (JointType::Prismatic, _) => {
                if !lo.is_finite() || !hi.is_finite() {
                    return Err(jerr(
                        "a prismatic joint needs finite limits (lower, upper)".into(),
                    ));
                }
                JointLimit {
                    min: lo * 1000.0,
                    max: hi * 1000.0,
                }
            }
        };
        steps.push(Step::Motion {
            name: j.name.clone(),
            kind,
            axis,
            limit,
        });
    }
    let chain = UrdfChain {
        name: robot.name.clone(),
        base_link: base,
        tip_link: tip,
        steps,
    };
    let n = chain.dof();
    if n == 0 || n > crate::model::MAX_JOINTS {
        return Err(err(
            None,
            None,
            format!(
                "the chain from `{}` to `{}` has {n} movable joints; a robot needs 1 to {}",
                chain.base_link,
                chain.tip_link,
                crate::model::MAX_JOINTS
            ),
        ));
    }
    Ok(chain)
}
