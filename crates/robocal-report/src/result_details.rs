//! The report sections read from the sections `robocal calibrate` adds to a result file beyond
//! the contract (`identifiability`, `uncertainty`, `solver`, `settings`, `registration`), through
//! their typed structs ([`robocal_core::io::result_sections`]). Files without them (or from
//! another tool) simply give no such section.

use crate::data::{CorrelatedPair, FixedParam, Identifiability, Setting, SolverSummary};
use robocal_core::io::result_sections::{InitialFrameEntry, LossEntry};
use robocal_core::io::CalibrationResult;

/// Identifiability: condition number, counts, most correlated pairs, fixed parameters.
pub fn identifiability(result: &CalibrationResult) -> Option<Identifiability> {
    let id = result.identifiability.as_ref()?;
    let fixed = id
        .fixed
        .iter()
        .map(|f| FixedParam {
            name: f.name.clone(),
            reason: f.reason.clone(),
        })
        .collect();
    let correlated_pairs = result
        .uncertainty
        .as_ref()
        .map(|u| {
            u.most_correlated
                .iter()
                .map(|c| CorrelatedPair {
                    a: c.a.clone(),
                    b: c.b.clone(),
                    correlation: c.rho,
                })
                .collect()
        })
        .unwrap_or_default();
    Some(Identifiability {
        condition_number: Some(id.condition_number).filter(|c| !c.is_nan()),
        identified: Some(id.n_identified),
        total: Some(id.n_identified + id.n_fixed),
        correlated_pairs,
        fixed,
    })
}

/// A stage's loss by name.
fn loss_name(l: &LossEntry) -> &'static str {
    match l {
        LossEntry::SumOfNorms { .. } => "sum-of-norms",
        LossEntry::LeastSquares => "least-squares",
        LossEntry::Huber { .. } => "huber",
        LossEntry::Cauchy { .. } => "cauchy",
        LossEntry::Adaptive { .. } => "adaptive",
    }
}

/// The solver's summary.
pub fn solver(result: &CalibrationResult) -> Option<SolverSummary> {
    let s = result.solver.as_ref()?;
    let mut extra = Vec::new();
    if s.stages.len() > 1 {
        let names: Vec<&str> = s.stages.iter().map(|x| loss_name(&x.loss)).collect();
        extra.push(Setting::new("Stages", names.join(" → ")));
    }
    Some(SolverSummary {
        method: "Levenberg–Marquardt with reweighting (robocal)".into(),
        objective: s.objective.phrase().to_owned(),
        initial_value: s.stages.first().map(|f| f.initial_objective),
        final_value: Some(s.final_objective),
        value_unit: s.objective.value_unit().map(str::to_owned),
        termination: s.termination.clone(),
        iterations: Some(s.iterations),
        evaluations: (!s.stages.is_empty())
            .then(|| s.stages.iter().map(|x| x.evaluations).sum::<usize>()),
        extra,
    })
}

/// Settings of the run as recorded in the result: files, objective, registration.
pub fn settings(result: &CalibrationResult) -> Vec<Setting> {
    let mut out = Vec::new();
    let s = result.settings.as_ref();
    if let Some(d) = s.and_then(|s| s.data.as_deref()) {
        out.push(Setting::new("Calibration data", crate::file_name(d)));
    }
    if let Some(v) = s.and_then(|s| s.validate.as_deref()) {
        out.push(Setting::new("Validation data", crate::file_name(v)));
    }
    if let Some(s) = s {
        out.push(Setting::new("Objective", s.objective.phrase()));
        for (v, label) in [
            (&s.fix, "Fixed by the user (--fix)"),
            (&s.free, "Preferred (--free)"),
            (&s.beta, "Hayati tilt parameters"),
        ] {
            if !v.is_empty() {
                out.push(Setting::new(label, v.join(", ")));
            }
        }
    }
    if let Some(reg) = &result.registration {
        let how = match &reg.initial {
            InitialFrameEntry::Plane { points, .. } => {
                format!("initial frame from {points} plane points, then")
            }
            InitialFrameEntry::LeastSquares => "initial frame by least-squares fit, then".into(),
        };
        let objective = reg.objective.name().replace('-', " ");
        out.push(Setting::new(
            "Measurement frame",
            format!("{how} fitted to the calibration points ({objective}, eq. 8–11)"),
        ));
    }
    if let Some(s) = s {
        out.push(Setting::new(
            "Rank tolerance (identifiability)",
            format!("{:e}", s.rank_tolerance),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use robocal_core::io::result_sections::ObjectiveName;

    /// Every objective a result can name reads as a phrase in the report, never as its raw
    /// name (robust runs once showed `robust (Cauchy)`).
    #[test]
    fn every_objective_has_a_phrase() {
        for o in [
            ObjectiveName::SumOfNorms,
            ObjectiveName::LeastSquares,
            ObjectiveName::RobustCauchy,
            ObjectiveName::RobustHuber,
            ObjectiveName::Adaptive,
        ] {
            let raw = serde_json::to_value(o).unwrap();
            let phrase = o.phrase();
            assert_ne!(raw.as_str().unwrap(), phrase);
            assert!(
                phrase.contains("loss") || phrase.contains("error"),
                "{phrase}"
            );
        }
        assert!(ObjectiveName::RobustCauchy.phrase().contains("Cauchy"));
        assert!(ObjectiveName::RobustHuber.phrase().contains("Huber"));
    }
}
