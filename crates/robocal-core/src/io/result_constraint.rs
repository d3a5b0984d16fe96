//! The result's `constraint` section (issue 31): a calibration made from constraint data (fixed
//! points, spheres, planes; no tracker) is a normal result file ([`CalibrationResult`]) whose
//! `tracker_frame` is the identity (the features are in the base frame of the calibrated model)
//! and which records, in this section, the features as estimated, where the length scale came
//! from, what the data cannot see, and that the result is up to the base pose.
//!
//! Readers look it up with [`ConstraintSection::of`]: a result with it has no tracker frame to
//! use, so tracker data evaluated against it need a registration of their own, and positions
//! compensated with it are in the calibrated base frame, whose pose is the nominal one.

use crate::error::{Error, Result};
use crate::identification::constraint::FeatureEstimate;
use crate::io::result::CalibrationResult;
use crate::observations::constraint::ConstraintKind;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The section's key in the result file.
pub const KEY: &str = "constraint";

/// What every constraint result says about its base frame (readers print it).
pub const BASE_POSE_NOTE: &str = "the calibration is up to the base pose: constraint data have \
     no reference frame, so the base frame is the nominal one and positions are right relative \
     to each other and to the constrained features, not absolutely";

/// One fixed feature as estimated.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureEntry {
    /// `point`, `sphere` or `plane`.
    pub kind: String,
    /// Its name.
    pub name: String,
    /// A point's position, a sphere's centre, a plane's point nearest the base origin (mm,
    /// base frame of the calibrated model).
    pub position_mm: [f64; 3],
    /// A sphere's radius (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<f64>,
    /// Whether a sphere's radius was given (held) rather than estimated.
    #[serde(default)]
    pub radius_given: bool,
    /// A plane's unit normal (base frame).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 3]>,
    /// A plane's offset along its normal (mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset_mm: Option<f64>,
    /// Number of calibration rows on it.
    pub rows: usize,
    /// RMS of its rows' residuals (mm).
    pub residual_rms_mm: f64,
}

impl FeatureEntry {
    /// The entry of an estimated feature.
    pub fn of(f: &FeatureEstimate, rows: usize, residual_rms_mm: f64) -> FeatureEntry {
        FeatureEntry {
            kind: f.kind.key().to_owned(),
            name: f.name.clone(),
            position_mm: [f.position.x, f.position.y, f.position.z],
            radius_mm: f.radius_mm,
            radius_given: f.radius_known,
            normal: f.normal.map(|n| [n.x, n.y, n.z]),
            offset_mm: f.offset_mm,
            rows,
            residual_rms_mm,
        }
    }

    /// `kind:name`.
    pub fn label(&self) -> String {
        format!("{}:{}", self.kind, self.name)
    }

    /// The feature as the fit represents it; `path` names the result in errors.
    pub fn estimate(&self, path: &Path) -> Result<FeatureEstimate> {
        let bad = |msg: String| {
            Error::parse(
                path,
                None,
                Some(&format!("{KEY}.features.{}", self.name)),
                msg,
            )
        };
        let kind = ConstraintKind::parse(&self.kind)
            .ok_or_else(|| bad(format!("`{}` is not point, sphere or plane", self.kind)))?;
        let [x, y, z] = self.position_mm;
        let mut f = FeatureEstimate {
            kind,
            name: self.name.clone(),
            position: Vector3::new(x, y, z),
            radius_mm: None,
            radius_known: self.radius_given,
            normal: None,
            offset_mm: None,
        };
        match kind {
            ConstraintKind::Point => {}
            ConstraintKind::Sphere => {
                let r = self
                    .radius_mm
                    .filter(|r| r.is_finite() && *r > 0.0)
                    .ok_or_else(|| bad("a sphere needs a positive radius_mm".into()))?;
                f.radius_mm = Some(r);
            }
            ConstraintKind::Plane => {
                let n = self
                    .normal
                    .map(|[a, b, c]| Vector3::new(a, b, c))
                    .filter(|n| (n.norm() - 1.0).abs() < 1e-6)
                    .ok_or_else(|| bad("a plane needs a unit normal".into()))?;
                let d = self
                    .offset_mm
                    .filter(|d| d.is_finite())
                    .ok_or_else(|| bad("a plane needs its offset_mm".into()))?;
                f.normal = Some(n);
                f.offset_mm = Some(d);
            }
        }
        if !f.position.iter().all(|v| v.is_finite()) {
            return Err(bad("position_mm is not finite".into()));
        }
        Ok(f)
    }
}

/// A known distance between two features and how well the fit meets it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DistanceEntry {
    /// One feature's name.
    pub from: String,
    /// The other's.
    pub to: String,
    /// The given distance (mm).
    pub distance_mm: f64,
    /// Fitted minus given (mm).
    pub residual_mm: f64,
}

/// Where the length scale came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScaleEntry {
    /// Whether the data determine it.
    pub known: bool,
    /// What gives it (`6 known distances`), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<String>,
    /// The link length held at its nominal value, when the scale was accepted as unknown.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held: Option<String>,
}

/// The `constraint` section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConstraintSection {
    /// The frame of the result ([`BASE_POSE_NOTE`], or that tracker rows fixed it).
    pub frame: String,
    /// Whether the base pose is known (tracker rows in the data registered it).
    pub base_pose_known: bool,
    /// Number of constraint rows.
    pub rows: usize,
    /// Number of tracker rows calibrated with them (mixed data).
    #[serde(default)]
    pub tracker_rows: usize,
    /// RMS of the tracker rows' residuals (mm), with tracker rows.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tracker_residual_rms_mm: Option<f64>,
    /// The features.
    pub features: Vec<FeatureEntry>,
    /// The known distances.
    #[serde(default)]
    pub known_distances: Vec<DistanceEntry>,
    /// The length scale.
    pub scale: ScaleEntry,
    /// What the data cannot see, in words.
    pub unseen: Vec<String>,
    /// RMS of the constraint rows' residuals (mm).
    pub residual_rms_mm: f64,
    /// Largest constraint row residual (mm).
    pub residual_max_mm: f64,
    /// Condition number of the column-scaled Jacobian of the final fit.
    pub condition_number: f64,
}

impl ConstraintSection {
    /// The section of `result`, if it has one; a malformed one is an error naming `path`.
    pub fn of(result: &CalibrationResult, path: &Path) -> Result<Option<ConstraintSection>> {
        let Some(v) = result.extra.get(KEY) else {
            return Ok(None);
        };
        serde_json::from_value(v.clone())
            .map(Some)
            .map_err(|e| Error::parse(path, None, Some(KEY), e.to_string()))
    }

    /// Stores the section in `result`.
    pub fn store(&self, result: &mut CalibrationResult) {
        let v = serde_json::to_value(self).expect("plain data serialize");
        result.extra.insert(KEY.to_owned(), v);
    }

    /// The features as the fit represents them; `path` names the result in errors.
    pub fn estimates(&self, path: &Path) -> Result<Vec<FeatureEstimate>> {
        self.features.iter().map(|f| f.estimate(path)).collect()
    }
}
