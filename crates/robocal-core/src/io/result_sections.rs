//! The result JSON's sections beyond the DESIGN.md contract, as typed structs: what `calibrate`
//! writes ([`crate::identification::pipeline::Calibration::to_result`]) and every reader (the
//! CLI, the report) reads. Readers see exactly the schema the writer uses.
//!
//! The result writes each section through `sorted`, which orders the keys of every object
//! alphabetically, as results have always been written. The sections' structs declare their
//! fields in that order where they can (a tagged or flattened entry cannot), so that they are
//! written directly; the order of a declaration never changes the text, only the speed. A non-finite number is written as `null`
//! (JSON has no NaN) and read back as NaN ([`nullable`]).

use crate::frame::TrackerFrame;
use crate::stats::ErrorStats;
use crate::unit::Unit;
use serde::{Deserialize, Serialize, Serializer};
use std::collections::BTreeMap;

/// Writes `v` with the keys of every object in alphabetical order: directly when its keys
/// already come so ([`crate::io::result_key_order`]: the types declare their fields in that
/// order), else through a `serde_json::Value`, whose maps sort them. The text is the same.
pub(crate) fn sorted<T: Serialize, S: Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    use serde::ser::Error;
    if crate::io::result_key_order::keys_sorted(v) {
        return v.serialize(s);
    }
    serde_json::to_value(v)
        .map_err(S::Error::custom)?
        .serialize(s)
}

/// `Option<T>` written with [`sorted`] (`None` fields are skipped by the caller).
pub(crate) fn sorted_opt<T: Serialize, S: Serializer>(
    v: &Option<T>,
    s: S,
) -> Result<S::Ok, S::Error> {
    match v {
        Some(v) => sorted(v, s),
        None => s.serialize_none(),
    }
}

/// Reading `null` (a non-finite number written by serde_json) back as NaN.
pub mod nullable {
    use serde::{Deserialize, Deserializer};

    /// An `f64`, `null` as NaN.
    pub fn f64<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
    }

    /// A list of `f64`, each `null` as NaN.
    pub fn vec<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        Ok(Vec::<Option<f64>>::deserialize(d)?
            .into_iter()
            .map(|v| v.unwrap_or(f64::NAN))
            .collect())
    }
}

/// The objective a calibration minimized, as the result names it (`settings.objective`,
/// `solver.objective`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ObjectiveName {
    /// The paper's sum of error norms (eq. 4).
    #[serde(rename = "sum-of-norms")]
    SumOfNorms,
    /// The sum of squared errors.
    #[serde(rename = "least-squares")]
    LeastSquares,
    /// Least squares, then the Cauchy loss.
    #[serde(rename = "robust (Cauchy)")]
    RobustCauchy,
    /// Least squares, then with outliers down-weighted (the default).
    #[serde(rename = "adaptive")]
    Adaptive,
    /// Least squares, then the Huber loss.
    #[serde(rename = "robust (Huber)")]
    RobustHuber,
}

impl ObjectiveName {
    /// The objective as a phrase, with the paper's equation where it has one.
    pub fn phrase(self) -> &'static str {
        match self {
            ObjectiveName::SumOfNorms => "sum of displacement error norms (eq. 4)",
            ObjectiveName::LeastSquares => "sum of squared displacement errors",
            ObjectiveName::RobustCauchy => {
                "robust Cauchy loss (least squares first, then down-weighting outliers)"
            }
            ObjectiveName::RobustHuber => {
                "robust Huber loss (least squares first, then down-weighting outliers)"
            }
            ObjectiveName::Adaptive => {
                "squared displacement errors, outliers down-weighted beyond a data-scaled \
                 threshold (least squares first)"
            }
        }
    }

    /// The unit of the objective's value, where it has one (mm for a sum of norms).
    pub fn value_unit(self) -> Option<&'static str> {
        match self {
            ObjectiveName::SumOfNorms => Some("mm"),
            ObjectiveName::LeastSquares => Some("mm²"),
            ObjectiveName::RobustCauchy | ObjectiveName::RobustHuber | ObjectiveName::Adaptive => {
                None
            }
        }
    }
}

/// Rows of an input file outside the joint limits, used anyway (`settings.rows_outside_limits`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RowsOutside {
    /// The file.
    pub file: String,
    /// How many rows.
    pub rows: usize,
    /// Their lines.
    pub lines: Vec<usize>,
}

/// `settings`: how the calibration was run and on which files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// The objective minimized.
    pub objective: ObjectiveName,
    /// The robust loss's scale (mm), for a robust objective.
    pub robust_scale_mm: Option<f64>,
    /// Whether the affine registration was fitted too.
    pub affine_registration: bool,
    /// The relative rank threshold of the identifiability analysis.
    pub rank_tolerance: f64,
    /// Parameters the user held fixed.
    pub fix: Vec<String>,
    /// Parameters the user preferred.
    pub free: Vec<String>,
    /// The solver's iteration limit.
    pub max_iterations: usize,
    /// Step tolerance (mm).
    pub step_tolerance_mm: f64,
    /// Gradient tolerance.
    pub gradient_tolerance: f64,
    /// Objective tolerance.
    pub objective_tolerance: f64,
    /// The Hayati tilts that were parameters (`beta3`, ...).
    pub beta: Vec<String>,
    /// The robot argument (`--robot`) as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_arg: Option<String>,
    /// The calibration measurement file as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// The validation measurement file as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validate: Option<String>,
    /// Whether the joint limits were taken as nominal only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_limits: Option<bool>,
    /// Rows outside the joint limits that were used anyway.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rows_outside_limits: Option<Vec<RowsOutside>>,
    /// The point weights the fit used: `source` (`column`, `given`, `automatic`, `none`), the
    /// tracker model applied and the registered tracker's distance from the base (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weighting: Option<crate::observations::AppliedWeighting>,
    /// Further settings a caller recorded.
    #[serde(flatten)]
    pub other: serde_json::Map<String, serde_json::Value>,
}

impl Settings {
    /// Sets the keys of `keys` (the typed ones by their JSON names, e.g. `data`; any other
    /// into [`Settings::other`]); an error if a typed key's value has the wrong type.
    pub fn merge(
        &mut self,
        keys: serde_json::Map<String, serde_json::Value>,
    ) -> serde_json::Result<()> {
        let serde_json::Value::Object(mut all) = serde_json::to_value(&*self)? else {
            unreachable!("settings serialize as an object");
        };
        all.extend(keys);
        *self = serde_json::from_value(serde_json::Value::Object(all))?;
        Ok(())
    }
}

/// How the registration started (`registration.initial`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "source")]
pub enum InitialFrameEntry {
    /// From the plane points.
    #[serde(rename = "plane points")]
    Plane {
        /// How many.
        points: usize,
        /// Tilt of their plane (deg).
        #[serde(deserialize_with = "nullable::f64")]
        plane_tilt_deg: f64,
        /// The frame found.
        frame: FrameVec,
        /// Largest error of the plane points (mm).
        #[serde(deserialize_with = "nullable::f64")]
        max_error_mm: f64,
    },
    /// From a least-squares fit.
    #[serde(rename = "least-squares fit")]
    LeastSquares,
}

/// The registration's objective.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RegistrationObjectiveName {
    /// Sum of error norms.
    SumOfNorms,
    /// Sum of squared errors.
    LeastSquares,
}

impl RegistrationObjectiveName {
    /// `"sum-of-norms"` or `"least-squares"`, as the result writes it.
    pub fn name(self) -> &'static str {
        match self {
            RegistrationObjectiveName::SumOfNorms => "sum-of-norms",
            RegistrationObjectiveName::LeastSquares => "least-squares",
        }
    }
}

/// The paper's affine Tr (eq. 8-11), when fitted (`registration.affine`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AffineEntry {
    /// Its 12 parameters.
    #[serde(deserialize_with = "nullable::vec")]
    pub t: Vec<f64>,
    /// Singular values of its linear part.
    #[serde(deserialize_with = "nullable::vec")]
    pub singular_values: Vec<f64>,
    /// Iterations of its fit.
    pub iterations: usize,
    /// Errors after it.
    pub stats: ErrorStats,
}

/// `registration`: the measurement frame fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Registration {
    /// Its objective.
    pub objective: RegistrationObjectiveName,
    /// How it started.
    pub initial: InitialFrameEntry,
    /// Iterations.
    pub iterations: usize,
    /// The frame found.
    pub frame: FrameVec,
    /// Errors of the nominal model in it.
    pub stats: ErrorStats,
    /// The affine fit, if asked for.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub affine: Option<AffineEntry>,
    /// The frame and tools fitted to the nominal geometry before identification.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_fit: Option<ToolFitEntry>,
    /// The frame the validation points were given of their own (another tracker station).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation_frame: Option<FrameVec>,
}

/// An identified parameter (`identifiability.identified`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IdentifiedEntry {
    /// How independent of the others its effect is (0..1).
    #[serde(deserialize_with = "nullable::f64")]
    pub independence: f64,
    /// Its name.
    pub name: String,
    /// RMS effect of one unit on the points (mm per mm or deg).
    #[serde(deserialize_with = "nullable::f64")]
    pub rms_effect_mm_per_unit: f64,
    /// Its unit.
    pub unit: Unit,
}

/// Why a parameter was fixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FixKind {
    /// The user fixed it.
    User,
    /// It has no effect on the points.
    NoEffect,
    /// Its effect is that of others.
    Duplicate,
    /// The data cannot pin it (predicted std above a third of the plausible move).
    Undetermined,
    /// Held at the bound of its plausible values (a physical compliance at 0): the fit wanted a
    /// value beyond it by less than 3 standard deviations.
    AtBound,
}

/// A parameter whose effect another one duplicates, with the coefficient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DuplicateEntry {
    /// Its coefficient (unit of the fixed parameter per unit of this one).
    #[serde(deserialize_with = "nullable::f64")]
    pub coefficient: f64,
    /// The parameter.
    pub name: String,
}

/// A fixed parameter (`identifiability.fixed`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FixedEntry {
    /// For a duplicate: the parameters whose combination it is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duplicates: Option<Vec<DuplicateEntry>>,
    /// For a duplicate: how independent its effect is.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "nullable_opt"
    )]
    pub independence: Option<f64>,
    /// Why, as a kind.
    pub kind: FixKind,
    /// Its name.
    pub name: String,
    /// Why, in words.
    pub reason: String,
}

fn nullable_opt<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Ok(Some(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN)))
}

/// `identifiability`: which parameters the data identify.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Identifiability {
    /// The limit above which it is ill-conditioned.
    pub condition_limit: f64,
    /// Condition number of the scaled identification Jacobian.
    #[serde(deserialize_with = "nullable::f64")]
    pub condition_number: f64,
    /// The fixed parameters.
    pub fixed: Vec<FixedEntry>,
    /// The identified parameters.
    pub identified: Vec<IdentifiedEntry>,
    /// Whether it is.
    pub ill_conditioned: bool,
    /// How many fixed.
    pub n_fixed: usize,
    /// How many identified.
    pub n_identified: usize,
    /// The relative rank threshold.
    pub rank_tolerance: f64,
}

/// A solver stage's loss (`solver.stages[].loss` and its scale).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "loss", rename_all = "kebab-case")]
pub enum LossEntry {
    /// Smoothed sum of norms.
    SumOfNorms {
        /// Smoothing (mm).
        smoothing_mm: f64,
    },
    /// Least squares.
    LeastSquares,
    /// Huber.
    Huber {
        /// Threshold (mm).
        scale_mm: f64,
    },
    /// Cauchy.
    Cauchy {
        /// Scale (mm).
        scale_mm: f64,
    },
    /// Least squares up to the threshold, a logarithmic tail beyond.
    Adaptive {
        /// Threshold (mm).
        scale_mm: f64,
    },
}

/// One solver stage (`solver.stages[]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageEntry {
    /// Its loss.
    #[serde(flatten)]
    pub loss: LossEntry,
    /// How it ended, in words.
    pub termination: String,
    /// Whether it converged.
    pub converged: bool,
    /// Iterations.
    pub iterations: usize,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Objective before.
    #[serde(deserialize_with = "nullable::f64")]
    pub initial_objective: f64,
    /// Objective after.
    #[serde(deserialize_with = "nullable::f64")]
    pub final_objective: f64,
    /// Final gradient norm.
    #[serde(deserialize_with = "nullable::f64")]
    pub final_gradient: f64,
    /// Last step (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub last_step_mm: f64,
    /// The points the stage used when fewer than all (a large set's warm start on an even
    /// subsample); absent: every point.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<usize>,
}

/// `solver`: how the identification ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Solver {
    /// The objective.
    pub objective: ObjectiveName,
    /// How the last stage ended, in words.
    pub termination: String,
    /// Whether it converged.
    pub converged: bool,
    /// Iterations of all stages.
    pub iterations: usize,
    /// The final objective.
    #[serde(deserialize_with = "nullable::f64")]
    pub final_objective: f64,
    /// The stages.
    pub stages: Vec<StageEntry>,
}

/// A pair of correlated estimates.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrelationEntry {
    /// One parameter.
    pub a: String,
    /// The other.
    pub b: String,
    /// Their correlation.
    #[serde(deserialize_with = "nullable::f64")]
    pub rho: f64,
}

/// `uncertainty`: the estimates' covariance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Uncertainty {
    /// The most correlated pairs.
    pub most_correlated: Vec<CorrelationEntry>,
    /// The fit's sigma (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub sigma_mm: f64,
    /// Each identified parameter's standard deviation (its unit); `None` where unavailable.
    pub std: BTreeMap<String, Option<f64>>,
    /// Why standard deviations are unavailable, if they are.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_unavailable: Option<String>,
}

/// A point the robust loss down-weighted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DownweightedEntry {
    /// Its line.
    pub line: usize,
    /// Its error (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub error_mm: f64,
    /// Its orientation error (deg), for 6-DoF rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orientation_deg: Option<f64>,
    /// Its final weight.
    #[serde(deserialize_with = "nullable::f64")]
    pub weight: f64,
}

/// One point's errors. (Fields in alphabetical order: the result writes them as declared.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointEntry {
    /// Error of the calibrated model (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub after_mm: f64,
    /// Error of the nominal model (mm).
    #[serde(deserialize_with = "nullable::f64")]
    pub before_mm: f64,
    /// Its line.
    pub line: usize,
}

/// `points`: per-point errors. (Fields in alphabetical order: the result writes them as
/// declared.)
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Points {
    /// The calibration points.
    pub calibration: Vec<PointEntry>,
    /// The validation points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub validation: Option<Vec<PointEntry>>,
}

/// A tracker frame's vector in mm and degrees, as a JSON object (the form of a
/// [`TrackerFrame`] in files).
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
    /// The frame vector of a tracker frame.
    pub fn from_tracker_frame(f: &TrackerFrame) -> FrameVec {
        let v = f.vector_deg();
        FrameVec {
            x: v[0],
            y: v[1],
            z: v[2],
            a: v[3],
            b: v[4],
            c: v[5],
        }
    }

    /// The tracker frame this vector describes.
    pub fn to_tracker_frame(&self) -> TrackerFrame {
        TrackerFrame::from_vector_deg(&[self.x, self.y, self.z, self.a, self.b, self.c])
    }
}

/// `registration.tool_fit`: the frame and tool vectors fitted to the nominal geometry before
/// identification.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ToolFitEntry {
    /// The frame fitted with the tools (the result's `tracker_frame`).
    pub frame: FrameVec,
    /// Every target's fitted tool vector (mm, deg).
    pub tools: Vec<[f64; 6]>,
    /// Alternations run.
    pub iterations: usize,
    /// Whether they converged.
    pub converged: bool,
    /// Whether the calibration started from them (not when the nominal geometry misses the
    /// data by more than the plausibility gate's nominal-error limit).
    #[serde(default)]
    pub applied: bool,
    /// Errors of the nominal geometry with the fitted tools (Table II with the fitted tool).
    pub stats: ErrorStats,
}
