//! The rows of a measurement file sorted by their role (`set` column): calibration, validation
//! and the paper's plane points.

use crate::error::{Error, Result};
use crate::io::measurements::MeasurementReader;
use crate::io::row_extras::ExtrasLayout;
use crate::io::set_label::Labeler;
use crate::io::{Measurement, MeasurementSet, SetLabel};
use crate::observations::Observations;
use std::io::Read;

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
    let labels = set.set_labels()?;
    let mut split = Splitter::new(set)?;
    for (r, label) in set.rows.iter().zip(labels) {
        split.push(set, r, label)?;
    }
    Ok(split.out)
}

/// Reads a measurement file row by row into its [`SplitData`], as [`split_measurements`] of
/// [`MeasurementReader::read_all`] would, without holding the file's rows: a million rows take
/// the memory of their observations only (about 80 bytes each), not of the text rows as well.
/// `each_row` sees every row as it is read (a check of its joints, say). Returns the split and
/// the reader's warnings ([`MeasurementReader::finish`]).
pub fn read_split<R: Read>(
    mut reader: MeasurementReader<R>,
    mut each_row: impl FnMut(&Measurement),
) -> Result<(SplitData, Vec<String>)> {
    let header = reader.header();
    let mut split = Splitter::new(&header)?;
    let mut labeler = Labeler::new(&header.extra_columns);
    let mut r = Measurement {
        line: 0,
        q: Vec::new(),
        p: None,
        extra: Vec::new(),
    };
    while reader.next_row_into(&mut r)? {
        each_row(&r);
        if let Some(label) = labeler.label(r.line, &r.extra) {
            split.push(&header, &r, label)?;
        }
    }
    labeler.finish(&header.path)?;
    let warnings = reader.finish()?;
    Ok((split.out, warnings))
}

/// The split being built: the extra columns' layout and the three sets.
struct Splitter {
    extras: ExtrasLayout,
    out: SplitData,
}

impl Splitter {
    fn new(header: &MeasurementSet) -> Result<Splitter> {
        let mk = || Observations::with_source(header.dof(), &header.path);
        Ok(Splitter {
            extras: ExtrasLayout::of(header)?,
            out: SplitData {
                calibration: mk(),
                validation: mk(),
                plane: mk(),
            },
        })
    }

    /// Adds row `r` of the file `header` describes to the set `label` names.
    fn push(&mut self, header: &MeasurementSet, r: &Measurement, label: SetLabel) -> Result<()> {
        let Some(p) = r.p else {
            return Err(Error::parse(
                &header.path,
                Some(r.line),
                Some("x"),
                "no measured position (x,y,z) in this row",
            ));
        };
        let target = match label {
            SetLabel::Plane => &mut self.out.plane,
            SetLabel::Validation => &mut self.out.validation,
            SetLabel::Calibration => &mut self.out.calibration,
        };
        target.push_with(&r.q, p, self.extras.read(header, r)?, r.line)
    }
}
