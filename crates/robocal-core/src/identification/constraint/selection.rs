//! The model constraint data support (`--model auto` on constraint data): the same forward
//! search and one-standard-error rule as for tracker data ([`crate::identification::selection`]),
//! among the geometric model and the geometric model plus joint compliance, transmission
//! harmonics (1, 2), backlash (when the rows have approach directions), thermal expansion (when
//! they have temperatures) and their combinations; only the candidates' fit and
//! cross-validation are the constraint calibration's.
//!
//! A candidate is calibrated on every row ([`calibrate_constraints`]: structural analysis, the
//! directions the constraints do not see fixed, the gate) and cross-validated over
//! [`FOLDS`] folds by configuration ([`cross_validate_constraints`]): each fold's constraint rows
//! are left out, the robot and the features refitted on the others (from the full fit, with the
//! same identified parameters; known distances and tracker rows stay in every refit), and the
//! left-out rows' residuals measured under the refit (a fixed point's row: its distance from the
//! point the other rows put the feature at; a sphere's or a plane's: its distance from the
//! surface). The candidate's cross-validated error is the mean of those residual norms (mm), its
//! standard error that mean's. A candidate whose fit fails, does not converge or fails the gate
//! is not chosen; the robot as given failing is the calibration's error (the scale's refusal
//! among them).

use super::fit::{self, Layout};
use super::result::row_residuals;
use super::{calibrate_constraints, ConstraintCalibration, ConstraintOptions};
use crate::error::{Error, Result};
use crate::identification::cross_validation::{pose_folds, summarize, CrossValidation};
use crate::identification::selection::{search, Extends, FOLDS};
use crate::identification::{AutoFamilies, Candidate, ModelSelection};
use crate::model::Robot;
use crate::observations::constraint::ConstraintData;
use crate::observations::Observations;
use rayon::prelude::*;

/// Iteration limit of a fold's refit (it starts at the full fit's minimum, a few steps from its
/// own).
pub const FOLD_MAX_ITERATIONS: usize = 30;

/// Chooses the model `data` support among `nominal`'s candidates (see the module docs), with the
/// chosen candidate's calibration.
pub fn select(
    nominal: &Robot,
    data: &ConstraintData,
    opts: &ConstraintOptions,
    auto: AutoFamilies,
) -> Result<(ModelSelection, ConstraintCalibration)> {
    let reference_c = data.mean_temperature_c();
    let auto = AutoFamilies {
        backlash: auto.backlash && data.has_directions(),
        thermal: auto.thermal && reference_c.is_some(),
        ..auto
    };
    // Constraint candidates are fitted, none screened.
    let fit = |robot: &Robot,
               reference: bool,
               _from: Option<Extends<'_, ConstraintCalibration>>|
     -> (Candidate, Option<ConstraintCalibration>) {
        match calibrate_constraints(robot, data, opts) {
            Err(e) => {
                let mut c = Candidate::new(robot, reference);
                c.rejected = Some(format!("the fit failed: {e}"));
                (c, None)
            }
            Ok(cal) => assess(robot, reference, cal, data),
        }
    };
    let given = |robot: &Robot| -> Result<(Candidate, Option<ConstraintCalibration>)> {
        Ok(assess(
            robot,
            false,
            calibrate_constraints(robot, data, opts)?,
            data,
        ))
    };
    let (selection, chosen) = search(nominal, auto, reference_c, given, &fit)?;
    let cal = match chosen {
        Some(c) => c,
        // The robot as given, rejected (it did not converge or failed the gate): its own
        // calibration says why.
        None => calibrate_constraints(&selection.robot, data, opts)?,
    };
    Ok((selection, cal))
}

/// Calibrates the model `data` support ([`select`]), the choice recorded in the calibration's
/// `model_selection`.
pub fn calibrate_constraints_auto(
    nominal: &Robot,
    data: &ConstraintData,
    opts: &ConstraintOptions,
    auto: AutoFamilies,
) -> Result<ConstraintCalibration> {
    let (selection, mut cal) = select(nominal, data, opts, auto)?;
    cal.model_selection = Some(selection);
    Ok(cal)
}

/// A candidate's calibration judged: rejected when it did not converge or fails the gate, else
/// cross-validated. The calibration is returned when it stands.
fn assess(
    robot: &Robot,
    reference: bool,
    cal: ConstraintCalibration,
    data: &ConstraintData,
) -> (Candidate, Option<ConstraintCalibration>) {
    let mut c = Candidate::new(robot, reference);
    c.identified = cal.identified.len();
    if !cal.fit.converged {
        c.rejected = Some(format!(
            "the constraint fit did not converge in {} iterations",
            cal.fit.iterations
        ));
        return (c, None);
    }
    if !cal.implausible.is_empty() {
        c.rejected = Some(format!(
            "failed the plausibility gate: {}",
            cal.implausible.join("; ")
        ));
        return (c, None);
    }
    // The folds' refits start from the full fit, which already follows every row: they mean
    // something only where each refit (on four folds of five) stays overdetermined.
    let rows = fit::row_count(data, &cal.features);
    let unknowns = cal.identified.len()
        + cal.features.iter().map(|f| f.param_count()).sum::<usize>()
        + if cal.frame.is_some() { 6 } else { 0 };
    if 4 * unknowns > 3 * rows {
        c.rejected = Some(format!(
            "{unknowns} unknowns for {rows} residual rows: more than three quarters of them, so              a fit can follow the rows' noise and its cross-validation (refits on four folds of              five, from the full fit) says nothing; measure more configurations"
        ));
        return (c, None);
    }
    match cross_validate_constraints(&cal, data, FOLDS) {
        Ok(cv) => {
            c.cv_mean_mm = Some(cv.mean_mm);
            c.cv_std_error_mm = Some(cv.std_error_mm);
            (c, Some(cal))
        }
        Err(e) => {
            c.rejected = Some(format!("the cross-validation failed: {e}"));
            (c, None)
        }
    }
}

/// The fold (0..folds) of each constraint row of `data`: its configurations dealt out in a
/// seeded random order ([`pose_folds`]), so that rows of one configuration share a fold.
pub fn configuration_folds(data: &ConstraintData, folds: usize) -> Result<Vec<usize>> {
    let mut obs = Observations::new(data.dof);
    for r in &data.rows {
        obs.push(&r.q, nalgebra::Vector3::zeros(), r.line)?;
    }
    Ok(pose_folds(&obs, folds))
}

/// Cross-validates `cal` (calibrated on `data`) over `folds` folds by configuration (see the
/// module docs), the folds in parallel.
pub fn cross_validate_constraints(
    cal: &ConstraintCalibration,
    data: &ConstraintData,
    folds: usize,
) -> Result<CrossValidation> {
    let fold = configuration_folds(data, folds)?;
    let runs: Vec<Result<(Vec<f64>, bool)>> = (0..folds)
        .into_par_iter()
        .map(|f| refit_fold(cal, data, &fold, f))
        .collect();
    summarize(runs)
}

/// The left-out rows' residual norms of fold `f` under a refit on the other rows, and whether
/// the refit converged.
fn refit_fold(
    cal: &ConstraintCalibration,
    data: &ConstraintData,
    fold: &[usize],
    f: usize,
) -> Result<(Vec<f64>, bool)> {
    let split = |keep: bool| ConstraintData {
        rows: data
            .rows
            .iter()
            .zip(fold)
            .filter(|(_, k)| (**k == f) != keep)
            .map(|(r, _)| r.clone())
            .collect(),
        ..data.clone()
    };
    let (train, test) = (split(true), split(false));
    if test.rows.is_empty() {
        return Ok((Vec::new(), true));
    }
    for (k, feat) in data.features.iter().enumerate() {
        let n = train.rows_of(k).count();
        if n < feat.kind.min_rows() {
            return Err(Error::Numerical(format!(
                "leaving fold {} out leaves `{}` {n} row(s), fewer than it needs ({})",
                f + 1,
                feat.label(),
                feat.kind.min_rows()
            )));
        }
    }
    let mut robot = cal.robot.clone();
    let mut features = cal.features.clone();
    let mut frame = cal.frame;
    let mut layout = Layout::new(&robot, &cal.identified, &features);
    if frame.is_some() {
        layout = layout.with_frame();
    }
    let report = fit::solve(
        &mut robot,
        &layout,
        &train,
        &mut features,
        &mut frame,
        FOLD_MAX_ITERATIONS,
    )?;
    Ok((row_residuals(&robot, &test, &features), report.converged))
}
