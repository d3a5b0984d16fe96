//! The model the data support (`--model auto`): cross-validation over the calibration data
//! among the geometric model and the geometric model plus transmission harmonics (1, 2), joint
//! compliance under gravity, backlash (when the data have approach directions), thermal
//! expansion (when they have temperatures; referred to their mean temperature), and their
//! combinations.
//!
//! Each candidate is fitted once to all calibration points (the whole calibration, plausibility
//! gate included), then refitted on each of [`FOLDS`] folds with the fold's poses left out,
//! warm-started from the full fit with the same identified parameters, frame and final loss
//! (the folds in parallel). Rows of one pose (several reflectors, 6-DoF rows) stay in one fold.
//! The candidate's cross-validated error is the mean position error of every calibration point
//! under the fit that left it out; its standard error that mean's (per-point spread over the
//! square root of the count).
//!
//! The choice (the one-standard-error rule): among the candidates whose full fit converged and
//! passed the plausibility gate, the one with the fewest identified parameters whose error is
//! within one standard error of the lowest. The robot as given (the first candidate) is part of
//! every other: when its fit fails, does not converge or fails the gate, it is the choice, and
//! its calibration reports why. A family therefore stays only when it lowers the
//! cross-validated error by more than the best candidate's standard error, and the simpler model
//! wins a tie.

use crate::error::Result;
use crate::identification::cross_validation::{cross_validate, CrossValidation};
pub use crate::identification::model_choice::{
    AutoFamilies, Candidate, ModelChoice, ModelSelection,
};
use crate::identification::pipeline::{
    calibrate_model, calibrate_model_for, Calibration, CalibrationData, CalibrationSettings,
    Purpose,
};
use crate::model::family::{backlash, compliance, thermal, transmission};
use crate::model::Robot;
use crate::progress::{self, Observer};

/// Folds of the cross-validation.
pub const FOLDS: usize = 5;

/// Harmonics per joint the selection tries (besides none).
pub const HARMONICS: [usize; 2] = [1, 2];

/// Iteration limit of a candidate's full fit: a candidate the solver cannot fit in this many
/// iterations is not chosen (the chosen model's own calibration keeps the user's limit). A
/// well-posed fit converges in a handful (Gauss-Newton steps, see [`super::solver`]); one that
/// needs more has nearly undetermined parameters whose values the data do not support.
pub const CANDIDATE_MAX_ITERATIONS: usize = 25;

/// Runs a calibration of `nominal` (the library's entry point): the model the data support
/// when `settings.model` is [`ModelChoice::Auto`] (the selection step, [`select`], then the
/// chosen model's calibration), else the robot as given
/// ([`crate::identification::pipeline::calibrate_model`]). `observer` hears the stages.
pub fn calibrate(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    observer: &dyn Observer,
) -> Result<Calibration> {
    let ModelChoice::Auto(auto) = settings.model else {
        return calibrate_model(nominal, data, settings, observer);
    };
    observer.progress(progress::Stage::ModelSelection, 0, 1);
    let chosen = select(nominal, data, settings, auto)?;
    let given = CalibrationSettings {
        model: ModelChoice::Given,
        ..settings.clone()
    };
    let mut cal = calibrate_model(&chosen.robot, data, &given, observer)?;
    cal.settings.model = settings.model;
    cal.model_selection = Some(chosen);
    Ok(cal)
}

/// The non-geometric families of `robot`, as [`Candidate::families`] names them.
pub fn families(robot: &Robot) -> Vec<String> {
    let mut out = Vec::new();
    if !compliance::joints(robot).is_empty() {
        out.push("compliance".to_string());
    }
    let h = transmission::harmonics(robot);
    if h > 0 {
        out.push(format!("harmonics {h}"));
    }
    if !backlash::joints(robot).is_empty() {
        out.push("backlash".to_string());
    }
    if thermal::reference_c(robot).is_some() {
        out.push("thermal".to_string());
    }
    out
}

/// The temperature a thermal candidate refers its lengths to: the mean of the calibration
/// rows' temperatures, rounded to 0.1 deg C (`None` without temperatures).
pub fn reference_temperature_c(data: &CalibrationData) -> Option<f64> {
    let obs = data.calibration;
    let t: Vec<f64> = (0..obs.len())
        .map(|i| obs.conditions(i).temperature_c)
        .filter(|t| t.is_finite())
        .collect();
    (!t.is_empty()).then(|| (t.iter().sum::<f64>() / t.len() as f64 * 10.0).round() / 10.0)
}

/// The candidate robots: `nominal` as given, then with the families `auto` selects.
pub fn candidates(nominal: &Robot, auto: AutoFamilies) -> Result<Vec<Robot>> {
    let compliant = compliance::auto_joints(nominal);
    let with_compliance: &[bool] = if auto.compliance && !compliant.is_empty() {
        &[false, true]
    } else {
        &[false]
    };
    let harmonics: Vec<Option<usize>> = if auto.harmonics {
        std::iter::once(None)
            .chain(HARMONICS.iter().map(|&h| Some(h)))
            .collect()
    } else {
        vec![None]
    };
    let all: Vec<usize> = (0..nominal.dof()).collect();
    let with_backlash: &[bool] = if auto.backlash {
        &[false, true]
    } else {
        &[false]
    };
    let with_thermal: &[bool] = if auto.thermal {
        &[false, true]
    } else {
        &[false]
    };
    let mut out = Vec::new();
    for &c in with_compliance {
        for h in &harmonics {
            for &b in with_backlash {
                for &t in with_thermal {
                    let mut r = nominal.clone();
                    if c {
                        compliance::enable(&mut r, &compliant, None)?;
                    }
                    if let Some(h) = *h {
                        transmission::enable(&mut r, &all, h)?;
                    }
                    if b {
                        backlash::enable(&mut r, &all)?;
                    }
                    if t {
                        thermal::enable(&mut r, thermal::DEFAULT_REFERENCE_C)?;
                    }
                    out.push(r);
                }
            }
        }
    }
    // Simplest first: fewer parameters, then the order above.
    out.sort_by_key(|r| r.param_count());
    Ok(out)
}

/// Chooses the model the calibration data support among the [`candidates`] of `nominal` (see
/// the module docs). `settings.model` is ignored: each candidate is fitted as given.
pub fn select(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    auto: AutoFamilies,
) -> Result<ModelSelection> {
    // Backlash needs approach directions, thermal expansion temperatures.
    let reference_c = reference_temperature_c(&data);
    let auto = AutoFamilies {
        backlash: auto.backlash && data.calibration.has_directions(),
        thermal: auto.thermal && reference_c.is_some(),
        ..auto
    };
    let mut robots = candidates(nominal, auto)?;
    if let Some(t) = reference_c {
        for r in &mut robots {
            thermal::set_reference_c(r, t)?;
        }
    }
    let selectable = robots.len();
    // Families the user fixed are in every candidate: the geometric model beside them tells
    // whether they lower the error at all.
    if !families(nominal).is_empty() {
        robots.push(nominal.geometric());
    }
    let mut fit_settings = settings.clone();
    fit_settings.model = ModelChoice::Given;
    fit_settings.solver.max_iterations =
        settings.solver.max_iterations.min(CANDIDATE_MAX_ITERATIONS);
    let data = CalibrationData {
        validation: None,
        ..data
    };
    let mut candidates = Vec::with_capacity(robots.len());
    for (i, robot) in robots.iter().enumerate() {
        let mut cand = Candidate {
            families: families(robot),
            identified: 0,
            cv_mean_mm: None,
            cv_std_error_mm: None,
            rejected: None,
            chosen: false,
            reference: i >= selectable,
        };
        match calibrate_model_for(robot, data, &fit_settings, Purpose::Candidate, &()) {
            // The robot as given is part of every candidate: its error is the calibration's.
            Err(e) if i == 0 => return Err(e),
            Err(e) => cand.rejected = Some(format!("the fit failed: {e}")),
            Ok(cal) => {
                cand.identified = cal.identifiability.identified.len();
                let whole = cal.whole_solve();
                if !whole.termination.converged() {
                    cand.rejected = Some(format!(
                        "the solver {} after {} iterations",
                        whole.termination.describe(),
                        whole.iterations
                    ));
                } else if cal.plausibility.implausible() {
                    cand.rejected = Some(format!(
                        "failed the plausibility gate: {}",
                        cal.plausibility
                            .failures()
                            .map(|f| f.detail.clone())
                            .collect::<Vec<_>>()
                            .join("; ")
                    ));
                }
                if cand.rejected.is_some() {
                    candidates.push(cand);
                    continue;
                }
                match cross_validate(&cal, data.calibration, FOLDS) {
                    Ok(CrossValidation {
                        mean_mm,
                        std_error_mm,
                        ..
                    }) => {
                        cand.cv_mean_mm = Some(mean_mm);
                        cand.cv_std_error_mm = Some(std_error_mm);
                    }
                    Err(e) => {
                        cand.rejected = Some(format!("the cross-validation failed: {e}"));
                    }
                }
            }
        }
        candidates.push(cand);
    }
    let chosen = choose(&candidates);
    candidates[chosen].chosen = true;
    Ok(ModelSelection {
        folds: FOLDS,
        remark: overfitting(&candidates[chosen], candidates.iter().find(|c| c.reference)),
        candidates,
        robot: robots[chosen].clone(),
    })
}

/// The remark on families given explicitly (`chosen`, which carries them) that do not lower the
/// cross-validated error below the geometric `reference`'s by more than their standard error
/// (the one-standard-error rule would not keep them).
fn overfitting(chosen: &Candidate, reference: Option<&Candidate>) -> Option<String> {
    let r = reference?;
    let (Some(m), Some(se), Some(rm), Some(rse)) = (
        chosen.cv_mean_mm,
        chosen.cv_std_error_mm,
        r.cv_mean_mm,
        r.cv_std_error_mm,
    ) else {
        return None;
    };
    (rm <= m + se).then(|| {
        format!(
            "the families given ({}, {} parameters) do not lower the cross-validated error \
             below the geometric model's ({} parameters) by more than its standard error: \
             {m:.4} +- {se:.4} mm against {rm:.4} +- {rse:.4} mm. They likely fit the noise \
             (overfitting): the automatic model choice would not keep them",
            chosen.families.join(" + "),
            chosen.identified,
            r.identified
        )
    })
}

/// The one-standard-error rule over the selectable candidates (simplest first in `c`): the
/// simplest whose error is within one standard error of the lowest. The first candidate (the
/// robot as given) when none is selectable.
fn choose(c: &[Candidate]) -> usize {
    // The families refine the robot as given: on top of a fit that failed, did not converge or
    // is implausible they are not chosen, and its calibration says why.
    if c.first().map_or(true, |x| x.rejected.is_some()) {
        return 0;
    }
    let ok = |x: &Candidate| !x.reference && x.rejected.is_none() && x.cv_mean_mm.is_some();
    let Some(best) = c
        .iter()
        .filter(|x| ok(x))
        .min_by(|a, b| a.cv_mean_mm.unwrap().total_cmp(&b.cv_mean_mm.unwrap()))
    else {
        return 0;
    };
    let limit = best.cv_mean_mm.unwrap() + best.cv_std_error_mm.unwrap_or(0.0);
    c.iter()
        .enumerate()
        .filter(|(_, x)| ok(x) && x.cv_mean_mm.unwrap() <= limit)
        .min_by_key(|(i, x)| (x.identified, *i))
        .map_or(0, |(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cand(identified: usize, mean: f64, se: f64, rejected: bool) -> Candidate {
        Candidate {
            families: vec![],
            identified,
            cv_mean_mm: Some(mean),
            cv_std_error_mm: Some(se),
            rejected: rejected.then(|| "no".into()),
            chosen: false,
            reference: false,
        }
    }

    #[test]
    fn the_simplest_within_one_standard_error_of_the_best_is_chosen() {
        // A family that gains less than the standard error does not stay.
        let c = [cand(26, 0.050, 0.003, false), cand(36, 0.048, 0.003, false)];
        assert_eq!(choose(&c), 0);
        // One that gains more does.
        let c = [cand(26, 0.100, 0.002, false), cand(36, 0.088, 0.001, false)];
        assert_eq!(choose(&c), 1);
        // A rejected candidate is never chosen, however low its error.
        let c = [cand(26, 0.100, 0.002, false), cand(36, 0.010, 0.001, true)];
        assert_eq!(choose(&c), 0);
        // Nothing selectable: the robot as given.
        let c = [cand(26, 0.100, 0.002, true), cand(36, 0.010, 0.001, true)];
        assert_eq!(choose(&c), 0);
        // The robot as given rejected: no family on top of it.
        let c = [cand(26, 0.100, 0.002, true), cand(36, 0.010, 0.001, false)];
        assert_eq!(choose(&c), 0);
        // The reference (the geometric model beside explicit families) is never chosen.
        let mut r = cand(20, 0.010, 0.001, false);
        r.reference = true;
        let c = [cand(26, 0.100, 0.002, false), r];
        assert_eq!(choose(&c), 0);
    }

    #[test]
    fn explicit_families_that_do_not_beat_the_geometric_model_are_remarked() {
        let mut given = cand(43, 0.0318, 0.0010, false);
        given.families = vec!["compliance".into(), "harmonics 1".into()];
        let mut geo = cand(26, 0.0292, 0.0009, false);
        geo.reference = true;
        let r = overfitting(&given, Some(&geo)).expect("a remark");
        assert!(r.contains("compliance + harmonics 1, 43 parameters"), "{r}");
        assert!(
            r.contains("0.0318 +- 0.0010 mm against 0.0292 +- 0.0009 mm"),
            "{r}"
        );
        // Families that lower the error by more than the standard error: no remark.
        let given = cand(43, 0.0250, 0.0010, false);
        assert_eq!(overfitting(&given, Some(&geo)), None);
        // Within the standard error: a tie goes to the simpler model, so remarked.
        let given = cand(43, 0.0285, 0.0010, false);
        assert!(overfitting(&given, Some(&geo)).is_some());
        // No reference (no explicit family): nothing to remark.
        assert_eq!(overfitting(&given, None), None);
    }
}
