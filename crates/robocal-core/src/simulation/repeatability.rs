//! The robot's pose repeatability in the virtual cell: every move ends a little away from the
//! commanded joints, by an independent Gaussian error per joint and per move (servo resolution,
//! friction, the controller's stopping tolerance). Repeating a pose then scatters the tool point
//! as a real robot does, so that `simulate --joints plan.csv` produces the measurements of an
//! ISO 9283 test.

use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// The random stream of the repeatability errors (beside those of [`super::Stream`], so that
/// turning repeatability on changes nothing else: the same poses, noise and outliers).
const STREAM: u64 = 20;

/// The class default: each revolute joint's 1-sigma error turns the tool by this much (mm) at
/// the arm's reach ([`Robot::reach_mm`]), i.e. `std = DEFAULT_TOOL_MM / reach` rad; a
/// prismatic joint's 1-sigma error is this length. Small arms thus get larger joint errors than
/// large ones, as their gear trains and encoders are coarser for their size.
pub const DEFAULT_TOOL_MM: f64 = 0.01;

/// Per-joint random error per move (1-sigma; degrees, or mm for a prismatic joint).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RepeatabilityModel {
    /// Standard deviation per joint (deg, mm for a prismatic joint), one per joint.
    pub std_deg: Vec<f64>,
}

impl RepeatabilityModel {
    /// The same standard deviation (deg, or mm) for every joint of `robot`.
    pub fn uniform(std_deg: f64, robot: &Robot) -> Self {
        RepeatabilityModel {
            std_deg: vec![std_deg; robot.dof()],
        }
    }

    /// The class default for `robot` (see [`DEFAULT_TOOL_MM`]).
    pub fn default_for(robot: &Robot) -> Self {
        let reach = robot.reach_mm().max(1.0);
        RepeatabilityModel {
            std_deg: robot
                .joint_types()
                .iter()
                .map(|t| match t {
                    JointType::Revolute => (DEFAULT_TOOL_MM / reach).to_degrees(),
                    JointType::Prismatic => DEFAULT_TOOL_MM,
                })
                .collect(),
        }
    }

    /// Checks one finite, non-negative value of at most 1 (deg or mm) per joint. Errors name the
    /// field `repeatability.std_deg`.
    pub fn validate(&self, dof: usize) -> Result<()> {
        const FIELD: &str = "repeatability.std_deg";
        if self.std_deg.len() != dof {
            return Err(Error::invalid(
                FIELD,
                format!("{} values for {dof} joints", self.std_deg.len()),
            ));
        }
        for (i, v) in self.std_deg.iter().enumerate() {
            if !(v.is_finite() && (0.0..=1.0).contains(v)) {
                return Err(Error::invalid(
                    FIELD,
                    format!("joint {}: {v} is not a standard deviation in [0, 1]", i + 1),
                ));
            }
        }
        Ok(())
    }

    /// The joints the robot really stops at for each commanded joint vector (rad, mm): one
    /// independent error per joint and per move, from the repeatability stream of `seed`.
    pub fn attained(&self, robot: &Robot, qs: &[Vec<f64>], seed: u64) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(STREAM);
        let scale: Vec<f64> = robot
            .joint_types()
            .iter()
            .zip(&self.std_deg)
            .map(|(t, s)| match t {
                JointType::Revolute => s.to_radians(),
                JointType::Prismatic => *s,
            })
            .collect();
        qs.iter()
            .map(|q| {
                q.iter()
                    .zip(&scale)
                    .map(|(v, s)| {
                        let z: f64 = StandardNormal.sample(&mut rng);
                        v + s * z
                    })
                    .collect()
            })
            .collect()
    }
}
