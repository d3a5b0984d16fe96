//! The settings of a simulated session as a user gives them (the `robocal simulate` flags, the
//! `robocal.simulate` keyword arguments), checked once, here: [`SimulationBuilder::build`]
//! refuses every bad setting with the library's error naming it (the field of
//! [`SimulationConfig`] or of this builder), so that the command line and the Python bindings
//! refuse the same input with the same message (each shows the setting as its own flag or
//! keyword). Counts outside their limits and settings given where they do not apply are
//! [`Error::Usage`]; values outside their plausible ranges are [`Error::Invalid`].

use super::backlash::BacklashModel;
use super::config::SimulationConfig;
use super::gravity::GravityModel;
use super::outliers::OutlierModel;
use super::repeatability::RepeatabilityModel;
use super::targets::TargetMeasurement;
use super::thermal::ThermalModel;
use super::truth::{check_truth_matches, GeometricErrors, TruthSpec};
use super::truth_file::TruthFile;
use crate::error::{Error, Result};
use crate::io::result::FrameVec;
use crate::model::Robot;
use std::path::Path;

/// Most poses of one session (calibration + validation). Measured: 1,000,000 poses take 0.5 GB
/// of memory and 9 s and write a 139 MB CSV, so 10,000,000 need about 5 GB, 1.5 minutes and
/// 1.4 GB of disk: still a fraction of a 2-core, 24 GiB machine, and far beyond any real
/// calibration (the paper uses 75 + 73). Larger sets: several runs with different seeds.
pub const MAX_POSES: usize = 10_000_000;

/// Why [`MAX_POSES`] (for messages).
const POSES_WHY: &str = "about 5 GB of memory and a 1.4 GB file at the limit; draw larger sets \
                         in several runs with different seeds";

/// The largest orientation noise of a simulated 6-DoF probe (deg).
pub const MAX_ORIENTATION_SIGMA_DEG: f64 = 10.0;

/// The robot that really moves, as given.
#[derive(Debug, Clone)]
pub enum TruthSource {
    /// The nominal robot with seeded random geometric errors (sizes from the builder).
    Random,
    /// A robot (a preset, a robot file).
    Robot(Robot),
    /// The robot of an earlier truth file, and its tracker frame (the session's default).
    File {
        /// The truth robot.
        robot: Robot,
        /// The tracker frame the file records.
        tracker: FrameVec,
    },
}

impl TruthSource {
    /// The truth a user names: `random`, a truth file (`*.json`) of a simulation of `nominal`,
    /// or a preset or robot file.
    pub fn from_arg(arg: &str, nominal: &Robot) -> Result<TruthSource> {
        if arg == "random" {
            return Ok(TruthSource::Random);
        }
        if arg.ends_with(".json") {
            let p = Path::new(arg);
            let tf = TruthFile::read(p)?;
            let robot = tf.truth_robot(nominal, p)?;
            return Ok(TruthSource::File {
                robot,
                tracker: tf.tracker_frame,
            });
        }
        Ok(TruthSource::Robot(crate::load_robot(arg)?))
    }
}

/// Per-joint values of a model: the robot class's default, or values (one for all joints or
/// one per joint).
#[derive(Debug, Clone, PartialEq)]
pub enum PerJoint {
    /// The default of the robot's class.
    ClassDefault,
    /// One value for every joint, or one per joint.
    Values(Vec<f64>),
}

/// Everything a simulated session is given, unchecked: set the fields, then
/// [`SimulationBuilder::build`]. `None` and the defaults are what the command line's absent
/// flags mean.
#[derive(Debug, Clone)]
pub struct SimulationBuilder {
    /// The seed of every random choice.
    pub seed: u64,
    /// Random calibration poses; `None` with [`SimulationBuilder::joints_given`].
    pub poses: Option<usize>,
    /// Random validation poses.
    pub validation_poses: usize,
    /// Given joint values are measured instead of random poses (no pose counts, no plane).
    pub joints_given: bool,
    /// Add the paper's three plane points.
    pub plane_points: bool,
    /// Height of the plane points' plane (mm); `None`: the median tool height.
    pub plane_z_mm: Option<f64>,
    /// The tracker's pose; `None`: the truth file's, else the default.
    pub tracker_frame: Option<FrameVec>,
    /// Tracker noise, constant part (mm).
    pub noise_mm: f64,
    /// Tracker noise per metre (mm/m).
    pub noise_per_m: f64,
    /// A random truth's length errors (mm); `None`: the default.
    pub length_sigma_mm: Option<f64>,
    /// A random truth's angle errors (deg); `None`: the default.
    pub angle_sigma_deg: Option<f64>,
    /// A random truth tilts nominally parallel axes.
    pub tilt_parallel_axes: bool,
    /// Lowest tool point (mm).
    pub floor_z_mm: f64,
    /// Smallest distance of the tool point from the base axis (mm); `None`: automatic.
    pub footprint_radius_mm: Option<f64>,
    /// Joint compliances (rad per N·m, one or one per joint): turns gravity on.
    pub compliance_rad_per_nm: Option<Vec<f64>>,
    /// Link masses (kg, one or one per joint); `None`: 0.
    pub link_masses_kg: Option<Vec<f64>>,
    /// Payload (kg); `None`: 0.
    pub payload_kg: Option<f64>,
    /// Share of readings displaced (turns outliers on).
    pub outlier_fraction: Option<f64>,
    /// Smallest outlier displacement (mm); `None`: the default.
    pub outlier_min_mm: Option<f64>,
    /// Largest outlier displacement (mm); `None`: the default.
    pub outlier_max_mm: Option<f64>,
    /// Measure every reflector of the robot.
    pub all_targets: bool,
    /// 6-DoF measurements with this orientation noise (deg).
    pub orientation_sigma_deg: Option<f64>,
    /// Repeatability per joint (deg).
    pub repeatability: Option<PerJoint>,
    /// Backlash: half the gear play per joint (deg).
    pub backlash: Option<PerJoint>,
    /// Thermal growth with the class's defaults.
    pub thermal: bool,
    /// Thermal rise (K); `None`: the class's.
    pub thermal_rise_c: Option<f64>,
    /// Start on the warm-up curve (s); `None`: 0.
    pub thermal_start_s: Option<f64>,
    /// Seconds between poses; `None`: the class's.
    pub seconds_per_pose: Option<f64>,
    /// How much each link warms relative to the measured temperature (one value for all
    /// links or one per link, [`ThermalModel::link_gain`]); `None`: evenly.
    pub thermal_link_gain: Option<Vec<f64>>,
    /// The tracker station (0: `tracker_frame`).
    pub station: u32,
}

impl Default for SimulationBuilder {
    /// Seed 1, no poses given, plane points, the default tracker and noise, nothing else.
    fn default() -> Self {
        let d = SimulationConfig::default();
        SimulationBuilder {
            seed: 1,
            poses: None,
            validation_poses: 0,
            joints_given: false,
            plane_points: true,
            plane_z_mm: None,
            tracker_frame: None,
            noise_mm: d.noise_mm,
            noise_per_m: d.noise_per_m,
            length_sigma_mm: None,
            angle_sigma_deg: None,
            tilt_parallel_axes: false,
            floor_z_mm: d.floor_z_mm,
            footprint_radius_mm: None,
            compliance_rad_per_nm: None,
            link_masses_kg: None,
            payload_kg: None,
            outlier_fraction: None,
            outlier_min_mm: None,
            outlier_max_mm: None,
            all_targets: false,
            orientation_sigma_deg: None,
            repeatability: None,
            backlash: None,
            thermal: false,
            thermal_rise_c: None,
            thermal_start_s: None,
            seconds_per_pose: None,
            thermal_link_gain: None,
            station: 0,
        }
    }
}

/// A session's checked settings: what [`super::simulate`] or [`super::simulate_joints`] and
/// [`super::Simulation::measure_targets`] are given.
#[derive(Debug, Clone)]
pub struct SimulationSettings {
    /// The truth robot.
    pub truth: TruthSpec,
    /// The session's configuration.
    pub config: SimulationConfig,
    /// What each pose measures beyond a point.
    pub targets: TargetMeasurement,
}

/// One value for all `dof` joints or one per joint, as setting `field`.
fn per_joint(field: &str, v: &[f64], dof: usize) -> Result<Vec<f64>> {
    match v.len() {
        1 => Ok(vec![v[0]; dof]),
        n if n == dof => Ok(v.to_vec()),
        n => Err(Error::usage(
            field,
            format!("{n} values; give one for all joints or one per joint ({dof})"),
        )),
    }
}

impl SimulationBuilder {
    /// Checks every setting against `nominal` and the truth and returns the session's settings:
    /// first the combinations and counts ([`Error::Usage`]), then every value against its
    /// plausible range ([`SimulationConfig::validate`], the truth's errors, the orientation
    /// noise) and the robots against each other ([`Error::Invalid`]).
    pub fn build(&self, nominal: &Robot, truth: TruthSource) -> Result<SimulationSettings> {
        self.check_usage(&truth)?;
        let d = SimulationConfig::default();
        let dof = nominal.dof();
        let (truth, truth_tracker) = match truth {
            TruthSource::Random => {
                let g = GeometricErrors::default();
                let e = GeometricErrors {
                    length_sigma_mm: self.length_sigma_mm.unwrap_or(g.length_sigma_mm),
                    angle_sigma_deg: self.angle_sigma_deg.unwrap_or(g.angle_sigma_deg),
                    tilt_parallel_axes: self.tilt_parallel_axes,
                };
                (TruthSpec::Random(e), None)
            }
            TruthSource::Robot(r) => (TruthSpec::Robot(r), None),
            TruthSource::File { robot, tracker } => (TruthSpec::Robot(robot), Some(tracker)),
        };
        let gravity = match &self.compliance_rad_per_nm {
            None => None,
            Some(c) => Some(GravityModel::new(
                per_joint("gravity.compliance_rad_per_nm", c, dof)?,
                match &self.link_masses_kg {
                    Some(m) => per_joint("gravity.link_masses_kg", m, dof)?,
                    None => vec![0.0; dof],
                },
                self.payload_kg.unwrap_or(0.0),
            )),
        };
        let outliers = self.outlier_fraction.map(|fraction| {
            let o = OutlierModel::default();
            OutlierModel {
                fraction,
                min_mm: self.outlier_min_mm.unwrap_or(o.min_mm),
                max_mm: self.outlier_max_mm.unwrap_or(o.max_mm),
            }
        });
        let repeatability = match &self.repeatability {
            None => None,
            Some(PerJoint::ClassDefault) => Some(RepeatabilityModel::default_for(nominal)),
            Some(PerJoint::Values(v)) => Some(RepeatabilityModel {
                std_deg: per_joint("repeatability.std_deg", v, dof)?,
            }),
        };
        let backlash = match &self.backlash {
            None => None,
            Some(PerJoint::ClassDefault) => Some(BacklashModel::for_robot(nominal)),
            Some(PerJoint::Values(v)) => Some(BacklashModel {
                half_play_deg: per_joint("backlash.half_play_deg", v, dof)?,
            }),
        };
        let link_gain = match &self.thermal_link_gain {
            Some(g) => Some(per_joint("thermal.link_gain", g, dof)?),
            None => None,
        };
        let thermal = self.thermal.then(|| {
            let t = ThermalModel::for_robot(nominal);
            ThermalModel {
                rise_c: self.thermal_rise_c.unwrap_or(t.rise_c),
                start_s: self.thermal_start_s.unwrap_or(t.start_s),
                seconds_per_pose: self.seconds_per_pose.unwrap_or(t.seconds_per_pose),
                link_gain,
                ..t
            }
        });
        let config = SimulationConfig {
            seed: self.seed,
            poses: self.poses.unwrap_or(0),
            validation_poses: self.validation_poses,
            plane_points: self.plane_points && !self.joints_given,
            plane_z_mm: self.plane_z_mm,
            floor_z_mm: self.floor_z_mm,
            footprint_radius_mm: self.footprint_radius_mm,
            tracker_frame: self
                .tracker_frame
                .or(truth_tracker)
                .unwrap_or(d.tracker_frame),
            noise_mm: self.noise_mm,
            noise_per_m: self.noise_per_m,
            gravity,
            outliers,
            repeatability,
            backlash,
            thermal,
            station: self.station,
        };
        config.validate(nominal)?;
        match &truth {
            TruthSpec::Random(e) => e.validate()?,
            TruthSpec::Robot(t) => check_truth_matches(nominal, t)?,
        }
        if let Some(s) = self.orientation_sigma_deg {
            if !(0.0..=MAX_ORIENTATION_SIGMA_DEG).contains(&s) {
                return Err(Error::invalid(
                    "orientation_sigma_deg",
                    format!("{s}: not an angle noise in [0, {MAX_ORIENTATION_SIGMA_DEG}] deg"),
                ));
            }
        }
        // A setting that does not apply to this robot: a usage error.
        if self.all_targets && nominal.target_count() < 2 {
            return Err(Error::usage(
                "targets",
                format!(
                    "robot `{}` has one target; give its reflectors' nominal tools in the robot \
                     file (`tools = [[x, y, z, a, b, c], ...]`)",
                    nominal.name()
                ),
            ));
        }
        Ok(SimulationSettings {
            truth,
            config,
            targets: TargetMeasurement {
                all_targets: self.all_targets,
                orientation_sigma_deg: self.orientation_sigma_deg,
            },
        })
    }

    /// The combinations and counts ([`Error::Usage`]).
    fn check_usage(&self, truth: &TruthSource) -> Result<()> {
        if self.joints_given {
            let not = |field: &str| {
                Error::usage(
                    field,
                    "not with given joints (the given joint values are measured as they are)",
                )
            };
            if self.poses.is_some() {
                return Err(not("poses"));
            }
            if self.validation_poses > 0 {
                return Err(not("validation_poses"));
            }
            if self.plane_z_mm.is_some() {
                return Err(not("plane_z_mm"));
            }
        }
        let needs = |given: bool, field: &str, what: &str| -> Result<()> {
            if given {
                return Err(Error::usage(field, what.to_owned()));
            }
            Ok(())
        };
        needs(
            self.compliance_rad_per_nm.is_none()
                && (self.link_masses_kg.is_some() || self.payload_kg.is_some()),
            if self.link_masses_kg.is_some() {
                "gravity.link_masses_kg"
            } else {
                "gravity.payload_kg"
            },
            "models gravity deflection: give `gravity.compliance_rad_per_nm` too",
        )?;
        needs(
            self.outlier_fraction.is_none()
                && (self.outlier_min_mm.is_some() || self.outlier_max_mm.is_some()),
            if self.outlier_min_mm.is_some() {
                "outliers.min_mm"
            } else {
                "outliers.max_mm"
            },
            "shapes the outliers: give `outliers.fraction` too",
        )?;
        needs(
            self.outlier_fraction.is_some()
                && (self.all_targets || self.orientation_sigma_deg.is_some()),
            "outliers.fraction",
            "outliers are drawn for single points, not with `targets` or \
             `orientation_sigma_deg`",
        )?;
        needs(
            !self.thermal
                && (self.thermal_rise_c.is_some()
                    || self.thermal_start_s.is_some()
                    || self.seconds_per_pose.is_some()
                    || self.thermal_link_gain.is_some()),
            "thermal.rise_c",
            "`thermal.rise_c`, `thermal.start_s`, `thermal.seconds_per_pose` and \
             `thermal.link_gain` shape the thermal growth: turn it on too",
        )?;
        let random_given = self.length_sigma_mm.is_some()
            || self.angle_sigma_deg.is_some()
            || self.tilt_parallel_axes;
        needs(
            random_given && !matches!(truth, TruthSource::Random),
            "truth",
            "`truth.length_sigma_mm`, `truth.angle_sigma_deg` and `truth.tilt_parallel_axes` \
             apply only to `truth` random",
        )?;
        if !self.joints_given {
            let Some(poses) = self.poses else {
                return Err(Error::usage(
                    "poses",
                    "give the number of random calibration poses, or joint values to measure",
                ));
            };
            Error::check_count("poses", poses as u64, 1, MAX_POSES as u64, POSES_WHY)?;
            Error::check_count(
                "validation_poses",
                self.validation_poses as u64,
                0,
                MAX_POSES as u64,
                POSES_WHY,
            )?;
            let all = poses + self.validation_poses;
            if all > MAX_POSES {
                return Err(Error::usage(
                    "validation_poses",
                    format!(
                        "`poses` {poses} and `validation_poses` {} are {all} poses in all, at \
                         most {MAX_POSES} ({POSES_WHY})",
                        self.validation_poses
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
#[path = "settings_tests.rs"]
mod tests;
