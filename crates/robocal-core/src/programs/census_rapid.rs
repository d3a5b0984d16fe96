//! The motions of a RAPID module and the frames each names (see [`super::census`]).
//!
//! The tool is the instruction's tool argument (the last positional one; before the signal and
//! value of `*DO`, `*AO`, `*GO`, before the procedure of `*Sync`), the work object its
//! `\WObj:=` (else `wobj0`, the robot's base frame). `tool0` is the flange; other tools and work
//! objects are the `tooldata`/`wobjdata` declared in the module (a stationary tool, a work
//! object held by the robot or moved by a mechanical unit, or one declared elsewhere: unknown).
//! A work object's frame is its user frame times its object frame.

use super::census::{split_args, target_ref, Motion};
use super::frames::{FrameSpec, Frames};
use super::lex::{line_end, past_string};
use super::rapid::{aggregate, Node};
use crate::frame::Frame;
use nalgebra::{Quaternion, Rotation3, Translation3, UnitQuaternion};
use std::collections::HashMap;
use std::ops::Range;

const NAMED: [&str; 15] = [
    "triggj",
    "triggl",
    "triggc",
    "triggjios",
    "triggljios",
    "arcl",
    "arcc",
    "spotl",
    "spotj",
    "capl",
    "capc",
    "paintl",
    "paintc",
    "displ",
    "dispc",
];

fn is_motion(w: &str) -> bool {
    (w.starts_with("move") && w != "moveextj" && w.len() > 4)
        || (w.starts_with("search") && w != "searchextj" && w.len() > 6)
        || NAMED.contains(&w)
}

/// The frame `[[x, y, z], [q1, q2, q3, q4]]` of a pose node.
fn pose_node(text: &str, n: &Node) -> Option<Frame> {
    let Node::List(v) = n else { return None };
    let nums = |n: &Node| -> Option<Vec<f64>> {
        let Node::List(s) = n else { return None };
        s.iter()
            .map(|x| match x {
                Node::Scalar(r) => text[r.clone()].trim().parse::<f64>().ok(),
                Node::List(_) => None,
            })
            .collect()
    };
    let (t, q) = (nums(v.first()?)?, nums(v.get(1)?)?);
    if t.len() != 3 || q.len() != 4 {
        return None;
    }
    let q = UnitQuaternion::try_new(Quaternion::new(q[0], q[1], q[2], q[3]), 1e-9)?;
    Some(Frame::from_parts(
        Translation3::new(t[0], t[1], t[2]),
        Rotation3::from(q),
    ))
}

fn boolean(text: &str, n: Option<&Node>) -> Option<bool> {
    match n? {
        Node::Scalar(r) => match text[r.clone()].trim().to_ascii_uppercase().as_str() {
            "TRUE" => Some(true),
            "FALSE" => Some(false),
            _ => None,
        },
        Node::List(_) => None,
    }
}

/// The declared tooldata (`true`) and wobjdata (`false`) of a module, by lower-case name.
fn declared_frames(text: &str) -> HashMap<(bool, String), FrameSpec> {
    let b = text.as_bytes();
    let mut out = HashMap::new();
    let mut words: Vec<String> = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'!' => i = line_end(b, i),
            b'"' => i = past_string(b, i),
            b';' => {
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
                let Some((node, end)) = aggregate(b, i, 0) else {
                    i += 1;
                    continue;
                };
                i = end;
                let Some(d) = words
                    .iter()
                    .position(|w| matches!(w.as_str(), "const" | "pers" | "var"))
                else {
                    continue;
                };
                let rest: Vec<&String> = words[d + 1..]
                    .iter()
                    .filter(|w| !matches!(w.as_str(), "local" | "task"))
                    .collect();
                let (Some(ty), Some(name)) = (rest.first(), rest.get(1)) else {
                    continue;
                };
                let Node::List(v) = &node else { continue };
                let spec = match ty.as_str() {
                    "tooldata" => match (
                        boolean(text, v.first()),
                        v.get(1).and_then(|n| pose_node(text, n)),
                    ) {
                        (Some(false), _) => {
                            FrameSpec::Unknown(format!("{name}: a stationary tool (robhold FALSE)"))
                        }
                        (Some(true), Some(f)) => FrameSpec::Known(f),
                        _ => FrameSpec::Unknown(format!("{name}: a tooldata robocal cannot read")),
                    },
                    "wobjdata" => {
                        let u = v.get(3).and_then(|n| pose_node(text, n));
                        let o = v.get(4).and_then(|n| pose_node(text, n));
                        match (boolean(text, v.first()), boolean(text, v.get(1)), u, o) {
                            (Some(true), ..) => FrameSpec::Unknown(format!(
                                "{name}: held by the robot (robhold TRUE)"
                            )),
                            (_, Some(false), ..) => FrameSpec::Unknown(format!(
                                "{name}: moved by a mechanical unit (ufprog FALSE)"
                            )),
                            (Some(false), Some(true), Some(u), Some(o)) => FrameSpec::Known(u * o),
                            _ => FrameSpec::Unknown(format!(
                                "{name}: a wobjdata robocal cannot read"
                            )),
                        }
                    }
                    _ => continue,
                };
                out.insert((ty.as_str() == "tooldata", (*name).clone()), spec);
            }
            _ => i += 1,
        }
    }
    out
}

/// The motions of a RAPID module's text, with the frames each names.
pub fn motions(text: &str) -> Vec<Motion> {
    let b = text.as_bytes();
    let declared = declared_frames(text);
    let mut out = Vec::new();
    let mut stmt_start = true;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'!' => i = line_end(b, i),
            b'"' => {
                stmt_start = false;
                i = past_string(b, i);
            }
            b';' => {
                stmt_start = true;
                i += 1;
            }
            c if c.is_ascii_whitespace() => i += 1,
            c if c.is_ascii_alphabetic() => {
                let s = i;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                let w = text[s..i].to_ascii_lowercase();
                let starts = std::mem::replace(&mut stmt_start, false) || first_on_line(text, s);
                if ends_at_its_line(&w) {
                    stmt_start = true;
                    continue;
                }
                if !starts || !is_motion(&w) {
                    continue;
                }
                let e = statement_end(b, i);
                out.push(motion_statement(text, &declared, &w, s..i, e));
                i = e;
            }
            _ => {
                stmt_start = false;
                i += 1;
            }
        }
    }
    out
}

/// Whether only blanks precede byte `s` on its line of `text`.
fn first_on_line(text: &str, s: usize) -> bool {
    text[..s]
        .rfind('\n')
        .map_or(&text[..s], |k| &text[k + 1..s])
        .trim()
        .is_empty()
}

/// Whether the lower-case word `w` ends a statement without `;`: statements without `;` (PROC,
/// IF ... THEN, ENDIF) end at their line.
fn ends_at_its_line(w: &str) -> bool {
    matches!(
        w,
        "proc"
            | "then"
            | "else"
            | "endif"
            | "endproc"
            | "do"
            | "endwhile"
            | "endfor"
            | "endtest"
            | "module"
            | "endmodule"
            | "func"
            | "trap"
    )
}

/// The end of the statement whose instruction ends at byte `i`: its `;` outside strings and
/// comments, or the end of the text.
fn statement_end(b: &[u8], i: usize) -> usize {
    let mut e = i;
    while e < b.len() && b[e] != b';' {
        match b[e] {
            b'"' => e = past_string(b, e),
            b'!' => e = line_end(b, e),
            _ => e += 1,
        }
    }
    e.min(b.len())
}

/// The motion of the instruction `w` (lower case) written at `word` and ending at byte `e`: the
/// targets it names and its tool and work object, resolved in the module's `declared` frames.
fn motion_statement(
    text: &str,
    declared: &HashMap<(bool, String), FrameSpec>,
    w: &str,
    word: Range<usize>,
    e: usize,
) -> Motion {
    let (s, i) = (word.start, word.end);
    let line = text[..s].matches('\n').count() + 1;
    let mut m = Motion::new(line, &text[s..i], s..e, Frames::default());
    let args: Vec<&str> = split_args(text.as_bytes(), i, e)
        .into_iter()
        .map(|r| &text[r])
        .collect();
    let (pos, wobj) = positional_and_wobj(&args);
    let circ = w.ends_with('c')
        || w.contains("cdo")
        || w.contains("csync")
        || w.contains("cao")
        || w.contains("cgo");
    let first = if w.starts_with("search") { 2 } else { 0 };
    let n = if circ { 2 } else { 1 };
    for k in first..first + n {
        if let Some(a) = pos.get(k) {
            m.refs.push(target_ref(a, &["["]));
        }
    }
    let back = if w.ends_with("do") || w.ends_with("ao") || w.ends_with("go") {
        3
    } else if w.ends_with("sync") {
        2
    } else {
        1
    };
    m.frames.tool = match pos.len().checked_sub(back).and_then(|k| pos.get(k)) {
        Some(t) if pos.len() > first + n => named_frame(declared, true, t),
        _ => FrameSpec::Unknown("no tool argument".into()),
    };
    m.frames.base = named_frame(declared, false, wobj.as_deref().unwrap_or("wobj0"));
    m
}

/// The positional arguments of an instruction (each argument's text before its first `\`) and
/// the work object of its `\WObj:=`, if any.
fn positional_and_wobj<'a>(args: &[&'a str]) -> (Vec<&'a str>, Option<String>) {
    let mut pos: Vec<&str> = Vec::new();
    let mut wobj = None;
    for a in args {
        for part in a.split('\\').skip(1) {
            let p = part.trim();
            if let Some(v) = p
                .strip_prefix("WObj")
                .or_else(|| p.strip_prefix("wobj"))
                .and_then(|v| v.trim().strip_prefix(":="))
            {
                wobj = Some(v.trim().to_owned());
            }
        }
        let head = a.split('\\').next().unwrap_or("").trim();
        if !head.is_empty() {
            pos.push(head);
        }
    }
    (pos, wobj)
}

/// The frame of the tool (`tool`) or work object named `name`: `tool0` and `wobj0` the identity,
/// else the module's `declared` one, else unknown.
fn named_frame(declared: &HashMap<(bool, String), FrameSpec>, tool: bool, name: &str) -> FrameSpec {
    let n = name.trim().to_ascii_lowercase();
    if n == "tool0" || n == "wobj0" {
        return FrameSpec::Known(Frame::identity());
    }
    declared
        .get(&(tool, n.clone()))
        .cloned()
        .unwrap_or_else(|| {
            FrameSpec::Unknown(format!("`{}` is not declared in this module", name.trim()))
        })
}

#[cfg(test)]
mod tests {
    use super::super::census::TargetRef;
    use super::*;

    #[test]
    fn motions_and_their_tools_and_work_objects() {
        let text = "MODULE m\n  PERS tooldata gun := [TRUE,[[0,0,200],[1,0,0,0]],[5,[0,0,100],[1,0,0,0],0,0,0]];\n  \
            PERS wobjdata wobj1 := [FALSE,TRUE,\"\",[[1000,0,0],[1,0,0,0]],[[0,0,50],[1,0,0,0]]];\n  \
            PROC main()\n    MoveJ p0, v100, z10, gun\\WObj:=wobj1;\n    MoveL \\Conc, Offs(p0,0,0,100), v100, fine, tool0;\n    \
            MoveC p1, p2, v100, z10, gun; ! circle\n    SearchL \\Stop, di1, sp, p3, v100, tool9;\n    \
            MoveLDO [[1,2,3],[1,0,0,0],[0,0,0,0],[9E9,9E9,9E9,9E9,9E9,9E9]], v100, z10, gun, do1, 1;\n    \
            MoveExtJ j1, v100, fine;\n  ENDPROC\nENDMODULE\n";
        let m = motions(text);
        let names: Vec<&str> = m.iter().map(|m| m.statement.as_str()).collect();
        assert_eq!(names, ["MoveJ", "MoveL", "MoveC", "SearchL", "MoveLDO"]);
        assert_eq!(m[0].line, 5);
        assert_eq!(m[0].refs, [TargetRef::Named("p0".into())]);
        let FrameSpec::Known(w) = &m[0].frames.base else {
            panic!("{:?}", m[0].frames)
        };
        assert_eq!(w.translation.vector.z, 50.0);
        assert!(matches!(m[0].frames.tool, FrameSpec::Known(_)));
        assert!(matches!(m[1].refs[0], TargetRef::Computed(_)));
        assert_eq!(m[2].refs.len(), 2);
        assert_eq!(m[3].refs, [TargetRef::Named("p3".into())]);
        assert!(m[3].frames.tool.unknown().unwrap().contains("tool9"));
        assert_eq!(m[4].refs, [TargetRef::Inline]);
        assert!(matches!(m[4].frames.tool, FrameSpec::Known(_)));
    }
}
