//! Tests of the joint compliance family: its columns against central differences, and its
//! agreement with the simulator's gravity physics.

use super::*;
use crate::model::presets::preset;
use crate::simulation::{random_poses, GravityModel, PoseSampler};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn poses(r: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    random_poses(r, n, &PoseSampler::default(), &mut rng).unwrap()
}

fn gravity() -> GravityModel {
    GravityModel::new(
        vec![1e-8, 3e-8, 2e-8, 5e-8, 5e-8, 5e-8],
        vec![900.0, 500.0, 400.0, 150.0, 60.0, 20.0],
        300.0,
    )
}

/// The family with the simulator's masses and compliances deflects the joints exactly as the
/// simulator does, lumped or with the payload known, for a floor and a wall mounted robot.
#[test]
fn the_family_agrees_with_the_simulated_gravity_physics() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    for gvec in [[0.0, 0.0, -9.80665], [0.0, -9.81, 0.0]] {
        let mut g = gravity();
        g.gravity_m_s2 = gvec;
        for physical in [false, true] {
            let r = g.equivalent(&nominal, physical).unwrap();
            for q in poses(&nominal, 40, 3) {
                let want = g.deflection(&nominal, &q);
                let mut dq = vec![0.0; 6];
                Compliance.add_joint_deflection(&r, &r.rigid_pose(&q), &mut dq);
                for i in 0..6 {
                    let tol = 1e-12 + 1e-9 * want[i].abs();
                    assert!(
                        (dq[i] - want[i]).abs() < tol,
                        "{i}: {} vs {}",
                        dq[i],
                        want[i]
                    );
                }
                let a = r.tool_position(&q);
                let b = nominal.tool_position(&g.deflected(&nominal, &q));
                assert!((a - b).norm() < 1e-9, "{:?}", a - b);
            }
        }
    }
}

/// The physical compliance predicts another payload: the model built at 300 kg and moved to
/// 100 kg matches the simulator at 100 kg up to the last link's half mass lumped with the payload.
#[test]
fn a_physical_compliance_predicts_another_payload() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let g = gravity();
    let mut r = g.equivalent(&nominal, true).unwrap();
    assert_eq!(payload_kg(&r), Some(300.0));
    set_payload_kg(&mut r, 100.0).unwrap();
    let mut g100 = g.clone();
    g100.payload_kg = 100.0;
    // The part folded in: c m_n/2 (100/300 - 1) of the tool lever, at most 10 kg's share.
    let mut worst: f64 = 0.0;
    let mut sag: f64 = 0.0;
    for q in poses(&nominal, 40, 4) {
        let a = r.tool_position(&q);
        let b = nominal.tool_position(&g100.deflected(&nominal, &q));
        worst = worst.max((a - b).norm());
        sag = sag.max((b - nominal.tool_position(&q)).norm());
    }
    assert!(worst < 0.05 * sag, "worst {worst} mm of a {sag} mm sag");
    // Lumped coefficients cannot move to another payload.
    let mut lumped = g.equivalent(&nominal, false).unwrap();
    assert!(set_payload_kg(&mut lumped, 100.0).is_err());
    assert!(enable(&mut lumped, &[1], Some(0.0)).is_err());
}

/// Every column of the compliance and transmission families, linear and angular, against
/// central differences of the tool frame, with both families active and the coefficients away
/// from zero.
#[test]
fn compliance_and_transmission_columns_match_central_differences() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    for physical in [false, true] {
        let mut r = gravity().equivalent(&nominal, physical).unwrap();
        super::super::transmission::enable(&mut r, &[0, 1, 2, 3, 4, 5], 2).unwrap();
        for (k, p) in r.params().into_iter().enumerate() {
            if p.family().key() == super::super::transmission::KEY {
                r.set(p, 1e-4 * (k as f64 % 7.0 - 3.0));
            }
        }
        let n = r.param_count();
        for q in poses(&r, 6, 9) {
            let mut jp = vec![Vector3::zeros(); n];
            let mut jw = vec![Vector3::zeros(); n];
            r.tool_screw_jacobians(&q, None, Some(&mut jp), Some(&mut jw));
            for (k, p) in r.params().into_iter().enumerate() {
                let key = p.family().key();
                if key != KEY && key != super::super::transmission::KEY {
                    continue;
                }
                // A step that moves the tool by about 1e-4 mm (the units differ by 10 decades).
                let h = 1e-4 / jp[k].norm().max(1e-9);
                let mut plus = r.clone();
                plus.set(p, r.get(p) + h);
                let mut minus = r.clone();
                minus.set(p, r.get(p) - h);
                let (fp, fm) = (plus.tool_pose(&q), minus.tool_pose(&q));
                let dp = (fp.translation.vector - fm.translation.vector) / (2.0 * h);
                let m = fp.rotation.matrix() * fm.rotation.matrix().transpose();
                let dw = Vector3::new(
                    m[(2, 1)] - m[(1, 2)],
                    m[(0, 2)] - m[(2, 0)],
                    m[(1, 0)] - m[(0, 1)],
                ) * (0.5 / (2.0 * h));
                assert!(
                    (dp - jp[k]).norm() <= 1e-5 * (1.0 + dp.norm()),
                    "{p}: dp {dp:?} vs {:?}",
                    jp[k]
                );
                assert!(
                    (dw - jw[k]).norm() <= 1e-5 * (1e-3 + dw.norm()),
                    "{p}: dw {dw:?} vs {:?}",
                    jw[k]
                );
            }
        }
    }
}

/// A floor robot's first axis is always vertical: `auto` leaves it out; on a wall every axis
/// may carry a torque. Names round-trip and have their units.
#[test]
fn auto_joints_names_and_units() {
    let mut r = preset("kuka-kr480-r3330").unwrap();
    assert_eq!(auto_joints(&r), vec![1, 2, 3, 4, 5]);
    r.set_gravity([0.0, 1.0, 0.0]).unwrap();
    assert_eq!(auto_joints(&r), vec![0, 1, 2, 3, 4, 5]);
    let mut r = preset("kuka-kr480-r3330").unwrap();
    enable(&mut r, &[1, 2], Some(300.0)).unwrap();
    let names: Vec<String> = r.params()[36..].iter().map(|p| p.name()).collect();
    assert_eq!(
        names,
        [
            "grav2_o3",
            "grav2_o4",
            "grav3_o4",
            "grav2_o5",
            "grav3_o5",
            "grav2_o6",
            "grav3_o6",
            "compliance2",
            "compliance3"
        ]
    );
    for p in &r.params()[36..] {
        assert_eq!(Param::parse(&p.name()), Some(*p));
    }
    assert_eq!(
        r.param_by_name("grav2_o3").unwrap().unit(),
        Unit::MicroradPerM
    );
    assert_eq!(
        r.param_by_name("compliance3").unwrap().unit(),
        Unit::MicroradPerNm
    );
    assert!(enable(&mut r, &[7], None).is_err());
    // A result's parameter enables its joint, in its mode.
    let mut fresh = preset("kuka-kr480-r3330").unwrap();
    fresh
        .enable_param(Param::parse("compliance3").unwrap())
        .unwrap();
    assert_eq!(joints(&fresh), vec![2]);
    assert!(payload_kg(&fresh).is_some());
}

/// The robot file's `gravity`: read, normalized, written back into the description (and so
/// into a result's embedded robot), compared by `nominal_difference`; a bad one names the key.
#[test]
fn the_robot_files_gravity_direction() {
    use crate::model::description::{nominal_difference, RobotDescription};
    use crate::model::robot_file::parse_robot_toml;
    let path = std::path::Path::new("wall.toml");
    let text = |g: &str| {
        format!(
            "convention = \"mdh\"\n{g}\n[[joints]]\nalpha = 0\nd = 0\na = 0\n\
             [[joints]]\nalpha = 90\nd = 0\na = 500\n"
        )
    };
    let floor = parse_robot_toml(&text(""), path).unwrap();
    assert_eq!(floor.gravity(), Vector3::new(0.0, 0.0, -1.0));
    let wall = parse_robot_toml(&text("gravity = [0, -9.81, 0]"), path).unwrap();
    assert!((wall.gravity() - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-15);
    assert_eq!(auto_joints(&wall), vec![0, 1]);
    let back = RobotDescription::of(&wall).to_robot(path).unwrap();
    assert_eq!(back.gravity(), wall.gravity());
    assert!(nominal_difference(&floor, &wall)
        .unwrap()
        .starts_with("gravity"));
    for bad in ["gravity = [0, 0]", "gravity = [0, 0, 0]"] {
        let e = parse_robot_toml(&text(bad), path).unwrap_err().to_string();
        assert!(e.contains("wall.toml:2: field `gravity`"), "{bad}: {e}");
    }
}
