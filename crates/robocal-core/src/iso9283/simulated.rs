//! An ISO 9283 test run in the virtual cell: a plan's rows measured as `simulate --joints` does
//! (with the cell's repeatability), mapped to the base frame by a tracker frame and evaluated.

use super::metrics::{evaluate, Evaluation, PoseSamples, Sample};
use super::plan::Plan;
use super::spec::TrackerMpe;
use crate::error::Result;
use crate::frame::TrackerFrame;
use crate::io::measurements::{Measurement, MeasurementSet};
use crate::model::Robot;
use crate::progress::Observer;
use crate::simulation::{simulate_joints, SimulationConfig, TruthSpec};
use std::path::PathBuf;

/// The plan's rows as a joint file (`cycle`, `pose` extra columns), in the order the robot runs
/// them.
pub fn plan_rows(robot: &Robot, plan: &Plan) -> MeasurementSet {
    let rows = plan
        .rows()
        .enumerate()
        .map(|(i, r)| Measurement {
            line: i + 2,
            q: plan.joints[r.pose - 1].clone(),
            p: None,
            extra: vec![r.cycle.to_string(), r.pose.to_string()],
        })
        .collect();
    MeasurementSet {
        path: PathBuf::from("<iso9283 plan>"),
        joints: robot.joint_space().clone(),
        extra_columns: vec!["cycle".into(), "pose".into()],
        rows,
        warnings: Vec::new(),
    }
}

/// Runs `plan` on the cell of `nominal`, `truth` and `config` and evaluates it with the tracker
/// frame `frame` (the calibration's fitted frame, as `iso9283 evaluate --params` does) and the
/// tracker MPE `tracker`.
pub fn simulate_test(
    nominal: &Robot,
    truth: &TruthSpec,
    config: &SimulationConfig,
    plan: &Plan,
    frame: &TrackerFrame,
    tracker: &TrackerMpe,
    observer: &dyn Observer,
) -> Result<Evaluation> {
    let set = plan_rows(nominal, plan);
    let sim = simulate_joints(nominal, truth, config, &set, observer)?;
    let mut samples = vec![Vec::new(); 5];
    for (r, m) in plan.rows().zip(&sim.measurements.rows) {
        if let Some(p) = m.p {
            samples[r.pose - 1].push(Sample {
                cycle: r.cycle,
                position: frame.to_base(&p),
                rotation: None,
                time_s: None,
            });
        }
    }
    let poses: Vec<PoseSamples> = samples
        .into_iter()
        .enumerate()
        .map(|(k, s)| PoseSamples {
            pose: k + 1,
            commanded: plan.poses[k],
            samples: s,
        })
        .collect();
    evaluate(&poses, tracker, &frame.origin(), None)
}
