//! Measured tool points in the form the registration and the solvers use: joint vectors and
//! measured points (tracker frame), each with the CSV line it came from.

pub mod kinds;

use crate::error::{Error, Result};
use crate::model::Robot;
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// Largest accepted measured coordinate (mm): the bound of every length ([`crate::ranges::LENGTH`],
/// 1 km), far beyond any tracker's range, but small enough that squares and sums of coordinates
/// stay accurate.
pub const MAX_COORDINATE_MM: f64 = crate::ranges::LENGTH.max;

/// A set of measured tool points: joint values (model values, rad, stored flat) and the measured
/// position of the tool in the tracker frame (mm), with the 1-based CSV line of each point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Observations {
    dof: usize,
    q: Vec<f64>,
    m: Vec<Vector3<f64>>,
    lines: Vec<usize>,
    source: Option<PathBuf>,
}

impl Observations {
    /// An empty set for a robot with `dof` joints.
    pub fn new(dof: usize) -> Self {
        Observations {
            dof,
            ..Default::default()
        }
    }

    /// An empty set whose points come from `path` (used in messages).
    pub fn with_source(dof: usize, path: &Path) -> Self {
        Observations {
            dof,
            source: Some(path.to_owned()),
            ..Default::default()
        }
    }

    /// The measurement kind of these observations (one reflector's point).
    pub fn kind(&self) -> &'static dyn kinds::MeasurementKind {
        &kinds::Point
    }

    /// Adds a point: joint values (rad), measured position (mm, tracker frame), CSV line (0 when
    /// the point does not come from a file). Rejects a wrong joint count and non-finite values.
    pub fn push(&mut self, q: &[f64], m: Vector3<f64>, line: usize) -> Result<()> {
        let at = self.describe(line);
        if q.len() != self.dof {
            return Err(Error::JointCount {
                context: at,
                expected: self.dof,
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{at}: q{}", i + 1),
                "not a finite number",
            ));
        }
        if let Some(k) = m.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{at}: {}", ["x", "y", "z"][k]),
                "not a finite number",
            ));
        }
        if let Some(k) = m.iter().position(|v| v.abs() > MAX_COORDINATE_MM) {
            return Err(Error::invalid(
                format!("{at}: {}", ["x", "y", "z"][k]),
                format!(
                    "{:.3e} mm is not a plausible tracker reading (more than {} km away)",
                    m[k],
                    MAX_COORDINATE_MM / 1e6
                ),
            ));
        }
        self.q.extend_from_slice(q);
        self.m.push(m);
        self.lines.push(line);
        Ok(())
    }

    /// How a point is named in messages: `file:line` or `point N`.
    pub fn describe(&self, line: usize) -> String {
        match (&self.source, line) {
            (Some(p), l) if l > 0 => format!("{}:{l}", p.display()),
            (Some(p), _) => p.display().to_string(),
            (None, l) if l > 0 => format!("line {l}"),
            _ => format!("point {}", self.m.len() + 1),
        }
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.m.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.m.is_empty()
    }

    /// Joint values of point `i` (rad).
    pub fn q(&self, i: usize) -> &[f64] {
        &self.q[i * self.dof..(i + 1) * self.dof]
    }

    /// Measured position of point `i` (mm, tracker frame).
    pub fn m(&self, i: usize) -> &Vector3<f64> {
        &self.m[i]
    }

    /// All measured positions.
    pub fn measured(&self) -> &[Vector3<f64>] {
        &self.m
    }

    /// CSV line of point `i` (0 when unknown).
    pub fn line(&self, i: usize) -> usize {
        self.lines[i]
    }

    /// The file the points came from, if any.
    pub fn source(&self) -> Option<&Path> {
        self.source.as_deref()
    }

    /// The nominal (model) tool positions of every point for `robot` (eq. 1).
    pub fn model_positions(&self, robot: &Robot) -> Vec<Vector3<f64>> {
        (0..self.len())
            .map(|i| robot.tool_position(self.q(i)))
            .collect()
    }

    /// Rejects two points with identical joint values: a repeated pose adds no information about
    /// the geometry and usually means a copy-paste error in the file.
    pub fn check_no_duplicate_poses(&self) -> Result<()> {
        let mut idx: Vec<usize> = (0..self.len()).collect();
        let bits = |i: usize| self.q(i).iter().map(|v| v.to_bits());
        idx.sort_unstable_by(|&a, &b| bits(a).cmp(bits(b)).then(a.cmp(&b)));
        for w in idx.windows(2) {
            if bits(w[0]).eq(bits(w[1])) {
                let (a, b) = (w[0].min(w[1]), w[0].max(w[1]));
                return Err(Error::invalid(
                    self.describe(self.line(b)),
                    format!(
                        "duplicated pose: the same joint values as {} (remove the repeat or \
                         average the two measurements)",
                        if self.line(a) > 0 {
                            format!("line {}", self.line(a))
                        } else {
                            format!("point {}", a + 1)
                        }
                    ),
                ));
            }
        }
        Ok(())
    }
}
