//! Which format a file is in, from its first non-empty line.

use super::{JointsFormat, PointsFormat};

/// The format of a tracker export whose first non-empty line is `line`: `//` comments are
/// SpatialAnalyzer's; `U(95)` or `Time Stamp` beside `X` is Leica's; `NAME;X;Y;Z` is xyz; three
/// numbers (or a name and three) are headerless text; three numbers after up to three names
/// separated by spaces are SA's; anything else is a CSV with a header.
pub fn points_format(line: &str) -> PointsFormat {
    let t = line.trim();
    if t.starts_with("//") {
        PointsFormat::Sa
    } else if super::leica::looks_like(t) {
        PointsFormat::Leica
    } else if super::xyz::looks_like(t) {
        PointsFormat::Xyz
    } else if super::text::looks_like(t) {
        PointsFormat::Text
    } else {
        let f: Vec<&str> = t.split_whitespace().collect();
        if (5..=6).contains(&f.len()) && f[f.len() - 3..].iter().all(|v| super::lines::is_number(v))
        {
            PointsFormat::Sa
        } else {
            PointsFormat::Csv
        }
    }
}

/// The format of a joint log whose first non-empty line is `line`.
pub fn joints_format(line: &str) -> JointsFormat {
    if super::rtde::looks_like(line) {
        JointsFormat::Rtde
    } else {
        JointsFormat::Csv
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_are_told_apart() {
        let leica = "X  [mm],Y  [mm],Z  [mm],U(95)  [mm],Q0,Q1,Q2,Q3,Time Stamp";
        assert_eq!(points_format(leica), PointsFormat::Leica);
        assert_eq!(points_format("// SA export"), PointsFormat::Sa);
        assert_eq!(points_format("Coll Grp P1 1.5 2 3"), PointsFormat::Sa);
        assert_eq!(
            points_format("P5;-274.556;-3189.212;-248.113;;;;"),
            PointsFormat::Xyz
        );
        assert_eq!(
            points_format("P5;-274,556;-3189,212;-248,113"),
            PointsFormat::Xyz
        );
        assert_eq!(points_format("1.5 2 3"), PointsFormat::Text);
        assert_eq!(points_format("1.5,2,3"), PointsFormat::Text);
        assert_eq!(points_format("id;X;Y;Z"), PointsFormat::Csv);
        assert_eq!(points_format("x,y,z"), PointsFormat::Csv);
        assert_eq!(
            joints_format("timestamp actual_q_0 actual_q_1"),
            JointsFormat::Rtde
        );
        assert_eq!(joints_format("A1,A2,A3"), JointsFormat::Csv);
    }
}
