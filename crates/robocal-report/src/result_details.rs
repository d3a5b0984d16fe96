//! The report sections read from the keys `robocal calibrate` adds to a result file beyond the
//! contract (`identifiability`, `uncertainty`, `solver`, `settings`, `registration`). Files
//! without them (or from another tool) simply give no such section.

use crate::data::{CorrelatedPair, FixedParam, Identifiability, Setting, SolverSummary};
use robocal_core::io::CalibrationResult;
use serde_json::Value;

fn get<'a>(result: &'a CalibrationResult, path: &[&str]) -> Option<&'a Value> {
    let mut v = result.extra.get(path[0])?;
    for k in &path[1..] {
        v = v.get(k)?;
    }
    Some(v)
}

fn f64_at(result: &CalibrationResult, path: &[&str]) -> Option<f64> {
    get(result, path).and_then(Value::as_f64)
}

fn str_of(v: &Value, key: &str) -> Option<String> {
    v.get(key).and_then(Value::as_str).map(str::to_owned)
}

/// The objective's name as a phrase, with the paper's equation.
fn objective_phrase(name: &str) -> String {
    match name {
        "sum-of-norms" => "sum of displacement error norms (eq. 4)".into(),
        "least-squares" => "sum of squared displacement errors".into(),
        "robust" => "robust loss (sum of norms first, then down-weighting outliers)".into(),
        other => other.into(),
    }
}

/// Identifiability: condition number, counts, most correlated pairs, fixed parameters.
pub fn identifiability(result: &CalibrationResult) -> Option<Identifiability> {
    let id = result.extra.get("identifiability")?;
    let fixed = id
        .get("fixed")
        .and_then(Value::as_array)
        .map(|list| {
            list.iter()
                .filter_map(|f| {
                    Some(FixedParam {
                        name: str_of(f, "name")?,
                        reason: str_of(f, "reason").unwrap_or_default(),
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    let correlated_pairs = get(result, &["uncertainty", "most_correlated"])
        .and_then(Value::as_array)
        .map(|list| {
            list.iter()
                .filter_map(|c| {
                    Some(CorrelatedPair {
                        a: str_of(c, "a")?,
                        b: str_of(c, "b")?,
                        correlation: c.get("rho")?.as_f64()?,
                    })
                })
                .collect()
        })
        .unwrap_or_default();
    let count = |k: &str| id.get(k).and_then(Value::as_u64).map(|v| v as usize);
    let identified = count("n_identified");
    Some(Identifiability {
        condition_number: id.get("condition_number").and_then(Value::as_f64),
        identified,
        total: identified
            .zip(count("n_fixed"))
            .map(|(a, b)| a + b)
            .or(Some(result.parameters.len())),
        correlated_pairs,
        fixed,
    })
}

/// The solver's summary.
pub fn solver(result: &CalibrationResult) -> Option<SolverSummary> {
    let s = result.extra.get("solver")?;
    let stages = s.get("stages").and_then(Value::as_array);
    let first = stages.and_then(|v| v.first());
    let mut extra = Vec::new();
    if let Some(stages) = stages.filter(|v| v.len() > 1) {
        let names: Vec<String> = stages.iter().filter_map(|x| str_of(x, "loss")).collect();
        extra.push(Setting::new("Stages", names.join(" → ")));
    }
    Some(SolverSummary {
        method: "Levenberg–Marquardt with reweighting (robocal)".into(),
        objective: str_of(s, "objective")
            .map(|o| objective_phrase(&o))
            .unwrap_or_default(),
        initial_value: first.and_then(|f| f.get("initial_objective")?.as_f64()),
        final_value: s.get("final_objective").and_then(Value::as_f64),
        value_unit: match str_of(s, "objective").as_deref() {
            Some("sum-of-norms") => Some("mm".into()),
            Some("least-squares") => Some("mm²".into()),
            _ => None,
        },
        termination: str_of(s, "termination").unwrap_or_default(),
        iterations: s
            .get("iterations")
            .and_then(Value::as_u64)
            .map(|v| v as usize),
        evaluations: stages.map(|v| {
            v.iter()
                .filter_map(|x| x.get("evaluations")?.as_u64())
                .sum::<u64>() as usize
        }),
        extra,
    })
}

/// Settings of the run as recorded in the result: files, objective, registration.
pub fn settings(result: &CalibrationResult) -> Vec<Setting> {
    let mut out = Vec::new();
    let s = result.extra.get("settings");
    let text = |k: &str| s.and_then(|s| s.get(k)).and_then(Value::as_str);
    if let Some(d) = text("data") {
        out.push(Setting::new("Calibration data", d));
    }
    if let Some(v) = text("validate") {
        out.push(Setting::new("Validation data", v));
    }
    if let Some(o) = text("objective") {
        out.push(Setting::new("Objective", objective_phrase(o)));
    }
    let list = |k: &str| -> Vec<String> {
        s.and_then(|s| s.get(k))
            .and_then(Value::as_array)
            .map(|v| {
                v.iter()
                    .filter_map(|x| x.as_str().map(str::to_owned))
                    .collect()
            })
            .unwrap_or_default()
    };
    for (k, label) in [
        ("fix", "Fixed by the user (--fix)"),
        ("free", "Preferred (--free)"),
        ("beta", "Hayati tilt parameters"),
    ] {
        let v = list(k);
        if !v.is_empty() {
            out.push(Setting::new(label, v.join(", ")));
        }
    }
    if let Some(reg) = result.extra.get("registration") {
        let initial = reg.get("initial");
        let source = initial.and_then(|i| str_of(i, "source"));
        let mut how = match source.as_deref() {
            Some("plane points") => format!(
                "initial frame from {} plane points, then",
                initial
                    .and_then(|i| i.get("points"))
                    .and_then(Value::as_u64)
                    .unwrap_or(3)
            ),
            Some(other) => format!("initial frame by {other}, then"),
            None => String::new(),
        };
        if let Some(o) = str_of(reg, "objective") {
            if !how.is_empty() {
                how.push(' ');
            }
            how.push_str(&format!(
                "fitted to the calibration points ({}, eq. 8–11)",
                o.replace('-', " ")
            ));
        }
        if !how.is_empty() {
            out.push(Setting::new("Measurement frame", how));
        }
    }
    if let Some(t) = f64_at(result, &["settings", "rank_tolerance"]) {
        out.push(Setting::new(
            "Rank tolerance (identifiability)",
            format!("{t:e}"),
        ));
    }
    out
}
