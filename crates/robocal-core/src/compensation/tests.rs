use super::*;
use crate::model::{presets::preset, JointLimit};
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::{Matrix3, Vector3};
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

fn within_limits(robot: &Robot, q: &[f64]) -> bool {
    robot.joints_outside_limits(q).is_empty()
}

/// IK on 10,000 random reachable targets: the Table III model's own tool positions at random
/// joints within the limits, started from joints off by up to 0.01 rad each (the size of a
/// compensation). Every solve must converge to 1e-6 mm (checked by an independent forward
/// kinematics), within the limits.
#[test]
fn ik_converges_on_10000_random_reachable_targets() {
    let (_, cal) = kuka();
    let solver = DampedLeastSquares::default();
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    let mut q = vec![0.0; 6];
    let mut worst: f64 = 0.0;
    let mut max_iter = 0;
    for t in uniform_poses(&cal, 10_000, 1) {
        let target = cal.tool_position(&t);
        let start: Vec<f64> = t.iter().map(|v| v + rng.gen_range(-0.01..0.01)).collect();
        let rep = solver.solve(&cal, &target, &start, &mut q);
        assert_eq!(rep.status, IkStatus::Converged, "{t:?}: {rep:?}");
        let r = (cal.tool_position(&q) - target).norm();
        assert!(r <= 1e-6, "{t:?}: residual {r}");
        assert!((r - rep.residual_mm).abs() < 1e-9);
        assert!(within_limits(&cal, &q), "{q:?}");
        worst = worst.max(r);
        max_iter = max_iter.max(rep.iterations);
    }
    eprintln!("worst residual {worst:.2e} mm, max iterations {max_iter}");
}

/// The paper's compensation (eq. 12-14) on 10,000 random desired poses over the whole joint space:
/// target = nominal (Table I) tool position, solved on the Table III model from the desired joints.
/// Every row converges to 1e-6 mm with a small joint change, except targets the Table III arm
/// cannot reach (nominal points at the outer edge of the workspace, with the arm stretched out):
/// those are reported `unreachable`, and 200 further starts around the pose confirm that no
/// solution exists nearby.
#[test]
fn compensation_of_10000_random_poses_converges_or_reports() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut q = vec![0.0; 6];
    let mut unreachable = 0;
    let mut max_change: f64 = 0.0;
    for d in uniform_poses(&nom, 10_000, 1) {
        let (target, rep) = comp.compensate(&d, &mut q);
        let r = (cal.tool_position(&q) - target).norm();
        assert!((r - rep.residual_mm).abs() < 1e-9);
        assert!(within_limits(&cal, &q), "{q:?}");
        match rep.status {
            IkStatus::Converged => {
                assert!(r <= 1e-6, "{d:?}: residual {r}");
                let change = q
                    .iter()
                    .zip(&d)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                max_change = max_change.max(change);
            }
            IkStatus::Unreachable => {
                unreachable += 1;
                let mut other = vec![0.0; 6];
                for _ in 0..200 {
                    let s: Vec<f64> = d.iter().map(|v| v + rng.gen_range(-0.5..0.5)).collect();
                    let again = comp.solver.solve(&cal, &target, &s, &mut other);
                    assert!(
                        !again.status.is_converged(),
                        "{d:?} is reachable from {s:?}"
                    );
                }
            }
            _ => panic!("{d:?}: {rep:?}"),
        }
    }
    assert!(unreachable <= 10, "{unreachable} unreachable");
    // The model difference is a few mm on a 3 m arm: the correction is a small joint motion
    // (largest near the stretched-out arm, where the tool moves little per radian).
    assert!(max_change < 0.6, "largest joint change {max_change} rad");
    eprintln!("unreachable {unreachable}, largest joint change {max_change:.3} rad");
}

/// The step is the minimum-norm one: the joint correction lies in the row space of the joint
/// Jacobian at the desired pose (to first order), i.e. no motion is wasted in the null space.
#[test]
fn compensation_step_is_minimum_norm() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    for d in uniform_poses(&nom, 200, 2) {
        let (_, rep) = comp.compensate(&d, &mut q);
        assert!(rep.status.is_converged());
        if rep.limited_joints().next().is_some() {
            continue;
        }
        let mut jq = [Vector3::zeros(); 6];
        cal.tool_position_jacobians(&d, Some(&mut jq), None);
        let dq: Vec<f64> = q.iter().zip(&d).map(|(a, b)| a - b).collect();
        // Projection of dq onto the row space: J^T (J J^T)^-1 J dq.
        let mut jjt = Matrix3::zeros();
        let mut jdq = Vector3::zeros();
        for i in 0..6 {
            jjt += jq[i] * jq[i].transpose();
            jdq += jq[i] * dq[i];
        }
        let y = jjt.try_inverse().unwrap() * jdq;
        let norm: f64 = dq.iter().map(|v| v * v).sum::<f64>().sqrt();
        let off: f64 = (0..6)
            .map(|i| (dq[i] - jq[i].dot(&y)).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(off < 0.05 * norm, "null-space part {off} of {norm}");
    }
}

/// Cartesian targets without a seed: points the Table III model reaches within its limits, solved
/// from the default seeds. All must converge.
#[test]
fn reachable_cartesian_targets_converge_from_default_seeds() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    let mut failed = Vec::new();
    for t in uniform_poses(&cal, 2_000, 3) {
        let p = cal.tool_position(&t);
        let rep = comp.reach(&p, None, &mut q);
        if !rep.status.is_converged() {
            failed.push((t, rep));
            continue;
        }
        assert!((cal.tool_position(&q) - p).norm() <= 1e-6);
        assert!(within_limits(&cal, &q));
    }
    assert!(
        failed.is_empty(),
        "{} failed: {:?}",
        failed.len(),
        &failed[..failed.len().min(5)]
    );
}

/// Targets outside the workspace are reported as unreachable, with the distance from the nearest
/// point the arm reaches; never as converged.
#[test]
fn targets_outside_the_workspace_are_reported() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    for _ in 0..50 {
        // Beyond any reach: 6 to 20 m from the base, any direction.
        let dir = Vector3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        )
        .normalize();
        let p = dir * rng.gen_range(6_000.0..20_000.0);
        let rep = comp.reach(&p, None, &mut q);
        assert_eq!(rep.status, IkStatus::Unreachable, "{p}: {rep:?}");
        let r = (cal.tool_position(&q) - p).norm();
        assert!((r - rep.residual_mm).abs() < 1e-6);
        assert!(r > 1_000.0, "{r}");
        assert!(within_limits(&cal, &q));
    }
    // Below the floor, beyond reach even without joint limits (while the limits also block the
    // way from most starts): unreachable, not joint_limit.
    let p = Vector3::new(0.0, 0.0, -3_000.0);
    let rep = comp.reach(&p, None, &mut q);
    assert_eq!(rep.status, IkStatus::Unreachable, "{rep:?}");
    // The same through the batch API with a seed: the row is kept and flagged.
    let targets = vec![
        Target {
            line: 2,
            p: Vector3::new(8_000.0, 0.0, 1_000.0),
            abc: None,
            seed: Some(vec![0.0; 6]),
            extra: vec![],
        },
        Target {
            line: 3,
            p: cal.tool_position(&[0.1, -0.5, 0.4, 0.2, 0.3, 0.0]),
            abc: None,
            seed: None,
            extra: vec![],
        },
    ];
    let out = comp.reach_all(&targets, &()).unwrap();
    assert_eq!(out.len(), 2);
    assert_eq!(out[0].report.status, IkStatus::Unreachable);
    assert_eq!(out[1].report.status, IkStatus::Converged);
}

/// A target reachable only with a joint beyond its limit is reported as `joint_limit`, the
/// returned joints stay within the limits and name the joint at its limit.
#[test]
fn targets_beyond_the_limits_are_reported() {
    let (nom, mut cal) = kuka();
    let mut lim = cal.limits().to_vec();
    lim[0] = JointLimit {
        min: (-10f64).to_radians(),
        max: 10f64.to_radians(),
    };
    cal.set_limits(lim).unwrap();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    // Reachable at q1 = 60 degrees.
    let p = cal.tool_position(&[60f64.to_radians(), -0.5, 0.4, 0.2, 0.3, 0.0]);
    let rep = comp.reach(&p, None, &mut q);
    assert_eq!(rep.status, IkStatus::JointLimit, "{rep:?}");
    assert!(within_limits(&cal, &q));
    assert_eq!(rep.limited_joints().collect::<Vec<_>>(), vec![0]);
    assert!(rep.residual_mm > 100.0);
}

/// Desired poses at a joint limit (q2 at +20 degrees): redundancy lets the other joints take the
/// correction, so compensation still converges within the limits.
#[test]
fn desired_poses_at_a_limit_still_converge() {
    let (nom, cal) = kuka();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    for mut d in uniform_poses(&nom, 500, 5) {
        d[1] = nom.limits()[1].max;
        let (_, rep) = comp.compensate(&d, &mut q);
        assert_eq!(rep.status, IkStatus::Converged, "{d:?} {rep:?}");
        assert!(within_limits(&cal, &q));
    }
}

/// The nominal model compensated by itself: zero correction, zero iterations of change.
#[test]
fn identical_models_give_identical_joints() {
    let (nom, _) = kuka();
    let comp = Compensator::new(&nom, &nom, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 6];
    for d in uniform_poses(&nom, 100, 6) {
        let (_, rep) = comp.compensate(&d, &mut q);
        assert_eq!(rep.status, IkStatus::Converged);
        assert_eq!(q, d);
        assert_eq!(rep.iterations, 1);
    }
}

/// A 7-joint chain (standard DH, the Barrett WAM of the real data) and a perturbed copy: the
/// solver is not tied to six joints or to MDH.
#[test]
fn seven_joint_dh_chain_compensates() {
    let wam = crate::load_robot(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/wam.toml"
    ))
    .unwrap();
    let mut cal = wam.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for p in wam.params() {
        let dv = match p.unit() {
            crate::Unit::Mm => rng.gen_range(-1.0..1.0),
            crate::Unit::Deg => rng.gen_range(-0.002..0.002),
            // The geometric robots of these tests have no other units.
            _ => 0.0,
        };
        cal.set(p, wam.get(p) + dv);
    }
    let comp = Compensator::new(&wam, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 7];
    for d in uniform_poses(&wam, 1_000, 8) {
        let (t, rep) = comp.compensate(&d, &mut q);
        assert_eq!(rep.status, IkStatus::Converged, "{d:?} {rep:?}");
        assert!((cal.tool_position(&q) - t).norm() <= 1e-6);
    }
}

#[test]
fn mismatched_models_and_bad_settings_are_errors() {
    let (nom, _) = kuka();
    let wam = crate::load_robot(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/wam.toml"
    ))
    .unwrap();
    assert!(Compensator::new(&nom, &wam, DampedLeastSquares::default()).is_err());
    let mut s = DampedLeastSquares::default();
    assert!(s.validate().is_ok());
    s.tolerance_mm = 0.0;
    assert!(s.validate().is_err());
    s = DampedLeastSquares {
        max_iterations: 0,
        ..Default::default()
    };
    assert!(s.validate().is_err());
    s = DampedLeastSquares {
        stationary_cosine: f64::NAN,
        ..Default::default()
    };
    assert!(s.validate().is_err());
    let comp = Compensator::new(&nom, &nom, DampedLeastSquares::default()).unwrap();
    let e = comp
        .compensate_all(&[vec![0.0; 5]], &())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("desired pose 1") && e.contains("expected 6"),
        "{e}"
    );
}

#[test]
fn statuses_roundtrip_and_seeds_are_within_limits() {
    for s in IkStatus::ALL {
        assert_eq!(IkStatus::parse(s.as_str()), Some(s));
    }
    assert_eq!(IkStatus::parse("done"), None);
    let (nom, _) = kuka();
    let seeds = default_seeds(&nom, 8);
    assert_eq!(seeds.len(), 8);
    for s in &seeds {
        assert!(within_limits(&nom, s), "{s:?}");
    }
    assert_ne!(seeds[1], seeds[2]);
}

/// The allocation-free axis of joint 1 used to turn seeds agrees with `joint_axes`.
#[test]
fn seed_turning_uses_joint_1_axis() {
    let (_, cal) = kuka();
    let wam = crate::load_robot(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/wam.toml"
    ))
    .unwrap();
    for r in [&cal, &wam] {
        let n = r.dof();
        let mut q = vec![0.3; n];
        let target = r.tool_position(&{
            let mut t = q.clone();
            t[0] += 0.7;
            t
        });
        turn_towards(r, &target, &mut q);
        // Turning joint 1 alone back onto the target's azimuth recovers the 0.7 rad.
        assert!((q[0] - 1.0).abs() < 1e-9, "{}: {}", r.name(), q[0]);
    }
}

/// The KR 480 on a linear track (`examples/kr480-track.toml`) and a "calibrated" copy with
/// seeded random errors of the paper's size (0.5 mm, 0.03 deg).
fn track() -> (Robot, Robot) {
    let nom = crate::load_robot_file(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/kr480-track.toml"
    )))
    .unwrap();
    let cal = crate::simulation::GeometricErrors::default()
        .apply(&nom, &mut ChaCha8Rng::seed_from_u64(3))
        .unwrap();
    (nom, cal)
}

/// Compensation (eq. 12-14) of 2,000 random desired poses of the tracked robot: every row
/// converges to 1e-6 mm within the limits (the track's too), or is reported unreachable; the
/// correction mixes mm of track and radians of arm, and stays small in both.
#[test]
fn compensation_converges_on_the_tracked_robot() {
    let (nom, cal) = track();
    assert_eq!(nom.joint_type(0), crate::JointType::Prismatic);
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 7];
    let (mut converged, mut unreachable) = (0, 0);
    let (mut max_track, mut max_angle) = (0.0f64, 0.0f64);
    for d in uniform_poses(&nom, 2000, 4) {
        let (target, rep) = comp.compensate(&d, &mut q);
        let r = (cal.tool_position(&q) - target).norm();
        assert!((r - rep.residual_mm).abs() < 1e-9);
        assert!(within_limits(&cal, &q), "{q:?}");
        match rep.status {
            IkStatus::Converged => {
                converged += 1;
                assert!(r <= 1e-6, "{d:?}: residual {r}");
                max_track = max_track.max((q[0] - d[0]).abs());
                for i in 1..7 {
                    max_angle = max_angle.max((q[i] - d[i]).abs());
                }
            }
            IkStatus::Unreachable => unreachable += 1,
            _ => panic!("{d:?}: {rep:?}"),
        }
    }
    eprintln!(
        "converged {converged}, unreachable {unreachable}, largest change {max_track:.3} mm of \
         track, {max_angle:.4} rad of arm"
    );
    assert!(converged >= 1990, "{converged} converged");
    assert!(
        max_track > 0.0 && max_track < 20.0,
        "track moved {max_track} mm"
    );
    assert!(max_angle < 0.6, "arm moved {max_angle} rad");
}

/// Cartesian targets along the whole track, without start configurations: the default seeds
/// (spread over the track's travel) and the turn of the arm's first axis find every one.
#[test]
fn reach_along_the_track_without_seeds() {
    let (nom, cal) = track();
    let comp = Compensator::new(&nom, &cal, DampedLeastSquares::default()).unwrap();
    let mut q = vec![0.0; 7];
    for t in uniform_poses(&cal, 300, 5) {
        let target = cal.tool_position(&t);
        let rep = comp.reach(&target, None, &mut q);
        assert_eq!(rep.status, IkStatus::Converged, "{t:?}: {rep:?}");
        assert!((cal.tool_position(&q) - target).norm() <= 1e-6);
        assert!(within_limits(&cal, &q), "{q:?}");
    }
}
