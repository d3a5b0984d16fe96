//! Files made through the library for the compensation and evaluation tests: result files, joint
//! files and a virtual measurement (what `robocal simulate` and a real tracker provide).

use super::{KUKA, TRUTH};
use rand::SeedableRng;
use robocal_core::frame::TrackerFrame;
use robocal_core::io::result::{BeforeAfter, ErrorTables, FrameVec, RobotInfo};
use robocal_core::io::{write_measurements, CalibrationResult, Measurement, MeasurementSet};
use robocal_core::simulation::{random_poses, PoseSampler, Tracker};
use robocal_core::{pose, preset, ErrorStats, Robot};
use std::path::{Path, PathBuf};

/// The tracker of the virtual cell: about 4 m from the base, turned about its vertical axis.
pub fn tracker(noise: bool) -> Tracker {
    let (s0, s1) = if noise { (0.010, 0.005) } else { (0.0, 0.0) };
    let frame = TrackerFrame::new(pose(&[3600.0, 1800.0, -250.0, -2.2, 0.003, 0.002]));
    Tracker::new(frame, s0, s1).unwrap()
}

/// A result file as `calibrate` writes it: `calibrated` as the calibrated model of `nominal`,
/// with the given tracker frame.
pub fn result_for(nominal: &Robot, calibrated: &Robot, frame: &TrackerFrame) -> CalibrationResult {
    let s = ErrorStats::from_norms(&[1.0, 2.0]);
    // Every result robocal writes has a status (readers refuse one without).
    CalibrationResult::new(
        RobotInfo::of(nominal),
        CalibrationResult::parameter_entries(nominal, calibrated),
        FrameVec::from_tracker_frame(frame),
        ErrorTables {
            calibration: BeforeAfter {
                before: s,
                after: s,
            },
            validation: None,
        },
        robocal_core::io::result::Status::Calibrated,
    )
}

/// Writes the standard result: nominal Table I, "calibrated" = Table III (the simulation's truth).
pub fn write_result(dir: &Path, frame: &TrackerFrame) -> PathBuf {
    let nom = preset(KUKA).unwrap();
    let cal = preset(TRUTH).unwrap();
    let path = dir.join("result.json");
    result_for(&nom, &cal, frame).write(&path).unwrap();
    path
}

/// `n` random poses (rad) of the nominal robot.
pub fn poses(n: usize, seed: u64) -> Vec<Vec<f64>> {
    let nom = preset(KUKA).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    random_poses(&nom, n, &PoseSampler::default(), &mut rng).unwrap()
}

/// Writes a joint file `id,q1..q6` (degrees).
pub fn write_joints(path: &Path, qs: &[Vec<f64>]) {
    let mut s = String::from("id,q1,q2,q3,q4,q5,q6\n");
    for (k, q) in qs.iter().enumerate() {
        let v: Vec<String> = q
            .iter()
            .map(|x| format!("{:.10}", x.to_degrees()))
            .collect();
        s.push_str(&format!("p{k},{}\n", v.join(",")));
    }
    std::fs::write(path, s).unwrap();
}

/// Measures the truth (Table III) at the joints of `set` with `tracker`, keeping every other
/// column: what `robocal simulate --joints` does.
pub fn measure_set(set: &MeasurementSet, tracker: &Tracker, seed: u64) -> MeasurementSet {
    let truth = preset(TRUTH).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut out = set.clone();
    out.rows = set
        .rows
        .iter()
        .map(|r| Measurement {
            p: Some(tracker.measure(&truth.tool_position(&r.q), &mut rng)),
            ..r.clone()
        })
        .collect();
    out
}

/// Reads a joint file, measures it (see [`measure_set`]) and writes the measurement file.
pub fn simulate(joints: &Path, out: &Path, tracker: &Tracker, seed: u64) {
    let kuka = robocal_core::preset(KUKA).unwrap();
    let set = robocal_core::io::read_measurements(
        joints,
        kuka.joint_space(),
        robocal_core::io::Positions::Optional,
    )
    .unwrap();
    write_measurements(out, &measure_set(&set, tracker, seed)).unwrap();
}
