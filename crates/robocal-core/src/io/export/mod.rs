//! The calibrated robot as a file other tools read: a robocal robot file (TOML) or a URDF (for
//! ROS/MoveIt). Both hold the geometry exactly: the calibrated parameter table, base frame and
//! tool(s), with each tool correction folded into its nominal tool vector, so that the file's
//! robot is a nominal robot whose forward kinematics is the calibrated one.
//!
//! What neither holds: parameter families that act through the joints (joint compliance,
//! transmission errors; [`non_geometric`] lists them) and the tracker frame, which belongs to
//! the measurement, not to the robot. The URDF also cannot hold the controller's axis map (the
//! robot file can). Each file says so in a comment.

use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use crate::model::description::RobotDescription;
use crate::model::{family, Convention, JointType, Param, Robot};
use nalgebra::{Translation3, Vector3};

/// The file formats of an export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExportFormat {
    /// A robocal robot file.
    Toml,
    /// A URDF: one link per DH frame, every joint about (or along) its link's z axis.
    Urdf,
}

/// Lines for the file's leading comment (its origin, the tracker frame, what was left out).
pub type Notes = Vec<String>;

/// The parameters of `robot` that belong to families acting through the joints (compliance,
/// transmission): neither a robot file nor a URDF holds them.
pub fn non_geometric(robot: &Robot) -> Vec<Param> {
    let mut out = Vec::new();
    for (id, span) in robot.family_spans() {
        if family::all()[id.index()].deflects_joints(robot) {
            out.extend_from_slice(&robot.param_list()[span.clone()]);
        }
    }
    out
}

/// `robot`'s geometry as a nominal robot: without the joint-deflecting families, each tool
/// correction folded into its nominal tool vector (`pose(T0 + T)` is unchanged).
pub fn geometric_nominal(robot: &Robot) -> Result<Robot> {
    let mut r = robot.geometric();
    let tools: Vec<[f64; 6]> = (0..r.target_count())
        .map(|t| {
            let mut v = *r.target_tool0(t);
            for (x, c) in v.iter_mut().zip(r.target_tool_correction(t)) {
                *x += c;
            }
            v
        })
        .collect();
    r.set_target_tools(&tools)?;
    for k in 0..6 {
        if r.has_param(Param::tool(k)) {
            r.set(Param::tool(k), 0.0);
        }
        for t in 1..r.target_count() {
            r.set_target_correction(t, k, 0.0);
        }
    }
    Ok(r)
}

/// The export of `robot` (already [`geometric_nominal`]) in `format`, with `notes` as the file's
/// leading comment.
pub fn export(robot: &Robot, format: ExportFormat, notes: &[String]) -> Result<String> {
    match format {
        ExportFormat::Toml => export_toml(robot, notes),
        ExportFormat::Urdf => export_urdf(robot, notes),
    }
}

fn export_toml(robot: &Robot, notes: &[String]) -> Result<String> {
    let mut out = String::new();
    for n in notes {
        for l in n.lines() {
            out.push_str("# ");
            out.push_str(l);
            out.push('\n');
        }
    }
    out.push_str(&RobotDescription::of(robot).to_toml()?);
    Ok(out)
}

/// The constant frames `E_0..E_n` with `flange = base * E_0 M_1(q_1) E_1 ... M_n(q_n) E_n`, each
/// joint motion `M_i` a rotation about (or translation along) z.
///
/// MDH link i is `Rx(alpha) Tx(a) Ry(beta) Rz(phi) Tz(d) * M_i` (Rz and Tz commute with the
/// motion), DH link i is `M_i * Rz(phi) Tz(d) Tx(a) Rx(alpha) Ry(beta)`.
pub fn chain_frames(robot: &Robot) -> Vec<Frame> {
    let n = robot.dof();
    let mut e = vec![Frame::identity(); n + 1];
    for (i, l) in robot.links().iter().enumerate() {
        let rz_tz = frame::frame(frame::rot_z(l.phi), Vector3::new(0.0, 0.0, 0.0))
            * Translation3::new(0.0, 0.0, l.d);
        let c = frame::frame(
            frame::rot_x(l.alpha) * frame::rot_y(l.beta),
            Vector3::new(l.a, 0.0, 0.0),
        );
        match robot.convention() {
            Convention::Mdh => e[i] *= c * rz_tz,
            Convention::Dh => e[i + 1] = rz_tz * c,
        }
    }
    e
}

/// `<origin>` of a frame in mm: xyz in metres and URDF roll, pitch, yaw.
fn origin(f: &Frame) -> urdf_rs::Pose {
    let (r, p, y) = f.rotation.euler_angles();
    let t = f.translation.vector / 1000.0;
    urdf_rs::Pose {
        xyz: urdf_rs::Vec3([t.x, t.y, t.z]),
        rpy: urdf_rs::Vec3([r, p, y]),
    }
}

fn link(name: &str) -> urdf_rs::Link {
    urdf_rs::Link {
        name: name.to_owned(),
        inertial: Default::default(),
        visual: Vec::new(),
        collision: Vec::new(),
    }
}

fn joint(
    name: &str,
    kind: urdf_rs::JointType,
    parent: &str,
    child: &str,
    f: &Frame,
) -> urdf_rs::Joint {
    urdf_rs::Joint {
        name: name.to_owned(),
        joint_type: kind,
        origin: origin(f),
        parent: urdf_rs::LinkName {
            link: parent.to_owned(),
        },
        child: urdf_rs::LinkName {
            link: child.to_owned(),
        },
        axis: urdf_rs::Axis {
            xyz: urdf_rs::Vec3([0.0, 0.0, 1.0]),
        },
        limit: Default::default(),
        calibration: None,
        dynamics: None,
        mimic: None,
        safety_controller: None,
    }
}

/// Links: `base_link` (the base frame's reference) -> fixed `base` -> `frame0` -> `joint_i` ->
/// `link_i` ... -> fixed `flange` -> fixed `tool` -> `tcp` (and `target_k` for further
/// reflectors, beside `tcp`). Revolute limits in radians, prismatic ones (and joint values) in
/// metres.
fn export_urdf(robot: &Robot, notes: &[String]) -> Result<String> {
    let n = robot.dof();
    let e = chain_frames(robot);
    let mut links = vec![link("base_link"), link("frame0")];
    let mut joints = vec![joint(
        "base",
        urdf_rs::JointType::Fixed,
        "base_link",
        "frame0",
        robot.base_frame(),
    )];
    let mut parent = "frame0".to_owned();
    for i in 0..n {
        let child = format!("link_{}", i + 1);
        let (kind, scale) = match robot.joint_type(i) {
            JointType::Revolute => (urdf_rs::JointType::Revolute, 1.0),
            JointType::Prismatic => (urdf_rs::JointType::Prismatic, 1e-3),
        };
        let mut j = joint(&format!("joint_{}", i + 1), kind, &parent, &child, &e[i]);
        let l = robot.limits()[i];
        j.limit = urdf_rs::JointLimit {
            lower: l.min * scale,
            upper: l.max * scale,
            ..Default::default()
        };
        joints.push(j);
        links.push(link(&child));
        parent = child;
    }
    links.push(link("flange"));
    joints.push(joint(
        "flange",
        urdf_rs::JointType::Fixed,
        &parent,
        "flange",
        &e[n],
    ));
    for t in 0..robot.target_count() {
        let name = if t == 0 {
            "tcp".to_owned()
        } else {
            format!("target_{}", t + 1)
        };
        links.push(link(&name));
        joints.push(joint(
            &format!("{name}_fixed"),
            urdf_rs::JointType::Fixed,
            "flange",
            &name,
            robot.target_tool_frame(t),
        ));
    }
    let u = urdf_rs::Robot {
        name: robot.name().to_owned(),
        version: None,
        links,
        joints,
        materials: Vec::new(),
    };
    let body = urdf_rs::write_to_string(&u)
        .map_err(|e| Error::invalid("robot", format!("cannot write as URDF: {e}")))?;
    let mut out = String::from("<?xml version=\"1.0\"?>\n<!--\n");
    for n in notes {
        // "--" may not stand inside an XML comment.
        out.push_str(&n.replace("--", "- -"));
        out.push('\n');
    }
    out.push_str("-->\n");
    out.push_str(
        body.trim_start_matches("<?xml version=\"1.0\"?>")
            .trim_start(),
    );
    out.push('\n');
    Ok(out)
}

#[cfg(test)]
mod tests;
