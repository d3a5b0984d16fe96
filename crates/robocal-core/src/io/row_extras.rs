//! The columns a real cell adds to a measurement file (DESIGN.md, "Measurement CSV additions"),
//! read from the rows' extra columns so that every reader and writer keeps carrying them:
//! `target` (which reflector, 1..k), `a,b,c` (the measured frame's orientation in the tracker
//! frame, degrees, ABC as in frame vectors: a 6-DoF measurement) and `sigma_mm` (the point's
//! 1-sigma uncertainty per axis). Each cell is checked, naming the file, line and column.

use crate::error::{Error, Result};
use crate::frame::pose;
use crate::io::{Measurement, MeasurementSet};
use crate::observations::{RowExtras, MAX_TARGETS};

/// The target column.
pub const TARGET_COLUMN: &str = "target";
/// The uncertainty column.
pub const SIGMA_COLUMN: &str = "sigma_mm";
/// The orientation columns.
pub const ORIENTATION_COLUMNS: [&str; 3] = ["a", "b", "c"];

/// Where a file's extra columns hold the additions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ExtrasLayout {
    target: Option<usize>,
    abc: Option<[usize; 3]>,
    sigma: Option<usize>,
    conditions: super::row_conditions::ConditionsLayout,
}

impl ExtrasLayout {
    /// Finds the columns in `set`'s extra columns; a file with some but not all of `a,b,c` is
    /// rejected.
    pub fn of(set: &MeasurementSet) -> Result<ExtrasLayout> {
        let find = |name: &str| set.extra_columns.iter().position(|c| c == name);
        let abc = ORIENTATION_COLUMNS.map(find);
        let abc = match abc {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            [None, None, None] => None,
            _ => {
                let k = abc.iter().position(Option::is_none).unwrap_or(0);
                return Err(Error::parse(
                    &set.path,
                    Some(1),
                    Some(ORIENTATION_COLUMNS[k]),
                    "missing column (a 6-DoF measurement needs a,b,c in degrees)",
                ));
            }
        };
        Ok(ExtrasLayout {
            target: find(TARGET_COLUMN),
            abc,
            sigma: find(SIGMA_COLUMN),
            conditions: super::row_conditions::ConditionsLayout::of(set)?,
        })
    }

    /// Whether the file has a `target` column.
    pub fn has_target(&self) -> bool {
        self.target.is_some()
    }

    /// Whether the file holds 6-DoF measurements.
    pub fn has_orientation(&self) -> bool {
        self.abc.is_some()
    }

    /// One row's additions.
    pub fn read(&self, set: &MeasurementSet, row: &Measurement) -> Result<RowExtras> {
        let cell = |k: usize, name: &str| -> Result<f64> {
            let s = row.extra[k].trim();
            let v: f64 = s.parse().map_err(|_| {
                Error::parse(
                    &set.path,
                    Some(row.line),
                    Some(name),
                    format!("`{s}` is not a number"),
                )
            })?;
            if !v.is_finite() {
                return Err(Error::parse(
                    &set.path,
                    Some(row.line),
                    Some(name),
                    "not a finite number",
                ));
            }
            Ok(v)
        };
        let mut out = RowExtras::default();
        if let Some(k) = self.target {
            let s = row.extra[k].trim();
            let t: usize = s
                .parse()
                .ok()
                .filter(|t| (1..=MAX_TARGETS).contains(t))
                .ok_or_else(|| {
                    Error::parse(
                        &set.path,
                        Some(row.line),
                        Some(TARGET_COLUMN),
                        format!("`{s}` is not a target number (1 to {MAX_TARGETS})"),
                    )
                })?;
            out.target = t - 1;
        }
        if let Some(cols) = self.abc {
            let mut v = [0.0; 6];
            for (j, k) in cols.iter().enumerate() {
                let deg = cell(*k, ORIENTATION_COLUMNS[j])?;
                if deg.abs() > 720.0 {
                    return Err(Error::parse(
                        &set.path,
                        Some(row.line),
                        Some(ORIENTATION_COLUMNS[j]),
                        format!("{deg} degrees is not a plausible orientation angle"),
                    ));
                }
                v[3 + j] = deg.to_radians();
            }
            out.rotation = Some(*pose(&v).rotation.matrix());
        }
        if let Some(k) = self.sigma {
            let s = cell(k, SIGMA_COLUMN)?;
            if !(s > 0.0 && s <= 1e3) {
                return Err(Error::parse(
                    &set.path,
                    Some(row.line),
                    Some(SIGMA_COLUMN),
                    format!(
                        "{} is not a plausible uncertainty (mm, above 0 and at most 1000)",
                        if (1e-4..1e6).contains(&s.abs()) {
                            s.to_string()
                        } else {
                            format!("{s:e}")
                        }
                    ),
                ));
            }
            out.sigma_mm = Some(s);
        }
        out.conditions = self.conditions.read(set, row)?;
        Ok(out)
    }
}
