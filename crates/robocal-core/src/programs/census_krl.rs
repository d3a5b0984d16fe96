//! The motions of a KRL `.src` and the frames in force at each (see [`super::census`]).
//!
//! Frames are followed in the order of the text, from the robot description's tool and base at
//! the start: `$TOOL = ...` and `$BASE = ...` (a literal frame, `$NULLFRAME`, `TOOL_DATA[n]`,
//! `BASE_DATA[n]`), `BAS(#TOOL, n)`, `BAS(#BASE, n)`, `FDAT_ACT = FP1` (the tool and base numbers
//! of the `.dat`'s `DECL FDAT FP1={TOOL_NO 1,BASE_NO 2,...}`, as the inline forms set them), and
//! `WITH $TOOL = ..., $BASE = ...` on a spline motion (that motion only). `TOOL_DATA[n]` and
//! `BASE_DATA[n]` come from the controller's `$config.dat` ([`KrlConfig`]); number 0 is the
//! flange (tool) and the robot's base frame (base). A frame set inside a block (`IF`, `FOR`,
//! `WHILE`, `LOOP`, `REPEAT`, `SWITCH`) is unknown after the block's end; an external TCP
//! (`IPO_FRAME #TCP`, `$IPO_MODE = #TCP`) and any other expression are unknown.

use super::census::{target_ref, Motion, TargetRef};
use super::frames::{krl_frame, FrameSpec, Frames, KrlConfig};
use super::krl::parse_aggregate;
use std::collections::HashMap;
use std::path::Path;

const MOTIONS: [&str; 14] = [
    "PTP",
    "LIN",
    "CIRC",
    "SPTP",
    "SLIN",
    "SCIRC",
    "SPL",
    "PTP_REL",
    "LIN_REL",
    "CIRC_REL",
    "SPTP_REL",
    "SLIN_REL",
    "SCIRC_REL",
    "SPL_REL",
];
const OPEN: [&str; 6] = ["IF", "FOR", "WHILE", "LOOP", "REPEAT", "SWITCH"];
const CLOSE: [&str; 6] = [
    "ENDIF",
    "ENDFOR",
    "ENDWHILE",
    "ENDLOOP",
    "UNTIL",
    "ENDSWITCH",
];

/// The code of a line: up to its comment, strings kept.
fn code(line: &str) -> &str {
    let b = line.as_bytes();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += 1;
                }
            }
            b';' => return &line[..i],
            _ => {}
        }
        i += 1;
    }
    line
}

struct State<'a> {
    frames: Frames,
    /// The block depth at which tool and base were set.
    set_at: [usize; 2],
    config: Option<&'a KrlConfig>,
    /// The `.dat`'s FDAT: upper-case name -> (TOOL_NO, BASE_NO, external TCP).
    fdats: HashMap<String, Option<(usize, usize, bool)>>,
}

impl State<'_> {
    fn numbered(&self, tool: bool, n: usize) -> FrameSpec {
        let (what, map) = match (tool, self.config) {
            (true, Some(c)) => ("TOOL_DATA", Some(&c.tool_data)),
            (false, Some(c)) => ("BASE_DATA", Some(&c.base_data)),
            (true, None) => ("TOOL_DATA", None),
            (false, None) => ("BASE_DATA", None),
        };
        if n == 0 {
            return FrameSpec::Known(crate::frame::Frame::identity());
        }
        match map {
            None => FrameSpec::Unknown(format!("{what}[{n}] without the controller's $config.dat")),
            Some(m) => match m.get(&n) {
                Some(f) => FrameSpec::Known(*f),
                None => FrameSpec::Unknown(format!("{what}[{n}] is not in the $config.dat")),
            },
        }
    }

    /// The frame an expression `rhs` (`$TOOL = rhs`) gives.
    fn resolve(&self, tool: bool, rhs: &str) -> FrameSpec {
        let r = rhs.trim();
        let u = r.to_ascii_uppercase();
        let prefix = if tool { "TOOL_DATA[" } else { "BASE_DATA[" };
        if let Some(n) = u
            .strip_prefix(prefix)
            .and_then(|x| x.strip_suffix(']'))
            .and_then(|n| n.trim().parse::<usize>().ok())
        {
            return self.numbered(tool, n);
        }
        if u == "$NULLFRAME" {
            return FrameSpec::Known(crate::frame::Frame::identity());
        }
        if r.starts_with('{') {
            if let Ok(a) = parse_aggregate(Path::new(""), r, 0, 1) {
                if let Some(f) = krl_frame(r, &a) {
                    return FrameSpec::Known(f);
                }
            }
        }
        FrameSpec::Unknown(format!("`{r}` is computed at run time"))
    }

    /// Applies the frame assignments of a statement (`$TOOL = ...`, `BAS(...)`, `FDAT_ACT = ...`);
    /// returns whether it was one.
    fn assign(&mut self, stmt: &str, depth: usize) -> bool {
        let u = stmt.to_ascii_uppercase();
        let compact: String = u.split_whitespace().collect();
        if let Some((lhs, rhs)) = stmt.split_once('=') {
            let l = lhs.trim().to_ascii_uppercase();
            if l == "$TOOL" || l == "$BASE" {
                let tool = l == "$TOOL";
                let f = self.resolve(tool, rhs);
                self.set(tool, f, depth);
                return true;
            }
            if l == "$IPO_MODE" && rhs.to_ascii_uppercase().contains("#TCP") {
                let f = FrameSpec::Unknown("an external TCP ($IPO_MODE = #TCP)".into());
                self.set(true, f, depth);
                return true;
            }
            if l == "FDAT_ACT" {
                self.fdat(rhs.trim(), depth);
                return true;
            }
        }
        for (tool, head) in [(true, "BAS(#TOOL,"), (false, "BAS(#BASE,")] {
            if let Some(rest) = compact.strip_prefix(head) {
                let f = match rest.trim_end_matches(')').parse::<usize>() {
                    Ok(n) => self.numbered(tool, n),
                    Err(_) => {
                        FrameSpec::Unknown(format!("`{}` is computed at run time", stmt.trim()))
                    }
                };
                self.set(tool, f, depth);
                return true;
            }
        }
        false
    }

    fn set(&mut self, tool: bool, f: FrameSpec, depth: usize) {
        let k = usize::from(!tool);
        self.set_at[k] = depth;
        if tool {
            self.frames.tool = f;
        } else {
            self.frames.base = f;
        }
    }

    /// `FDAT_ACT = name`: the tool and base numbers of the `.dat`'s `DECL FDAT name={...}`.
    fn fdat(&mut self, name: &str, depth: usize) {
        let unknown = |why: String| (FrameSpec::Unknown(why.clone()), FrameSpec::Unknown(why));
        let found = self
            .fdats
            .get(&name.to_ascii_uppercase())
            .copied()
            .flatten();
        let (t, b) = match found {
            None => unknown(format!("FDAT_ACT = {name}: no FDAT {name} in the .dat")),
            Some((_, _, true)) => unknown(format!("FDAT {name}: an external TCP (IPO_FRAME #TCP)")),
            Some((t, b, false)) => (self.numbered(true, t), self.numbered(false, b)),
        };
        self.set(true, t, depth);
        self.set(false, b, depth);
    }
}

/// The `DECL FDAT name={...}` of a `.dat`: upper-case name -> `TOOL_NO`, `BASE_NO` and whether
/// `IPO_FRAME` is `#TCP` (`None`: not readable).
fn fdats(dat: &str) -> HashMap<String, Option<(usize, usize, bool)>> {
    let mut out = HashMap::new();
    for (k, l) in dat.lines().enumerate() {
        let c = code(l);
        let Some(open) = c.find('{') else { continue };
        let u = c[..open].to_ascii_uppercase();
        let head: Vec<&str> = u
            .split(|ch: char| ch.is_whitespace() || ch == '=')
            .filter(|w| !w.is_empty())
            .collect();
        if !head.contains(&"FDAT") {
            continue;
        }
        let Some(name) = head.last() else { continue };
        let value = parse_aggregate(Path::new(""), c, open, k + 1)
            .ok()
            .and_then(|a| {
                let int = |m: &str| -> Option<usize> {
                    c[a.member(m)?.value_span()?].trim().parse().ok()
                };
                let tcp = a
                    .member("IPO_FRAME")
                    .and_then(|m| m.value_span())
                    .is_some_and(|s| c[s].to_ascii_uppercase().contains("TCP"));
                Some((int("TOOL_NO")?, int("BASE_NO")?, tcp))
            });
        out.insert((*name).to_owned(), value);
    }
    out
}

/// The motions of a KRL `.src` text, with the frames in force; `dat` is its `.dat` (FDAT data),
/// `config` the controller's `$config.dat` frames.
pub fn motions(text: &str, dat: Option<&str>, config: Option<&KrlConfig>) -> Vec<Motion> {
    let mut st = State {
        frames: Frames::default(),
        set_at: [0, 0],
        config,
        fdats: dat.map(fdats).unwrap_or_default(),
    };
    let mut out = Vec::new();
    let mut depth = 0usize;
    let mut offset = 0;
    for (k, raw) in text.split('\n').enumerate() {
        let start = offset;
        offset += raw.len() + 1;
        let c = code(raw);
        let stmt = c.trim();
        let first = stmt
            .split(|ch: char| ch.is_whitespace() || ch == '(' || ch == '{')
            .next()
            .unwrap_or("")
            .to_ascii_uppercase();
        if OPEN.contains(&first.as_str()) {
            depth += 1;
        }
        if CLOSE.contains(&first.as_str()) {
            depth = depth.saturating_sub(1);
            for (i, tool) in [(0, true), (1, false)] {
                if st.set_at[i] > depth {
                    let f = FrameSpec::Unknown(format!(
                        "set inside a block that ends on line {}",
                        k + 1
                    ));
                    st.set(tool, f, depth);
                }
            }
        }
        if st.assign(stmt, depth) || !MOTIONS.contains(&first.as_str()) {
            continue;
        }
        let lead = c.len() - c.trim_start().len();
        let kw_end = start + lead + first.len();
        let mut m = Motion::new(
            k + 1,
            &stmt[..first.len()],
            start + lead..start + c.trim_end().len(),
            st.frames.clone(),
        );
        m.relative = first.ends_with("_REL");
        let mut args = &stmt[first.len()..];
        // `WITH $TOOL = ..., $BASE = ...`: this motion's frames.
        let up = args.to_ascii_uppercase();
        if let Some(w) = up.find(" WITH ") {
            let with = &args[w + 6..];
            args = &args[..w];
            for part in super::census::split_args(with.as_bytes(), 0, with.len()) {
                let a = &with[part];
                if let Some((l, r)) = a.split_once('=') {
                    match l.trim().to_ascii_uppercase().as_str() {
                        "$TOOL" => m.frames.tool = st.resolve(true, r),
                        "$BASE" => m.frames.base = st.resolve(false, r),
                        _ => {}
                    }
                }
            }
        }
        let _ = kw_end;
        let n = if first.contains("CIRC") { 2 } else { 1 };
        let mut rest = args.trim_start();
        for _ in 0..n {
            // A target, or frames joined by the geometric operator (`XP1:{X 100}`,
            // `BASE_DATA[1]:XP1`): computed at run time.
            let operand = |s: &str| {
                if s.starts_with('{') {
                    s.find('}').map_or(s.len(), |e| e + 1)
                } else {
                    s.find(|ch: char| ch.is_whitespace() || ch == ',' || ch == ':')
                        .unwrap_or(s.len())
                }
            };
            let mut end = operand(rest);
            let mut joined = false;
            while let Some(r) = rest[end..].trim_start().strip_prefix(':') {
                let r = r.trim_start();
                let start = rest.len() - r.len();
                end = start + operand(r);
                joined = true;
            }
            m.refs.push(if joined {
                TargetRef::Computed(rest[..end].to_owned())
            } else {
                target_ref(&rest[..end], &["{"])
            });
            rest = rest[end..]
                .trim_start()
                .trim_start_matches(',')
                .trim_start();
        }
        out.push(m);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::census::TargetRef;
    use super::*;

    #[test]
    fn motions_folds_and_frames_are_found_in_order() {
        let src = "DEF m()\n;FOLD PTP P1 Vel=100 % PDAT1 Tool[1] Base[2];%{PE}\n\
                   FDAT_ACT=FP1\nBAS(#PTP_PARAMS,100)\nPTP XP1 \n;ENDFOLD\n\
                   LIN {X 1,Y 2,Z 3,A 0,B 0,C 0} C_DIS ; go\nCIRC XA, XB CA 90\n\
                   IF A THEN\n$TOOL=TOOL_DATA[3]\nENDIF\nLIN_REL {X 10}\nLIN P[2]\n\
                   SLIN XP3 WITH $TOOL=TOOL_DATA[1], $BASE=BASE_DATA[0]\nEND\n";
        let dat = "DEFDAT m\nDECL FDAT FP1={TOOL_NO 1,BASE_NO 2,IPO_FRAME #BASE,POINT2[] \" \"}\n";
        let mut cfg = KrlConfig::default();
        cfg.tool_data.insert(1, crate::frame::Frame::identity());
        let m = motions(src, Some(dat), Some(&cfg));
        let lines: Vec<usize> = m.iter().map(|m| m.line).collect();
        assert_eq!(lines, [5, 7, 8, 12, 13, 14]);
        assert_eq!(m[0].refs, [TargetRef::Named("XP1".into())]);
        assert!(matches!(m[0].frames.tool, FrameSpec::Known(_)));
        assert!(m[0].frames.base.unknown().unwrap().contains("BASE_DATA[2]"));
        assert_eq!(m[1].refs, [TargetRef::Inline]);
        assert_eq!(
            m[2].refs,
            [TargetRef::Named("XA".into()), TargetRef::Named("XB".into())]
        );
        assert!(m[3].relative);
        assert!(m[3].frames.tool.unknown().unwrap().contains("block"));
        assert!(matches!(m[4].refs[0], TargetRef::Computed(_)));
        assert!(matches!(m[5].frames.tool, FrameSpec::Known(_)));
        assert!(matches!(m[5].frames.base, FrameSpec::Known(_)));
        crate::programs::tests::edits_never_panic(crate::programs::Format::Krl, src);
        crate::programs::tests::edits_never_panic(crate::programs::Format::Krl, dat);
    }
}
