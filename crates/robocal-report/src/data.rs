//! What a report shows: plain structs that a caller fills from a calibration run (or a result
//! file) and hands to [`crate::write_report`]. Nothing here computes a calibration.
//!
//! Units: millimetres and degrees, as everywhere at robocal's interfaces. Error values that are
//! missing or failed are `NaN` (in JSON: `null`); plots and tables skip them and say how many.

use robocal_core::{ErrorStats, Unit};
use serde::{Deserialize, Serialize};

/// Everything a report shows. Every section is optional: an empty list or `None` leaves its
/// section out (or shows a short "not available" line where the reader would look for it).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ReportData {
    /// The report's title, e.g. "KUKA KR 480 R3330 — simulated calibration".
    pub title: String,
    /// One line under the title (robot, data files...). Never an absolute path of the machine
    /// that made the report: file names only.
    pub subtitle: Option<String>,
    /// What identifies the calibration, shown under the title: robot serial, tracker,
    /// reflector, operator, temperature, notes, dates (in the order given; empty values are
    /// left out).
    pub metadata: Vec<Setting>,
    /// Units of the joint values in [`PointDetail::joints`] (degrees for a revolute joint, mm for
    /// a prismatic one): one per joint, for the error-against-joint panels.
    pub joint_units: Vec<Unit>,
    /// Add the table of every point's errors (long for large sets: on demand).
    pub point_table: bool,
    /// Settings of the run, shown in order (seed, point counts, noise, files, ...).
    pub settings: Vec<Setting>,
    /// Error statistics tables (the paper's Tables II, IV and V).
    pub error_tables: Vec<ErrorTable>,
    /// The series of the error histogram (the paper's Fig. 2), usually "before" and "after".
    /// All series share the same bin edges.
    pub histogram: Vec<HistogramSeries>,
    /// Per-point errors of each point set, for the error-against-reach plot.
    pub point_sets: Vec<PointSet>,
    /// What the reach of a point ([`PointError::reach_mm`]) measures.
    pub reach: ReachKind,
    /// Model parameters in model order: nominal, calibrated, standard deviation, fixed.
    pub parameters: Vec<ParamRow>,
    /// Which parameters could be identified and how well.
    pub identifiability: Option<Identifiability>,
    /// How the solver ended.
    pub solver: Option<SolverSummary>,
    /// Warnings and notes, shown near the top.
    pub notes: Vec<Note>,
    /// Orientation errors of 6-DoF measurements (the angle of `R_measured R_model^T`, deg): one
    /// row per point set and model; empty for point data.
    pub orientation: Vec<AngleRow>,
    /// ISO 9283 acceptance tests (e.g. before and after calibration); empty: no section.
    pub iso9283: Vec<crate::iso_results::IsoTest>,
}

/// One row of the orientation-error table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AngleRow {
    /// Which points and which model, e.g. "Calibration, nominal model".
    pub label: String,
    /// Number of points.
    pub n: usize,
    /// Mean, sample standard deviation, maximum and RMS of the angles (deg).
    pub mean_deg: f64,
    /// See [`AngleRow::mean_deg`].
    pub std_deg: f64,
    /// See [`AngleRow::mean_deg`].
    pub max_deg: f64,
    /// See [`AngleRow::mean_deg`].
    pub rms_deg: f64,
}

/// A key/value line of the run's settings.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Setting {
    /// What, e.g. "Seed".
    pub key: String,
    /// Its value as shown, with units, e.g. "0.010 mm + 5 µm/m".
    pub value: String,
}

impl Setting {
    /// A setting line.
    pub fn new(key: impl Into<String>, value: impl ToString) -> Setting {
        Setting {
            key: key.into(),
            value: value.to_string(),
        }
    }
}

/// A table of error statistics, e.g. "Before calibration (Table II)".
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorTable {
    /// The table's heading.
    pub title: String,
    /// A sentence under the table saying what the figures are.
    #[serde(default)]
    pub caption: Option<String>,
    /// One row per point set.
    pub rows: Vec<ErrorRow>,
}

/// One row of an [`ErrorTable`]: our statistics of one point set, and optionally the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorRow {
    /// The point set, e.g. "Calibration points".
    pub label: String,
    /// Our figures (`n = 0` and NaN figures show as dashes).
    pub stats: ErrorStats,
    /// The paper's figures for the same row, shown beside ours.
    #[serde(default)]
    pub paper: Option<PaperStats>,
}

impl ErrorRow {
    /// A row without reference figures.
    pub fn new(label: impl Into<String>, stats: ErrorStats) -> ErrorRow {
        ErrorRow {
            label: label.into(),
            stats,
            paper: None,
        }
    }

    /// The same row with the paper's figures beside it.
    pub fn with_paper(mut self, paper: PaperStats) -> ErrorRow {
        self.paper = Some(paper);
        self
    }
}

/// Reference figures from a publication (the paper gives only mean, std and max).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperStats {
    /// Where the figures come from, e.g. "Samak et al. 2019, Table II".
    pub source: String,
    /// Number of points.
    #[serde(default)]
    pub n: Option<usize>,
    /// Mean error (mm).
    #[serde(default)]
    pub mean_mm: Option<f64>,
    /// Standard deviation (mm).
    #[serde(default)]
    pub std_mm: Option<f64>,
    /// Largest error (mm).
    #[serde(default)]
    pub max_mm: Option<f64>,
    /// Root mean square (mm).
    #[serde(default)]
    pub rms_mm: Option<f64>,
    /// 95th percentile (mm).
    #[serde(default)]
    pub p95_mm: Option<f64>,
}

/// One series of the error histogram.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HistogramSeries {
    /// Legend text, e.g. "Before calibration (calibration points)".
    pub label: String,
    /// Error norms (mm). Non-finite values are skipped and counted.
    #[serde(with = "crate::serde_nan::vec")]
    pub values_mm: Vec<f64>,
}

impl HistogramSeries {
    /// A series.
    pub fn new(label: impl Into<String>, values_mm: Vec<f64>) -> HistogramSeries {
        HistogramSeries {
            label: label.into(),
            values_mm,
        }
    }
}

/// The errors of one set of points (calibration, validation, verification...).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointSet {
    /// The set's name, e.g. "Calibration" (shown as "Calibration points").
    pub name: String,
    /// Its points.
    pub points: Vec<PointError>,
    /// Where each point is and its error vectors, in the order of `points` (empty when not
    /// known, e.g. a report from a result file without its measurements): the per-axis,
    /// per-joint and workspace views need them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub details: Vec<PointDetail>,
}

impl PointSet {
    /// A set without point details.
    pub fn new(name: impl Into<String>, points: Vec<PointError>) -> PointSet {
        PointSet {
            name: name.into(),
            points,
            details: Vec::new(),
        }
    }
}

/// Where one point is and its error vectors (base frame, mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointDetail {
    /// The joint values of the pose (degrees, mm for a prismatic joint).
    pub joints: Vec<f64>,
    /// The tool point of the nominal model at these joints (mm, base frame): where the point
    /// is in the workspace.
    #[serde(with = "crate::serde_nan::arr3")]
    pub position_mm: [f64; 3],
    /// Error vector E = P_act − P_ref before calibration (NaN components when not available).
    #[serde(with = "crate::serde_nan::arr3")]
    pub before_mm: [f64; 3],
    /// Error vector after calibration (or, for a verification set, as measured after
    /// compensation).
    #[serde(with = "crate::serde_nan::arr3")]
    pub after_mm: [f64; 3],
}

/// The error of one point before and after calibration, and where the point is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointError {
    /// Reach of the tool point (mm), see [`ReachKind`].
    #[serde(with = "crate::serde_nan::one")]
    pub reach_mm: f64,
    /// Error norm with the nominal model after the measurement frame is fitted (mm); NaN if not
    /// available.
    #[serde(with = "crate::serde_nan::one")]
    pub before_mm: f64,
    /// Error norm with the calibrated model (or, for a verification set, as measured after
    /// compensation) (mm); NaN if not available.
    #[serde(with = "crate::serde_nan::one")]
    pub after_mm: f64,
}

/// What "reach" means on the error-against-reach plot.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReachKind {
    /// Distance of the tool point from the base z axis (horizontal reach).
    #[default]
    Radial,
    /// Distance of the tool point from the base origin.
    Spherical,
}

impl ReachKind {
    /// The reach of a tool point `p` = (x, y, z) in the base frame (mm).
    pub fn of(self, p: [f64; 3]) -> f64 {
        match self {
            ReachKind::Radial => p[0].hypot(p[1]),
            ReachKind::Spherical => (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt(),
        }
    }

    /// Axis label, with the unit.
    pub fn axis_label(self) -> &'static str {
        match self {
            ReachKind::Radial => "Reach from the base z axis (mm)",
            ReachKind::Spherical => "Distance from the base origin (mm)",
        }
    }

    /// What the reach is, in words.
    pub fn description(self) -> &'static str {
        match self {
            ReachKind::Radial => "distance of the tool point from the base z axis",
            ReachKind::Spherical => "distance of the tool point from the base origin",
        }
    }
}

/// One model parameter: nominal and calibrated value, in mm or degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamRow {
    /// Name as in DESIGN.md (`d3`, `base_x`, `tool_c`...).
    pub name: String,
    /// Unit of the values.
    pub unit: Unit,
    /// Nominal value.
    pub nominal: f64,
    /// Calibrated value (equal to nominal for a fixed parameter).
    pub calibrated: f64,
    /// Standard deviation of the estimate, for identified parameters.
    #[serde(default)]
    pub std: Option<f64>,
    /// Whether the parameter was held at its nominal value.
    #[serde(default)]
    pub fixed: bool,
    /// Why it was fixed.
    #[serde(default)]
    pub reason: Option<String>,
    /// The true value, where it is known (a simulation), in the same parameterization as the
    /// calibration (see `robocal_core::experiment::TruthComparison`): shown in a column of its
    /// own beside the calibrated value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truth: Option<f64>,
}

impl ParamRow {
    /// Calibrated minus nominal; for angles wrapped to (-180, 180] degrees.
    pub fn difference(&self) -> f64 {
        let d = self.calibrated - self.nominal;
        match self.unit {
            Unit::Mm | Unit::MicroradPerNm | Unit::MicroradPerM | Unit::PpmPerK => d,
            Unit::Deg => {
                let w = d.rem_euclid(360.0);
                if w > 180.0 {
                    w - 360.0
                } else {
                    w
                }
            }
        }
    }
}

/// Which parameters could be identified from the measurements, and how well.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Identifiability {
    /// Condition number of the scaled identification Jacobian of the identified parameters.
    pub condition_number: Option<f64>,
    /// Number of identified parameters.
    pub identified: Option<usize>,
    /// Number of model parameters considered.
    pub total: Option<usize>,
    /// The most correlated pairs of identified parameters, strongest first.
    pub correlated_pairs: Vec<CorrelatedPair>,
    /// Parameters held fixed, with the reason (shown instead of the parameter rows' reasons when
    /// not empty).
    pub fixed: Vec<FixedParam>,
}

/// Two identified parameters whose estimates are correlated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrelatedPair {
    /// First parameter.
    pub a: String,
    /// Second parameter.
    pub b: String,
    /// Correlation coefficient (-1..1).
    pub correlation: f64,
}

/// A parameter held at its nominal value.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FixedParam {
    /// Parameter name.
    pub name: String,
    /// Why, e.g. "absorbed by base_z (same column of the Jacobian)".
    pub reason: String,
}

/// How the optimisation ended.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SolverSummary {
    /// The method, e.g. "Levenberg-Marquardt".
    pub method: String,
    /// The objective, e.g. "sum of displacement error norms (eq. 4)".
    pub objective: String,
    /// Objective at the start (nominal model).
    pub initial_value: Option<f64>,
    /// Objective at the end.
    pub final_value: Option<f64>,
    /// Unit or meaning of the objective values, e.g. "mm".
    pub value_unit: Option<String>,
    /// Why the solver stopped.
    pub termination: String,
    /// Iterations made.
    pub iterations: Option<usize>,
    /// Objective or Jacobian evaluations.
    pub evaluations: Option<usize>,
    /// Further lines (tolerances, time...).
    pub extra: Vec<Setting>,
}

/// How much a note matters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoteLevel {
    /// For information.
    #[default]
    Info,
    /// Something the reader should check.
    Warning,
}

/// A warning or note.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Note {
    /// Info or warning.
    #[serde(default)]
    pub level: NoteLevel,
    /// The text.
    pub text: String,
}

impl Note {
    /// An informational note.
    pub fn info(text: impl Into<String>) -> Note {
        Note {
            level: NoteLevel::Info,
            text: text.into(),
        }
    }

    /// A warning.
    pub fn warning(text: impl Into<String>) -> Note {
        Note {
            level: NoteLevel::Warning,
            text: text.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_difference_wraps() {
        let p = ParamRow {
            name: "phi6".into(),
            unit: Unit::Deg,
            nominal: 180.0,
            calibrated: -179.99,
            std: None,
            fixed: false,
            reason: None,
            truth: None,
        };
        assert!((p.difference() - 0.01).abs() < 1e-9, "{}", p.difference());
        let q = ParamRow {
            unit: Unit::Mm,
            nominal: 1045.0,
            calibrated: 1044.237,
            ..p
        };
        assert!((q.difference() + 0.763).abs() < 1e-9);
    }

    #[test]
    fn nan_round_trips_through_json_as_null() {
        let s = PointSet {
            name: "Validation".into(),
            points: vec![PointError {
                reach_mm: 2000.0,
                before_mm: 1.5,
                after_mm: f64::NAN,
            }],
            details: vec![],
        };
        let j = serde_json::to_string(&s).unwrap();
        assert!(j.contains("\"after_mm\":null"), "{j}");
        let back: PointSet = serde_json::from_str(&j).unwrap();
        assert!(back.points[0].after_mm.is_nan());
        assert_eq!(back.points[0].before_mm, 1.5);

        let h = HistogramSeries::new("x", vec![1.0, f64::INFINITY, 2.0]);
        let j = serde_json::to_string(&h).unwrap();
        let back: HistogramSeries = serde_json::from_str(&j).unwrap();
        assert_eq!(back.values_mm[0], 1.0);
        assert!(back.values_mm[1].is_nan());
    }

    #[test]
    fn reach() {
        assert_eq!(ReachKind::Radial.of([3.0, 4.0, 100.0]), 5.0);
        assert_eq!(ReachKind::Spherical.of([2.0, 3.0, 6.0]), 7.0);
    }
}
