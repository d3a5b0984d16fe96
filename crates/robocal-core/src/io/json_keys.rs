//! A pass over a JSON document that rejects a key repeated within one object, anywhere in the
//! document, and that finds the line of a key (for messages about a value found wrong after
//! parsing).
//!
//! serde_json keeps the last of two equal keys without a word (its maintainers keep it so and
//! point to a custom `Deserialize`), and serde's derived structs see only their own fields, not
//! those of maps such as `parameters` or of flattened extra keys. The maintained crates that
//! reject duplicates do it per field (serde_with's `MapPreventDuplicates`) or build a whole
//! `Value` with a JSON library of their own; this walk is a small `DeserializeSeed` over
//! serde_json's own parser, so it reads exactly the JSON the typed pass reads, allocates only the
//! key paths, and gets the line from serde_json (which attaches the position of the parser to an
//! error raised inside a visitor).

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use std::cell::RefCell;
use std::collections::HashSet;
use std::fmt;

/// What a walk is after, and what it found.
struct Walk<'a> {
    /// The key path to stop at (`parameters.a2`), or `None` to check every object for duplicates.
    find: Option<&'a str>,
    /// The key path of the duplicate (or of the key found) that stopped the walk.
    hit: RefCell<Option<String>>,
}

/// Where a value sits in the document: a chain of keys and indices up to the root, written out
/// as a path (`points.calibration[3].line`) only when a walk stops there (building every
/// value's path would allocate for each of a result's thousands of array elements).
enum At<'p> {
    Root,
    Key(&'p str, &'p At<'p>),
    Index(usize, &'p At<'p>),
}

impl At<'_> {
    /// The path written out (`""` for the root).
    fn path(&self) -> String {
        match self {
            At::Root => String::new(),
            At::Key(k, up) => match up.path() {
                p if p.is_empty() => (*k).to_string(),
                p => format!("{p}.{k}"),
            },
            At::Index(i, up) => format!("{}[{i}]", up.path()),
        }
    }
}

/// One value of the document, at `at`.
struct Node<'w, 'a, 'p> {
    walk: &'w Walk<'a>,
    at: &'p At<'p>,
}

impl<'de> DeserializeSeed<'de> for Node<'_, '_, '_> {
    type Value = ();

    fn deserialize<D: de::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Node<'_, '_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }

    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }

    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }

    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }

    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }

    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut i = 0;
        loop {
            let at = At::Index(i, self.at);
            let node = Node {
                walk: self.walk,
                at: &at,
            };
            if seq.next_element_seed(node)?.is_none() {
                return Ok(());
            }
            i += 1;
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let at = At::Key(&key, self.at);
            let stop = match self.walk.find {
                Some(target) => target == at.path(),
                None => seen.contains(&key),
            };
            if stop {
                // serde_json adds the line of the key just read to this error.
                *self.walk.hit.borrow_mut() = Some(at.path());
                return Err(de::Error::custom("duplicate key"));
            }
            map.next_value_seed(Node {
                walk: self.walk,
                at: &at,
            })?;
            seen.insert(key);
        }
        Ok(())
    }
}

/// A key that appears twice in one object.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DuplicateKey {
    /// Its path, e.g. `parameters.a2` or `points.calibration[3].line`.
    pub path: String,
    /// The 1-based line of its second appearance.
    pub line: usize,
}

/// Checks that no object of the JSON document `text` has a key twice. `Ok(None)` when none does;
/// `Err` is serde_json's error for text that is not one JSON document (callers that parsed the
/// text already never see it).
pub fn find_duplicate_key(text: &str) -> Result<Option<DuplicateKey>, serde_json::Error> {
    let walk = Walk {
        find: None,
        hit: RefCell::new(None),
    };
    match run(&walk, text) {
        Ok(()) => Ok(None),
        Err(e) => match walk.hit.into_inner() {
            Some(path) => Ok(Some(DuplicateKey {
                path,
                line: e.line(),
            })),
            None => Err(e),
        },
    }
}

/// The 1-based line of the key at `path` (e.g. `tracker_frame.x`, `parameters.a2.calibrated`)
/// in the JSON document `text`, if it is there.
pub fn line_of_key(text: &str, path: &str) -> Option<usize> {
    let walk = Walk {
        find: Some(path),
        hit: RefCell::new(None),
    };
    let e = run(&walk, text).err()?;
    walk.hit.into_inner().map(|_| e.line()).filter(|l| *l > 0)
}

fn run(walk: &Walk, text: &str) -> Result<(), serde_json::Error> {
    let mut de = serde_json::Deserializer::from_str(text);
    Node {
        walk,
        at: &At::Root,
    }
    .deserialize(&mut de)?;
    de.end()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_duplicates_at_any_depth_with_path_and_line() {
        assert_eq!(
            find_duplicate_key("{\"a\": 1, \"b\": {\"a\": 2}}").unwrap(),
            None
        );
        assert_eq!(find_duplicate_key("[1, {\"x\": [2]}, 3]").unwrap(), None);
        let d = find_duplicate_key("{\n \"a\": 1,\n \"a\": 2\n}")
            .unwrap()
            .unwrap();
        assert_eq!(d.path, "a");
        assert_eq!(d.line, 3);
        let text =
            "{\"parameters\": {\n  \"a2\": {\"nominal\": 1},\n  \"d4\": {\"nominal\": 2},\n  \
                    \"a2\": {\"nominal\": 3}\n}}";
        let d = find_duplicate_key(text).unwrap().unwrap();
        assert_eq!((d.path.as_str(), d.line), ("parameters.a2", 4));
        let text = "{\"p\": [{\"x\": 1}, {\"x\": 1,\n\"y\": 2, \"x\": 3}]}";
        let d = find_duplicate_key(text).unwrap().unwrap();
        assert_eq!((d.path.as_str(), d.line), ("p[1].x", 2));
        // Keys equal after unescaping are the same key.
        let d = find_duplicate_key("{\"ab\": 1, \"a\\u0062\": 2}")
            .unwrap()
            .unwrap();
        assert_eq!(d.path, "ab");
        // Not JSON: serde_json's error.
        assert!(find_duplicate_key("{\"a\": }").is_err());
        assert!(find_duplicate_key("{} {}").is_err());
    }

    #[test]
    fn finds_the_line_of_a_key() {
        let text = "{\n \"t\": {\n  \"x\": 1,\n  \"y\": [1, 2]\n },\n \"s\": \"ok\"\n}";
        assert_eq!(line_of_key(text, "t.y"), Some(4));
        assert_eq!(line_of_key(text, "t"), Some(2));
        assert_eq!(line_of_key(text, "s"), Some(6));
        assert_eq!(line_of_key(text, "t.z"), None);
        assert_eq!(line_of_key("not json", "t"), None);
    }
}
