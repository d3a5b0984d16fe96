//! Backlash (gear play) in the virtual cell: a joint stops short of its commanded value by half
//! its gear's play, on the side it came from.
//!
//! # Model
//! - Each joint j has a half play `b_j` (deg; mm for a prismatic joint). The measured pose is the
//!   one the robot reaches at `q_j - b_j * dir_j`, where `dir_j` (+1 or -1) is the sign of the
//!   joint's last motion before it stopped at this pose (its approach direction).
//! - The poses are visited in the order of the rows (the order a program visits them), starting
//!   from the robot's home ([`home`]: every joint at 0, clamped into its limits). A joint that
//!   does not move keeps the direction of its last motion; one that has never moved counts as
//!   approached from below (+1).
//! - A constant half play on every row is a joint offset (`phi`); only the difference between
//!   the two directions, `2 b_j`, is visible in the data.
//!
//! Typical figures: the lost motion of a robot's cycloidal (RV) reducer is about one arc minute
//! (0.017 deg), that of a harmonic drive a fraction of it; [`BacklashModel::for_robot`] gives a
//! default per robot class.

use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use serde::{Deserialize, Serialize};

/// The largest accepted half play (deg or mm): a degree of play on one side is not a gear but a
/// broken joint or a value in the wrong unit.
pub const MAX_HALF_PLAY: f64 = 1.0;

/// The gear play of every joint of a simulated robot (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BacklashModel {
    /// Half the play of each joint (deg; mm for a prismatic joint), one value per joint, each
    /// within `0..=`[`MAX_HALF_PLAY`].
    pub half_play_deg: Vec<f64>,
}

impl BacklashModel {
    /// The default for the robot's class, by its reach ([`Robot::reach_mm`]):
    /// - at least 2000 mm (heavy-payload arms with RV reducers, e.g. the KR 480 R3330): 0.004 deg
    ///   on joints 1..3 and 0.008 deg on the wrist joints (about half an arc minute);
    /// - 1000 to 2000 mm (medium arms): 0.003 deg and 0.006 deg;
    /// - below 1000 mm (small arms and cobots with harmonic drives, e.g. a UR5): 0.002 deg on
    ///   every joint.
    ///
    /// Prismatic joints (a linear track's rack and pinion): 0.005 mm.
    ///
    /// Why these figures for the heavy class, against the published anchors:
    /// - A cycloidal (RV) reducer's catalogued lost motion is about one arc minute, a half play
    ///   of 0.008 deg; the wrist joints get that, the main joints half of it, because gravity
    ///   holds a heavy arm's joints 2 and 3 (and the payload's moment joint 1 at many poses)
    ///   against one flank of their gears, so that only part of the play shows.
    /// - Le Reun et al. (Robotica 2022) measured 1.53 mm of bidirectional mean error on an ABB
    ///   IRB 4600 (2.55 m reach) after a geometric calibration, 0.07 mm with backlash modelled.
    ///   These defaults give a simulated KR 480 0.36 mm (the README's bidirectional test), a
    ///   quarter of that. They are not raised to it: a calibration whose poses are approached
    ///   from either side keeps half the bidirectional error in its residual, and the paper's
    ///   KR 480 calibration left 0.174 mm (its Table IV), which the IRB 4600's play (0.7 mm of
    ///   residual) rules out for that cell; with these defaults the honest cell's geometric
    ///   residual is already 0.24 to 0.28 mm over seeds 1..8 (with its gravity sag).
    pub fn for_robot(robot: &Robot) -> BacklashModel {
        let reach = robot.reach_mm();
        let (main, wrist) = if reach >= 2000.0 {
            (0.004, 0.008)
        } else if reach >= 1000.0 {
            (0.003, 0.006)
        } else {
            (0.002, 0.002)
        };
        // The wrist: the last three revolute joints of a chain with more than three of them.
        let revolute: Vec<usize> = (0..robot.dof())
            .filter(|&i| robot.joint_type(i) == JointType::Revolute)
            .collect();
        let wrist_from = if revolute.len() > 3 {
            revolute[revolute.len() - 3]
        } else {
            usize::MAX
        };
        let half_play_deg = (0..robot.dof())
            .map(|i| match robot.joint_type(i) {
                JointType::Prismatic => 0.005,
                JointType::Revolute if i >= wrist_from => wrist,
                JointType::Revolute => main,
            })
            .collect();
        BacklashModel { half_play_deg }
    }

    /// Checks the model against a robot with `dof` joints: one value per joint, each finite and
    /// within `0..=`[`MAX_HALF_PLAY`]. Errors name the setting `backlash.half_play_deg`.
    pub fn validate(&self, dof: usize) -> Result<()> {
        let name = "backlash.half_play_deg";
        if self.half_play_deg.len() != dof {
            return Err(Error::invalid(
                name,
                format!(
                    "{} values for a robot with {dof} joints (one per joint)",
                    self.half_play_deg.len()
                ),
            ));
        }
        for (i, v) in self.half_play_deg.iter().enumerate() {
            if !(v.is_finite() && (0.0..=MAX_HALF_PLAY).contains(v)) {
                return Err(Error::invalid(
                    format!("{name} (joint {})", i + 1),
                    format!(
                        "{v} is not a half play within 0..{MAX_HALF_PLAY} deg (mm for a \
                         prismatic joint)"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The joint values (internal units) the robot reaches when commanded to `q` (internal
    /// units) and approaching with directions `dir` (+1 or -1 per joint).
    pub fn reached(&self, robot: &Robot, q: &[f64], dir: &[i8]) -> Vec<f64> {
        q.iter()
            .zip(dir)
            .enumerate()
            .map(|(i, (v, d))| {
                let b = match robot.joint_type(i) {
                    JointType::Revolute => self.half_play_deg[i].to_radians(),
                    JointType::Prismatic => self.half_play_deg[i],
                };
                v - b * f64::from(*d)
            })
            .collect()
    }
}

/// The robot's home: every joint at 0, clamped into its limits (internal units).
pub fn home(robot: &Robot) -> Vec<f64> {
    robot
        .limits()
        .iter()
        .map(|l| 0.0_f64.clamp(l.min, l.max))
        .collect()
}

/// The approach direction (+1 or -1) of every joint at every pose when the poses `qs` are
/// visited in order from `start` (see the module documentation): the sign of the joint's last
/// motion; +1 for a joint that has not moved yet.
pub fn approach_directions(start: &[f64], qs: &[Vec<f64>]) -> Vec<Vec<i8>> {
    let mut prev = start.to_vec();
    let mut dir = vec![1_i8; start.len()];
    let mut out = Vec::with_capacity(qs.len());
    for q in qs {
        for (j, (a, b)) in q.iter().zip(&prev).enumerate() {
            if a > b {
                dir[j] = 1;
            } else if a < b {
                dir[j] = -1;
            }
        }
        out.push(dir.clone());
        prev.clone_from(q);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::preset;

    #[test]
    fn directions_follow_the_last_motion() {
        let qs = vec![
            vec![1.0, 0.0],
            vec![0.5, 0.0],
            vec![0.5, -1.0],
            vec![0.7, -1.0],
        ];
        let d = approach_directions(&[0.0, 0.0], &qs);
        assert_eq!(d, vec![vec![1, 1], vec![-1, 1], vec![-1, -1], vec![1, -1]]);
    }

    #[test]
    fn reached_is_short_of_the_command_on_the_side_it_came_from() {
        let r = crate::load_robot_file(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/ur5.toml"
        )))
        .unwrap();
        let m = BacklashModel::for_robot(&r);
        m.validate(6).unwrap();
        let q = vec![0.1; 6];
        let up = m.reached(&r, &q, &[1; 6]);
        let down = m.reached(&r, &q, &[-1; 6]);
        for i in 0..6 {
            let b = m.half_play_deg[i].to_radians();
            assert!((q[i] - up[i] - b).abs() < 1e-15);
            assert!((down[i] - q[i] - b).abs() < 1e-15);
        }
    }

    #[test]
    fn defaults_follow_the_class_and_bad_values_are_named() {
        let kr = preset("kuka-kr480-r3330").unwrap();
        let m = BacklashModel::for_robot(&kr);
        assert_eq!(
            m.half_play_deg,
            vec![0.004, 0.004, 0.004, 0.008, 0.008, 0.008]
        );
        let bad = BacklashModel {
            half_play_deg: vec![0.004, -0.1, 0.0, 0.0, 0.0, 0.0],
        };
        let e = bad.validate(6).unwrap_err().to_string();
        assert!(e.contains("backlash.half_play_deg (joint 2)"), "{e}");
        assert!(BacklashModel {
            half_play_deg: vec![0.0; 5]
        }
        .validate(6)
        .is_err());
    }
}
