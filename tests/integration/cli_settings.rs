//! Settings and their flags: the library names its settings (`outliers.max_mm`,
//! `identifiability.fix`, ...), and the CLI shows the flag the user typed instead, in the field
//! of the message and inside its text; every command checks its settings before any work, so a
//! bad one writes nothing.

use crate::util::*;
use std::path::Path;

/// Runs `args` and asserts exit `code`, every one of `wants` in stderr, and no library setting
/// name (a dotted or snake_case field) where a flag belongs.
fn fails(args: &[&str], code: i32, wants: &[&str]) {
    let o = robocal(args);
    let err = o.stderr();
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    for w in wants {
        assert!(err.contains(w), "{args:?}: `{w}` not in: {err}");
    }
    for setting in [
        "outliers.",
        "gravity.",
        "truth.",
        "identifiability.",
        "`robot`",
        "noise_mm",
        "plane_z_mm",
        "tracker_frame",
    ] {
        assert!(!err.contains(setting), "{args:?}: `{setting}` in: {err}");
    }
}

fn simulate(extra: &str, out: &Path) -> Vec<String> {
    let mut v: Vec<String> = format!(
        "simulate --robot kuka-kr480-r3330 --truth kuka-kr480-r3330-table3 --poses 5 {extra}"
    )
    .split_whitespace()
    .map(str::to_owned)
    .collect();
    v.push("--out".into());
    v.push(out.display().to_string());
    v
}

#[test]
fn library_settings_are_reported_as_flags() {
    let dir = Dir::new();
    let out = dir.path().join("out.csv");
    let cases: &[(&str, i32, &[&str])] = &[
        // The field and a setting named inside the text both become flags.
        (
            "--outlier-fraction 0.1 --outlier-min-mm 5 --outlier-max-mm 2",
            3,
            &["--outlier-min-mm: 5 is greater than --outlier-max-mm 2"],
        ),
        (
            "--compliance 1e-7,1e-7,1e-7,1e-7,1e-7,1e-7",
            3,
            &["--payload-kg: gravity deflection needs a mass: give --payload-kg and/or --link-masses-kg"],
        ),
        ("--noise-mm 1e300", 3, &["--noise-mm: 1e300 mm is out of range"]),
        ("--plane-z-mm -1e7", 3, &["--plane-z-mm: "]),
        ("--tracker 0,0,0,0,1e9,0", 3, &["--tracker: B: 1e9 deg"]),
    ];
    for (extra, code, wants) in cases {
        let args = simulate(extra, &out);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fails(&args, *code, wants);
        assert!(!out.exists(), "{extra}: written");
    }
}

#[test]
fn a_truth_robot_of_another_shape_names_the_truth_flag() {
    let dir = Dir::new();
    let robot = dir.path().join("one.toml");
    std::fs::write(
        &robot,
        "convention = \"mdh\"\n[[joints]]\nalpha = 0\nd = 0\na = 100\n",
    )
    .unwrap();
    let out = dir.path().join("out.csv");
    let args = [
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        robot.to_str().unwrap(),
        "--poses",
        "5",
        "--out",
        out.to_str().unwrap(),
    ];
    fails(&args, 3, &["--truth: truth robot", "has 1 joints"]);
    assert!(!out.exists());
}

/// Settings are checked before any work: a parameter given to both --fix and --free is refused
/// before the data file is read (this one is not even a measurement file), and nothing is
/// written.
#[test]
fn calibrate_checks_its_settings_before_reading_the_data() {
    let dir = Dir::new();
    let data = dir.path().join("data.csv");
    std::fs::write(&data, "not,a,measurement,file\n").unwrap();
    let out = dir.path().join("r.json");
    let args = [
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        data.to_str().unwrap(),
        "--fix",
        "d2,a4",
        "--free",
        "d2",
        "--out",
        out.to_str().unwrap(),
    ];
    fails(
        &args,
        3,
        &["--fix: `d2` is given both to --fix and to --free"],
    );
    assert!(!robocal(&args).stderr().contains("data.csv"));
    assert!(!out.exists());
}
