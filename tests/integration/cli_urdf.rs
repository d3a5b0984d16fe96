//! URDF robots (`--robot FILE.urdf`, `--base-link`, `--tip-link`) and `robocal export`: the UR5
//! URDF has the DH file's kinematics and calibrates the real UR5 data to the same validation
//! error; exports reproduce the calibrated FK and import again; trees and bad files are refused
//! with the documented exit codes.

use crate::util::*;
use serde_json::Value;
use std::path::Path;

/// The tool position `fk --json` prints.
fn fk(args: &[&str], joints: &str) -> [f64; 3] {
    let mut a = vec!["fk", "--json", "--joints", joints];
    a.extend_from_slice(args);
    let v: Value = serde_json::from_str(ok(&a).stdout().trim()).unwrap();
    [
        v["x"].as_f64().unwrap(),
        v["y"].as_f64().unwrap(),
        v["z"].as_f64().unwrap(),
    ]
}

fn gap(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

const JOINTS: [&str; 3] = [
    "0,0,0,0,0,0",
    "10,-80,95,-30,45,120",
    "-150,-20,-60,170,-95,-300",
];

#[test]
fn the_ur5_urdf_has_the_dh_file_kinematics() {
    let urdf = example("ur5.urdf");
    let toml = example("ur5.toml");
    for j in JOINTS {
        let d = gap(fk(&["--robot", &urdf], j), fk(&["--robot", &toml], j));
        assert!(d < 1e-9, "{j}: {d:e} mm");
    }
    let o = ok(&["robot", "show", &urdf]);
    assert!(
        o.stdout().contains("ur5 (6 joints, modified DH (Craig))"),
        "{}",
        o.stdout()
    );
}

const TREE: &str = r#"<robot name="two_arms">
  <link name="torso"/> <link name="l1"/> <link name="l2"/> <link name="left_hand"/>
  <link name="right_hand"/>
  <joint name="left" type="revolute"><parent link="torso"/><child link="l1"/>
    <origin xyz="0 0.2 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="left2" type="revolute"><parent link="l1"/><child link="left_hand"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="right" type="revolute"><parent link="torso"/><child link="l2"/>
    <origin xyz="0 -0.2 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="right2" type="prismatic"><parent link="l2"/><child link="right_hand"/>
    <origin xyz="0.3 0 0" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.2" effort="1" velocity="1"/></joint>
</robot>"#;

#[test]
fn a_tree_needs_tip_link_and_bad_files_exit_3() {
    let dir = Dir::new();
    let tree = dir.write("tree.urdf", TREE);
    let o = robocal(&["robot", "show", p(&tree)]);
    o.assert_code(3);
    let e = o.stderr();
    assert!(
        e.contains("tree.urdf")
            && e.contains("`left_hand`, `right_hand`")
            && e.contains("--tip-link"),
        "{e}"
    );
    let o = ok(&["robot", "show", p(&tree), "--tip-link", "right_hand"]);
    assert!(o.stdout().contains("prismatic"), "{}", o.stdout());
    ok(&[
        "fk",
        "--robot",
        p(&tree),
        "--base-link",
        "torso",
        "--tip-link",
        "left_hand",
        "--joints",
        "0.5,-0.2",
    ]);
    // A link that is not there: bad robot data (3); links for a TOML robot: usage (2).
    robocal(&["robot", "show", p(&tree), "--tip-link", "hand"]).assert_code(3);
    let o = robocal(&["robot", "show", &example("ur5.toml"), "--tip-link", "tool0"]);
    o.assert_code(2);
    assert!(o.stderr().contains("not a URDF"), "{}", o.stderr());
    let bad = dir.write("bad.urdf", "<robot name=\"x\"><link name=\"a\">");
    let o = robocal(&["robot", "show", p(&bad)]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("bad.urdf") && o.stderr().contains("not a valid URDF"),
        "{}",
        o.stderr()
    );
    let planar = dir.write(
        "planar.urdf",
        TREE.replace("type=\"prismatic\"", "type=\"planar\""),
    );
    let o = robocal(&["robot", "show", p(&planar), "--tip-link", "right_hand"]);
    o.assert_code(3);
    assert!(
        o.stderr().contains("planar.urdf:13:") && o.stderr().contains("joint `right2`"),
        "{}",
        o.stderr()
    );
}

/// Exports of a calibration reproduce its FK (`fk --params`) to 1e-6 mm, import again, refuse
/// to overwrite their input and write nothing on failure.
fn check_exports(result: &std::path::Path, reimport_args: &[&str]) {
    let dir = Dir::new();
    let xml = dir.join("cal.urdf");
    let toml = dir.join("cal.toml");
    ok(&["export", p(result), "--format", "urdf", "--out", p(&xml)]);
    ok(&["export", p(result), "--format", "toml", "--out", p(&toml)]);
    let text = std::fs::read_to_string(&xml).unwrap();
    assert!(
        text.contains("tracker frame") && text.contains("<robot"),
        "{text}"
    );
    for j in JOINTS {
        let want = fk(&["--params", p(result)], j);
        let mut a = vec!["--robot", p(&xml), "--tip-link", "tcp"];
        a.extend_from_slice(reimport_args);
        for (what, got) in [("URDF", fk(&a, j)), ("TOML", fk(&["--robot", p(&toml)], j))] {
            let d = gap(want, got);
            assert!(d < 1e-6, "{what} export at {j}: {d:e} mm");
        }
    }
    robocal(&["export", p(result), "--format", "toml", "--out", p(result)]).assert_code(2);
    robocal(&[
        "export",
        p(result),
        "--format",
        "json",
        "--out",
        p(&dir.join("x")),
    ])
    .assert_code(2);
    assert!(!dir.join("x").exists());
}

#[test]
fn exports_of_a_simulated_calibration_reproduce_its_kinematics() {
    check_exports(&fixtures::cell().result, &[]);
}

#[test]
fn ur5_urdf_calibrates_the_real_data_like_the_dh_file() {
    let Some(d) = real_data() else { return };
    // The geometric model of each (the URDF export holds geometry only).
    let dir = Dir::new();
    let fit = |robot: &str, out: &Path| {
        ok(&[
            "calibrate",
            "--robot",
            &example(robot),
            "--model",
            "geometric",
            "--data",
            p(&d.join("jacobi_ur5_grid.csv")),
            "--validate",
            p(&d.join("jacobi_ur5_random.csv")),
            "--out",
            p(out),
        ]);
        read_json(out)
    };
    let out = dir.join("ur5_urdf.json");
    let urdf = fit("ur5.urdf", &out);
    let dh = &fit("ur5.toml", &dir.join("ur5_dh.json"));
    let mean = |j: &Value, set: &str| j["errors"][set]["after"]["mean_mm"].as_f64().unwrap();
    let (a, b) = (mean(&urdf, "validation"), mean(dh, "validation"));
    let (ca, cb) = (mean(&urdf, "calibration"), mean(dh, "calibration"));
    eprintln!(
        "UR5 real data, validation mean: URDF {a:.6} mm, DH file {b:.6} mm; calibration mean: \
         URDF {ca:.6} mm, DH {cb:.6} mm"
    );
    assert!((a - b).abs() <= 0.002, "URDF {a} against DH {b}");
    // The result embeds the imported robot: later commands need no --robot.
    check_exports(&out, &[]);
}
