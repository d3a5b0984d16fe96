//! One reflector's position: the paper's measurement (section II.A). Three rows per observation:
//! the error vector `E_i = pose(F) m_i - p(q_i)` (eq. 3), whose Jacobian rows are the tool point's
//! velocities `dp`.

use super::{Measurability, MeasurementKind, ToolState};
use crate::frame::TrackerFrame;
use crate::observations::Observations;
use nalgebra::Vector3;

/// A measured tool point.
pub struct Point;

impl MeasurementKind for Point {
    fn key(&self) -> &'static str {
        "point"
    }

    fn rows(&self) -> usize {
        3
    }

    fn measurability(&self) -> Measurability {
        Measurability {
            position: true,
            orientation: false,
        }
    }

    fn blind_to_orientation(&self) -> Option<&'static str> {
        Some("points carry no orientation")
    }

    fn target_len(&self) -> usize {
        3
    }

    #[inline]
    fn target(&self, obs: &Observations, i: usize, frame: &TrackerFrame, out: &mut [f64]) {
        let t = frame.to_base(&obs.measured()[i]);
        out.copy_from_slice(t.as_slice());
    }

    fn model_target(&self, tool: &ToolState, out: &mut [f64]) {
        out[..3].copy_from_slice(tool.point.as_slice());
    }

    #[inline]
    fn residual(&self, target: &[f64], tool: &ToolState, e: &mut [f64]) {
        for a in 0..3 {
            e[a] = target[a] - tool.point[a];
        }
    }

    #[inline]
    fn jacobian_rows(
        &self,
        _target: &[f64],
        _tool: &ToolState,
        jp: &[Vector3<f64>],
        _jw: Option<&[Vector3<f64>]>,
        cols: &[usize],
        out: &mut [f64],
    ) {
        let k = cols.len();
        let (x, rest) = out.split_at_mut(k);
        let (y, z) = rest.split_at_mut(k);
        // Zipped rather than indexed: one bounds check a column (the screw's) instead of four.
        for (((x, y), z), &j) in x.iter_mut().zip(y).zip(&mut z[..k]).zip(cols) {
            let v = jp[j];
            *x = v.x;
            *y = v.y;
            *z = v.z;
        }
    }
}
