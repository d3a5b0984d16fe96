//! The calibration result JSON (DESIGN.md "Result JSON"): what `robocal calibrate --out` writes
//! and `fk`, `evaluate`, `compensate` and `report` read.
//!
//! The contract keys (`parameters`, `tracker_frame`, `errors`) are typed; other keys are kept in
//! [`CalibrationResult::extra`] so that a file written by a newer robocal still reads.

use crate::error::{Error, Result};
use crate::frame::{self, Frame};
use crate::model::{JointType, Param, Robot, Unit};
use crate::stats::ErrorStats;
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The value of a result's `status` key when the solver converged: a calibration.
pub const STATUS_CALIBRATED: &str = "calibrated";
/// The value of a result's `status` key when the solver did not converge and the result was kept
/// anyway (`robocal calibrate --keep-partial`): not a calibration.
pub const STATUS_PARTIAL: &str = "partial";
/// The value of a result's `status` key when the fit converged but failed the plausibility gate
/// and was kept on explicit request: not to be used for compensation unless the user accepts it
/// again there.
pub const STATUS_IMPLAUSIBLE: &str = "implausible";
/// Every `status` robocal writes; a reader refuses any other.
pub const KNOWN_STATUSES: [&str; 3] = [STATUS_CALIBRATED, STATUS_PARTIAL, STATUS_IMPLAUSIBLE];

/// Which robot a result belongs to.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotInfo {
    /// The robot's name.
    pub name: String,
    /// Number of joints.
    pub dof: usize,
    /// `"mdh"` or `"dh"`.
    pub convention: String,
    /// Each joint's type, `"revolute"` or `"prismatic"`. Empty (absent) in files written before
    /// joint types existed: all revolute.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_types: Vec<JointType>,
}

impl RobotInfo {
    /// The description of `robot`.
    pub fn of(robot: &Robot) -> RobotInfo {
        RobotInfo {
            name: robot.name().to_owned(),
            dof: robot.dof(),
            convention: robot.convention().as_str().to_owned(),
            joint_types: robot.joint_types().to_vec(),
        }
    }

    /// Checks that the joint types match `robot`'s (an absent list means all revolute); `what`
    /// describes the file's robot in the message. The error names the field `robot.joint_types`.
    pub fn check_joint_types(&self, robot: &Robot, path: &Path, what: &str) -> Result<()> {
        let mine = robot.joint_types();
        let same = if self.joint_types.is_empty() {
            mine.iter().all(|t| *t == JointType::Revolute)
        } else {
            self.joint_types == mine
        };
        if same {
            return Ok(());
        }
        let list = |v: &[JointType]| v.iter().map(|t| t.as_str()).collect::<Vec<_>>().join(", ");
        let theirs = if self.joint_types.is_empty() {
            "all revolute".to_owned()
        } else {
            list(&self.joint_types)
        };
        Err(Error::parse(
            path,
            None,
            Some("robot.joint_types"),
            format!(
                "{what} has joints {theirs}; the robot given ({}) has {}",
                robot.name(),
                list(mine)
            ),
        ))
    }
}

/// One parameter's entry: nominal and calibrated value in display units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEntry {
    /// Nominal value (mm or deg).
    pub nominal: f64,
    /// Calibrated value (mm or deg).
    pub calibrated: f64,
    /// `"mm"` or `"deg"`.
    pub unit: Unit,
    /// Whether the parameter was held at its nominal value.
    pub fixed: bool,
    /// Standard deviation of the estimate (same unit), for identified parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Why a fixed parameter was fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// A frame vector in mm and degrees, as a JSON object.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FrameVec {
    /// x (mm).
    pub x: f64,
    /// y (mm).
    pub y: f64,
    /// z (mm).
    pub z: f64,
    /// A, rotation about z (deg).
    pub a: f64,
    /// B, rotation about y (deg).
    pub b: f64,
    /// C, rotation about x (deg).
    pub c: f64,
}

impl FrameVec {
    /// From a frame.
    pub fn from_frame(f: &Frame) -> FrameVec {
        let v = frame::vec_rad_to_deg(&frame::frame_vector(f));
        FrameVec {
            x: v[0],
            y: v[1],
            z: v[2],
            a: v[3],
            b: v[4],
            c: v[5],
        }
    }

    /// To a frame.
    pub fn to_frame(&self) -> Frame {
        frame::pose(&frame::vec_deg_to_rad(&[
            self.x, self.y, self.z, self.a, self.b, self.c,
        ]))
    }
}

/// Error statistics before (nominal model, fitted frame) and after calibration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BeforeAfter {
    /// Nominal model after the measurement frame is fitted (Table II).
    pub before: ErrorStats,
    /// Calibrated model (Table IV).
    pub after: ErrorStats,
}

/// The `errors` object.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ErrorTables {
    /// On the calibration points.
    pub calibration: BeforeAfter,
    /// On the validation points (only with `--validate`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation: Option<BeforeAfter>,
}

/// A calibration result file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibrationResult {
    /// The robot the result was made for.
    pub robot: RobotInfo,
    /// Every model parameter, in model order.
    pub parameters: IndexMap<String, ParamEntry>,
    /// Pose of the tracker frame in the base frame: a measured point p maps to
    /// `pose(tracker_frame) * p`.
    pub tracker_frame: FrameVec,
    /// Error tables.
    pub errors: ErrorTables,
    /// Any further keys (identifiability, solver report, settings, ...).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

impl CalibrationResult {
    /// Reads a result file, naming the file and line on malformed JSON or missing keys.
    pub fn read(path: &Path) -> Result<CalibrationResult> {
        let text = crate::io::input::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses result JSON; `path` is used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<CalibrationResult> {
        let r: CalibrationResult = crate::io::input::parse_json(text, path, "robocal result")?;
        for (name, p) in &r.parameters {
            if !p.nominal.is_finite() || !p.calibrated.is_finite() {
                return Err(Error::parse(
                    path,
                    None,
                    Some(&format!("parameters.{name}")),
                    "not a finite number",
                ));
            }
        }
        let t = &r.tracker_frame;
        if [t.x, t.y, t.z, t.a, t.b, t.c]
            .iter()
            .any(|v| !v.is_finite())
        {
            return Err(Error::parse(
                path,
                None,
                Some("tracker_frame"),
                "not a finite number",
            ));
        }
        Ok(r)
    }

    /// Writes the result atomically as pretty JSON.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut s = serde_json::to_string_pretty(self)
            .map_err(|e| Error::Numerical(format!("cannot serialize result: {e}")))?;
        s.push('\n');
        crate::io::atomic::write_atomic(path, s.as_bytes())
    }

    /// Why this result is not a finished calibration, if it is not: its `status` is
    /// [`STATUS_PARTIAL`] (`partial_reason` says why), or its solver report says it did not
    /// converge (`solver.converged` = false). `None` for a calibration, and for files without
    /// these keys.
    pub fn partial_reason(&self) -> Option<String> {
        let status = self.extra.get("status").and_then(|s| s.as_str());
        let converged = self
            .extra
            .get("solver")
            .and_then(|s| s.get("converged"))
            .and_then(|c| c.as_bool());
        if status != Some(STATUS_PARTIAL) && converged != Some(false) {
            return None;
        }
        let reason = self.extra.get("partial_reason").and_then(|r| r.as_str());
        let termination = self
            .extra
            .get("solver")
            .and_then(|s| s.get("termination"))
            .and_then(|t| t.as_str());
        Some(match (reason, converged, termination) {
            (Some(r), _, _) => r.to_owned(),
            (None, Some(false), Some(t)) => format!("the solver {t}"),
            (None, Some(false), None) => "the solver did not converge".to_owned(),
            _ => format!("marked \"status\": \"{STATUS_PARTIAL}\""),
        })
    }

    /// The tracker frame as a rigid transform.
    pub fn tracker_frame(&self) -> Frame {
        self.tracker_frame.to_frame()
    }

    /// Applies the calibrated values to `nominal` (the robot given on the command line), checking
    /// that the result was made for a robot of the same shape. `path` names the result file in
    /// errors. Parameters like `beta2` that the result has and the robot lacks are enabled.
    pub fn calibrated_robot(&self, nominal: &Robot, path: &Path) -> Result<Robot> {
        let bad = |field: &str, msg: String| Error::parse(path, None, Some(field), msg);
        if self.robot.dof != nominal.dof() {
            return Err(bad(
                "robot.dof",
                format!(
                    "result is for a {}-joint robot ({}), the robot given has {} joints",
                    self.robot.dof,
                    self.robot.name,
                    nominal.dof()
                ),
            ));
        }
        if self.robot.convention != nominal.convention().as_str() {
            return Err(bad(
                "robot.convention",
                format!(
                    "result uses {} parameters, the robot given uses {}",
                    self.robot.convention,
                    nominal.convention().as_str()
                ),
            ));
        }
        self.robot
            .check_joint_types(nominal, path, "the result's robot")?;
        let mut r = nominal.clone();
        for name in self.parameters.keys() {
            if let Some(Param::Beta(i)) = Param::parse(name) {
                if i < r.dof() {
                    r.enable_beta(i)?;
                }
            }
        }
        for p in r.params() {
            let name = p.name();
            let Some(e) = self.parameters.get(&name) else {
                return Err(bad("parameters", format!("parameter `{name}` is missing")));
            };
            if e.unit != p.unit() {
                return Err(bad(
                    &format!("parameters.{name}.unit"),
                    format!("expected {}", p.unit().as_str()),
                ));
            }
            r.set_display(p, e.calibrated);
        }
        for name in self.parameters.keys() {
            if r.param_by_name(name).is_err() {
                return Err(bad(
                    &format!("parameters.{name}"),
                    format!("not a parameter of robot `{}`", nominal.name()),
                ));
            }
        }
        Ok(r)
    }

    /// The parameter table of a robot as result entries (nominal from `nominal`, calibrated from
    /// `calibrated`); `fixed`, `std` and `reason` are left for the caller.
    pub fn parameter_entries(nominal: &Robot, calibrated: &Robot) -> IndexMap<String, ParamEntry> {
        calibrated
            .params()
            .into_iter()
            .map(|p| {
                (
                    p.name(),
                    ParamEntry {
                        nominal: nominal.get_display_or_zero(p),
                        calibrated: calibrated.get_display(p),
                        unit: p.unit(),
                        fixed: false,
                        std: None,
                        reason: None,
                    },
                )
            })
            .collect()
    }
}
