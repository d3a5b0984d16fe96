use super::poe::Poe;
use crate::model::{presets::preset, Convention, JointLimit, JointType, Link, Param, Robot};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_robot(rng: &mut ChaCha8Rng, conv: Convention, n: usize, betas: bool) -> Robot {
    let links = (0..n)
        .map(|_| Link {
            alpha: rng.gen_range(-3.0..3.0),
            d: rng.gen_range(-500.0..500.0),
            a: rng.gen_range(-500.0..500.0),
            phi: rng.gen_range(-3.0..3.0),
            beta: if betas { rng.gen_range(-0.1..0.1) } else { 0.0 },
        })
        .collect();
    let limits = vec![
        JointLimit {
            min: -3.0,
            max: 3.0
        };
        n
    ];
    let base = [
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    ];
    let tool0 = [
        rng.gen_range(-100.0..100.0),
        rng.gen_range(-100.0..100.0),
        rng.gen_range(0.0..300.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    ];
    let mut r = Robot::new("random", conv, links, limits, base, tool0).unwrap();
    if betas {
        for i in 0..n {
            r.enable_beta(i).unwrap();
        }
    }
    for k in 0..6 {
        r.set(
            Param::tool(k),
            rng.gen_range(-2.0..2.0) * if k < 3 { 1.0 } else { 0.01 },
        );
    }
    r
}

fn random_q(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| rng.gen_range(-3.1..3.1)).collect()
}

#[test]
fn table1_zero_pose() {
    let r = preset("kuka-kr480-r3330").unwrap();
    let q = [0.0; 6];
    let f = r.flange_pose(&q).translation.vector;
    assert!(
        (f - Vector3::new(3615.0, 0.0, 990.0)).norm() < 1e-9,
        "flange {f}"
    );
    let t = r.tool_position(&q);
    let want = Vector3::new(3854.5558, -70.9065, 947.5837);
    assert!((t - want).norm() < 1e-4, "tool {t}");
    assert!((r.tool_pose(&q).translation.vector - t).norm() < 1e-12);
}

#[test]
fn kuka_has_36_parameters_with_paper_names() {
    let r = preset("kuka-kr480-r3330").unwrap();
    let names: Vec<String> = r.params().iter().map(|p| p.name()).collect();
    assert_eq!(names.len(), 36);
    assert_eq!(names[0], "alpha1");
    assert_eq!(names[6], "d1");
    assert_eq!(names[12], "a1");
    assert_eq!(names[18], "phi1");
    assert_eq!(names[24], "base_x");
    assert_eq!(names[35], "tool_c");
    let t3 = preset("kuka-kr480-r3330-table3").unwrap();
    assert!((t3.get_display(Param::d(0)) - 1044.237).abs() < 1e-12);
    assert!((t3.get_display(Param::base(3)) + 0.0497).abs() < 1e-12);
    assert!((t3.get_display(Param::tool(1)) + 0.4149).abs() < 1e-12);
}

#[test]
fn poe_equals_dh_product() {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let cases = [
        (Convention::Mdh, 6, false),
        (Convention::Dh, 6, false),
        (Convention::Mdh, 7, true),
        (Convention::Dh, 7, true),
    ];
    for (conv, n, betas) in cases {
        let r = random_robot(&mut rng, conv, n, betas);
        let poe = Poe::from_robot(&r);
        for _ in 0..250 {
            let q = random_q(&mut rng, n);
            let a = r.tool_pose(&q);
            let b = poe.tool_pose(&q);
            let dp = (a.translation.vector - b.translation.vector).norm();
            let dr = (a.rotation.matrix() - b.rotation.matrix()).norm();
            assert!(dp < 1e-9, "{conv:?} n={n}: position differs by {dp} mm");
            assert!(dr < 1e-12, "{conv:?} n={n}: rotation differs by {dr}");
        }
    }
    // And the paper's robot, 1000 poses.
    for name in ["kuka-kr480-r3330", "kuka-kr480-r3330-table3"] {
        let r = preset(name).unwrap();
        let poe = Poe::from_robot(&r);
        for _ in 0..1000 {
            let q = random_q(&mut rng, 6);
            let dp = (r.tool_position(&q) - poe.tool_pose(&q).translation.vector).norm();
            assert!(dp < 1e-9, "{name}: {dp}");
        }
    }
}

fn check_close(an: &Vector3<f64>, fd: &Vector3<f64>, scale: f64, what: &str) {
    let err = (an - fd).norm();
    assert!(
        err <= 1e-6 * fd.norm().max(scale),
        "{what}: analytic {an} vs finite difference {fd} (err {err})"
    );
}

#[test]
fn jacobians_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let mut robots = vec![
        preset("kuka-kr480-r3330").unwrap(),
        preset("kuka-kr480-r3330-table3").unwrap(),
    ];
    for (conv, n, betas) in [
        (Convention::Mdh, 6, true),
        (Convention::Dh, 6, true),
        (Convention::Mdh, 7, true),
        (Convention::Dh, 7, false),
        (Convention::Dh, 7, true),
    ] {
        robots.push(random_robot(&mut rng, conv, n, betas));
    }
    for r in robots {
        let n = r.dof();
        let params = r.params();
        let mut jq = vec![Vector3::zeros(); n];
        let mut jp = vec![Vector3::zeros(); params.len()];
        for _ in 0..20 {
            let q = random_q(&mut rng, n);
            let p = r.tool_position_jacobians(&q, Some(&mut jq), Some(&mut jp));
            assert!((p - r.tool_position(&q)).norm() < 1e-9);
            // Typical magnitude of a column: the reach (mm per rad).
            let scale = p.norm().max(1.0) * 1e-3;
            for i in 0..n {
                let h = 1e-6;
                let mut qp = q.clone();
                qp[i] += h;
                let mut qm = q.clone();
                qm[i] -= h;
                let fd = (r.tool_position(&qp) - r.tool_position(&qm)) / (2.0 * h);
                check_close(&jq[i], &fd, scale, &format!("{} dp/dq{}", r.name(), i + 1));
            }
            for (k, &prm) in params.iter().enumerate() {
                let h = if prm.unit() == crate::Unit::Mm {
                    1e-4
                } else {
                    1e-7
                };
                let v = r.get(prm);
                let mut rp = r.clone();
                rp.set(prm, v + h);
                let mut rm = r.clone();
                rm.set(prm, v - h);
                let fd = (rp.tool_position(&q) - rm.tool_position(&q)) / (2.0 * h);
                check_close(
                    &jp[k],
                    &fd,
                    scale,
                    &format!("{} {:?} dp/d{}", r.name(), r.convention(), prm),
                );
            }
        }
    }
}

#[test]
fn parameter_get_set_by_name() {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    let p = r.param_by_name("a2").unwrap();
    r.set_display(p, 501.0);
    assert_eq!(r.get_display(p), 501.0);
    let q = [0.0; 6];
    assert!((r.flange_pose(&q).translation.vector.x - 3616.0).abs() < 1e-9);
    assert!(r.param_by_name("beta2").is_err());
    r.enable_beta(1).unwrap();
    assert!(r.param_by_name("beta2").is_ok());
    assert_eq!(r.param_count(), 37);
    let e = r.param_by_name("d9").unwrap_err().to_string();
    assert!(e.contains("unknown parameter `d9`"), "{e}");
}

#[test]
fn parallel_axes_detection() {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    // Axes 2 and 3 are parallel (alpha3 = 0).
    assert_eq!(r.enable_beta_for_parallel_axes(), vec![2]);
}

/// A random robot whose joints in `prismatic` (0-based) are prismatic.
fn random_robot_with_prismatic(
    rng: &mut ChaCha8Rng,
    conv: Convention,
    n: usize,
    betas: bool,
    prismatic: &[usize],
) -> Robot {
    let mut r = random_robot(rng, conv, n, betas);
    let types = (0..n)
        .map(|i| {
            if prismatic.contains(&i) {
                JointType::Prismatic
            } else {
                JointType::Revolute
            }
        })
        .collect();
    r.set_joint_types(types).unwrap();
    r
}

/// Joint values within ±3.1 rad, or ±800 mm for a prismatic joint.
fn random_q_for(rng: &mut ChaCha8Rng, r: &Robot) -> Vec<f64> {
    r.joint_types()
        .iter()
        .map(|t| match t {
            JointType::Revolute => rng.gen_range(-3.1..3.1),
            JointType::Prismatic => rng.gen_range(-800.0..800.0),
        })
        .collect()
}

fn track_robot() -> Robot {
    crate::load_robot_file(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/kr480-track.toml"
    )))
    .unwrap()
}

#[test]
fn prismatic_joint_adds_to_d_and_leaves_phi_constant() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for conv in [Convention::Mdh, Convention::Dh] {
        let r = random_robot_with_prismatic(&mut rng, conv, 4, false, &[1]);
        let q = random_q_for(&mut rng, &r);
        // The same chain with the joint value moved into d2 and joint 2 held at 0.
        let mut moved = r.clone();
        moved.set(Param::d(1), r.get(Param::d(1)) + q[1]);
        let mut q0 = q.clone();
        q0[1] = 0.0;
        let d = (r.tool_position(&q) - moved.tool_position(&q0)).norm();
        assert!(d < 1e-9, "{conv:?}: {d}");
        // The joint value does not turn anything: phi2 stays what it is.
        let a = r.tool_pose(&q).rotation;
        let b = r.tool_pose(&q0).rotation;
        assert!((a.matrix() - b.matrix()).norm() < 1e-12, "{conv:?}");
    }
    // The track example: the arm is the KR 480 of Table I carried along x, 500 mm up.
    let track = track_robot();
    let kuka = preset("kuka-kr480-r3330").unwrap();
    for _ in 0..100 {
        let q = random_q(&mut rng, 6);
        let s = rng.gen_range(0.0..4000.0);
        let mut qt = vec![s];
        qt.extend_from_slice(&q);
        let want = kuka.tool_position(&q) + Vector3::new(s, 0.0, 500.0);
        assert!((track.tool_position(&qt) - want).norm() < 1e-9);
    }
}

#[test]
fn poe_equals_dh_product_with_prismatic_joints() {
    let mut rng = ChaCha8Rng::seed_from_u64(6);
    let mut robots = vec![track_robot()];
    for (conv, n, betas, prismatic) in [
        (Convention::Mdh, 6, false, vec![0]),
        (Convention::Dh, 6, false, vec![0]),
        (Convention::Mdh, 7, true, vec![0, 3]),
        (Convention::Dh, 7, true, vec![2, 6]),
        (Convention::Mdh, 3, false, vec![0, 1, 2]),
        (Convention::Dh, 3, false, vec![0, 1, 2]),
    ] {
        robots.push(random_robot_with_prismatic(
            &mut rng, conv, n, betas, &prismatic,
        ));
    }
    for r in robots {
        let poe = Poe::from_robot(&r);
        for (t, tw) in r.joint_types().iter().zip(&poe.twists) {
            assert_eq!(*t == JointType::Prismatic, tw.w == Vector3::zeros());
        }
        for _ in 0..250 {
            let q = random_q_for(&mut rng, &r);
            let a = r.tool_pose(&q);
            let b = poe.tool_pose(&q);
            let dp = (a.translation.vector - b.translation.vector).norm();
            let dr = (a.rotation.matrix() - b.rotation.matrix()).norm();
            let what = format!("{} {:?} {:?}", r.name(), r.convention(), r.joint_types());
            assert!(dp < 1e-9, "{what}: position differs by {dp} mm");
            assert!(dr < 1e-12, "{what}: rotation differs by {dr}");
        }
    }
}

#[test]
fn jacobians_match_finite_differences_with_prismatic_joints() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut robots = vec![track_robot()];
    for (conv, n, betas, prismatic) in [
        (Convention::Mdh, 7, true, vec![0]),
        (Convention::Dh, 7, true, vec![0]),
        (Convention::Mdh, 6, true, vec![1, 4]),
        (Convention::Dh, 6, true, vec![2, 5]),
        (Convention::Dh, 7, false, vec![3]),
    ] {
        robots.push(random_robot_with_prismatic(
            &mut rng, conv, n, betas, &prismatic,
        ));
    }
    for r in robots {
        let n = r.dof();
        let params = r.params();
        let mut jq = vec![Vector3::zeros(); n];
        let mut jp = vec![Vector3::zeros(); params.len()];
        for _ in 0..20 {
            let q = random_q_for(&mut rng, &r);
            let p = r.tool_position_jacobians(&q, Some(&mut jq), Some(&mut jp));
            assert!((p - r.tool_position(&q)).norm() < 1e-9);
            let scale = p.norm().max(1.0) * 1e-3;
            let what = |s: String| format!("{} {:?}: {s}", r.name(), r.convention());
            for i in 0..n {
                let h = match r.joint_type(i) {
                    JointType::Revolute => 1e-6,
                    JointType::Prismatic => 1e-4,
                };
                let mut qp = q.clone();
                qp[i] += h;
                let mut qm = q.clone();
                qm[i] -= h;
                let fd = (r.tool_position(&qp) - r.tool_position(&qm)) / (2.0 * h);
                check_close(&jq[i], &fd, scale, &what(format!("dp/dq{}", i + 1)));
                if r.joint_type(i) == JointType::Prismatic {
                    // A prismatic column is the unit axis: the d column of the same row.
                    assert!((jq[i].norm() - 1.0).abs() < 1e-12);
                    let k = params.iter().position(|x| *x == Param::d(i)).unwrap();
                    assert!((jq[i] - jp[k]).norm() < 1e-12);
                }
            }
            for (k, &prm) in params.iter().enumerate() {
                let h = if prm.unit() == crate::Unit::Mm {
                    1e-4
                } else {
                    1e-7
                };
                let v = r.get(prm);
                let mut rp = r.clone();
                rp.set(prm, v + h);
                let mut rm = r.clone();
                rm.set(prm, v - h);
                let fd = (rp.tool_position(&q) - rm.tool_position(&q)) / (2.0 * h);
                check_close(&jp[k], &fd, scale, &what(format!("dp/d{prm}")));
            }
        }
    }
}

/// A forward pass written over an earlier one (the reused buffers of the Jacobian passes) equals
/// a fresh one, for the families that deflect the joints and under known and unknown conditions.
#[test]
fn a_pass_written_in_place_equals_a_fresh_one() {
    use crate::model::family::{backlash, compliance, thermal, transmission, PoseFrames};
    use crate::model::Conditions;
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut r = preset("kuka-kr480-r3330").unwrap();
    let t0 = *r.tool0();
    r.set_target_tools(&[t0, [50.0, 0.0, 20.0, 0.0, 0.0, 0.0]])
        .unwrap();
    compliance::enable(&mut r, &[1, 2], Some(300.0)).unwrap();
    transmission::enable(&mut r, &[0, 1, 2, 3, 4, 5], 2).unwrap();
    backlash::enable(&mut r, &[0, 1, 2]).unwrap();
    thermal::enable(&mut r, 20.0).unwrap();
    // Every family parameter away from zero, so each deflects the pass.
    for p in r.param_list().to_vec() {
        if p.family_id() != crate::model::family::link::ID && r.get(p) == 0.0 {
            r.set(p, rng.gen_range(1e-4..1e-3));
        }
    }
    let known = Conditions {
        temperature_c: 27.5,
        dir: [1, -1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
    };
    for (c0, c1) in [
        (Conditions::UNKNOWN, Conditions::UNKNOWN),
        (known, Conditions::UNKNOWN),
        (Conditions::UNKNOWN, known),
    ] {
        let (q0, q1) = (random_q(&mut rng, 6), random_q(&mut rng, 6));
        let fresh = r.pose_frames_in(&q1, 1, &c1);
        let mut reused: PoseFrames = r.pose_frames_in(&q0, 0, &c0);
        r.pose_frames_in_into(&q1, 1, &c1, &mut reused);
        assert_eq!(reused.flange, fresh.flange);
        assert_eq!(reused.point, fresh.point);
        assert_eq!(reused.target, fresh.target);
        assert_eq!(reused.axis[..6], fresh.axis[..6]);
        assert_eq!(reused.link[..6], fresh.link[..6]);
        assert_eq!(reused.rigid.commanded, fresh.rigid.commanded);
        assert_eq!(reused.rigid.axes, fresh.rigid.axes);
        assert_eq!(reused.rigid.point, fresh.rigid.point);
        assert!(reused.rigid.conditions.same(&fresh.rigid.conditions));
        // The deflection moved the pass away from the rigid one.
        assert_ne!(fresh.point, r.geometric().target_position(&q1, 1));
    }
}

/// The base's and each target's Euler axes the robot keeps with their frames follow every change
/// of the angles: by parameter, by a new set of target tools, and for a further target.
#[test]
fn the_kept_euler_axes_follow_the_angles() {
    use crate::frame::euler_axes;
    let mut r = preset("kuka-kr480-r3330").unwrap();
    let t0 = *r.tool0();
    r.set_target_tools(&[t0, [50.0, 0.0, 20.0, 0.3, -0.2, 0.1]])
        .unwrap();
    let check = |r: &Robot| {
        let b = r.base();
        assert_eq!(*r.base_euler_axes(), euler_axes(b[3], b[4]));
        for t in 0..r.target_count() {
            let (n, c) = (r.target_tool0(t), r.target_tool_correction(t));
            assert_eq!(
                *r.target_euler_axes(t),
                euler_axes(n[3] + c[3], n[4] + c[4]),
                "target {t}"
            );
        }
    };
    check(&r);
    r.set(Param::base(3), 0.4);
    r.set(Param::base(4), -0.3);
    r.set(Param::tool(4), 0.05);
    for name in ["tool2_a", "tool2_b"] {
        let p = r.param_by_name(name).unwrap();
        r.set(p, 0.02);
    }
    check(&r);
    r.set_target_tools(&[
        [1.0, 2.0, 300.0, 0.2, 0.1, 0.0],
        [0.0, 50.0, 20.0, -0.1, 0.4, 0.0],
    ])
    .unwrap();
    check(&r);
    assert_ne!(r.target_euler_axes(0), r.target_euler_axes(1));
}

/// The per-thread buffer of the Jacobian passes serves robots of any size: a rigid 6-joint
/// robot's columns after a deflecting 7-joint robot's pass (which leaves a seventh frame and a
/// `rigid` the smaller robot does not write) equal those from a fresh pass, to the bit.
#[test]
fn the_shared_pass_buffer_serves_robots_of_any_size() {
    use crate::model::family::compliance;
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let mut big = random_robot(&mut rng, Convention::Mdh, 7, true);
    compliance::enable(&mut big, &[1, 2, 4], Some(10.0)).unwrap();
    for p in big.param_list().to_vec() {
        if p.family_id() == compliance::ID {
            big.set(p, rng.gen_range(1e-4..1e-3));
        }
    }
    assert!(big.deflects_joints());
    let small = preset("kuka-kr480-r3330").unwrap();
    assert!(!small.deflects_joints());
    let (q7, q6) = (random_q(&mut rng, 7), random_q(&mut rng, 6));
    let n = small.param_count();
    let fresh = small.pose_frames_target(&q6, 0);
    let (mut jp_fresh, mut jw_fresh) = (vec![Vector3::zeros(); n], vec![Vector3::zeros(); n]);
    let p_fresh = small.screws_at(&fresh, None, Some(&mut jp_fresh), Some(&mut jw_fresh));
    let mut jp_big = vec![Vector3::zeros(); big.param_count()];
    big.target_screws(&q7, 0, None, Some(&mut jp_big), None);
    let (mut jp, mut jw) = (vec![Vector3::zeros(); n], vec![Vector3::zeros(); n]);
    let p = small.target_screws(&q6, 0, None, Some(&mut jp), Some(&mut jw));
    assert_eq!(p, p_fresh);
    assert_eq!(jp, jp_fresh);
    assert_eq!(jw, jw_fresh);
}
