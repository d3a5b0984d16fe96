//! Round trips of robot descriptions (every preset and example robot) and the comparison of two
//! nominal robots.

use super::*;
use crate::model::presets;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn examples() -> Vec<Robot> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut out: Vec<Robot> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| crate::load_robot_file(&p).unwrap())
        .collect();
    out.sort_by(|a, b| a.name().cmp(b.name()));
    out
}

/// Every preset and example robot, and two with Hayati tilts (one of them non-zero).
fn all_robots() -> Vec<Robot> {
    let mut v: Vec<Robot> = presets::PRESETS
        .iter()
        .map(|n| presets::preset(n).unwrap())
        .collect();
    v.extend(examples());
    let mut tilted = presets::preset("kuka-kr480-r3330").unwrap();
    assert!(!tilted.enable_beta_for_parallel_axes().is_empty());
    v.push(tilted.clone());
    tilted.set_display(Param::beta(2), 0.0123);
    tilted.set_name("tilted");
    v.push(tilted);
    v
}

fn random_q(r: &Robot, rng: &mut ChaCha8Rng) -> Vec<f64> {
    r.limits()
        .iter()
        .map(|l| rng.gen_range(l.min..=l.max))
        .collect()
}

fn assert_same(a: &Robot, b: &Robot) {
    assert_eq!(a, b, "{}", a.name());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..50 {
        let q = random_q(a, &mut rng);
        assert_eq!(a.tool_pose(&q), b.tool_pose(&q), "{} at {q:?}", a.name());
    }
}

#[test]
fn every_robot_round_trips_exactly_through_json_and_toml() {
    let robots = all_robots();
    let names: Vec<&str> = robots.iter().map(|r| r.name()).collect();
    for want in [
        "kr480-track",
        "fanuc-like",
        "ur5",
        "barrett-wam",
        "kuka-kr480-r3330-table3",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    let path = Path::new("r.json");
    for r in &robots {
        let d = RobotDescription::of(r);
        assert_same(r, &d.to_robot(path).unwrap());
        let json = serde_json::to_string_pretty(&d).unwrap();
        let back: RobotDescription = serde_json::from_str(&json).unwrap();
        assert_eq!(back, d);
        assert_same(r, &back.to_robot(path).unwrap());
        // The TOML form is a robot file.
        let file = crate::model::robot_file::parse_robot_toml(&d.to_toml().unwrap(), path);
        assert_same(r, &file.unwrap());
    }
}

/// `to_robot` hands the description to the robot file's checks without writing and parsing its
/// TOML text: the robot, and the refusal of a bad description, are those of the text.
#[test]
fn to_robot_is_the_robot_of_its_toml_text() {
    let path = Path::new("r.json");
    let via_text = |d: &RobotDescription| {
        crate::model::robot_file::parse_robot_toml(&d.to_toml().unwrap(), path)
            .map_err(|e| e.without_line().to_string())
    };
    let direct = |d: &RobotDescription| d.to_robot(path).map_err(|e| e.to_string());
    for r in &all_robots() {
        let d = RobotDescription::of(r);
        assert_same(&direct(&d).unwrap(), &via_text(&d).unwrap());
    }
    let kr = RobotDescription::of(&presets::preset("kuka-kr480-r3330").unwrap());
    let fanuc = RobotDescription::of(
        &examples()
            .into_iter()
            .find(|r| r.name() == "fanuc-like")
            .unwrap(),
    );
    let track = RobotDescription::of(
        &examples()
            .into_iter()
            .find(|r| r.name() == "kr480-track")
            .unwrap(),
    );
    type Spoil = fn(&mut RobotDescription);
    let bad: Vec<(RobotDescription, Spoil)> = vec![
        (kr.clone(), |d| d.joints[1].alpha = 1e300),
        (kr.clone(), |d| d.joints[2].d = f64::NAN),
        (kr.clone(), |d| d.joints[0].limits = [10.0, -10.0]),
        (kr.clone(), |d| d.base[4] = f64::INFINITY),
        (kr.clone(), |d| {
            d.tool_correction = Some([0.0, 0.0, 0.0, 0.0, 1e9, 0.0])
        }),
        (kr.clone(), |d| d.gravity = Some([0.0, 0.0, 0.0])),
        (kr.clone(), |d| d.tools = Some(vec![[1.0; 6], [2.0; 6]])),
        (kr.clone(), |d| d.tools = Some(Vec::new())),
        (kr.clone(), |d| d.joints.clear()),
        (kr.clone(), |d| d.joints[3].beta = Some(-1e200)),
        (fanuc.clone(), |d| {
            d.controller.as_mut().unwrap().sign[0] = 0.5
        }),
        (fanuc.clone(), |d| {
            d.controller.as_mut().unwrap().offset.pop();
        }),
        (fanuc.clone(), |d| {
            d.controller.as_mut().unwrap().coupling = vec![(2, 2, 1.0)]
        }),
        (fanuc.clone(), |d| {
            d.controller.as_mut().unwrap().coupling = vec![(9, 1, 1.0)]
        }),
        (track.clone(), |d| d.joints[0].limits = [0.0, -1.0]),
    ];
    for (mut d, spoil) in bad {
        spoil(&mut d);
        let e = direct(&d).unwrap_err();
        assert_eq!(e, via_text(&d).unwrap_err());
    }
}

#[test]
fn the_description_carries_what_the_robot_file_says() {
    let track = examples()
        .into_iter()
        .find(|r| r.name() == "kr480-track")
        .unwrap();
    let d = RobotDescription::of(&track);
    assert_eq!(d.joints.len(), 7);
    assert_eq!(d.joints[0].kind, JointType::Prismatic);
    assert_eq!(d.joints[0].limits, [0.0, 4000.0]);
    assert_eq!(d.joints[1].phi, -90.0);
    assert_eq!(d.base, [0.0, 0.0, 500.0, 90.0, 0.0, 0.0]);
    assert_eq!(d.tool, [42.4163, -70.9065, 239.5558, -0.038, 0.237, 0.054]);
    assert_eq!(d.tool_correction, None);
    let fanuc = examples()
        .into_iter()
        .find(|r| r.name() == "fanuc-like")
        .unwrap();
    let c = RobotDescription::of(&fanuc).controller.unwrap();
    assert_eq!(c.sign, [1.0, 1.0, -1.0, 1.0, 1.0, 1.0]);
    assert_eq!(c.coupling, [(3, 2, -1.0)]);
    let t3 = RobotDescription::of(&presets::preset("kuka-kr480-r3330-table3").unwrap());
    assert_eq!(t3.tool_correction.unwrap()[1], -0.4149);
    let ur5 = examples().into_iter().find(|r| r.name() == "ur5").unwrap();
    assert!(RobotDescription::of(&ur5).controller.is_none());
}

#[test]
fn bad_descriptions_are_refused_naming_the_field() {
    let mut d = RobotDescription::of(&presets::preset("kuka-kr480-r3330").unwrap());
    d.joints[1].alpha = 1e300;
    let e = d.to_robot(Path::new("r.json")).unwrap_err().to_string();
    assert!(
        e.starts_with("r.json: field `joints[2].alpha`: 1e300 deg is out of range"),
        "{e}"
    );
    let mut d = RobotDescription::of(&presets::preset("kuka-kr480-r3330").unwrap());
    d.controller.as_mut().unwrap().sign[0] = 0.5;
    let e = d.to_robot(Path::new("r.json")).unwrap_err().to_string();
    assert!(e.contains("controller.sign[1]"), "{e}");
}

#[test]
fn nominal_difference_names_the_first_difference() {
    let kr = presets::preset("kuka-kr480-r3330").unwrap();
    let file = examples()
        .into_iter()
        .find(|r| r.name() == "kr480-r3330-file")
        .unwrap();
    // The preset and its robot file are the same robot under two names.
    assert_eq!(nominal_difference(&kr, &file), None);
    let mut other = kr.clone();
    other.set_display(Param::d(3), 1525.5);
    let d = nominal_difference(&kr, &other).unwrap();
    assert_eq!(d, "nominal d4 = 1525 mm against 1525.5 mm");
    other = kr.clone();
    other.set_display(Param::d(3), 1525.0 + 1e-8);
    assert!(nominal_difference(&kr, &other).is_some());
    other.set_display(Param::d(3), 1525.0 + 1e-10);
    assert_eq!(nominal_difference(&kr, &other), None);
    // Tilts that are zero are the same model with or without the parameter.
    other = kr.clone();
    other.enable_beta_for_parallel_axes();
    assert_eq!(nominal_difference(&kr, &other), None);
    other.set_display(Param::beta(2), 0.01);
    assert!(nominal_difference(&kr, &other).unwrap().contains("beta3"));
    let t3 = presets::preset("kuka-kr480-r3330-table3").unwrap();
    assert!(nominal_difference(&kr, &t3).is_some());
    // Controller maps.
    let mut plain = kr.clone();
    plain.set_controller(None).unwrap();
    let d = nominal_difference(&kr, &plain).unwrap();
    assert_eq!(d, "controller sign of joint 1 is -1 against 1");
    let fanuc = examples()
        .into_iter()
        .find(|r| r.name() == "fanuc-like")
        .unwrap();
    let mut uncoupled = fanuc.clone();
    let c = fanuc.controller().unwrap();
    uncoupled
        .set_controller(Some(
            crate::model::Controller::new(c.sign().to_vec(), c.offset().to_vec(), vec![]).unwrap(),
        ))
        .unwrap();
    let d = nominal_difference(&fanuc, &uncoupled).unwrap();
    assert_eq!(
        d,
        "controller coupling of joint 3 with axis 2 is -1 against 0"
    );
    // Shape.
    let track = examples()
        .into_iter()
        .find(|r| r.name() == "kr480-track")
        .unwrap();
    assert_eq!(
        nominal_difference(&kr, &track).unwrap(),
        "6 joints against 7"
    );
    let mut prismatic = kr.clone();
    let mut types = vec![JointType::Revolute; 6];
    types[0] = JointType::Prismatic;
    prismatic.set_joint_types(types).unwrap();
    assert_eq!(
        nominal_difference(&kr, &prismatic).unwrap(),
        "joint 1 is revolute against prismatic"
    );
}
