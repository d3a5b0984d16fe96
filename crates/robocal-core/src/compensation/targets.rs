//! Target files for `robocal compensate --targets`: a header row, columns `x,y,z` (mm, robot base
//! frame = ACS), optionally `a,b,c` (deg: the tool frame's orientation as A, B, C of a frame
//! vector, `Rz(A) Ry(B) Rx(C)`; all three or none) and, optionally, `q1..qn` (degrees, mm for a
//! prismatic joint) or the controller's `axis1..axisN`, a start configuration for the solve.
//! Other columns are carried through. Every rejection names the file, the line and the column.

use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use crate::io::columns::{csv_reader, next_record, ColumnLayout};
use crate::model::JointSpace;
use crate::ranges;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// The orientation columns of a target file (deg).
pub const ORIENTATION_COLUMNS: [&str; 3] = ["a", "b", "c"];

/// One target.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// 1-based line in the file.
    pub line: usize,
    /// The target point (mm, base frame).
    pub p: Vector3<f64>,
    /// The target orientation as A, B, C (rad), when the file has `a,b,c`.
    pub abc: Option<[f64; 3]>,
    /// Start configuration (model joint values, internal units), when the file has `q1..qn` or
    /// `axis1..axisN`.
    pub seed: Option<Vec<f64>>,
    /// Values of the extra columns, in [`TargetSet::extra_columns`] order.
    pub extra: Vec<String>,
}

impl Target {
    /// The target frame (base frame) when the target has an orientation.
    pub fn frame(&self) -> Option<Frame> {
        self.abc
            .map(|[a, b, c]| frame::pose(&[self.p.x, self.p.y, self.p.z, a, b, c]))
    }
}

/// A target file.
#[derive(Debug, Clone, PartialEq)]
pub struct TargetSet {
    /// The file it was read from.
    pub path: PathBuf,
    /// Whether the targets have orientations (`a,b,c`).
    pub has_orientation: bool,
    /// Names of the columns other than `x,y,z`, `a,b,c` and the joint columns.
    pub extra_columns: Vec<String>,
    /// The targets, in file order.
    pub rows: Vec<Target>,
}

/// Reads a target file for a robot with the joints `joints` (`Robot::joint_space`).
pub fn read_targets(path: &Path, joints: &JointSpace) -> Result<TargetSet> {
    let file = crate::io::input::open_input(path)?;
    parse_targets(std::io::BufReader::new(file), path, joints)
}

/// Parses target CSV text from any reader; `path` is used in messages.
pub fn parse_targets<R: std::io::Read>(
    reader: R,
    path: &Path,
    joints: &JointSpace,
) -> Result<TargetSet> {
    let dof = joints.dof();
    let perr = |line: Option<usize>, field: Option<&str>, msg: String| {
        Error::parse(path, line, field, msg)
    };
    let mut rdr = csv_reader(reader);
    let mut layout = ColumnLayout::read(
        &mut rdr,
        path,
        dof,
        true,
        "x,y,z (and optionally a,b,c and q1..qn)",
    )?;
    // a,b,c: all three or none; taken out of the extra columns.
    let abc_at = ORIENTATION_COLUMNS.map(|n| layout.extra_columns.iter().position(|c| c == n));
    let abc_cols = if abc_at.iter().all(Option::is_none) {
        None
    } else if let Some(m) = abc_at.iter().position(Option::is_none) {
        return Err(perr(
            Some(1),
            Some(ORIENTATION_COLUMNS[m]),
            "missing column: an orientation needs all of a,b,c (deg), or none of them for \
             position-only targets"
                .into(),
        ));
    } else {
        let cols = abc_at.map(|k| layout.extra[k.expect("all present")]);
        let keep: Vec<usize> = (0..layout.extra.len())
            .filter(|k| !abc_at.contains(&Some(*k)))
            .collect();
        layout.extra = keep.iter().map(|&k| layout.extra[k]).collect();
        layout.extra_columns = keep
            .iter()
            .map(|&k| layout.extra_columns[k].clone())
            .collect();
        Some(cols)
    };
    let [Some(x), Some(y), Some(z)] = layout.xyz else {
        let a = layout.xyz.iter().position(Option::is_none).unwrap_or(0);
        return Err(perr(
            Some(1),
            Some(["x", "y", "z"][a]),
            "missing column (targets need x,y,z in mm, robot base frame)".into(),
        ));
    };
    let q_cols = layout.joint_columns(path).map_err(|e| match e {
        Error::Parse { field, .. } => perr(
            Some(1),
            field.as_deref(),
            format!(
                "missing column: a start configuration needs all of q1..q{dof} (or \
                 axis1..axis{dof})"
            ),
        ),
        other => other,
    })?;
    let mut rows = Vec::new();
    let mut rec = csv::StringRecord::new();
    while let Some(line) = next_record(&mut rdr, &mut rec, path)? {
        let num = |k: usize, range, what| layout.number_in(&rec, k, path, line, range, what);
        let pos = |k| num(k, &ranges::LENGTH, "not a plausible target");
        let p = Vector3::new(pos(x)?, pos(y)?, pos(z)?);
        let abc = match abc_cols {
            Some(c) => {
                let ang =
                    |k| num(k, &ranges::ANGLE, "not a plausible orientation").map(f64::to_radians);
                Some([ang(c[0])?, ang(c[1])?, ang(c[2])?])
            }
            None => None,
        };
        let seed = match &q_cols {
            Some(c) => Some(layout.joint_values(&rec, c, joints, path, line)?.0),
            None => None,
        };
        rows.push(Target {
            line,
            p,
            abc,
            seed,
            extra: layout.extra_values(&rec),
        });
    }
    if rows.is_empty() {
        return Err(perr(None, None, "no data rows after the header".into()));
    }
    Ok(TargetSet {
        path: path.to_owned(),
        has_orientation: abc_cols.is_some(),
        extra_columns: layout.extra_columns,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<TargetSet> {
        parse_targets(s.as_bytes(), Path::new("t.csv"), &JointSpace::revolute(2))
    }

    #[test]
    fn reads_targets_with_and_without_seeds() {
        let t = parse("id,x,y,z\na,1,2,3\n").unwrap();
        assert_eq!(t.rows[0].p, Vector3::new(1.0, 2.0, 3.0));
        assert_eq!(t.rows[0].seed, None);
        assert_eq!(t.extra_columns, vec!["id"]);
        let t = parse("x,y,z,q1,q2\n1,2,3,90,-45\n").unwrap();
        let s = t.rows[0].seed.as_ref().unwrap();
        assert!((s[0] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(t.rows[0].line, 2);
        assert!(!t.has_orientation && t.rows[0].frame().is_none());
        // Orientation columns anywhere, carried columns kept in order.
        let t = parse("c,id,x,y,z,b,a,note\n30,p1,1,2,3,20,10,n\n").unwrap();
        assert!(t.has_orientation);
        assert_eq!(t.extra_columns, vec!["id", "note"]);
        assert_eq!(t.rows[0].extra, vec!["p1", "n"]);
        let [a, b, c] = t.rows[0].abc.unwrap();
        assert!((a.to_degrees() - 10.0).abs() < 1e-12);
        assert!((b.to_degrees() - 20.0).abs() < 1e-12);
        assert!((c.to_degrees() - 30.0).abs() < 1e-12);
        let f = t.rows[0].frame().unwrap();
        assert_eq!(f.translation.vector, Vector3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn rejections_name_line_and_column() {
        let e = parse("x,y\n1,2\n").unwrap_err().to_string();
        assert!(e.contains("t.csv:1: field `z`: missing column"), "{e}");
        let e = parse("x,y,z,q1\n1,2,3,4\n").unwrap_err().to_string();
        assert!(e.contains("field `q2`: missing column"), "{e}");
        let e = parse("x,y,z\n1,2,3\n1,inf,3\n").unwrap_err().to_string();
        assert!(
            e.contains("t.csv:3: field `y`") && e.contains("finite"),
            "{e}"
        );
        let e = parse("x,y,z,q3\n1,2,3,4\n").unwrap_err().to_string();
        assert!(e.contains("field `q3`") && e.contains("2 joints"), "{e}");
        let e = parse("x,y,z\n").unwrap_err().to_string();
        assert!(e.contains("no data rows"), "{e}");
        let e = parse("x,y,z\n1,2\n").unwrap_err().to_string();
        assert!(e.contains("t.csv:2") && e.contains("2 fields"), "{e}");
        let e = parse("x,y,z\n1,2,3\n-2e6,2,3\n").unwrap_err().to_string();
        assert!(
            e.contains("t.csv:3: field `x`: not a plausible target: -2000000 mm is out of range"),
            "{e}"
        );
        let e = parse("x,y,z,a,c\n1,2,3,4,5\n").unwrap_err().to_string();
        assert!(
            e.contains("t.csv:1: field `b`: missing column: an orientation needs all of a,b,c"),
            "{e}"
        );
        let e = parse("x,y,z,a,b,c\n1,2,3,4,5,6\n1,2,3,4,x,6\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.csv:3: field `b`"), "{e}");
        let e = parse("x,y,z,q1,q2\n1,2,3,4,1e300\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("t.csv:2: field `q2`: not a plausible joint value: 1e300 deg"),
            "{e}"
        );
    }
}
