//! Full-pose compensation: the calibrated tool on the nominal pose, position and orientation,
//! on the desired configuration, with statuses for singular neighbourhoods, configuration
//! changes and poses out of reach.

use super::configuration::configuration;
use super::*;
use crate::frame::Frame;
use crate::model::presets::preset;
use crate::simulation::{random_poses, PoseSampler};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn kuka() -> (Robot, Robot) {
    (
        preset("kuka-kr480-r3330").unwrap(),
        preset("kuka-kr480-r3330-table3").unwrap(),
    )
}

fn uniform_poses(robot: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    random_poses(
        robot,
        n,
        &PoseSampler {
            floor_z_mm: f64::NEG_INFINITY,
            ..PoseSampler::default()
        },
        &mut rng,
    )
    .unwrap()
}

/// Position (mm) and orientation (deg) distance of two frames, computed independently of the
/// solver: the angle of `R_a^T R_b` from its trace.
fn pose_distance(a: &Frame, b: &Frame) -> (f64, f64) {
    let dp = (a.translation.vector - b.translation.vector).norm();
    let r = a.rotation.matrix().transpose() * b.rotation.matrix();
    let c = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    // acos loses precision near 0: use the skew part's norm there.
    let s = 0.5
        * ((r[(2, 1)] - r[(1, 2)]).powi(2)
            + (r[(0, 2)] - r[(2, 0)]).powi(2)
            + (r[(1, 0)] - r[(0, 1)]).powi(2))
        .sqrt();
    (dp, s.atan2(c).to_degrees())
}

/// The acceptance test: 10,000 random poses over the whole joint space, target = the
/// nominal (Table I) tool frame, solved on the Table III model from the desired joints. Every
/// pose outside the singular neighbourhood converges to 1e-6 mm and 1e-6 deg (checked by forward
/// kinematics here) on the desired configuration; the rest are `singular` (and really near a
/// singularity), near the joint limits `joint_limit`, or, where the calibrated arm cannot reach
/// even the point (as position-only compensation confirms), `unreachable`. Nothing else.
#[test]
fn full_pose_compensation_of_10000_random_poses() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (mut singular, mut limit, mut unreachable) = (0, 0, 0);
    let (mut worst_mm, mut worst_deg, mut max_iter) = (0.0f64, 0.0f64, 0);
    for d in uniform_poses(&nom, 10_000, 3) {
        let (target, rep) = comp.compensate_pose(&d, &mut q);
        let (dp, dw) = pose_distance(&cal.tool_pose(&q), &nom.tool_pose(&d));
        assert!(nom.joints_outside_limits(&q).is_empty() || rep.status == IkStatus::JointLimit);
        assert!((target.translation.vector - nom.tool_position(&d)).norm() < 1e-9);
        let (cd, cc) = (
            configuration(&nom, &d).unwrap(),
            configuration(&cal, &q).unwrap(),
        );
        match rep.status {
            IkStatus::Converged => {
                assert!(dp <= 1e-6 && dw <= 1e-6, "{d:?}: {dp} mm {dw} deg");
                assert!((dp - rep.residual_mm).abs() < 1e-9);
                assert_eq!(cd.flags, cc.flags, "{d:?}");
                assert!(cd.margin() >= 0.01 && cc.margin() >= 0.01);
                worst_mm = worst_mm.max(dp);
                worst_deg = worst_deg.max(dw);
                max_iter = max_iter.max(rep.iterations);
            }
            IkStatus::Singular => {
                singular += 1;
                assert!(dp <= 1e-6 && dw <= 1e-6, "{d:?}: {dp} mm {dw} deg");
                assert!(cd.margin().min(cc.margin()) < 0.01, "{cd:?} {cc:?}");
            }
            IkStatus::JointLimit => {
                limit += 1;
                assert!(rep.joints_at_limit != 0);
            }
            IkStatus::Unreachable => {
                // The nominal arm stretched out at the edge of its workspace, where the
                // calibrated arm cannot follow on the desired branch: 100 further starts around
                // the pose confirm that no solution exists nearby on that branch (the pose may
                // be reachable on another one, e.g. with the elbow bent the other way).
                unreachable += 1;
                let mut other = vec![0.0; 6];
                for _ in 0..100 {
                    let s: Vec<f64> = d.iter().map(|v| v + rng.gen_range(-0.5..0.5)).collect();
                    let again = comp.pose_solver.solve(&cal, &target, 0, &s, &mut other);
                    if again.status.reaches_target() {
                        let c = configuration(&cal, &other).unwrap();
                        assert_ne!(c.flags, cd.flags, "{d:?} reachable from {s:?}");
                    }
                }
            }
            _ => panic!("{d:?}: {rep:?}"),
        }
    }
    eprintln!(
        "worst {worst_mm:.1e} mm {worst_deg:.1e} deg, max iterations {max_iter}, \
         singular {singular}, joint_limit {limit}, unreachable {unreachable}"
    );
    // Measured: 149 of 10,000 (the stretched-out elbow of the longer nominal arm).
    assert!(unreachable <= 200, "{unreachable} unreachable");
    // The singular neighbourhood (margin 0.01) is a small part of the joint space.
    assert!(singular < 400, "{singular} singular");
    assert!(limit < 100, "{limit} at a limit");
}

/// Across the wrist singularity: a pose whose wrist is 2 degrees on one side, solved from a seed
/// 2 degrees on the other side (same q4, q6), is reached on the pose's branch, not the seed's:
/// `configuration_change`. Half a degree from the singularity: `singular`.
#[test]
fn a_branch_change_and_a_singular_neighbourhood_get_their_statuses() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    let two = 2f64.to_radians();
    let target = cal.tool_pose(&[0.3, -1.2, 1.3, 0.4, two, 0.2]);
    let seed = [0.3, -1.2, 1.3, 0.4, -two, 0.2];
    let rep = comp.reach_pose(&target, Some(&seed), &mut q);
    assert_eq!(rep.status, IkStatus::ConfigurationChange, "{rep:?} {q:?}");
    assert!(rep.residual_mm <= 1e-6 && rep.residual_deg <= 1e-6);
    assert!(!rep.status.is_converged() && rep.status.reaches_target());
    let (a, b) = (
        configuration(&cal, &seed).unwrap(),
        configuration(&cal, &q).unwrap(),
    );
    assert_eq!(a.changes(&b), vec!["wrist"]);
    // Half a degree from the wrist singularity.
    let d = [0.3, -1.2, 1.3, 0.4, 0.5f64.to_radians(), 0.2];
    let (_, rep) = comp.compensate_pose(&d, &mut q);
    assert_eq!(rep.status, IkStatus::Singular, "{rep:?}");
    // Far from it, the same pose converges on the same branch.
    let d = [0.3, -1.2, 1.3, 0.4, 0.6, 0.2];
    let (_, rep) = comp.compensate_pose(&d, &mut q);
    assert_eq!(rep.status, IkStatus::Converged, "{rep:?}");
}

/// Cartesian poses: out of reach is `unreachable`; a reachable pose with a seed converges on the
/// seed's branch; without a seed one of the default starts reaches it.
#[test]
fn cartesian_poses_reach_or_report() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    let seed = [0.3, -1.0, 1.2, 0.4, 0.9, -0.3];
    let target = cal.tool_pose(&seed);
    let start: Vec<f64> = seed.iter().map(|v| v + 0.05).collect();
    let rep = comp.reach_pose(&target, Some(&start), &mut q);
    assert_eq!(rep.status, IkStatus::Converged, "{rep:?}");
    let (dp, dw) = pose_distance(&cal.tool_pose(&q), &target);
    assert!(dp <= 1e-6 && dw <= 1e-6);
    let rep = comp.reach_pose(&target, None, &mut q);
    assert!(rep.status.reaches_target(), "{rep:?}");
    let (dp, dw) = pose_distance(&cal.tool_pose(&q), &target);
    assert!(dp <= 1e-6 && dw <= 1e-6);
    // 9 m away: out of reach.
    let far = Frame::from_parts(
        nalgebra::Translation3::new(9000.0, 0.0, 1000.0),
        target.rotation,
    );
    let rep = comp.reach_pose(&far, Some(&seed), &mut q);
    assert_eq!(rep.status, IkStatus::Unreachable, "{rep:?}");
    assert!(rep.residual_mm > 1000.0);
}

#[test]
fn statuses_read_back_and_settings_are_checked() {
    for s in IkStatus::ALL {
        assert_eq!(IkStatus::parse(s.as_str()), Some(s));
    }
    assert_eq!(
        IkStatus::parse("configuration_change"),
        Some(IkStatus::ConfigurationChange)
    );
    assert!(PoseNewton::default().validate().is_ok());
    let bad = PoseNewton {
        tolerance_deg: 0.0,
        ..PoseNewton::default()
    };
    assert!(bad
        .validate()
        .unwrap_err()
        .to_string()
        .contains("tolerance_deg"));
}
