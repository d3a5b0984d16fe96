//! The calibration result JSON (DESIGN.md "Result JSON"): what `robocal calibrate --out` writes
//! and `fk`, `evaluate`, `compensate` and `report` read.
//!
//! The contract keys (`parameters`, `tracker_frame`, `errors`) are typed; other keys are kept in
//! [`CalibrationResult::extra`] so that a file written by a newer robocal still reads.

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
#[path = "result_checks.rs"]
mod checks;
#[path = "result_deferred.rs"]
pub(crate) mod deferred;
use crate::io::result_plausibility::PlausibilitySection;
use crate::io::result_sections::{
    sorted_opt, DownweightedEntry, Identifiability, Points, Registration, Settings, Solver,
    Uncertainty,
};
use crate::model::{Param, Robot, Unit};
use crate::stats::ErrorStats;
use checks::check_read;
pub(crate) use checks::{check_frame, check_parameters};
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

/// Why a result file is not a calibration (see [`CalibrationResult::not_calibrated`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NotCalibrated {
    /// The solver did not converge (`status` partial); the reason.
    Partial(String),
    /// The fit failed the plausibility gate (`status` implausible); the failed checks.
    Implausible(String),
}

impl NotCalibrated {
    /// `PARTIAL` or `IMPLAUSIBLE`, for warnings and labels.
    pub fn label(&self) -> &'static str {
        match self {
            NotCalibrated::Partial(_) => "PARTIAL",
            NotCalibrated::Implausible(_) => "IMPLAUSIBLE",
        }
    }

    /// The reason.
    pub fn reason(&self) -> &str {
        match self {
            NotCalibrated::Partial(r) | NotCalibrated::Implausible(r) => r,
        }
    }
}

pub use super::result_robot::RobotInfo;

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

pub use super::result_sections::FrameVec;

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
    /// Points the robust loss down-weighted.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub downweighted_points: Option<Vec<DownweightedEntry>>,
    /// Which parameters the data identify.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub identifiability: Option<Identifiability>,
    /// Why the fit failed the plausibility gate (with `status` implausible).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub implausible_reason: Option<String>,
    /// The input files (robot, data, validation) with their paths and SHA-256
    /// ([`crate::io::inputs`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs: Option<crate::io::inputs::Inputs>,
    /// Why the result is partial (with `status` partial).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub partial_reason: Option<String>,
    /// The plausibility gate's checks.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub plausibility: Option<PlausibilitySection>,
    /// Orientation errors of 6-DoF data (deg).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_errors: Option<super::result_cell::OrientationErrors>,
    /// Per-point errors. Written directly, not through `sorted_opt`: its structs declare their
    /// fields in alphabetical order, and a million points through a `serde_json::Value` took
    /// 600 MB.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "deferred::points",
        deserialize_with = "crate::io::result_skim::option"
    )]
    pub points: Option<Points>,
    /// The predicted accuracy at new poses.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub prediction: Option<crate::io::result_prediction::PredictionSection>,
    /// The measurement frame fit.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub registration: Option<Registration>,
    /// How the calibration was run.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub settings: Option<Settings>,
    /// How the identification ended.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub solver: Option<Solver>,
    /// Whether the result is a calibration; required on reading ([`KNOWN_STATUSES`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status: Option<StatusValue>,
    /// The automatic model choice (`--model auto`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_selection: Option<super::result_selection::ModelSelectionSection>,
    /// The estimates' covariance.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        serialize_with = "sorted_opt"
    )]
    pub uncertainty: Option<Uncertainty>,
    /// Any further keys (from a newer robocal, or another tool).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// What a result can be: its `status`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// [`STATUS_CALIBRATED`].
    Calibrated,
    /// [`STATUS_PARTIAL`].
    Partial,
    /// [`STATUS_IMPLAUSIBLE`].
    Implausible,
}

impl Status {
    /// The JSON value: one of [`KNOWN_STATUSES`].
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Calibrated => STATUS_CALIBRATED,
            Status::Partial => STATUS_PARTIAL,
            Status::Implausible => STATUS_IMPLAUSIBLE,
        }
    }
}

/// A `status` as read: one robocal writes, or anything else (refused by
/// [`CalibrationResult::parse`] with a message naming it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum StatusValue {
    /// A status robocal writes.
    Known(Status),
    /// Any other JSON value.
    Other(serde_json::Value),
}

impl CalibrationResult {
    /// Reads a result file, naming the file and line on malformed JSON or missing keys.
    pub fn read(path: &Path) -> Result<CalibrationResult> {
        let text = crate::io::input::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses result JSON; `path` is used in messages. Beyond the JSON's shape it checks that
    /// the `status` is one robocal writes ([`KNOWN_STATUSES`]) and that every number is within
    /// its plausible range ([`crate::ranges`]): parameters, tracker frame and error statistics.
    pub fn parse(text: &str, path: &Path) -> Result<CalibrationResult> {
        Ok(Self::parse_with_nominal(text, path)?.0)
    }

    /// [`CalibrationResult::parse`], with the nominal robot the result describes (when it
    /// describes one).
    fn parse_with_nominal(
        text: &str,
        path: &Path,
    ) -> Result<(CalibrationResult, Option<crate::model::Robot>)> {
        let r: CalibrationResult = crate::io::input::parse_json(text, path, "robocal result")?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        check_read(r, text, path)
    }

    /// Reads back `text`, which [`CalibrationResult::to_text`] just made of `self`, with the
    /// checks of [`CalibrationResult::parse`]. The text of a result without [`extra`] keys has
    /// no key twice in one object: the struct's fields are distinct, its maps (`parameters`, the
    /// sorted sections written through a `serde_json::Value`) hold each key once, and only the
    /// flattened `extra` could repeat a field's name. Such text is parsed directly (the
    /// duplicate-key pass and the key-path tracking add nothing to it); anything else, or text
    /// that does not parse, takes the whole reading path, whose messages name the field.
    ///
    /// The per-point sections are skimmed on that direct path (`io::result_skim`).
    ///
    /// [`extra`]: CalibrationResult::extra
    fn read_back(&self, text: &str, path: &Path) -> Result<(CalibrationResult, Option<Robot>)> {
        if self.extra.is_empty() {
            let skimmed = crate::io::result_skim::skimming(|| {
                serde_json::from_str::<CalibrationResult>(text)
            });
            if let Ok(r) = skimmed {
                crate::io::result_skim::finite_map(self.prediction.as_ref())?;
                return check_read(r, text, path);
            }
        }
        Self::parse_with_nominal(text, path)
    }

    /// The result's text as robocal writes it: pretty JSON with each per-point entry on one
    /// line, ending with a newline. Every writer of a result (the CLI, the demo's files, the
    /// Python bindings) uses it, so that the same result is the same bytes wherever it is made.
    /// The per-point sections are written apart and put in place (`io::result_deferred`); the
    /// bytes are those of serializing the whole result.
    pub fn to_text(&self) -> Result<String> {
        Ok(match deferred::split(self, || self.serialized_text())? {
            Some(d) => d.text(),
            None => self.serialized_text()?,
        })
    }

    /// [`CalibrationResult::to_text`] made by serializing the whole result with serde_json.
    fn serialized_text(&self) -> Result<String> {
        // Sized for the per-point entries (one line of at most about 90 bytes each: two errors
        // written to the last digit and a line number), so that a million points' text is
        // neither copied as it grows nor given twice the room it needs. A skeleton
        // (`io::result_deferred`) has none, and its other sections take a few tens of kB.
        let capacity = if deferred::deferring() {
            1 << 16
        } else {
            let points = self.points.as_ref().map_or(0, |p| {
                p.calibration.len() + p.validation.as_ref().map_or(0, Vec::len)
            });
            (1 << 17) + 92 * points
        };
        let mut buf = Vec::with_capacity(capacity);
        let mut ser = serde_json::Serializer::with_formatter(
            &mut buf,
            crate::io::result_format::ResultFormatter::new(),
        );
        serde::Serialize::serialize(self, &mut ser)
            .map_err(|e| Error::Numerical(format!("cannot serialize result: {e}")))?;
        buf.push(b'\n');
        String::from_utf8(buf)
            .map_err(|e| Error::Numerical(format!("cannot serialize result: {e}")))
    }

    /// Writes the result atomically as pretty JSON (each per-point entry on one line), after
    /// reading the text back as every command that takes a result does
    /// ([`CalibrationResult::parse`], then the calibrated model): what robocal writes, robocal
    /// reads. A result its readers would refuse (a value outside its range) is not written:
    /// [`Error::Implausible`] names the field.
    ///
    /// The text read back is the one without its per-point sections (`io::result_deferred`
    /// says why that is the same check); when it does not pass, the whole text is read back,
    /// and its verdict and message are the ones given.
    pub fn write(&self, path: &Path) -> Result<()> {
        let text = match deferred::split(self, || self.serialized_text())? {
            Some(d) if self.skeleton_readable(&d.skeleton, path).is_ok() => {
                let pieces: Vec<&[u8]> = d.pieces().iter().map(|p| p.as_bytes()).collect();
                return crate::io::atomic::write_atomic_parts(path, &pieces);
            }
            Some(d) => self.readable(d.text(), path)?,
            None => self.readable(self.serialized_text()?, path)?,
        };
        crate::io::atomic::write_atomic(path, text.as_bytes())
    }

    /// Whether the skeleton of this result's text (`io::result_deferred`) reads back and its
    /// calibrated model can be made. Its errors are not shown: on any, the whole text is read.
    fn skeleton_readable(&self, skeleton: &str, path: &Path) -> Result<()> {
        let r: CalibrationResult = serde_json::from_str(skeleton)
            .map_err(|e| Error::Numerical(format!("skeleton: {e}")))?;
        crate::io::result_skim::finite_map(self.prediction.as_ref())?;
        let (back, nominal) = check_read(r, skeleton, path)?;
        match nominal {
            Some(nominal) => back.calibrated_robot(&nominal, path).map(|_| ()),
            None => Ok(()),
        }
    }

    /// `text`, which [`CalibrationResult::to_text`] made of `self`, when it reads back and its
    /// calibrated model can be made; else [`Error::Implausible`] with the reader's message.
    fn readable(&self, text: String, path: &Path) -> Result<String> {
        let readable = self
            .read_back(&text, path)
            .and_then(|(back, nominal)| match nominal {
                Some(nominal) => back.calibrated_robot(&nominal, path).map(|_| ()),
                None => Ok(()),
            });
        if let Err(e) = readable {
            return Err(Error::Implausible(format!(
                "the result cannot be right: robocal's own readers (evaluate, compensate, report, \
                 export, fk) would refuse it, so it is not written: {e}"
            )));
        }
        Ok(text)
    }

    /// Why this result is not a finished calibration, if it is not: its `status` is
    /// [`STATUS_PARTIAL`] (`partial_reason` says why), or its solver report says it did not
    /// converge (`solver.converged` = false). `None` for a calibration, and for files without
    /// these keys.
    pub fn partial_reason(&self) -> Option<String> {
        let converged = self.solver.as_ref().map(|s| s.converged);
        if self.status() != Some(Status::Partial) && converged != Some(false) {
            return None;
        }
        let termination = self.solver.as_ref().map(|s| s.termination.as_str());
        Some(match (&self.partial_reason, converged, termination) {
            (Some(r), _, _) => r.clone(),
            (None, Some(false), Some(t)) => format!("the solver {t}"),
            (None, Some(false), None) => "the solver did not converge".to_owned(),
            _ => format!("marked \"status\": \"{STATUS_PARTIAL}\""),
        })
    }

    /// Why this result failed the plausibility gate, if it did: its `status` is
    /// [`STATUS_IMPLAUSIBLE`] (`calibrate` wrote it on explicit request); `implausible_reason`
    /// lists the failed checks.
    pub fn implausible_reason(&self) -> Option<String> {
        if self.status() != Some(Status::Implausible) {
            return None;
        }
        Some(
            self.implausible_reason
                .clone()
                .unwrap_or_else(|| "it failed the plausibility gate".to_owned()),
        )
    }

    /// The `status`, when it is one robocal writes.
    pub fn status(&self) -> Option<Status> {
        match self.status {
            Some(StatusValue::Known(s)) => Some(s),
            _ => None,
        }
    }

    /// A result of the contract keys alone (no further sections), with `status`.
    pub fn new(
        robot: RobotInfo,
        parameters: IndexMap<String, ParamEntry>,
        tracker_frame: FrameVec,
        errors: ErrorTables,
        status: Status,
    ) -> CalibrationResult {
        CalibrationResult {
            robot,
            parameters,
            tracker_frame,
            errors,
            downweighted_points: None,
            model_selection: None,
            identifiability: None,
            implausible_reason: None,
            inputs: None,
            partial_reason: None,
            plausibility: None,
            points: None,
            prediction: None,
            registration: None,
            orientation_errors: None,
            settings: None,
            solver: None,
            status: Some(StatusValue::Known(status)),
            uncertainty: None,
            extra: serde_json::Map::new(),
        }
    }

    /// Why this result is not a calibration to use, if it is not: partial
    /// ([`CalibrationResult::partial_reason`]) before implausible
    /// ([`CalibrationResult::implausible_reason`]).
    pub fn not_calibrated(&self) -> Option<NotCalibrated> {
        self.partial_reason()
            .map(NotCalibrated::Partial)
            .or_else(|| self.implausible_reason().map(NotCalibrated::Implausible))
    }

    /// The tracker frame: measured points map into the base frame with
    /// [`TrackerFrame::to_base`].
    pub fn tracker_frame(&self) -> TrackerFrame {
        self.tracker_frame.to_tracker_frame()
    }

    /// The frame of the nominal model's errors (Table II): the registration's frame when the
    /// result records it, else [`CalibrationResult::tracker_frame`].
    pub fn nominal_frame(&self) -> TrackerFrame {
        self.registration
            .as_ref()
            .map_or_else(|| self.tracker_frame(), |r| r.frame.to_tracker_frame())
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
            if let Some(p) = Param::parse(name) {
                r.enable_param(p)?;
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
        crate::io::result_payload::apply(self, &mut r, path)?;
        crate::io::result_thermal::apply(self, &mut r, path)?;
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

#[cfg(test)]
#[path = "result_tests.rs"]
mod tests;
