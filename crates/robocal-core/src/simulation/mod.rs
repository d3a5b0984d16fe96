//! The virtual cell: a "true" robot measured by a simulated laser tracker (paper, section IV).
//!
//! Everything is driven by seeded ChaCha RNGs, so the same seed gives the same data.
//!
//! - [`VirtualCell`]: the nominal robot (what the controller believes), the true robot, a
//!   [`Tracker`] (pose and noise), optional gravity deflection ([`GravityModel`]) and gross
//!   outliers ([`OutlierModel`]); it draws poses ([`VirtualCell::random_poses`],
//!   [`VirtualCell::plane_poses`]) and measures joint values ([`VirtualCell::measure_joints`]).
//! - [`SimulationBuilder`]: a session's settings as a user gives them, checked once by its
//!   `build` (the CLI and the Python bindings both use it).
//! - [`SimulationConfig`]: the validated settings of a session; [`simulate`] runs the paper's
//!   session (3 plane points, calibration and validation points) and [`simulate_joints`]
//!   measures given joint values (the verification phase). [`Simulation::truth_file`] is the
//!   `FILE.truth.json` written beside the data.
//! - [`run_trials`] / [`simulate_trials`]: Monte Carlo studies in parallel, one seed per trial.
//!
//! # Noise model
//! Each coordinate (x, y, z) of a reading gets independent Gaussian noise of standard deviation
//! `sigma = noise_mm + noise_per_m * distance_m` (per axis, not of the 3-D norm: the norm of the
//! error averages about 1.6 sigma), `distance_m` being the distance from the tracker to the point.
//!
//! # Example: the paper's 3 + 75 + 73 points from one cell
//! ```
//! use robocal_core::simulation::{Tracker, VirtualCell, DEFAULT_TRACKER_FRAME};
//! use robocal_core::frame::TrackerFrame;
//! use robocal_core::preset;
//! let nominal = preset("kuka-kr480-r3330")?;
//! let truth = preset("kuka-kr480-r3330-table3")?;
//! let frame = TrackerFrame::from_vector_deg(&DEFAULT_TRACKER_FRAME);
//! let tracker = Tracker::new(frame, 0.010, 0.005)?;
//! let mut cell = VirtualCell::new(nominal, truth, tracker, 42)?;
//! let (plane, _z) = cell.plane_poses()?;
//! let cal = cell.random_poses(75)?;
//! let val = cell.validation_poses(73)?;
//! let m_cal = cell.measure_joints(&cal)?;
//! assert_eq!((plane.len(), m_cal.len(), val.len()), (3, 75, 73));
//! # Ok::<(), robocal_core::Error>(())
//! ```

mod backlash;
mod cell;
mod conditions;
mod config;
pub mod constraint;
mod gravity;
mod gravity_equivalent;
mod monte_carlo;
mod outliers;
mod plane;
mod poses;
mod repeatability;
mod session;
mod settings;
mod station;
mod targets;
mod thermal;
mod tracker;
mod truth;
mod truth_file;

pub use backlash::{approach_directions, home, BacklashModel, MAX_HALF_PLAY};
pub use cell::{stream_rng, Readings, Stream, VirtualCell};
pub use conditions::{direction_column, TEMPERATURE_COLUMN, TIME_COLUMN};
pub use config::{
    SimulationConfig, DEFAULT_NOISE_MM, DEFAULT_NOISE_PER_M, DEFAULT_TRACKER_FRAME,
    FOOTPRINT_FRACTION,
};
pub use gravity::{GravityModel, STANDARD_GRAVITY};
pub use monte_carlo::{run_trials, simulate_trials, trial_seed};
pub use outliers::{Outlier, OutlierModel};
pub use plane::{plane_poses, quantize_joints, reach_position};
pub use poses::{random_poses, random_poses_within, PoseSampler, TrackerRange};
pub use repeatability::{RepeatabilityModel, DEFAULT_TOOL_MM};
pub use session::{
    simulate, simulate_joints, Simulation, SET_CALIBRATION, SET_PLANE, SET_VALIDATION,
};
pub use settings::{
    PerJoint, SimulationBuilder, SimulationSettings, TruthSource, MAX_ORIENTATION_SIGMA_DEG,
    MAX_POSES,
};
pub use station::{station_frame, MAX_STATION};
pub use targets::TargetMeasurement;
pub use thermal::{ThermalModel, TEMPERATURE_STEP_C};
pub use tracker::Tracker;
pub use truth::{check_truth_matches, parameter_differences, GeometricErrors, TruthSpec};
pub use truth_file::{OutlierRecord, SetInfo, TruthFile};

#[cfg(test)]
mod real_cell_tests;
#[cfg(test)]
mod tests;
