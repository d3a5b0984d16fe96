//! The paper's three points on a plane parallel to the base plane (section II.C: "initially,
//! transformation matrix Tr is set measuring 3 points on the plane parallel to the base plane of
//! the robot").
//!
//! The controller knows only the nominal model, so the three poses are chosen on it: their
//! nominal tool points share one height z and sit at the corners of an equilateral triangle
//! around the robot's base axis, as far apart as the typical reach allows. The real robot then
//! lands within its own errors of that plane, as in a real cell.

use super::poses::{random_poses, PoseSampler};
use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use nalgebra::{Matrix3, Vector3};
use rand::Rng;

/// Candidate poses drawn to find the plane's height, radius and good starting poses.
const CANDIDATES: usize = 300;
/// Starting poses tried per corner.
const STARTS_PER_CORNER: usize = 25;
/// Triangle orientations tried before giving up.
const ORIENTATIONS: usize = 12;
/// Plane poses keep this far from the joint limits (degrees), as a careful operator would.
const LIMIT_MARGIN_DEG: f64 = 5.0;
/// The same for a prismatic joint (mm).
const LIMIT_MARGIN_MM: f64 = 5.0;

/// Joint values (rad, or mm for a prismatic joint) that put the nominal tool point at `target`
/// (mm, base frame), starting from `start`, by damped least squares on the position Jacobian,
/// staying within the joint limits. `None` if it does not converge to `tol_mm` within
/// `max_iter` steps. A prismatic joint's motion is weighed as in
/// [`crate::DampedLeastSquares::prismatic_scale_mm`] (its default).
pub fn reach_position(
    robot: &Robot,
    start: &[f64],
    target: &Vector3<f64>,
    tol_mm: f64,
    max_iter: usize,
) -> Option<Vec<f64>> {
    reach_within(robot, start, target, tol_mm, max_iter, false)
}

/// The margin kept from joint `i`'s limits by the plane poses (rad or mm).
fn limit_margin(robot: &Robot, i: usize) -> f64 {
    match robot.joint_type(i) {
        JointType::Revolute => LIMIT_MARGIN_DEG.to_radians(),
        JointType::Prismatic => LIMIT_MARGIN_MM,
    }
}

/// [`reach_position`], with `margin` keeping [`limit_margin`] (at most a quarter of each joint's
/// range) away from the joint limits.
fn reach_within(
    robot: &Robot,
    start: &[f64],
    target: &Vector3<f64>,
    tol_mm: f64,
    max_iter: usize,
    margin: bool,
) -> Option<Vec<f64>> {
    let n = robot.dof();
    let bounds: Vec<(f64, f64)> = robot
        .limits()
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let m = if margin { limit_margin(robot, i) } else { 0.0 };
            let m = m.min(0.25 * (l.max - l.min));
            (l.min + m, l.max - m)
        })
        .collect();
    let scale = crate::DampedLeastSquares::default().prismatic_scale_mm;
    let sc: Vec<f64> = robot
        .joint_types()
        .iter()
        .map(|t| match t {
            JointType::Revolute => 1.0,
            JointType::Prismatic => scale,
        })
        .collect();
    let mut q = start.to_vec();
    let mut jq = vec![Vector3::zeros(); n];
    for _ in 0..max_iter {
        let p = robot.tool_position_jacobians(&q, Some(&mut jq), None);
        let e = target - p;
        if e.norm() < tol_mm {
            return Some(q);
        }
        // du = Js^T (Js Js^T + lambda^2 I)^-1 e with the scaled Jacobian Js = J S, dq = S du;
        // lambda small against Js's scale (mm/rad).
        let mut jjt = Matrix3::zeros();
        for (c, s) in jq.iter().zip(&sc) {
            jjt += c * c.transpose() * (s * s);
        }
        let lambda2 = 1e-8 * jjt.trace() + 1e-12;
        let w = (jjt + Matrix3::identity() * lambda2).lu().solve(&e)?;
        let mut du: Vec<f64> = jq.iter().zip(&sc).map(|(c, s)| s * c.dot(&w)).collect();
        let big = du.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if big > 0.2 {
            du.iter_mut().for_each(|v| *v *= 0.2 / big);
        }
        for (((v, d), (lo, hi)), s) in q.iter_mut().zip(&du).zip(&bounds).zip(&sc) {
            *v = (*v + s * d).clamp(*lo, *hi);
        }
    }
    None
}

/// Rounds joint values (rad, or mm for a prismatic joint) of `robot` to the resolution of the
/// measurement CSV (1e-9 degree or mm), so that the positions computed from them are those of
/// the values written.
pub fn quantize_joints(robot: &Robot, q: &mut [f64]) {
    let s = robot.joint_space();
    for (i, v) in q.iter_mut().enumerate() {
        *v = s.to_internal(i, (s.to_display(i, *v) * 1e9).round() / 1e9);
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Three poses whose nominal tool points lie on the plane `z = z_mm` (base frame), at the corners
/// of an equilateral triangle centred on the base axis, with every joint at least 5 degrees (5 mm
/// for a prismatic joint; or a quarter of its range) inside its limits. `plane_z_mm: None` picks the median tool
/// height of random poses; the triangle's radius is their median distance from the base axis.
/// Returns the poses (rad, quantized as in the CSV) and the plane's height.
pub fn plane_poses<R: Rng + ?Sized>(
    robot: &Robot,
    sampler: &PoseSampler,
    plane_z_mm: Option<f64>,
    rng: &mut R,
) -> Result<(Vec<Vec<f64>>, f64)> {
    if let Some(z) = plane_z_mm {
        if !z.is_finite() {
            return Err(Error::invalid("plane_z_mm", "not a finite number"));
        }
        if z < sampler.floor_z_mm {
            return Err(Error::invalid(
                "plane_z_mm",
                format!("{z} mm is below the floor ({} mm)", sampler.floor_z_mm),
            ));
        }
    }
    let cands = random_poses(robot, CANDIDATES, sampler, rng)?;
    let pos: Vec<Vector3<f64>> = cands.iter().map(|q| robot.tool_position(q)).collect();
    let z = plane_z_mm.unwrap_or_else(|| median(pos.iter().map(|p| p.z).collect()));
    let radius =
        median(pos.iter().map(|p| p.xy().norm()).collect()).max(sampler.footprint_radius_mm);
    for _ in 0..ORIENTATIONS {
        let theta0 = rng.gen_range(0.0..std::f64::consts::TAU);
        let mut found = Vec::with_capacity(3);
        for k in 0..3 {
            let th = theta0 + k as f64 * std::f64::consts::TAU / 3.0;
            let target = Vector3::new(radius * th.cos(), radius * th.sin(), z);
            let mut order: Vec<usize> = (0..cands.len()).collect();
            order.sort_by(|&a, &b| {
                (pos[a] - target)
                    .norm()
                    .total_cmp(&(pos[b] - target).norm())
            });
            let hit = order.iter().take(STARTS_PER_CORNER).find_map(|&i| {
                let mut q = reach_within(robot, &cands[i], &target, 1e-7, 200, true)?;
                quantize_joints(robot, &mut q);
                let p = robot.tool_position(&q);
                ((p - target).norm() < 1e-5 && sampler.accepts(&p)).then_some(q)
            });
            match hit {
                Some(q) => found.push(q),
                None => break,
            }
        }
        if found.len() == 3 {
            return Ok((found, z));
        }
    }
    Err(Error::invalid(
        "plane points",
        format!(
            "found no three poses with the tool at z = {z:.1} mm, {radius:.1} mm from the base \
             axis, 120 degrees apart, within the joint limits; choose another `plane_z_mm` or \
             leave the plane points out (`plane_points`)"
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;
    use rand::SeedableRng;

    #[test]
    fn three_points_on_one_level_well_spread() {
        let r = preset("kuka-kr480-r3330").unwrap();
        let s = PoseSampler {
            footprint_radius_mm: 700.0,
            ..PoseSampler::default()
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let (qs, z) = plane_poses(&r, &s, None, &mut rng).unwrap();
        assert_eq!(qs.len(), 3);
        let p: Vec<_> = qs.iter().map(|q| r.tool_position(q)).collect();
        for (q, pi) in qs.iter().zip(&p) {
            assert!((pi.z - z).abs() < 1e-5, "{} vs {z}", pi.z);
            for (v, l) in q.iter().zip(r.limits()) {
                let m = (LIMIT_MARGIN_DEG - 1e-6).to_radians();
                assert!(v - l.min >= m && l.max - v >= m, "{v} near a limit");
            }
            assert!(s.accepts(pi));
        }
        // Equilateral: every side at least 1.5 m for this robot.
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let side = (p[a] - p[b]).norm();
            assert!(side > 1500.0, "side {side}");
        }
        let (_, z2) = plane_poses(&r, &s, Some(1200.0), &mut rng).unwrap();
        assert_eq!(z2, 1200.0);
        assert!(plane_poses(&r, &s, Some(-5.0), &mut rng).is_err());
        assert!(plane_poses(&r, &s, Some(20_000.0), &mut rng).is_err());
    }

    #[test]
    fn reach_position_converges() {
        let r = preset("kuka-kr480-r3330").unwrap();
        let q0 = [0.1, -0.8, 0.5, 0.2, 0.6, -0.3];
        let target = r.tool_position(&q0) + Vector3::new(150.0, -80.0, 60.0);
        let q = reach_position(&r, &q0, &target, 1e-8, 100).unwrap();
        assert!((r.tool_position(&q) - target).norm() < 1e-8);
    }
}
