//! A constraint calibration as a normal result file ([`CalibrationResult`]) with its
//! `constraint` section ([`ConstraintSection`]), and the residuals of held-out constraint rows
//! under a calibrated model ([`held_out`]), which `evaluate` reports.
//!
//! The result's `tracker_frame` is the identity: the features, and any position the calibrated
//! model gives, are in the base frame of the calibrated model, whose pose is the nominal one;
//! with tracker rows (mixed data) it is the tracker frame they registered.
//! Its error tables are the constraint rows' residual norms (mm): `before`, the nominal model
//! with the features fitted to it alone; `after`, the joint fit.

use super::features::FeatureEstimate;
use super::fit::{self, Layout};
use super::{ConstraintCalibration, Scale};
use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::io::result::{BeforeAfter, CalibrationResult, ErrorTables, Status};
use crate::io::result_constraint::{
    ConstraintSection, DistanceEntry, FeatureEntry, ScaleEntry, BASE_POSE_NOTE,
};
use crate::io::result_robot::RobotInfo;
use crate::io::result_sections::{FrameVec, ObjectiveName, Solver};
use crate::model::Robot;
use crate::observations::constraint::{ConstraintData, CONSTRAINT_COLUMN};
use crate::stats::ErrorStats;

/// Each row's residual norm (mm) of `data` at `robot` and `features` (in `data`'s feature
/// order).
pub fn row_residuals(
    robot: &Robot,
    data: &ConstraintData,
    features: &[FeatureEstimate],
) -> Vec<f64> {
    let layout = Layout::new(robot, &[], features);
    let rows_only = ConstraintData {
        distances: Vec::new(),
        tracker: Vec::new(),
        ..data.clone()
    };
    let (e, _) = fit::evaluate(robot, &layout, &rows_only, features, None, false);
    let mut out = Vec::with_capacity(data.rows.len());
    let mut row = 0;
    for r in &data.rows {
        let k = features[r.feature].rows();
        out.push(e.rows(row, k).norm());
        row += k;
    }
    out
}

/// The features of `data` (and the tracker frame of its tracker rows, if any) fitted to `robot`
/// alone (the robot held), from start values that need no guess.
pub fn fit_features(
    robot: &Robot,
    data: &ConstraintData,
    max_iterations: usize,
) -> Result<Vec<FeatureEstimate>> {
    let mut robot = robot.clone();
    let mut features = super::start_values(&robot, data)?;
    let mut frame = super::start_frame(&robot, data)?;
    let mut layout = Layout::new(&robot, &[], &features);
    if frame.is_some() {
        layout = layout.with_frame();
    }
    fit::solve(
        &mut robot,
        &layout,
        data,
        &mut features,
        &mut frame,
        max_iterations,
    )?;
    Ok(features)
}

/// The features of `data` as a result recorded them, matched by kind and name; a feature the
/// result does not have is an error naming its first row.
pub fn recorded_features(
    data: &ConstraintData,
    recorded: &[FeatureEstimate],
) -> Result<Vec<FeatureEstimate>> {
    data.features
        .iter()
        .map(|f| {
            recorded
                .iter()
                .find(|r| r.kind == f.kind && r.name == f.name)
                .cloned()
                .ok_or_else(|| {
                    data.parse_error(
                        f.first_line,
                        CONSTRAINT_COLUMN,
                        format!(
                            "`{}` is not a feature of the calibration (it has {}): held-out \
                             rows must reach the calibration's own features",
                            f.label(),
                            recorded
                                .iter()
                                .map(|r| format!("`{}`", r.label()))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    )
                })
        })
        .collect()
}

/// Held-out constraint rows under a calibration: each row's residual (mm) under the nominal
/// model with the features fitted to it alone, and under the calibrated model with the
/// calibration's features.
pub fn held_out(
    nominal: &Robot,
    calibrated: &Robot,
    data: &ConstraintData,
    recorded: &[FeatureEstimate],
) -> Result<[Vec<f64>; 2]> {
    let cal_features = recorded_features(data, recorded)?;
    let nominal = nominal.geometric();
    let nom_features = fit_features(&nominal, data, 200)?;
    Ok([
        row_residuals(&nominal, data, &nom_features),
        row_residuals(calibrated, data, &cal_features),
    ])
}

impl ConstraintCalibration {
    /// The section recording the features, the scale and what the data cannot see.
    pub fn section(&self, data: &ConstraintData) -> ConstraintSection {
        let features = self
            .features
            .iter()
            .zip(&self.feature_rms_mm)
            .enumerate()
            .map(|(k, (f, rms))| FeatureEntry::of(f, data.rows_of(k).count(), *rms))
            .collect();
        let known_distances = data
            .distances
            .iter()
            .zip(&self.distance_residuals_mm)
            .map(|(d, r)| DistanceEntry {
                from: data.features[d.from].name.clone(),
                to: data.features[d.to].name.clone(),
                distance_mm: d.distance_mm,
                residual_mm: *r,
            })
            .collect();
        let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
        ConstraintSection {
            frame: if data.tracker.is_empty() {
                BASE_POSE_NOTE.to_owned()
            } else {
                format!(
                    "the base is registered to the tracker frame by {} tracker row(s) (the \
                     result's tracker_frame, as for tracker data); the features are in the base \
                     frame",
                    data.tracker.len()
                )
            },
            base_pose_known: !data.tracker.is_empty(),
            rows: data.rows.len(),
            tracker_rows: data.tracker.len(),
            tracker_residual_rms_mm: (!data.tracker.is_empty())
                .then(|| rms(&self.tracker_residuals_mm)),
            features,
            known_distances,
            scale: match &self.scale {
                Scale::Known { from } => ScaleEntry {
                    known: true,
                    from: Some(from.clone()),
                    held: None,
                },
                Scale::Assumed { held } => ScaleEntry {
                    known: false,
                    from: None,
                    held: Some(held.name()),
                },
            },
            unseen: self.unseen.clone(),
            residual_rms_mm: self.residual_rms_mm,
            residual_max_mm: self.residual_max_mm,
            condition_number: self.condition_number,
        }
    }

    /// The result file: `nominal`'s parameters with the calibrated values (held ones marked,
    /// with why; the families fitted, with their keys: payload, reference temperature), the identity tracker frame, the error tables of the constraint residuals, the
    /// solver's report, the status (`implausible` when the gate failed, `partial` when the fit
    /// did not converge), the `constraint` section and the model choice (`model_selection`).
    pub fn to_result(&self, nominal: &Robot, data: &ConstraintData) -> Result<CalibrationResult> {
        let mut parameters = CalibrationResult::parameter_entries(nominal, &self.robot);
        for f in &self.fixed {
            if let Some(e) = parameters.get_mut(&f.param.name()) {
                e.fixed = true;
                e.reason = Some(f.reason.clone());
            }
        }
        for (name, e) in parameters.iter_mut() {
            let identified = self.identified.iter().any(|p| &p.name() == name);
            if !identified && !e.fixed {
                e.fixed = true;
                e.reason = Some("not part of the model fitted to constraint data".into());
            }
        }
        let geometric = nominal.geometric();
        let before = row_residuals(
            &geometric,
            data,
            &fit_features(&geometric, data, 200).map_err(|e| {
                Error::Numerical(format!(
                    "the features under the nominal model (the error table's `before`): {e}"
                ))
            })?,
        );
        let after = row_residuals(&self.robot, data, &self.features);
        let errors = ErrorTables {
            calibration: BeforeAfter {
                before: ErrorStats::from_norms(&before),
                after: ErrorStats::from_norms(&after),
            },
            validation: None,
        };
        let (status, partial, implausible) = if !self.fit.converged {
            (
                Status::Partial,
                Some(format!(
                    "the constraint fit did not converge in {} iterations",
                    self.fit.iterations
                )),
                None,
            )
        } else if !self.implausible.is_empty() {
            (Status::Implausible, None, Some(self.implausible.join("; ")))
        } else {
            (Status::Calibrated, None, None)
        };
        let frame = self
            .frame
            .map_or_else(TrackerFrame::identity, TrackerFrame::new);
        let mut r = CalibrationResult::new(
            RobotInfo::of(nominal),
            parameters,
            FrameVec::from_tracker_frame(&frame),
            errors,
            status,
        );
        r.partial_reason = partial;
        r.implausible_reason = implausible;
        r.solver = Some(Solver {
            objective: ObjectiveName::LeastSquares,
            termination: if self.fit.converged {
                "converged (the sum of squared residuals stopped decreasing)".into()
            } else {
                format!("stopped at the iteration limit ({})", self.fit.iterations)
            },
            converged: self.fit.converged,
            iterations: self.fit.iterations,
            final_objective: self.fit.cost,
            stages: Vec::new(),
        });
        self.section(data).store(&mut r);
        // The families' own keys, as a tracker result records them.
        crate::io::result_payload::record(&mut r, &self.robot);
        crate::io::result_thermal::record(&mut r, &self.robot);
        r.model_selection = self
            .model_selection
            .as_ref()
            .map(crate::io::result_selection::ModelSelectionSection::of);
        Ok(r)
    }
}
