//! The optional `set` column of a measurement file: the role of each row. Every reader that sorts
//! rows by their set uses [`SetLabel`] and [`MeasurementSet::set_labels`], so a label is spelled
//! and checked in one place, and a misspelt one (`validaton`) is an error instead of a row that
//! silently becomes calibration data.

use crate::error::{Error, Result};
use crate::io::MeasurementSet;

/// The name of the column (matched without regard to ASCII case).
pub const SET_COLUMN: &str = "set";

/// The role of a measured row.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SetLabel {
    /// One of the paper's three points on a plane parallel to the base plane, for the initial
    /// measurement frame (section II.C).
    Plane,
    /// A calibration point.
    Calibration,
    /// A validation point: evaluated, never fitted.
    Validation,
}

impl SetLabel {
    /// Every label.
    pub const ALL: [SetLabel; 3] = [SetLabel::Plane, SetLabel::Calibration, SetLabel::Validation];

    /// The label as robocal writes it: `plane`, `calibration`, `validation`.
    pub const fn as_str(self) -> &'static str {
        match self {
            SetLabel::Plane => "plane",
            SetLabel::Calibration => "calibration",
            SetLabel::Validation => "validation",
        }
    }

    /// The label of a `set` cell: one of [`SetLabel::as_str`] or `val` (for validation), without
    /// regard to ASCII case or surrounding spaces; an empty cell is a calibration point. `None`
    /// for anything else.
    pub fn of_cell(cell: &str) -> Option<SetLabel> {
        let c = cell.trim();
        if c.is_empty() {
            return Some(SetLabel::Calibration);
        }
        if c.eq_ignore_ascii_case("val") {
            return Some(SetLabel::Validation);
        }
        SetLabel::ALL
            .into_iter()
            .find(|l| c.eq_ignore_ascii_case(l.as_str()))
    }

    /// The accepted spellings, for messages and documentation.
    pub const ACCEPTED: &'static str =
        "plane, calibration, validation (or val), in any case; an empty cell is a calibration point";
}

impl std::fmt::Display for SetLabel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The position of the `set` column among `extra_columns`, if there is one.
pub fn set_column(extra_columns: &[String]) -> Option<usize> {
    extra_columns
        .iter()
        .position(|c| c.eq_ignore_ascii_case(SET_COLUMN))
}

impl MeasurementSet {
    /// The [`SetLabel`] of every row, in row order: from the `set` column, or
    /// [`SetLabel::Calibration`] for every row of a file without one. Fails on the first row
    /// whose label is not one of [`SetLabel::ACCEPTED`], naming the file, its line, the column
    /// and the labels that exist, and counting the rows with unknown labels.
    pub fn set_labels(&self) -> Result<Vec<SetLabel>> {
        let mut labeler = Labeler::new(&self.extra_columns);
        let labels = self
            .rows
            .iter()
            .filter_map(|r| labeler.label(r.line, &r.extra))
            .collect();
        labeler.finish(&self.path)?;
        Ok(labels)
    }
}

/// Labels a file's rows one at a time, as they are read ([`MeasurementSet::set_labels`] for
/// rows already in memory): remembers the first unknown label and counts them, so that
/// [`Labeler::finish`] fails as `set_labels` does.
#[derive(Debug, Clone)]
pub struct Labeler {
    /// The `set` column among the extra columns, and its name.
    column: Option<(usize, String)>,
    /// The line and the cell of the first unknown label.
    first_bad: Option<(usize, String)>,
    /// How many rows have an unknown label.
    bad: usize,
}

impl Labeler {
    /// A labeler for a file whose extra columns are `extra_columns`.
    pub fn new(extra_columns: &[String]) -> Labeler {
        Labeler {
            column: set_column(extra_columns).map(|k| (k, extra_columns[k].clone())),
            first_bad: None,
            bad: 0,
        }
    }

    /// The label of the row at `line` with the extra values `extra`; `None` (remembered for
    /// [`Labeler::finish`]) when it is not one of [`SetLabel::ACCEPTED`].
    pub fn label(&mut self, line: usize, extra: &[String]) -> Option<SetLabel> {
        let Some((k, _)) = &self.column else {
            return Some(SetLabel::Calibration);
        };
        let cell = &extra[*k];
        let l = SetLabel::of_cell(cell);
        if l.is_none() {
            self.bad += 1;
            self.first_bad
                .get_or_insert_with(|| (line, cell.trim().to_owned()));
        }
        l
    }

    /// Fails when some row had an unknown label, naming the first (file `path`, its line, the
    /// column) and counting the others.
    pub fn finish(self, path: &std::path::Path) -> Result<()> {
        let (Some((line, cell)), Some((_, column))) = (self.first_bad, self.column) else {
            return Ok(());
        };
        let others = match self.bad {
            1 => String::new(),
            n => format!(" ({n} rows of this file have an unknown set)"),
        };
        Err(Error::parse(
            path,
            Some(line),
            Some(&column),
            format!(
                "unknown set `{cell}`{others}: the sets are {}",
                SetLabel::ACCEPTED
            ),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{parse_measurements, Positions};
    use std::path::Path;

    fn labels(csv: &str) -> Result<Vec<SetLabel>> {
        parse_measurements(
            csv.as_bytes(),
            Path::new("m.csv"),
            &crate::model::JointSpace::revolute(1),
            Positions::Required,
        )
        .unwrap()
        .set_labels()
    }

    #[test]
    fn accepted_spellings() {
        use SetLabel::*;
        let l = labels("q1,x,y,z,SET\n1,0,0,0,plane\n2,0,0,0, Validation \n3,0,0,0,val\n4,0,0,0,\n5,0,0,0,CALIBRATION\n")
            .unwrap();
        assert_eq!(l, [Plane, Validation, Validation, Calibration, Calibration]);
        assert_eq!(labels("q1,x,y,z\n1,0,0,0\n").unwrap(), [Calibration]);
        for l in SetLabel::ALL {
            assert_eq!(SetLabel::of_cell(l.as_str()), Some(l));
        }
    }

    #[test]
    fn unknown_labels_name_file_line_column_and_the_labels() {
        let e = labels("q1,x,y,z,set\n1,0,0,0,plane\n2,0,0,0,validaton\n3,0,0,0,plain\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("m.csv:3: field `set`: unknown set `validaton` (2 rows of this file have an unknown set): the sets are plane, calibration, validation (or val)"),
            "{e}"
        );
        let e = labels("q1,x,y,z,Set\n1,0,0,0,cal\n")
            .unwrap_err()
            .to_string();
        assert!(
            // Header names robocal knows are read in any case and named in lower case.
            e.starts_with("m.csv:2: field `set`: unknown set `cal`: "),
            "{e}"
        );
    }
}
