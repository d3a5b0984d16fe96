//! The layout of a result file's text: serde_json's pretty layout, except that each entry of
//! `points.calibration` and `points.validation` takes one line.
//!
//! A million points written pretty take five lines and about 140 bytes each; on one line about
//! 60. The text is built, read back and checked in memory before it is written
//! ([`super::result::CalibrationResult::write`]), so its size is the largest allocation of a
//! large calibration. serde_json lays out whole documents only (pretty or compact); this
//! formatter is its pretty one with the entries' objects written compactly, recognised by the
//! keys on their path, which serde_json hands to the formatter as it writes them.

use serde_json::ser::{Formatter, PrettyFormatter};
use std::io::{self, Write};

/// The arrays whose object entries take one line each: (parent key, key).
const ONE_LINE_ENTRIES: [(Key, Key); 2] = [
    (Key::Points, Key::Calibration),
    (Key::Points, Key::Validation),
];

/// A key as far as the layout cares: one of the keys of [`ONE_LINE_ENTRIES`], or another (so
/// that no key is kept as text beyond the one being written).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Key {
    Points,
    Calibration,
    Validation,
    Other,
}

impl Key {
    fn of(text: &str) -> Key {
        match text {
            "points" => Key::Points,
            "calibration" => Key::Calibration,
            "validation" => Key::Validation,
            _ => Key::Other,
        }
    }
}

/// serde_json's pretty formatter, with the entries of [`ONE_LINE_ENTRIES`] on one line each.
pub(crate) struct ResultFormatter {
    pretty: PrettyFormatter<'static>,
    /// For each open object or array, the key it is the value of (`None` at the root and in
    /// arrays).
    open: Vec<Option<Key>>,
    /// The text of the key being written, while `in_key` (reused from key to key).
    key: String,
    /// Whether a key is being written.
    in_key: bool,
    /// The last key written in the innermost open object.
    last_key: Option<Key>,
    /// The depth (`open.len()`) of the one-line entry being written, while one is.
    one_line: Option<usize>,
}

impl ResultFormatter {
    /// A formatter indenting by two spaces, as serde_json's pretty one.
    pub(crate) fn new() -> ResultFormatter {
        ResultFormatter {
            pretty: PrettyFormatter::new(),
            open: Vec::new(),
            key: String::new(),
            in_key: false,
            last_key: None,
            one_line: None,
        }
    }

    /// Opens a container that is the value of the last key (in an object) or an element.
    fn push(&mut self) {
        self.open.push(self.last_key.take());
    }

    /// Whether an object opened now is an entry of one of [`ONE_LINE_ENTRIES`]: the innermost
    /// open container is an array under such a key, inside an object under the parent key.
    fn entry_starts(&self) -> bool {
        let n = self.open.len();
        if n < 2 || self.last_key.is_some() {
            return false;
        }
        let (Some(array), Some(parent)) = (self.open[n - 1], self.open[n - 2]) else {
            return false;
        };
        ONE_LINE_ENTRIES.contains(&(parent, array))
    }

    fn in_one_line(&self) -> bool {
        self.one_line.is_some()
    }
}

impl Formatter for ResultFormatter {
    fn begin_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.push();
        if self.in_one_line() {
            return w.write_all(b"[");
        }
        self.pretty.begin_array(w)
    }

    fn end_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.open.pop();
        if self.in_one_line() {
            return w.write_all(b"]");
        }
        self.pretty.end_array(w)
    }

    fn begin_array_value<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        self.last_key = None;
        if self.in_one_line() {
            return if first { Ok(()) } else { w.write_all(b", ") };
        }
        self.pretty.begin_array_value(w, first)
    }

    fn end_array_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        if self.in_one_line() {
            return Ok(());
        }
        self.pretty.end_array_value(w)
    }

    fn begin_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        let starts = !self.in_one_line() && self.entry_starts();
        self.push();
        if starts {
            self.one_line = Some(self.open.len());
        }
        if self.in_one_line() {
            return w.write_all(b"{");
        }
        self.pretty.begin_object(w)
    }

    fn end_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        let depth = self.open.len();
        self.open.pop();
        self.last_key = None;
        if self.in_one_line() {
            if self.one_line == Some(depth) {
                self.one_line = None;
            }
            return w.write_all(b"}");
        }
        self.pretty.end_object(w)
    }

    fn begin_object_key<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        self.key.clear();
        self.in_key = true;
        if self.in_one_line() {
            return if first { Ok(()) } else { w.write_all(b", ") };
        }
        self.pretty.begin_object_key(w, first)
    }

    fn end_object_key<W: ?Sized + Write>(&mut self, _w: &mut W) -> io::Result<()> {
        self.in_key = false;
        self.last_key = Some(Key::of(&self.key));
        Ok(())
    }

    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        if self.in_one_line() {
            return w.write_all(b": ");
        }
        self.pretty.begin_object_value(w)
    }

    fn end_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.last_key = None;
        if self.in_one_line() {
            return Ok(());
        }
        self.pretty.end_object_value(w)
    }

    fn write_string_fragment<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        fragment: &str,
    ) -> io::Result<()> {
        if self.in_key {
            self.key.push_str(fragment);
        }
        w.write_all(fragment.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;
    use serde_json::json;

    fn text(v: &impl Serialize) -> String {
        let mut buf = Vec::new();
        v.serialize(&mut serde_json::Serializer::with_formatter(
            &mut buf,
            ResultFormatter::new(),
        ))
        .unwrap();
        String::from_utf8(buf).unwrap()
    }

    #[test]
    fn points_entries_take_one_line_and_the_rest_is_pretty() {
        let v = json!({
            "a": {"calibration": [{"x": 1, "y": [1, 2]}], "k": "v\"w"},
            "points": {
                "calibration": [{"after_mm": 0.5, "before_mm": 1.5, "line": 2},
                                {"after_mm": 0.25, "before_mm": null, "line": 3}],
                "validation": [{"after_mm": 1.0, "line": 9, "nested": {"q": [1, {"r": 2}]}}]
            },
            "z": [{"calibration": [{"x": 1}]}]
        });
        let t = text(&v);
        let expected = r#"{
  "a": {
    "calibration": [
      {
        "x": 1,
        "y": [
          1,
          2
        ]
      }
    ],
    "k": "v\"w"
  },
  "points": {
    "calibration": [
      {"after_mm": 0.5, "before_mm": 1.5, "line": 2},
      {"after_mm": 0.25, "before_mm": null, "line": 3}
    ],
    "validation": [
      {"after_mm": 1.0, "line": 9, "nested": {"q": [1, {"r": 2}]}}
    ]
  },
  "z": [
    {
      "calibration": [
        {
          "x": 1
        }
      ]
    }
  ]
}"#;
        assert_eq!(t, expected);
        let back: serde_json::Value = serde_json::from_str(&t).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn everything_else_is_serde_jsons_pretty_layout() {
        let v = json!({"points": [], "p": {"points": {"calibration": 3}}, "e": {}, "l": [[], {}]});
        assert_eq!(text(&v), serde_json::to_string_pretty(&v).unwrap());
    }
}
