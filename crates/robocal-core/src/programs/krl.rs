//! KUKA KRL targets (`.src` and `.dat`): the aggregates `{...}` that hold a complete joint target
//! (AXIS/E6AXIS: `A1..A6` in degrees, external axes `E1..E6` kept) or a complete Cartesian target
//! (POS/E6POS/FRAME: `X, Y, Z` mm and `A, B, C` deg; `S` and `T` kept).
//!
//! What is read: every `{...}` outside comments (`;` to the end of the line) and strings, with an
//! optional type prefix (`{E6POS: X 1, ...}`), members `NAME value` separated by commas, values
//! numbers, words or nested aggregates (`LOAD_DATA[1]={M 5,CM {X 0,...},J {...}}`; the syntax is
//! read by the module `krl_aggregate`, shared with the frames and the motion census). An aggregate
//! is a target when it is declared or prefixed as one of the target types, or has a member of one
//! (`A1..A6`, `X, Y, Z, A, B, C`), and holds all six of its kind. Such an aggregate is checked
//! whole, and an error names its line and member: not closed on its line, a nested aggregate, a
//! member given twice or unknown to its type (`A7` on a six-axis robot), a value that is not a
//! number or out of range ([`crate::ranges`]: `A1..A6` joint values, `X, Y, Z` and `E1..E6`
//! lengths, `A, B, C` angles), a status `S` outside 0..7 or a turn `T` outside 0..63. Not
//! targets, and left alone: aggregates assigned to a system variable (`$BASE = {...}`, `$TOOL =
//! {...}`: frames, not motions; checked like a Cartesian target), the arguments of relative
//! motions (`PTP_REL`, `LIN_REL`), and incomplete aggregates (`{A1 10}`: "the other axes
//! unchanged"). A hand-written parser: KRL has no maintained Rust parser, and this is all robocal
//! needs of it.

pub(crate) use super::krl_aggregate::{parse_aggregate, Aggregate};
use super::lex::{line_end, past_string};
use super::{Field, ProgramTarget, TargetKind};
use crate::error::{Error, Result};
use crate::frame::{frame_vector, pose, Frame};
use crate::ranges;
use std::ops::Range;
use std::path::Path;

const JOINT_FIELDS: [&str; 6] = ["A1", "A2", "A3", "A4", "A5", "A6"];
const POSE_FIELDS: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
const EXTERNAL: [&str; 6] = ["E1", "E2", "E3", "E4", "E5", "E6"];
/// The KRL types of targets and what they hold.
const TYPES: [(&str, TargetKind); 5] = [
    ("E6POS", TargetKind::Pose),
    ("POS", TargetKind::Pose),
    ("FRAME", TargetKind::Pose),
    ("E6AXIS", TargetKind::Joints),
    ("AXIS", TargetKind::Joints),
];

/// Finds the targets of a KRL file's text, in file order. A target (see the module
/// documentation) that is malformed is an error naming its line and member.
pub fn targets(path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let mut line = 1;
    let mut counted = 0;
    while i < b.len() {
        match b[i] {
            b';' => i = line_end(b, i),
            b'"' => i = past_string(b, i),
            b'{' => {
                line += text[counted..i].matches('\n').count();
                counted = i;
                let agg = parse_aggregate(path, text, i, line)?;
                if let Some(t) = classify(path, text, i, &agg, line)? {
                    out.push(t);
                }
                i = agg.close + 1;
            }
            _ => i += 1,
        }
    }
    Ok(out)
}

/// The statement text before the aggregate at `open`, on its line.
pub(crate) fn statement_before(text: &str, open: usize) -> &str {
    let start = text[..open].rfind('\n').map_or(0, |k| k + 1);
    &text[start..open]
}

/// Whether the statement before an aggregate assigns it to a system variable (`$TOOL =`,
/// `WITH $BASE =`) or a numbered frame (`TOOL_DATA[1]=`).
pub(crate) fn assigns_frame(before: &str) -> bool {
    let Some(eq) = before.rfind('=') else {
        return false;
    };
    let lhs = before[..eq].trim_end();
    let word = lhs
        .rsplit(|c: char| c.is_whitespace() || c == ',')
        .next()
        .unwrap_or("")
        .to_ascii_uppercase();
    word.starts_with('$') || word.starts_with("TOOL_DATA[") || word.starts_with("BASE_DATA[")
}

/// The declared type of `DECL [GLOBAL] TYPE NAME=`, upper case.
fn declared_type(before: &str) -> Option<String> {
    let u = before.to_ascii_uppercase();
    let mut w = u.split_whitespace();
    if w.next()? != "DECL" {
        return None;
    }
    let t = w.next()?;
    if t == "GLOBAL" || t == "CONST" {
        return w.next().map(str::to_owned);
    }
    Some(t.to_owned())
}

fn kind_of_type(t: &str) -> Option<TargetKind> {
    TYPES.iter().find(|(n, _)| *n == t).map(|(_, k)| *k)
}

/// A target, a checked frame (`None`) or nothing, from an aggregate.
fn classify(
    path: &Path,
    text: &str,
    open: usize,
    agg: &Aggregate,
    line: usize,
) -> Result<Option<ProgramTarget>> {
    let before = statement_before(text, open);
    let first = before
        .split_whitespace()
        .next()
        .unwrap_or("")
        .to_ascii_uppercase();
    if first.ends_with("_REL") {
        return Ok(None);
    }
    let typed = agg
        .prefix
        .as_deref()
        .or(declared_type(before).as_deref())
        .and_then(kind_of_type);
    let has = |names: &[&str]| agg.members.iter().any(|m| names.contains(&m.name.as_str()));
    let frame = assigns_frame(before);
    let kind = match typed {
        Some(k) => k,
        None if frame && has(&POSE_FIELDS) => TargetKind::Pose,
        None if has(&JOINT_FIELDS) || agg.members.iter().any(|m| is_axis(&m.name)) => {
            TargetKind::Joints
        }
        None if has(&POSE_FIELDS) => TargetKind::Pose,
        None => return Ok(None),
    };
    let checked = check(path, text, agg, kind, line)?;
    if frame {
        return Ok(None);
    }
    let Some((fields, turn, status)) = checked else {
        return Ok(None);
    };
    Ok(Some(ProgramTarget {
        name: target_name(before),
        line,
        kind,
        fields,
        turn: turn.as_ref().map(|t| t.0),
        turn_span: turn.map(|t| t.1),
        status,
        conf: None,
        file: 0,
    }))
}

/// `A7`, `A12`: a robot axis name.
fn is_axis(name: &str) -> bool {
    name.len() > 1 && name.starts_with('A') && name[1..].bytes().all(|c| c.is_ascii_digit())
}

type Checked = (Vec<Field>, Option<(u32, Range<usize>)>, Option<u32>);

/// Checks every member of a target aggregate of `kind`; its fields when it is complete.
fn check(
    path: &Path,
    text: &str,
    agg: &Aggregate,
    kind: TargetKind,
    line: usize,
) -> Result<Option<Checked>> {
    let err = |field: &str, msg: String| Error::parse(path, Some(line), Some(field), msg);
    let (main, what): (&[&str; 6], &str) = match kind {
        TargetKind::Joints => (&JOINT_FIELDS, "a joint target (A1..A6, E1..E6)"),
        TargetKind::Pose => (
            &POSE_FIELDS,
            "a Cartesian target (X, Y, Z, A, B, C, S, T, E1..E6)",
        ),
    };
    let mut seen: Vec<&str> = Vec::new();
    let mut turn = None;
    let mut status = None;
    let mut values: Vec<Option<Field>> = vec![None; 6];
    for m in &agg.members {
        let n = m.name.as_str();
        if seen.contains(&n) {
            return Err(err(n, format!("member `{n}` given twice")));
        }
        seen.push(n);
        let Some(span) = m.value_span() else {
            return Err(err(n, "a nested aggregate where a number belongs".into()));
        };
        let raw = &text[span.clone()];
        let pos = main.iter().position(|x| *x == n);
        let ext = EXTERNAL.contains(&n);
        let int_field = kind == TargetKind::Pose && (n == "S" || n == "T");
        if pos.is_none() && !ext && !int_field {
            if kind == TargetKind::Joints && is_axis(n) {
                return Err(err(
                    n,
                    format!("axis `{n}`: the robot has 6 axes (A1..A6; external axes E1..E6)"),
                ));
            }
            return Err(err(n, format!("`{n}` is not a member of {what}")));
        }
        if int_field {
            let v = int_member(n, raw).map_err(|m| err(n, m))?;
            if n == "T" {
                turn = Some((v, span));
            } else {
                status = Some(v);
            }
            continue;
        }
        let v: f64 = raw
            .parse()
            .map_err(|_| err(n, format!("`{raw}` is not a number")))?;
        let range = match (kind, pos) {
            (TargetKind::Joints, Some(_)) => &ranges::JOINT,
            (TargetKind::Pose, Some(k)) if k >= 3 => &ranges::ANGLE,
            _ => &ranges::LENGTH,
        };
        range.check(v).map_err(|m| err(n, m))?;
        if let Some(k) = pos {
            values[k] = Some(Field {
                name: n.to_owned(),
                value: v,
                span,
            });
        }
    }
    if values.iter().any(Option::is_none) {
        return Ok(None);
    }
    Ok(Some((values.into_iter().flatten().collect(), turn, status)))
}

/// The value of the status `S` or the turn `T` (member `n`) written `raw`, or what is wrong
/// with it.
fn int_member(n: &str, raw: &str) -> std::result::Result<u32, String> {
    let (max, desc) = if n == "T" {
        (63, "turn `T` (one bit per axis: 0..63)")
    } else {
        (7, "status `S` (3 bits: 0..7)")
    };
    let v = parse_krl_int(raw).ok_or_else(|| format!("`{raw}` is not an integer ({desc})"))?;
    if !(0..=max).contains(&v) {
        return Err(format!("{desc}: {v} is outside 0..{max}"));
    }
    Ok(v as u32)
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

/// A KRL integer: decimal (also written `35.0`) or a binary literal `'B010'`.
fn parse_krl_int(s: &str) -> Option<i64> {
    let s = s.trim();
    if let Some(bits) = s
        .strip_prefix("'B")
        .or_else(|| s.strip_prefix("'b"))
        .and_then(|r| r.strip_suffix('\''))
    {
        return i64::from_str_radix(bits, 2).ok();
    }
    s.parse::<f64>()
        .ok()
        .filter(|v| v.fract() == 0.0 && v.abs() < 1e15)
        .map(|v| v as i64)
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

#[cfg(test)]
mod tests {
    use super::*;

    const DAT: &str =
        "&ACCESS RVP\nDEFDAT demo\n; a comment {A1 1, A2 2, A3 3, A4 4, A5 5, A6 6}\n\
        DECL E6AXIS XHOME={A1 0.0,A2 -90.0,A3 90.0,A4 0.0,A5 45.0,A6 0.0,E1 0.0}\n\
        DECL E6POS XP1={X 2500.0,Y -100.5,Z 1500,A 10,B 80.5,C -170,S 'B010',T 35,E1 0.0}\n\
        DECL FRAME F1={X 1,Y 2,Z 3}\n\
        DECL FDAT FP1={TOOL_NO 1,BASE_NO 2,IPO_FRAME #BASE,POINT2[] \" \",TQ_STATE FALSE}\n\
        DECL LOAD L1={M 5,CM {X 0,Y 0,Z 100,A 0,B 0,C 0},J {X 0,Y 0,Z 0}}\n\
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

    /// The malformed aggregates of issue 26, each exit 3 naming its line and member.
    #[test]
    fn a_malformed_target_is_an_error_naming_its_line_and_field() {
        let cases = [
            (
                "\n\nPTP {A1 1, A2 -90, A3 9O, A4 0, A5 30, A6 0}\n",
                "m.src:3",
                "`A3`",
                "9O",
            ),
            (
                "LIN {X 1, Y 2, Z 3, A 0, B 90, C 0, S 'B2', T 0}\n",
                "m.src:1",
                "`S`",
                "'B2'",
            ),
            (
                "PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0\n",
                "m.src:1",
                "not closed",
                "",
            ),
            (
                "PTP {A1 0, A2 {A1 1}, A3 90, A4 0, A5 30, A6 0}\n",
                "m.src:1",
                "`A2`",
                "nested",
            ),
            (
                "PTP {A1 0, A2 -90, A3 90, A3 91, A4 0, A5 30, A6 0}\n",
                "m.src:1",
                "`A3`",
                "twice",
            ),
            (
                "PTP {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0, A7 5}\n",
                "m.src:1",
                "`A7`",
                "6 axes",
            ),
            (
                "PTP {A1 0, A2 -9e99, A3 90, A4 0, A5 30, A6 0}\n",
                "m.src:1",
                "`A2`",
                "out of range",
            ),
            (
                "LIN {X 9e15, Y 2, Z 3, A 0, B 90, C 0}\n",
                "m.src:1",
                "`X`",
                "out of range",
            ),
            (
                "LIN {X 1, Y 2, Z 3, A 0, B 90, C 0, T -5}\n",
                "m.src:1",
                "turn `T`",
                "0..63",
            ),
            (
                "LIN {X 1, Y 2, Z 3, A 0, B 90, C 0, T 64}\n",
                "m.src:1",
                "turn `T`",
                "0..63",
            ),
            (
                "DECL E6POS P={X 1, Y 2, Z 3, A 0, B 90, Q 0}\n",
                "m.src:1",
                "`Q`",
                "not a member",
            ),
        ];
        for (src, at, field, what) in cases {
            let e = targets(Path::new("m.src"), src).unwrap_err().to_string();
            assert!(
                e.contains(at) && e.contains(field) && e.contains(what),
                "{src}: {e}"
            );
        }
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
}
