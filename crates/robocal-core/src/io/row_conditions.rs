//! The columns of a real cell's conditions in a measurement file (DESIGN.md, "Measurement CSV
//! additions (real cells)"), read from the rows' extra columns: `temperature_c` (the arm's
//! temperature, deg C) and `dir1..dirN` (each joint's approach direction, +1 or -1; an empty cell
//! is unknown). `time_s` is carried but not read. Each cell is checked, naming the file, line and
//! column.

use crate::error::{Error, Result};
use crate::io::{Measurement, MeasurementSet};
use crate::kinematics::Conditions;
use crate::model::MAX_JOINTS;

/// The temperature column.
pub const TEMPERATURE_COLUMN: &str = "temperature_c";
/// The session time column (seconds since the session started).
pub const TIME_COLUMN: &str = "time_s";
/// The plausible temperatures of a working robot (deg C).
pub const TEMPERATURE_RANGE_C: (f64, f64) = (-50.0, 150.0);

/// The approach direction column of joint `j` (0-based): `dir1..dirN`.
pub fn direction_column(j: usize) -> String {
    format!("dir{}", j + 1)
}

/// Where a file's extra columns hold the conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ConditionsLayout {
    temperature: Option<usize>,
    /// The `dir{j}` column of each joint (valid when `has_dir`).
    dir: [usize; MAX_JOINTS],
    has_dir: bool,
}

impl ConditionsLayout {
    /// Finds the columns in `set`'s extra columns; a file with some but not all of
    /// `dir1..dirN` is rejected.
    pub fn of(set: &MeasurementSet) -> Result<ConditionsLayout> {
        let find = |name: &str| set.extra_columns.iter().position(|c| c == name);
        let n = set.dof().min(MAX_JOINTS);
        let found: Vec<Option<usize>> = (0..n).map(|j| find(&direction_column(j))).collect();
        let mut out = ConditionsLayout {
            temperature: find(TEMPERATURE_COLUMN),
            ..ConditionsLayout::default()
        };
        if found.iter().any(Option::is_some) {
            if let Some(j) = found.iter().position(Option::is_none) {
                return Err(Error::parse(
                    &set.path,
                    Some(1),
                    Some(&direction_column(j)),
                    format!("missing column (approach directions need dir1..dir{n})"),
                ));
            }
            for (j, k) in found.iter().enumerate() {
                out.dir[j] = k.unwrap_or(0);
            }
            out.has_dir = true;
        }
        Ok(out)
    }

    /// Whether the file has any condition column.
    pub fn is_empty(&self) -> bool {
        self.temperature.is_none() && !self.has_dir
    }

    /// Whether the file has a temperature column.
    pub fn has_temperature(&self) -> bool {
        self.temperature.is_some()
    }

    /// Whether the file has approach directions.
    pub fn has_directions(&self) -> bool {
        self.has_dir
    }

    /// One row's conditions (`None` when the file has no condition column).
    pub fn read(&self, set: &MeasurementSet, row: &Measurement) -> Result<Option<Conditions>> {
        if self.is_empty() {
            return Ok(None);
        }
        let bad =
            |name: &str, msg: String| Error::parse(&set.path, Some(row.line), Some(name), msg);
        let mut c = Conditions::UNKNOWN;
        if let Some(k) = self.temperature {
            let s = row.extra[k].trim();
            if !s.is_empty() {
                let (lo, hi) = TEMPERATURE_RANGE_C;
                let v: f64 = s
                    .parse()
                    .map_err(|_| bad(TEMPERATURE_COLUMN, format!("`{s}` is not a number")))?;
                if !(v.is_finite() && (lo..=hi).contains(&v)) {
                    return Err(bad(
                        TEMPERATURE_COLUMN,
                        format!("{s} is not a robot's temperature within {lo}..{hi} deg C"),
                    ));
                }
                c.temperature_c = v;
            }
        }
        if self.has_dir {
            for j in 0..set.dof().min(MAX_JOINTS) {
                let s = row.extra[self.dir[j]].trim();
                c.dir[j] = match s {
                    "" => 0,
                    "1" | "+1" => 1,
                    "-1" => -1,
                    _ => {
                        return Err(bad(
                            &direction_column(j),
                            format!("`{s}` is not a direction (+1 or -1, empty when unknown)"),
                        ))
                    }
                };
            }
        }
        Ok(Some(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::measurements::{parse_measurements, Positions};
    use crate::preset;

    fn set(text: &str) -> MeasurementSet {
        let r = preset("kuka-kr480-r3330").unwrap();
        parse_measurements(
            text.as_bytes(),
            std::path::Path::new("m.csv"),
            r.joint_space(),
            Positions::Required,
        )
        .unwrap()
    }

    #[test]
    fn reads_temperature_and_directions_and_names_bad_cells() {
        let h = "q1,q2,q3,q4,q5,q6,x,y,z,temperature_c,time_s,dir1,dir2,dir3,dir4,dir5,dir6";
        let s = set(&format!("{h}\n0,0,0,0,0,0,1,2,3,21.5,0,1,-1,+1,,1,-1\n"));
        let l = ConditionsLayout::of(&s).unwrap();
        assert!(l.has_temperature() && l.has_directions());
        let c = l.read(&s, &s.rows[0]).unwrap().unwrap();
        assert_eq!(c.temperature_c, 21.5);
        assert_eq!(&c.dir[..6], &[1, -1, 1, 0, 1, -1]);
        let s = set(&format!("{h}\n0,0,0,0,0,0,1,2,3,21.5,0,1,-1,2,1,1,1\n"));
        let e = ConditionsLayout::of(&s)
            .unwrap()
            .read(&s, &s.rows[0])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.csv") && e.contains("dir3") && e.contains('2'),
            "{e}"
        );
        let s = set(&format!("{h}\n0,0,0,0,0,0,1,2,3,2150,0,1,1,1,1,1,1\n"));
        let e = ConditionsLayout::of(&s)
            .unwrap()
            .read(&s, &s.rows[0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("temperature_c"), "{e}");
        let s = set("q1,q2,q3,q4,q5,q6,x,y,z,dir1\n0,0,0,0,0,0,1,2,3,1\n");
        let e = ConditionsLayout::of(&s).unwrap_err().to_string();
        assert!(e.contains("dir2"), "{e}");
        let s = set("q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,1,2,3\n");
        let l = ConditionsLayout::of(&s).unwrap();
        assert!(l.is_empty());
        assert_eq!(l.read(&s, &s.rows[0]).unwrap(), None);
    }
}
