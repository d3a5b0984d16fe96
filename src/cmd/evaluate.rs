//! `robocal evaluate`: error statistics of a measured data set under the nominal and the
//! calibrated model (validation, paper section IV), or of measured commanded poses against their
//! desired positions (verification, section V.B, Table V).

use super::common;
use anyhow::Context;
use clap::{Args, ValueEnum};
use robocal_core::evaluation::{self, Against, Evaluation, Reference};
use robocal_core::io::{read_measurements, CalibrationResult, MeasurementSet, Positions};
use robocal_core::{ErrorStats, Robot};

use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct EvaluateArgs {
    /// The nominal robot: a preset name or a TOML robot file.
    #[arg(long)]
    robot: String,
    /// The calibration result (`robocal calibrate --out`): calibrated model and tracker frame.
    #[arg(long)]
    params: PathBuf,
    /// Measured data: q1..qn (degrees), x,y,z (mm, tracker frame), other columns carried.
    #[arg(long)]
    data: PathBuf,
    /// What the measured points are compared with. `auto`: the desired positions when the data
    /// carry the columns `compensate` writes (x_desired,y_desired,z_desired or q1_desired..),
    /// else the models.
    #[arg(long, value_enum, default_value_t = AgainstArg::Auto)]
    against: AgainstArg,
    /// Write per-point errors (dx, dy, dz, norm per series, mm, base frame) to this CSV.
    #[arg(long, value_name = "OUT.csv")]
    per_point: Option<PathBuf>,
    /// Print the statistics as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum AgainstArg {
    /// Desired positions if the data carry them, else the models.
    Auto,
    /// The nominal and calibrated models at the measured joints (validation).
    Model,
    /// The desired positions of commanded poses (verification).
    Desired,
}

/// The nominal robot, the calibrated one and the result, checked to belong together.
pub(super) fn calibrated_model(
    robot: &str,
    params: &Path,
) -> anyhow::Result<(Robot, Robot, CalibrationResult)> {
    let m = common::model(robot, Some(params))?;
    let (cal, res) = m.calibrated.expect("--params given");
    evaluation::check_result_nominal(&res, &m.nominal, params)?;
    Ok((m.nominal, cal, res))
}

pub fn run(a: EvaluateArgs) -> anyhow::Result<()> {
    if let Some(p) = &a.per_point {
        common::check_output("--per-point", p, &[&a.data, &a.params])?;
    }
    let (nominal, cal, res) = calibrated_model(&a.robot, &a.params)?;
    common::warn_partial(&res, &a.params);
    let data = read_measurements(&a.data, nominal.dof(), Positions::Required)
        .with_context(|| format!("--data {}", a.data.display()))?;
    for w in &data.warnings {
        eprintln!("warning: {w}");
    }
    let against = match a.against {
        AgainstArg::Auto => Against::Auto,
        AgainstArg::Model => Against::Model,
        AgainstArg::Desired => Against::Desired,
    };
    let ev = evaluation::evaluate(&nominal, &cal, &res.tracker_frame(), &data, against)?;
    if let Some(p) = &a.per_point {
        ev.write_per_point(p, &data)?;
    }
    note_statuses(&data);
    if a.json {
        let mut o = serde_json::Map::new();
        o.insert("data".into(), a.data.display().to_string().into());
        o.insert("params".into(), a.params.display().to_string().into());
        o.insert(
            "reference".into(),
            match ev.reference {
                Reference::Model => "model",
                Reference::Desired => "desired",
            }
            .into(),
        );
        o.insert("n".into(), data.rows.len().into());
        for s in &ev.series {
            o.insert(s.name.into(), serde_json::to_value(s.stats)?);
        }
        if ev.reference == Reference::Desired {
            o.insert(
                "predicted".into(),
                serde_json::json!({
                    "calibration": res.errors.calibration.after,
                    "validation": res.errors.validation.map(|v| v.after),
                }),
            );
        }
        if let Some(p) = &a.per_point {
            o.insert("per_point".into(), p.display().to_string().into());
        }
        println!("{}", serde_json::to_string_pretty(&o)?);
    } else {
        print_table(&a, &data, &ev, &res);
    }
    Ok(())
}

/// Tells the user about rows of a commanded file whose compensation did not converge.
fn note_statuses(data: &MeasurementSet) {
    if !data.extra_columns.iter().any(|c| c == "status") {
        return;
    }
    let bad: Vec<String> = data
        .rows
        .iter()
        .filter_map(|r| {
            let s = data.extra_value(r, "status")?;
            (s != "converged").then(|| format!("line {} ({s})", r.line))
        })
        .collect();
    if !bad.is_empty() {
        eprintln!(
            "note: {} row(s) were not converged in compensation; their errors are included: {}",
            bad.len(),
            bad.join(", ")
        );
    }
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

fn print_table(a: &EvaluateArgs, data: &MeasurementSet, ev: &Evaluation, res: &CalibrationResult) {
    let what = match ev.reference {
        Reference::Model => "validation: measured points against the models at the measured joints",
        Reference::Desired => {
            "verification: measured commanded poses against their desired positions (Table V)"
        }
    };
    println!(
        "{}: {} points; {what}; tracker frame of {}",
        a.data.display(),
        data.rows.len(),
        a.params.display()
    );
    match ev.reference {
        Reference::Model => {
            for s in &ev.series {
                println!("  {:<11} {}", s.name, s.description);
            }
            println!();
            println!(
                "{:<14} {:>12} {:>12}",
                "", ev.series[0].name, ev.series[1].name
            );
            for (label, f) in STAT_ROWS {
                println!(
                    "{label:<14}{}{}",
                    cell(f(&ev.series[0].stats)),
                    cell(f(&ev.series[1].stats))
                );
            }
            let (b, c) = (ev.series[0].stats.mean_mm, ev.series[1].stats.mean_mm);
            if b > 0.0 {
                println!(
                    "mean error {} by {:.1}% with the calibrated model",
                    if c <= b { "reduced" } else { "increased" },
                    100.0 * (b - c).abs() / b
                );
            }
        }
        Reference::Desired => {
            // Verification beside what the calibration predicted (the result's Table IV).
            let cal = res.errors.calibration.after;
            let val = res.errors.validation.map(|v| v.after);
            println!(
                "  predicted: the calibrated model's errors in {} (Table IV)",
                a.params.display()
            );
            println!();
            print!("{:<14} {:>12} {:>12}", "", "verification", "pred. cal.");
            if val.is_some() {
                print!(" {:>12}", "pred. val.");
            }
            println!();
            for (label, f) in STAT_ROWS {
                // A result file without p95 reads it as 0: show it as unknown.
                let pred = |s: &ErrorStats| {
                    if label.starts_with("P95") && s.p95_mm == 0.0 {
                        f64::NAN
                    } else {
                        f(s)
                    }
                };
                print!(
                    "{label:<14}{}{}",
                    cell(f(&ev.series[0].stats)),
                    cell(pred(&cal))
                );
                if let Some(v) = &val {
                    print!("{}", cell(pred(v)));
                }
                println!();
            }
            let (m, p) = (ev.series[0].stats.mean_mm, cal.mean_mm);
            if p > 0.0 {
                println!(
                    "verification mean {m:.4} mm vs {p:.4} mm predicted on the calibration points \
                     ({:+.0}%)",
                    100.0 * (m - p) / p
                );
            }
        }
    }
    if let Some(p) = &a.per_point {
        println!("wrote {} ({} rows)", p.display(), data.rows.len());
    }
}
