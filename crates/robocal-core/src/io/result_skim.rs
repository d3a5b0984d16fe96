//! Reading back the whole text of a result robocal has just written
//! ([`super::result::CalibrationResult::write`], when the text without its per-point sections,
//! which it reads back first, does not pass: `io::result_deferred`) without building its
//! per-point sections again: `points` (an entry per calibration and
//! validation row, a million of them for a million rows) and `prediction.map`. There they are
//! only checked to be well-formed JSON, at a tenth of the cost of parsing every number.
//!
//! Nothing in them can make a reader refuse the file, which is what the read-back is for: their
//! errors and weights read a `null` (a NaN written) as NaN, and their line numbers are integers
//! the writer made. The one exception, a map point's position (not nullable), is checked in
//! memory by the writer instead ([`finite_map`]).

use super::result_prediction::PredictionSection;
use crate::error::{Error, Result};
use serde::de::{Deserialize, Deserializer, IgnoredAny};
use std::cell::Cell;

thread_local! {
    /// Whether this thread is reading back a result it wrote (see the module docs).
    static SKIMMING: Cell<bool> = const { Cell::new(false) };
}

/// Runs `read` with the per-point sections skimmed (see the module docs), as before afterwards.
pub(super) fn skimming<R>(read: impl FnOnce() -> R) -> R {
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            SKIMMING.with(|s| s.set(self.0));
        }
    }
    let _restore = Restore(SKIMMING.with(|s| s.replace(true)));
    read()
}

/// `d`'s value, or `skimmed` after checking it is JSON while [`skimming`].
fn value_or<'de, D, T>(d: D, skimmed: T) -> std::result::Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    if SKIMMING.with(Cell::get) {
        IgnoredAny::deserialize(d)?;
        Ok(skimmed)
    } else {
        T::deserialize(d)
    }
}

/// `deserialize_with` for an optional per-point section: `None` when skimmed.
pub(crate) fn option<'de, D, T>(d: D) -> std::result::Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    value_or(d, None)
}

/// `deserialize_with` for a per-point list: empty when skimmed.
pub(crate) fn list<'de, D, T>(d: D) -> std::result::Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    value_or(d, Vec::new())
}

/// What a reader of `prediction.map` would refuse and a skimmed read-back does not see: a
/// position that is not finite (written as `null`).
pub(super) fn finite_map(prediction: Option<&PredictionSection>) -> Result<()> {
    let Some(p) = prediction else { return Ok(()) };
    match p
        .map
        .iter()
        .position(|m| !(m.x.is_finite() && m.y.is_finite() && m.z.is_finite()))
    {
        None => Ok(()),
        Some(i) => Err(Error::Numerical(format!(
            "prediction.map[{i}]: the position ({}, {}, {}) is not finite",
            p.map[i].x, p.map[i].y, p.map[i].z
        ))),
    }
}
