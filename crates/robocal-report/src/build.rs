//! Convenience builders: the paper's reference figures, the paper's table layout, and a report
//! skeleton from a calibration result file.

use crate::data::{
    ErrorRow, ErrorTable, HistogramSeries, Note, PaperStats, ParamRow, PointSet, ReportData,
    Setting,
};
use robocal_core::io::result::BeforeAfter;
use robocal_core::io::CalibrationResult;
use robocal_core::ErrorStats;

/// The reference figures of Samak et al. (2019), Tables II, IV and V (mean, std and max in mm).
pub mod paper {
    use crate::data::PaperStats;

    fn stats(table: &str, n: usize, mean: f64, std: f64, max: f64) -> PaperStats {
        PaperStats {
            source: format!("Samak et al. 2019, {table}"),
            n: Some(n),
            mean_mm: Some(mean),
            std_mm: Some(std),
            max_mm: Some(max),
            rms_mm: None,
            p95_mm: None,
        }
    }

    /// Table II, calibration points (75), before calibration.
    pub fn table2_calibration() -> PaperStats {
        stats("Table II", 75, 1.619, 0.269, 2.268)
    }
    /// Table II, validation points (73), before calibration.
    pub fn table2_validation() -> PaperStats {
        stats("Table II", 73, 1.603, 0.272, 2.173)
    }
    /// Table IV, calibration points, predicted after calibration.
    pub fn table4_calibration() -> PaperStats {
        stats("Table IV", 75, 0.174, 0.070, 0.370)
    }
    /// Table IV, validation points, predicted after calibration.
    pub fn table4_validation() -> PaperStats {
        stats("Table IV", 73, 0.242, 0.150, 0.921)
    }
    /// Table V, verification points, measured after compensation.
    pub fn table5_verification() -> PaperStats {
        stats("Table V", 75, 0.293, 0.168, 1.511)
    }
}

/// The error tables laid out as the paper's Tables II (before calibration), IV (after
/// calibration, predicted) and V (verification, measured after compensation). With
/// `with_paper`, the paper's figures are shown beside ours (meant for the paper's experiment).
pub fn paper_tables(
    calibration: BeforeAfter,
    validation: Option<BeforeAfter>,
    verification: Option<ErrorStats>,
    with_paper: bool,
) -> Vec<ErrorTable> {
    let row = |label: &str, s: ErrorStats, p: fn() -> PaperStats| {
        let r = ErrorRow::new(label, s);
        if with_paper {
            r.with_paper(p())
        } else {
            r
        }
    };
    let mut before = vec![row(
        "Calibration points",
        calibration.before,
        paper::table2_calibration,
    )];
    let mut after = vec![row(
        "Calibration points",
        calibration.after,
        paper::table4_calibration,
    )];
    if let Some(v) = validation {
        before.push(row("Validation points", v.before, paper::table2_validation));
        after.push(row("Validation points", v.after, paper::table4_validation));
    }
    let mut tables = vec![
        ErrorTable {
            title: "Before calibration (Table II)".into(),
            caption: Some(
                "Nominal model, after the measurement frame is fitted (eq. 8–11); error norms of \
                 eq. (3)."
                    .into(),
            ),
            rows: before,
        },
        ErrorTable {
            title: "After calibration, predicted (Table IV)".into(),
            caption: Some(
                "Calibrated model on the same measurements. The calibration points were used in \
                 the fit; the validation points were not."
                    .into(),
            ),
            rows: after,
        },
    ];
    if let Some(v) = verification {
        tables.push(ErrorTable {
            title: "Verification, measured after compensation (Table V)".into(),
            // The verified poses are whichever the verification file holds (the paper's and the
            // demo's are the calibration poses; the quick start's the validation poses).
            caption: Some(format!(
                "The {} poses of the verification file, commanded with compensated joint values \
                 (eq. 12–14), measured again and compared with their desired positions.",
                v.n
            )),
            rows: vec![row("Verification points", v, paper::table5_verification)],
        });
    }
    tables
}

/// Histogram series "before" and "after" from the named point sets (pooled), e.g.
/// `before_after_histogram(&sets, &["Calibration"], &["Calibration"])`.
pub fn before_after_histogram(
    sets: &[PointSet],
    before_from: &[&str],
    after_from: &[&str],
) -> Vec<HistogramSeries> {
    let pick = |names: &[&str], after: bool| -> Vec<f64> {
        sets.iter()
            .filter(|s| names.contains(&s.name.as_str()))
            .flat_map(|s| {
                s.points
                    .iter()
                    .map(move |p| if after { p.after_mm } else { p.before_mm })
            })
            .collect()
    };
    let describe = |names: &[&str]| -> String {
        match names {
            [] => String::new(),
            [one] => format!(" – {} points", one.to_lowercase()),
            more => format!(" – {} points", more.join(" + ").to_lowercase()),
        }
    };
    vec![
        HistogramSeries::new(
            format!("Before calibration{}", describe(before_from)),
            pick(before_from, false),
        ),
        HistogramSeries::new(
            format!("After calibration{}", describe(after_from)),
            pick(after_from, true),
        ),
    ]
}

/// Where a parameter goes in a table by joint: `(joint, kind)` for `alpha`, `d`, `a`, `phi`,
/// `beta` of a joint (in that order), then the base and the tool frame's x, y, z, A, B, C.
/// The reflector (1-based) whose tool parameter `name` is (`tool_x`: 1, `tool2_x`: 2), and its
/// axis (`x`).
pub(crate) fn reflector(name: &str) -> Option<(usize, &str)> {
    let rest = name.strip_prefix("tool")?;
    let (j, axis) = rest.split_once('_')?;
    match j {
        "" => Some((1, axis)),
        j if j.bytes().all(|b| b.is_ascii_digit()) => j.parse().ok().map(|j| (j, axis)),
        _ => None,
    }
}

pub(crate) fn display_order(name: &str) -> (usize, usize) {
    const AXES: [&str; 6] = ["x", "y", "z", "a", "b", "c"];
    let axis = |rest: &str| AXES.iter().position(|a| *a == rest).unwrap_or(AXES.len());
    if let Some(rest) = name.strip_prefix("base_") {
        return (usize::MAX - 1, axis(rest));
    }
    // The tool of reflector 1 (`tool_x`), then each further reflector's (`tool2_x`, ...), each
    // in axis order.
    if let Some((j, rest)) = reflector(name) {
        return (usize::MAX, (AXES.len() + 1) * j + axis(rest));
    }
    let digits = name.trim_start_matches(|c: char| !c.is_ascii_digit());
    let kind = &name[..name.len() - digits.len()];
    match (
        digits.parse::<usize>(),
        ["alpha", "d", "a", "phi", "beta"]
            .iter()
            .position(|k| *k == kind),
    ) {
        (Ok(j), Some(k)) => (j, k),
        _ => (usize::MAX - 2, 0),
    }
}

impl ReportData {
    /// A report skeleton from a result file: parameters, error tables, robot and tracker frame,
    /// and, when the file has the keys `robocal calibrate` writes, identifiability, solver and
    /// run settings. Per-point errors are the caller's to add (see [`ReportData::from_run`]).
    pub fn from_result(result: &CalibrationResult) -> ReportData {
        let mut parameters: Vec<ParamRow> = result
            .parameters
            .iter()
            .map(|(name, p)| ParamRow {
                name: name.clone(),
                unit: p.unit,
                nominal: p.nominal,
                calibrated: p.calibrated,
                std: p.std,
                fixed: p.fixed,
                reason: p.reason.clone(),
                truth: None,
            })
            .collect();
        // By joint, then base and tool, as in the paper's Tables I and III (the result lists
        // them by kind: alpha1..n, d1..n, ...).
        parameters.sort_by_key(|p| display_order(&p.name));
        let t = &result.tracker_frame;
        let mut settings = vec![
            Setting::new("Robot", &result.robot.name),
            Setting::new(
                "Model",
                format!(
                    "{} joints, {} parameters",
                    result.robot.dof,
                    result.robot.convention.to_uppercase()
                ),
            ),
            Setting::new(
                "Tracker frame (fitted)",
                format!(
                    "x {:.3}, y {:.3}, z {:.3} mm; A {:.4}, B {:.4}, C {:.4} deg (pose in the \
                     base frame)",
                    t.x, t.y, t.z, t.a, t.b, t.c
                ),
            ),
        ];
        settings.extend(crate::result_details::settings(result));
        settings.extend(crate::prediction::setting(result));
        let mut notes = Vec::new();
        if result.errors.validation.is_none() {
            notes.push(Note::info(
                "No validation set: the errors after calibration are on the points used in the fit.",
            ));
        }
        ReportData {
            title: format!("Calibration report – {}", result.robot.name),
            settings,
            error_tables: paper_tables(
                result.errors.calibration,
                result.errors.validation,
                None,
                false,
            ),
            parameters,
            identifiability: crate::result_details::identifiability(result),
            solver: crate::result_details::solver(result),
            notes,
            orientation: orientation_rows(result),
            ..ReportData::default()
        }
    }
}

/// The orientation-error rows of a 6-DoF result (none for point data).
fn orientation_rows(result: &CalibrationResult) -> Vec<crate::data::AngleRow> {
    let Some(o) = &result.orientation_errors else {
        return Vec::new();
    };
    let row = |label: &str, s: &robocal_core::io::result_cell::AngleStats| crate::data::AngleRow {
        label: label.to_string(),
        n: s.n,
        mean_deg: s.mean_deg,
        std_deg: s.std_deg,
        max_deg: s.max_deg,
        rms_deg: s.rms_deg,
    };
    let mut rows = vec![
        row("Calibration, nominal model", &o.calibration.before),
        row("Calibration, calibrated model", &o.calibration.after),
    ];
    if let Some(v) = &o.validation {
        rows.push(row("Validation, nominal model", &v.before));
        rows.push(row("Validation, calibrated model", &v.after));
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::PointError;

    #[test]
    fn histogram_from_sets_pools_named_sets() {
        let p = |b, a| PointError {
            reach_mm: 2000.0,
            before_mm: b,
            after_mm: a,
        };
        let sets = vec![
            PointSet {
                name: "Calibration".into(),
                points: vec![p(1.0, 0.1), p(2.0, 0.2)],
                details: Vec::new(),
            },
            PointSet {
                name: "Verification".into(),
                points: vec![p(f64::NAN, 0.3)],
                details: Vec::new(),
            },
        ];
        let h = before_after_histogram(&sets, &["Calibration"], &["Verification"]);
        assert_eq!(h[0].values_mm, vec![1.0, 2.0]);
        assert_eq!(h[1].values_mm, vec![0.3]);
        assert!(h[1].label.contains("verification points"), "{}", h[1].label);
    }

    #[test]
    fn parameters_by_joint_then_base_and_tool() {
        let mut names = vec![
            "tool_x", "alpha1", "alpha2", "d1", "d2", "a1", "a2", "phi1", "phi2", "base_c",
            "base_x", "beta2", "tool_a", "tool3_x", "tool2_y", "tool2_x", "tool3_a",
        ];
        names.sort_by_key(|n| display_order(n));
        assert_eq!(
            names,
            vec![
                "alpha1", "d1", "a1", "phi1", "alpha2", "d2", "a2", "phi2", "beta2", "base_x",
                "base_c", "tool_x", "tool_a", "tool2_x", "tool2_y", "tool3_x", "tool3_a"
            ]
        );
    }

    #[test]
    fn paper_layout() {
        let s = ErrorStats::from_norms(&[1.0, 2.0]);
        let t = paper_tables(
            BeforeAfter {
                before: s,
                after: s,
            },
            Some(BeforeAfter {
                before: s,
                after: s,
            }),
            Some(s),
            true,
        );
        assert_eq!(t.len(), 3);
        assert_eq!(t[0].rows.len(), 2);
        assert_eq!(t[0].rows[1].paper.as_ref().unwrap().mean_mm, Some(1.603));
        assert_eq!(t[2].rows[0].paper.as_ref().unwrap().max_mm, Some(1.511));
        let t = paper_tables(
            BeforeAfter {
                before: s,
                after: s,
            },
            None,
            None,
            false,
        );
        assert_eq!(t.len(), 2);
        assert!(t[0].rows[0].paper.is_none());
    }
}
