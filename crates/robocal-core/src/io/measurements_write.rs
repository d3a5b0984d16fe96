//! Writing measurement (or joint) CSV files: the text [`read_measurements`] reads back, written
//! atomically.
//!
//! [`read_measurements`]: crate::io::measurements::read_measurements

use crate::error::{Error, Result};
use crate::io::columns::joint_column;
use crate::io::measurements::MeasurementSet;
use std::path::Path;

/// Writes a measurement (or joint) CSV atomically: `q1..qn` (model joint values: degrees, or mm
/// for a prismatic joint), then `x,y,z` in mm if every row has a position, then the extra
/// columns.
pub fn write_measurements(path: &Path, set: &MeasurementSet) -> Result<()> {
    let bytes = measurements_csv(set).map_err(|e| Error::Io {
        path: path.to_owned(),
        source: e,
    })?;
    crate::io::atomic::write_atomic(path, &bytes)
}

/// The CSV text [`write_measurements`] writes (`q` with 9 decimals of a degree or mm, `x,y,z`
/// with 6 decimals of a millimetre), for callers that write several files together
/// ([`crate::io::write_all_atomic`]).
pub fn measurements_csv(set: &MeasurementSet) -> std::io::Result<Vec<u8>> {
    let with_p = set.has_positions();
    let mut header: Vec<String> = (0..set.dof()).map(joint_column).collect();
    if with_p {
        header.extend(["x", "y", "z"].map(String::from));
    }
    header.extend(set.extra_columns.iter().cloned());
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record(&header).map_err(std::io::Error::other)?;
    let mut fields = Vec::with_capacity(header.len());
    for r in &set.rows {
        fields.clear();
        fields.extend(
            r.q.iter()
                .enumerate()
                .map(|(i, v)| format!("{:.9}", set.joints.to_display(i, *v))),
        );
        if let (true, Some(p)) = (with_p, r.p) {
            fields.extend([p.x, p.y, p.z].iter().map(|v| format!("{v:.6}")));
        }
        fields.extend(r.extra.iter().cloned());
        w.write_record(&fields).map_err(std::io::Error::other)?;
    }
    w.into_inner()
        .map_err(|e| std::io::Error::other(e.to_string()))
}
