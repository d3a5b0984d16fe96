//! URScript targets (`.script`, `.urscript`): joint lists `[q1, ..., q6]` (rad, controller axes:
//! UR robots have no controller map) and poses `p[x, y, z, rx, ry, rz]` (m, rotation vector in
//! rad: the tool frame in the base frame, for the TCP of the robot description: a `set_tcp` in
//! the program is not followed).
//!
//! What is read: every list or pose given directly as a positional argument of a motion
//! (`movej`, `movel`, `movep`, `movec`, `servoj`: `movej([0, -1.57, ...], a=1.4, v=1.05)`,
//! `movel(p[...], ...)`, `movej(p[...])`), and every assignment `name = p[...]` or `name = [...]`
//! (optionally `global`/`local`) whose variable is later given directly to one of these motions
//! (`movel(name, ...)`), also as the target of `pose_trans(T, p[...])`, `pose_trans(p[...], T)`
//! (T a variable) or `pose_add(T, p[...])` (the literal pose is the motion's offset, see
//! [`super::frames::Offset`]). Other lists and poses (`pose_trans(base, offset)` with a variable
//! offset, `set_tcp(p[...])`, variables used only as offsets) are not targets and are left alone. A
//! target that is not six numbers is an error naming its line. Comments (`#` to the end of the
//! line) and strings are skipped. A hand-written reader: there is no maintained Rust parser of
//! URScript.

use super::census::split_args;
use super::frames::Offset;
use super::lex::{line_end, past_string};
use super::{Field, ProgramTarget, TargetKind};
use crate::error::{Error, Result};
use crate::frame::Frame;
use nalgebra::{Rotation3, Translation3, Vector3};
use std::ops::Range;
use std::path::Path;

const MOTIONS: [&str; 6] = ["movej", "movel", "movep", "movec", "servoj", "servoc"];

/// A list `[...]` or pose `p[...]` found in the text.
struct List {
    pose: bool,
    /// The entries' spans (trimmed).
    items: Vec<Range<usize>>,
    line: usize,
}

/// Reads the list whose `[` is at `open`; returns it and the index after its `]`; `None` when it
/// is not a flat list closed on the same statement.
fn list(b: &[u8], open: usize) -> Option<(Vec<Range<usize>>, usize)> {
    let mut items = Vec::new();
    let mut i = open + 1;
    let mut start = i;
    while i < b.len() {
        match b[i] {
            b',' | b']' => {
                let (mut s, mut e) = (start, i);
                while s < e && b[s].is_ascii_whitespace() {
                    s += 1;
                }
                while e > s && b[e - 1].is_ascii_whitespace() {
                    e -= 1;
                }
                if b[i] == b']' {
                    if s < e || !items.is_empty() {
                        items.push(s..e);
                    }
                    return Some((items, i + 1));
                }
                items.push(s..e);
                start = i + 1;
            }
            b'[' | b'#' | b'(' | b')' | b'"' => return None,
            _ => {}
        }
        i += 1;
    }
    None
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// A literal pose `p[x, y, z, rx, ry, rz]` as a frame (mm).
pub(crate) fn literal_pose(s: &str) -> Option<crate::frame::Frame> {
    let inner = s.trim().strip_prefix("p[")?.strip_suffix(']')?;
    let v: Vec<f64> = inner
        .split(',')
        .map(|x| x.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()?;
    (v.len() == 6).then(|| pose_of(&v))
}

/// The first argument of the call whose arguments (and closing parenthesis) are `rest`.
pub(crate) fn first_argument(rest: &str) -> &str {
    let b = rest.as_bytes();
    let first = split_args(b, 0, b.len())
        .first()
        .map_or(rest, |r| &rest[r.clone()]);
    // The call's own `)` when it has one argument.
    if first.matches(')').count() > first.matches('(').count() {
        first.strip_suffix(')').unwrap_or(first).trim_end()
    } else {
        first
    }
}

/// For a `pose_trans(..)` or `pose_add(..)` argument `a`: its target and offset when its
/// operands are a target and a literal pose (see the module docs), `Some(None)` when they are
/// not; `None` when `a` is not such a call.
pub(crate) fn offset_call(a: &str) -> Option<Option<(&str, Offset)>> {
    let (name, rest) = a.trim().split_once('(')?;
    let add = match name.trim_end() {
        "pose_trans" => false,
        "pose_add" => true,
        _ => return None,
    };
    let inner = rest.trim_end().strip_suffix(')')?;
    let b = inner.as_bytes();
    let ops: Vec<&str> = split_args(b, 0, b.len())
        .into_iter()
        .map(|r| &inner[r])
        .collect();
    let ident =
        |s: &str| !s.is_empty() && s.bytes().all(is_ident) && !s.as_bytes()[0].is_ascii_digit();
    let target = |s: &str| ident(s) || s.starts_with("p[");
    Some(match ops[..] {
        [t, o] if target(t) && literal_pose(o).is_some() => {
            let o = literal_pose(o).expect("checked");
            Some((
                t,
                if add {
                    Offset::Add(o)
                } else {
                    Offset::After(o)
                },
            ))
        }
        [o, t] if !add && ident(t) && literal_pose(o).is_some() => {
            Some((t, Offset::Before(literal_pose(o).expect("checked"))))
        }
        _ => None,
    })
}

/// The end of the call whose `(` is at `open` (the index of its `)`, or of the line's end).
pub(crate) fn call_end(b: &[u8], open: usize) -> usize {
    let mut depth = 0usize;
    let mut i = open;
    while i < b.len() {
        match b[i] {
            b'(' | b'[' => depth += 1,
            b')' | b']' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    return i;
                }
            }
            b'\n' | b'#' => return i,
            b'"' | b'\'' => {
                i = past_string(b, i);
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    b.len()
}

/// Finds the targets of a URScript program's text, in file order.
pub fn targets(path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
    let b = text.as_bytes();
    let line_of = |at: usize| text[..at].matches('\n').count() + 1;
    // Assignments of lists to variables: name -> (position, list or the line of a list that
    // could not be read).
    let mut assigned: Vec<(String, usize, std::result::Result<List, usize>)> = Vec::new();
    // Targets given directly to motions, and the variables given to them.
    let mut direct: Vec<(String, usize, std::result::Result<List, usize>)> = Vec::new();
    let mut used: Vec<String> = Vec::new();
    let mut line_start = true;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'#' => i = line_end(b, i),
            b'"' | b'\'' => i = past_string(b, i),
            b'\n' => {
                line_start = true;
                i += 1;
            }
            c if c.is_ascii_whitespace() => i += 1,
            c if is_ident(c) && (i == 0 || !is_ident(b[i - 1])) => {
                let s = i;
                while i < b.len() && is_ident(b[i]) {
                    i += 1;
                }
                let word = &text[s..i];
                let at_start = std::mem::replace(&mut line_start, false);
                if MOTIONS.contains(&word) {
                    let j = skip_ws(b, i);
                    if b.get(j) == Some(&b'(') {
                        i = motion_args(b, j, &line_of, word, &mut direct, &mut used);
                    }
                } else if at_start {
                    let (name_end, name) = if matches!(word, "global" | "local") {
                        let j = skip_ws(b, i);
                        let e = (j..b.len()).find(|k| !is_ident(b[*k])).unwrap_or(b.len());
                        (e, &text[j..e])
                    } else {
                        (i, word)
                    };
                    let j = skip_ws(b, name_end);
                    if !name.is_empty() && b.get(j) == Some(&b'=') && b.get(j + 1) != Some(&b'=') {
                        let k = skip_ws(b, j + 1);
                        if let Some((end, l)) = value_list(b, k, &line_of) {
                            assigned.push((name.to_owned(), k, l));
                            i = end;
                        }
                    }
                }
            }
            _ => {
                line_start = false;
                i += 1;
            }
        }
    }
    let mut found: Vec<(usize, String, std::result::Result<List, usize>)> =
        direct.into_iter().map(|(n, at, l)| (at, n, l)).collect();
    for (name, at, l) in assigned {
        if used.contains(&name) {
            found.push((at, name, l));
        }
    }
    found.sort_by_key(|f| f.0);
    found
        .into_iter()
        .map(|(_, name, l)| target(path, text, name, l))
        .collect()
}

fn skip_ws(b: &[u8], mut i: usize) -> usize {
    while i < b.len() && (b[i] == b' ' || b[i] == b'\t') {
        i += 1;
    }
    i
}

type Found = (usize, std::result::Result<List, usize>);

/// A list `[...]` or pose `p[...]` starting at `k`, if one starts there: the list (or its line,
/// when it cannot be read) and the index after it.
fn value_list(b: &[u8], k: usize, line_of: &dyn Fn(usize) -> usize) -> Option<Found> {
    let (pose, open) = match (b.get(k), b.get(k + 1)) {
        (Some(b'p'), Some(b'[')) => (true, k + 1),
        (Some(b'['), _) => (false, k),
        _ => return None,
    };
    let line = line_of(k);
    Some(match list(b, open) {
        Some((items, end)) => (end, Ok(List { pose, items, line })),
        None => (open + 1, Err(line)),
    })
}

/// Reads the arguments of a motion whose `(` is at `open`; returns the index after them.
fn motion_args(
    b: &[u8],
    open: usize,
    line_of: &dyn Fn(usize) -> usize,
    word: &str,
    direct: &mut Vec<(String, usize, std::result::Result<List, usize>)>,
    used: &mut Vec<String>,
) -> usize {
    let mut i = open + 1;
    loop {
        let mut k = skip_ws(b, i);
        // A named argument `q=[...]`, `pose=p[...]`: its value.
        let e = (k..b.len()).find(|j| !is_ident(b[*j])).unwrap_or(b.len());
        let after = skip_ws(b, e);
        if e > k && b.get(after) == Some(&b'=') && b.get(after + 1) != Some(&b'=') {
            k = skip_ws(b, after + 1);
        }
        // The end of a call the target is inside (its other arguments are not targets).
        let mut inside: Option<usize> = None;
        // `get_inverse_kin(p[...], ...)`: the pose it is given.
        if b[k.min(b.len())..].starts_with(b"get_inverse_kin(") {
            let open = k + "get_inverse_kin".len();
            inside = Some(call_end(b, open));
            k = skip_ws(b, open + 1);
        }
        // `pose_trans(T, p[...])`, `pose_trans(p[...], T)`, `pose_add(T, p[...])`: T (see
        // census_ur); any other combination is no target.
        let mut no_target = false;
        for call in ["pose_trans", "pose_add"] {
            let rest = &b[k.min(b.len())..];
            if rest.starts_with(call.as_bytes()) && b.get(skip_ws(b, k + call.len())) == Some(&b'(')
            {
                let open = skip_ws(b, k + call.len());
                let close = call_end(b, open);
                inside = inside.or(Some(close));
                let a = std::str::from_utf8(&b[k..(close + 1).min(b.len())]).unwrap_or("");
                match offset_call(a) {
                    Some(Some((t, _))) => k += t.as_ptr() as usize - a.as_ptr() as usize,
                    _ => no_target = true,
                }
            }
        }
        if no_target {
            i = k;
        } else if let Some((end, l)) = value_list(b, k, line_of) {
            direct.push((word.to_owned(), k, l));
            i = end;
        } else {
            let e = (k..b.len()).find(|j| !is_ident(b[*j])).unwrap_or(b.len());
            let after = skip_ws(b, e);
            if e > k && matches!(b.get(after), Some(b',') | Some(b')')) {
                used.push(String::from_utf8_lossy(&b[k..e]).into_owned());
            }
            i = k;
        }
        if let Some(close) = inside {
            i = i.max((close + 1).min(b.len()));
        }
        // To the end of this argument (nested parentheses and brackets skipped).
        let mut depth = 0usize;
        while i < b.len() {
            match b[i] {
                b'(' | b'[' => depth += 1,
                b')' | b']' if depth > 0 => depth -= 1,
                b')' => return i + 1,
                b',' if depth == 0 => break,
                b'\n' | b'#' => return i,
                _ => {}
            }
            i += 1;
        }
        if i >= b.len() {
            return i;
        }
        i += 1;
    }
}

fn target(
    path: &Path,
    text: &str,
    name: String,
    l: std::result::Result<List, usize>,
) -> Result<ProgramTarget> {
    let l = l.map_err(|line| {
        Error::parse(
            path,
            Some(line),
            None,
            format!("{name}: a target that is not a list of numbers"),
        )
    })?;
    let (kind, names): (TargetKind, [&str; 6]) = if l.pose {
        (TargetKind::Pose, ["x", "y", "z", "rx", "ry", "rz"])
    } else {
        (TargetKind::Joints, ["q1", "q2", "q3", "q4", "q5", "q6"])
    };
    if l.items.len() != 6 {
        return Err(Error::parse(
            path,
            Some(l.line),
            None,
            format!("{name}: {} entries, a target has 6", l.items.len()),
        ));
    }
    let mut fields = Vec::with_capacity(6);
    for (span, f) in l.items.iter().zip(names) {
        let s = &text[span.clone()];
        let value = s
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Error::parse(
                    path,
                    Some(l.line),
                    Some(f),
                    format!(
                        "{name}: `{s}` is not a number (robocal compensates targets written as \
                         numbers)"
                    ),
                )
            })?;
        fields.push(Field {
            name: f.to_owned(),
            value,
            span: span.clone(),
        });
    }
    Ok(ProgramTarget {
        name,
        line: l.line,
        kind,
        fields,
        turn: None,
        turn_span: None,
        status: None,
        conf: None,
        file: 0,
    })
}

/// The tool frame (mm) of a URScript pose `x, y, z` (m), `rx, ry, rz` (rotation vector, rad).
pub fn pose_of(values: &[f64]) -> Frame {
    Frame::from_parts(
        Translation3::new(values[0] * 1e3, values[1] * 1e3, values[2] * 1e3),
        Rotation3::new(Vector3::new(values[3], values[4], values[5])),
    )
}

/// The URScript pose of a tool frame: the rotation vector of angle below pi, or its equivalent
/// of angle 2 pi - |v| (the opposite direction) when `old` was written that way (closer to it).
pub fn pose_values(f: &Frame, old: &[f64]) -> Vec<f64> {
    let mut v = crate::frame::rotation_vector(f.rotation.matrix());
    let o = Vector3::new(old[3], old[4], old[5]);
    let n = v.norm();
    if n > 1e-9 {
        let alt = v * (1.0 - std::f64::consts::TAU / n);
        if (alt - o).norm() < (v - o).norm() {
            v = alt;
        }
    }
    let t = f.translation.vector / 1e3;
    vec![t.x, t.y, t.z, v.x, v.y, v.z]
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) const SCRIPT: &str = "def demo():\n  # a comment movej([1,2,3,4,5,6])\n  \
        home = [0.0, -1.5708, 1.5708,-1.5708, -1.5708, 0.0]\n  \
        offset = p[0, 0, 0.05, 0, 0, 0]\n  global pick = p[0.4, -0.1 ,0.3, 0, 3.1416, 0]\n  \
        movej(home, a=1.4, v=1.05)\n  movel( pick, a=1.2, v=0.25, r=0)\n  \
        movel(pose_trans(pick, offset), a=1.2, v=0.25)\n  \
        movej([0.1,-1.2, 1.4, -1.7, -1.5, 0.2], a=1.4, v=1.05, t=0, r=0)\n  \
        movej(p[0.3, 0.2, 0.4, 0.0, 3.0, 0.1])\n  textmsg(\"movej([1,2])\")\nend\n";

    #[test]
    fn motion_arguments_and_used_variables_with_exact_spans() {
        let t = targets(Path::new("demo.script"), SCRIPT).unwrap();
        let names: Vec<&str> = t.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["home", "pick", "movej", "movej"]);
        let lines: Vec<usize> = t.iter().map(|t| t.line).collect();
        assert_eq!(lines, [3, 5, 9, 10]);
        assert_eq!(t[0].kind, TargetKind::Joints);
        assert_eq!(t[1].kind, TargetKind::Pose);
        let got: Vec<&str> = t[1]
            .fields
            .iter()
            .map(|f| &SCRIPT[f.span.clone()])
            .collect();
        assert_eq!(got, ["0.4", "-0.1", "0.3", "0", "3.1416", "0"]);
        let got: Vec<&str> = t[2]
            .fields
            .iter()
            .map(|f| &SCRIPT[f.span.clone()])
            .collect();
        assert_eq!(got, ["0.1", "-1.2", "1.4", "-1.7", "-1.5", "0.2"]);
        assert_eq!(t[3].kind, TargetKind::Pose);
    }

    #[test]
    fn malformed_targets_are_errors_naming_the_line() {
        let cases = [
            ("def a():\n  movej([1, 2, 3, 4, 5])\nend\n", "a.script:2"),
            (
                "def a():\n\n  movel(p[0.1, 0.2, z, 0, 0, 0])\nend\n",
                "a.script:3",
            ),
            ("def a():\n  x = [1, 2, 3]\n  movej(x)\nend\n", "a.script:2"),
            ("def a():\n  movej([1, 2, 3, 4, 5, 6\nend\n", "a.script:2"),
        ];
        for (text, want) in cases {
            let e = targets(Path::new("a.script"), text)
                .unwrap_err()
                .to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
    }

    #[test]
    fn random_byte_edits_never_panic() {
        crate::programs::tests::edits_never_panic(super::super::Format::UrScript, SCRIPT);
    }

    #[test]
    fn rotation_vectors_keep_their_turn() {
        let old = [0.0, 0.0, 0.0, 0.0, 3.2, 0.0];
        let v = pose_values(&pose_of(&old), &old);
        assert!((v[4] - 3.2).abs() < 1e-12, "{v:?}");
        let old = [0.1, 0.0, 0.0, 0.0, 3.0, 0.0];
        let v = pose_values(&pose_of(&old), &old);
        assert!(
            (v[4] - 3.0).abs() < 1e-12 && (v[0] - 0.1).abs() < 1e-15,
            "{v:?}"
        );
    }
}
