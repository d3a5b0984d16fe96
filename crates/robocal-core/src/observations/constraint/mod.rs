//! Measurements without a tracker (DESIGN.md, "Measurement CSV additions", the "No tracker"
//! bullet): rows that say where the tool point *is* rather than give its coordinates. A row's
//! `constraint` cell is `point:NAME` (the tool point is at a fixed, unknown point NAME: a ball
//! in a socket), `sphere:NAME` (on the surface of a fixed sphere; the group's `radius_mm` gives a
//! known radius, empty means unknown) or `plane:NAME` (on a fixed, unknown plane). Such rows
//! have no `x,y,z`. Known distances between named points or sphere centres come from a separate
//! file ([`read_distances`]).
//!
//! [`ConstraintData::from_measurements`] turns a measurement file read with
//! [`crate::io::Positions::Ignored`] into such data, rejecting (file, line, column named) an
//! unknown kind, an empty name, a label used on one row only, a sphere given two radii, and
//! `x,y,z` given on a constraint row.
//!
//! Mixed data: a row with an empty `constraint` cell and `x,y,z` is a tracker row
//! ([`TrackerRow`]); calibrated with the constraint rows, such rows fix the scale and register
//! the base to the tracker frame.

mod distances;

pub use distances::{parse_distances, read_distances, KnownDistance};

use crate::error::{Error, Result};
use crate::io::row_conditions::ConditionsLayout;
use crate::io::MeasurementSet;
use crate::kinematics::Conditions;
use std::path::{Path, PathBuf};

/// The column naming a row's constraint.
pub const CONSTRAINT_COLUMN: &str = "constraint";
/// The column giving a sphere's known radius (mm).
pub const RADIUS_COLUMN: &str = "radius_mm";

/// What a constraint row says about the tool point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConstraintKind {
    /// At a fixed, unknown point.
    Point,
    /// On the surface of a fixed sphere (unknown centre; radius known or not).
    Sphere,
    /// On a fixed, unknown plane.
    Plane,
}

impl ConstraintKind {
    /// The key used in the `constraint` column (`point`, `sphere`, `plane`).
    pub fn key(self) -> &'static str {
        match self {
            ConstraintKind::Point => "point",
            ConstraintKind::Sphere => "sphere",
            ConstraintKind::Plane => "plane",
        }
    }

    /// The kind of a key; `None` for anything else.
    pub fn parse(key: &str) -> Option<ConstraintKind> {
        match key.trim().to_ascii_lowercase().as_str() {
            "point" => Some(ConstraintKind::Point),
            "sphere" => Some(ConstraintKind::Sphere),
            "plane" => Some(ConstraintKind::Plane),
            _ => None,
        }
    }

    /// The fewest rows a feature of this kind needs to be determined at all (a point: two
    /// configurations; a sphere: four points; a plane: three).
    pub fn min_rows(self) -> usize {
        match self {
            ConstraintKind::Point => 2,
            ConstraintKind::Sphere => 4,
            ConstraintKind::Plane => 3,
        }
    }
}

/// One fixed feature the rows refer to: a point, a sphere or a plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Feature {
    /// Its kind.
    pub kind: ConstraintKind,
    /// Its name (the part after `kind:`).
    pub name: String,
    /// A sphere's known radius (mm); `None` when unknown (and for points and planes).
    pub radius_mm: Option<f64>,
    /// The 1-based line of its first row (0 when not from a file).
    pub first_line: usize,
}

impl Feature {
    /// `kind:name`, as written in the `constraint` column.
    pub fn label(&self) -> String {
        format!("{}:{}", self.kind.key(), self.name)
    }
}

/// One constraint row: joint values and the feature the tool point touches.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintRow {
    /// Joint values (model values: rad, or mm for a prismatic joint).
    pub q: Vec<f64>,
    /// Index of the feature in [`ConstraintData::features`].
    pub feature: usize,
    /// 1-based line in the file (0 when not from a file).
    pub line: usize,
    /// The arm's temperature and the joints' approach directions at the row (`temperature_c`,
    /// `dir1..dirN`, read as for tracker data), unknown when the file has none.
    pub conditions: Conditions,
}

/// A tracker row among constraint rows (mixed data): joint values and the measured tool point.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackerRow {
    /// Joint values (model values: rad, or mm for a prismatic joint).
    pub q: Vec<f64>,
    /// The measured point (mm, tracker frame).
    pub m: nalgebra::Vector3<f64>,
    /// 1-based line in the file (0 when not from a file).
    pub line: usize,
    /// The row's conditions, as for a constraint row.
    pub conditions: Conditions,
}

/// Fewest tracker rows of mixed data: the tracker frame's registration needs three points not
/// on one line.
pub const MIN_TRACKER_ROWS: usize = 3;

/// Constraint measurements: rows, the features they refer to and known distances.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ConstraintData {
    /// The file the rows came from, if any (for messages).
    pub source: Option<PathBuf>,
    /// The robot's joint count.
    pub dof: usize,
    /// The features, in order of first appearance.
    pub features: Vec<Feature>,
    /// The rows, in file order.
    pub rows: Vec<ConstraintRow>,
    /// Known distances between points or sphere centres.
    pub distances: Vec<KnownDistance>,
    /// Tracker rows calibrated with the constraint rows (mixed data), in file order.
    pub tracker: Vec<TrackerRow>,
}

impl ConstraintData {
    /// An empty set for a robot with `dof` joints.
    pub fn new(dof: usize) -> Self {
        ConstraintData {
            dof,
            ..ConstraintData::default()
        }
    }

    /// Whether a measurement file's header has a `constraint` column (any case).
    pub fn has_constraint_column(set: &MeasurementSet) -> bool {
        column(set, CONSTRAINT_COLUMN).is_some()
    }

    /// The index of the feature `kind:name`, added (with `radius_mm`, the row's line) when new.
    /// A sphere given another radius than before, or a name already used by another kind, is
    /// an error: the column to name and the message.
    pub fn feature_index(
        &mut self,
        kind: ConstraintKind,
        name: &str,
        radius_mm: Option<f64>,
        line: usize,
    ) -> std::result::Result<usize, (&'static str, String)> {
        if let Some(k) = self
            .features
            .iter()
            .position(|f| f.name == name && f.kind == kind)
        {
            let f = &self.features[k];
            if f.radius_mm != radius_mm {
                let show =
                    |r: Option<f64>| r.map_or("none (unknown)".to_string(), |r| format!("{r} mm"));
                return Err((
                    RADIUS_COLUMN,
                    format!(
                        "sphere `{name}` has radius {} here but {} on line {} (one sphere, one \
                     radius: leave radius_mm empty on every row of a sphere of unknown radius)",
                        show(radius_mm),
                        show(f.radius_mm),
                        f.first_line
                    ),
                ));
            }
            return Ok(k);
        }
        if let Some(f) = self.features.iter().find(|f| f.name == name) {
            return Err((
                CONSTRAINT_COLUMN,
                format!(
                "the name `{name}` is already the {} `{}` (line {}); give each feature its own \
                 name",
                f.kind.key(),
                f.label(),
                f.first_line
            ),
            ));
        }
        self.features.push(Feature {
            kind,
            name: name.to_owned(),
            radius_mm,
            first_line: line,
        });
        Ok(self.features.len() - 1)
    }

    /// Adds a row touching feature `feature` (an index from [`ConstraintData::feature_index`]).
    pub fn push(&mut self, q: Vec<f64>, feature: usize, line: usize) -> Result<()> {
        self.push_in(q, feature, line, Conditions::UNKNOWN)
    }

    /// [`ConstraintData::push`] with the row's conditions (temperature, approach directions).
    pub fn push_in(
        &mut self,
        q: Vec<f64>,
        feature: usize,
        line: usize,
        conditions: Conditions,
    ) -> Result<()> {
        if q.len() != self.dof {
            return Err(Error::JointCount {
                context: self.describe(line),
                expected: self.dof,
                got: q.len(),
            });
        }
        if feature >= self.features.len() {
            return Err(Error::invalid("feature", format!("no feature {feature}")));
        }
        if let Some(j) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{}: q{}", self.describe(line), j + 1),
                "not a finite number",
            ));
        }
        self.rows.push(ConstraintRow {
            q,
            feature,
            line,
            conditions,
        });
        Ok(())
    }

    /// How a row is named in messages: `file:line` or `line N`.
    pub fn describe(&self, line: usize) -> String {
        match &self.source {
            Some(p) if line > 0 => format!("{}:{line}", p.display()),
            Some(p) => p.display().to_string(),
            None => format!("line {line}"),
        }
    }

    /// Whether some constraint or tracker row has a temperature.
    pub fn has_temperature(&self) -> bool {
        self.all_conditions().any(|c| c.temperature_c.is_finite())
    }

    /// Whether some constraint or tracker row has an approach direction.
    pub fn has_directions(&self) -> bool {
        self.all_conditions().any(|c| c.dir.iter().any(|d| *d != 0))
    }

    /// The mean temperature of the rows that have one, rounded to 0.1 deg C (the reference a
    /// thermal model is referred to, as for tracker data); `None` without temperatures.
    pub fn mean_temperature_c(&self) -> Option<f64> {
        let t: Vec<f64> = self
            .all_conditions()
            .map(|c| c.temperature_c)
            .filter(|t| t.is_finite())
            .collect();
        (!t.is_empty()).then(|| (t.iter().sum::<f64>() / t.len() as f64 * 10.0).round() / 10.0)
    }

    fn all_conditions(&self) -> impl Iterator<Item = &Conditions> {
        self.rows
            .iter()
            .map(|r| &r.conditions)
            .chain(self.tracker.iter().map(|t| &t.conditions))
    }

    /// The rows of feature `k`.
    pub fn rows_of(&self, k: usize) -> impl Iterator<Item = &ConstraintRow> {
        self.rows.iter().filter(move |r| r.feature == k)
    }

    /// The feature named `name` (points, spheres and planes share one name space).
    pub fn feature_named(&self, name: &str) -> Option<usize> {
        self.features.iter().position(|f| f.name == name)
    }

    /// Whether the data carry a length scale of their own: a known distance, a sphere of known
    /// radius, or tracker rows (without one the robot's scale is not determined).
    pub fn has_known_length(&self) -> bool {
        !self.distances.is_empty()
            || self.features.iter().any(|f| f.radius_mm.is_some())
            || !self.tracker.is_empty()
    }

    /// Checks that every feature has enough rows ([`ConstraintKind::min_rows`]); a label used
    /// once is an error naming its line.
    pub fn check_counts(&self) -> Result<()> {
        for (k, f) in self.features.iter().enumerate() {
            let n = self.rows_of(k).count();
            if n < f.kind.min_rows() {
                let what = match f.kind {
                    ConstraintKind::Point => {
                        "a fixed point needs the tool there in at least 2 \
                                              configurations"
                    }
                    ConstraintKind::Sphere => "a sphere needs at least 4 points on it",
                    ConstraintKind::Plane => "a plane needs at least 3 points on it",
                };
                return Err(self.parse_error(
                    f.first_line,
                    CONSTRAINT_COLUMN,
                    format!(
                        "`{}` is used on {n} row{} only ({what}; a label used once is usually a \
                         misspelt name)",
                        f.label(),
                        if n == 1 { "" } else { "s" }
                    ),
                ));
            }
        }
        Ok(())
    }

    /// A parse error naming this data's file, `line` and `field`.
    pub fn parse_error(&self, line: usize, field: &str, msg: String) -> Error {
        Error::parse(
            self.source
                .clone()
                .unwrap_or_else(|| PathBuf::from("<constraints>")),
            (line > 0).then_some(line),
            Some(field),
            msg,
        )
    }

    /// The constraint rows of a measurement file read with [`crate::io::Positions::Ignored`]
    /// (its `x,y,z`, if any, are then extra columns). Every row must have a constraint (rows
    /// with a tracker point beside constraint rows are not supported yet) and none may give
    /// `x,y,z`.
    pub fn from_measurements(set: &MeasurementSet) -> Result<ConstraintData> {
        let path: &Path = &set.path;
        let perr =
            |line, field: &str, msg: String| Error::parse(path, Some(line), Some(field), msg);
        let Some(kc) = column(set, CONSTRAINT_COLUMN) else {
            return Err(perr(
                1,
                CONSTRAINT_COLUMN,
                "missing column (constraint rows name their feature: point:NAME, sphere:NAME or \
                 plane:NAME)"
                    .into(),
            ));
        };
        let rc = column(set, RADIUS_COLUMN);
        let xyz: Vec<(usize, &str)> = ["x", "y", "z"]
            .iter()
            .filter_map(|a| column(set, a).map(|k| (k, *a)))
            .collect();
        let mut data = ConstraintData {
            source: Some(path.to_owned()),
            ..ConstraintData::new(set.dof())
        };
        let conditions = ConditionsLayout::of(set)?;
        for r in &set.rows {
            let cell = r.extra[kc].trim();
            let c = conditions.read(set, r)?.unwrap_or(Conditions::UNKNOWN);
            if cell.is_empty() && xyz.iter().any(|(k, _)| !r.extra[*k].trim().is_empty()) {
                let mut t = tracker_row(set, &xyz, r)?;
                t.conditions = c;
                data.tracker.push(t);
                continue;
            }
            let Some((kind, name)) = cell.split_once(':') else {
                let msg = if cell.is_empty() {
                    "empty: every row of a constraint file names its feature, or is a tracker \
                     row with x,y,z (mm)"
                        .to_string()
                } else {
                    format!("`{cell}` is not kind:NAME (point:NAME, sphere:NAME or plane:NAME)")
                };
                return Err(perr(r.line, CONSTRAINT_COLUMN, msg));
            };
            let Some(kind) = ConstraintKind::parse(kind) else {
                return Err(perr(
                    r.line,
                    CONSTRAINT_COLUMN,
                    format!(
                        "unknown constraint kind `{}` in `{cell}` (known: point, sphere, plane)",
                        kind.trim()
                    ),
                ));
            };
            let name = name.trim();
            if name.is_empty() {
                return Err(perr(
                    r.line,
                    CONSTRAINT_COLUMN,
                    format!("`{cell}` has no name after `{}:`", kind.key()),
                ));
            }
            if let Some((_, a)) = xyz.iter().find(|(k, _)| !r.extra[*k].trim().is_empty()) {
                return Err(perr(
                    r.line,
                    a,
                    format!(
                        "a constraint row ({cell}) has no measured position: leave x,y,z empty \
                         (the tool point's coordinates are what the calibration does not know)"
                    ),
                ));
            }
            let radius = match rc.map(|k| r.extra[k].trim()) {
                None | Some("") => None,
                Some(s) => {
                    let v: f64 = s.parse().map_err(|_| {
                        perr(r.line, RADIUS_COLUMN, format!("`{s}` is not a number"))
                    })?;
                    if kind != ConstraintKind::Sphere {
                        return Err(perr(
                            r.line,
                            RADIUS_COLUMN,
                            format!("a radius is given for `{cell}`, which is not a sphere"),
                        ));
                    }
                    if !(v > 0.0 && v.is_finite()) {
                        return Err(perr(
                            r.line,
                            RADIUS_COLUMN,
                            format!("{s} is not a positive length (mm)"),
                        ));
                    }
                    crate::ranges::LENGTH
                        .check(v)
                        .map_err(|m| perr(r.line, RADIUS_COLUMN, m))?;
                    Some(v)
                }
            };
            let k = data
                .feature_index(kind, name, radius, r.line)
                .map_err(|(field, m)| perr(r.line, field, m))?;
            data.push_in(r.q.clone(), k, r.line, c)?;
        }
        data.check_counts()?;
        if !data.tracker.is_empty() && data.tracker.len() < MIN_TRACKER_ROWS {
            return Err(perr(
                data.tracker[0].line,
                "x",
                format!(
                    "{} tracker row(s) among constraint rows: registering the tracker frame \
                     needs at least {MIN_TRACKER_ROWS} (not on one line)",
                    data.tracker.len()
                ),
            ));
        }
        Ok(data)
    }
}

/// A tracker row of mixed data: `x,y,z` all given, numbers within the plausible range.
fn tracker_row(
    set: &MeasurementSet,
    xyz: &[(usize, &str)],
    r: &crate::io::Measurement,
) -> Result<TrackerRow> {
    let perr = |field: &str, msg: String| Error::parse(&set.path, Some(r.line), Some(field), msg);
    let mut m = nalgebra::Vector3::zeros();
    for (i, axis) in ["x", "y", "z"].iter().enumerate() {
        let Some((k, _)) = xyz.iter().find(|(_, a)| a == axis) else {
            return Err(perr(
                axis,
                "missing column: a tracker row among constraint rows needs x,y,z (mm)".into(),
            ));
        };
        let s = r.extra[*k].trim();
        if s.is_empty() {
            return Err(perr(
                axis,
                "empty: a row without a constraint is a tracker row and needs x,y,z (mm)".into(),
            ));
        }
        let v: f64 = s
            .parse()
            .map_err(|_| perr(axis, format!("`{s}` is not a number")))?;
        crate::ranges::LENGTH
            .check(v)
            .map_err(|msg| perr(axis, msg))?;
        m[i] = v;
    }
    Ok(TrackerRow {
        q: r.q.clone(),
        m,
        line: r.line,
        conditions: Conditions::UNKNOWN,
    })
}

/// The position of an extra column by name (any case).
fn column(set: &MeasurementSet, name: &str) -> Option<usize> {
    set.extra_columns
        .iter()
        .position(|c| c.eq_ignore_ascii_case(name))
}

#[cfg(test)]
mod tests;
