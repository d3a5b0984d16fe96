//! `robocal robot show` and `robocal fk`, including bad robot files and arguments.

use crate::util::*;

#[test]
fn fk_table1_zero_pose_json() {
    let o = robocal(&[
        "fk",
        "--robot",
        "kuka-kr480-r3330",
        "--joints",
        "0,0,0,0,0,0",
        "--json",
    ]);
    o.assert_ok();
    let v: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    let got = [
        v["x"].as_f64().unwrap(),
        v["y"].as_f64().unwrap(),
        v["z"].as_f64().unwrap(),
    ];
    let want = [3854.5558, -70.9065, 947.5837];
    for k in 0..3 {
        assert!((got[k] - want[k]).abs() < 1e-4, "{got:?}");
    }
}

#[test]
fn fk_negative_joint_values_and_text_output() {
    let o = robocal(&[
        "fk",
        "--robot",
        "kuka-kr480-r3330",
        "--joints",
        "-10,-20,30,-40,50,-60",
    ]);
    o.assert_ok();
    assert!(o.stdout().contains("tool position (mm, base frame): x ="));
}

#[test]
fn robot_file_equals_preset() {
    let q = "10,-30,20,40,-50,60";
    let a = robocal(&["fk", "--robot", "kuka-kr480-r3330", "--joints", q, "--json"]);
    let b = robocal(&[
        "fk",
        "--robot",
        &example("kr480-r3330.toml"),
        "--joints",
        q,
        "--json",
    ]);
    assert!(a.success() && b.success(), "{}", b.stderr());
    assert_eq!(a.stdout(), b.stdout());
}

#[test]
fn robot_show_prints_table_one() {
    let o = robocal(&["robot", "show", "kuka-kr480-r3330"]);
    o.assert_ok();
    let s = o.stdout();
    assert!(
        s.contains("alpha (deg)") && s.contains("1045.0000") && s.contains("-55.0000"),
        "{s}"
    );
    assert!(s.contains("q2: -130 .. 20"), "{s}");
    let o = robocal(&["robot", "show", &example("wam.toml")]);
    o.assert_ok();
    assert!(o.stdout().contains("7 joints"));
}

/// Writes a robot file into a temporary directory and runs `fk` on it.
fn fk_with_file(toml: &str, joints: &str) -> (Outcome, String) {
    let dir = Dir::new();
    let p = dir.write("bad.toml", toml);
    let ps = p.display().to_string();
    (robocal(&["fk", "--robot", &ps, "--joints", joints]), ps)
}

const TWO: &str = "convention = \"dh\"\n[[joints]]\nalpha = 90\nd = 100\na = 0\n[[joints]]\nalpha = 0\nd = 0\na = 300\nlimits = [-90, 90]\n";

fn expect_failure(toml: &str, joints: &str, code: i32, needles: &[&str]) {
    let (o, path) = fk_with_file(toml, joints);
    o.assert_code(code);
    let e = o.stderr();
    assert!(!e.contains("panicked"), "{e}");
    for n in needles {
        let n = n.replace("{path}", &path);
        assert!(e.contains(&n), "`{e}` lacks `{n}`");
    }
}

#[test]
fn good_file_works() {
    let (o, _) = fk_with_file(TWO, "0,0");
    o.assert_ok();
}

#[test]
fn missing_field_names_file_and_field() {
    expect_failure(
        &TWO.replace("d = 100\n", ""),
        "0,0",
        3,
        &["{path}:", "missing field `d`"],
    );
}

#[test]
fn wrong_type_names_file_line_and_field() {
    expect_failure(
        &TWO.replace("a = 300", "a = \"long\""),
        "0,0",
        3,
        &["{path}:9", "field `a`", "invalid type"],
    );
}

#[test]
fn nan_names_file_line_and_field() {
    expect_failure(
        &TWO.replace("d = 100", "d = nan"),
        "0,0",
        3,
        &["{path}:4", "joints[1].d", "not a finite number"],
    );
}

#[test]
fn limit_min_above_max() {
    expect_failure(
        &TWO.replace("[-90, 90]", "[90, -90]"),
        "0,0",
        3,
        &["{path}:10", "joints[2].limits", "greater than max"],
    );
}

#[test]
fn joint_count_mismatch() {
    expect_failure(TWO, "0,0,0", 2, &["--joints", "2 joints, got 3 values"]);
    let o = robocal(&[
        "fk",
        "--robot",
        "kuka-kr480-r3330",
        "--joints",
        "0,0,x,0,0,0",
    ]);
    o.assert_code(2);
    assert!(
        o.stderr().contains("value 3 `x` is not a number"),
        "{}",
        o.stderr()
    );
}

#[test]
fn unknown_preset_and_missing_file() {
    let o = robocal(&["fk", "--robot", "kuka-kr1000", "--joints", "0,0,0,0,0,0"]);
    o.assert_code(2);
    assert!(
        o.stderr().contains("unknown robot preset `kuka-kr1000`"),
        "{}",
        o.stderr()
    );
    let o = robocal(&["fk", "--robot", "missing/robot.toml", "--joints", "0"]);
    o.assert_code(4);
    assert!(o.stderr().contains("missing/robot.toml"), "{}", o.stderr());
}

/// `robocal ... | head`: a closed stdout ends the program quietly (SIGPIPE), never with a panic.
#[cfg(unix)]
#[test]
fn closed_stdout_is_not_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let mut child = command()
        .args(["robot", "show", "kuka-kr480-r3330"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!e.contains("panicked"), "{e}");
    assert!(
        o.status.success() || o.status.signal() == Some(13),
        "{:?}: {e}",
        o.status
    );
}
