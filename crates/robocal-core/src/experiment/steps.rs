//! The steps of [`super::run_experiment`], each as the equivalent command does it on the files
//! the step before wrote (the texts are parsed back before use).

use super::{csv_bytes, files, parse_csv, real_cell, ExperimentConfig};
use crate::compensation::commanded::commanded_csv;
use crate::compensation::{Compensation, Compensator};
use crate::error::{Error, Result};
use crate::evaluation::{evaluate, Against, Evaluation};
use crate::identification::{
    calibrate, split_measurements, Calibration, CalibrationData, SplitData,
};
use crate::io::{CalibrationResult, MeasurementSet, Positions};
use crate::model::Robot;
use crate::progress::{As, Observer, Stage};
use crate::simulation::{
    simulate, simulate_joints, Simulation, SimulationConfig, TruthFile, TruthSpec, SET_CALIBRATION,
    SET_VALIDATION,
};
use std::path::Path;

/// Step 1: the measurement session, split into the files `simulate --validation-out` writes,
/// and the desired poses of the verification, each as text and read back.
pub(super) struct Measured {
    pub session: Simulation,
    pub cell_csv: Vec<u8>,
    pub val_csv: Vec<u8>,
    pub truth_json: String,
    pub data: MeasurementSet,
    pub validation: MeasurementSet,
    pub desired_csv: Vec<u8>,
    pub desired: MeasurementSet,
}

/// Step 1 (sections II.C, III.A): measures the session on the true robot in the cell.
pub(super) fn measure(
    config: &ExperimentConfig,
    geometric: &Robot,
    observer: &dyn Observer,
) -> Result<Measured> {
    let joints = config.nominal.joint_space();
    observer.progress(Stage::Measurement, 0, 1);
    let session = simulate(
        geometric,
        &TruthSpec::Robot(config.truth.clone()),
        &config.session,
        observer,
    )?;
    let main = session.select(SET_VALIDATION, false);
    let val = session.select(SET_VALIDATION, true);
    let set_col = session
        .measurements
        .extra_columns
        .iter()
        .position(|c| c == "set");
    let row_files: Vec<&Path> = session
        .measurements
        .rows
        .iter()
        .map(|r| match set_col {
            Some(k) if r.extra[k] == SET_VALIDATION => Path::new(files::VALIDATION),
            _ => Path::new(files::CELL),
        })
        .collect();
    let truth_file = session.truth_file(&row_files);
    let cell_csv = csv_bytes(&main, files::CELL)?;
    let val_csv = csv_bytes(&val, files::VALIDATION)?;
    let truth_json = truth_file.to_json()?;
    let data = parse_csv(&cell_csv, files::CELL, joints, Positions::Required)?;
    let validation = parse_csv(&val_csv, files::VALIDATION, joints, Positions::Required)?;
    let desired_csv = csv_bytes(&desired_poses(config, &session), files::DESIRED)?;
    let desired = parse_csv(&desired_csv, files::DESIRED, joints, Positions::Optional)?;
    observer.progress(Stage::Measurement, 1, 1);
    Ok(Measured {
        session,
        cell_csv,
        val_csv,
        truth_json,
        data,
        validation,
        desired_csv,
        desired,
    })
}

/// The desired poses of the verification: the calibration rows, joints only, with their `id`
/// and `set` (not the session's conditions); in a real cell, approached from below.
fn desired_poses(config: &ExperimentConfig, session: &Simulation) -> MeasurementSet {
    let mut desired = session.select(SET_CALIBRATION, true);
    for r in &mut desired.rows {
        r.p = None;
    }
    let keep: Vec<usize> = (0..desired.extra_columns.len())
        .filter(|&k| matches!(desired.extra_columns[k].as_str(), "id" | "set"))
        .collect();
    desired.extra_columns = keep
        .iter()
        .map(|&k| desired.extra_columns[k].clone())
        .collect();
    for r in &mut desired.rows {
        r.extra = keep.iter().map(|&k| r.extra[k].clone()).collect();
    }
    real_cell::approach_from_below(config, &mut desired);
    desired
}

/// Step 2: the calibration, and the result file it writes, read back.
pub(super) struct Calibrated {
    /// The nominal robot, referred to the data's conditions.
    pub nominal: Robot,
    pub split: SplitData,
    pub split_val: SplitData,
    pub calibration: Calibration,
    pub result_json: String,
    pub result: CalibrationResult,
    /// The calibrated model of the result (what `compensate` and `evaluate` load).
    pub calibrated: Robot,
}

/// Step 2 (sections II.C, III): the calibration from the files, as `robocal calibrate --data
/// cell.csv --validate validation.csv` reads them. An implausible fit is an error.
pub(super) fn calibrate_files(
    config: &ExperimentConfig,
    measured: &Measured,
    observer: &dyn Observer,
) -> Result<Calibrated> {
    let split = split_measurements(&measured.data)?;
    let split_val = split_measurements(&measured.validation)?;
    let nominal = real_cell::refer_to_data(&config.nominal, &split)?;
    let calibration = calibrate(
        &nominal,
        CalibrationData {
            calibration: &split.calibration,
            plane: Some(&split.plane),
            validation: Some(&split_val.validation),
        },
        &config.calibration,
        &As {
            inner: observer,
            stage: Stage::Calibration,
        },
    )?;
    if calibration.plausibility.implausible() {
        return Err(Error::Implausible(format!(
            "the simulated calibration failed the plausibility gate:\n{}",
            calibration.plausibility.summary()
        )));
    }
    let result_json = result_text(config, &nominal, &calibration, measured)?;
    let result = CalibrationResult::parse(&result_json, Path::new(files::RESULT))?;
    let calibrated = result.calibrated_robot(&nominal, Path::new(files::RESULT))?;
    observer.progress(Stage::Calibration, 1, 1);
    Ok(Calibrated {
        nominal,
        split,
        split_val,
        calibration,
        result_json,
        result,
        calibrated,
    })
}

/// The result file's text: the calibration's result with the settings and inputs `calibrate`
/// records, under the paths the configuration's settings give.
fn result_text(
    config: &ExperimentConfig,
    nominal: &Robot,
    calibration: &Calibration,
    measured: &Measured,
) -> Result<String> {
    let mut result = calibration.to_result();
    if let Some(s) = &mut result.settings {
        s.robot_arg = Some(nominal.name().to_owned());
        s.data = Some(files::CELL.to_owned());
        s.validate = Some(files::VALIDATION.to_owned());
        // Simulated poses are within the limits: the joint limits are enforced, as by default.
        s.nominal_limits = Some(false);
        s.merge(config.result_settings.clone())
            .map_err(|e| Error::invalid("result settings", e.to_string()))?;
    }
    let given = |f: Option<&String>, default: &str| f.cloned().unwrap_or_else(|| default.into());
    let settings = result.settings.as_ref();
    result.inputs = Some(
        [
            (
                "data",
                given(settings.and_then(|s| s.data.as_ref()), files::CELL),
                &measured.cell_csv,
            ),
            (
                "validation",
                given(
                    settings.and_then(|s| s.validate.as_ref()),
                    files::VALIDATION,
                ),
                &measured.val_csv,
            ),
        ]
        .into_iter()
        .map(|(role, f, bytes)| {
            (
                role.to_owned(),
                crate::io::inputs::InputFile::from_bytes(Path::new(&f), bytes),
            )
        })
        .collect(),
    );
    result.to_text()
}

/// Step 3 (section V.A, eq. 12-14): the commanded joints of the desired poses on the calibrated
/// model (in a real cell, at the arm's temperature), as `commanded.csv` and read back.
pub(super) fn compensate_desired(
    config: &ExperimentConfig,
    cal: &Calibrated,
    desired: &MeasurementSet,
    observer: &dyn Observer,
) -> Result<(Vec<Compensation>, Vec<u8>, MeasurementSet)> {
    let joints = config.nominal.joint_space();
    let at = cal
        .calibrated
        .at_conditions(&real_cell::compensation_conditions(config))?;
    let plain = cal.nominal.at_conditions(&Default::default())?;
    let comp = Compensator::new(&plain, &at, config.ik)?;
    let qs: Vec<Vec<f64>> = desired.rows.iter().map(|r| r.q.clone()).collect();
    let compensation = comp.compensate_all(&qs, observer)?;
    let extra_rows: Vec<&[String]> = desired.rows.iter().map(|r| r.extra.as_slice()).collect();
    let bytes = commanded_csv(
        joints,
        &compensation,
        Some(&qs),
        &desired.extra_columns,
        &extra_rows,
    )?;
    let commanded = parse_csv(&bytes, files::COMMANDED, joints, Positions::Optional)?;
    Ok((compensation, bytes, commanded))
}

/// Step 4: the verification session and its errors.
pub(super) struct Verified {
    pub verification: Simulation,
    pub verify_csv: Vec<u8>,
    pub verify: MeasurementSet,
    pub verification_errors: Evaluation,
}

/// Step 4 (section V.B, Table V): the commanded joints measured in the same cell (the truth and
/// tracker frame as `simulate --truth cell.truth.json` reads them), against the desired
/// positions. From another station (a real cell), the frame is registered again under the
/// calibrated model.
pub(super) fn verify(
    config: &ExperimentConfig,
    geometric: &Robot,
    truth_json: &str,
    commanded: &MeasurementSet,
    cal: &Calibrated,
    observer: &dyn Observer,
) -> Result<Verified> {
    let tf: TruthFile = serde_json::from_str(truth_json)
        .map_err(|e| Error::parse(Path::new(files::CELL_TRUTH), None, None, e.to_string()))?;
    let truth_again = tf.truth_robot(geometric, Path::new(files::CELL_TRUTH))?;
    let vconfig = SimulationConfig {
        tracker_frame: tf.tracker_frame,
        ..config.verification_session()
    };
    let verification = simulate_joints(
        geometric,
        &TruthSpec::Robot(truth_again),
        &vconfig,
        commanded,
        &As {
            inner: observer,
            stage: Stage::Verification,
        },
    )?;
    let joints = config.nominal.joint_space();
    let verify_csv = csv_bytes(&verification.measurements, files::VERIFY)?;
    let verify = parse_csv(&verify_csv, files::VERIFY, joints, Positions::Required)?;
    let frame = match config.real_cell {
        Some(r) if r.verification_station != 0 => crate::registration::refit_frame(
            &cal.calibrated,
            &crate::evaluation::observations_of(&verify)?,
        )?,
        _ => cal.result.tracker_frame(),
    };
    let verification_errors = evaluate(
        &cal.nominal,
        &cal.calibrated,
        &frame,
        &verify,
        Against::Desired,
    )?;
    Ok(Verified {
        verification,
        verify_csv,
        verify,
        verification_errors,
    })
}
