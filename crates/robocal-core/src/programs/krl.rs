//! KUKA KRL targets (`.src` and `.dat`): the aggregates `{...}` that hold a complete joint target
//! (AXIS/E6AXIS: `A1..A6` in degrees, external axes `E1..` kept) or a complete Cartesian target
//! (POS/E6POS/FRAME: `X, Y, Z` mm and `A, B, C` deg; `S` and `T` kept).
//!
//! What is read: every `{...}` outside comments (`;` to the end of the line) and strings, with an
//! optional type prefix (`{E6POS: X 1, ...}`), whose fields are `NAME number` pairs separated by
//! commas. It is a target when it has all of `A1..A6` (joints) or all of `X, Y, Z, A, B, C`
//! (Cartesian). Not targets, and left alone: aggregates assigned to a system variable (`$BASE =
//! {...}`, `$TOOL = {...}`: frames, not motions), the arguments of relative motions (`PTP_REL`,
//! `LIN_REL`), and incomplete aggregates (`{A1 10}`: "the other axes unchanged"). A hand-written
//! parser: KRL has no maintained Rust parser, and this is all robocal needs of it.

use super::lex::{line_end, past_string};
use super::{Field, ProgramTarget, TargetKind};
use crate::error::{Error, Result};
use crate::frame::{frame_vector, pose, Frame};
use std::ops::Range;
use std::path::Path;

const JOINT_FIELDS: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];
const POSE_FIELDS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];

/// Finds the targets of a KRL file's text, in file order. An aggregate that names every field of
/// a target but holds something else than a number in one of them (or in `S` or `T`) is an error
/// naming its line and field.
pub fn targets(path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b';' => i = line_end(b, i),
            b'"' => i = past_string(b, i),
            b'{' => {
                // The aggregate ends at `}`; a `;`, `{` or the end of the text first: not one.
                let Some(end) = b[i + 1..]
                    .iter()
                    .position(|&c| c == b'}' || c == b';' || c == b'{')
                    .map(|k| k + 1)
                else {
                    break;
                };
                if b[i + end] != b'}' {
                    i += end;
                    continue;
                }
                let body = i + 1..i + end;
                if let Some(t) = aggregate(path, text, i, body)? {
                    out.push(t);
                }
                i += end + 1;
            }
            _ => i += 1,
        }
    }
    Ok(out)
}

/// The statement text before the aggregate at `open`, on its line.
fn statement_before(text: &str, open: usize) -> &str {
    let start = text[..open].rfind('\n').map_or(0, |k| k + 1);
    &text[start..open]
}

fn aggregate(
    path: &Path,
    text: &str,
    open: usize,
    body: Range<usize>,
) -> Result<Option<ProgramTarget>> {
    let before = statement_before(text, open).trim();
    let upper = before.to_ascii_uppercase();
    if upper.starts_with('$') || upper.contains("_REL") {
        return Ok(None);
    }
    let line = text[..open].matches('\n').count() + 1;
    let bad = |field: &str, value: &str| {
        Error::parse(
            path,
            Some(line),
            Some(field),
            format!("`{value}` is not a number"),
        )
    };
    let mut inner = &text[body.clone()];
    let mut offset = body.start;
    // An optional type prefix `E6POS:`.
    if let Some(colon) = inner.find(':') {
        let head = inner[..colon].trim();
        if head.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
            offset += colon + 1;
            inner = &inner[colon + 1..];
        }
    }
    let mut fields = Vec::new();
    let mut pos = offset;
    for part in inner.split(',') {
        let part_start = pos;
        pos += part.len() + 1;
        let trimmed = part.trim_start();
        let lead = part.len() - trimmed.len();
        let name_len = trimmed
            .find(|c: char| c.is_whitespace())
            .unwrap_or(trimmed.len());
        let name = &trimmed[..name_len];
        let rest = &trimmed[name_len..];
        let value = rest.trim();
        if name.is_empty() || value.is_empty() {
            return Ok(None);
        }
        let vstart = part_start + lead + name_len + (rest.len() - rest.trim_start().len());
        let span = vstart..vstart + value.len();
        let v = value.parse::<f64>().ok();
        fields.push((name.to_ascii_uppercase(), v, span, value.to_owned()));
    }
    let has = |names: &[&str]| names.iter().all(|n| fields.iter().any(|f| f.0 == *n));
    let kind = if has(&JOINT_FIELDS) {
        TargetKind::Joints
    } else if has(&POSE_FIELDS) {
        TargetKind::Pose
    } else {
        return Ok(None);
    };
    let wanted: &[&str] = match kind {
        TargetKind::Joints => &JOINT_FIELDS,
        TargetKind::Pose => &POSE_FIELDS,
    };
    let mut picked = Vec::with_capacity(6);
    for n in wanted {
        let Some(f) = fields.iter().find(|f| f.0 == *n) else {
            return Ok(None);
        };
        let value = f.1.filter(|v| v.is_finite()).ok_or_else(|| bad(n, &f.3))?;
        picked.push(Field {
            name: (*n).to_owned(),
            value,
            span: f.2.clone(),
        });
    }
    let int = |name: &str| -> Result<Option<(u32, Range<usize>)>> {
        match fields.iter().find(|f| f.0 == name) {
            None => Ok(None),
            Some(f) => parse_krl_int(&f.3)
                .map(|v| Some((v, f.2.clone())))
                .ok_or_else(|| bad(name, &f.3)),
        }
    };
    let t = if kind == TargetKind::Pose {
        int("T")?
    } else {
        None
    };
    let status = if kind == TargetKind::Pose {
        int("S")?.map(|s| s.0)
    } else {
        None
    };
    Ok(Some(ProgramTarget {
        name: target_name(before),
        line,
        kind,
        fields: picked,
        turn: t.as_ref().map(|t| t.0),
        turn_span: t.map(|t| t.1),
        status,
        conf: None,
    }))
}

/// The tool frame of a KRL pose `X, Y, Z` (mm), `A, B, C` (deg).
pub fn pose_of(values: &[f64]) -> Frame {
    pose(&[
        values[0],
        values[1],
        values[2],
        values[3].to_radians(),
        values[4].to_radians(),
        values[5].to_radians(),
    ])
}

/// The KRL pose values of a tool frame.
pub fn pose_values(f: &Frame) -> Vec<f64> {
    let v = frame_vector(f);
    vec![
        v[0],
        v[1],
        v[2],
        v[3].to_degrees(),
        v[4].to_degrees(),
        v[5].to_degrees(),
    ]
}

/// A KRL integer: decimal or a binary literal `'B010'`.
fn parse_krl_int(s: &str) -> Option<u32> {
    let s = s.trim();
    if let Some(bits) = s
        .strip_prefix("'B")
        .or_else(|| s.strip_prefix("'b"))
        .and_then(|r| r.strip_suffix('\''))
    {
        return u32::from_str_radix(bits, 2).ok();
    }
    s.parse::<f64>()
        .ok()
        .filter(|v| *v >= 0.0 && v.fract() == 0.0)
        .map(|v| v as u32)
}

/// `DECL E6POS XP1=` gives `XP1`; `PTP` gives `PTP`; an empty statement gives `{...}`.
fn target_name(before: &str) -> String {
    let s = before.trim_end();
    if let Some(lhs) = s.strip_suffix('=') {
        if let Some(name) = lhs.split_whitespace().last() {
            return name.to_owned();
        }
    }
    s.split_whitespace()
        .next()
        .map(str::to_owned)
        .unwrap_or_else(|| "{...}".to_owned())
}

/// A turn written like `old` (a binary literal `'B...'` with at least as many digits, or a
/// decimal integer).
pub fn format_turn(t: u32, old: &str) -> String {
    let old = old.trim();
    if old.starts_with("'B") || old.starts_with("'b") {
        let width = old.len().saturating_sub(3);
        format!("{}{:0width$b}'", &old[..2], t)
    } else {
        t.to_string()
    }
}

/// A number written in KRL with `decimals` decimals (`-0.0000` written as `0.0000`).
pub fn format_number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.trim_start_matches('-')
        .bytes()
        .all(|c| c == b'0' || c == b'.')
    {
        s.trim_start_matches('-').to_owned()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DAT: &str =
        "&ACCESS RVP\nDEFDAT demo\n; a comment {A1 1, A2 2, A3 3, A4 4, A5 5, A6 6}\n\
        DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 45.0,A6 0.0,E1 0.0}\n\
        DECL E6POS XP1={X 2500.0,Y -100.5,Z 1500,A 10,B 80.5,C -170,S 'B010',T 35,E1 0.0}\n\
        DECL FRAME F1={X 1,Y 2,Z 3}\n\
        ENDDAT\n";

    #[test]
    fn finds_complete_targets_and_their_spans() {
        let t = targets(Path::new("demo.dat"), DAT).unwrap();
        assert_eq!(t.len(), 2, "{t:?}");
        assert_eq!(t[0].name, "XHOME");
        assert_eq!(t[0].kind, TargetKind::Joints);
        assert_eq!(t[0].line, 4);
        assert_eq!(t[0].fields[1].value, -90.0);
        assert_eq!(&DAT[t[0].fields[1].span.clone()], "-90.0");
        assert_eq!(t[1].name, "XP1");
        assert_eq!(t[1].kind, TargetKind::Pose);
        assert_eq!(&DAT[t[1].fields[2].span.clone()], "1500");
        assert_eq!(t[1].status, Some(2));
        assert_eq!(t[1].turn, Some(35));
    }

    #[test]
    fn system_frames_relative_motions_and_partial_aggregates_are_not_targets() {
        let src =
            "DEF m()\n$BASE={X 0,Y 0,Z 0,A 0,B 0,C 0}\nPTP_REL {A1 10,A2 0,A3 0,A4 0,A5 0,A6 0}\n\
                   PTP {A1 10}\nPTP {E6AXIS: A1 1,A2 -90,A3 90,A4 0,A5 30,A6 0} ; go\n\
                   LIN {X 2000,Y 0,Z 1000,A 0,B 90,C 0} C_DIS\nEND\n";
        let t = targets(Path::new("m.src"), src).unwrap();
        assert_eq!(t.len(), 2, "{t:?}");
        assert_eq!(t[0].name, "PTP");
        assert_eq!(t[0].line, 5);
        assert_eq!(&src[t[0].fields[0].span.clone()], "1");
        assert_eq!(t[1].name, "LIN");
        assert_eq!(t[1].status, None);
    }

    #[test]
    fn a_malformed_target_is_an_error_naming_its_line_and_field() {
        let src = "DEF m()\n\nPTP {A1 1, A2 -90, A3 9O, A4 0, A5 30, A6 0}\nEND\n";
        let e = targets(Path::new("m.src"), src).unwrap_err().to_string();
        assert!(
            e.contains("m.src:3") && e.contains("A3") && e.contains("9O"),
            "{e}"
        );
        let src = "DEF m()\nLIN {X 1, Y 2, Z 3, A 0, B 90, C 0, S 'B2', T 0}\nEND\n";
        let e = targets(Path::new("m.src"), src).unwrap_err().to_string();
        assert!(e.contains("m.src:2") && e.contains("`S`"), "{e}");
    }

    #[test]
    fn odd_spacing_tabs_and_case_are_read_with_exact_spans() {
        let src = "ptp {e6axis:a1\t1.5 ,  A2  -90,a3 90.25,A4 0,A5 30,A6 -0.0}\r\n";
        let t = targets(Path::new("m.src"), src).unwrap();
        assert_eq!(t.len(), 1);
        let got: Vec<&str> = t[0].fields.iter().map(|f| &src[f.span.clone()]).collect();
        assert_eq!(got, ["1.5", "-90", "90.25", "0", "30", "-0.0"]);
    }

    #[test]
    fn random_byte_edits_never_panic() {
        crate::programs::tests::edits_never_panic(super::super::Format::Krl, DAT);
    }

    #[test]
    fn numbers_are_written_with_fixed_decimals() {
        assert_eq!(format_number(1.23456789, 4), "1.2346");
        assert_eq!(format_number(-0.00001, 4), "0.0000");
        assert_eq!(format_number(-90.0, 4), "-90.0000");
    }
}
