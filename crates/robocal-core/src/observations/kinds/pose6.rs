//! A 6-DoF measurement (a tracker's probe, e.g. a Leica T-Mac): the measured frame's position
//! and orientation. Six rows per observation: the point's error (as [`super::Point`]) and the
//! orientation error as a rotation vector `log(R_meas R_model^T)` in the ACS (rad), never a
//! difference of A, B, C angles, which are unstable near B = ±90 degrees (DESIGN.md). A fit weights
//! the orientation rows by the observations' mm per radian.

use super::{Measurability, MeasurementKind, ToolState};
use crate::frame::rotation_vector;
use crate::frame::TrackerFrame;
use crate::observations::Observations;
use nalgebra::{Matrix3, Vector3};

/// A measured tool frame.
pub struct Pose6;

/// The inverse right Jacobian of SO(3) at rotation vector `e`: how `log(exp(e) exp(-d))`
/// changes with a small `d` (`-J_r^{-1}(e) d`).
fn inverse_right_jacobian(e: &Vector3<f64>) -> Matrix3<f64> {
    let t = e.norm();
    let k = e.cross_matrix();
    let c = if t < 1e-4 {
        1.0 / 12.0 + t * t / 720.0
    } else {
        1.0 / (t * t) - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    Matrix3::identity() + 0.5 * k + c * k * k
}

impl MeasurementKind for Pose6 {
    fn key(&self) -> &'static str {
        "pose6"
    }

    fn rows(&self) -> usize {
        6
    }

    fn measurability(&self) -> Measurability {
        Measurability {
            position: true,
            orientation: true,
        }
    }

    fn orientation_rows(&self) -> usize {
        3
    }

    fn target_len(&self) -> usize {
        12
    }

    fn target(&self, obs: &Observations, i: usize, frame: &TrackerFrame, out: &mut [f64]) {
        let t = frame.to_base(obs.m(i));
        out[..3].copy_from_slice(t.as_slice());
        let r = frame.pose().rotation.matrix()
            * obs.rotation(i).copied().unwrap_or_else(Matrix3::identity);
        out[3..].copy_from_slice(r.as_slice());
    }

    fn model_target(&self, tool: &ToolState, out: &mut [f64]) {
        out[..3].copy_from_slice(tool.point.as_slice());
        let r = tool.rotation.unwrap_or_else(Matrix3::identity);
        out[3..12].copy_from_slice(r.as_slice());
    }

    fn residual(&self, target: &[f64], tool: &ToolState, e: &mut [f64]) {
        for a in 0..3 {
            e[a] = target[a] - tool.point[a];
        }
        let rt = Matrix3::from_column_slice(&target[3..12]);
        let rm = tool.rotation.unwrap_or_else(Matrix3::identity);
        let w = rotation_vector(&(rt * rm.transpose()));
        e[3..6].copy_from_slice(w.as_slice());
    }

    fn jacobian_rows(
        &self,
        target: &[f64],
        tool: &ToolState,
        jp: &[Vector3<f64>],
        jw: Option<&[Vector3<f64>]>,
        cols: &[usize],
        out: &mut [f64],
    ) {
        let k = cols.len();
        let mut e = [0.0; 6];
        self.residual(target, tool, &mut e);
        let jinv = inverse_right_jacobian(&Vector3::new(e[3], e[4], e[5]));
        let jw = jw.expect("a 6-DoF kind gets the angular screws");
        for (c, &j) in cols.iter().enumerate() {
            let v = jp[j];
            let w = jinv * jw[j];
            for a in 0..3 {
                out[a * k + c] = v[a];
                out[(3 + a) * k + c] = w[a];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    #[test]
    fn rotation_vector_inverts_exp_small_and_large() {
        for v in [
            Vector3::new(1e-9, -2e-9, 3e-10),
            Vector3::new(0.01, 0.2, -0.3),
            Vector3::new(1.0, -1.5, 0.5),
            Vector3::new(0.0, 3.0, 0.0),
        ] {
            let r = Rotation3::new(v).into_inner();
            let back = rotation_vector(&r);
            assert!(
                (back - v).norm() <= 1e-12 * (1.0 + v.norm()),
                "{v} -> {back}"
            );
        }
    }

    #[test]
    fn inverse_right_jacobian_matches_finite_differences() {
        let e = Vector3::new(0.02, -0.05, 0.03);
        let j = inverse_right_jacobian(&e);
        let re = Rotation3::new(e).into_inner();
        let h = 1e-7;
        for c in 0..3 {
            let mut d = Vector3::zeros();
            d[c] = h;
            let p = rotation_vector(&(re * Rotation3::new(-d).into_inner()));
            let m = rotation_vector(&(re * Rotation3::new(d).into_inner()));
            let fd = (p - m) / (2.0 * h);
            let an = -(j.column(c));
            assert!((fd - an).norm() < 1e-7, "column {c}: {fd} vs {an}");
        }
    }
}
