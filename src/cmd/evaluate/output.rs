//! What `robocal evaluate` prints: the statistics as a table or as JSON.

use super::{conditions, gap, io_plan, Evaluated, Settings};
use robocal_core::evaluation::Reference;
use robocal_core::io::CalibrationResult;
use robocal_core::ErrorStats;
use std::path::Path;

/// The statistics as JSON (`--json`).
pub(super) fn json(
    s: &Settings,
    e: &Evaluated,
) -> anyhow::Result<serde_json::Map<String, serde_json::Value>> {
    let res = &s.result;
    let mut o = serde_json::Map::new();
    o.insert("data".into(), s.data.display().to_string().into());
    o.insert("params".into(), s.params.display().to_string().into());
    o.insert(
        "reference".into(),
        match e.reference {
            Reference::Model => "model",
            Reference::Desired => "desired",
        }
        .into(),
    );
    o.insert("n".into(), e.n.into());
    if s.refit_frame {
        o.insert(
            "refit_frame".into(),
            serde_json::json!({
                "calibrated": e.frame.vector_deg(),
                "nominal": e.nominal_frame.vector_deg(),
            }),
        );
    }
    if s.nominal_limits {
        o.insert("rows_outside_limits".into(), e.n_outside.into());
    }
    for series in &e.series {
        o.insert(series.name.into(), serde_json::to_value(series.stats)?);
    }
    if e.reference == Reference::Desired {
        o.insert(
            "predicted".into(),
            serde_json::json!({
                "new_poses": res.prediction.as_ref().map(|p| serde_json::json!({
                    "mean_mm": p.mean_mm,
                    "std_mm": p.std_mm,
                    "rms_mm": p.rms_mm,
                })),
                "calibration": res.errors.calibration.after,
                "validation": res.errors.validation.map(|v| v.after),
            }),
        );
    }
    if let Some(g) = &e.gap {
        o.insert("gap".into(), g.json());
    }
    if !e.without.is_empty() {
        o.insert(
            "calibrated_without".into(),
            e.without
                .iter()
                .zip(&e.means_without)
                .map(|(w, m)| (w.key.to_owned(), serde_json::json!({ "mean_mm": m })))
                .collect::<serde_json::Map<_, _>>()
                .into(),
        );
    }
    if let Some(p) = &s.per_point {
        o.insert("per_point".into(), p.display().to_string().into());
    }
    Ok(o)
}

/// The statistics as a table, with the gap's split and the models without each condition family.
pub(super) fn print(s: &Settings, e: &Evaluated) -> anyhow::Result<()> {
    print_table(
        (&s.data, &s.params, s.per_point.as_deref()),
        e.n,
        e.reference,
        &e.series,
        &s.result,
        s.refit_frame.then_some(&e.frame),
    )?;
    if let Some(g) = &e.gap {
        gap::print(g)?;
    }
    conditions::print(&e.without, &e.means_without, e.series[1].stats.mean_mm)
}

/// Picks one figure out of a statistics record.
type Figure = fn(&ErrorStats) -> f64;

/// The rows of the statistics tables.
const STAT_ROWS: [(&str, Figure); 5] = [
    ("Mean (mm)", |s| s.mean_mm),
    ("St. dev. (mm)", |s| s.std_mm),
    ("Max. (mm)", |s| s.max_mm),
    ("RMS (mm)", |s| s.rms_mm),
    ("P95 (mm)", |s| s.p95_mm),
];

fn cell(v: f64) -> String {
    if v.is_finite() {
        format!(" {v:>12.4}")
    } else {
        format!(" {:>12}", "-")
    }
}

/// Prints the statistics of `files` (`--data`, `--params`, `--per-point`).
fn print_table(
    (data, params, per_point_path): (&Path, &Path, Option<&Path>),
    n: usize,
    reference: Reference,
    series: &[super::Series],
    res: &CalibrationResult,
    refit: Option<&robocal_core::frame::TrackerFrame>,
) -> anyhow::Result<()> {
    let what = match reference {
        Reference::Model => "validation: measured points against the models at the measured joints",
        Reference::Desired => {
            "verification: measured commanded poses against their desired positions (Table V)"
        }
    };
    let frame = match refit {
        Some(f) => {
            let v = f.vector_deg();
            format!(
                "tracker frame fitted to these data (another station): x={:.3} y={:.3} z={:.3} mm, \
                 A={:.4} B={:.4} C={:.4} deg",
                v[0], v[1], v[2], v[3], v[4], v[5]
            )
        }
        None => format!("tracker frame of {}", params.display()),
    };
    outln!("{}: {} points; {what}; {frame}", data.display(), n)?;
    match reference {
        Reference::Model => {
            for s in series {
                outln!("  {:<11} {}", s.name, s.description)?;
            }
            outln!()?;
            outln!("{:<14} {:>12} {:>12}", "", series[0].name, series[1].name)?;
            for (label, f) in STAT_ROWS {
                outln!(
                    "{label:<14}{}{}",
                    cell(f(&series[0].stats)),
                    cell(f(&series[1].stats))
                )?;
            }
            let (b, c) = (series[0].stats.mean_mm, series[1].stats.mean_mm);
            if b > 0.0 {
                outln!(
                    "mean error {} by {:.1}% with the calibrated model",
                    if c <= b { "reduced" } else { "increased" },
                    100.0 * (b - c).abs() / b
                )?;
            }
        }
        Reference::Desired => {
            // Verification beside what the calibration predicted (the result's Table IV).
            let cal = res.errors.calibration.after;
            let val = res.errors.validation.map(|v| v.after);
            outln!(
                "  predicted: the calibrated model's errors in {} (Table IV)",
                params.display()
            )?;
            outln!()?;
            out!("{:<14} {:>12} {:>12}", "", "verification", "pred. cal.")?;
            if val.is_some() {
                out!(" {:>12}", "pred. val.")?;
            }
            outln!()?;
            for (label, f) in STAT_ROWS {
                // A result file without p95 reads it as 0: show it as unknown.
                let pred = |s: &ErrorStats| {
                    if label.starts_with("P95") && s.p95_mm == 0.0 {
                        f64::NAN
                    } else {
                        f(s)
                    }
                };
                out!(
                    "{label:<14}{}{}",
                    cell(f(&series[0].stats)),
                    cell(pred(&cal))
                )?;
                if let Some(v) = &val {
                    out!("{}", cell(pred(v)))?;
                }
                outln!()?;
            }
            // One prediction everywhere: the expected mean error at new poses spread like the
            // calibration poses (calibrate's `prediction`); Table IV's calibration points only
            // for a result without one, and then named as such.
            let m = series[0].stats.mean_mm;
            let (p, basis) = match res.prediction.as_ref().map(|p| p.mean_mm) {
                Some(p) if p.is_finite() => (
                    p,
                    "predicted at new poses spread like the calibration poses (calibrate's \
                     prediction)",
                ),
                _ => (
                    cal.mean_mm,
                    "on the calibration points (Table IV; the result has no prediction)",
                ),
            };
            if p > 0.0 {
                outln!(
                    "verification mean {m:.4} mm vs {p:.4} mm {basis} ({:+.0}%)",
                    100.0 * (m - p) / p
                )?;
            }
        }
    }
    if let Some(p) = per_point_path {
        outln!("wrote {} ({n} rows)", io_plan::shown(p))?;
    }
    Ok(())
}
