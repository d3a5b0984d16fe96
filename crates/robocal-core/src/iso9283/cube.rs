//! The test cube of ISO 9283 (section 6.2): edges parallel to the base axes, the measuring plane
//! one of its diagonal planes, the five test points on it, and the search for the largest cube
//! whose test points the robot reaches with a given tool orientation.
//!
//! The measuring plane is the diagonal plane through the cube's corners `C1 = c + h(-1,-1,-1)`,
//! `C2 = c + h(1,-1,-1)`, `C3 = c + h(1,1,1)`, `C4 = c + h(-1,1,1)` (`c` the centre, `h` half
//! the edge): it holds the edge along x at the bottom front and the edge along x at the top back.
//! P1 is the centre; P2, P3, P4, P5 lie on the plane's diagonals at 10 % of the diagonal's length
//! from C1, C2, C3, C4: `P = c + 0.8 (C - c)` (a diagonal is `2 |C - c|` long). P2 and P4, P3 and
//! P5 face each other across the centre.
//!
//! A cube *fits* when it lies whole above the floor ([`Reach::floor_z_mm`]: by default the base
//! plane z = 0, the surface the robot is mounted on) and outside the robot's footprint (the
//! cylinder of [`Reach::footprint_radius_mm`] about the base z axis: its base and column), and
//! every test point is reached by the robot at the tool orientation with all
//! joints within their limits (by [`Reach::limit_margin`]), on one configuration (P2..P5 solved
//! from P1's joints and on its branch), every solution at least [`Reach::singular_margin`] away
//! from a singularity; with a calibrated model, the compensated joints must reach the poses on
//! it within the limits and half that margin from a singularity. The largest cube: for a
//! centre, the largest edge that fits (bisection, then grown in 1 % steps while it still fits);
//! without a given centre, a pattern search over centres (from the better of the reference
//! configuration's tool point and that point moved into the free space) for the largest such
//! edge.

use crate::compensation::{configuration, Compensator, DampedLeastSquares, IkStatus};
use crate::frame::Frame;
use crate::model::Robot;
use nalgebra::{Rotation3, Translation3, Vector3};

/// Fraction of the diagonal's length between a corner and its test point.
pub const CORNER_FRACTION: f64 = 0.1;

/// An axis-parallel cube.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cube {
    /// The centre (mm, base frame).
    pub centre: Vector3<f64>,
    /// The edge length (mm).
    pub edge_mm: f64,
}

impl Cube {
    /// The four corners of the measuring plane, C1..C4 (mm, base frame).
    pub fn plane_corners(&self) -> [Vector3<f64>; 4] {
        let h = 0.5 * self.edge_mm;
        [
            Vector3::new(-h, -h, -h),
            Vector3::new(h, -h, -h),
            Vector3::new(h, h, h),
            Vector3::new(-h, h, h),
        ]
        .map(|v| self.centre + v)
    }

    /// The eight corners of the cube (mm, base frame).
    pub fn corners(&self) -> [Vector3<f64>; 8] {
        let h = 0.5 * self.edge_mm;
        let mut out = [Vector3::zeros(); 8];
        for (k, c) in out.iter_mut().enumerate() {
            let s = |bit: usize| if k & bit != 0 { h } else { -h };
            *c = self.centre + Vector3::new(s(1), s(2), s(4));
        }
        out
    }

    /// The test points P1..P5 (mm, base frame).
    pub fn test_points(&self) -> [Vector3<f64>; 5] {
        let c = self.plane_corners();
        let towards = |k: usize| self.centre + (1.0 - 2.0 * CORNER_FRACTION) * (c[k] - self.centre);
        [self.centre, towards(0), towards(1), towards(2), towards(3)]
    }

    /// The test poses P1..P5: the test points with the tool orientation `rotation`.
    pub fn test_poses(&self, rotation: &Rotation3<f64>) -> [Frame; 5] {
        self.test_points()
            .map(|p| Frame::from_parts(Translation3::from(p), *rotation))
    }
}

/// Why a cube does not fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Miss {
    /// The cube reaches below the floor: the height of its lowest corner (mm, base frame).
    Floor {
        /// The lowest corner's z (mm).
        z_mm: f64,
    },
    /// The cube reaches into the robot's footprint: the distance of its nearest point from the
    /// base z axis (mm).
    Footprint {
        /// The distance (mm).
        distance_mm: f64,
    },
    /// A test pose is not reached.
    Pose {
        /// The test pose (1..5) that failed.
        pose: usize,
        /// How its solve ended (`Singular` also when the margin is below
        /// [`Reach::singular_margin`]).
        status: IkStatus,
        /// On the calibrated model (compensation) rather than the nominal.
        calibrated: bool,
    },
}

impl std::fmt::Display for Miss {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Miss::Floor { z_mm } => {
                write!(f, "its lowest corner (z = {z_mm} mm) is below the floor")
            }
            Miss::Footprint { distance_mm } => write!(
                f,
                "it comes within {distance_mm} mm of the base z axis, inside the robot's footprint"
            ),
            Miss::Pose {
                pose,
                status,
                calibrated,
            } => write!(
                f,
                "P{pose} {status} on the {} model",
                if *calibrated { "calibrated" } else { "nominal" }
            ),
        }
    }
}

/// The joints of a fitting cube's test poses.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Joints (rad) that reach P1..P5 on the nominal model.
    pub nominal: Vec<Vec<f64>>,
    /// The compensated joints (rad) on the calibrated model, when there is one.
    pub compensated: Option<Vec<Vec<f64>>>,
}

/// Whether test poses are reached: the robot, its calibrated model (optional), the tool
/// orientation and the reference configuration.
#[derive(Debug, Clone)]
pub struct Reach<'a> {
    nominal: &'a Robot,
    calibrated: Option<&'a Robot>,
    rotation: Rotation3<f64>,
    reference: Vec<f64>,
    /// Smallest configuration margin accepted ([`configuration::Configuration::margin`]) on
    /// the nominal model (half of it for the compensated joints, which move by little).
    pub singular_margin: f64,
    /// How far inside its limits every joint of a nominal solution must stay (rad for a
    /// revolute joint, mm for a prismatic one), so that the compensated joints, which differ by
    /// a calibration's corrections, stay inside too. Default 1 degree (1 mm).
    pub limit_margin: f64,
    /// Lowest z (mm, base frame) of any point of the cube: the floor, or the surface the robot
    /// is mounted on (its base plane, z = 0, whatever the mounting). Default 0.
    pub floor_z_mm: f64,
    /// The cube keeps at least this far (mm) from the base z axis: the robot's own base and
    /// column. Default 0.
    pub footprint_radius_mm: f64,
}

impl<'a> Reach<'a> {
    /// A reach test for `nominal` (and the compensated joints on `calibrated`), tool orientation
    /// `rotation`, P1 solved from `reference` (rad) first.
    pub fn new(
        nominal: &'a Robot,
        calibrated: Option<&'a Robot>,
        rotation: Rotation3<f64>,
        reference: Vec<f64>,
        singular_margin: f64,
    ) -> Self {
        Reach {
            nominal,
            calibrated,
            rotation,
            reference,
            singular_margin,
            limit_margin: 1f64.to_radians(),
            floor_z_mm: 0.0,
            footprint_radius_mm: 0.0,
        }
    }

    /// The tool orientation.
    pub fn rotation(&self) -> &Rotation3<f64> {
        &self.rotation
    }

    /// The reference configuration (rad) P1 is solved from first.
    pub fn reference(&self) -> &[f64] {
        &self.reference
    }

    fn margin_ok(&self, robot: &Robot, q: &[f64], margin: f64) -> bool {
        configuration::configuration(robot, q).map_or(true, |c| c.margin() >= margin)
    }

    fn inside_limits(&self, q: &[f64]) -> bool {
        q.iter()
            .zip(self.nominal.limits())
            .enumerate()
            .all(|(i, (v, l))| {
                let m = match self.nominal.joint_type(i) {
                    crate::model::JointType::Revolute => self.limit_margin,
                    crate::model::JointType::Prismatic => self.limit_margin.to_degrees(),
                };
                *v >= l.min + m && *v <= l.max - m
            })
    }

    /// Whether the whole cube lies above the floor and outside the footprint cylinder.
    pub fn clear_of_base(&self, cube: &Cube) -> Result<(), Miss> {
        let h = 0.5 * cube.edge_mm;
        let z = cube.centre.z - h;
        if z < self.floor_z_mm {
            return Err(Miss::Floor { z_mm: z });
        }
        let dx = (cube.centre.x.abs() - h).max(0.0);
        let dy = (cube.centre.y.abs() - h).max(0.0);
        let d = dx.hypot(dy);
        if d < self.footprint_radius_mm {
            return Err(Miss::Footprint { distance_mm: d });
        }
        Ok(())
    }

    /// Solves the test poses of `cube`, or says why it does not fit (the floor, the footprint,
    /// or the first pose that fails).
    pub fn solve(&self, cube: &Cube) -> Result<Solution, Miss> {
        let nom = Compensator::new(self.nominal, self.nominal, DampedLeastSquares::default())
            .expect("same robot");
        let n = self.nominal.dof();
        let poses = cube.test_poses(&self.rotation);
        self.clear_of_base(cube)?;
        let miss = |pose: usize, status: IkStatus, calibrated: bool| Miss::Pose {
            pose,
            status,
            calibrated,
        };
        let mut q1 = vec![0.0; n];
        let mut rep = nom.reach_pose(&poses[0], Some(&self.reference), &mut q1);
        if !rep.status.is_converged() {
            rep = nom.reach_pose(&poses[0], None, &mut q1);
        }
        if !rep.status.is_converged() {
            return Err(miss(1, rep.status, false));
        }
        if !self.margin_ok(self.nominal, &q1, self.singular_margin) {
            return Err(miss(1, IkStatus::Singular, false));
        }
        if !self.inside_limits(&q1) {
            return Err(miss(1, IkStatus::JointLimit, false));
        }
        let mut nominal = vec![q1.clone()];
        for (k, target) in poses.iter().enumerate().skip(1) {
            let mut q = vec![0.0; n];
            let rep = nom.reach_pose(target, Some(&q1), &mut q);
            if !rep.status.is_converged() {
                return Err(miss(k + 1, rep.status, false));
            }
            if !self.margin_ok(self.nominal, &q, self.singular_margin) {
                return Err(miss(k + 1, IkStatus::Singular, false));
            }
            if !self.inside_limits(&q) {
                return Err(miss(k + 1, IkStatus::JointLimit, false));
            }
            nominal.push(q);
        }
        let compensated = match self.calibrated {
            None => None,
            Some(cal) => {
                let comp = Compensator::new(self.nominal, cal, DampedLeastSquares::default())
                    .map_err(|_| miss(1, IkStatus::Unreachable, true))?;
                let mut out = Vec::with_capacity(5);
                for (k, d) in nominal.iter().enumerate() {
                    let mut q = vec![0.0; n];
                    let (_, rep) = comp.compensate_pose(d, &mut q);
                    if !rep.status.is_converged() {
                        return Err(miss(k + 1, rep.status, true));
                    }
                    if !self.margin_ok(cal, &q, 0.5 * self.singular_margin) {
                        return Err(miss(k + 1, IkStatus::Singular, true));
                    }
                    out.push(q);
                }
                Some(out)
            }
        };
        Ok(Solution {
            nominal,
            compensated,
        })
    }

    /// Whether the cube fits.
    pub fn fits(&self, cube: &Cube) -> bool {
        self.solve(cube).is_ok()
    }

    /// The largest edge (mm) of a cube at `centre` that fits, to `resolution_mm` (0 when not even
    /// a cube of that edge fits): bisection up to `max_edge_mm`, then grown in 1 % steps while it
    /// still fits.
    pub fn largest_edge(&self, centre: &Vector3<f64>, max_edge_mm: f64, resolution_mm: f64) -> f64 {
        let cube = |edge_mm: f64| Cube {
            centre: *centre,
            edge_mm,
        };
        if !self.fits(&cube(resolution_mm)) {
            return 0.0;
        }
        let (mut lo, mut hi) = (resolution_mm, max_edge_mm);
        if self.fits(&cube(hi)) {
            return hi;
        }
        while hi - lo > resolution_mm {
            let mid = 0.5 * (lo + hi);
            if self.fits(&cube(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        for _ in 0..100 {
            let grown = lo * 1.01;
            if grown > max_edge_mm || !self.fits(&cube(grown)) {
                break;
            }
            lo = grown;
        }
        lo
    }

    /// The largest fitting cube found by a pattern search: from the best of `starts` (centres,
    /// mm, base frame), steps along the base axes from `max_edge_mm / 8`, halved when no step
    /// improves, down to `resolution_mm`.
    pub fn largest_cube(
        &self,
        starts: &[Vector3<f64>],
        max_edge_mm: f64,
        resolution_mm: f64,
    ) -> Cube {
        let edge = |c: &Vector3<f64>| self.largest_edge(c, max_edge_mm, resolution_mm);
        let mut best = Cube {
            centre: Vector3::zeros(),
            edge_mm: f64::NEG_INFINITY,
        };
        for s in starts {
            let e = edge(s);
            if e > best.edge_mm {
                best = Cube {
                    centre: *s,
                    edge_mm: e,
                };
            }
        }
        let mut step = max_edge_mm / 8.0;
        let dirs = [
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
        ];
        while step >= resolution_mm {
            let mut moved = false;
            for d in &dirs {
                let c = best.centre + step * d;
                let e = edge(&c);
                if e > best.edge_mm + 0.5 * resolution_mm {
                    best = Cube {
                        centre: c,
                        edge_mm: e,
                    };
                    moved = true;
                }
            }
            if !moved {
                step *= 0.5;
            }
        }
        best
    }

    /// `p` (mm, base frame) moved into the free workspace: lifted to `clearance_mm` above the
    /// floor and pushed out radially to `clearance_mm` beyond the footprint (along x when it is
    /// on the axis), where it was closer.
    pub fn into_free_space(&self, p: &Vector3<f64>, clearance_mm: f64) -> Vector3<f64> {
        let mut q = *p;
        q.z = q.z.max(self.floor_z_mm + clearance_mm);
        let r = p.x.hypot(p.y);
        let want = self.footprint_radius_mm + clearance_mm;
        if self.footprint_radius_mm > 0.0 && r < want {
            let (ux, uy) = if r > 1e-9 {
                (p.x / r, p.y / r)
            } else {
                (1.0, 0.0)
            };
            q.x = want * ux;
            q.y = want * uy;
        }
        q
    }
}
