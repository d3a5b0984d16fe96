//! The syntax of a KRL aggregate `{[TYPE:] NAME value, ...}`, read on its line without regard to
//! what it holds: an optional type prefix (`{E6POS: X 1, ...}`), members `NAME value` separated
//! by commas, values numbers, words, strings or nested aggregates
//! (`LOAD_DATA[1]={M 5,CM {X 0,...},J {...}}`). What an aggregate means is for its readers:
//! targets ([`super::krl`]), frames ([`super::frames`]), motions ([`super::census_krl`]).

use super::lex::past_string;
use crate::error::{Error, Result};
use std::ops::Range;
use std::path::Path;

/// Deepest nesting of aggregates read.
const MAX_DEPTH: usize = 8;

/// A member's value.
#[derive(Debug, Clone)]
pub(crate) enum Value {
    /// A number, word or string: its trimmed span.
    Scalar(Range<usize>),
    /// A nested aggregate.
    Nested,
}

/// One member `NAME value` of an aggregate.
#[derive(Debug, Clone)]
pub(crate) struct Member {
    /// Its name, upper case.
    pub name: String,
    /// Its value.
    pub value: Value,
}

impl Member {
    /// The span of a scalar value.
    pub fn value_span(&self) -> Option<Range<usize>> {
        match &self.value {
            Value::Scalar(r) => Some(r.clone()),
            Value::Nested => None,
        }
    }
}

/// A KRL aggregate `{[TYPE:] NAME value, ...}`.
#[derive(Debug, Clone)]
pub(crate) struct Aggregate {
    /// The byte of its `}`.
    pub close: usize,
    /// Its type prefix, upper case.
    pub prefix: Option<String>,
    /// Its members, in order.
    pub members: Vec<Member>,
}

impl Aggregate {
    /// The member named `name` (upper case).
    pub fn member(&self, name: &str) -> Option<&Member> {
        self.members.iter().find(|m| m.name == name)
    }
}

/// Reads the aggregate whose `{` is at `open` (on `line`). An aggregate not closed on its line,
/// or a member without a name or value, is an error.
pub(crate) fn parse_aggregate(
    path: &Path,
    text: &str,
    open: usize,
    line: usize,
) -> Result<Aggregate> {
    nested(At { path, line }, text, open, 0)
}

/// Where an aggregate is read, for its errors.
#[derive(Clone, Copy)]
struct At<'a> {
    path: &'a Path,
    line: usize,
}

impl At<'_> {
    fn err(self, field: Option<&str>, msg: &str) -> Error {
        Error::parse(self.path, Some(self.line), field, msg)
    }

    fn unclosed(self) -> Error {
        self.err(
            None,
            "an aggregate `{` that is not closed by `}` on its line",
        )
    }
}

fn skip_blank(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
        i += 1;
    }
    i
}

fn is_word(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'$'
}

/// The aggregate at `open`, `depth` aggregates deep: its prefix, then its members up to `}`.
fn nested(at: At<'_>, text: &str, open: usize, depth: usize) -> Result<Aggregate> {
    let b = text.as_bytes();
    if depth > MAX_DEPTH {
        return Err(at.err(None, "aggregates nested too deep"));
    }
    let (prefix, mut i) = type_prefix(text, open + 1);
    let mut members = Vec::new();
    if b.get(i) == Some(&b'}') {
        return Ok(Aggregate {
            close: i,
            prefix,
            members,
        });
    }
    loop {
        let (m, end) = member(at, text, i, depth)?;
        members.push(m);
        i = skip_blank(b, end);
        match b.get(i) {
            Some(b',') => i += 1,
            Some(b'}') => {
                return Ok(Aggregate {
                    close: i,
                    prefix,
                    members,
                })
            }
            Some(b'{') => return Err(at.err(None, "a nested aggregate `{` where a member belongs")),
            _ => return Err(at.unclosed()),
        }
    }
}

/// The optional type prefix `E6POS:` from byte `start` on (upper case), and the byte after it
/// and its blanks (after the blanks at `start` when there is none).
fn type_prefix(text: &str, start: usize) -> (Option<String>, usize) {
    let b = text.as_bytes();
    let i = skip_blank(b, start);
    let w = (i..b.len()).find(|&k| !is_word(b[k])).unwrap_or(b.len());
    let after = skip_blank(b, w);
    if w > i && b.get(after) == Some(&b':') {
        (
            Some(text[i..w].to_ascii_uppercase()),
            skip_blank(b, after + 1),
        )
    } else {
        (None, i)
    }
}

/// The member `NAME value` from byte `start` on, in an aggregate `depth` deep, and the byte
/// after its value.
fn member(at: At<'_>, text: &str, start: usize, depth: usize) -> Result<(Member, usize)> {
    let b = text.as_bytes();
    let s = skip_blank(b, start);
    let mut i = s;
    while i < b.len()
        && !matches!(
            b[i],
            b' ' | b'\t' | b',' | b'}' | b'{' | b'\n' | b'\r' | b';'
        )
    {
        i += 1;
    }
    if i == s {
        return Err(match b.get(i) {
            None | Some(b'\n' | b'\r' | b';') => at.unclosed(),
            _ => at.err(None, "an aggregate member without a name"),
        });
    }
    let name = text[s..i].to_ascii_uppercase();
    i = skip_blank(b, i);
    let value = match b.get(i) {
        Some(b'{') => {
            let n = nested(at, text, i, depth + 1)?;
            i = n.close + 1;
            Value::Nested
        }
        _ => {
            let (span, end) = scalar(at, text, i, &name)?;
            i = end;
            Value::Scalar(span)
        }
    };
    Ok((Member { name, value }, i))
}

/// The scalar value of member `name` from byte `start` on (a string may hold the separators):
/// its trimmed span, and the byte after it.
fn scalar(at: At<'_>, text: &str, start: usize, name: &str) -> Result<(Range<usize>, usize)> {
    let b = text.as_bytes();
    let mut i = start;
    while i < b.len() && !matches!(b[i], b',' | b'}' | b'{' | b'\n' | b';') {
        if b[i] == b'"' {
            i = past_string(b, i).min(b.len());
            continue;
        }
        i += 1;
    }
    let mut ve = i.min(b.len());
    while ve > start && b[ve - 1].is_ascii_whitespace() {
        ve -= 1;
    }
    if ve == start {
        if matches!(b.get(i), None | Some(b'\n' | b';')) {
            return Err(at.unclosed());
        }
        return Err(at.err(Some(name), "a member without a value"));
    }
    Ok((start..ve, i))
}
