//! Robot programs: every target of a controller program replaced by its compensated value, in the
//! controller's own units and axis conventions, everything else kept byte for byte.
//!
//! A format's reader finds the targets and the byte spans of their numeric fields
//! ([`ProgramTarget`]); [`compensate_program`] compensates each (full pose by default, see
//! [`crate::compensation`]) and splices the new numbers into exactly those spans, so the text
//! outside them is unchanged. Formats ([`Format`]): KUKA KRL ([`krl`]), ABB RAPID ([`rapid`]),
//! URScript ([`urscript`]). The readers are hand-written: no maintained Rust parser exists for
//! these languages, and robocal needs only their targets.
//!
//! - **Joint targets** (KRL AXIS/E6AXIS, RAPID jointtarget, URScript joint lists): the
//!   controller's axis values (deg; URScript rad) go through the robot's controller map
//!   ([`crate::model::JointSpace::joints_from_axes`]; the KUKA presets: q = (-A1, A2, A3, -A4,
//!   A5, -A6); robots without a map: the identity) to the desired model joints; the commanded
//!   joints go back to axis values.
//! - **Cartesian targets** (KRL POS/E6POS/FRAME, RAPID robtarget, URScript `p[...]`): the pose
//!   is in the base and for the tool in force at the motions that use it ([`frames`]: KRL
//!   `$TOOL`/`$BASE`, `BAS`, `FDAT_ACT`, `TOOL_DATA[n]`/`BASE_DATA[n]` of a `$config.dat`; RAPID
//!   tooldata and wobjdata; URScript `set_tcp`), mapped to the model's tool frame in its base
//!   frame; a frame robocal cannot resolve leaves the target unchanged ("frame unknown"), never
//!   compensated in another frame. The desired joints are the nominal model's inverse
//!   kinematics on the branch the target's configuration data give ([`seed::Branch`]: KRL `S`
//!   and `T`, RAPID confdata; a URScript pose, which has none, takes the solution nearest the
//!   previous target's joints, as the controller takes the one nearest its current joints). The
//!   compensated pose written is the nominal model's pose at the commanded joints, so that the
//!   controller, which believes the nominal model, drives the robot to the commanded joints.
//!   The configuration data are kept, and must still hold at the commanded joints
//!   ([`IkStatus::ConfigurationChange`] otherwise), with one exception: a KRL `T` follows an
//!   axis that compensation moves across 0 from within 1 degree of it (a target at A4 = 0 may
//!   need A4 = -0.002).
//!
//! Every motion statement is counted by a scan independent of the readers ([`census`]), and
//! reported compensated or unchanged with its reason ([`CompensatedProgram::motions`]).
//!
//! Numbers are written as precisely as the controller stores them ([`digits`]: 32-bit floats for
//! KRL and RAPID, 9 decimals for URScript), and every written target is verified as the
//! controller stores it: read back as the controller would (joints, or the nominal inverse
//! kinematics of the written pose from the commanded joints, on the target's branch), the
//! calibrated model's tool must be within [`ProgramSettings::verify_mm`] and
//! [`ProgramSettings::verify_deg`] of the desired pose.

pub mod census;
pub mod census_krl;
pub mod census_rapid;
pub mod census_ur;
mod compensate;
pub mod digits;
pub mod frames;
pub mod krl;
mod krl_aggregate;
mod lex;
pub mod rapid;
pub mod seed;
mod target_solve;
pub mod urscript;

use crate::compensation::IkStatus;
use crate::error::{Error, Result};
use crate::frame::Frame;
use census::{MotionOutcome, MotionReport};
use digits::Precision;
use seed::Branch;
use std::ops::Range;
use std::path::{Path, PathBuf};

pub use compensate::compensate_program;

pub use seed::turn_of;

/// One numeric field of a target: its name in the program, its value, its byte span.
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// The field's name (`A1`, `X`, `q1`, ...).
    pub name: String,
    /// Its value as written (controller units).
    pub value: f64,
    /// Its byte range in the program text.
    pub span: Range<usize>,
}

/// What a target holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TargetKind {
    /// Controller axis values.
    Joints,
    /// A Cartesian pose (the format's units and orientation representation).
    Pose,
}

/// A target found in a program.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramTarget {
    /// Its name (the variable it is declared as, or the motion command).
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// Joints or pose.
    pub kind: TargetKind,
    /// The numeric fields compensation replaces, in order (`A1..A6`, `X, Y, Z, A, B, C`, ...).
    pub fields: Vec<Field>,
    /// KRL's turn `T`, when given.
    pub turn: Option<u32>,
    /// The byte range of the turn's value.
    pub turn_span: Option<Range<usize>>,
    /// KRL's status `S`, when given.
    pub status: Option<u32>,
    /// RAPID's confdata `[cf1, cf4, cf6, cfx]`, for a robtarget.
    pub conf: Option<[i64; 4]>,
    /// Index of the file it is in ([`Source`]; 0: the program, 1: a KRL `.dat`).
    pub file: usize,
}

impl ProgramTarget {
    /// The branch a Cartesian target asks for; `previous`: the joints (model values, rad) of the
    /// target before it in the program, for a target without configuration data.
    pub fn branch(&self, previous: Option<&[f64]>) -> Branch {
        if let Some(c) = self.conf {
            Branch::Rapid(c)
        } else if self.turn.is_some() || self.status.is_some() {
            Branch::Krl {
                status: self.status,
                turn: self.turn,
            }
        } else if let Some(p) = previous {
            Branch::Nearest(p.to_vec())
        } else {
            Branch::Any
        }
    }
}

/// A program format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// KUKA KRL (`.src`, `.dat`).
    Krl,
    /// ABB RAPID (`.mod`, `.modx`, `.prg`).
    Rapid,
    /// Universal Robots URScript (`.script`, `.urscript`).
    UrScript,
}

impl Format {
    /// The format of a program file, from its extension.
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("src") | Some("dat") => Ok(Format::Krl),
            Some("mod") | Some("modx") | Some("prg") => Ok(Format::Rapid),
            Some("script") | Some("urscript") => Ok(Format::UrScript),
            _ => Err(Error::invalid(
                "program",
                format!(
                    "{}: unknown program format from its extension (known: KUKA KRL .src/.dat, \
                     ABB RAPID .mod/.modx/.prg, URScript .script/.urscript)",
                    path.display()
                ),
            )),
        }
    }

    /// The targets of a program text, in file order; `path` names the program in errors (a
    /// malformed target: its line and field).
    pub fn targets(self, path: &Path, text: &str) -> Result<Vec<ProgramTarget>> {
        match self {
            Format::Krl => krl::targets(path, text),
            Format::Rapid => rapid::targets(path, text),
            Format::UrScript => urscript::targets(path, text),
        }
    }

    /// The tool frame (mm) of a Cartesian target's values.
    pub fn pose_of(self, values: &[f64]) -> Frame {
        match self {
            Format::Krl => krl::pose_of(values),
            Format::Rapid => rapid::pose_of(values),
            Format::UrScript => urscript::pose_of(values),
        }
    }

    /// The values of a Cartesian target at tool frame `f`, written like `old` (the target's
    /// values in the input: quaternion sign, rotation vector turn).
    pub fn pose_values(self, f: &Frame, old: &[f64]) -> Vec<f64> {
        match self {
            Format::Krl => krl::pose_values(f),
            Format::Rapid => rapid::pose_values(f, old),
            Format::UrScript => urscript::pose_values(f, old),
        }
    }

    /// Controller axis values in the robot's display units (deg, mm) from a joint target's values.
    pub fn axes_of(self, values: &[f64]) -> Vec<f64> {
        match self {
            Format::UrScript => values.iter().map(|v| v.to_degrees()).collect(),
            _ => values.to_vec(),
        }
    }

    /// A joint target's values from controller axis values (display units).
    pub fn joint_values(self, axes: &[f64]) -> Vec<f64> {
        match self {
            Format::UrScript => axes.iter().map(|v| v.to_radians()).collect(),
            _ => axes.to_vec(),
        }
    }

    /// How field `i` of a target of `kind` is stored and written ([`digits`]).
    pub fn precision(self, _kind: TargetKind, _i: usize) -> Precision {
        match self {
            Format::UrScript => Precision::Decimals(9),
            _ => Precision::F32,
        }
    }

    /// Refuses a program whose content is another dialect than its extension says (a RAPID
    /// module saved as `.src`, KRL saved as `.mod`): its first statement decides.
    pub fn check_dialect(self, path: &Path, text: &str) -> Result<()> {
        let first = text
            .lines()
            .map(str::trim)
            .find(|l| {
                !l.is_empty()
                    && !l.starts_with(';')
                    && !l.starts_with('&')
                    && !l.starts_with('!')
                    && !l.starts_with('%')
                    && !l.starts_with('#')
            })
            .unwrap_or("");
        let word = first
            .split(|c: char| !c.is_ascii_alphanumeric() && c != '_')
            .next()
            .unwrap_or("")
            .to_ascii_uppercase();
        let is = match word.as_str() {
            "MODULE" => Some(Format::Rapid),
            "DEF" | "DEFDAT" | "DEFFCT" | "GLOBAL" => Some(Format::Krl),
            _ => None,
        };
        match is {
            Some(f) if f != self && !(self == Format::UrScript && word == "DEF") => {
                Err(Error::parse(
                    path,
                    None,
                    None,
                    format!(
                        "the extension says {}, but the text is {} (it starts with `{}`): save \
                         it with that format's extension",
                        self.name(),
                        f.name(),
                        first.split_whitespace().next().unwrap_or("")
                    ),
                ))
            }
            _ => Ok(()),
        }
    }

    /// The format's name.
    pub fn name(self) -> &'static str {
        match self {
            Format::Krl => "KUKA KRL",
            Format::Rapid => "ABB RAPID",
            Format::UrScript => "URScript",
        }
    }
}

/// How a program is compensated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProgramSettings {
    /// Whole pose (default) or position only.
    pub full_pose: bool,
    /// Largest position error (mm) of a written target after rounding. Default 0.01: a joint
    /// rounded to 5e-5 deg moves the tool of a 3.6 m arm by up to 3e-3 mm.
    pub verify_mm: f64,
    /// Largest orientation error (deg) of a written target after rounding. Default 0.001.
    pub verify_deg: f64,
}

impl Default for ProgramSettings {
    fn default() -> Self {
        ProgramSettings {
            full_pose: true,
            verify_mm: 0.01,
            verify_deg: 0.001,
        }
    }
}

/// What happened to one target.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// The target's name.
    pub name: String,
    /// 1-based line.
    pub line: usize,
    /// Index of the file it is in ([`Source`]; 0: the program, 1: a KRL `.dat`).
    pub file: usize,
    /// Joints or pose.
    pub kind: TargetKind,
    /// The values as written in the input (controller units).
    pub old: Vec<f64>,
    /// The values written to the output (after rounding; the old ones when not applied).
    pub new: Vec<f64>,
    /// The correction: position (mm) and angle (deg) between the nominal tool poses of the old
    /// and the new values.
    pub correction_mm: f64,
    /// See [`Change::correction_mm`].
    pub correction_deg: f64,
    /// How the compensation ended.
    pub status: IkStatus,
    /// The verified error of the written target on the calibrated model (mm, deg): see the
    /// module documentation. Infinite when the target was not compensated.
    pub verified_mm: f64,
    /// See [`Change::verified_mm`].
    pub verified_deg: f64,
    /// The turn written (KRL `T` of the commanded joints), when the target has one.
    pub new_turn: Option<u32>,
    /// Whether the output holds the new values (false for a target that could not be
    /// compensated: left unchanged).
    pub applied: bool,
    /// Why the target was not tried (a frame robocal cannot resolve), when it was not.
    pub skipped: Option<String>,
}

/// One file of a program.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    /// Its path (in messages).
    pub path: PathBuf,
    /// Its text.
    pub text: String,
}

/// A compensated program.
#[derive(Debug, Clone, PartialEq)]
pub struct CompensatedProgram {
    /// The output texts, one per [`Source`]: the input with the applied targets' fields
    /// replaced.
    pub texts: Vec<String>,
    /// Every target, in file order (the program's, then its `.dat`'s).
    pub changes: Vec<Change>,
    /// Every motion statement of the program, in order, with what became of it.
    pub motions: Vec<MotionReport>,
}

impl CompensatedProgram {
    /// The motions left unchanged.
    pub fn unchanged_motions(&self) -> impl Iterator<Item = &MotionReport> {
        self.motions
            .iter()
            .filter(|m| m.outcome != MotionOutcome::Compensated)
    }
}

/// Position (mm) and angle (deg) between two frames.
pub fn pose_distance(a: &Frame, b: &Frame) -> (f64, f64) {
    let r = a.rotation.matrix().transpose() * b.rotation.matrix();
    let w = crate::compensation::rotation_angle(&r);
    (
        (a.translation.vector - b.translation.vector).norm(),
        w.to_degrees(),
    )
}

#[cfg(test)]
mod offset_tests;
#[cfg(test)]
mod tests;
