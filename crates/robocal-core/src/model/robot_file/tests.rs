//! Tests of the robot-file parser: good files, every rejection with file, line and field, joint
//! types and the `[controller]` section.

use super::*;
use crate::io::robot::load_robot;
use crate::model::JointType;

const GOOD: &str = r#"
name = "two"
convention = "dh"
tool = [0, 0, 10, 0, 0, 0]
[[joints]]
alpha = 90
d = 100
a = 0
[[joints]]
alpha = 0
d = 0
a = 300
limits = [-90, 90]
beta = 0
"#;

fn parse(s: &str) -> Result<Robot> {
    parse_robot_toml(s, Path::new("robot.toml"))
}

#[test]
fn parses_good_file() {
    let r = parse(GOOD).unwrap();
    assert_eq!(r.dof(), 2);
    assert_eq!(r.name(), "two");
    assert!(r.beta_enabled(1));
    assert!(!r.beta_enabled(0));
    assert!((r.limits()[1].max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert_eq!(r.param_count(), 4 * 2 + 1 + 12);
}

fn expect_err(s: &str, needles: &[&str]) {
    let e = parse(s).expect_err("must fail").to_string();
    assert!(e.starts_with("robot.toml"), "{e}");
    for n in needles {
        assert!(e.contains(n), "`{e}` lacks `{n}`");
    }
}

#[test]
fn missing_field() {
    expect_err(
        &GOOD.replace("d = 100\n", ""),
        &["missing field `d`", "robot.toml:"],
    );
}

#[test]
fn wrong_type() {
    expect_err(
        &GOOD.replace("d = 100", "d = \"abc\""),
        &[":7", "field `d`", "invalid type"],
    );
}

#[test]
fn nan_value() {
    expect_err(
        &GOOD.replace("a = 300", "a = nan"),
        &[":12", "joints[2].a", "not a finite"],
    );
}

#[test]
fn limits_min_above_max() {
    expect_err(
        &GOOD.replace("[-90, 90]", "[90, -90]"),
        &[":13", "joints[2].limits", "greater than max"],
    );
}

#[test]
fn unknown_field_and_convention() {
    expect_err(
        &GOOD.replace("beta = 0", "bta = 0"),
        &["unknown field `bta`"],
    );
    expect_err(&GOOD.replace("\"dh\"", "\"xyz\""), &["convention", "`xyz`"]);
}

#[test]
fn bad_frame_vector_length() {
    expect_err(
        &GOOD.replace("[0, 0, 10, 0, 0, 0]", "[0, 0, 10]"),
        &["tool", "6 numbers"],
    );
}

#[test]
fn no_joints() {
    expect_err("convention = \"mdh\"\njoints = []\n", &["joints"]);
}

const TRACKED: &str = r#"
name = "tracked"
convention = "mdh"
[[joints]]
type = "prismatic"
alpha = 90
d = 10
a = 0
limits = [0, 4000]
[[joints]]
alpha = -90
d = 1045
a = 0
phi = -90
limits = [-185, 185]
[[joints]]
alpha = -90
d = 0
a = 500
[controller]
sign = [1, -1, 1]
offset = [100, 0, 0]
coupling = [[3, 2, -1.0]]
"#;

#[test]
fn prismatic_joint_and_controller() {
    let r = parse(TRACKED).unwrap();
    assert_eq!(r.joint_type(0), JointType::Prismatic);
    assert_eq!(r.joint_type(1), JointType::Revolute);
    // Prismatic limits are mm, not converted; revolute ones degrees.
    assert_eq!(r.limits()[0].min, 0.0);
    assert_eq!(r.limits()[0].max, 4000.0);
    assert!((r.limits()[1].max - 185f64.to_radians()).abs() < 1e-15);
    assert_eq!(r.joint_unit(0), super::super::Unit::Mm);
    let c = r.controller().unwrap();
    assert_eq!(c.sign(), &[1.0, -1.0, 1.0]);
    assert_eq!(c.offset(), &[100.0, 0.0, 0.0]);
    // q1 = axis1 + 100 mm, q2 = -axis2, q3 = axis3 - axis2.
    let q = r.joint_space().joints_from_axes(&[5.0, 10.0, 30.0]);
    assert_eq!(q[0], 105.0);
    assert!((q[1] + 10f64.to_radians()).abs() < 1e-15);
    assert!((q[2] - 20f64.to_radians()).abs() < 1e-15);
    // Without [controller]: no map.
    let plain = parse(GOOD).unwrap();
    assert!(plain.controller().is_none());
    assert!(plain
        .joint_types()
        .iter()
        .all(|t| *t == JointType::Revolute));
}

#[test]
fn bad_joint_type_and_prismatic_without_limits() {
    expect_err(
        &TRACKED.replace("\"prismatic\"", "\"linear\""),
        &[
            "robot.toml:5",
            "joints[1].type",
            "`linear` is not a joint type",
        ],
    );
    expect_err(
        &TRACKED.replace("limits = [0, 4000]\n", ""),
        &[
            "robot.toml:5",
            "joints[1].limits",
            "prismatic joint needs",
            "mm",
        ],
    );
    expect_err(
        &TRACKED.replace("[0, 4000]", "[4000, 0]"),
        &[
            "robot.toml:9",
            "joints[1].limits",
            "min 4000 mm is greater than max 0 mm",
        ],
    );
}

/// Every bad `[controller]` names the file, the line and the field.
#[test]
fn bad_controller_sections() {
    let cases: &[(&str, &str, &[&str])] = &[
        (
            "sign = [1, -1, 1]",
            "sign = [1, -1]",
            &[
                "robot.toml:21",
                "`controller.sign`",
                "expected 3 values",
                "got 2",
            ],
        ),
        (
            "sign = [1, -1, 1]",
            "sign = [1, -2, 1]",
            &["robot.toml:21", "`controller.sign[2]`", "-2 is not 1 or -1"],
        ),
        (
            "offset = [100, 0, 0]",
            "offset = [100, 0, 0, 0]",
            &["robot.toml:22", "`controller.offset`", "expected 3 values"],
        ),
        (
            "offset = [100, 0, 0]",
            "offset = [100, nan, 0]",
            &["robot.toml:22", "`controller.offset[2]`", "not a finite"],
        ),
        (
            "[[3, 2, -1.0]]",
            "[[4, 2, -1.0]]",
            &[
                "robot.toml:23",
                "`controller.coupling[1]`",
                "i 4 is not a joint number 1..3",
            ],
        ),
        (
            "[[3, 2, -1.0]]",
            "[[3, 2.5, -1.0]]",
            &[
                "robot.toml:23",
                "`controller.coupling[1]`",
                "j 2.5 is not a joint number",
            ],
        ),
        (
            "[[3, 2, -1.0]]",
            "[[3, 2]]",
            &[
                "robot.toml:23",
                "`controller.coupling[1]`",
                "expected [i, j, k]",
            ],
        ),
        (
            "[[3, 2, -1.0]]",
            "[[3, 3, -1.0]]",
            &["robot.toml:23", "`controller.coupling[1]`", "its own axis"],
        ),
        // q2 = -axis2 + axis3 and q3 = axis3 - axis2: two joints follow one combination.
        (
            "[[3, 2, -1.0]]",
            "[[2, 3, 1.0], [3, 2, -1.0]]",
            &["robot.toml:23", "`controller.coupling`", "singular"],
        ),
        (
            "sign = [1, -1, 1]",
            "sign = [1, -1, 1]\nscale = 2",
            &["robot.toml", "unknown field `scale`"],
        ),
    ];
    for (from, to, needles) in cases {
        let text = TRACKED.replace(from, to);
        assert_ne!(text, TRACKED, "{from}");
        expect_err(&text, needles);
    }
}

/// The KUKA presets' signs and the FANUC-style example's J2/J3 coupling go axis -> q -> axis
/// to 1e-12 (through the whole joint space: display units, radians and back).
#[test]
fn kuka_and_fanuc_maps_round_trip() {
    let kuka = load_robot("kuka-kr480-r3330").unwrap();
    let q = kuka
        .joint_space()
        .joints_from_axes(&[10.0, -20.0, 30.0, 40.0, -50.0, 60.0]);
    let want = [-10.0, -20.0, 30.0, -40.0, -50.0, -60.0];
    for (a, b) in q.iter().zip(want) {
        assert!((a.to_degrees() - b).abs() < 1e-12, "{q:?}");
    }
    assert_eq!(
        load_robot("kuka-kr480-r3330-table3")
            .unwrap()
            .controller()
            .unwrap()
            .sign(),
        kuka.controller().unwrap().sign()
    );
    let fanuc = load_robot(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/fanuc-like.toml"
    ))
    .unwrap();
    let q = fanuc
        .joint_space()
        .joints_from_axes(&[0.0, 20.0, 15.0, 0.0, 0.0, 0.0]);
    assert!((q[2].to_degrees() + 35.0).abs() < 1e-12, "q3 = -(J2 + J3)");
    for r in [&kuka, &fanuc] {
        for k in 0..200 {
            let axis: Vec<f64> = (0..6)
                .map(|i| ((k * 31 + i * 17) % 341) as f64 - 170.0 + 0.123 * i as f64)
                .collect();
            let back = r
                .joint_space()
                .axes_from_joints(&r.joint_space().joints_from_axes(&axis));
            for (a, b) in axis.iter().zip(&back) {
                assert!((a - b).abs() <= 1e-12, "{}: {axis:?} -> {back:?}", r.name());
            }
        }
    }
}

#[test]
fn absurd_magnitudes() {
    expect_err(
        &GOOD.replace("a = 300", "a = 1e300"),
        &[
            ":12",
            "field `joints[2].a`",
            "1e300 mm is out of range",
            "±1e6 mm",
        ],
    );
    expect_err(
        &GOOD.replace("alpha = 90", "alpha = 1e5"),
        &[":6", "field `joints[1].alpha`", "1e5 deg is out of range"],
    );
    expect_err(
        &GOOD.replace("[-90, 90]", "[-90, 2e5]"),
        &[
            ":13",
            "field `joints[2].limits`",
            "a joint value must be within ±1e5 deg",
        ],
    );
    expect_err(
        &GOOD.replace("[0, 0, 10, 0, 0, 0]", "[0, 0, 10, 0, -1e9, 0]"),
        &[":4", "field `tool[4]`", "-1e9 deg is out of range"],
    );
    expect_err(
        &format!("base = [2e6, 0, 0, 0, 0, 0]\n{GOOD}"),
        &[":1", "field `base[0]`", "2000000 mm is out of range"],
    );
    // Multi-turn axes are fine.
    parse(&GOOD.replace("[-90, 90]", "[-3600, 3600]")).unwrap();
}
