//! `robocal compensate`: commanded joint values from the calibrated model (paper, section V.A,
//! eq. 12-14), for desired joint vectors or for Cartesian targets.

use super::evaluate::calibrated_model;
use crate::exit;
use anyhow::Context;
use clap::Args;
use robocal_core::compensation::commanded::{check_extra_columns, status_counts, write_commanded};
use robocal_core::compensation::{read_targets, Compensation, IkStatus};
use robocal_core::io::{read_measurements, Positions};
use robocal_core::{Compensator, DampedLeastSquares};
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct CompensateArgs {
    /// The nominal robot (what the controller believes): a preset name or a TOML robot file.
    #[arg(long)]
    robot: String,
    /// The calibration result (`robocal calibrate --out`).
    #[arg(long)]
    params: PathBuf,
    /// Desired joint values: CSV with q1..qn (degrees). Each row's target is its nominal tool
    /// position (eq. 13); the solve starts from the row's joints. Other columns are carried;
    /// x,y,z (old measurements), if present, are not.
    #[arg(long, value_name = "DESIRED.csv", required_unless_present = "targets")]
    joints: Option<PathBuf>,
    /// Cartesian targets instead: CSV with x,y,z (mm, robot base frame) and optionally q1..qn
    /// (degrees) to start from; without them, several start configurations are tried.
    #[arg(long, value_name = "XYZ.csv", conflicts_with = "joints")]
    targets: Option<PathBuf>,
    /// Output: commanded joints (degrees) with status, residual and the desired values.
    #[arg(long, value_name = "COMMANDED.csv")]
    out: PathBuf,
    /// A solve has converged when the tool is this close to its target (mm).
    #[arg(long, default_value_t = 1e-6)]
    tolerance_mm: f64,
    /// Most iterations (Jacobian evaluations) per solve.
    #[arg(long, default_value_t = 500)]
    max_iterations: usize,
    /// Fail (exit code 5, nothing written) if any row does not converge. Without it, such rows
    /// are written with their status and the closest joints found, and listed as warnings.
    #[arg(long)]
    strict: bool,
}

/// Rows listed one by one in warnings before the rest are summarized.
const LISTED: usize = 20;

pub fn run(a: CompensateArgs) -> anyhow::Result<()> {
    let solver = DampedLeastSquares {
        tolerance_mm: a.tolerance_mm,
        max_iterations: a.max_iterations,
        ..DampedLeastSquares::default()
    };
    solver.validate().map_err(|e| {
        exit::usage(
            e.to_string()
                .replace("tolerance_mm", "--tolerance-mm")
                .replace("max_iterations", "--max-iterations"),
        )
    })?;
    let input = a.joints.as_ref().or(a.targets.as_ref());
    let mut inputs = vec![a.params.as_path()];
    inputs.extend(input.map(|p| p.as_path()));
    super::common::check_output("--out", &a.out, &inputs)?;
    let (nominal, cal, res) = calibrated_model(&a.robot, &a.params)?;
    if let Some(why) = res.partial_reason() {
        return Err(exit::input(format!(
            "--params {}: a partial result, not a calibration ({why}); compensation refuses \
             it: re-run calibrate with a higher --max-iterations",
            a.params.display()
        )));
    }
    let dof = nominal.dof();
    let comp = Compensator::new(&nominal, &cal, solver)?;
    let (input, rows, desired, extra_columns, extra, lines) = if let Some(path) = &a.joints {
        let set = read_measurements(path, dof, Positions::Optional)
            .with_context(|| format!("--joints {}", path.display()))?;
        for w in &set.warnings {
            eprintln!("warning: {w}");
        }
        check_extra_columns(path, dof, &set.extra_columns)?;
        if set.has_positions() {
            eprintln!(
                "note: {}: the x,y,z columns (measured positions) are not used or carried",
                path.display()
            );
        }
        let outside: Vec<String> = set
            .rows
            .iter()
            .filter_map(|r| {
                let o = nominal.joints_outside_limits(&r.q);
                (!o.is_empty()).then(|| {
                    let js: Vec<String> = o.iter().map(|i| format!("q{}", i + 1)).collect();
                    format!("line {} ({})", r.line, js.join(" "))
                })
            })
            .collect();
        if !outside.is_empty() {
            eprintln!(
                "warning: {} desired pose(s) outside the joint limits; solved from the nearest \
                 pose within them: {}",
                outside.len(),
                abbreviate(&outside)
            );
        }
        let desired: Vec<Vec<f64>> = set.rows.iter().map(|r| r.q.clone()).collect();
        let pb = crate::progress::bar(desired.len() as u64, "compensating");
        let rows = comp.compensate_all(&desired, &mut |d, _| pb.set_position(d as u64))?;
        pb.finish_and_clear();
        let extra: Vec<Vec<String>> = set.rows.iter().map(|r| r.extra.clone()).collect();
        let lines: Vec<usize> = set.rows.iter().map(|r| r.line).collect();
        (path, rows, Some(desired), set.extra_columns, extra, lines)
    } else {
        let path = a
            .targets
            .as_ref()
            .expect("clap requires --joints or --targets");
        let set =
            read_targets(path, dof).with_context(|| format!("--targets {}", path.display()))?;
        check_extra_columns(path, dof, &set.extra_columns)?;
        let pb = crate::progress::bar(set.rows.len() as u64, "reaching");
        let rows = comp.reach_all(&set.rows, &mut |d, _| pb.set_position(d as u64))?;
        pb.finish_and_clear();
        let extra: Vec<Vec<String>> = set.rows.iter().map(|r| r.extra.clone()).collect();
        let lines: Vec<usize> = set.rows.iter().map(|r| r.line).collect();
        (path, rows, None, set.extra_columns, extra, lines)
    };

    let failed: Vec<String> = rows
        .iter()
        .zip(&lines)
        .filter(|(c, _)| !c.report.status.is_converged())
        .map(|(c, l)| describe_failure(*l, c))
        .collect();
    if !failed.is_empty() {
        if a.strict {
            return Err(exit::numerical(format!(
                "--strict: {} of {} row(s) of {} did not converge; nothing written:\n  {}",
                failed.len(),
                rows.len(),
                input.display(),
                failed.join("\n  ")
            )));
        }
        for f in failed.iter().take(LISTED) {
            eprintln!("warning: {}: {f}", input.display());
        }
        if failed.len() > LISTED {
            eprintln!(
                "warning: ... and {} more (see the status column of {})",
                failed.len() - LISTED,
                a.out.display()
            );
        }
    }
    let extra_refs: Vec<&[String]> = extra.iter().map(|v| v.as_slice()).collect();
    write_commanded(
        &a.out,
        dof,
        &rows,
        desired.as_deref(),
        &extra_columns,
        &extra_refs,
    )?;
    print_summary(&a, input, &rows, desired.as_deref(), &lines);
    Ok(())
}

fn describe_failure(line: usize, c: &Compensation) -> String {
    let r = &c.report;
    let why = match r.status {
        IkStatus::JointLimit => {
            let js: Vec<String> = r.limited_joints().map(|i| format!("q{}", i + 1)).collect();
            format!(
                "reachable only beyond the joint limits (held at the limit: {})",
                js.join(" ")
            )
        }
        IkStatus::Unreachable => "outside the workspace of the calibrated model".to_owned(),
        IkStatus::NotConverged => format!("no convergence in {} iterations", r.iterations),
        IkStatus::Converged => "converged".to_owned(),
    };
    format!(
        "line {line}: {}: {why}; closest {:.4} mm from the target",
        r.status, r.residual_mm
    )
}

fn abbreviate(items: &[String]) -> String {
    let mut s = items
        .iter()
        .take(LISTED)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > LISTED {
        s.push_str(&format!(", ... ({} more)", items.len() - LISTED));
    }
    s
}

fn print_summary(
    a: &CompensateArgs,
    input: &std::path::Path,
    rows: &[Compensation],
    desired: Option<&[Vec<f64>]>,
    lines: &[usize],
) {
    let mode = if desired.is_some() {
        "desired poses; target = nominal tool position (eq. 13)"
    } else {
        "Cartesian targets (base frame)"
    };
    println!(
        "{}: {} {mode}; solved on the calibrated model of {}",
        input.display(),
        rows.len(),
        a.params.display()
    );
    for (s, n) in status_counts(rows) {
        println!("  {:<14} {n:>8}", s.as_str());
    }
    let max_all = rows
        .iter()
        .map(|c| c.report.residual_mm)
        .fold(0.0, f64::max);
    let conv: Vec<&Compensation> = rows
        .iter()
        .filter(|c| c.report.status.is_converged())
        .collect();
    let max_conv = conv
        .iter()
        .map(|c| c.report.residual_mm)
        .fold(0.0, f64::max);
    println!(
        "  residual       max {:.3e} mm over converged rows, {:.3e} mm over all (tolerance {:e} mm)",
        max_conv, max_all, a.tolerance_mm
    );
    let it_max = rows.iter().map(|c| c.report.iterations).max().unwrap_or(0);
    let it_mean =
        rows.iter().map(|c| c.report.iterations).sum::<usize>() as f64 / rows.len().max(1) as f64;
    println!("  iterations     mean {it_mean:.1}, max {it_max}");
    if let Some(d) = desired {
        // The largest joint correction among converged rows.
        let mut best: Option<(f64, usize, usize)> = None;
        for (k, c) in rows.iter().enumerate() {
            if !c.report.status.is_converged() {
                continue;
            }
            for (i, (qc, qd)) in c.commanded.iter().zip(&d[k]).enumerate() {
                let ch = (qc - qd).abs().to_degrees();
                if !matches!(best, Some(b) if b.0 >= ch) {
                    best = Some((ch, lines[k], i));
                }
            }
        }
        if let Some((ch, line, i)) = best {
            println!("  joint change   max {ch:.4} deg (line {line}, q{})", i + 1);
        }
    }
    println!("wrote {} ({} rows)", a.out.display(), rows.len());
}
