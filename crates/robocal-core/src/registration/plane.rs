//! The paper's initial measurement frame: three points on a plane parallel to the robot's base
//! plane (section II.C, "Initially, transformation matrix Tr is set measuring 3 points on the
//! plane parallel to the base plane of the robot").

use crate::error::{Error, Result};
use crate::frame::{self, Frame, TrackerFrame};
use nalgebra::{Matrix3, Vector3};

/// Smallest angle (degrees) the three points may span at any corner before they count as collinear.
const MIN_CORNER_DEG: f64 = 1.0;

/// The frame built on three points: origin at `p[0]`, x towards `p[1]`, z normal to their plane.
fn triad(p: &[Vector3<f64>; 3], what: &str) -> Result<Frame> {
    let u = p[1] - p[0];
    let v = p[2] - p[0];
    let n = u.cross(&v);
    // |u x v| = |u||v| sin(angle): require a real triangle.
    let w = p[2] - p[1];
    let longest = u.norm().max(v.norm()).max(w.norm());
    let sin_min = MIN_CORNER_DEG.to_radians().sin();
    if longest.is_nan() || longest <= 0.0 || n.norm() <= sin_min * longest * longest * 0.5 {
        return Err(Error::Numerical(format!(
            "registration: the three plane points ({what}) are (nearly) collinear; the plane \
             they define is undetermined"
        )));
    }
    let x = u.normalize();
    let z = n.normalize();
    let y = z.cross(&x);
    Ok(frame::frame(Matrix3::from_columns(&[x, y, z]), p[0]))
}

/// The rigid frame mapping the three measured plane points (tracker frame) onto their nominal
/// positions (base frame): the plane's normal goes to the nominal plane's normal, the direction
/// from the first to the second point to its nominal direction, the first point onto its nominal
/// position. With a plane parallel to the base plane the normal is the base z axis, which fixes
/// the frame's tilt exactly as the paper's procedure does.
pub fn plane_frame(
    measured: &[Vector3<f64>; 3],
    nominal: &[Vector3<f64>; 3],
) -> Result<TrackerFrame> {
    let m = triad(measured, "measured")?;
    let p = triad(nominal, "nominal positions")?;
    Ok(TrackerFrame::new(p * m.inverse()))
}

/// The angle (degrees) between the nominal plane of three points and the base plane (x-y): the
/// paper's procedure assumes it is zero.
pub fn plane_tilt_deg(nominal: &[Vector3<f64>; 3]) -> f64 {
    let n = (nominal[1] - nominal[0]).cross(&(nominal[2] - nominal[0]));
    let c = (n.z.abs() / n.norm()).clamp(0.0, 1.0);
    c.acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::pose;

    #[test]
    fn three_points_give_the_exact_frame() {
        let f = TrackerFrame::new(pose(&[4000.0, 300.0, -200.0, 2.2, 0.01, 0.02]));
        let nominal = [
            Vector3::new(2000.0, 0.0, 800.0),
            Vector3::new(2500.0, 600.0, 800.0),
            Vector3::new(1800.0, -700.0, 800.0),
        ];
        let measured = nominal.map(|p| f.to_tracker(&p));
        let g = plane_frame(&measured, &nominal).unwrap();
        for (m, p) in measured.iter().zip(&nominal) {
            assert!((g.to_base(m) - p).norm() < 1e-9);
        }
        assert!(plane_tilt_deg(&nominal) < 1e-12);
    }

    #[test]
    fn collinear_plane_points_are_rejected() {
        let p = [
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(2.0, 0.001, 0.0),
        ];
        assert!(plane_frame(&p, &p)
            .unwrap_err()
            .to_string()
            .contains("collinear"));
    }
}
