//! A measurement set as the CLI writes it: the library's own CSV text
//! (`io::measurements_csv`), read back into numbers with the parse the CLI's reader uses
//! (`str::parse::<f64>`). Arrays built this way hold exactly the values a later `robocal`
//! command reads from the CLI's file, so a Python session and a CLI session agree to the bit.

use crate::errors::raise;
use pyo3::prelude::*;
use robocal_core::io::measurements::measurements_csv;
use robocal_core::io::MeasurementSet;

/// The values of a written measurement set, column by column.
pub struct Written {
    /// Rows.
    pub rows: usize,
    /// Joint values in interface units (degrees, mm for a prismatic joint), row-major.
    pub q: Vec<f64>,
    /// Tracker readings x, y, z (mm), row-major, when the set has positions.
    pub xyz: Option<Vec<f64>>,
    /// The further columns (`id`, `set`, `target`, `a,b,c`, a joint file's own), by name, each
    /// one string per row.
    pub extra: Vec<(String, Vec<String>)>,
}

impl Written {
    /// The column named `name` of the further columns.
    pub fn column(&self, name: &str) -> Option<&[String]> {
        self.extra
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The numbers of further column `name` (`None` when there is no such column).
    pub fn numbers(&self, name: &str) -> PyResult<Option<Vec<f64>>> {
        self.column(name)
            .map(|v| v.iter().map(|s| number(s, name)).collect())
            .transpose()
    }
}

/// `s` as the CLI's reader parses a number.
fn number(s: &str, column: &str) -> PyResult<f64> {
    s.parse::<f64>().map_err(|_| {
        raise(
            1,
            format!("internal: column {column}: `{s}` written by robocal does not read back"),
        )
    })
}

/// The CSV text `robocal` writes for `set`.
pub fn csv_bytes(set: &MeasurementSet) -> PyResult<Vec<u8>> {
    measurements_csv(set)
        .map_err(|e| raise(1, format!("internal: cannot format the measurements: {e}")))
}

/// `set` as the CLI writes it, and its values read back.
pub fn written(set: &MeasurementSet) -> PyResult<Written> {
    read_back(&csv_bytes(set)?, set.dof(), set.has_positions())
}

/// The values of CSV text `csv` written by robocal for a set of `dof` joints, with x,y,z
/// columns when `with_p`.
pub fn read_back(csv: &[u8], dof: usize, with_p: bool) -> PyResult<Written> {
    let fixed = dof + if with_p { 3 } else { 0 };
    let mut reader = csv::ReaderBuilder::new().has_headers(true).from_reader(csv);
    let headers: Vec<String> = reader
        .headers()
        .map_err(|e| raise(1, format!("internal: {e}")))?
        .iter()
        .map(str::to_owned)
        .collect();
    let mut q = Vec::new();
    let mut xyz = Vec::new();
    let mut extra: Vec<(String, Vec<String>)> = headers[fixed..]
        .iter()
        .map(|h| (h.clone(), Vec::new()))
        .collect();
    let mut rows = 0;
    for record in reader.records() {
        let r = record.map_err(|e| raise(1, format!("internal: {e}")))?;
        for k in 0..dof {
            q.push(number(&r[k], &headers[k])?);
        }
        for k in dof..fixed {
            xyz.push(number(&r[k], &headers[k])?);
        }
        for (k, (_, col)) in extra.iter_mut().enumerate() {
            col.push(r[fixed + k].to_owned());
        }
        rows += 1;
    }
    Ok(Written {
        rows,
        q,
        xyz: with_p.then_some(xyz),
        extra,
    })
}
