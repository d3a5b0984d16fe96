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
#![warn(missing_docs)]

pub mod compensation;
pub mod error;
pub mod evaluation;
pub mod experiment;
pub mod frame;
pub mod identification;
pub mod io;
pub mod kinematics;
pub mod model;
pub mod observations;
pub mod ranges;
pub mod registration;
pub mod simulation;
pub mod stats;
pub mod unit;

pub use compensation::{Compensator, DampedLeastSquares, IkSolver, IkStatus};
pub use error::{Error, Result};
pub use frame::{frame_vector, pose, Frame};
pub use io::robot::{load_robot, load_robot_file};
pub use kinematics::poe::{Poe, Twist};
pub use model::presets::{preset, PRESETS};
pub use model::robot_file::parse_robot_toml;
pub use model::{
    Controller, Convention, JointLimit, JointSpace, JointType, Link, Param, Robot, Unit, MAX_JOINTS,
};
pub use stats::ErrorStats;
