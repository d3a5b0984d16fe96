//! The motions of a URScript program and the TCP in force at each (see [`super::census`]).
//!
//! The target of `movej`, `movel`, `movep`, `servoj`, `servoc` is the first argument (or `q=`,
//! `pose=`), of `movec` the first two (or `pose_via=`, `pose_to=`); `get_inverse_kin(p[...])`
//! counts as the pose it is given. `speedj` and `speedl` have no target position. The TCP is
//! the robot description's until `set_tcp(p[...])` (a literal pose, or a variable assigned one);
//! any other `set_tcp` makes it unknown. Poses are in the robot's base frame.
//!
//! A target combined with a literal pose counts as that target with an offset ([`super::frames::Offset`]):
//! `pose_trans(T, p[...])` (after T), `pose_trans(p[...], T)` with T a variable (T in the
//! literal's frame), `pose_add(T, p[...])`; T is a literal pose or a variable. Any other
//! combination (a variable offset, a nested call) is computed at run time.

use super::census::{split_args, target_ref, Motion, TargetRef};
use super::frames::{FrameSpec, Frames};
use super::lex::{line_end, past_string};
use super::urscript::{call_end, first_argument, literal_pose, offset_call};
use std::collections::HashMap;

const MOTIONS: [&str; 8] = [
    "movej", "movel", "movep", "movec", "servoj", "servoc", "speedj", "speedl",
];

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// The motions of a URScript text, with the TCP in force.
pub fn motions(text: &str) -> Vec<Motion> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut frames = Frames::default();
    let mut poses: HashMap<String, String> = HashMap::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'#' => i = line_end(b, i),
            b'"' | b'\'' => i = past_string(b, i),
            c if is_ident(c) && (i == 0 || !is_ident(b[i - 1])) => {
                let s = i;
                while i < b.len() && is_ident(b[i]) {
                    i += 1;
                }
                let word = &text[s..i];
                let mut j = i;
                while j < b.len() && (b[j] == b' ' || b[j] == b'\t') {
                    j += 1;
                }
                if b.get(j) == Some(&b'=') && b.get(j + 1) != Some(&b'=') {
                    let e = line_end(b, j);
                    poses.insert(word.to_owned(), text[j + 1..e].trim().to_owned());
                    continue;
                }
                if b.get(j) != Some(&b'(') {
                    continue;
                }
                let e = call_end(b, j);
                let args: Vec<&str> = split_args(b, j + 1, e)
                    .into_iter()
                    .map(|r| &text[r])
                    .collect();
                if word == "set_tcp" {
                    let a = args.first().copied().unwrap_or("");
                    let lit = literal_pose(a)
                        .or_else(|| poses.get(a.trim()).and_then(|v| literal_pose(v)));
                    frames.tool = match lit {
                        Some(f) => FrameSpec::Known(f),
                        None => FrameSpec::Unknown(format!("set_tcp({a}) is computed at run time")),
                    };
                    i = e;
                    continue;
                }
                if !MOTIONS.contains(&word) {
                    continue;
                }
                let line = text[..s].matches('\n').count() + 1;
                let mut m = Motion::new(line, word, s..(e + 1).min(b.len()), frames.clone());
                if word.starts_with("speed") {
                    m.no_target = Some("a speed command: no target position to compensate".into());
                } else {
                    let names: &[&str] = if word == "movec" {
                        &["pose_via", "pose_to"]
                    } else {
                        &["q", "pose"]
                    };
                    let n = if word == "movec" { 2 } else { 1 };
                    let mut picked: Vec<&str> = Vec::new();
                    for (k, a) in args.iter().enumerate() {
                        let named = a.split_once('=').filter(|(l, _)| {
                            l.trim().bytes().all(is_ident) && !l.trim().is_empty()
                        });
                        match named {
                            Some((l, v)) if names.contains(&l.trim()) => picked.push(v.trim()),
                            None if k < n => picked.push(a),
                            _ => {}
                        }
                    }
                    for a in picked {
                        let a = a.strip_prefix("get_inverse_kin(").map_or(a, first_argument);
                        // A target with an offset: one offset per motion (a movec whose two
                        // targets have different offsets keeps the second as computed).
                        let a = match offset_call(a) {
                            Some(Some((t, o)))
                                if m.refs.is_empty() || m.frames.offset == Some(o) =>
                            {
                                m.frames.offset = Some(o);
                                t
                            }
                            None if m.frames.offset.is_none() => a,
                            _ => {
                                m.refs.push(TargetRef::Computed(a.trim().to_owned()));
                                continue;
                            }
                        };
                        m.refs.push(target_ref(a, &["[", "p["]));
                    }
                }
                out.push(m);
                i = e;
            }
            _ => i += 1,
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::census::TargetRef;
    use super::*;

    #[test]
    fn motions_named_arguments_and_tcp() {
        let text = "def m():\n  tcp = p[0, 0, 0.2, 0, 0, 0]\n  movej(q=[0,-1.57,1.57,0,1.57,0], a=1.4, v=1.05)\n  \
            movej(get_inverse_kin(p[0.4, 0, 0.3, 0, 3.14, 0]))\n  set_tcp(tcp)\n  movel(pick, a=1)\n  \
            movel(pose_trans(pick, p[0,0,0.05,0,0,0]))\n  speedj([0.1,0,0,0,0,0], 0.5)\n  set_tcp(get_tcp())\n  \
            movec(p[0.1,0,0.3,0,3.14,0], p[0.2,0,0.3,0,3.14,0], a=1)\n  # movej(x)\n  \
            movel(pose_trans(pick, off))\n  movel(pose_add(p[0,0,0,0,0,0], pick))\nend\n";
        let m = motions(text);
        let lines: Vec<usize> = m.iter().map(|m| m.line).collect();
        assert_eq!(lines, [3, 4, 6, 7, 8, 10, 12, 13]);
        assert_eq!(m[0].refs, [TargetRef::Inline]);
        assert_eq!(m[1].refs, [TargetRef::Inline]);
        assert_eq!(m[0].frames.tool, FrameSpec::Default);
        assert_eq!(m[2].refs, [TargetRef::Named("pick".into())]);
        assert!(matches!(m[2].frames.tool, FrameSpec::Known(_)));
        // A target with a literal offset is that target; a variable offset is computed.
        assert_eq!(m[3].refs, [TargetRef::Named("pick".into())]);
        assert!(matches!(
            m[3].frames.offset,
            Some(super::super::frames::Offset::After(_))
        ));
        assert!(m[4].no_target.is_some());
        assert_eq!(m[5].refs, [TargetRef::Inline, TargetRef::Inline]);
        assert!(m[5].frames.tool.unknown().is_some());
        assert!(matches!(&m[6].refs[0], TargetRef::Computed(e) if e == "pose_trans(pick, off)"));
        assert!(matches!(m[7].refs[0], TargetRef::Computed(_)));
    }
}
