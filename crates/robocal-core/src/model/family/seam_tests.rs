//! The family seam, proven by a family written only against [`ParameterFamily`] and registered
//! for tests: constant joint offsets `qoffset{j}` that act through the joints (a deflection
//! `dq_i = theta_i`). Nothing else in the library knows it, yet forward kinematics, the Jacobians,
//! the identifiability analysis, the solver, the covariance and the result take it; and every
//! family's screw columns (linear and angular) match central differences.

use super::{priority, put, FamilyId, ParameterFamily, PoseFrames};
use crate::frame::Frame;
use crate::identification::{calibrate, CalibrationData, CalibrationSettings, Observations};
use crate::model::presets::preset;
use crate::model::{JointType, Param, Robot, Unit};
use crate::simulation::{random_poses, PoseSampler};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const KEY: &str = "qoffset";
const ID: FamilyId = FamilyId::new(9);

/// Constant offsets added to the joint values (a test family).
pub struct JointOffsets;

impl ParameterFamily for JointOffsets {
    fn key(&self) -> &'static str {
        KEY
    }

    fn templates(&self) -> &'static [&'static str] {
        &["qoffset{j}"]
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::Deg
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        if robot.family_values(KEY).map(<[f64]>::len) == Some(robot.dof()) {
            out.extend((0..robot.dof()).map(|i| Param::new(ID, 0, i as u16)));
        }
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot.family_values(KEY).map_or(0.0, |v| v[p.index()])
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        if let Some(v) = robot.family_values_mut(KEY) {
            v[p.index()] = value;
        }
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        priority::NON_GEOMETRIC + p.index() as u32
    }

    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        for i in 0..robot.dof() {
            let (v, w) = pose.joint_screw(robot, i);
            dp[i] = v;
            put(&mut dw, i, w);
        }
    }

    fn deflects_joints(&self, robot: &Robot) -> bool {
        robot.family_values(KEY).is_some()
    }

    fn add_joint_deflection(&self, robot: &Robot, _rigid: &super::RigidPose, dq: &mut [f64]) {
        if let Some(v) = robot.family_values(KEY) {
            for (d, o) in dq.iter_mut().zip(v) {
                *d += o;
            }
        }
    }
}

fn offsets(robot: &Robot, deg: &[f64]) -> Robot {
    let mut r = robot.clone();
    let v = deg.iter().map(|d| d.to_radians()).collect();
    r.set_family_values(KEY, Some(v)).unwrap();
    r
}

fn poses(r: &Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    random_poses(r, n, &PoseSampler::default(), &mut rng).unwrap()
}

#[test]
fn the_registry_positions_are_the_families_ids() {
    for (k, fam) in super::all().iter().enumerate() {
        let mut ps = Vec::new();
        let mut r = offsets(&preset("kuka-kr480-r3330").unwrap(), &[0.0; 6]);
        r.enable_beta(2).unwrap();
        let t0 = *r.tool0();
        r.set_target_tools(&[t0, [50.0, 0.0, 20.0, 0.0, 0.0, 0.0]])
            .unwrap();
        super::compliance::enable(&mut r, &[1, 2], Some(10.0)).unwrap();
        super::transmission::enable(&mut r, &[0, 1, 2, 3, 4, 5], 2).unwrap();
        super::backlash::enable(&mut r, &[0, 1, 2]).unwrap();
        super::thermal::enable(&mut r, 20.0).unwrap();
        fam.params(&r, &mut ps);
        assert!(!ps.is_empty(), "{}", fam.key());
        for p in ps {
            assert_eq!(p.family_id().index(), k, "{p} of {}", fam.key());
            assert_eq!(Param::parse(&p.name()), Some(p));
        }
    }
    assert_eq!(
        super::by_key("link").map(|(id, _)| id),
        Some(super::link::ID)
    );
}

#[test]
fn a_new_family_joins_the_parameter_list_by_name_and_unit() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    assert_eq!(nominal.param_count(), 36);
    let r = offsets(&nominal, &[0.0; 6]);
    assert_eq!(r.param_count(), 42);
    let p = r.param_by_name("qoffset3").unwrap();
    assert_eq!(r.param_position(p), Some(38));
    assert_eq!(p.unit(), Unit::Deg);
    assert!(nominal.param_by_name("qoffset3").is_err());
}

#[test]
fn joint_offsets_move_the_chain_like_phi() {
    let nominal = preset("kuka-kr480-r3330").unwrap();
    let deg = [0.3, -0.2, 0.15, 0.5, -0.4, 0.25];
    let with_offsets = offsets(&nominal, &deg);
    let mut with_phi = nominal.clone();
    for (i, d) in deg.iter().enumerate() {
        let p = Param::phi(i);
        with_phi.set(p, with_phi.get(p) + d.to_radians());
    }
    for q in poses(&nominal, 50, 1) {
        let a = with_offsets.tool_pose(&q);
        let b = with_phi.tool_pose(&q);
        assert!((a.translation.vector - b.translation.vector).norm() < 1e-9);
        assert!((a.rotation.matrix() - b.rotation.matrix()).amax() < 1e-12);
    }
}

/// The small rotation from `b` to `a` (`R_a R_b^T`) as a rotation vector, from the
/// skew-symmetric part (accurate for tiny angles, unlike the angle's arc cosine).
fn rotvec(a: &Frame, b: &Frame) -> Vector3<f64> {
    let m = a.rotation.matrix() * b.rotation.matrix().transpose();
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) * 0.5
}

/// Every column of every family, linear and angular, against central differences of the tool
/// frame: on the 6R arm with Hayati tilts and joint offsets, in MDH, and on the 7-joint track
/// robot with a prismatic axis.
#[test]
fn every_screw_column_matches_central_differences() {
    let mut kuka = offsets(&preset("kuka-kr480-r3330-table3").unwrap(), &[0.1; 6]);
    kuka.enable_beta(2).unwrap();
    kuka.set_family_values(KEY, Some(vec![0.002; 6])).unwrap();
    let track_file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/kr480-track.toml"
    );
    let track = crate::load_robot_file(std::path::Path::new(track_file)).unwrap();
    assert_eq!(track.joint_type(0), JointType::Prismatic);
    let track = offsets(&track, &[0.1; 7]);
    for robot in [kuka, track] {
        let n = robot.param_count();
        for q in poses(&robot, 8, 7) {
            let mut jp = vec![Vector3::zeros(); n];
            let mut jw = vec![Vector3::zeros(); n];
            robot.tool_screw_jacobians(&q, None, Some(&mut jp), Some(&mut jw));
            for (k, p) in robot.params().into_iter().enumerate() {
                // A joint offset of the prismatic axis is a length (the test family names every
                // offset in degrees).
                let length = p.unit() == Unit::Mm
                    || (p.family().key() == KEY
                        && robot.joint_type(p.index()) == JointType::Prismatic);
                let h = if length { 1e-5 } else { 1e-7 };
                let mut plus = robot.clone();
                plus.set(p, robot.get(p) + h);
                let mut minus = robot.clone();
                minus.set(p, robot.get(p) - h);
                let (fp, fm) = (plus.tool_pose(&q), minus.tool_pose(&q));
                let dp = (fp.translation.vector - fm.translation.vector) / (2.0 * h);
                let dw = rotvec(&fp, &fm) / (2.0 * h);
                assert!(
                    (dp - jp[k]).norm() <= 1e-6 * (1.0 + dp.norm()),
                    "{} {p}: dp {dp:?} vs {:?}",
                    robot.name(),
                    jp[k]
                );
                assert!(
                    (dw - jw[k]).norm() <= 1e-7,
                    "{} {p}: dw {dw:?} vs {:?}",
                    robot.name(),
                    jw[k]
                );
            }
        }
    }
}

/// Noise-free data of a robot whose joints carry offsets: with phi held fixed, the calibration
/// (identifiability, solver, covariance, result) takes the new family's parameters, fixes those
/// that duplicate others (joint 1's offset turns like `base_c`, joint 6's moves the tool point
/// like `tool_x/y`: the paper's reasons for fixing phi1 and phi6) and recovers the rest exactly.
#[test]
fn calibration_identifies_a_family_it_does_not_know() {
    let nominal = offsets(&preset("kuka-kr480-r3330").unwrap(), &[0.0; 6]);
    let deg = [0.05, -0.04, 0.03, 0.06, -0.05, 0.02];
    let truth = offsets(&nominal, &deg);
    let mut obs = Observations::new(6);
    for (i, q) in poses(&truth, 80, 11).iter().enumerate() {
        obs.push(q, truth.tool_position(q), i + 2).unwrap();
    }
    let mut settings = CalibrationSettings::default();
    settings.identifiability.fix = (0..6).map(Param::phi).collect();
    let data = CalibrationData {
        calibration: &obs,
        plane: None,
        validation: None,
    };
    let cal = calibrate(&nominal, data, &settings, &()).unwrap();
    let qoffset = |i: usize| nominal.param_by_name(&format!("qoffset{i}")).unwrap();
    for i in [1, 6] {
        let why = cal.identifiability.fixed_reason(qoffset(i)).expect("fixed");
        assert!(
            why.describe().starts_with("same effect as"),
            "{}",
            why.describe()
        );
    }
    for i in 2..=5 {
        let p = qoffset(i);
        assert!(
            cal.identifiability.identified.contains(&p),
            "{p} identified"
        );
        let got = cal.calibrated.get_display(p);
        assert!(
            (got - deg[i - 1]).abs() < 1e-6,
            "{p}: {got} vs {}",
            deg[i - 1]
        );
        assert!(
            cal.covariance.std_of(p).is_some(),
            "{p} has a standard deviation"
        );
    }
    let worst = cal.calibration.after.iter().cloned().fold(0.0, f64::max);
    assert!(worst < 1e-6, "largest error after {worst} mm");
    let result = cal.to_result();
    let entry = &result.parameters["qoffset4"];
    assert!(!entry.fixed && (entry.calibrated - deg[3]).abs() < 1e-6);
    assert_eq!(entry.unit, Unit::Deg);
}
