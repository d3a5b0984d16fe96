//! The model the data support (`--model auto`): cross-validation over the calibration data
//! among the geometric model and the geometric model plus transmission harmonics (1, 2), joint
//! compliance under gravity, backlash (when the data have approach directions), thermal
//! expansion (when they have temperatures; referred to their mean temperature), and their
//! combinations.
//!
//! The candidates are found by a forward search: from the robot as given, each round judges every
//! model with one family more than the current one (or the next harmonic order), and moves to
//! the best of them when it lowers the current model's cross-validated error by more than its
//! own standard error; the search stops where none does. Combinations are so tried only on top
//! of families that earned their place, and a geometric robot costs the robot as given and one
//! round of single families.
//!
//! Each candidate is first screened ([`crate::identification::screen`]): its cross-validated
//! error estimated by one Newton step from the fit of the model it extends, at the cost of one
//! pass over the data. One whose estimate stays
//! [`SCREEN_MARGIN`](crate::identification::screen::SCREEN_MARGIN) of the current model's standard
//! errors away from lowering its error is not fitted: it keeps its estimate, marked
//! [`Candidate::screened`], and takes part in the search and the choice with it as its fit would
//! with its error. It is never the choice: one whose fit could turn the search (the round's
//! lowest error while a candidate would move the search) or the choice is fitted after all.
//! Every other candidate is fitted once to all calibration points (the whole calibration,
//! plausibility gate included) and cross-validated over [`FOLDS`] folds by pose (see
//! [`super::cross_validation`]: one Newton step from the full fit on the other folds' normal
//! equations). Rows of one pose (several reflectors, 6-DoF rows) stay in one fold. The
//! candidate's cross-validated error is the mean position error of every calibration point
//! under the fit that left it out; its standard error that mean's (per-point spread over the
//! square root of the count).
//!
//! The choice (the one-standard-error rule): among the candidates whose full fit converged and
//! passed the plausibility gate (and the screened ones, by their estimates), the one with the
//! fewest identified parameters whose error is within one standard error of the lowest. The robot as given (the first
//! candidate) is part of every other: when its fit fails, does not converge or fails the gate,
//! it is the choice, and its calibration reports why. A family therefore stays only when it
//! lowers the cross-validated error by more than the best candidate's standard error, and the
//! simpler model wins a tie. The chosen candidate's fit is the result's (completed with the
//! prediction's workspace map and the validation points), not fitted again.

use crate::error::Result;
use crate::identification::cross_validation::{cross_validate, CrossValidation};
pub use crate::identification::model_choice::{
    AutoFamilies, Candidate, ModelChoice, ModelSelection,
};
use crate::identification::pipeline::{
    begin_for, calibrate_model, calibrate_model_for, calibrate_model_from, complete, Calibration,
    CalibrationData, CalibrationSettings, Purpose, Shared,
};
use crate::identification::screen::screen_candidate;
use crate::model::family::{backlash, compliance, thermal, transmission};
use crate::model::Robot;
use crate::progress::{self, Observer};
use rayon::prelude::*;

pub use crate::identification::folds::FOLDS;

#[path = "selection_families.rs"]
mod families_set;
use families_set::Families;

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
    let (chosen, fit) = select_fitted(nominal, data, settings, auto)?;
    let given = CalibrationSettings {
        model: ModelChoice::Given,
        ..settings.clone()
    };
    // The chosen candidate's fit is the result's: it only lacks what a candidate skips.
    let mut cal = match fit {
        Some(fit) => complete(fit, data, &given, observer)?,
        None => calibrate_model(&chosen.robot, data, &given, observer)?,
    };
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

/// Chooses the model the calibration data support among the candidates of `nominal` (see
/// the module docs). `settings.model` is ignored: each candidate is judged as given.
pub fn select(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    auto: AutoFamilies,
) -> Result<ModelSelection> {
    Ok(select_fitted(nominal, data, settings, auto)?.0)
}

/// [`select`], with the chosen candidate's fit when it converged within the candidates'
/// iteration limit (a fit that did not is redone with the settings' limit).
fn select_fitted(
    nominal: &Robot,
    data: CalibrationData,
    settings: &CalibrationSettings,
    auto: AutoFamilies,
) -> Result<(ModelSelection, Option<Calibration>)> {
    // Backlash needs approach directions, thermal expansion temperatures.
    let reference_c = reference_temperature_c(&data);
    let auto = AutoFamilies {
        backlash: auto.backlash && data.calibration.has_directions(),
        thermal: auto.thermal && reference_c.is_some(),
        ..auto
    };
    let mut fit_settings = settings.clone();
    fit_settings.model = ModelChoice::Given;
    fit_settings.solver.max_iterations =
        settings.solver.max_iterations.min(CANDIDATE_MAX_ITERATIONS);
    let data = CalibrationData {
        validation: None,
        ..data
    };
    let given = Families::default().robot(nominal, reference_c)?;
    // The candidates are the robot as given with families at zero: the same tool points, so
    // the same frame and tools, registered once (checked point by point, else their own), and
    // the same start passes, those of the widest candidate.
    let widest = Families::widest(auto, !compliance::auto_joints(nominal).is_empty())
        .robot(nominal, reference_c)?;
    let shared = Shared::new(&given, &widest, data, &fit_settings)?;
    let fit = |robot: &Robot, reference: bool, from: Option<Extends<'_, Calibration>>| {
        let shared = shared
            .same_tool_points(robot, data.calibration)
            .then_some(&shared);
        judge(robot, reference, from, data, &fit_settings, shared)
    };
    let given_fit = |robot: &Robot| -> Result<(Candidate, Option<Calibration>)> {
        let shared = shared
            .same_tool_points(robot, data.calibration)
            .then_some(&shared);
        let cal = calibrate_model_for(robot, data, &fit_settings, Purpose::Candidate, &(), shared)?;
        Ok(assess(robot, false, cal, data))
    };
    search(nominal, auto, reference_c, given_fit, &fit)
}

/// One candidate of [`select_fitted`] judged: screened first when the model it extends stands
/// (`from`), then, unless spared, fitted (from the screen's start and identifiability steps; a
/// step that failed there is the fit's to report) and assessed. `true`: the reference candidate.
fn judge(
    robot: &Robot,
    reference: bool,
    from: Option<Extends<'_, Calibration>>,
    data: CalibrationData,
    settings: &CalibrationSettings,
    shared: Option<&Shared>,
) -> (Candidate, Option<Calibration>) {
    let mut begun = None;
    if let Some(from) = from {
        if let Ok(b) = begin_for(robot, data, settings, shared) {
            let (fit, cand) = (from.fit, from.candidate);
            if let Some(c) = screen_candidate(fit, cand, robot, b.params(), data.calibration) {
                return (c, None);
            }
            begun = Some(b);
        }
    }
    match calibrate_model_from(
        robot,
        data,
        settings,
        Purpose::Candidate,
        &(),
        shared,
        begun,
    ) {
        Err(e) => {
            let mut cand = Candidate::new(robot, reference);
            cand.rejected = Some(format!("the fit failed: {e}"));
            (cand, None)
        }
        Ok(cal) => assess(robot, reference, cal, data),
    }
}

/// The model a candidate extends, for its screen: that model's fit and its candidate.
pub(crate) struct Extends<'a, T> {
    /// The model's fit.
    pub fit: &'a T,
    /// The model's candidate (its cross-validated error).
    pub candidate: &'a Candidate,
}

impl<T> Clone for Extends<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Extends<'_, T> {}

/// Fits and judges one candidate model for [`search`] (`true`: the reference candidate). Given
/// the fit and the candidate of the model it extends, it may screen it first: then the
/// candidate with its estimated error ([`Candidate::screened`]) when it need not be fitted.
pub(crate) type FitCandidate<'a, T> =
    dyn Fn(&Robot, bool, Option<Extends<'_, T>>) -> (Candidate, Option<T>) + Sync + 'a;

/// The forward search and the choice (see the module docs) over candidates that `fit` fits and
/// judges (a [`Candidate`] with its cross-validated error, or rejected, and the fit when it
/// stands; `true` for the reference candidate), whatever the data: tracker points here,
/// constraint rows in [`crate::identification::constraint::selection`]. `auto` names the
/// families to try (those the data cannot support already left out); `given` fits the robot as
/// given, whose failure is the calibration's; thermal candidates are referred to
/// `reference_c`. `fit` may screen a candidate instead of fitting it (given the model it
/// extends); a screened candidate the choice would pick is fitted after all.
pub(crate) fn search<T: Send + Sync>(
    nominal: &Robot,
    auto: AutoFamilies,
    reference_c: Option<f64>,
    given: impl FnOnce(&Robot) -> Result<(Candidate, Option<T>)>,
    fit: &FitCandidate<'_, T>,
) -> Result<(ModelSelection, Option<T>)> {
    let compliant = !compliance::auto_joints(nominal).is_empty();
    let given_robot = Families::default().robot(nominal, reference_c)?;
    // The robot as given is part of every candidate: its fit failing is the calibration's.
    let (c0, f0) = given(&given_robot)?;
    let mut sets = vec![Families::default()];
    let mut robots = vec![given_robot];
    let mut candidates = vec![c0];
    let mut fits = vec![f0];
    // Forward search: from the robot as given, each round judges every set with one family more
    // than the current one, and moves to the best if it lowers the error by more than its
    // standard error; the search stops where none does.
    let mut current = 0;
    while candidates[current].rejected.is_none() {
        let next: Vec<Families> = sets[current]
            .larger(auto, compliant)
            .into_iter()
            .filter(|f| !sets.contains(f))
            .collect();
        let built: Vec<Robot> = next
            .iter()
            .map(|f| f.robot(nominal, reference_c))
            .collect::<Result<_>>()?;
        let from = fits[current].as_ref().map(|fit| Extends {
            fit,
            candidate: &candidates[current],
        });
        let outcomes: Vec<(Candidate, Option<T>)> =
            built.par_iter().map(|r| fit(r, false, from)).collect();
        let first = candidates.len();
        for ((f, r), o) in next.into_iter().zip(built).zip(outcomes) {
            let (c, fitted) = o;
            sets.push(f);
            robots.push(r);
            candidates.push(c);
            fits.push(fitted);
        }
        // The round's best, as if every candidate were fitted: a screened best stops the search
        // (its estimate does not lower the error) unless it would move it or a fitted candidate
        // of the round would, and then its fit decides (it may be rejected).
        let round = first..candidates.len();
        let best = loop {
            let best = lowest(&candidates, round.clone(), |c| c.rejected.is_none());
            let moves = |i: usize| {
                let c = &candidates[i];
                c.rejected.is_none() && lowers(c, &candidates[current])
            };
            match best {
                Some(b) if candidates[b].screened && round.clone().any(moves) => {
                    (candidates[b], fits[b]) = fit(&robots[b], false, None);
                }
                _ => break best,
            }
        };
        match best {
            Some(b) if lowers(&candidates[b], &candidates[current]) => current = b,
            _ => break,
        }
    }
    // Families the user fixed are in every candidate: the geometric model beside them tells
    // whether they lower the error at all.
    if !families(nominal).is_empty() {
        let geometric = nominal.geometric();
        let (c, _) = fit(&geometric, true, None);
        robots.push(geometric);
        candidates.push(c);
        fits.push(None);
    }
    // Screened candidates take part in the choice with their estimates, as their fits would
    // with their errors, but are never chosen: one the choice would pick is fitted first, and so
    // is one whose estimate turns the choice (the lowest error, whose fit may be rejected).
    // Each round fits one, so this ends. (With the selection's screen only the pick can happen:
    // a screened candidate does not lower the model it extends, so its limit takes that model
    // in. The limit's case guards `search` for any screen.) A candidate so fitted does not
    // resume the search: its estimate, its error to a small fraction of the margin, did not
    // lower its model's.
    let chosen = loop {
        let (with, limit) = choose(&candidates, true);
        let (without, _) = choose(&candidates, false);
        let refit = if candidates[with].screened {
            Some(with)
        } else if with != without {
            limit.filter(|&b| candidates[b].screened)
        } else {
            None
        };
        match refit {
            Some(i) => (candidates[i], fits[i]) = fit(&robots[i], false, None),
            None => break with,
        }
    };
    candidates[chosen].chosen = true;
    let selection = ModelSelection {
        folds: FOLDS,
        remark: overfitting(&candidates[chosen], candidates.iter().find(|c| c.reference)),
        candidates,
        robot: robots.swap_remove(chosen),
    };
    Ok((selection, fits.swap_remove(chosen)))
}

/// A candidate's fit judged: rejected when it did not converge or fails the plausibility gate,
/// else cross-validated. The fit is returned when it stands.
fn assess(
    robot: &Robot,
    reference: bool,
    cal: Calibration,
    data: CalibrationData,
) -> (Candidate, Option<Calibration>) {
    let mut cand = Candidate::new(robot, reference);
    cand.identified = cal.identifiability.identified.len();
    let whole = cal.whole_solve();
    if !whole.termination.converged() {
        cand.rejected = Some(format!(
            "the solver {} after {} iterations",
            whole.termination.describe(),
            whole.iterations
        ));
        return (cand, None);
    }
    if cal.plausibility.implausible() {
        cand.rejected = Some(format!(
            "failed the plausibility gate: {}",
            cal.plausibility
                .failures()
                .map(|f| f.detail.clone())
                .collect::<Vec<_>>()
                .join("; ")
        ));
        return (cand, None);
    }
    match cross_validate(&cal, data.calibration, FOLDS) {
        Ok(CrossValidation {
            mean_mm,
            std_error_mm,
            ..
        }) => {
            cand.cv_mean_mm = Some(mean_mm);
            cand.cv_std_error_mm = Some(std_error_mm);
            (cand, Some(cal))
        }
        Err(e) => {
            cand.rejected = Some(format!("the cross-validation failed: {e}"));
            (cand, None)
        }
    }
}

impl Candidate {
    /// A candidate for `robot` not yet fitted.
    pub(crate) fn new(robot: &Robot, reference: bool) -> Candidate {
        Candidate {
            families: families(robot),
            identified: 0,
            cv_mean_mm: None,
            cv_std_error_mm: None,
            rejected: None,
            chosen: false,
            screened: false,
            reference,
        }
    }
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

/// A candidate's cross-validated error (infinite when it has none).
fn cv(c: &Candidate) -> f64 {
    c.cv_mean_mm.unwrap_or(f64::INFINITY)
}

/// Whether `larger` lowers `smaller`'s cross-validated error by more than its own standard
/// error.
fn lowers(larger: &Candidate, smaller: &Candidate) -> bool {
    cv(larger) + larger.cv_std_error_mm.unwrap_or(f64::INFINITY) < cv(smaller)
}

/// The candidate among `range` with the lowest cross-validated error, of those `keep` takes.
fn lowest(
    c: &[Candidate],
    range: std::ops::Range<usize>,
    keep: impl Fn(&Candidate) -> bool,
) -> Option<usize> {
    range
        .filter(|&i| keep(&c[i]))
        .min_by(|&a, &b| cv(&c[a]).total_cmp(&cv(&c[b])))
}

/// The one-standard-error rule over the selectable candidates (simplest first in `c`;
/// screened ones counted when `screened`, with their estimates): the simplest whose error is
/// within one standard error of the lowest, and the lowest (which set that limit). The first
/// candidate (the robot as given) when none is selectable.
fn choose(c: &[Candidate], screened: bool) -> (usize, Option<usize>) {
    // The families refine the robot as given: on top of a fit that failed, did not converge or
    // is implausible they are not chosen, and its calibration says why.
    if c.first().map_or(true, |x| x.rejected.is_some()) {
        return (0, None);
    }
    let ok = |x: &Candidate| {
        !x.reference && x.rejected.is_none() && x.cv_mean_mm.is_some() && (screened || !x.screened)
    };
    let Some(best) = lowest(c, 0..c.len(), ok) else {
        return (0, None);
    };
    let limit = cv(&c[best]) + c[best].cv_std_error_mm.unwrap_or(0.0);
    let chosen = c
        .iter()
        .enumerate()
        .filter(|(_, x)| ok(x) && cv(x) <= limit)
        .min_by_key(|(i, x)| (x.identified, *i))
        .map_or(0, |(i, _)| i);
    (chosen, Some(best))
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
            screened: false,
            reference: false,
        }
    }

    #[test]
    fn the_simplest_within_one_standard_error_of_the_best_is_chosen() {
        // A family that gains less than the standard error does not stay.
        let c = [cand(26, 0.050, 0.003, false), cand(36, 0.048, 0.003, false)];
        assert_eq!(choose(&c, true).0, 0);
        // One that gains more does.
        let c = [cand(26, 0.100, 0.002, false), cand(36, 0.088, 0.001, false)];
        assert_eq!(choose(&c, true).0, 1);
        // A rejected candidate is never chosen, however low its error.
        let c = [cand(26, 0.100, 0.002, false), cand(36, 0.010, 0.001, true)];
        assert_eq!(choose(&c, true).0, 0);
        // Nothing selectable: the robot as given.
        let c = [cand(26, 0.100, 0.002, true), cand(36, 0.010, 0.001, true)];
        assert_eq!(choose(&c, true).0, 0);
        // The robot as given rejected: no family on top of it.
        let c = [cand(26, 0.100, 0.002, true), cand(36, 0.010, 0.001, false)];
        assert_eq!(choose(&c, true).0, 0);
        // The reference (the geometric model beside explicit families) is never chosen.
        let mut r = cand(20, 0.010, 0.001, false);
        r.reference = true;
        let c = [cand(26, 0.100, 0.002, false), r];
        assert_eq!(choose(&c, true).0, 0);
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
