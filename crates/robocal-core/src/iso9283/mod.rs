//! Acceptance by ISO 9283 (manipulating industrial robots, performance criteria and test
//! methods): pose accuracy AP and repeatability RP at the five poses of a test cube over N
//! cycles, distance accuracy and repeatability, drift.
//!
//! - [`make_plan`]: the largest axis-parallel cube the robot reaches at every test pose with a
//!   tool orientation ([`cube`]), its measuring plane, P1..P5 and the joints to command (nominal,
//!   or compensated on a calibrated model, so that the same test runs before and after
//!   calibration); [`plan_csv`] writes it (`cycle,pose,q1..qn,x_c,y_c,z_c,a_c,b_c,c_c`).
//! - [`read_plan`] and [`read_test_data`] read the plan back and match the measured rows to it.
//! - [`evaluate`]: AP, RP, orientation AP/RP, AD/RD, drift ([`metrics`] states the formulas),
//!   the tracker's uncertainty beside RP ([`TrackerMpe`]) and pass/fail against a [`Spec`].
//! - [`plan_program`]: the plan as a KRL, RAPID or URScript program of joint motions.
//! - [`simulate_test`]: a plan run in the virtual cell (with its repeatability) and evaluated.

pub mod cube;
mod files;
pub mod metrics;
mod plan;
mod program;
mod simulated;
mod spec;

pub use cube::{Cube, Miss, Reach, CORNER_FRACTION};
pub use files::{
    plan_csv, read_plan, read_test_data, PlanFile, PlanFileRow, JOINT_MATCH_DEG, PLAN_TOLERANCE_MM,
    POSE_COLUMNS,
};
pub use metrics::{
    evaluate, evaluate_distance, evaluate_pose, DistanceResult, Drift, Evaluation,
    OrientationResult, PoseResult, PoseSamples, Sample,
};
pub use plan::{
    make_plan, reference_configuration, Plan, PlanRow, PlanSettings, CYCLE_ORDER, DEFAULT_CYCLES,
};
pub use program::{plan_program, PlanProgram, DEFAULT_DWELL_S};
pub use simulated::{plan_rows, simulate_test};
pub use spec::{Spec, TrackerMpe};

#[cfg(test)]
mod plan_tests;
#[cfg(test)]
mod program_tests;
#[cfg(test)]
mod sim_tests;
#[cfg(test)]
mod tests;
