//! robocal-core: kinematic calibration of serial robots from laser-tracker measurements.
//!
//! The method follows Samak et al. (2019), "Computer-based simulation and validation of robot
//! accuracy improvement method and its verification in robot calibration procedure": screw-theory
//! kinematics (eq. 6), registration of the measurement frame (eq. 8-11), identification by
//! minimizing the total displacement error (eq. 4), validation, IK-based compensation (eq. 12-14)
//! and verification.
//!
//! Units: millimetres and radians inside the library; millimetres and degrees at every interface
//! (files, reports). A prismatic joint's value is millimetres everywhere; every conversion of joint
//! values goes through [`JointSpace`] (`Robot::joint_space`), which also holds the controller's
//! axis map. See `DESIGN.md` for the conventions.
//!
//! The library never prints. Long work (simulating, calibrating, compensating many rows, Monte
//! Carlo trials, a whole experiment) reports its progress to one observer type,
//! [`progress::Observer`]: `fn progress(&self, stage: Stage, done: usize, total: usize)`, with
//! [`progress::Stage`] naming every long stage (the solver's iterations too). Pass `&()` to
//! ignore it, or a closure `|stage, done, total| ...`; observers are `Send + Sync`, so Monte
//! Carlo trials report from rayon's worker threads.
//!
//! Errors about settings name the setting, never a command-line flag: the field of the settings
//! struct (`noise_mm`, `gravity.payload_kg`, `identifiability.fix`), as the `field` of
//! [`Error::Invalid`] or in backticks inside a message. A front end maps them to its own words.
//!
//! The model is open at two seams. A parameter family ([`ParameterFamily`], `model/family/`: the
//! link table, Hayati tilts, base and tool today) contributes named, unit-carrying parameters and
//! their Jacobian columns as screws at the tool; a measurement kind ([`MeasurementKind`],
//! `observations/kinds/`: one reflector's point today) turns those screws into its residual
//! rows. Problem assembly, identifiability, the solver, the covariance, the result
//! ([`ParamVector`]) and the tables use both without knowing which they are: adding a family or
//! a kind is adding a file and a registry line.
#![warn(missing_docs)]

pub mod compensation;
pub mod error;
pub mod evaluation;
pub mod experiment;
pub mod frame;
pub mod identification;
pub mod io;
pub mod iso9283;
pub mod kinematics;
pub mod model;
pub mod observations;
pub mod planning;
pub mod programs;
pub mod progress;
pub mod ranges;
pub mod registration;
pub mod simulation;
pub mod stats;
pub mod trig;
pub mod unit;

#[cfg(test)]
mod messages_tests;
#[cfg(test)]
mod study_tests;

pub use compensation::{Compensator, DampedLeastSquares, IkSolver, IkStatus};
pub use error::{Error, Result};
pub use frame::{frame_vector, pose, Frame, TrackerFrame};
pub use identification::{ParamEntry, ParamVector};
pub use io::robot::{load_robot, load_robot_file, load_robot_with};
pub use kinematics::poe::{Poe, Twist};
pub use model::presets::{preset, PRESETS};
pub use model::robot_file::parse_robot_toml;
pub use model::urdf::ChainSelection;
pub use model::{
    Controller, Convention, FamilyId, JointLimit, JointSpace, JointType, Link, Param,
    ParameterFamily, PoseFrames, Robot, Unit, MAX_JOINTS,
};
pub use observations::kinds::{Measurability, MeasurementKind};
pub use observations::Observations;
pub use progress::{Observer, Stage};
pub use stats::ErrorStats;
