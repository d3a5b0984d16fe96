//! The per-point sections of a result's text, `points` (an entry per calibration and validation
//! row) and `prediction.map` (an entry per map point), written apart from the rest and put in
//! their place: nearly all of a result's numbers are there.
//!
//! [`CalibrationResult::to_text`] serializes the result with these sections deferred, `points`
//! written as `null` and `prediction.map` as `[]` (the *skeleton*), then writes the sections
//! here in the layout serde_json's pretty writer and `ResultFormatter` give them (one line per
//! point entry; the map pretty), and replaces the two placeholders with them. The text is the
//! same bytes as serializing the whole result (tested on simulated results and on entries with
//! NaN, infinite, signed-zero, tiny and huge values and empty lists); its numbers are written by
//! serde_json's own number writer, without serde's calls per key and token.
//!
//! The skeleton also serves [`CalibrationResult::write`]'s read-back, which parses it instead of
//! the whole text. It gives the same guarantee (a result robocal's readers would refuse is not
//! written), because the readers' verdict depends on these two sections only through:
//! - their being JSON of their schema. They are by construction: fixed punctuation and keys
//!   between numbers written by serde_json (a finite `f64` as its shortest decimal, which reads
//!   back as the same finite value; a non-finite one as `null`, which the entries' `nullable`
//!   fields read as NaN; a line as an unsigned integer);
//! - a map position being finite (`x,y,z` are not nullable), which `write` checks in memory
//!   (`result_skim::finite_map`), as the skimmed read-back did.
//!
//! Every other byte of the skeleton is the text's, so it reads as the text read with the
//! sections skimmed (`points` none, the map empty), and the checks see the same values. When
//! anything fails on the skeleton, `write` reads back the whole text instead, whose messages
//! name the line in the file.
//!
//! A placeholder is found by its text. A raw line break in the text is the formatter's (a
//! string's are escaped) and the indentation after it gives the depth, so `\n  "points": null`
//! is the result's own field; only a flattened [`CalibrationResult::extra`] key could repeat
//! it, and a result with extra keys is serialized whole. A placeholder not found where expected
//! also means serializing whole.

use super::CalibrationResult;
use crate::error::{Error, Result};
use crate::io::result_prediction::MapEntry;
use crate::io::result_sections::{PointEntry, Points};
use serde::ser::{SerializeSeq, Serializer};
use serde::Serialize;
use std::cell::Cell;

thread_local! {
    /// Whether this thread is serializing a result's skeleton (see the module docs).
    static DEFERRING: Cell<bool> = const { Cell::new(false) };
}

/// Whether this thread is serializing a result's skeleton.
pub(super) fn deferring() -> bool {
    DEFERRING.with(Cell::get)
}

/// `serialize_with` for the result's `points`: `null` while the skeleton is written.
pub(crate) fn points<S: Serializer>(
    p: &Option<Points>,
    s: S,
) -> std::result::Result<S::Ok, S::Error> {
    if deferring() {
        s.serialize_none()
    } else {
        p.serialize(s)
    }
}

/// `serialize_with` for `prediction.map`: `[]` while the skeleton is written.
pub(crate) fn map<S: Serializer>(m: &[MapEntry], s: S) -> std::result::Result<S::Ok, S::Error> {
    if deferring() {
        s.serialize_seq(Some(0))?.end()
    } else {
        m.serialize(s)
    }
}

/// Where the placeholder of `points` is: the key at the top level, then `null`.
const POINTS_AT: &str = "\n  \"points\": ";
/// Where the placeholder of `prediction.map` is: its first key, then `[]`.
const MAP_AT: &str = "\n  \"prediction\": {\n    \"map\": ";

/// A result's text in two parts: the skeleton and the sections that replace its placeholders.
pub(super) struct Deferred {
    /// The text with `points` written as `null` and `prediction.map` as `[]`.
    pub skeleton: String,
    /// Each section: the offset of its placeholder in the skeleton, the placeholder's length,
    /// and the section's text. In increasing offset.
    sections: Vec<(usize, usize, String)>,
}

impl Deferred {
    /// The whole text, in pieces: the skeleton's, with the sections in place of the
    /// placeholders.
    pub fn pieces(&self) -> Vec<&str> {
        let mut out = Vec::with_capacity(2 * self.sections.len() + 1);
        let mut from = 0;
        for (at, len, t) in &self.sections {
            out.push(&self.skeleton[from..*at]);
            out.push(t.as_str());
            from = at + len;
        }
        out.push(&self.skeleton[from..]);
        out
    }

    /// The whole text: [`Deferred::pieces`] joined.
    pub fn text(&self) -> String {
        self.pieces().concat()
    }
}

/// `r`'s text as a skeleton and its per-point sections; `None` when it is written whole (no
/// per-point section, extra keys, or a placeholder not found). `serialize` is the whole-result
/// serializer, run here with the sections deferred.
pub(super) fn split(
    r: &CalibrationResult,
    serialize: impl FnOnce() -> Result<String>,
) -> Result<Option<Deferred>> {
    let map = r.prediction.as_ref().map(|p| p.map.as_slice());
    let has_map = map.is_some_and(|m| !m.is_empty());
    if !r.extra.is_empty() || (r.points.is_none() && !has_map) {
        return Ok(None);
    }
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            DEFERRING.with(|s| s.set(self.0));
        }
    }
    let skeleton = {
        let _restore = Restore(DEFERRING.with(|s| s.replace(true)));
        serialize()?
    };
    let place = |key: &str, placeholder: &str| -> Option<usize> {
        let at = memchr::memmem::find(skeleton.as_bytes(), key.as_bytes())? + key.len();
        skeleton[at..].starts_with(placeholder).then_some(at)
    };
    let mut sections = Vec::with_capacity(2);
    if let Some(p) = &r.points {
        let Some(at) = place(POINTS_AT, "null") else {
            return Ok(None);
        };
        sections.push((at, 4, points_text(p).map_err(cannot)?));
    }
    if let Some(m) = map.filter(|m| !m.is_empty()) {
        let Some(at) = place(MAP_AT, "[]") else {
            return Ok(None);
        };
        sections.push((at, 2, map_text(m).map_err(cannot)?));
    }
    sections.sort_by_key(|s| s.0);
    Ok(Some(Deferred { skeleton, sections }))
}

fn cannot(e: serde_json::Error) -> Error {
    Error::Numerical(format!("cannot serialize result: {e}"))
}

/// `v` as serde_json writes it: the shortest decimal that reads back as `v`, `null` when it is
/// not finite.
fn number(out: &mut Vec<u8>, v: f64) -> serde_json::Result<()> {
    serde_json::Serializer::new(out).serialize_f64(v)
}

/// A point entry's line as serde_json writes it.
fn integer(out: &mut Vec<u8>, v: usize) -> serde_json::Result<()> {
    serde_json::Serializer::new(out).serialize_u64(v as u64)
}

/// The text of `points` at the top level of a result (its value, after `"points": `).
fn points_text(p: &Points) -> serde_json::Result<String> {
    let n = p.calibration.len() + p.validation.as_ref().map_or(0, Vec::len);
    let mut out = Vec::with_capacity(64 + 92 * n);
    out.extend_from_slice(b"{\n    \"calibration\": ");
    point_list(&mut out, &p.calibration)?;
    if let Some(v) = &p.validation {
        out.extend_from_slice(b",\n    \"validation\": ");
        point_list(&mut out, v)?;
    }
    out.extend_from_slice(b"\n  }");
    ascii(out)
}

/// A list of point entries at depth 2, one entry a line.
fn point_list(out: &mut Vec<u8>, list: &[PointEntry]) -> serde_json::Result<()> {
    if list.is_empty() {
        out.extend_from_slice(b"[]");
        return Ok(());
    }
    out.push(b'[');
    for (k, e) in list.iter().enumerate() {
        out.extend_from_slice(if k == 0 { b"\n" } else { b",\n" });
        out.extend_from_slice(b"      {\"after_mm\": ");
        number(out, e.after_mm)?;
        out.extend_from_slice(b", \"before_mm\": ");
        number(out, e.before_mm)?;
        out.extend_from_slice(b", \"line\": ");
        integer(out, e.line)?;
        out.push(b'}');
    }
    out.extend_from_slice(b"\n    ]");
    Ok(())
}

/// The text of a non-empty `prediction.map` (its value, after `"map": `), pretty at depth 2.
fn map_text(map: &[MapEntry]) -> serde_json::Result<String> {
    let mut out = Vec::with_capacity(16 + 200 * map.len());
    out.push(b'[');
    for (k, m) in map.iter().enumerate() {
        out.extend_from_slice(if k == 0 { b"\n" } else { b",\n" });
        out.extend_from_slice(b"      {\n        \"mean_mm\": ");
        number(&mut out, m.mean_mm)?;
        out.extend_from_slice(b",\n        \"model_mm\": ");
        number(&mut out, m.model_mm)?;
        out.extend_from_slice(b",\n        \"x\": ");
        number(&mut out, m.x)?;
        out.extend_from_slice(b",\n        \"y\": ");
        number(&mut out, m.y)?;
        out.extend_from_slice(b",\n        \"z\": ");
        number(&mut out, m.z)?;
        out.extend_from_slice(b"\n      }");
    }
    out.extend_from_slice(b"\n    ]");
    ascii(out)
}

/// Text written by the functions above (ASCII punctuation and serde_json's numbers) as a string.
fn ascii(bytes: Vec<u8>) -> serde_json::Result<String> {
    String::from_utf8(bytes).map_err(serde::ser::Error::custom)
}
