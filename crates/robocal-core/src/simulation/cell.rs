//! [`VirtualCell`]: a true robot, a tracker, optional non-geometric errors and seeded random
//! streams, measured as a real cell would be.

use super::backlash::{approach_directions, home, BacklashModel};
use super::config::SimulationConfig;
use super::gravity::GravityModel;
use super::outliers::{Outlier, OutlierModel};
use super::plane::{plane_poses, quantize_joints};
use super::poses::{random_poses, PoseSampler};
use super::thermal::ThermalModel;
use super::tracker::Tracker;
use super::truth::{check_truth_matches, TruthSpec};
use crate::error::{Error, Result};
use crate::model::Robot;
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The independent random streams of a cell. Each purpose has its own ChaCha stream of the same
/// seed, so that, e.g., adding validation poses or dropping the plane points does not change the
/// calibration poses or the truth robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u64)]
pub enum Stream {
    /// Random geometric errors of a `random` truth robot.
    Truth = 1,
    /// The three plane poses.
    Plane = 2,
    /// Calibration poses ([`VirtualCell::random_poses`]).
    Calibration = 3,
    /// Validation poses ([`VirtualCell::validation_poses`]).
    Validation = 4,
    /// Tracker noise.
    Noise = 5,
    /// Outliers.
    Outliers = 6,
}

/// A seeded ChaCha RNG for one purpose of a cell.
pub fn stream_rng(seed: u64, stream: Stream) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream as u64);
    r
}

/// What the tracker reported for a batch of joint vectors, with the truth behind it.
#[derive(Debug, Clone, PartialEq)]
pub struct Readings {
    /// The readings (mm, tracker frame): what a measurement file holds.
    pub points: Vec<Vector3<f64>>,
    /// The same without noise and outliers (deflection included) (mm, tracker frame).
    pub exact: Vec<Vector3<f64>>,
    /// The readings that were displaced as outliers.
    pub outliers: Vec<Outlier>,
    /// How far gravity moved each tool point (mm); zeros without a gravity model.
    pub deflection_mm: Vec<f64>,
    /// Each reading's approach direction per joint (+1 or -1), when the cell has backlash.
    pub directions: Option<Vec<Vec<i8>>>,
    /// Each reading's time since the session started (s) and the arm's temperature (deg C),
    /// when the cell has thermal growth.
    pub thermal: Option<Vec<(f64, f64)>>,
}

/// A simulated robot cell: the robot the controller believes in (nominal), the robot that really
/// moves (truth), a laser tracker, optional gravity deflection and outliers, and seeded random
/// streams (see [`Stream`]). Methods that draw random numbers take `&mut self`; a sequence of
/// calls on a cell built from the same inputs always gives the same results.
#[derive(Debug, Clone)]
pub struct VirtualCell {
    nominal: Robot,
    truth: Robot,
    tracker: Tracker,
    sampler: PoseSampler,
    plane_z_mm: Option<f64>,
    gravity: Option<GravityModel>,
    outliers: Option<OutlierModel>,
    backlash: Option<BacklashModel>,
    thermal: Option<ThermalModel>,
    seed: u64,
    plane_rng: ChaCha8Rng,
    cal_rng: ChaCha8Rng,
    val_rng: ChaCha8Rng,
    noise_rng: ChaCha8Rng,
    outlier_rng: ChaCha8Rng,
}

impl VirtualCell {
    /// A cell with the nominal and true robots, a tracker and a seed; no gravity deflection, no
    /// outliers, the default pose sampler. Fails if the robots differ in joint count or
    /// convention.
    pub fn new(nominal: Robot, truth: Robot, tracker: Tracker, seed: u64) -> Result<VirtualCell> {
        check_truth_matches(&nominal, &truth)?;
        Ok(VirtualCell {
            nominal,
            truth,
            tracker,
            sampler: PoseSampler::default(),
            plane_z_mm: None,
            gravity: None,
            outliers: None,
            backlash: None,
            thermal: None,
            seed,
            plane_rng: stream_rng(seed, Stream::Plane),
            cal_rng: stream_rng(seed, Stream::Calibration),
            val_rng: stream_rng(seed, Stream::Validation),
            noise_rng: stream_rng(seed, Stream::Noise),
            outlier_rng: stream_rng(seed, Stream::Outliers),
        })
    }

    /// The cell a configuration describes: the truth robot (drawn from the `Truth` stream for a
    /// `random` truth), the tracker, the pose sampler, gravity and outliers. Validates `config`.
    pub fn from_config(
        nominal: &Robot,
        truth: &TruthSpec,
        config: &SimulationConfig,
    ) -> Result<VirtualCell> {
        config.validate(nominal)?;
        let truth = match truth {
            TruthSpec::Robot(r) => r.clone(),
            TruthSpec::Random(e) => {
                e.apply(nominal, &mut stream_rng(config.seed, Stream::Truth))?
            }
        };
        let tracker = Tracker::new(
            config.station_tracker_frame().to_tracker_frame(),
            config.noise_mm,
            config.noise_per_m,
        )?;
        let mut cell = VirtualCell::new(nominal.clone(), truth, tracker, config.seed)?
            .with_sampler(config.sampler(nominal));
        cell.plane_z_mm = config.plane_z_mm;
        if let Some(g) = &config.gravity {
            cell = cell.with_gravity(g.clone())?;
        }
        if let Some(o) = config.outliers {
            cell = cell.with_outliers(o)?;
        }
        cell.backlash.clone_from(&config.backlash);
        cell.thermal.clone_from(&config.thermal);
        Ok(cell)
    }

    /// Uses `sampler` for random poses.
    pub fn with_sampler(mut self, sampler: PoseSampler) -> VirtualCell {
        self.sampler = sampler;
        self
    }

    /// Adds gravity deflection (validated against the robot).
    pub fn with_gravity(mut self, gravity: GravityModel) -> Result<VirtualCell> {
        gravity.validate(self.truth.dof())?;
        self.gravity = Some(gravity);
        Ok(self)
    }

    /// Adds gross outliers (validated).
    pub fn with_outliers(mut self, outliers: OutlierModel) -> Result<VirtualCell> {
        outliers.validate()?;
        self.outliers = Some(outliers);
        Ok(self)
    }

    /// The robot the controller believes in.
    pub fn nominal(&self) -> &Robot {
        &self.nominal
    }

    /// The robot that really moves.
    pub fn truth(&self) -> &Robot {
        &self.truth
    }

    /// The tracker (its frame is the true `tracker_frame`).
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// The pose sampler.
    pub fn sampler(&self) -> &PoseSampler {
        &self.sampler
    }

    /// The gravity model, if any.
    pub fn gravity(&self) -> Option<&GravityModel> {
        self.gravity.as_ref()
    }

    /// The outlier model, if any.
    pub fn outlier_model(&self) -> Option<&OutlierModel> {
        self.outliers.as_ref()
    }

    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// `n` random calibration poses (rad or mm, quantized to the CSV's 1e-9 degree or mm), uniform within
    /// the joint limits, rejecting nominal tool points below the floor or inside the footprint
    /// (paper, section II.A). Successive calls continue the `Calibration` stream.
    pub fn random_poses(&mut self, n: usize) -> Result<Vec<Vec<f64>>> {
        draw(&self.nominal, n, &self.sampler, &mut self.cal_rng)
    }

    /// `n` random validation poses, like [`VirtualCell::random_poses`] but from the
    /// `Validation` stream, so they do not depend on how many calibration poses were drawn.
    pub fn validation_poses(&mut self, n: usize) -> Result<Vec<Vec<f64>>> {
        draw(&self.nominal, n, &self.sampler, &mut self.val_rng)
    }

    /// The paper's three plane poses (see [`super::plane_poses`]) and the plane's height (mm).
    pub fn plane_poses(&mut self) -> Result<(Vec<Vec<f64>>, f64)> {
        plane_poses(
            &self.nominal,
            &self.sampler,
            self.plane_z_mm,
            &mut self.plane_rng,
        )
    }

    /// Where the true tool point is (mm, base frame) when the controller is commanded to `q`
    /// (rad): the truth robot's forward kinematics at `q + dq` (gravity deflection, if any).
    /// Backlash and thermal growth depend on the session (see [`VirtualCell::measure`]).
    pub fn true_position(&self, q: &[f64]) -> Vector3<f64> {
        position_of(&self.truth, self.gravity.as_ref(), q)
    }

    /// The backlash model, if any.
    pub fn backlash(&self) -> Option<&BacklashModel> {
        self.backlash.as_ref()
    }

    /// The thermal growth model, if any.
    pub fn thermal(&self) -> Option<&ThermalModel> {
        self.thermal.as_ref()
    }

    /// Where target `t`'s frame really is (base frame) when the controller is commanded to `q`
    /// (0-based target of the truth robot; see [`Robot::target_count`]).
    pub fn true_target_pose(&self, q: &[f64], t: usize) -> crate::frame::Frame {
        match &self.gravity {
            Some(g) => self.truth.target_pose(&g.deflected(&self.truth, q), t),
            None => self.truth.target_pose(q, t),
        }
    }

    /// Measures target `t` (0-based) at every joint vector as a 6-DoF probe would: the point as
    /// [`VirtualCell::measure`] does (the tracker's noise), and the frame's orientation in the
    /// tracker frame, turned by a random rotation of `orientation_sigma_deg` per axis. Outliers
    /// are not drawn.
    pub fn measure_target_frames(
        &mut self,
        qs: &[Vec<f64>],
        t: usize,
        orientation_sigma_deg: f64,
    ) -> Result<Vec<(Vector3<f64>, nalgebra::Matrix3<f64>)>> {
        use rand_distr::{Distribution, StandardNormal};
        if t >= self.truth.target_count() {
            return Err(Error::invalid(
                "target",
                format!(
                    "target {} of a robot with {} targets",
                    t + 1,
                    self.truth.target_count()
                ),
            ));
        }
        if !(orientation_sigma_deg >= 0.0 && orientation_sigma_deg.is_finite()) {
            return Err(Error::invalid(
                "orientation_sigma_deg",
                format!("{orientation_sigma_deg} is not a non-negative angle (deg)"),
            ));
        }
        let mut out = Vec::with_capacity(qs.len());
        let fr = *self.tracker.frame.pose();
        for (i, q) in qs.iter().enumerate() {
            self.truth
                .check_joints(q, &format!("joint vector {}", i + 1))?;
            let f = self.true_target_pose(q, t);
            let p = self
                .tracker
                .measure(&f.translation.vector, &mut self.noise_rng);
            let mut r = fr.rotation.inverse() * f.rotation;
            if orientation_sigma_deg > 0.0 {
                let mut v = Vector3::zeros();
                for k in 0..3 {
                    let z: f64 = StandardNormal.sample(&mut self.noise_rng);
                    v[k] = orientation_sigma_deg.to_radians() * z;
                }
                r = nalgebra::Rotation3::new(v) * r;
            }
            out.push((p, *r.matrix()));
        }
        Ok(out)
    }

    /// Measures the tool at every joint vector (rad): the tracker's readings (mm, tracker frame).
    pub fn measure_joints(&mut self, qs: &[Vec<f64>]) -> Result<Vec<Vector3<f64>>> {
        Ok(self.measure(qs)?.points)
    }

    /// Measures the tool at every joint vector (rad), returning the readings with the exact
    /// values, the outliers and the gravity effect. Joint vectors must have the robot's joint
    /// count and finite values; values outside the limits are measured anyway (the caller may
    /// warn: see [`Robot::joints_outside_limits`]). The joint vectors are one session visited in
    /// order: with backlash, each joint stops short on the side it came from (from the robot's
    /// home); with thermal growth, row r is measured `r` poses into the warm-up.
    pub fn measure(&mut self, qs: &[Vec<f64>]) -> Result<Readings> {
        self.measure_approached(qs, None)
    }

    /// [`VirtualCell::measure`] with each pose's approach directions given (+1 or -1 per joint,
    /// one list per pose): the program approaches every pose from those sides (an approach
    /// move before it), instead of from wherever the previous pose left the joints.
    pub fn measure_approached(
        &mut self,
        qs: &[Vec<f64>],
        given: Option<&[Vec<i8>]>,
    ) -> Result<Readings> {
        if let Some(g) = given {
            if g.len() != qs.len() {
                return Err(Error::invalid(
                    "directions",
                    format!("{} direction lists for {} poses", g.len(), qs.len()),
                ));
            }
        }
        for (i, q) in qs.iter().enumerate() {
            self.truth
                .check_joints(q, &format!("joint vector {}", i + 1))?;
        }
        let mut points = Vec::with_capacity(qs.len());
        let mut exact = Vec::with_capacity(qs.len());
        let mut deflection_mm = Vec::with_capacity(qs.len());
        let directions = self.backlash.as_ref().map(|_| match given {
            Some(g) => g.to_vec(),
            None => approach_directions(&home(&self.truth), qs),
        });
        let thermal = self.thermal.as_ref().map(|t| {
            (0..qs.len())
                .map(|r| (t.time_s(r), t.temperature_c(t.time_s(r))))
                .collect::<Vec<_>>()
        });
        for (r, q) in qs.iter().enumerate() {
            let grown = match (&self.thermal, &thermal) {
                (Some(t), Some(v)) => Some(t.grown(&self.truth, v[r].1)),
                _ => None,
            };
            let robot = grown.as_ref().unwrap_or(&self.truth);
            let reached = match (&self.backlash, &directions) {
                (Some(b), Some(d)) => Some(b.reached(robot, q, &d[r])),
                _ => None,
            };
            let q = reached.as_deref().unwrap_or(q);
            let p = position_of(robot, self.gravity.as_ref(), q);
            deflection_mm.push(match &self.gravity {
                Some(_) => (p - robot.tool_position(q)).norm(),
                None => 0.0,
            });
            exact.push(self.tracker.exact(&p));
            points.push(self.tracker.measure(&p, &mut self.noise_rng));
        }
        let outliers = match &self.outliers {
            Some(m) => m.draw(qs.len(), &mut self.outlier_rng),
            None => Vec::new(),
        };
        for o in &outliers {
            points[o.index] += Vector3::from(o.displacement_mm);
        }
        // A reading no measurement file may hold (crate::ranges::LENGTH) is never produced.
        for (i, p) in points.iter().enumerate() {
            for (k, v) in p.iter().enumerate() {
                crate::ranges::LENGTH.check(*v).map_err(|msg| {
                    Error::invalid(
                        format!("reading {} ({})", i + 1, ["x", "y", "z"][k]),
                        format!(
                            "{msg}: the tracker frame, the noise or the robot put the simulated \
                             reading beyond what a measurement file may hold"
                        ),
                    )
                })?;
            }
        }
        Ok(Readings {
            points,
            exact,
            outliers,
            deflection_mm,
            directions,
            thermal,
        })
    }
}

/// The tool point of `robot` commanded to `q`, deflected by `gravity` if given.
fn position_of(robot: &Robot, gravity: Option<&GravityModel>, q: &[f64]) -> Vector3<f64> {
    match gravity {
        Some(g) => robot.tool_position(&g.deflected(robot, q)),
        None => robot.tool_position(q),
    }
}

fn draw(
    robot: &Robot,
    n: usize,
    sampler: &PoseSampler,
    rng: &mut ChaCha8Rng,
) -> Result<Vec<Vec<f64>>> {
    let mut qs = random_poses(robot, n, sampler, rng)?;
    for q in &mut qs {
        quantize_joints(robot, q);
    }
    Ok(qs)
}
