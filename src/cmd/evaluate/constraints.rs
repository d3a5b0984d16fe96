//! `evaluate` and constraint calibrations (issue 31).
//!
//! - Constraint rows (held-out configurations that reach the calibration's fixed points or touch
//!   its spheres and planes): their residuals under the calibrated model with the calibration's
//!   features, beside the nominal model's with the features fitted to it alone.
//! - Tracker points against a calibration up to the base pose: the result has no tracker frame
//!   to use, so the data are registered as with `--refit-frame` (the caller does it, and says
//!   so).

use robocal_core::identification::constraint::result::held_out;
use robocal_core::io::result_constraint::ConstraintSection;
use robocal_core::io::{read_measurements, Positions};
use robocal_core::observations::constraint::ConstraintData;
use robocal_core::{ErrorStats, Robot};
use std::path::Path;

/// What evaluating constraint rows needs.
pub(super) struct HeldOut<'a> {
    pub nominal: &'a Robot,
    pub calibrated: &'a Robot,
    pub section: Option<&'a ConstraintSection>,
    pub params: &'a Path,
    pub data: &'a Path,
    pub json: bool,
}

/// Evaluates constraint rows (see the module docs) and prints the table or JSON.
pub(super) fn run(h: HeldOut) -> anyhow::Result<()> {
    let Some(section) = h.section else {
        return Err(crate::exit::input(format!(
            "--data {}: constraint rows are evaluated against a calibration's fixed features, \
             and {} is a tracker calibration without any (give tracker points, x,y,z)",
            h.data.display(),
            h.params.display()
        )));
    };
    let set = read_measurements(h.data, h.nominal.joint_space(), Positions::Ignored)?;
    for w in &set.warnings {
        errln!("warning: {w}")?;
    }
    let mut data = ConstraintData::from_measurements(&set)?;
    data.distances = Vec::new();
    if !data.tracker.is_empty() {
        errln!(
            "note: {}: {} tracker row(s) left out (evaluate them from a file of tracker rows \
             alone); the constraint rows follow",
            h.data.display(),
            data.tracker.len()
        )?;
        data.tracker.clear();
    }
    data.check_counts()?;
    let recorded = section.estimates(h.params)?;
    let [nom, cal] = held_out(h.nominal, h.calibrated, &data, &recorded)?;
    let (nom, cal) = (ErrorStats::from_norms(&nom), ErrorStats::from_norms(&cal));
    if h.json {
        let o = serde_json::json!({
            "data": h.data.display().to_string(),
            "params": h.params.display().to_string(),
            "reference": "constraint",
            "n": data.rows.len(),
            "nominal": nom,
            "calibrated": cal,
            "frame": section.frame,
        });
        outln!("{}", serde_json::to_string_pretty(&o)?)?;
        return Ok(());
    }
    outln!(
        "constraint residuals of {} held-out row(s) of {} (mm; a fixed point's residual is the \
         distance to it, a sphere's or plane's the distance to its surface):",
        data.rows.len(),
        h.data.display()
    )?;
    outln!(
        "{:<44} {:>9} {:>9} {:>9} {:>9}",
        "model",
        "mean",
        "rms",
        "max",
        "p95"
    )?;
    for (name, s) in [
        ("nominal (features fitted to it alone)", nom),
        ("calibrated (the calibration's features)", cal),
    ] {
        outln!(
            "{name:<44} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
            s.mean_mm,
            s.rms_mm,
            s.max_mm,
            s.p95_mm
        )?;
    }
    outln!("note: {}", section.frame)?;
    Ok(())
}
