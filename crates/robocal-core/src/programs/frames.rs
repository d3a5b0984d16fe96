//! The tool and base frames a program's Cartesian targets are written in, and their mapping to
//! the robot model's tool frame in its base frame.
//!
//! A controller reaches a Cartesian target `P` (the program's values) by putting its tool `TOOL`
//! on `BASE * P`: the flange at `BASE * P * TOOL^-1`. robocal's models have their own tool `Tm`
//! (the robot description's, and its calibrated value): the model's tool frame is `flange * Tm`.
//! - With the robot description's tool ([`FrameSpec::Default`] tool) the program's `P` is the
//!   model's tool frame in `BASE`: the real tool is the calibrated one.
//! - With a tool the program gives (KRL `$TOOL`, `TOOL_DATA[n]`, a RAPID `tooldata`, a URScript
//!   `set_tcp`), the tool is taken as given: the calibrated model must reach
//!   `BASE * P * TOOL^-1 * Tm_calibrated` and the controller, believing the nominal model, reads
//!   a written `P'` as the nominal tool frame `BASE * P' * TOOL^-1 * Tm_nominal`.
//!
//! A frame robocal cannot resolve ([`FrameSpec::Unknown`]) leaves every target that needs it
//! unchanged, with the reason.

use super::krl::{parse_aggregate, Aggregate};
use super::lex::{line_end, past_string};
use crate::error::{Error, Result};
use crate::frame::{pose, Frame};
use std::collections::BTreeMap;
use std::path::Path;

/// One frame (tool or base) in force at a motion.
#[derive(Debug, Clone, PartialEq)]
pub enum FrameSpec {
    /// The robot description's (tool: the robot file's tool; base: the robot's base frame).
    Default,
    /// A frame the program gives (mm), relative to the flange (tool) or the robot's base frame
    /// (base).
    Known(Frame),
    /// A frame robocal cannot resolve, and why.
    Unknown(String),
}

impl FrameSpec {
    /// The reason, for an unknown frame.
    pub fn unknown(&self) -> Option<&str> {
        match self {
            FrameSpec::Unknown(s) => Some(s),
            _ => None,
        }
    }
}

/// A literal pose a motion combines its target with (URScript `pose_trans`, `pose_add`), so
/// that the robot goes to the combination, not to the target itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Offset {
    /// `pose_trans(target, o)`: the target followed by `o`, in the target's frame.
    After(Frame),
    /// `pose_trans(o, target)`: `o` followed by the target (the target given in frame `o`).
    Before(Frame),
    /// `pose_add(target, o)`: positions added, rotations multiplied (`R_target R_o`).
    Add(Frame),
}

impl Offset {
    /// The pose the robot goes to for target `p`.
    pub fn apply(&self, p: &Frame) -> Frame {
        match self {
            Offset::After(o) => p * o,
            Offset::Before(o) => o * p,
            Offset::Add(o) => {
                Frame::from_parts(o.translation, nalgebra::Rotation3::identity())
                    * p
                    * Frame::from_parts(nalgebra::Translation3::identity(), o.rotation)
            }
        }
    }

    /// The target whose combination is `x` (the inverse of [`Offset::apply`]).
    pub fn unapply(&self, x: &Frame) -> Frame {
        match self {
            Offset::After(o) => x * o.inverse(),
            Offset::Before(o) => o.inverse() * x,
            Offset::Add(o) => {
                Frame::from_parts(o.translation.inverse(), nalgebra::Rotation3::identity())
                    * x
                    * Frame::from_parts(nalgebra::Translation3::identity(), o.rotation.inverse())
            }
        }
    }
}

/// The tool and base in force at a motion, and the offset it combines its target with.
#[derive(Debug, Clone, PartialEq)]
pub struct Frames {
    /// The tool.
    pub tool: FrameSpec,
    /// The base (KRL base, RAPID work object).
    pub base: FrameSpec,
    /// The literal pose the motion combines its target with, if any (URScript).
    pub offset: Option<Offset>,
}

impl Default for Frames {
    fn default() -> Self {
        Frames {
            tool: FrameSpec::Default,
            base: FrameSpec::Default,
            offset: None,
        }
    }
}

impl Frames {
    /// Why a target in these frames cannot be compensated, if it cannot.
    pub fn unknown(&self) -> Option<String> {
        match (self.tool.unknown(), self.base.unknown()) {
            (Some(t), _) => Some(format!("tool unknown: {t}")),
            (None, Some(b)) => Some(format!("base unknown: {b}")),
            _ => None,
        }
    }

    /// The model tool frame (base frame) for program pose `p`, with model tool `tm` (the
    /// calibrated one for the pose to reach, the nominal one for what the controller reads).
    pub fn to_model(&self, p: &Frame, tm: &Frame) -> Frame {
        let p = self.offset.map_or(*p, |o| o.apply(p));
        let b = match &self.base {
            FrameSpec::Known(b) => *b * p,
            _ => p,
        };
        match &self.tool {
            FrameSpec::Known(t) => b * t.inverse() * tm,
            _ => b,
        }
    }

    /// The program pose of the model tool frame `x` (model tool `tm`: the nominal one).
    pub fn from_model(&self, x: &Frame, tm: &Frame) -> Frame {
        let x = match &self.tool {
            FrameSpec::Known(t) => x * tm.inverse() * t,
            _ => *x,
        };
        let x = match &self.base {
            FrameSpec::Known(b) => b.inverse() * x,
            _ => x,
        };
        self.offset.map_or(x, |o| o.unapply(&x))
    }
}

/// The numbered frames of a KUKA controller's `$config.dat`: `TOOL_DATA[n]` and `BASE_DATA[n]`
/// (mm, deg: `{X, Y, Z, A, B, C}`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KrlConfig {
    /// `TOOL_DATA[n]`, by `n`.
    pub tool_data: BTreeMap<usize, Frame>,
    /// `BASE_DATA[n]`, by `n`.
    pub base_data: BTreeMap<usize, Frame>,
}

/// The frame of a KRL aggregate `{X .., Y .., Z .., A .., B .., C ..}` (all six members).
pub(crate) fn krl_frame(text: &str, a: &Aggregate) -> Option<Frame> {
    let mut v = [0.0; 6];
    for (k, n) in ["X", "Y", "Z", "A", "B", "C"].iter().enumerate() {
        let m = a.member(n)?;
        v[k] = text[m.value_span()?].trim().parse::<f64>().ok()?;
        if k >= 3 {
            v[k] = v[k].to_radians();
        }
    }
    Some(pose(&v))
}

impl KrlConfig {
    /// Reads `TOOL_DATA[n]={...}` and `BASE_DATA[n]={...}` from a `$config.dat` text; a frame
    /// that is not six numbers is an error naming its line.
    pub fn parse(path: &Path, text: &str) -> Result<KrlConfig> {
        let b = text.as_bytes();
        let mut out = KrlConfig::default();
        let mut i = 0;
        while i < b.len() {
            match b[i] {
                b';' => i = line_end(b, i),
                b'"' => i = past_string(b, i),
                b'{' => {
                    let line = text[..i].matches('\n').count() + 1;
                    let agg = parse_aggregate(path, text, i, line)?;
                    let start = text[..i].rfind('\n').map_or(0, |k| k + 1);
                    let lhs = text[start..i].trim().trim_end_matches('=').trim();
                    let upper = lhs.to_ascii_uppercase();
                    let upper = upper.trim_start_matches("DECL").trim();
                    for (prefix, map) in [
                        ("TOOL_DATA[", &mut out.tool_data),
                        ("BASE_DATA[", &mut out.base_data),
                    ] {
                        let Some(rest) = upper.strip_prefix(prefix) else {
                            continue;
                        };
                        let Some(n) = rest
                            .strip_suffix(']')
                            .and_then(|n| n.trim().parse::<usize>().ok())
                        else {
                            continue;
                        };
                        let f = krl_frame(text, &agg).ok_or_else(|| {
                            Error::parse(
                                path,
                                Some(line),
                                Some(lhs),
                                "a frame needs the six numbers X, Y, Z, A, B, C",
                            )
                        })?;
                        map.insert(n, f);
                    }
                    i = agg.close + 1;
                }
                _ => i += 1,
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::frame_vector;

    #[test]
    fn config_frames_are_read_by_number() {
        let text = "DEFDAT $CONFIG\n;TOOL_DATA[9]={X 1,Y 2,Z 3,A 0,B 0,C 0}\n\
                    TOOL_DATA[1]={X 0.0,Y 0.0,Z 250.0,A 0.0,B 90.0,C 0.0}\n\
                    BASE_DATA[2]={X 1000,Y -500,Z 0,A 90,B 0,C 0}\n\
                    LOAD_DATA[1]={M -1,CM {X 0,Y 0,Z 0,A 0,B 0,C 0},J {X 0,Y 0,Z 0}}\nENDDAT\n";
        let c = KrlConfig::parse(Path::new("$config.dat"), text).unwrap();
        assert_eq!(c.tool_data.len(), 1);
        let t = frame_vector(&c.tool_data[&1]);
        assert!((t[2] - 250.0).abs() < 1e-12 && (t[4] - 90f64.to_radians()).abs() < 1e-12);
        assert_eq!(frame_vector(&c.base_data[&2])[0], 1000.0);
        let bad = "BASE_DATA[2]={X 1000,Y -500,Z 0,A 90,B 0}\n";
        let e = KrlConfig::parse(Path::new("c.dat"), bad).unwrap_err();
        assert!(e.to_string().contains("c.dat:1"), "{e}");
    }

    #[test]
    fn model_and_program_frames_map_both_ways() {
        let o = pose(&[5.0, -20.0, 50.0, 0.3, -0.1, 0.7]);
        for offset in [
            None,
            Some(Offset::After(o)),
            Some(Offset::Before(o)),
            Some(Offset::Add(o)),
        ] {
            let f = Frames {
                tool: FrameSpec::Known(pose(&[0.0, 10.0, 200.0, 0.1, 0.2, 0.3])),
                base: FrameSpec::Known(pose(&[1000.0, -50.0, 20.0, 0.5, 0.0, -0.2])),
                offset,
            };
            let tm = pose(&[0.0, 0.0, 250.0, 0.0, 0.0, 0.0]);
            let p = pose(&[400.0, 300.0, 200.0, 1.0, -0.5, 2.0]);
            let back = f.from_model(&f.to_model(&p, &tm), &tm);
            let (dp, dw) = super::super::pose_distance(&back, &p);
            assert!(dp < 1e-9 && dw < 1e-9, "{offset:?}: {dp} {dw}");
        }
    }

    #[test]
    #[allow(clippy::approx_constant)] // the manual's numbers
    fn pose_add_adds_positions_and_multiplies_rotations() {
        // The script manual's example: pose_add(p[.2,.5,.1,1.57,0,0], p[.2,.5,.6,1.57,0,0]) is
        // p[0.4,1.0,0.7,3.14,0,0].
        let ur = |v: [f64; 6]| crate::programs::urscript::pose_of(&v);
        let sum = Offset::Add(ur([0.2, 0.5, 0.6, 1.57, 0.0, 0.0]))
            .apply(&ur([0.2, 0.5, 0.1, 1.57, 0.0, 0.0]));
        let (dp, dw) = super::super::pose_distance(&sum, &ur([0.4, 1.0, 0.7, 3.14, 0.0, 0.0]));
        assert!(dp < 1e-9 && dw < 1e-9, "{dp} {dw}");
        // pose_trans: the second in the first's frame (the manual's example gives
        // p[0.4, -0.0996, 0.60048, 3.14, 0, 0]).
        let t = Offset::After(ur([0.2, 0.5, 0.6, 1.57, 0.0, 0.0]))
            .apply(&ur([0.2, 0.5, 0.1, 1.57, 0.0, 0.0]));
        let (dp, dw) =
            super::super::pose_distance(&t, &ur([0.4, -0.0996, 0.60048, 3.14, 0.0, 0.0]));
        assert!(dp < 0.01 && dw < 1e-9, "{dp} {dw}");
    }
}
