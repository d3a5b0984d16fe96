//! The paper's whole experiment in simulation, in one call: what `robocal demo` runs.
//!
//! [`run_experiment`] chains the steps of Samak et al. (2019) on a virtual cell:
//!
//! 1. **Measurement** (sections II.C, III.A): the paper's 3 plane points, 75 calibration and
//!    73 validation points of the true robot, read by a noisy laser tracker
//!    ([`crate::simulation::simulate`]), with gravity deflection of the arm under its payload;
//! 2. **Calibration** (sections II.C, III): registration of the measurement frame from the plane
//!    points and the fit (eq. 8-11), identifiability, identification of the parameters
//!    minimizing the total displacement error (eq. 4), errors before (Table II) and after
//!    (Table IV) on both sets ([`crate::identification::calibrate`]);
//! 3. **Compensation** (section V.A, eq. 12-14): commanded joints for the 75 calibration poses on
//!    the *calibrated* model ([`crate::Compensator`]);
//! 4. **Verification** (section V.B, Table V): the commanded joints measured again in the same
//!    cell (same true robot, tracker and deflection; fresh tracker noise) and compared with the
//!    desired positions ([`crate::evaluation::evaluate`]);
//! 5. **Truth comparison** (only a simulation can do it): the true robot expressed in the
//!    parameters the calibration identified, beside the calibrated values ([`TruthComparison`]).
//!
//! Every step consumes the data as the files of the equivalent commands would hold them (the
//! texts of [`Experiment::files`] are parsed back before use), so that running `robocal simulate`,
//! `calibrate`, `compensate`, `simulate --joints` and `evaluate` by hand on those files gives the
//! same numbers. The library writes nothing; the caller writes [`Experiment::files`].

mod real_cell;
mod steps;
mod truth_compare;

#[cfg(test)]
mod elasto_tests;
#[cfg(test)]
mod tests;

pub use real_cell::{RealCell, VERIFICATION_START_S};
pub use truth_compare::{compare_with_truth, TruthComparison};

use crate::compensation::{Compensation, DampedLeastSquares};
use crate::error::{Error, Result};
use crate::evaluation::Evaluation;
use crate::identification::{Calibration, CalibrationSettings};
use crate::io::measurements::{measurements_csv, parse_measurements};
use crate::io::{CalibrationResult, MeasurementSet, Positions};
use crate::model::presets::preset;
use crate::model::{JointSpace, Robot};
use crate::progress::{Observer, Stage};
use crate::simulation::{GravityModel, Simulation, SimulationConfig};
use crate::stats::ErrorStats;
use std::path::Path;

/// The nominal robot of the paper's experiment (Table I).
pub const PAPER_NOMINAL: &str = "kuka-kr480-r3330";
/// The true robot of the simulated experiment (the paper's calibrated Table III).
pub const PAPER_TRUTH: &str = "kuka-kr480-r3330-table3";

/// Default joint compliances of the simulated KR 480 (rad per N·m): 1e-8 for the main axes
/// (stiffness 1e8 N·m/rad) and 5e-8 for the wrist (2e7 N·m/rad). These are *effective* values:
/// the deflection a geometric model cannot follow. With [`PAPER_LINK_MASSES_KG`] and
/// [`PAPER_PAYLOAD_KG`] the tool sags by about 0.4 mm on average (1 mm at most) over the
/// workspace, and a geometric calibration leaves about 0.15-0.25 mm, the size of the residual
/// the paper reports for its real robot (Table IV: 0.174 / 0.242 mm). Published full-joint
/// stiffnesses of heavy arms are lower (10^6-10^7 N·m/rad); with those a 300 kg payload sags the
/// tool by several millimetres and a purely geometric model no longer reaches the paper's figures.
pub const PAPER_COMPLIANCE: [f64; 6] = [1e-8, 1e-8, 1e-8, 5e-8, 5e-8, 5e-8];
/// Default link masses of the simulated KR 480 (kg): rotating column, link arm, arm, and the
/// three wrist bodies; about 2 t moving, as for a robot of this class (about 2.4 t in all).
pub const PAPER_LINK_MASSES_KG: [f64; 6] = [900.0, 500.0, 400.0, 150.0, 60.0, 20.0];
/// Default payload at the tool point (kg): a heavy tool, about 60% of the KR 480's rated 480 kg.
pub const PAPER_PAYLOAD_KG: f64 = 300.0;

/// File names of [`Experiment::files`] (what the equivalent commands write).
pub mod files {
    /// Plane and calibration measurements (`robocal simulate --out`).
    pub const CELL: &str = "cell.csv";
    /// Validation measurements (`robocal simulate --validation-out`).
    pub const VALIDATION: &str = "validation.csv";
    /// The truth of the cell (`robocal simulate`, beside `cell.csv`).
    pub const CELL_TRUTH: &str = "cell.truth.json";
    /// The calibration poses as a joint file: the desired poses of the verification (eq. 12).
    pub const DESIRED: &str = "desired.csv";
    /// The calibration result (`robocal calibrate --out`).
    pub const RESULT: &str = "result.json";
    /// Commanded joints (`robocal compensate --out`).
    pub const COMMANDED: &str = "commanded.csv";
    /// Measurements of the commanded joints (`robocal simulate --joints --out`).
    pub const VERIFY: &str = "verify.csv";
}

/// The default gravity model of the simulated experiment (see [`PAPER_COMPLIANCE`]).
pub fn paper_gravity() -> GravityModel {
    GravityModel::new(
        PAPER_COMPLIANCE.to_vec(),
        PAPER_LINK_MASSES_KG.to_vec(),
        PAPER_PAYLOAD_KG,
    )
}

/// Everything that defines an experiment.
#[derive(Debug, Clone)]
pub struct ExperimentConfig {
    /// The robot the controller believes in (the paper's Table I).
    pub nominal: Robot,
    /// The robot that really moves (the paper's Table III).
    pub truth: Robot,
    /// The first measurement session: seed, counts (75 calibration, 73 validation), plane
    /// points, tracker pose and noise, gravity.
    pub session: SimulationConfig,
    /// Seed of the verification measurement: another session in the same cell, with its own
    /// tracker noise (default: the session's seed + 1).
    pub verification_seed: u64,
    /// Calibration settings (default: the paper's sum of norms, eq. 4).
    pub calibration: CalibrationSettings,
    /// The inverse kinematics of the compensation.
    pub ik: DampedLeastSquares,
    /// Keys merged into the result's `settings` (the caller's file names, as `robocal
    /// calibrate` records them). By default the result records `robot_arg` = the nominal
    /// robot's name (a preset name in the paper's experiment; give the file for a robot file),
    /// `data` = `cell.csv`, `validate` = `validation.csv` and `nominal_limits` = false.
    pub result_settings: serde_json::Map<String, serde_json::Value>,
    /// The real cell's verification (another station, later and warmer), when the session
    /// simulates one ([`ExperimentConfig::honest`]); `None`: the verification is measured in
    /// the same cell as the session.
    pub real_cell: Option<RealCell>,
}

impl ExperimentConfig {
    /// The paper's experiment: nominal Table I, truth Table III with gravity deflection
    /// ([`paper_gravity`]) and tracker noise (0.010 mm + 0.005 mm/m per axis), 3 plane,
    /// 75 calibration and 73 validation points, the sum-of-norms objective.
    pub fn paper(seed: u64) -> Result<ExperimentConfig> {
        let session = SimulationConfig {
            seed,
            poses: 75,
            validation_poses: 73,
            plane_points: true,
            gravity: Some(paper_gravity()),
            ..SimulationConfig::default()
        };
        Ok(ExperimentConfig {
            nominal: preset(PAPER_NOMINAL)?,
            truth: preset(PAPER_TRUTH)?,
            session,
            verification_seed: seed.wrapping_add(1),
            // The paper's objective, explicitly: the library's default is the adaptive one.
            calibration: CalibrationSettings {
                objective: crate::identification::Objective::SumOfNorms,
                ..CalibrationSettings::default()
            },
            ik: DampedLeastSquares::default(),
            result_settings: serde_json::Map::new(),
            real_cell: None,
        })
    }

    /// The settings of the verification measurement: the session's cell (tracker, noise,
    /// gravity) with the verification seed, measuring given joints (as `robocal simulate
    /// --joints` configures it).
    pub fn verification_session(&self) -> SimulationConfig {
        real_cell::verification_session(
            self,
            SimulationConfig {
                seed: self.verification_seed,
                poses: 0,
                validation_poses: 0,
                plane_points: false,
                plane_z_mm: None,
                ..self.session.clone()
            },
        )
    }
}

/// The phases of an experiment, in order: the stages [`run_experiment`] reports (each phase's
/// inner steps are reported as the phase).
pub const PHASES: [Stage; 5] = [
    Stage::Measurement,
    Stage::Calibration,
    Stage::Compensation,
    Stage::Verification,
    Stage::TruthComparison,
];

/// What an experiment produced.
#[derive(Debug, Clone)]
pub struct Experiment {
    /// The settings.
    pub config: ExperimentConfig,
    /// The first measurement session (plane, calibration and validation points).
    pub session: Simulation,
    /// `cell.csv` as read back: the plane and calibration points.
    pub data: MeasurementSet,
    /// `validation.csv` as read back.
    pub validation: MeasurementSet,
    /// `desired.csv` as read back: the calibration poses (eq. 12).
    pub desired: MeasurementSet,
    /// The calibration (Tables II, III and IV).
    pub calibration: Calibration,
    /// The result file's content, as read back from its text.
    pub result: CalibrationResult,
    /// The calibrated model of the result (what `compensate` and `evaluate` load).
    pub calibrated: Robot,
    /// One compensation per desired pose (eq. 12-14).
    pub compensation: Vec<Compensation>,
    /// `commanded.csv` as read back.
    pub commanded: MeasurementSet,
    /// The verification measurement session.
    pub verification: Simulation,
    /// `verify.csv` as read back: the commanded joints and their measured positions, with the
    /// desired positions.
    pub verify: MeasurementSet,
    /// Verification errors against the desired positions (Table V), and of the calibrated model
    /// at the commanded joints.
    pub verification_errors: Evaluation,
    /// The truth in the identified parameters.
    pub truth_comparison: TruthComparison,
    files: Vec<(&'static str, Vec<u8>)>,
}

impl Experiment {
    /// The files of the experiment, as the equivalent commands write them (names in [`files`]):
    /// `cell.csv`, `validation.csv`, `cell.truth.json`, `desired.csv`, `result.json`,
    /// `commanded.csv`, `verify.csv`.
    pub fn files(&self) -> &[(&'static str, Vec<u8>)] {
        &self.files
    }

    /// Table II, calibration points: the nominal model with the fitted frame.
    pub fn before(&self) -> ErrorStats {
        self.result.errors.calibration.before
    }

    /// Table IV, calibration points: the prediction the verification is compared with.
    pub fn predicted(&self) -> ErrorStats {
        self.result.errors.calibration.after
    }

    /// Table V: the measured errors of the compensated poses against their desired positions.
    pub fn verified(&self) -> ErrorStats {
        self.verification_errors.series[0].stats
    }
}

fn parse_csv(
    bytes: &[u8],
    name: &str,
    joints: &JointSpace,
    positions: Positions,
) -> Result<MeasurementSet> {
    parse_measurements(bytes, Path::new(name), joints, positions)
}

fn csv_bytes(set: &MeasurementSet, name: &str) -> Result<Vec<u8>> {
    measurements_csv(set).map_err(|e| Error::Io {
        path: name.into(),
        source: e,
    })
}

/// Runs the experiment (see the module docs). `observer` hears the phases ([`PHASES`]) as the
/// work advances (`done` and `total` count steps within the phase).
pub fn run_experiment(config: ExperimentConfig, observer: &dyn Observer) -> Result<Experiment> {
    // The cell's robots are geometric (their deflection is the simulator's gravity model); the
    // nominal model may add the families that deflect the joints, for the calibration.
    let geometric = config.nominal.geometric();
    let measured = steps::measure(&config, &geometric, observer)?;
    let calibrated = steps::calibrate_files(&config, &measured, observer)?;
    let (compensation, commanded_bytes, commanded) =
        steps::compensate_desired(&config, &calibrated, &measured.desired, observer)?;
    let verified = steps::verify(
        &config,
        &geometric,
        &measured.truth_json,
        &commanded,
        &calibrated,
        observer,
    )?;

    // 5. The truth in the identified parameters.
    observer.progress(Stage::TruthComparison, 0, 1);
    let truth_comparison = compare_with_truth(
        &calibrated.calibration,
        &config.truth,
        &config.session.tracker_frame.to_tracker_frame(),
        &calibrated.split.calibration,
        &calibrated.split_val.validation,
    )?;
    observer.progress(Stage::TruthComparison, 1, 1);

    let files = vec![
        (files::CELL, measured.cell_csv),
        (files::VALIDATION, measured.val_csv),
        (files::CELL_TRUTH, measured.truth_json.into_bytes()),
        (files::DESIRED, measured.desired_csv),
        (files::RESULT, calibrated.result_json.into_bytes()),
        (files::COMMANDED, commanded_bytes),
        (files::VERIFY, verified.verify_csv),
    ];
    Ok(Experiment {
        config,
        session: measured.session,
        data: measured.data,
        validation: measured.validation,
        desired: measured.desired,
        calibration: calibrated.calibration,
        result: calibrated.result,
        calibrated: calibrated.calibrated,
        compensation,
        commanded,
        verification: verified.verification,
        verify: verified.verify,
        verification_errors: verified.verification_errors,
        truth_comparison,
        files,
    })
}
