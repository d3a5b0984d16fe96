//! What a run of `compensate --joints` or `--targets` tells: the tally gathered row by row, the
//! rows that did not converge (an error with `--strict`, else warnings) and the summary printed
//! at the end.

use super::super::io_plan;
use crate::exit;
use robocal_core::compensation::{Compensation, IkStatus};
use robocal_core::{Robot, Unit};
use std::path::Path;

/// Rows listed one by one in warnings before the rest are summarized.
const LISTED: usize = 20;

/// The first [`LISTED`] of a kind of row, and how many there are.
#[derive(Default)]
pub(super) struct Listing {
    count: usize,
    items: Vec<String>,
}

impl Listing {
    /// Counts `item`, and keeps it while fewer than [`LISTED`] are kept.
    pub(super) fn push(&mut self, item: String) {
        self.count += 1;
        if self.items.len() < LISTED {
            self.items.push(item);
        }
    }

    /// How many items were pushed.
    pub(super) fn count(&self) -> usize {
        self.count
    }

    /// The listed items, and a last line for the rest.
    fn lines(&self) -> Vec<String> {
        let mut v = self.items.clone();
        if self.count > v.len() {
            v.push(format!("... and {} more", self.count - v.len()));
        }
        v
    }

    /// The listed items on one line, and how many more there are.
    pub(super) fn text(&self) -> String {
        let mut s = self.items.join(", ");
        if self.count > self.items.len() {
            s.push_str(&format!(", ... ({} more)", self.count - self.items.len()));
        }
        s
    }
}

/// What the summary needs, gathered row by row.
#[derive(Default)]
pub(super) struct Tally {
    rows: usize,
    counts: [usize; IkStatus::ALL.len()],
    failed: Listing,
    max_residual_converged: f64,
    max_residual: f64,
    max_residual_deg_converged: f64,
    max_residual_deg: f64,
    iterations: usize,
    max_iterations: usize,
    /// The largest joint change among converged rows, of revolute joints (degrees) and of
    /// prismatic ones (mm): (change, line, joint).
    max_change: [Option<(f64, usize, usize)>; 2],
}

impl Tally {
    /// Counts the compensation `c` of the row on `line` (with its `desired` joints, when the
    /// input gives them) of `robot`.
    pub(super) fn add(
        &mut self,
        robot: &Robot,
        line: usize,
        c: &Compensation,
        desired: Option<&[f64]>,
    ) {
        let r = &c.report;
        self.rows += 1;
        if let Some(k) = IkStatus::ALL.iter().position(|s| *s == r.status) {
            self.counts[k] += 1;
        }
        self.max_residual = self.max_residual.max(r.residual_mm);
        self.max_residual_deg = self.max_residual_deg.max(r.residual_deg);
        self.iterations += r.iterations;
        self.max_iterations = self.max_iterations.max(r.iterations);
        if !r.status.is_converged() {
            self.failed.push(describe_failure(line, c));
            return;
        }
        self.max_residual_converged = self.max_residual_converged.max(r.residual_mm);
        self.max_residual_deg_converged = self.max_residual_deg_converged.max(r.residual_deg);
        if let Some(d) = desired {
            for (i, (qc, qd)) in c.commanded.iter().zip(d).enumerate() {
                let unit = robot.joint_unit(i);
                let ch = unit.from_internal((qc - qd).abs());
                let slot = &mut self.max_change[usize::from(unit == Unit::Mm)];
                if !matches!(slot, Some(b) if b.0 >= ch) {
                    *slot = Some((ch, line, i));
                }
            }
        }
    }

    /// Shows the count of rows on the spinner now and then.
    pub(super) fn tick(&self, pb: &indicatif::ProgressBar) {
        if self.rows % 4096 == 0 {
            pb.set_message(format!("compensating: {} rows", self.rows));
        }
    }
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
        IkStatus::ConfigurationChange => {
            "the pose is reached only on another configuration (shoulder, elbow or wrist) than \
             the desired one"
                .to_owned()
        }
        IkStatus::Singular => {
            "near a singularity (configuration undecided, large joint motions)".to_owned()
        }
        IkStatus::Converged => "converged".to_owned(),
    };
    if c.desired_orientation.is_some() {
        format!(
            "line {line}: {}: {why}; {:.4} mm and {:.4} deg from the target pose",
            r.status, r.residual_mm, r.residual_deg
        )
    } else {
        format!(
            "line {line}: {}: {why}; closest {:.4} mm from the target",
            r.status, r.residual_mm
        )
    }
}

/// The rows of `input` that did not converge: with `strict` an error (exit 5; the caller then
/// writes nothing), else listed as warnings (the rest counted, with where their status is: `out`).
pub(super) fn failures(t: &Tally, strict: bool, input: &Path, out: &Path) -> anyhow::Result<()> {
    if t.failed.count == 0 {
        return Ok(());
    }
    if strict {
        return Err(exit::numerical(format!(
            "--strict: {} of {} row(s) of {} did not converge; nothing written:\n  {}",
            t.failed.count,
            t.rows,
            input.display(),
            t.failed.lines().join("\n  ")
        )));
    }
    for f in &t.failed.items {
        errln!("warning: {}: {f}", input.display())?;
    }
    if t.failed.count > LISTED {
        errln!(
            "warning: ... and {} more (see the status column of {})",
            t.failed.count - LISTED,
            io_plan::shown(out)
        )?;
    }
    Ok(())
}

/// Prints the summary of a run on `input` (desired joints if `joints`, else targets), solved on
/// the calibrated model of `params`, written to `out`.
pub(super) fn print_summary(
    joints: bool,
    full_pose: bool,
    params: &Path,
    (tolerance_mm, tolerance_deg): (f64, f64),
    out: &Path,
    input: &Path,
    t: &Tally,
) -> anyhow::Result<()> {
    let mode = match (joints, full_pose) {
        (true, true) => "desired poses; target = nominal tool pose (eq. 13, full pose)",
        (true, false) => "desired poses; target = nominal tool position (eq. 13, position only)",
        (false, true) => "Cartesian targets (base frame, full pose)",
        (false, false) => "Cartesian targets (base frame, position only)",
    };
    outln!(
        "{}: {} {mode}; solved on the calibrated model of {}",
        input.display(),
        t.rows,
        params.display()
    )?;
    for (s, n) in IkStatus::ALL.iter().zip(t.counts) {
        outln!("  {:<14} {n:>8}", s.as_str())?;
    }
    outln!(
        "  residual       max {:.3e} mm over converged rows, {:.3e} mm over all (tolerance {:e} mm)",
        t.max_residual_converged, t.max_residual, tolerance_mm
    )?;
    if full_pose {
        outln!(
            "  orientation    max {:.3e} deg over converged rows, {:.3e} deg over all \
             (tolerance {:e} deg)",
            t.max_residual_deg_converged,
            t.max_residual_deg,
            tolerance_deg
        )?;
    }
    let it_mean = t.iterations as f64 / t.rows.max(1) as f64;
    outln!(
        "  iterations     mean {it_mean:.1}, max {}",
        t.max_iterations
    )?;
    for (m, unit) in t.max_change.iter().zip(["deg", "mm"]) {
        if let Some((ch, line, i)) = m {
            outln!(
                "  joint change   max {ch:.4} {unit} (line {line}, q{})",
                i + 1
            )?;
        }
    }
    outln!("wrote {} ({} rows)", io_plan::shown(out), t.rows)?;
    Ok(())
}
