//! Measurement kinds: the open seam through which calibration takes new kinds of data.
//!
//! A kind turns one observation into residual rows (measured minus model, in the base frame) and
//! the model's parameter screws at the tool ([`crate::model::family`]) into the matching Jacobian
//! rows. The problem assembly, the identifiability analysis, the solver and the covariance work on
//! those rows without knowing the kind: a point of one reflector (3 rows, from `dp`) now; several
//! reflectors (`dp + dw x (p_k - p)` per reflector), a 6-DoF pose (`dp` and a weighted `dw`) or a
//! distance (`u^T (dp_1 - dp_2)`) each as one more file implementing [`MeasurementKind`].
//!
//! A kind declares what it sees of the tool's motion (its [`Measurability`], FIGAROH's mask): a
//! point sees the tool point's translation and nothing of the tool frame's rotation, so the tool
//! orientation is not identifiable from points, and the Jacobians skip the angular columns.

mod point;
mod pose6;

pub use point::Point;
pub use pose6::Pose6;

use crate::frame::TrackerFrame;
use crate::observations::Observations;
use nalgebra::{Matrix3, Vector3};

/// Largest number of residual rows one observation may have.
pub const MAX_ROWS: usize = 24;

/// Which components of the tool's motion a measurement kind sees.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Measurability {
    /// The tool point's translation (`dp`).
    pub position: bool,
    /// The tool frame's rotation (`dw`).
    pub orientation: bool,
}

/// The model's tool at one pose, as a kind needs it for its residual.
#[derive(Debug, Clone, Copy)]
pub struct ToolState {
    /// The tool point (mm, ACS).
    pub point: Vector3<f64>,
    /// The tool frame's rotation in the ACS, when the kind sees orientation or needs it.
    pub rotation: Option<Matrix3<f64>>,
}

/// One kind of measurement (see the module docs).
pub trait MeasurementKind: Sync {
    /// A short key (`point`).
    fn key(&self) -> &'static str;

    /// Residual rows per observation (at most [`MAX_ROWS`]).
    fn rows(&self) -> usize;

    /// What the kind sees of the tool's motion.
    fn measurability(&self) -> Measurability;

    /// Why parameters that only turn the tool frame cannot be identified from this kind, when
    /// they cannot (`points carry no orientation`).
    fn blind_to_orientation(&self) -> Option<&'static str> {
        None
    }

    /// How many of the last residual rows are orientation rows (rad): a fit weights them by
    /// the observations' mm per radian ([`Observations::mm_per_rad`]).
    fn orientation_rows(&self) -> usize {
        0
    }

    /// Numbers per observation in [`MeasurementKind::target`].
    fn target_len(&self) -> usize;

    /// Observation `i`'s measured values mapped into the base frame by the tracker frame
    /// `frame` (the paper's MF to ACS mapping), written to `out` (`target_len` numbers).
    fn target(&self, obs: &Observations, i: usize, frame: &TrackerFrame, out: &mut [f64]);

    /// The target the model's own tool would give (`target_len` numbers, ACS): the residual
    /// against it is zero. The identifiability analysis linearizes there.
    fn model_target(&self, tool: &ToolState, out: &mut [f64]);

    /// The residual rows `measured - model` for one observation (`rows` numbers; for a point,
    /// the paper's E_i of eq. 3).
    fn residual(&self, target: &[f64], tool: &ToolState, e: &mut [f64]);

    /// The Jacobian rows of the model's prediction with respect to the parameters `cols` (their
    /// positions in the robot's parameter list), from the parameters' screws at the tool:
    /// `jp` (tool point velocities) and, when the kind sees orientation, `jw` (angular
    /// velocities). Written row-major to `out` (`rows x cols.len()`). The residual's Jacobian is
    /// minus this. `target` is the observation's target (some kinds linearize about the
    /// residual).
    fn jacobian_rows(
        &self,
        target: &[f64],
        tool: &ToolState,
        jp: &[Vector3<f64>],
        jw: Option<&[Vector3<f64>]>,
        cols: &[usize],
        out: &mut [f64],
    );
}
