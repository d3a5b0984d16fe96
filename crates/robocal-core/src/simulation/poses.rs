//! Random joint configurations spread over the workspace (paper, section II.A: "machine
//! coordinates are randomly generated, checking the tool positions to be distributed in entire
//! robot's workspace").

use crate::error::{Error, Result};
use crate::model::Robot;
use rand::Rng;

/// Rules for drawing random poses: uniform joint values within the robot's limits, rejecting
/// tool positions below a floor or inside the robot's own footprint.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseSampler {
    /// Lowest allowed tool z in the base frame (mm).
    pub floor_z_mm: f64,
    /// Tool positions closer than this to the base z axis are rejected (mm).
    pub footprint_radius_mm: f64,
    /// How many draws may be rejected per accepted pose before giving up.
    pub max_tries_per_pose: usize,
}

impl Default for PoseSampler {
    fn default() -> Self {
        PoseSampler {
            floor_z_mm: 0.0,
            footprint_radius_mm: 0.0,
            max_tries_per_pose: 10_000,
        }
    }
}

impl PoseSampler {
    /// Whether a tool position (base frame, mm) is acceptable.
    pub fn accepts(&self, p: &nalgebra::Vector3<f64>) -> bool {
        p.z >= self.floor_z_mm && (p.x * p.x + p.y * p.y).sqrt() >= self.footprint_radius_mm
    }
}

/// Tool positions within a laser tracker's working range: distance from the tracker's origin
/// (base frame) between `min_mm` and `max_mm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerRange {
    /// The tracker's origin in the base frame (mm).
    pub origin: nalgebra::Vector3<f64>,
    /// Nearest measurable distance (mm).
    pub min_mm: f64,
    /// Farthest measurable distance (mm).
    pub max_mm: f64,
}

impl TrackerRange {
    /// Whether a tool position (base frame, mm) is within range.
    pub fn accepts(&self, p: &nalgebra::Vector3<f64>) -> bool {
        let d = (p - self.origin).norm();
        d >= self.min_mm && d <= self.max_mm
    }
}

/// Draws `n` joint vectors (rad) for `robot` following `sampler`.
pub fn random_poses<R: Rng + ?Sized>(
    robot: &Robot,
    n: usize,
    sampler: &PoseSampler,
    rng: &mut R,
) -> Result<Vec<Vec<f64>>> {
    random_poses_within(robot, n, sampler, None, rng)
}

/// Draws `n` joint vectors (rad) for `robot` following `sampler` and, if given, within the
/// tracker's range.
pub fn random_poses_within<R: Rng + ?Sized>(
    robot: &Robot,
    n: usize,
    sampler: &PoseSampler,
    range: Option<&TrackerRange>,
    rng: &mut R,
) -> Result<Vec<Vec<f64>>> {
    if n == 0 {
        return Err(Error::invalid("poses", "must be at least 1"));
    }
    let mut out = Vec::with_capacity(n);
    let mut q = vec![0.0; robot.dof()];
    let mut tries = 0usize;
    while out.len() < n {
        for (v, l) in q.iter_mut().zip(robot.limits()) {
            *v = if l.max > l.min {
                rng.gen_range(l.min..=l.max)
            } else {
                l.min
            };
        }
        let p = robot.tool_position(&q);
        if sampler.accepts(&p) && range.map_or(true, |r| r.accepts(&p)) {
            out.push(q.clone());
            tries = 0;
        } else {
            tries += 1;
            if tries >= sampler.max_tries_per_pose {
                let within = range.map_or(String::new(), |r| {
                    format!(
                        " within {}..{} mm of the tracker at ({:.0}, {:.0}, {:.0}) mm",
                        r.min_mm, r.max_mm, r.origin.x, r.origin.y, r.origin.z
                    )
                });
                return Err(Error::invalid(
                    "poses",
                    format!(
                        "no acceptable pose in {} random draws: the joint limits leave no tool \
                         position above z = {} mm and outside radius {} mm{within}",
                        sampler.max_tries_per_pose, sampler.floor_z_mm, sampler.footprint_radius_mm
                    ),
                ));
            }
        }
    }
    Ok(out)
}
