//! The rows of a measurement file sorted by their role (`set` column): calibration, validation
//! and the paper's plane points.

use crate::error::{Error, Result};
use crate::io::row_extras::ExtrasLayout;
use crate::io::{MeasurementSet, SetLabel};
use crate::observations::Observations;

/// The points of a measurement file sorted by their role, from an optional `set` column
/// ([`SetLabel`]): `plane` marks the paper's three points for the initial measurement frame,
/// `validation` (or `val`) validation points, `calibration` (or an empty cell, or no `set`
/// column) calibration points. Any other label is an error.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitData {
    /// Calibration points.
    pub calibration: Observations,
    /// Validation points found in the file (`set` = `validation`).
    pub validation: Observations,
    /// Plane points for the initial frame (`set` = `plane`).
    pub plane: Observations,
}

/// Sorts a measurement file's rows by their `set` column (see [`SplitData`]). Every row must have
/// a measured position, and every `set` label must be known ([`MeasurementSet::set_labels`]).
pub fn split_measurements(set: &MeasurementSet) -> Result<SplitData> {
    let mk = || Observations::with_source(set.dof(), &set.path);
    let mut out = SplitData {
        calibration: mk(),
        validation: mk(),
        plane: mk(),
    };
    let labels = set.set_labels()?;
    let extras = ExtrasLayout::of(set)?;
    for (r, label) in set.rows.iter().zip(labels) {
        let Some(p) = r.p else {
            return Err(Error::parse(
                &set.path,
                Some(r.line),
                Some("x"),
                "no measured position (x,y,z) in this row",
            ));
        };
        let target = match label {
            SetLabel::Plane => &mut out.plane,
            SetLabel::Validation => &mut out.validation,
            SetLabel::Calibration => &mut out.calibration,
        };
        target.push_with(&r.q, p, extras.read(set, r)?, r.line)?;
    }
    Ok(out)
}
