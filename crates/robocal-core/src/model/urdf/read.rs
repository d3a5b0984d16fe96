//! The kinematic part of a URDF file read in one pass of a streaming XML reader (quick-xml):
//! the robot's name and version, its links' names and its joints (name, type, origin, parent,
//! child, axis, limit, mimic), as `urdf_rs` types. Linear in the file's size (urdf-rs reads a
//! file twice through a DOM and took 3.4 s for 100,000 fixed joints); the rest of a URDF
//! (visuals, collisions, inertias, materials, gazebo and transmission elements) is skipped
//! unread, as calibration does not use it.
//!
//! The URDF's rules as urdfdom and urdf-rs apply them: `<origin>` defaults to zero, `<axis>` to
//! `1 0 0`; before URDF 1.2 a `<limit>` needs `velocity` and its other values default to 0;
//! from 1.2 omitted limits are infinite (`lower` negative), and negative effort or velocity, or
//! `upper < lower`, are errors; from 1.1 an `<origin>` may give `quat_xyzw` instead of `rpy`.
//! Errors carry the 1-based line of the element they concern.

use nalgebra::{Quaternion, UnitQuaternion};
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

/// A reading error: the line it concerns, where known, and what is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadError {
    /// The 1-based line.
    pub line: Option<usize>,
    /// The message.
    pub msg: String,
}

type Read<T> = std::result::Result<T, ReadError>;

/// The joint types of URDF, by their `type` attribute.
const JOINT_TYPES: [(&str, urdf_rs::JointType); 7] = [
    ("revolute", urdf_rs::JointType::Revolute),
    ("continuous", urdf_rs::JointType::Continuous),
    ("prismatic", urdf_rs::JointType::Prismatic),
    ("fixed", urdf_rs::JointType::Fixed),
    ("floating", urdf_rs::JointType::Floating),
    ("planar", urdf_rs::JointType::Planar),
    ("spherical", urdf_rs::JointType::Spherical),
];

/// Line numbers of byte offsets, counted forward from the last one asked for (offsets asked in
/// increasing order cost the file's length once in all).
struct Lines<'a> {
    text: &'a [u8],
    at: usize,
    line: usize,
}

impl Lines<'_> {
    fn of(&mut self, offset: usize) -> usize {
        let offset = offset.min(self.text.len());
        if offset < self.at {
            self.at = 0;
            self.line = 1;
        }
        self.line += self.text[self.at..offset]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        self.at = offset;
        self.line
    }
}

/// A joint being read: the `<joint>` element's fields, and which children were seen.
struct OpenJoint {
    joint: urdf_rs::Joint,
    line: usize,
    parent: bool,
    child: bool,
}

/// Reads the kinematic part of a URDF (see the module documentation).
pub fn read(text: &str) -> Read<urdf_rs::Robot> {
    let mut reader = Reader::from_str(text);
    reader.config_mut().check_end_names = true;
    let mut lines = Lines {
        text: text.as_bytes(),
        at: 0,
        line: 1,
    };
    let mut robot: Option<urdf_rs::Robot> = None;
    let mut version = (1u32, 0u32);
    let mut open: Vec<Vec<u8>> = Vec::new();
    let mut joint: Option<OpenJoint> = None;
    let mut closed_root = false;
    loop {
        let event = reader.read_event().map_err(|e| {
            let at = usize::try_from(reader.error_position()).unwrap_or(usize::MAX);
            ReadError {
                line: Some(lines.of(at)),
                msg: format!("XML: {e}"),
            }
        })?;
        let end = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
        // The line of the tag just read: of its `<`.
        let mut line_here = || {
            let start = text[..end.min(text.len())].rfind('<').unwrap_or(0);
            lines.of(start)
        };
        let (e, empty) = match &event {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => {
                open.pop();
                match open.len() {
                    0 => closed_root = true,
                    1 => {
                        if let Some(j) = joint.take() {
                            let r = robot.as_mut().expect("a joint is read inside <robot>");
                            r.joints.push(finish_joint(j)?);
                        }
                    }
                    _ => {}
                }
                continue;
            }
            Event::Eof => break,
            _ => continue,
        };
        let line = line_here();
        let name = e.name().as_ref().to_vec();
        match open.len() {
            0 => {
                if closed_root || robot.is_some() {
                    return Err(err(line, "a second root element after </robot>".into()));
                }
                if name != b"robot" {
                    return Err(err(
                        line,
                        format!(
                            "the root element is <{}>, not <robot>",
                            String::from_utf8_lossy(&name)
                        ),
                    ));
                }
                let v = attr(e, "version", line)?;
                version = v.as_deref().map(parse_version).unwrap_or((1, 0));
                robot = Some(urdf_rs::Robot {
                    name: attr(e, "name", line)?.unwrap_or_default(),
                    version: v,
                    links: Vec::new(),
                    joints: Vec::new(),
                    materials: Vec::new(),
                });
            }
            1 => {
                let r = robot.as_mut().expect("the root is <robot>");
                match name.as_slice() {
                    b"link" => r.links.push(urdf_rs::Link {
                        name: required(e, "name", "<link>", line)?,
                        inertial: Default::default(),
                        visual: Vec::new(),
                        collision: Vec::new(),
                    }),
                    b"joint" => {
                        let jname = required(e, "name", "<joint>", line)?;
                        let kind = required(e, "type", &format!("joint `{jname}`"), line)?;
                        let Some((_, joint_type)) =
                            JOINT_TYPES.iter().find(|(n, _)| *n == kind.as_str())
                        else {
                            return Err(err(
                                line,
                                format!(
                                    "joint `{jname}`: unknown type `{kind}` (one of {})",
                                    JOINT_TYPES.map(|(n, _)| n).join(", ")
                                ),
                            ));
                        };
                        let j = OpenJoint {
                            joint: urdf_rs::Joint {
                                name: jname,
                                joint_type: joint_type.clone(),
                                origin: Default::default(),
                                parent: Default::default(),
                                child: Default::default(),
                                axis: Default::default(),
                                limit: default_limit(version),
                                calibration: None,
                                dynamics: None,
                                mimic: None,
                                safety_controller: None,
                            },
                            line,
                            parent: false,
                            child: false,
                        };
                        if empty {
                            r.joints.push(finish_joint(j)?);
                        } else {
                            joint = Some(j);
                        }
                    }
                    _ => {}
                }
            }
            2 => {
                if let Some(j) = joint.as_mut() {
                    joint_child(j, e, &name, line, version)?;
                }
            }
            _ => {}
        }
        if !empty {
            open.push(name);
        }
    }
    if let Some(last) = open.last() {
        return Err(err(
            lines.of(text.len()),
            format!(
                "the file ends inside <{}>: an element is not closed",
                String::from_utf8_lossy(last)
            ),
        ));
    }
    robot.ok_or_else(|| ReadError {
        line: None,
        msg: "no <robot> element".into(),
    })
}

fn err(line: usize, msg: String) -> ReadError {
    ReadError {
        line: Some(line),
        msg,
    }
}

/// `major.minor` of a `version` attribute; anything else is 1.0, as urdfdom reads it.
fn parse_version(v: &str) -> (u32, u32) {
    v.trim()
        .split_once('.')
        .and_then(|(a, b)| Some((a.parse().ok()?, b.parse().ok()?)))
        .unwrap_or((1, 0))
}

/// A joint's limits before its `<limit>` is read: URDF 1.2 leaves omitted limits open.
fn default_limit(version: (u32, u32)) -> urdf_rs::JointLimit {
    let mut l = urdf_rs::JointLimit::default();
    if version >= (1, 2) {
        l.lower = f64::NEG_INFINITY;
        l.upper = f64::INFINITY;
        l.effort = f64::INFINITY;
        l.velocity = f64::INFINITY;
    }
    l
}

/// The unescaped value of attribute `key`, if the element has it.
fn attr(e: &BytesStart, key: &str, line: usize) -> Read<Option<String>> {
    for a in e.attributes() {
        let a = a.map_err(|x| err(line, format!("XML: {x}")))?;
        if a.key.as_ref() == key.as_bytes() {
            let v = a
                .unescape_value()
                .map_err(|x| err(line, format!("XML: attribute `{key}`: {x}")))?;
            return Ok(Some(v.into_owned()));
        }
    }
    Ok(None)
}

fn required(e: &BytesStart, key: &str, what: &str, line: usize) -> Read<String> {
    attr(e, key, line)?.ok_or_else(|| err(line, format!("{what} has no `{key}` attribute")))
}

/// A number attribute (NaN is not one).
fn number(e: &BytesStart, key: &str, what: &str, line: usize) -> Read<Option<f64>> {
    attr(e, key, line)?
        .map(|v| match v.trim().parse::<f64>() {
            Ok(x) if !x.is_nan() => Ok(x),
            _ => Err(err(
                line,
                format!("{what}: `{key}` value `{v}` is not a number"),
            )),
        })
        .transpose()
}

/// `n` numbers separated by white space.
fn numbers<const N: usize>(v: &str, key: &str, what: &str, line: usize) -> Read<[f64; N]> {
    let bad = || {
        err(
            line,
            format!("{what}: `{key}` must be {N} numbers, not `{v}`"),
        )
    };
    let vals: Vec<f64> = v
        .split_whitespace()
        .map(|s| s.parse::<f64>().map_err(|_| bad()))
        .collect::<Read<_>>()?;
    <[f64; N]>::try_from(vals).map_err(|_| bad())
}

/// One child element of a `<joint>`.
fn joint_child(
    j: &mut OpenJoint,
    e: &BytesStart,
    name: &[u8],
    line: usize,
    version: (u32, u32),
) -> Read<()> {
    let what = format!("joint `{}`", j.joint.name);
    match name {
        b"origin" => {
            if let Some(v) = attr(e, "xyz", line)? {
                j.joint.origin.xyz = urdf_rs::Vec3(numbers(&v, "xyz", &what, line)?);
            }
            if let Some(v) = attr(e, "rpy", line)? {
                j.joint.origin.rpy = urdf_rs::Vec3(numbers(&v, "rpy", &what, line)?);
            }
            // URDF 1.1's quaternion orientation; ignored before 1.1, as urdfdom does.
            if version >= (1, 1) {
                if let Some(v) = attr(e, "quat_xyzw", line)? {
                    if attr(e, "rpy", line)?.is_some() {
                        return Err(err(
                            line,
                            format!("{what}: <origin> gives both `rpy` and `quat_xyzw`"),
                        ));
                    }
                    let [x, y, z, w] = numbers::<4>(&v, "quat_xyzw", &what, line)?;
                    let q = Quaternion::new(w, x, y, z);
                    let q = if q.norm() > 0.0 {
                        UnitQuaternion::from_quaternion(q)
                    } else {
                        UnitQuaternion::identity()
                    };
                    let (r, p, y) = q.euler_angles();
                    j.joint.origin.rpy = urdf_rs::Vec3([r, p, y]);
                }
            }
        }
        b"parent" => {
            j.joint.parent.link = required(e, "link", &format!("{what}: <parent>"), line)?;
            j.parent = true;
        }
        b"child" => {
            j.joint.child.link = required(e, "link", &format!("{what}: <child>"), line)?;
            j.child = true;
        }
        b"axis" => {
            let v = required(e, "xyz", &format!("{what}: <axis>"), line)?;
            j.joint.axis.xyz = urdf_rs::Vec3(numbers(&v, "xyz", &what, line)?);
        }
        b"limit" => j.joint.limit = limit(e, &what, line, version)?,
        b"mimic" => {
            j.joint.mimic = Some(urdf_rs::Mimic {
                joint: required(e, "joint", &format!("{what}: <mimic>"), line)?,
                ..Default::default()
            })
        }
        _ => {}
    }
    Ok(())
}

/// A `<limit>` by the rules of the file's URDF version (see the module documentation).
fn limit(
    e: &BytesStart,
    what: &str,
    line: usize,
    version: (u32, u32),
) -> Read<urdf_rs::JointLimit> {
    let mut l = default_limit(version);
    let get = |key| number(e, key, what, line);
    if version < (1, 2) && attr(e, "velocity", line)?.is_none() {
        return Err(err(line, format!("{what}: <limit> has no `velocity`")));
    }
    let (lower, upper) = (get("lower")?, get("upper")?);
    let (effort, velocity) = (get("effort")?, get("velocity")?);
    if version >= (1, 2) {
        if let (Some(lo), Some(hi)) = (lower, upper) {
            if hi < lo {
                return Err(err(
                    line,
                    format!("{what}: upper limit {hi} is smaller than lower limit {lo}"),
                ));
            }
        }
        for (key, v) in [("effort", effort), ("velocity", velocity)] {
            if v.is_some_and(|v| v < 0.0) {
                return Err(err(line, format!("{what}: `{key}` is negative")));
            }
        }
    }
    l.lower = lower.unwrap_or(l.lower);
    l.upper = upper.unwrap_or(l.upper);
    l.effort = effort.unwrap_or(l.effort);
    l.velocity = velocity.unwrap_or(l.velocity);
    Ok(l)
}

/// A joint whose `</joint>` was read: it must have named its parent and child links.
fn finish_joint(j: OpenJoint) -> Read<urdf_rs::Joint> {
    for (seen, tag) in [(j.parent, "parent"), (j.child, "child")] {
        if !seen {
            return Err(err(
                j.line,
                format!("joint `{}` has no <{tag}> link", j.joint.name),
            ));
        }
    }
    Ok(j.joint)
}
