//! The columns a real cell's session writes beside its readings (DESIGN.md, "Measurement CSV
//! additions (real cells)"): `temperature_c` and `time_s` with thermal growth, `dir1..dirN`
//! (each joint's approach direction) with backlash.

use super::cell::Readings;
use crate::io::measurements::MeasurementSet;

/// The temperature column.
pub const TEMPERATURE_COLUMN: &str = "temperature_c";
/// The session time column.
pub const TIME_COLUMN: &str = "time_s";

/// The approach direction column of joint `j` (0-based): `dir1..dirN`.
pub fn direction_column(j: usize) -> String {
    format!("dir{}", j + 1)
}

/// Writes the session's conditions of `readings` (one per row of `set`, in order) into `set`'s
/// extra columns, replacing columns of the same names.
pub(super) fn write_conditions(set: &mut MeasurementSet, readings: &Readings) {
    if let Some(t) = &readings.thermal {
        put(set, TEMPERATURE_COLUMN, |r| format!("{:.4}", t[r].1));
        put(set, TIME_COLUMN, |r| format!("{}", t[r].0));
    }
    if let Some(d) = &readings.directions {
        for j in 0..set.dof() {
            put(set, &direction_column(j), |r| d[r][j].to_string());
        }
    }
}

fn put(set: &mut MeasurementSet, name: &str, value: impl Fn(usize) -> String) {
    let k = match set.extra_columns.iter().position(|c| c == name) {
        Some(k) => k,
        None => {
            set.extra_columns.push(name.to_owned());
            for r in &mut set.rows {
                r.extra.push(String::new());
            }
            set.extra_columns.len() - 1
        }
    };
    for (i, r) in set.rows.iter_mut().enumerate() {
        r.extra[k] = value(i);
    }
}
