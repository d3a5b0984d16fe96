//! ABB RAPID targets (`.mod`, `.modx`, `.prg`): `jointtarget` and `robtarget` aggregates.
//!
//! - `jointtarget` `[[j1, ..., j6], [e1, ..., e6]]`: the robot axes in degrees (controller axes,
//!   through the robot's controller map: ABB robots have none, i.e. the identity); the external
//!   axes are left alone.
//! - `robtarget` `[[x, y, z], [q1, q2, q3, q4], [cf1, cf4, cf6, cfx], [e1, ..., e6]]`: the tool
//!   frame in the base frame (mm, the orientation as a unit quaternion with `q1` the scalar
//!   part), i.e. for `wobj0` and the tool of the robot description; its confdata name the branch
//!   ([`super::seed::rapid_conf`]) and are kept; the external axes (`9E+09`: none) are left
//!   alone. The quaternion is written normalized, with the sign of the input's `q1`.
//!
//! What is read: declarations `CONST|PERS|VAR [LOCAL|TASK] robtarget|jointtarget name := [...];`
//! (also arrays `name{n} := [[...], ...]`: targets `name{1}`, ...; the declaration's words on
//! the line where its `[` opens), and in any other statement
//! (`MoveJ [[...], ...], v100, z10, tool0;`, `p := [...];`) every bracket aggregate with the
//! shape of a robtarget or a jointtarget. Aggregates of other types (`tooldata`, `wobjdata`,
//! `pose`, ...) are left alone; in a motion instruction (`Move...`) an aggregate of neither
//! shape is an error. Comments (`!` to the end of the line) and strings are skipped. A
//! hand-written reader: there is no maintained Rust parser of RAPID.

use super::lex::{line_end, past_string};
use super::{Field, ProgramTarget, TargetKind};
use crate::error::{Error, Result};
use crate::frame::Frame;
use nalgebra::{Quaternion, Rotation3, Translation3, UnitQuaternion};
use std::ops::Range;
use std::path::Path;

/// Deepest nesting of brackets read (a robtarget array is 3 deep).
const MAX_DEPTH: usize = 8;

/// A bracket aggregate: nested lists of scalar tokens with their byte spans.
#[derive(Debug)]
pub(crate) enum Node {
    List(Vec<Node>),
    Scalar(Range<usize>),
}

/// Reads the aggregate whose `[` is at `open`; returns it and the index after its `]`.
pub(crate) fn aggregate(b: &[u8], open: usize, depth: usize) -> Option<(Node, usize)> {
    if depth > MAX_DEPTH {
        return None;
    }
    let mut items = Vec::new();
    let mut i = open + 1;
    loop {
        i = skip_space(b, i);
        if i >= b.len() {
            return None;
        }
        match b[i] {
            b'[' => {
                let (n, end) = aggregate(b, i, depth + 1)?;
                items.push(n);
                i = end;
            }
            b']' if items.is_empty() => return Some((Node::List(items), i + 1)),
            _ => {
                let start = i;
                while i < b.len() && !matches!(b[i], b',' | b']' | b'[' | b';' | b'!') {
                    if b[i] == b'"' {
                        i += 1;
                        while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                            i += 1;
                        }
                    }
                    i += 1;
                }
                i = i.min(b.len());
                let mut end = i;
                while end > start && b[end - 1].is_ascii_whitespace() {
                    end -= 1;
                }
                items.push(Node::Scalar(start..end));
            }
        }
        i = skip_space(b, i);
        match b.get(i) {
            Some(b',') => i += 1,
            Some(b']') => return Some((Node::List(items), i + 1)),
            _ => return None,
        }
    }
}

/// The index of the first byte at or after `i` that is neither white space nor in a comment.
fn skip_space(b: &[u8], mut i: usize) -> usize {
    while i < b.len() {
        if b[i] == b'!' {
            i = line_end(b, i);
        } else if b[i].is_ascii_whitespace() {
            i += 1;
        } else {
            break;
        }
    }
    i
}

/// The shape of a node: the lengths of its sublists, if it is a list of scalar lists.
fn shape(n: &Node) -> Option<Vec<usize>> {
    let Node::List(items) = n else { return None };
    items
        .iter()
        .map(|i| match i {
            Node::List(v) if v.iter().all(|x| matches!(x, Node::Scalar(_))) => Some(v.len()),
            _ => None,
        })
        .collect()
}

const ROBTARGET: [usize; 4] = [3, 4, 4, 6];
const JOINTTARGET: [usize; 2] = [6, 6];

fn kind_of(n: &Node) -> Option<TargetKind> {
    match shape(n)?.as_slice() {
        s if s == ROBTARGET => Some(TargetKind::Pose),
        s if s == JOINTTARGET => Some(TargetKind::Joints),
        _ => None,
    }
}

/// Finds the targets of a RAPID module's text, in file order. A declared robtarget or
/// jointtarget, or a motion instruction's aggregate, that is not one (shape, a non-number, a
/// zero quaternion, non-integer confdata, an unclosed bracket) is an error naming its line.
pub fn targets(path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
    let b = text.as_bytes();
    let line_of = |at: usize| text[..at].matches('\n').count() + 1;
    let mut out = Vec::new();
    let mut words: Vec<String> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'!' => i = line_end(b, i),
            b'"' => i = past_string(b, i),
            b';' | b'\n' => {
                words.clear();
                i += 1;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let s = i;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                words.push(text[s..i].to_ascii_lowercase());
            }
            b'[' => {
                let line = line_of(i);
                let Some((node, end)) = aggregate(b, i, 0) else {
                    return Err(Error::parse(
                        path,
                        Some(line),
                        None,
                        "an aggregate `[...` that is not closed, or not a list of values",
                    ));
                };
                statement_targets(path, text, &words, &node, line, &mut out)?;
                // A statement holds one aggregate value; later ones (e.g. `\WObj:=...`) are
                // read on their own.
                i = end;
            }
            _ => i += 1,
        }
    }
    Ok(out)
}

/// The targets of one aggregate `node` of the statement whose words so far are `words`.
fn statement_targets(
    path: &Path,
    text: &str,
    words: &[String],
    node: &Node,
    line: usize,
    out: &mut Vec<ProgramTarget>,
) -> Result<()> {
    let err = |msg: String| Error::parse(path, Some(line), None, msg);
    let decl = words
        .iter()
        .position(|w| matches!(w.as_str(), "const" | "pers" | "var"));
    if let Some(d) = decl {
        let rest: Vec<&String> = words[d + 1..]
            .iter()
            .filter(|w| !matches!(w.as_str(), "local" | "task"))
            .collect();
        let (Some(ty), Some(name)) = (rest.first(), rest.get(1)) else {
            return Ok(());
        };
        let kind = match ty.as_str() {
            "robtarget" => TargetKind::Pose,
            "jointtarget" => TargetKind::Joints,
            _ => return Ok(()),
        };
        // The name as written.
        let name = original_case(text, line, name);
        if kind_of(node) == Some(kind) {
            out.push(target(path, text, node, kind, name, line)?);
            return Ok(());
        }
        if let Node::List(items) = node {
            if !items.is_empty() && items.iter().all(|n| kind_of(n) == Some(kind)) {
                for (k, n) in items.iter().enumerate() {
                    out.push(target(
                        path,
                        text,
                        n,
                        kind,
                        format!("{name}{{{}}}", k + 1),
                        line,
                    )?);
                }
                return Ok(());
            }
        }
        return Err(err(format!(
            "{name}: not a {ty} ({})",
            if kind == TargetKind::Pose {
                "[[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[6 external axes]]"
            } else {
                "[[6 axes],[6 external axes]]"
            }
        )));
    }
    let first = words.first().map(String::as_str).unwrap_or("");
    match kind_of(node) {
        Some(kind) => {
            let name = original_case(text, line, first);
            out.push(target(path, text, node, kind, name, line)?);
        }
        None if first.starts_with("move") => {
            return Err(err(format!(
                "{}: an aggregate that is neither a robtarget nor a jointtarget",
                original_case(text, line, first)
            )));
        }
        None => {}
    }
    Ok(())
}

/// `word` (lower case) as written on `line`, else as given.
fn original_case(text: &str, line: usize, word: &str) -> String {
    let l = text.lines().nth(line - 1).unwrap_or("");
    let lower = l.to_ascii_lowercase();
    match lower.find(word).filter(|_| !word.is_empty()) {
        Some(k) => l[k..k + word.len()].to_owned(),
        None if word.is_empty() => "target".to_owned(),
        None => word.to_owned(),
    }
}

fn scalars(n: &Node, k: usize) -> &[Node] {
    match n {
        Node::List(v) => match &v[k] {
            Node::List(s) => s,
            Node::Scalar(_) => &[],
        },
        Node::Scalar(_) => &[],
    }
}

fn target(
    path: &Path,
    text: &str,
    node: &Node,
    kind: TargetKind,
    name: String,
    line: usize,
) -> Result<ProgramTarget> {
    let number = |n: &Node, field: String| -> Result<Field> {
        let Node::Scalar(span) = n else {
            unreachable!("shape checked")
        };
        let s = &text[span.clone()];
        let value = s
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                Error::parse(
                    path,
                    Some(line),
                    Some(&field),
                    format!("{name}: `{s}` is not a number"),
                )
            })?;
        let range = match field.as_str() {
            "x" | "y" | "z" => Some(&crate::ranges::LENGTH),
            f if f.starts_with("rax_") => Some(&crate::ranges::JOINT),
            _ => None,
        };
        if let Some(r) = range {
            r.check(value).map_err(|m| {
                Error::parse(path, Some(line), Some(&field), format!("{name}: {m}"))
            })?;
        }
        Ok(Field {
            name: field,
            value,
            span: span.clone(),
        })
    };
    let mut fields = Vec::new();
    let mut conf = None;
    match kind {
        TargetKind::Joints => {
            for (k, n) in scalars(node, 0).iter().enumerate() {
                fields.push(number(n, format!("rax_{}", k + 1))?);
            }
        }
        TargetKind::Pose => {
            for (n, f) in scalars(node, 0).iter().zip(["x", "y", "z"]) {
                fields.push(number(n, f.to_owned())?);
            }
            for (n, f) in scalars(node, 1).iter().zip(["q1", "q2", "q3", "q4"]) {
                fields.push(number(n, f.to_owned())?);
            }
            let qn: f64 = fields[3..].iter().map(|f| f.value * f.value).sum();
            if !(qn.sqrt() > 0.5 && qn.sqrt() < 1.5) {
                return Err(Error::parse(
                    path,
                    Some(line),
                    Some("q1"),
                    format!("{name}: the quaternion's norm is {:.6}, not 1", qn.sqrt()),
                ));
            }
            let mut c = [0i64; 4];
            for (k, (n, f)) in scalars(node, 2)
                .iter()
                .zip(["cf1", "cf4", "cf6", "cfx"])
                .enumerate()
            {
                let v = number(n, f.to_owned())?.value;
                if v.fract() != 0.0 {
                    return Err(Error::parse(
                        path,
                        Some(line),
                        Some(f),
                        format!("{name}: `{v}` is not an integer"),
                    ));
                }
                // cf1, cf4, cf6: quadrants of axes within the joint range (1e5 deg); cfx: 3 bits.
                let (lo, hi, what) = if f == "cfx" {
                    (0.0, 7.0, "cfx (3 bits: 0..7)")
                } else {
                    (-1112.0, 1111.0, "a quadrant (joint values within ±1e5 deg)")
                };
                if !(lo..=hi).contains(&v) {
                    return Err(Error::parse(
                        path,
                        Some(line),
                        Some(f),
                        format!("{name}: {what}: {v} is outside {lo}..{hi}"),
                    ));
                }
                c[k] = v as i64;
            }
            conf = Some(c);
        }
    }
    Ok(ProgramTarget {
        name,
        line,
        kind,
        fields,
        turn: None,
        turn_span: None,
        status: None,
        conf,
        file: 0,
    })
}

/// The tool frame of robtarget values `x, y, z` (mm), `q1..q4` (scalar first; normalized).
pub fn pose_of(values: &[f64]) -> Frame {
    let q = UnitQuaternion::from_quaternion(Quaternion::new(
        values[3], values[4], values[5], values[6],
    ));
    Frame::from_parts(
        Translation3::new(values[0], values[1], values[2]),
        Rotation3::from(q),
    )
}

/// The robtarget values of a tool frame: the quaternion with the sign of `old`'s `q1` (the
/// sign that keeps the closest to `old` when its `q1` is 0).
pub fn pose_values(f: &Frame, old: &[f64]) -> Vec<f64> {
    let q = UnitQuaternion::from_rotation_matrix(&f.rotation);
    let mut w = [q.w, q.i, q.j, q.k];
    let dot: f64 = w.iter().zip(&old[3..7]).map(|(a, b)| a * b).sum();
    let flip = if old[3] != 0.0 {
        (old[3] > 0.0) != (w[0] >= 0.0)
    } else {
        dot < 0.0
    };
    if flip {
        w.iter_mut().for_each(|v| *v = -*v);
    }
    let t = f.translation.vector;
    vec![t.x, t.y, t.z, w[0], w[1], w[2], w[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) const MODULE: &str = "MODULE demo\n  ! a comment [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]]\n  \
        CONST robtarget p10:=[[1500, -20.5,1800],[0.5,0.5,0.5,0.5],[0,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];\n  \
        PERS jointtarget jhome := [ [ 0, 0, 0, 0, 30, 0 ] , [9E9,9E9,9E9,9E9,9E9,9E9] ];\n  \
        PERS tooldata gun := [TRUE,[[0,0,200],[1,0,0,0]],[5,[0,0,100],[1,0,0,0],0,0,0]];\n  \
        VAR robtarget path{2} := [[[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]],[[4,5,6],[0,1,0,0],[1,0,1,0],[9E9,9E9,9E9,9E9,9E9,9E9]]];\n  \
        PROC main()\n    MoveAbsJ jhome\\NoEOffs, v100, fine, tool0;\n    \
        MoveL [[1200,0,1500],[0,0,1,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, z10, tool0\\WObj:=wobj0; ! inline\n  \
        ENDPROC\nENDMODULE\n";

    #[test]
    fn declarations_arrays_and_inline_targets_with_exact_spans() {
        let t = targets(Path::new("demo.mod"), MODULE).unwrap();
        let names: Vec<&str> = t.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["p10", "jhome", "path{1}", "path{2}", "MoveL"]);
        assert_eq!(t[0].kind, TargetKind::Pose);
        assert_eq!(t[0].line, 3);
        let got: Vec<&str> = t[0]
            .fields
            .iter()
            .map(|f| &MODULE[f.span.clone()])
            .collect();
        assert_eq!(got, ["1500", "-20.5", "1800", "0.5", "0.5", "0.5", "0.5"]);
        assert_eq!(t[0].conf, Some([0, -1, 0, 1]));
        assert_eq!(t[1].kind, TargetKind::Joints);
        let got: Vec<&str> = t[1]
            .fields
            .iter()
            .map(|f| &MODULE[f.span.clone()])
            .collect();
        assert_eq!(got, ["0", "0", "0", "0", "30", "0"]);
        assert_eq!(t[3].conf, Some([1, 0, 1, 0]));
        assert_eq!(t[4].line, 9);
        assert_eq!(t[4].fields[5].value, 1.0);
    }

    #[test]
    fn malformed_targets_are_errors_naming_the_line() {
        let cases = [
            ("MODULE m\nCONST robtarget p := [[1,2],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n", "m.mod:2"),
            ("MODULE m\n\nCONST robtarget p := [[1,2,x],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n", "m.mod:3"),
            ("MODULE m\nCONST robtarget p := [[1,2,3],[0,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n", "quaternion"),
            ("MODULE m\nCONST robtarget p := [[1,2,3],[1,0,0,0],[0,0.5,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]];\n", "cf4"),
            ("MODULE m\nPROC a()\nMoveJ [[1,2,3],[1,0,0,0]], v10, z1, tool0;\n", "m.mod:3"),
            ("MODULE m\nCONST jointtarget j := [[1,2,3,4,5,6],[9E9,9E9\n", "m.mod:2"),
        ];
        for (text, want) in cases {
            let e = targets(Path::new("m.mod"), text).unwrap_err().to_string();
            assert!(e.contains(want), "{want}: {e}");
        }
    }

    #[test]
    fn random_byte_edits_never_panic() {
        crate::programs::tests::edits_never_panic(super::super::Format::Rapid, MODULE);
    }

    #[test]
    fn the_quaternion_keeps_its_sign_convention() {
        let f = pose_of(&[0.0, 0.0, 0.0, -0.5, 0.5, 0.5, 0.5]);
        let v = pose_values(&f, &[0.0, 0.0, 0.0, -0.5, 0.5, 0.5, 0.5]);
        assert!(v[3] < 0.0 && (v[3] + 0.5).abs() < 1e-12, "{v:?}");
        let v = pose_values(&f, &[0.0, 0.0, 0.0, 0.5, -0.5, -0.5, -0.5]);
        assert!(v[3] > 0.0, "{v:?}");
    }
}
