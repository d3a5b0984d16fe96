//! Leica tracker software CSV (e.g. with a T-Mac probe): `X  [mm],Y  [mm],Z  [mm],U(95)  [mm],
//! U(95) X/Y/Z [mm],Tilt [deg],Q0,Q1,Q2,Q3,Image RMS [µm],Target,Temperature [C],Pressure [mBar],
//! Humidity [%],Time Stamp,OTG Applied,Delete`. Read: X, Y, Z (unit from the header), U(95)
//! as `sigma_mm` (divided by [`super::points::U95_PER_SIGMA`]), Q0..Q3 (scalar first) as a,b,c,
//! Temperature (C or F), Time Stamp (day first, leading apostrophe), a point-name column when
//! there is one, and Delete: rows marked deleted in the tracker software are left out and
//! listed. Other columns are listed as ignored.

use super::headed::{Col, Naming, NAME_COLUMNS};
use super::lines::LineReader;
use super::points::PointTable;
use super::{ImportConfig, PointsFormat};
use crate::error::Result;
use std::io::BufRead;

/// The column a Leica header name stands for.
pub fn classify(name: &str) -> Option<Col> {
    Some(match name {
        "x" => Col::Pos(0),
        "y" => Col::Pos(1),
        "z" => Col::Pos(2),
        "u(95)" => Col::U95,
        "q0" => Col::Quat(0),
        "q1" => Col::Quat(1),
        "q2" => Col::Quat(2),
        "q3" => Col::Quat(3),
        "temperature" => Col::Temperature,
        "time stamp" | "timestamp" => Col::Time,
        "delete" => Col::Deleted,
        n if NAME_COLUMNS.contains(&n) => Col::Name,
        _ => return None,
    })
}

/// Whether a header line looks like a Leica export (`U(95)` or `Time Stamp` beside X, Y, Z).
pub fn looks_like(header: &str) -> bool {
    let h = header.to_ascii_lowercase();
    (h.contains("u(95)") || h.contains("time stamp")) && h.contains("x ")
}

/// Reads a Leica export.
pub fn read<R: BufRead>(lines: &mut LineReader<R>, config: &ImportConfig) -> Result<PointTable> {
    super::headed::read(
        lines,
        &Naming {
            format: PointsFormat::Leica,
            classify,
            default_unit: None,
        },
        config,
    )
}

#[cfg(test)]
mod tests {
    use super::super::{parse_points, ImportConfig, MatchBy};
    use std::path::Path;

    const HEADER: &str = "X  [mm],Y  [mm],Z  [mm],U(95)  [mm],Temperature [C],Time Stamp,Delete\n";

    /// Rows marked deleted in the tracker software are left out and their lines kept; a mark
    /// that is neither yes nor no is an error naming the line and the column.
    #[test]
    fn rows_marked_deleted_are_left_out_and_listed() {
        let text = format!(
            "{HEADER}1.0,2.0,3.0,0.028,20.1,'11.10.2022 15:06:48.043,0\n\
             9.0,9.0,9.0,0.028,20.1,'11.10.2022 15:06:50.000,1\n\
             4.0,5.0,6.0,0.028,20.2,'11.10.2022 15:06:52.000,\n\
             7.0,8.0,9.0,0.028,20.2,'11.10.2022 15:06:54.000,TRUE\n"
        );
        let cfg = ImportConfig::new(MatchBy::Order);
        let t = parse_points(text.as_bytes(), Path::new("e.csv"), &cfg).unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[1].p, [4.0, 5.0, 6.0]);
        assert_eq!(t.deleted_lines, [3, 5]);
        let bad = format!("{HEADER}1.0,2.0,3.0,0.028,20.1,'11.10.2022 15:06:48.043,maybe\n");
        let e = parse_points(bad.as_bytes(), Path::new("e.csv"), &cfg)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("e.csv:2") && e.contains("Delete") && e.contains("maybe"),
            "{e}"
        );
    }
}
