//! Every motion statement of a program, found by a scan independent of the target readers, so
//! that a motion the readers do not compensate is listed rather than skipped in silence.
//!
//! - KRL: `PTP`, `LIN`, `CIRC`, `SPTP`, `SLIN`, `SCIRC`, `SPL` and their `_REL` forms (the
//!   statements inside inline-form folds `;FOLD PTP P1 ...;%{PE}` as the pendant writes them:
//!   the fold line is a comment, the statement inside it is the motion).
//! - RAPID: `Move*` (but `MoveExtJ`), `Search*` (but `SearchExtJ`), `TriggJ`, `TriggL`,
//!   `TriggC`, `TriggJIOs`, `TriggLIOs`, and the process motions `ArcL`, `ArcC`, `SpotL`,
//!   `SpotJ`, `CapL`, `CapC`, `PaintL`, `PaintC`, `DispL`, `DispC`.
//! - URScript: `movej`, `movel`, `movep`, `movec`, `servoj`, `servoc`, `speedj`, `speedl`.
//!
//! Each motion names its targets ([`TargetRef`]) and the frames in force ([`Frames`]).

use super::frames::Frames;
use std::ops::Range;

/// How a motion gives a target.
#[derive(Debug, Clone, PartialEq)]
pub enum TargetRef {
    /// Written in the statement (`PTP {A1 ...}`, `MoveL [[...]]`, `movej([...])`).
    Inline,
    /// A variable or declared point (`PTP XP1`, `MoveJ p10`, `movel(pick)`).
    Named(String),
    /// An expression computed at run time (`Offs(p10, 0, 0, 100)`, `$POS_ACT`, `P[i]`).
    Computed(String),
}

/// One motion statement.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Index of the file it is in (0: the program).
    pub file: usize,
    /// 1-based line.
    pub line: usize,
    /// The instruction as written (`PTP`, `MoveL`, `movej`).
    pub statement: String,
    /// Its byte range in the file.
    pub span: Range<usize>,
    /// Its targets (one; two for circular motions).
    pub refs: Vec<TargetRef>,
    /// A relative motion (`LIN_REL`).
    pub relative: bool,
    /// A motion without a target position (`speedj`), and what it is.
    pub no_target: Option<String>,
    /// The tool and base in force.
    pub frames: Frames,
}

impl Motion {
    pub(crate) fn new(line: usize, statement: &str, span: Range<usize>, frames: Frames) -> Self {
        Motion {
            file: 0,
            line,
            statement: statement.to_owned(),
            span,
            refs: Vec::new(),
            relative: false,
            no_target: None,
            frames,
        }
    }
}

/// What became of a motion.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionOutcome {
    /// Every target it names was compensated.
    Compensated,
    /// Left as it was, and why.
    Unchanged(String),
}

/// A motion and what became of it.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionReport {
    /// The motion.
    pub motion: Motion,
    /// Its outcome.
    pub outcome: MotionOutcome,
    /// The targets it names (indices into [`super::CompensatedProgram::changes`]).
    pub targets: Vec<usize>,
}

/// The arguments of a call or instruction, split at commas outside brackets, parentheses and
/// strings: each argument's trimmed span.
pub(crate) fn split_args(b: &[u8], start: usize, end: usize) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut s = start;
    let mut i = start;
    let trim = |mut s: usize, mut e: usize| {
        while s < e && b[s].is_ascii_whitespace() {
            s += 1;
        }
        while e > s && b[e - 1].is_ascii_whitespace() {
            e -= 1;
        }
        s..e
    };
    while i < end {
        match b[i] {
            b'(' | b'[' | b'{' => depth += 1,
            b')' | b']' | b'}' => depth = depth.saturating_sub(1),
            b'"' => {
                i += 1;
                while i < end && b[i] != b'"' {
                    i += 1;
                }
            }
            b',' if depth == 0 => {
                out.push(trim(s, i));
                s = i + 1;
            }
            _ => {}
        }
        i += 1;
    }
    let last = trim(s, end.min(b.len()));
    if !last.is_empty() || !out.is_empty() {
        out.push(last);
    }
    out
}

/// A target reference from an argument's text: inline when it starts with `open` (or `p[` in
/// URScript), a name when it is an identifier (RAPID: with an optional literal index `p{2}`),
/// computed otherwise.
pub(crate) fn target_ref(arg: &str, inline: &[&str]) -> TargetRef {
    let a = arg.trim();
    if inline.iter().any(|p| a.starts_with(p)) {
        return TargetRef::Inline;
    }
    let ident = |s: &str| {
        !s.is_empty()
            && s.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_')
            && !s.as_bytes()[0].is_ascii_digit()
    };
    if ident(a) {
        return TargetRef::Named(a.to_owned());
    }
    if let Some((n, rest)) = a.split_once('{') {
        if ident(n)
            && rest
                .strip_suffix('}')
                .is_some_and(|k| !k.is_empty() && k.trim().bytes().all(|c| c.is_ascii_digit()))
        {
            return TargetRef::Named(format!("{n}{{{}}}", rest.trim_end_matches('}').trim()));
        }
    }
    TargetRef::Computed(a.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arguments_split_outside_brackets_and_strings() {
        let s = b"Offs(p10, 0, 0, 100), v100, \"a,b\", [[1,2],[3]]";
        let a: Vec<&str> = split_args(s, 0, s.len())
            .into_iter()
            .map(|r| std::str::from_utf8(&s[r]).unwrap())
            .collect();
        assert_eq!(
            a,
            ["Offs(p10, 0, 0, 100)", "v100", "\"a,b\"", "[[1,2],[3]]"]
        );
        assert_eq!(target_ref("p10", &["["]), TargetRef::Named("p10".into()));
        assert_eq!(
            target_ref("path{2}", &["["]),
            TargetRef::Named("path{2}".into())
        );
        assert_eq!(target_ref(" [[1]]", &["["]), TargetRef::Inline);
        assert!(matches!(target_ref("p{i}", &["["]), TargetRef::Computed(_)));
        assert!(matches!(
            target_ref("$POS_ACT", &["{"]),
            TargetRef::Computed(_)
        ));
    }
}
