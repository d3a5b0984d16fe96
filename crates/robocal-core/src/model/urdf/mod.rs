//! URDF robots: the serial chain of a URDF file (ROS's robot description) imported as a
//! modified-DH [`Robot`] that calibrates like any other.
//!
//! The file's kinematic part is read in one streaming pass (`read`, linear in the file's size,
//! into `urdf-rs`'s types); [`chain`] picks the chain
//! from the base link to the tip link and keeps the URDF's own kinematics (joint origins and
//! motions); [`mdh`] turns it into an MDH table, a base frame and a tool (the tip link's frame).
//! The import is checked: the robot's forward kinematics must equal the URDF chain's at a set of
//! joint values, or the import is an error. Units: URDF metres and radians become mm and radians
//! (limits: rad, or mm for a prismatic joint); joint values and their signs are the URDF's.
//!
//! Which chain: `base_link` (default: the file's one root link) and `tip_link` (default: the one
//! leaf below the base that a movable joint leads to; several are an error naming them).

pub mod chain;
pub mod mdh;
mod read;

pub use chain::{Step, UrdfChain};

use crate::error::{Error, Result};
use crate::model::Robot;
use std::path::Path;

/// Which chain of a URDF to import (settings `base_link` and `tip_link`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ChainSelection {
    /// The link the robot starts at (its frame is the base frame); default: the root link.
    pub base_link: Option<String>,
    /// The link the robot ends at (its frame is the tool frame); default: the only tip.
    pub tip_link: Option<String>,
}

impl ChainSelection {
    /// Whether either link is named.
    pub fn is_given(&self) -> bool {
        self.base_link.is_some() || self.tip_link.is_some()
    }
}

/// Whether `text` looks like XML (a URDF) rather than TOML: its first non-blank character is `<`.
pub fn looks_like_urdf(text: &str) -> bool {
    text.trim_start_matches('\u{feff}')
        .trim_start()
        .starts_with('<')
}

/// Parses a URDF file's text and selects its chain; `path` names the file in errors.
pub fn parse_urdf_chain(text: &str, path: &Path, sel: &ChainSelection) -> Result<UrdfChain> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let robot = read::read(text)
        .map_err(|e| Error::parse(path, e.line, None, format!("not a valid URDF: {}", e.msg)))?;
    chain::select(&robot, sel, text, path)
}

/// Imports a URDF's chain as an MDH robot (see the module documentation), checked against the
/// URDF's own kinematics.
pub fn parse_urdf(text: &str, path: &Path, sel: &ChainSelection) -> Result<Robot> {
    let chain = parse_urdf_chain(text, path, sel)?;
    chain_robot(&chain, path)
}

/// The MDH robot of a chain, checked: its tool frame must equal the chain's tip frame within
/// 1e-9 of the chain's size (mm) at q = 0 and at joint values spread over the limits.
pub fn chain_robot(chain: &UrdfChain, path: &Path) -> Result<Robot> {
    let err = |msg: String| Error::parse(path, None, None, msg);
    let robot = mdh::to_robot(chain, err)?;
    let tol = 1e-9 * robot.reach_mm().max(1000.0);
    let worst = worst_fk_difference(chain, &robot, 64);
    if worst.is_nan() || worst > tol {
        return Err(err(format!(
            "the chain from `{}` to `{}` could not be written as a modified DH table: its \
             kinematics differ from the URDF's by {worst:.3e} mm",
            chain.base_link, chain.tip_link
        )));
    }
    Ok(robot)
}

/// Joint values spread over the robot's limits (deterministic): q = 0 first, then `count - 1`
/// points of a low-discrepancy sequence.
pub fn spread_joints(robot: &Robot, count: usize) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; robot.dof()]];
    for k in 1..count {
        out.push(
            robot
                .limits()
                .iter()
                .enumerate()
                .map(|(i, l)| {
                    // Additive recurrence with an irrational step per joint.
                    let step = (2.0 + i as f64).sqrt().fract();
                    let u = (k as f64 * step).fract();
                    l.min + u * (l.max - l.min)
                })
                .collect(),
        );
    }
    out
}

/// The largest distance (mm) between the chain's tip and the robot's tool frame over
/// [`spread_joints`], with orientation differences counted at 1 m (rad × 1000 mm).
pub fn worst_fk_difference(chain: &UrdfChain, robot: &Robot, count: usize) -> f64 {
    spread_joints(robot, count)
        .iter()
        .map(|q| frame_difference_mm(&chain.tip_pose(q), &robot.tool_pose(q)))
        .fold(0.0, f64::max)
}

/// The distance between two frames (mm): the larger of the origins' distance and the rotation
/// angle between them (for small angles; a monotonic measure of it beyond) times 1000 mm.
pub fn frame_difference_mm(a: &crate::frame::Frame, b: &crate::frame::Frame) -> f64 {
    let dp = (a.translation.vector - b.translation.vector).norm();
    // ||Ra - Rb|| (Frobenius) is 2 sqrt(2) |sin(angle / 2)|: the angle to full precision where
    // it is small (acos of the trace is not).
    let dr = (a.rotation.matrix() - b.rotation.matrix()).norm() / std::f64::consts::SQRT_2 * 1000.0;
    if dp.is_nan() || dr.is_nan() {
        f64::NAN
    } else {
        dp.max(dr)
    }
}

#[cfg(test)]
mod read_tests;
#[cfg(test)]
mod tests;
