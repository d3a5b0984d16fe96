//! The columns a real cell's session writes beside its readings (DESIGN.md, "Measurement CSV
//! additions (real cells)"): `temperature_c` and `time_s` with thermal growth, `dir1..dirN`
//! (each joint's approach direction) with backlash.

use super::cell::Readings;
use crate::error::Result;
use crate::io::measurements::MeasurementSet;
use crate::io::row_conditions::ConditionsLayout;

pub use crate::io::row_conditions::{direction_column, TEMPERATURE_COLUMN, TIME_COLUMN};

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

/// The approach directions a joint file gives (`dir1..dirN`, every cell +1 or -1), if it does.
pub(super) fn given_directions(set: &MeasurementSet) -> Result<Option<Vec<Vec<i8>>>> {
    let layout = ConditionsLayout::of(set)?;
    if !layout.has_directions() {
        return Ok(None);
    }
    let n = set.dof();
    let mut out = Vec::with_capacity(set.rows.len());
    for r in &set.rows {
        let Some(c) = layout.read(set, r)? else {
            return Ok(None);
        };
        if c.dir[..n].contains(&0) {
            return Ok(None);
        }
        out.push(c.dir[..n].to_vec());
    }
    Ok(Some(out))
}
