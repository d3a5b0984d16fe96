//! Bad output paths and command-line values, for every command that writes or takes them:
//! each fails with its exit code and message before any work, and leaves the directory as it was.

use crate::util::bad_input::expect_failure;
use crate::util::fixtures::cell;
use crate::util::*;

#[test]
fn output_paths_that_cannot_be_written_fail_before_any_work() {
    let fx = cell();
    let root = Dir::new();
    let d = root.path();
    let nodir = d.join("no-such-dir");
    let (data, res, joints) = (p(&fx.data), p(&fx.result), p(&fx.joints));
    let cases: Vec<(Vec<String>, &str, i32, String)> = {
        let out_in_missing = nodir.join("out.csv");
        let om = p(&out_in_missing).to_owned();
        let dir_out = d.join("a-directory");
        std::fs::create_dir(&dir_out).unwrap();
        let od = p(&dir_out).to_owned();
        let missing_msg = format!("directory {} does not exist", p(&nodir));
        let dir_msg = format!("{od}: is a directory, expected a file path");
        let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        vec![
            (
                v(&["calibrate", "--robot", KUKA, "--data", data, "--out", &om]),
                "--out",
                4,
                missing_msg.clone(),
            ),
            (
                v(&["calibrate", "--robot", KUKA, "--data", data, "--out", &od]),
                "--out",
                4,
                dir_msg.clone(),
            ),
            (
                v(&["calibrate", "--robot", KUKA, "--data", data, "--out", data]),
                "--out",
                2,
                "this is also an input".into(),
            ),
            (
                v(&[
                    "compensate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--joints",
                    joints,
                    "--out",
                    &om,
                ]),
                "--out",
                4,
                missing_msg.clone(),
            ),
            (
                v(&[
                    "compensate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--joints",
                    joints,
                    "--out",
                    &od,
                ]),
                "--out",
                4,
                dir_msg.clone(),
            ),
            (
                v(&[
                    "compensate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--joints",
                    joints,
                    "--out",
                    joints,
                ]),
                "--out",
                2,
                "this is also an input".into(),
            ),
            (
                v(&[
                    "evaluate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--data",
                    data,
                    "--per-point",
                    &om,
                ]),
                "--per-point",
                4,
                missing_msg.clone(),
            ),
            (
                v(&[
                    "evaluate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--data",
                    data,
                    "--per-point",
                    &od,
                ]),
                "--per-point",
                4,
                dir_msg.clone(),
            ),
            (
                v(&[
                    "evaluate",
                    "--robot",
                    KUKA,
                    "--params",
                    res,
                    "--data",
                    data,
                    "--per-point",
                    data,
                ]),
                "--per-point",
                2,
                "this is also an input".into(),
            ),
            (
                v(&[
                    "simulate", "--robot", KUKA, "--truth", TRUTH, "--poses", "5", "--out", &om,
                ]),
                "--out",
                4,
                missing_msg.clone(),
            ),
            (
                v(&[
                    "simulate", "--robot", KUKA, "--truth", TRUTH, "--poses", "5", "--out", &od,
                ]),
                "--out",
                4,
                dir_msg.clone(),
            ),
            (
                v(&[
                    "simulate",
                    "--robot",
                    KUKA,
                    "--truth",
                    TRUTH,
                    "--poses",
                    "5",
                    "--validation",
                    "2",
                    "--validation-out",
                    &om,
                    "--out",
                    p(&d.join("ok.csv")),
                ]),
                "--validation-out",
                4,
                missing_msg.clone(),
            ),
        ]
    };
    for (args, flag, code, msg) in cases {
        let label = format!("{flag}: {}", args.join(" "));
        expect_failure(&label, d, &args, code, &[flag.to_owned(), msg]);
        assert!(!nodir.exists());
    }
}

#[test]
fn bad_command_line_values_are_usage_errors() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let res = p(&fx.result);
    let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            v(&["fk", "--robot", KUKA, "--joints", "0,0,0,0,0"]),
            "--joints: robot `kuka-kr480-r3330` has 6 joints, got 5 values",
        ),
        (
            v(&["fk", "--robot", KUKA, "--joints", "0,0,0,0,0,abc"]),
            "--joints: value 6 `abc` is not a number",
        ),
        (
            v(&["fk", "--robot", KUKA, "--joints", "0,0,0,0,0,nan"]),
            "--joints: value 6 `nan` is not a finite number",
        ),
        (
            v(&["fk", "--robot", "kuka-kr999", "--joints", "0"]),
            "unknown robot preset `kuka-kr999`",
        ),
        (
            v(&["robot", "show", "kuka-kr480"]),
            "unknown robot preset `kuka-kr480`",
        ),
        (
            v(&[
                "compensate",
                "--robot",
                KUKA,
                "--params",
                res,
                "--joints",
                p(&fx.joints),
                "--out",
                p(&d.join("out.csv")),
                "--tolerance-mm=-1",
            ]),
            "--tolerance-mm",
        ),
        (
            v(&[
                "calibrate",
                "--robot",
                KUKA,
                "--data",
                p(&fx.data),
                "--out",
                p(&d.join("out.json")),
                "--fix",
                "d9",
            ]),
            "--fix: unknown parameter `d9`",
        ),
        (
            v(&[
                "simulate",
                "--robot",
                KUKA,
                "--truth",
                TRUTH,
                "--poses",
                "5",
                "--tracker",
                "1,2,3",
                "--out",
                p(&d.join("out.csv")),
            ]),
            "--tracker: expected 6 values",
        ),
    ];
    for (args, want) in cases {
        let label = args.join(" ");
        expect_failure(&label, d, &args, 2, &[want.to_owned()]);
    }
}
