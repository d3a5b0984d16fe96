//! Simulated sessions measured as real cells measure: each pose seen through several
//! reflectors (a `target` column, DESIGN.md "Measurement CSV additions") and, with a 6-DoF probe,
//! each target frame's orientation (`a,b,c` columns, degrees, the frame's ABC in the tracker
//! frame).

use super::session::{Simulation, SET_PLANE};
use crate::error::{Error, Result};
use crate::frame::{frame_vector, Frame};
use crate::io::measurements::Measurement;
use nalgebra::Vector3;

/// What a simulated session measures at each pose beyond the tool point.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TargetMeasurement {
    /// Measure every target of the robot (its `tools`), one row per target with a `target`
    /// column (1-based). The plane points are measured through target 1 only.
    pub all_targets: bool,
    /// Measure each target's frame as a 6-DoF probe does, with this 1-sigma orientation noise
    /// per axis (degrees): `a,b,c` columns.
    pub orientation_sigma_deg: Option<f64>,
}

impl TargetMeasurement {
    /// Whether anything beyond one point per pose is measured.
    pub fn is_active(&self) -> bool {
        self.all_targets || self.orientation_sigma_deg.is_some()
    }
}

impl Simulation {
    /// Measures the session's poses again as `how` says (every target, orientations), replacing
    /// the rows (renumbered in file order: each pose's targets in turn), the exact readings and
    /// the gravity deflections. Nothing changes when `how` asks for nothing more than points.
    /// Fails for sessions with outliers, backlash or thermal growth (simulated for single
    /// points) and, with
    /// `all_targets`, for a robot with a single target.
    pub fn measure_targets(&mut self, how: &TargetMeasurement) -> Result<()> {
        if !how.is_active() {
            return Ok(());
        }
        if !self.outliers.is_empty() {
            return Err(Error::invalid(
                "outliers",
                "outliers are drawn for single points: not with several targets or 6-DoF \
                 measurements",
            ));
        }
        if self.cell.backlash().is_some() || self.cell.thermal().is_some() {
            return Err(Error::invalid(
                "targets",
                "backlash and thermal growth are simulated for single points: not with several \
                 targets or 6-DoF measurements",
            ));
        }
        let count = self.cell.truth().target_count();
        if how.all_targets && count < 2 {
            return Err(Error::invalid(
                "targets",
                "the robot has one target: give its reflectors' nominal tools in the robot \
                 file (`tools = [[x, y, z, a, b, c], ...]`)",
            ));
        }
        let sigma = how.orientation_sigma_deg.unwrap_or(0.0);
        let m = &self.measurements;
        let set_col = m.extra_columns.iter().position(|c| c == "set");
        let mut columns = m.extra_columns.clone();
        if how.all_targets {
            columns.push("target".into());
        }
        if how.orientation_sigma_deg.is_some() {
            columns.extend(["a", "b", "c"].map(String::from));
        }
        let old = std::mem::take(&mut self.measurements.rows);
        let mut rows = Vec::with_capacity(old.len() * count);
        let mut exact = Vec::with_capacity(old.len() * count);
        let mut deflection = Vec::with_capacity(old.len() * count);
        for r in old {
            let plane = set_col.is_some_and(|k| r.extra[k] == SET_PLANE);
            let targets = if how.all_targets && !plane { count } else { 1 };
            for t in 0..targets {
                let (p, rot) =
                    self.cell
                        .measure_target_frames(std::slice::from_ref(&r.q), t, sigma)?[0];
                let truth = self.cell.true_target_pose(&r.q, t);
                exact.push(self.cell.tracker().exact(&truth.translation.vector));
                let rigid = self.cell.truth().target_pose(&r.q, t);
                deflection.push((truth.translation.vector - rigid.translation.vector).norm());
                let mut extra = r.extra.clone();
                if how.all_targets {
                    extra.push((t + 1).to_string());
                }
                if how.orientation_sigma_deg.is_some() {
                    let v = frame_vector(&Frame::from_parts(
                        Vector3::zeros().into(),
                        nalgebra::Rotation3::from_matrix_unchecked(rot),
                    ));
                    extra.extend(v[3..].iter().map(|a| format!("{:.9}", a.to_degrees())));
                }
                rows.push(Measurement {
                    line: rows.len() + 2,
                    q: r.q.clone(),
                    p: Some(p),
                    extra,
                });
            }
        }
        self.measurements.rows = rows;
        self.measurements.extra_columns = columns;
        self.exact = exact;
        if self.deflection_mm.is_some() {
            self.deflection_mm = Some(deflection);
        }
        Ok(())
    }
}
