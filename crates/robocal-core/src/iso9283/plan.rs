//! The test plan of ISO 9283: the cube, the five commanded poses, their joints (nominal, or
//! compensated on a calibrated model) and the cycles P1, P5, P4, P3, P2 repeated N times.

use super::cube::{Cube, Reach, Solution};
use crate::compensation::configuration;
use crate::compensation::default_seeds;
use crate::error::{Error, Result};
use crate::frame::{frame_vector, pose, Frame};
use crate::model::Robot;
use crate::ranges::{self, in_range};
use crate::simulation::FOOTPRINT_FRACTION;
use nalgebra::{Rotation3, Vector3};

/// The order the poses are visited in each cycle (ISO 9283, 7.2.1).
pub const CYCLE_ORDER: [usize; 5] = [1, 5, 4, 3, 2];

/// The default number of cycles (ISO 9283: 30).
pub const DEFAULT_CYCLES: usize = 30;

/// The settings of a plan. All lengths in mm, angles in degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanSettings {
    /// Number of cycles (at least 2). Default [`DEFAULT_CYCLES`].
    pub cycles: usize,
    /// The cube's edge (mm); `None`: the largest that fits.
    pub edge_mm: Option<f64>,
    /// The cube's centre (mm, base frame); `None`: searched.
    pub centre_mm: Option<[f64; 3]>,
    /// The tool orientation A, B, C (deg, base frame); `None`: the tool's orientation at the
    /// reference configuration ([`reference_configuration`]).
    pub orientation_deg: Option<[f64; 3]>,
    /// Smallest configuration margin accepted at a test pose
    /// ([`configuration::Configuration::margin`]). Default 0.05 (about 3 degrees from a wrist
    /// singularity).
    pub singular_margin: f64,
    /// Resolution of the cube search (mm). Default 0.5.
    pub resolution_mm: f64,
    /// The floor (mm, base frame): no point of the cube below it. Default 0, the base plane:
    /// the surface the robot stands on (or hangs from, on a wall or ceiling: its base frame's z
    /// points away from it whatever the mounting).
    pub floor_z_mm: f64,
    /// The robot's footprint: the cube keeps this far (mm) from the base z axis; `None`:
    /// [`FOOTPRINT_FRACTION`] of the chain's length, as the simulated poses do (0 allows a cube
    /// about the axis, e.g. above the robot).
    pub footprint_radius_mm: Option<f64>,
}

impl Default for PlanSettings {
    fn default() -> Self {
        PlanSettings {
            cycles: DEFAULT_CYCLES,
            edge_mm: None,
            centre_mm: None,
            orientation_deg: None,
            singular_margin: 0.05,
            resolution_mm: 0.5,
            floor_z_mm: 0.0,
            footprint_radius_mm: None,
        }
    }
}

impl PlanSettings {
    /// Checks every setting; errors name the field.
    pub fn validate(&self) -> Result<()> {
        if !(2..=10_000).contains(&self.cycles) {
            return Err(Error::invalid(
                "cycles",
                format!("{} is not in 2..=10000 (ISO 9283: 30)", self.cycles),
            ));
        }
        if let Some(e) = self.edge_mm {
            in_range("edge_mm", e, &ranges::SIZE_MM)?;
            if e <= 0.0 {
                return Err(Error::invalid(
                    "edge_mm",
                    format!("{e} is not a positive edge"),
                ));
            }
        }
        if let Some(c) = self.centre_mm {
            for v in c {
                in_range("centre_mm", v, &ranges::LENGTH)?;
            }
        }
        if let Some(o) = self.orientation_deg {
            for v in o {
                in_range("orientation_deg", v, &ranges::ANGLE)?;
            }
        }
        if !(self.singular_margin.is_finite() && (0.0..1.0).contains(&self.singular_margin)) {
            return Err(Error::invalid(
                "singular_margin",
                format!("{} is not in [0, 1)", self.singular_margin),
            ));
        }
        in_range("floor_z_mm", self.floor_z_mm, &ranges::LENGTH)?;
        if let Some(r) = self.footprint_radius_mm {
            in_range("footprint_radius_mm", r, &ranges::SIZE_MM)?;
        }
        if !(self.resolution_mm.is_finite() && self.resolution_mm > 0.0) {
            return Err(Error::invalid(
                "resolution_mm",
                format!("{} is not a positive length", self.resolution_mm),
            ));
        }
        Ok(())
    }

    /// The footprint radius used (mm): the given one, or [`FOOTPRINT_FRACTION`] of `robot`'s
    /// chain length ([`Robot::reach_mm`]).
    pub fn footprint_radius(&self, robot: &Robot) -> f64 {
        self.footprint_radius_mm
            .unwrap_or_else(|| FOOTPRINT_FRACTION * robot.reach_mm())
    }
}

/// A test plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The cube.
    pub cube: Cube,
    /// The commanded poses P1..P5 (base frame).
    pub poses: Vec<Frame>,
    /// The joints (rad) that reach P1..P5 on the nominal model.
    pub nominal_joints: Vec<Vec<f64>>,
    /// The joints (rad) sent to the robot for P1..P5: the compensated ones with a calibrated
    /// model, else the nominal ones.
    pub joints: Vec<Vec<f64>>,
    /// Whether [`Plan::joints`] are compensated on a calibrated model.
    pub compensated: bool,
    /// Number of cycles.
    pub cycles: usize,
}

/// One row of a plan: a cycle's visit of a pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanRow {
    /// The cycle (1-based).
    pub cycle: usize,
    /// The pose (1..5).
    pub pose: usize,
}

impl Plan {
    /// The rows in the order the robot runs them: cycle by cycle, P1, P5, P4, P3, P2.
    pub fn rows(&self) -> impl Iterator<Item = PlanRow> + '_ {
        (1..=self.cycles).flat_map(|cycle| CYCLE_ORDER.map(|pose| PlanRow { cycle, pose }))
    }

    /// The commanded pose `k` (1..5) as a frame vector (mm, deg).
    pub fn pose_vector_deg(&self, k: usize) -> [f64; 6] {
        let v = frame_vector(&self.poses[k - 1]);
        [
            v[0],
            v[1],
            v[2],
            v[3].to_degrees(),
            v[4].to_degrees(),
            v[5].to_degrees(),
        ]
    }
}

/// The reference configuration (rad): the middle of every joint's range, or, when that lies
/// within `margin` of a singularity, the first of the default seed configurations
/// ([`default_seeds`]) that does not. The default tool orientation is the tool's there, and the
/// cube search starts at its tool point.
pub fn reference_configuration(robot: &Robot, margin: f64) -> Vec<f64> {
    let seeds = default_seeds(robot, 64);
    seeds
        .iter()
        .find(|q| {
            configuration::configuration(robot, q).map_or(true, |c| c.margin() >= 2.0 * margin)
        })
        .unwrap_or(&seeds[0])
        .clone()
}

/// Makes the plan for `nominal` (compensated on `calibrated` when given): the cube (searched,
/// or as given), its five poses and their joints. Fails, naming the pose and why, when the
/// given cube does not fit or no cube fits.
pub fn make_plan<'a>(
    nominal: &'a Robot,
    calibrated: Option<&'a Robot>,
    settings: &PlanSettings,
) -> Result<Plan> {
    settings.validate()?;
    let reference = reference_configuration(nominal, settings.singular_margin);
    let rotation = tool_rotation(nominal, settings, &reference);
    // The cube is searched on the nominal model (the same search before and after
    // calibration); the compensated joints on the calibrated model are then checked, and a
    // searched cube shrunk in 1 % steps where they fail at its boundary (out of the limits or
    // near a singularity). To keep the cube of the plan before calibration, give it
    // ([`super::PlanFile::cube`]): then a pose that fails is an error.
    let footprint = settings.footprint_radius(nominal);
    let search = with_rules(
        Reach::new(
            nominal,
            None,
            rotation,
            reference.clone(),
            settings.singular_margin,
        ),
        settings,
        footprint,
    );
    let reach = with_rules(
        Reach::new(
            nominal,
            calibrated,
            rotation,
            reference,
            settings.singular_margin,
        ),
        settings,
        footprint,
    );
    let mut cube = chosen_cube(nominal, &search, settings)?;
    if calibrated.is_some() && settings.edge_mm.is_none() {
        shrink_until_it_fits(&reach, &mut cube);
    }
    let sol = solve_cube(&reach, &cube, settings)?;
    let compensated = sol.compensated.is_some();
    Ok(Plan {
        cube,
        poses: cube.test_poses(&rotation).to_vec(),
        joints: sol.compensated.unwrap_or_else(|| sol.nominal.clone()),
        nominal_joints: sol.nominal,
        compensated,
        cycles: settings.cycles,
    })
}

/// The tool orientation of the test poses: the given A, B, C, else the tool's at the
/// `reference` configuration.
fn tool_rotation(nominal: &Robot, settings: &PlanSettings, reference: &[f64]) -> Rotation3<f64> {
    let rotation = match settings.orientation_deg {
        Some([a, b, c]) => {
            pose(&[
                0.0,
                0.0,
                0.0,
                a.to_radians(),
                b.to_radians(),
                c.to_radians(),
            ])
            .rotation
        }
        None => nominal.tool_pose(reference).rotation,
    };
    Rotation3::from_matrix_unchecked(*rotation.matrix())
}

/// `r` with the plan's floor and the robot's footprint (`footprint`, mm) to keep the cube out of.
fn with_rules<'a>(mut r: Reach<'a>, settings: &PlanSettings, footprint: f64) -> Reach<'a> {
    r.floor_z_mm = settings.floor_z_mm;
    r.footprint_radius_mm = footprint;
    r
}

/// The cube of the plan before any shrinking: as given, or the largest the nominal `search`
/// finds about the given centre or anywhere; an error when the given edge is larger than the
/// largest found or no cube fits.
fn chosen_cube(nominal: &Robot, search: &Reach<'_>, settings: &PlanSettings) -> Result<Cube> {
    let max_edge = nominal.reach_mm();
    let res = settings.resolution_mm;
    let cube = match (settings.centre_mm, settings.edge_mm) {
        (Some(c), Some(e)) => Cube {
            centre: Vector3::from(c),
            edge_mm: e,
        },
        (Some(c), None) => {
            let centre = Vector3::from(c);
            Cube {
                centre,
                edge_mm: search.largest_edge(&centre, max_edge, res),
            }
        }
        (None, e) => {
            let start = nominal.tool_position(search.reference());
            let starts = [start, search.into_free_space(&start, max_edge / 8.0)];
            let best = search.largest_cube(&starts, max_edge, res);
            match e {
                Some(edge_mm) if edge_mm <= best.edge_mm => Cube {
                    centre: best.centre,
                    edge_mm,
                },
                Some(edge_mm) => {
                    return Err(Error::invalid(
                        "edge_mm",
                        format!(
                            "no cube of {edge_mm} mm found: the largest found is {:.1} mm, \
                             centred at ({:.1}, {:.1}, {:.1}) mm",
                            best.edge_mm, best.centre.x, best.centre.y, best.centre.z
                        ),
                    ))
                }
                None => best,
            }
        }
    };
    if cube.edge_mm <= 0.0 {
        return Err(Error::invalid(
            "centre_mm",
            "no cube fits there: the centre is below the floor or inside the robot's footprint, \
             or the robot does not reach it with the tool orientation (within the joint limits, \
             away from singularities)",
        ));
    }
    Ok(cube)
}

/// Shrinks `cube` in 1 % steps (at most 100) until `reach` fits it.
fn shrink_until_it_fits(reach: &Reach<'_>, cube: &mut Cube) {
    for _ in 0..100 {
        if reach.fits(cube) {
            break;
        }
        cube.edge_mm *= 0.99;
    }
}

/// The joints of `cube`'s test poses on `reach`; an error naming the cube and the pose that
/// fails.
fn solve_cube(reach: &Reach<'_>, cube: &Cube, settings: &PlanSettings) -> Result<Solution> {
    reach.solve(cube).map_err(|m| {
        Error::invalid(
            if settings.edge_mm.is_some() {
                "edge_mm"
            } else {
                "centre_mm"
            },
            format!(
                "the cube of {} mm at ({}, {}, {}) mm does not fit: {m}",
                cube.edge_mm, cube.centre.x, cube.centre.y, cube.centre.z,
            ),
        )
    })
}
