//! Measured tool points in the form the registration and the solvers use: joint vectors and
//! measured points (tracker frame), each with the CSV line it came from, and what a real cell
//! adds (DESIGN.md, "Measurement CSV additions"): which target (reflector) a row measures, the
//! measured frame's orientation of 6-DoF data, and each point's uncertainty.

pub mod constraint;
pub mod kinds;
mod weighting;

pub use weighting::{
    AppliedWeighting, TrackerSigma, WeightSource, Weighting, DEFAULT_MM_PER_DEG,
    TRACKER_FRAME_MIN_DISTANCE_MM, TYPICAL_TRACKER,
};

use crate::error::{Error, Result};
use crate::kinematics::Conditions;
use crate::model::Robot;
use nalgebra::{Matrix3, Vector3};
use std::path::{Path, PathBuf};

/// Largest accepted measured coordinate (mm): the bound of every length ([`crate::ranges::LENGTH`],
/// 1 km), far beyond any tracker's range, but small enough that squares and sums of coordinates
/// stay accurate.
pub const MAX_COORDINATE_MM: f64 = crate::ranges::LENGTH.max;

/// A set of measured tool points: joint values (model values, rad, stored flat) and the measured
/// position of the tool in the tracker frame (mm), with the 1-based CSV line of each point.
#[derive(Debug, Clone, PartialEq)]
pub struct Observations {
    dof: usize,
    q: Vec<f64>,
    m: Vec<Vector3<f64>>,
    lines: Vec<usize>,
    source: Option<PathBuf>,
    /// 0-based target of each observation (empty while every target is 0).
    target: Vec<u16>,
    /// Measured orientation of each observation (tracker frame), for 6-DoF data.
    rotation: Option<Vec<Matrix3<f64>>>,
    /// Each observation's 1-sigma uncertainty per axis (mm), when known.
    sigma: Option<Vec<f64>>,
    /// Weight of orientation rows: mm of position error one radian of orientation error
    /// counts as (see [`Weighting`]).
    mm_per_rad: f64,
    /// The sum of `sigma` (kept with it).
    sigma_sum: f64,
    /// Each observation's conditions (temperature, approach directions), when some row has
    /// them.
    conditions: Option<Vec<Conditions>>,
}

impl Default for Observations {
    fn default() -> Self {
        Observations::new(0)
    }
}

/// What a measurement row may carry beside its joints and point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RowExtras {
    /// 0-based target (reflector) the row measures.
    pub target: usize,
    /// The measured frame's orientation in the tracker frame (6-DoF data).
    pub rotation: Option<Matrix3<f64>>,
    /// The point's 1-sigma uncertainty per axis (mm).
    pub sigma_mm: Option<f64>,
    /// The arm's temperature and the joints' approach directions at the row, when known.
    pub conditions: Option<Conditions>,
}

/// Most targets one set of observations may use.
pub const MAX_TARGETS: usize = 64;

impl Observations {
    /// An empty set for a robot with `dof` joints.
    pub fn new(dof: usize) -> Self {
        Observations {
            dof,
            q: Vec::new(),
            m: Vec::new(),
            lines: Vec::new(),
            source: None,
            target: Vec::new(),
            rotation: None,
            sigma: None,
            mm_per_rad: DEFAULT_MM_PER_DEG.to_degrees(),
            sigma_sum: 0.0,
            conditions: None,
        }
    }

    /// An empty set whose points come from `path` (used in messages).
    pub fn with_source(dof: usize, path: &Path) -> Self {
        Observations {
            source: Some(path.to_owned()),
            ..Observations::new(dof)
        }
    }

    /// The measurement kind of these observations: a point per target, or a 6-DoF pose when
    /// the observations carry orientations.
    pub fn kind(&self) -> &'static dyn kinds::MeasurementKind {
        if self.rotation.is_some() {
            &kinds::Pose6
        } else {
            &kinds::Point
        }
    }

    /// Adds a point: joint values (rad), measured position (mm, tracker frame), CSV line (0 when
    /// the point does not come from a file). Rejects a wrong joint count and non-finite values.
    pub fn push(&mut self, q: &[f64], m: Vector3<f64>, line: usize) -> Result<()> {
        // Named only when a check fails (a million rows' names are a million allocations).
        let at = || self.describe(line);
        if q.len() != self.dof {
            return Err(Error::JointCount {
                context: at(),
                expected: self.dof,
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{}: q{}", at(), i + 1),
                "not a finite number",
            ));
        }
        if let Some(k) = m.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("{}: {}", at(), ["x", "y", "z"][k]),
                "not a finite number",
            ));
        }
        if let Some(k) = m.iter().position(|v| v.abs() > MAX_COORDINATE_MM) {
            return Err(Error::invalid(
                format!("{}: {}", at(), ["x", "y", "z"][k]),
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
        if !self.target.is_empty() {
            self.target.push(0);
        }
        if let Some(r) = &mut self.rotation {
            r.push(Matrix3::identity());
        }
        if let Some(s) = &mut self.sigma {
            s.push(f64::NAN);
        }
        if let Some(c) = &mut self.conditions {
            c.push(Conditions::UNKNOWN);
        }
        Ok(())
    }

    /// Adds a point with what a real cell's row carries beside it (see [`RowExtras`]). Every
    /// observation of a set has an orientation or none has; the same for the uncertainty.
    pub fn push_with(
        &mut self,
        q: &[f64],
        m: Vector3<f64>,
        extras: RowExtras,
        line: usize,
    ) -> Result<()> {
        let at = || self.describe(line);
        let first = self.is_empty();
        if extras.target >= MAX_TARGETS {
            return Err(Error::invalid(
                format!("{}: target", at()),
                format!("{} is more targets than {MAX_TARGETS}", extras.target + 1),
            ));
        }
        if !first && extras.rotation.is_some() != self.rotation.is_some() {
            return Err(Error::invalid(
                format!("{}: a", at()),
                "every row of a set is a 6-DoF measurement (a,b,c) or none is",
            ));
        }
        if !first && extras.sigma_mm.is_some() != self.sigma.is_some() {
            return Err(Error::invalid(
                format!("{}: sigma_mm", at()),
                "every row of a set has an uncertainty or none has",
            ));
        }
        if let Some(s) = extras.sigma_mm {
            if !(s > 0.0 && s.is_finite()) {
                return Err(Error::invalid(
                    format!("{}: sigma_mm", at()),
                    format!("{s} is not a positive length (mm)"),
                ));
            }
        }
        if let Some(r) = &extras.rotation {
            let orthonormal = (r.transpose() * r - Matrix3::identity()).amax() < 1e-6
                && (r.determinant() - 1.0).abs() < 1e-6;
            if !orthonormal {
                return Err(Error::invalid(
                    format!("{}: a", at()),
                    "the orientation is not a rotation",
                ));
            }
        }
        self.push(q, m, line)?;
        let i = self.len() - 1;
        if extras.target != 0 && self.target.is_empty() {
            self.target = vec![0; self.len()];
        }
        if !self.target.is_empty() {
            self.target[i] = extras.target as u16;
        }
        // `push` appended placeholders to columns the set already has; the first row creates
        // them.
        if let Some(r) = extras.rotation {
            match &mut self.rotation {
                Some(v) => v[i] = r,
                None => self.rotation = Some(vec![r]),
            }
        }
        if let Some(s) = extras.sigma_mm {
            match &mut self.sigma {
                Some(v) => v[i] = s,
                None => self.sigma = Some(vec![s]),
            }
            self.sigma_sum += s;
        }
        if let Some(c) = extras.conditions {
            self.conditions
                .get_or_insert_with(|| vec![Conditions::UNKNOWN; i + 1])[i] = c;
        }
        Ok(())
    }

    /// The observations `i` for which `keep(i)`, with their extras and weights.
    pub fn rows_where(&self, keep: impl Fn(usize) -> bool) -> Result<Observations> {
        let mut out = Observations::new(self.dof());
        out.set_mm_per_deg(self.mm_per_rad().to_radians())?;
        for i in (0..self.len()).filter(|&i| keep(i)) {
            out.push_with(self.q(i), *self.m(i), self.extras(i), self.line(i))?;
        }
        Ok(out)
    }

    /// Observation `i`'s conditions (temperature, approach directions; unknown when the rows
    /// carry none).
    #[inline]
    pub fn conditions(&self, i: usize) -> Conditions {
        self.conditions
            .as_ref()
            .map_or(Conditions::UNKNOWN, |c| c[i])
    }

    /// Whether some observation has a known temperature.
    pub fn has_temperature(&self) -> bool {
        self.conditions
            .as_ref()
            .is_some_and(|c| c.iter().any(|c| c.temperature_c.is_finite()))
    }

    /// Whether some observation has a known approach direction.
    pub fn has_directions(&self) -> bool {
        self.conditions
            .as_ref()
            .is_some_and(|c| c.iter().any(|c| c.dir.iter().any(|d| *d != 0)))
    }

    /// Sets every observation's approach directions from the order of the observations: the
    /// sign of each joint's motion from the previous observation (a joint that did not move
    /// keeps its direction; the first observation's are unknown). Temperatures are kept.
    pub fn derive_directions(&mut self) {
        let n = self.len();
        let mut out = Vec::with_capacity(n);
        let mut dir = [0_i8; crate::model::MAX_JOINTS];
        for i in 0..n {
            if i > 0 {
                for (j, (a, b)) in self.q(i).iter().zip(self.q(i - 1)).enumerate() {
                    if a > b {
                        dir[j] = 1;
                    } else if a < b {
                        dir[j] = -1;
                    }
                }
            }
            out.push(Conditions {
                dir,
                ..self.conditions(i)
            });
        }
        self.conditions = Some(out);
    }

    /// Everything observation `i` carries beside its joints and point.
    pub fn extras(&self, i: usize) -> RowExtras {
        RowExtras {
            target: self.target(i),
            rotation: self.rotation(i).copied(),
            sigma_mm: self.sigma_mm(i),
            conditions: self.conditions.as_ref().map(|c| c[i]),
        }
    }

    /// The 0-based target (reflector) observation `i` measures.
    #[inline]
    pub fn target(&self, i: usize) -> usize {
        self.target.get(i).map_or(0, |t| *t as usize)
    }

    /// Number of targets the observations use (the largest target plus one; 1 for plain data).
    pub fn target_count(&self) -> usize {
        self.target.iter().max().map_or(1, |t| *t as usize + 1)
    }

    /// The measured orientation of observation `i` (tracker frame), for 6-DoF data.
    #[inline]
    pub fn rotation(&self, i: usize) -> Option<&Matrix3<f64>> {
        self.rotation.as_ref().map(|r| &r[i])
    }

    /// Whether the observations are 6-DoF measurements.
    pub fn has_orientation(&self) -> bool {
        self.rotation.is_some()
    }

    /// Observation `i`'s 1-sigma uncertainty per axis (mm), when known.
    #[inline]
    pub fn sigma_mm(&self, i: usize) -> Option<f64> {
        self.sigma.as_ref().map(|s| s[i])
    }

    /// Whether every observation has an uncertainty.
    pub fn has_sigma(&self) -> bool {
        self.sigma.is_some()
    }

    /// Sets every observation's uncertainty (mm; one per observation, positive and finite).
    pub fn set_sigmas(&mut self, sigma: Option<Vec<f64>>) -> Result<()> {
        if let Some(s) = &sigma {
            if s.len() != self.len() {
                return Err(Error::invalid(
                    "sigma_mm",
                    format!("{} uncertainties for {} points", s.len(), self.len()),
                ));
            }
            if let Some(i) = s.iter().position(|v| !(*v > 0.0 && v.is_finite())) {
                return Err(Error::invalid(
                    format!("{}: sigma_mm", self.describe(self.line(i))),
                    format!("{} is not a positive length (mm)", s[i]),
                ));
            }
        }
        self.sigma_sum = sigma.as_ref().map_or(0.0, |s| s.iter().sum());
        self.sigma = sigma;
        Ok(())
    }

    /// How many mm of position error one radian of orientation error counts as in a fit.
    pub fn mm_per_rad(&self) -> f64 {
        self.mm_per_rad
    }

    /// Sets the orientation rows' weight (mm per degree, positive and finite).
    pub fn set_mm_per_deg(&mut self, w: f64) -> Result<()> {
        if !(w > 0.0 && w.is_finite()) {
            return Err(Error::invalid(
                "orientation_mm_per_deg",
                format!("{w} is not a positive weight (mm per degree)"),
            ));
        }
        self.mm_per_rad = w.to_degrees();
        Ok(())
    }

    /// The relative weight of observation `i`'s rows in a fit: `sigma_mean / sigma_i` (1 when
    /// uncertainties are unknown), so that weighted residuals stay in mm of a typical point.
    #[inline]
    pub fn weight(&self, i: usize) -> f64 {
        match &self.sigma {
            Some(s) => self.sigma_mean() / s[i],
            None => 1.0,
        }
    }

    /// The mean uncertainty (mm), 1 without uncertainties: the sum is kept as the sigmas are
    /// set, so [`Observations::weight`] costs O(1) in the hot loop.
    fn sigma_mean(&self) -> f64 {
        match &self.sigma {
            Some(s) if !s.is_empty() => self.sigma_sum / s.len() as f64,
            _ => 1.0,
        }
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
            .map(|i| robot.target_position_in(self.q(i), self.target(i), &self.conditions(i)))
            .collect()
    }

    /// Checks that `robot` carries every target the observations use.
    pub fn check_targets(&self, robot: &Robot) -> Result<()> {
        let k = self.target_count();
        if k > robot.target_count() {
            let i = (0..self.len())
                .find(|&i| self.target(i) >= robot.target_count())
                .unwrap_or(0);
            return Err(Error::invalid(
                format!("{}: target", self.describe(self.line(i))),
                format!(
                    "target {} is measured, but the robot has {} tool vector{} (give one per \
                     target in the robot file: tools = [[x, y, z, a, b, c], ...])",
                    self.target(i) + 1,
                    robot.target_count(),
                    if robot.target_count() == 1 { "" } else { "s" }
                ),
            ));
        }
        Ok(())
    }

    /// Rejects two points with identical joint values and target: a repeated pose adds no
    /// information about the geometry and usually means a copy-paste error in the file (one pose
    /// seen through several targets is not a repeat).
    pub fn check_no_duplicate_poses(&self) -> Result<()> {
        let mut idx: Vec<usize> = (0..self.len()).collect();
        let bits = |i: usize| {
            self.q(i)
                .iter()
                .map(|v| v.to_bits())
                .chain(std::iter::once(self.target(i) as u64))
                // The same joints at another temperature or from other directions are another
                // measurement (a bidirectional test), not a repeat.
                .chain(std::iter::once(self.conditions(i).temperature_c.to_bits()))
                .chain(self.conditions(i).dir.map(|d| d as u64))
        };
        // Sorted by a hash of the bits (one cheap key per row, where comparing the rows' bits
        // in the sort took a tenth of a million-row calibration); rows of equal hash compared.
        // The hash multiplies and rotates each word in (FxHash's step): a tenth of the cost of
        // the standard library's keyed SipHash, which guards hash tables against chosen
        // collisions that cost nothing here but a comparison.
        let hash = |i: usize| {
            bits(i).fold(0u64, |h, b| {
                (h.rotate_left(5) ^ b).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95)
            })
        };
        let hashes: Vec<u64> = idx.iter().map(|&i| hash(i)).collect();
        idx.sort_unstable_by_key(|&i| (hashes[i], i));
        // Within each run of equal hashes (one row, or a repeat), every pair compared; the
        // repeat reported is the first in the file (the pair whose later row comes first).
        let mut first: Option<(usize, usize)> = None;
        for run in idx.chunk_by(|&a, &b| hashes[a] == hashes[b]) {
            for (n, &a) in run.iter().enumerate() {
                let Some(&b) = run[n + 1..].iter().find(|&&b| bits(a).eq(bits(b))) else {
                    continue;
                };
                let pair = (a.min(b), a.max(b));
                if first.map_or(true, |(fa, fb)| (pair.1, pair.0) < (fb, fa)) {
                    first = Some(pair);
                }
            }
        }
        if let Some((a, b)) = first {
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
        Ok(())
    }
}
