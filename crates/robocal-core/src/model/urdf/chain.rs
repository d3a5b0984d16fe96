//! The serial chain of a URDF file: from its base link to its tip link, the joints' origins and
//! motions in robocal's units (mm, radians), and the URDF's own forward kinematics over it (the
//! product of the joint origins and joint motions, as ROS evaluates a URDF), against which the
//! imported model is checked.

use super::ChainSelection;
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::{JointLimit, JointType};
use nalgebra::{Rotation3, Translation3, Unit, Vector3};
use std::collections::{BTreeMap, HashSet};
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
    let tree = LinkTree::read(robot, text, path)?;
    let base = base_link(&tree, sel, path)?;
    let tip = tip_link(&tree, sel, &base, path)?;
    let path_joints = joints_from_base_to_tip(&tree, robot.joints.len(), &base, &tip, path)?;
    let steps = chain_steps(&path_joints, text, path)?;
    let chain = UrdfChain {
        name: robot.name.clone(),
        base_link: base,
        tip_link: tip,
        steps,
    };
    check_dof(&chain, path)?;
    Ok(chain)
}

/// A parse error of the URDF at `path` (no field: the line, where known, names the element).
fn chain_error(path: &Path, line: Option<usize>, msg: String) -> Error {
    Error::parse(path, line, None, msg)
}

/// The links of a URDF and the joints between them, checked to be a tree.
struct LinkTree<'a> {
    /// The links in the file's order.
    links: Vec<&'a str>,
    /// The same links as a set.
    link_set: HashSet<&'a str>,
    /// The joint that has each link as its child.
    parent_joint: BTreeMap<&'a str, &'a urdf_rs::Joint>,
    /// The joints that have each link as their parent, in the file's order.
    children: BTreeMap<&'a str, Vec<&'a urdf_rs::Joint>>,
}

impl<'a> LinkTree<'a> {
    /// The tree of `robot`'s links, or an error at the first joint that names a link the file
    /// does not define or gives a link a second parent.
    fn read(robot: &'a urdf_rs::Robot, text: &str, path: &Path) -> Result<LinkTree<'a>> {
        let links: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
        // Looked up once per joint: a set, so that reading is linear in the file's size.
        let link_set: HashSet<&str> = links.iter().copied().collect();
        let mut tree = LinkTree {
            links,
            link_set,
            parent_joint: BTreeMap::new(),
            children: BTreeMap::new(),
        };
        for j in &robot.joints {
            tree.add_joint(j, text, path)?;
        }
        Ok(tree)
    }

    /// Adds joint `j` as its child link's parent and one of its parent link's children, or an
    /// error if it names a link the file does not define or its child already has a parent.
    fn add_joint(&mut self, j: &'a urdf_rs::Joint, text: &str, path: &Path) -> Result<()> {
        // Found in the text only for a message (a search per joint would be quadratic).
        let line = || line_of_element(text, "joint", &j.name);
        for l in [&j.parent.link, &j.child.link] {
            if !self.link_set.contains(l.as_str()) {
                return Err(chain_error(
                    path,
                    line(),
                    format!(
                        "joint `{}` names link `{l}`, which the file does not define",
                        j.name
                    ),
                ));
            }
        }
        if self.parent_joint.insert(&j.child.link, j).is_some() {
            return Err(chain_error(
                path,
                line(),
                format!(
                    "link `{}` is the child of two joints: a URDF is a tree",
                    j.child.link
                ),
            ));
        }
        self.children.entry(&j.parent.link).or_default().push(j);
        Ok(())
    }

    /// The links that are no joint's child, in the file's order.
    fn roots(&self) -> Vec<&'a str> {
        self.links
            .iter()
            .copied()
            .filter(|l| !self.parent_joint.contains_key(l))
            .collect()
    }
}

/// The base link: the `base_link` setting if it names a link, else the file's one root link.
fn base_link(tree: &LinkTree, sel: &ChainSelection, path: &Path) -> Result<String> {
    let roots = tree.roots();
    match &sel.base_link {
        Some(b) => {
            if !tree.link_set.contains(b.as_str()) {
                return Err(chain_error(
                    path,
                    None,
                    format!(
                        "base link `{b}` (the `base_link` setting) is not a link of this file \
                         (links: {})",
                        tree.links.join(", ")
                    ),
                ));
            }
            Ok(b.clone())
        }
        None => match roots.as_slice() {
            [one] => Ok((*one).to_owned()),
            [] => Err(chain_error(
                path,
                None,
                "the file has no root link (the joints form a loop, or there are no links)".into(),
            )),
            many => Err(chain_error(
                path,
                None,
                format!(
                    "the file has several root links ({}): name the robot's base with the \
                     `base_link` setting",
                    many.join(", ")
                ),
            )),
        },
    }
}

/// The tip link: the `tip_link` setting if it names a link, else the one leaf below `base` that a
/// movable joint leads to.
fn tip_link(tree: &LinkTree, sel: &ChainSelection, base: &str, path: &Path) -> Result<String> {
    match &sel.tip_link {
        Some(t) => {
            if !tree.link_set.contains(t.as_str()) {
                return Err(chain_error(
                    path,
                    None,
                    format!(
                        "tip link `{t}` (the `tip_link` setting) is not a link of this file \
                         (links: {})",
                        tree.links.join(", ")
                    ),
                ));
            }
            Ok(t.clone())
        }
        None => only_tip(movable_leaves(tree, base), base, path),
    }
}

/// The leaves below `base` that at least one movable joint leads to, sorted.
fn movable_leaves(tree: &LinkTree, base: &str) -> Vec<String> {
    let mut tips = Vec::new();
    let mut stack: Vec<(&str, bool)> = vec![(base, false)];
    let mut seen = 0usize;
    while let Some((l, moved)) = stack.pop() {
        seen += 1;
        if seen > tree.links.len() + 1 {
            break;
        }
        match tree.children.get(l) {
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
    tips
}

/// The one tip of `tips`, or an error if there is none or several (naming them).
fn only_tip(mut tips: Vec<String>, base: &str, path: &Path) -> Result<String> {
    match tips.len() {
        1 => Ok(tips.remove(0)),
        0 => Err(chain_error(
            path,
            None,
            format!("no movable joint below the base link `{base}`"),
        )),
        _ => Err(chain_error(
            path,
            None,
            format!(
                "the file holds several chains below `{base}`, ending at the links \
                 {}: name the tip with the `tip_link` setting",
                tips.iter()
                    .map(|t| format!("`{t}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// The joints from `base` to `tip`, base first (found walking up from the tip), or an error if
/// the tip does not hang below the base or the walk takes more than the file's `joint_count`
/// joints (a loop).
fn joints_from_base_to_tip<'a>(
    tree: &LinkTree<'a>,
    joint_count: usize,
    base: &str,
    tip: &str,
    path: &Path,
) -> Result<Vec<&'a urdf_rs::Joint>> {
    // Walk up from the tip to the base.
    let mut path_joints = Vec::new();
    let mut at = tip;
    while at != base {
        let Some(j) = tree.parent_joint.get(at) else {
            return Err(chain_error(
                path,
                None,
                format!("the tip link `{tip}` does not hang below the base link `{base}`"),
            ));
        };
        path_joints.push(*j);
        at = &j.parent.link;
        if path_joints.len() > joint_count {
            return Err(chain_error(path, None, "the joints form a loop".into()));
        }
    }
    path_joints.reverse();
    Ok(path_joints)
}

/// The steps of the chain's joints, base to tip: each joint's origin, then its motion unless it
/// is fixed.
fn chain_steps(path_joints: &[&urdf_rs::Joint], text: &str, path: &Path) -> Result<Vec<Step>> {
    let mut steps = Vec::new();
    for j in path_joints {
        // The line is looked up only for a message: a search per joint would be quadratic.
        let jerr = |msg: String| {
            let line = line_of_element(text, "joint", &j.name);
            chain_error(path, line, format!("joint `{}`: {msg}", j.name))
        };
        steps.push(Step::Fixed(joint_origin(j, &jerr)?));
        let Some(kind) = motion_kind(j, &jerr)? else {
            continue;
        };
        if j.mimic.is_some() {
            return Err(jerr(
                "mimic joints (coupled to another joint) are not supported".into(),
            ));
        }
        let axis = joint_axis(j, &jerr)?;
        let limit = joint_limit(j, kind, &jerr)?;
        steps.push(Step::Motion {
            name: j.name.clone(),
            kind,
            axis,
            limit,
        });
    }
    Ok(steps)
}

/// Joint `j`'s origin as a frame in mm, or an error (by `jerr`) if it is not finite or farther
/// than 1 km.
fn joint_origin(j: &urdf_rs::Joint, jerr: &impl Fn(String) -> Error) -> Result<Frame> {
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
    Ok(origin_frame(o.xyz.0, o.rpy.0))
}

/// Joint `j`'s motion: revolute or prismatic, `None` for a fixed joint, or an error (by `jerr`)
/// for a joint type a serial robot cannot have.
fn motion_kind(j: &urdf_rs::Joint, jerr: &impl Fn(String) -> Error) -> Result<Option<JointType>> {
    match j.joint_type {
        urdf_rs::JointType::Fixed => Ok(None),
        urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => {
            Ok(Some(JointType::Revolute))
        }
        urdf_rs::JointType::Prismatic => Ok(Some(JointType::Prismatic)),
        ref other => Err(jerr(format!(
            "a {} joint cannot be part of a serial robot (revolute, continuous, \
             prismatic and fixed joints can)",
            format!("{other:?}").to_lowercase()
        ))),
    }
}

/// Joint `j`'s unit axis, or an error (by `jerr`) if its axis is not a direction.
fn joint_axis(j: &urdf_rs::Joint, jerr: &impl Fn(String) -> Error) -> Result<Unit<Vector3<f64>>> {
    let a = Vector3::from(j.axis.xyz.0);
    let n = a.norm();
    if !n.is_finite() || n < 1e-9 {
        return Err(jerr(format!(
            "the axis {:?} is not a direction",
            j.axis.xyz.0
        )));
    }
    Ok(Unit::new_normalize(a))
}

/// Joint `j`'s range in robocal's units (rad, or mm for a prismatic joint): robocal's default
/// range for a continuous joint and for an open end of a revolute one, or an error (by `jerr`)
/// for limits that are not numbers, not ordered, equal, or open on a prismatic joint.
fn joint_limit(
    j: &urdf_rs::Joint,
    kind: JointType,
    jerr: &impl Fn(String) -> Error,
) -> Result<JointLimit> {
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
    Ok(limit)
}

/// An error unless the chain has 1 to [`crate::model::MAX_JOINTS`] movable joints.
fn check_dof(chain: &UrdfChain, path: &Path) -> Result<()> {
    let n = chain.dof();
    if n == 0 || n > crate::model::MAX_JOINTS {
        return Err(chain_error(
            path,
            None,
            format!(
                "the chain from `{}` to `{}` has {n} movable joints; a robot needs 1 to {}",
                chain.base_link,
                chain.tip_link,
                crate::model::MAX_JOINTS
            ),
        ));
    }
    Ok(())
}
