//! Files robocal never touches: no command writes over one of its inputs (same path, symbolic
//! link or hard link) or writes two outputs to one file; special files (devices, FIFOs, sockets,
//! directories, links to them) are never replaced; absurd counts are usage errors, not panics
//! (interrupted and killed runs: `cli_interrupted`). Each refused run is checked for
//! its exit code, its message (flag and files), no panic, and a directory exactly as before.
#![cfg(unix)]

use crate::util::bad_input::expect_refused;
use crate::util::fixtures::cell;
use crate::util::*;
use std::path::Path;

/// Names of the files in `dir` named like temporary files (`.robocal-PID-RANDOM.tmp`, or any
/// hidden `.tmp`).
pub(crate) fn temporaries(dir: &Path) -> Vec<String> {
    snapshot(dir)
        .into_keys()
        .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
        .collect()
}

/// A directory with copies of the fixture's inputs: `data.csv`, `t.truth.json`, `res.json`
/// (recording `data.csv` as its calibration data), `j.csv` (joints), `targets.csv`,
/// `robot.toml`.
pub(crate) fn inputs() -> Dir {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    std::fs::copy(&fx.data, d.join("data.csv")).unwrap();
    std::fs::copy(&fx.truth, d.join("t.truth.json")).unwrap();
    std::fs::copy(&fx.joints, d.join("j.csv")).unwrap();
    std::fs::copy(&fx.targets, d.join("targets.csv")).unwrap();
    std::fs::copy(&fx.robot_toml, d.join("robot.toml")).unwrap();
    let data = d.join("data.csv");
    let res = fx.result_with(|v| v["settings"]["data"] = p(&data).into());
    std::fs::write(d.join("res.json"), res).unwrap();
    dir
}

/// Runs `args` (with `{d}` standing for the directory) and checks: exit `code`, stderr has every
/// string of `wants` (`{d}` replaced too), no panic, and `d` exactly as before (inputs
/// byte-identical, nothing added, no temporary file).
fn refused(d: &Path, args: &[&str], code: i32, wants: &[&str]) {
    let args: Vec<String> = args.iter().map(|a| a.replace("{d}", p(d))).collect();
    let wants: Vec<String> = wants.iter().map(|w| w.replace("{d}", p(d))).collect();
    expect_refused(&args.join(" "), d, &args, code, &wants);
}

#[test]
fn no_command_writes_over_its_own_input() {
    let dir = inputs();
    let d = dir.path();
    let sim = ["simulate", "--robot", KUKA, "--truth", TRUTH];
    let also = "is also an input";
    // simulate: --joints, --truth (the CSV and the truth file beside it), --robot.
    let mut a = sim.to_vec();
    a.extend(["--joints", "{d}/j.csv", "--out", "{d}/j.csv"]);
    refused(
        d,
        &a,
        2,
        &["--out {d}/j.csv: this", also, "--joints {d}/j.csv"],
    );
    let a = [
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        "{d}/t.truth.json",
        "--poses",
        "5",
        "--out",
        "{d}/t.truth.json",
    ];
    refused(d, &a, 2, &["--out {d}/t.truth.json", also, "--truth"]);
    let a = [
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        "{d}/t.truth.json",
        "--poses",
        "5",
        "--out",
        "{d}/t.csv",
    ];
    refused(
        d,
        &a,
        2,
        &[
            "--out {d}/t.csv: the truth file written beside it, {d}/t.truth.json,",
            also,
            "--truth {d}/t.truth.json",
        ],
    );
    let a = [
        "simulate",
        "--robot",
        "{d}/robot.toml",
        "--truth",
        TRUTH,
        "--poses",
        "5",
        "--out",
        "{d}/robot.toml",
    ];
    refused(d, &a, 2, &["--out {d}/robot.toml", also, "--robot"]);
    // calibrate: --robot file, --data, --validate.
    let cal = [
        "calibrate",
        "--robot",
        "{d}/robot.toml",
        "--data",
        "{d}/data.csv",
    ];
    let mut a = cal.to_vec();
    a.extend(["--out", "{d}/robot.toml"]);
    refused(
        d,
        &a,
        2,
        &["--out {d}/robot.toml", also, "--robot {d}/robot.toml"],
    );
    let mut a = cal.to_vec();
    a.extend(["--validate", "{d}/j.csv", "--out", "{d}/j.csv"]);
    refused(d, &a, 2, &["--out {d}/j.csv", also, "--validate {d}/j.csv"]);
    // compensate: --robot file, --params, --joints, --targets, the data the result records.
    let comp = [
        "compensate",
        "--robot",
        "{d}/robot.toml",
        "--params",
        "{d}/res.json",
    ];
    for (input_flag, input, out) in [
        ("--joints", "{d}/j.csv", "{d}/robot.toml"),
        ("--joints", "{d}/j.csv", "{d}/res.json"),
        ("--joints", "{d}/j.csv", "{d}/j.csv"),
        ("--targets", "{d}/targets.csv", "{d}/targets.csv"),
        ("--joints", "{d}/j.csv", "{d}/data.csv"),
    ] {
        let mut a = comp.to_vec();
        a.extend([input_flag, input, "--out", out]);
        refused(d, &a, 2, &[&format!("--out {out}: this"), also]);
    }
    let mut a = comp.to_vec();
    a.extend(["--joints", "{d}/j.csv", "--out", "{d}/data.csv"]);
    refused(
        d,
        &a,
        2,
        &["{d}/data.csv, the calibration data recorded in --params {d}/res.json"],
    );
    // evaluate: --robot file, --params, --data.
    let ev = [
        "evaluate",
        "--robot",
        "{d}/robot.toml",
        "--params",
        "{d}/res.json",
        "--data",
        "{d}/j.csv",
    ];
    for (out, input) in [
        ("{d}/robot.toml", "--robot {d}/robot.toml"),
        ("{d}/res.json", "--params {d}/res.json"),
        ("{d}/j.csv", "--data {d}/j.csv"),
    ] {
        let mut a = ev.to_vec();
        a.extend(["--per-point", out]);
        refused(
            d,
            &a,
            2,
            &[&format!("--per-point {out}: this"), also, input],
        );
    }
}

#[test]
fn links_to_an_input_are_the_input() {
    let dir = inputs();
    let d = dir.path();
    std::fs::hard_link(d.join("data.csv"), d.join("hard.csv")).unwrap();
    std::os::unix::fs::symlink(d.join("j.csv"), d.join("soft.csv")).unwrap();
    let cal = ["calibrate", "--robot", KUKA, "--data", "{d}/data.csv"];
    let mut a = cal.to_vec();
    a.extend(["--out", "{d}/hard.csv"]);
    refused(
        d,
        &a,
        2,
        &[
            "--out {d}/hard.csv: this is also an input (--data {d}/data.csv",
            "the same file through a hard link",
        ],
    );
    let a = [
        "compensate",
        "--robot",
        KUKA,
        "--params",
        "{d}/res.json",
        "--joints",
        "{d}/j.csv",
        "--out",
        "{d}/soft.csv",
    ];
    refused(
        d,
        &a,
        2,
        &[
            "--out {d}/soft.csv: this is also an input (--joints {d}/j.csv",
            "reached through a symbolic link",
        ],
    );
    // The same file spelled differently.
    let a = [
        "compensate",
        "--robot",
        KUKA,
        "--params",
        "{d}/res.json",
        "--joints",
        "{d}/j.csv",
        "--out",
        "{d}/../{name}/./j.csv",
    ];
    let name = d.file_name().unwrap().to_str().unwrap();
    let a: Vec<String> = a.iter().map(|s| s.replace("{name}", name)).collect();
    let a: Vec<&str> = a.iter().map(String::as_str).collect();
    refused(d, &a, 2, &["is also an input (--joints {d}/j.csv)"]);
}

#[test]
fn two_outputs_never_share_a_file() {
    let dir = inputs();
    let d = dir.path();
    let a = [
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "5",
        "--validation",
        "2",
        "--out",
        "{d}/a.csv",
        "--validation-out",
        "{d}/a.truth.json",
    ];
    refused(
        d,
        &a,
        2,
        &[
            "--validation-out {d}/a.truth.json",
            "is the same file as --out {d}/a.truth.json",
        ],
    );
    // Written into a directory: a link from one output to another.
    let out = d.join("demo");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink("cell.csv", out.join("result.json")).unwrap();
    refused(
        d,
        &["demo", "--out", "{d}/demo"],
        2,
        &[
            "--out {d}/demo",
            "result.json",
            "is the same file as --out {d}/demo/cell.csv",
        ],
    );
}

#[test]
fn report_never_writes_over_what_it_reads() {
    let dir = inputs();
    let d = dir.path();
    let out = d.join("rep");
    std::fs::create_dir(&out).unwrap();
    std::fs::copy(d.join("data.csv"), out.join("histogram.svg")).unwrap();
    refused(
        d,
        &[
            "report",
            "{d}/res.json",
            "--verify",
            "{d}/rep/histogram.svg",
            "--out",
            "{d}/rep",
        ],
        2,
        &[
            "--out {d}/rep",
            "histogram.svg",
            "is also an input (--verify",
        ],
    );
    std::os::unix::fs::symlink(d.join("res.json"), out.join("report.html")).unwrap();
    refused(
        d,
        &["report", "{d}/res.json", "--out", "{d}/rep"],
        2,
        &["report.html", "is also an input (RESULT {d}/res.json"],
    );
    // The data file the result records.
    std::fs::remove_file(out.join("report.html")).unwrap();
    std::fs::hard_link(d.join("data.csv"), out.join("report.html")).unwrap();
    refused(
        d,
        &["report", "{d}/res.json", "--out", "{d}/rep"],
        2,
        &[
            "report.html",
            "the calibration data recorded in RESULT {d}/res.json",
        ],
    );
}

#[test]
fn special_files_are_never_replaced() {
    let dir = inputs();
    let d = dir.path();
    std::os::unix::fs::symlink("/dev/null", d.join("null.csv")).unwrap();
    let fifo = d.join("fifo.csv");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap();
    assert!(made.success());
    let _socket = std::os::unix::net::UnixListener::bind(d.join("sock.csv")).unwrap();
    std::fs::create_dir(d.join("sub")).unwrap();
    std::os::unix::fs::symlink(d.join("sub"), d.join("dirlink.csv")).unwrap();
    let regular = "robocal replaces only regular files";
    let cal = [
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        "{d}/data.csv",
        "--out",
    ];
    for (out, what) in [
        (
            "{d}/null.csv",
            "is a symbolic link to /dev/null, a character device",
        ),
        ("{d}/fifo.csv", "is a FIFO (named pipe)"),
        ("{d}/sock.csv", "is a socket"),
        ("{d}/dirlink.csv", "a directory, not a regular file"),
        ("/dev/null", "/dev/null: is a character device"),
    ] {
        let mut a = cal.to_vec();
        a.push(out);
        refused(d, &a, 4, &["--out", what, regular]);
    }
    let comp = [
        "compensate",
        "--robot",
        KUKA,
        "--params",
        "{d}/res.json",
        "--joints",
        "{d}/j.csv",
        "--out",
        "{d}/fifo.csv",
    ];
    refused(d, &comp, 4, &["--out", "{d}/fifo.csv: is a FIFO"]);
    let ev = [
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        "{d}/res.json",
        "--data",
        "{d}/data.csv",
        "--per-point",
        "{d}/null.csv",
    ];
    refused(d, &ev, 4, &["--per-point", "character device"]);
    // simulate: the CSV, and the truth file written beside it.
    let sim = [
        "simulate", "--robot", KUKA, "--truth", TRUTH, "--poses", "5", "--out",
    ];
    let mut a = sim.to_vec();
    a.push("{d}/null.csv");
    refused(d, &a, 4, &["--out", "character device"]);
    std::os::unix::fs::symlink("/dev/null", d.join("x.truth.json")).unwrap();
    let mut a = sim.to_vec();
    a.push("{d}/x.csv");
    refused(
        d,
        &a,
        4,
        &["--out", "{d}/x.truth.json: is a symbolic link to /dev/null"],
    );
    // A link to this process's own standard output (a pipe here).
    #[cfg(target_os = "linux")]
    {
        std::os::unix::fs::symlink("/proc/self/fd/1", d.join("self.csv")).unwrap();
        let mut a = cal.to_vec();
        a.push("{d}/self.csv");
        refused(
            d,
            &a,
            4,
            &["--out", "{d}/self.csv: is a symbolic link to", regular],
        );
    }
    // Report and demo directories holding special files.
    std::fs::create_dir(d.join("rep")).unwrap();
    let rep_fifo = d.join("rep/report.html");
    assert!(std::process::Command::new("mkfifo")
        .arg(&rep_fifo)
        .status()
        .unwrap()
        .success());
    refused(
        d,
        &["report", "{d}/res.json", "--out", "{d}/rep"],
        4,
        &["--out", "report.html: is a FIFO"],
    );
    std::fs::create_dir(d.join("demo")).unwrap();
    std::os::unix::fs::symlink("/dev/null", d.join("demo/cell.csv")).unwrap();
    refused(
        d,
        &["demo", "--out", "{d}/demo"],
        4,
        &["--out", "cell.csv: is a symbolic link to /dev/null"],
    );
    let null = std::fs::metadata("/dev/null").unwrap();
    use std::os::unix::fs::FileTypeExt;
    assert!(null.file_type().is_char_device(), "/dev/null was replaced");
}

#[test]
fn a_link_to_a_regular_file_is_written_through() {
    let dir = inputs();
    let d = dir.path();
    std::fs::write(d.join("real.csv"), "old\n").unwrap();
    std::os::unix::fs::symlink("real.csv", d.join("link.csv")).unwrap();
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&d.join("res.json")),
        "--joints",
        p(&d.join("j.csv")),
        "--out",
        p(&d.join("link.csv")),
    ]);
    o.assert_ok();
    let link = std::fs::symlink_metadata(d.join("link.csv")).unwrap();
    assert!(link.file_type().is_symlink(), "the link was replaced");
    let text = std::fs::read_to_string(d.join("real.csv")).unwrap();
    assert!(
        text.starts_with("q1,q2,q3,q4,q5,q6,axis1,axis2,axis3,axis4,axis5,axis6,status"),
        "{text}"
    );
    assert!(temporaries(d).is_empty());
}

#[test]
fn dash_is_standard_output_where_it_makes_sense() {
    let dir = inputs();
    let d = dir.path();
    let before = snapshot(d);
    let o = robocal(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&d.join("res.json")),
        "--joints",
        p(&d.join("j.csv")),
        "--out",
        "-",
    ]);
    o.assert_ok();
    let csv = o.stdout();
    assert!(
        csv.starts_with("q1,q2,q3,q4,q5,q6,axis1,axis2,axis3,axis4,axis5,axis6,status"),
        "{csv}"
    );
    assert_eq!(csv.lines().count(), 6, "{csv}");
    let err = o.stderr();
    assert!(err.contains("converged             5"), "{err}");
    assert!(err.contains("wrote standard output (5 rows)"), "{err}");
    let o = robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&d.join("res.json")),
        "--data",
        p(&d.join("data.csv")),
        "--per-point",
        "-",
    ]);
    o.assert_ok();
    let csv = o.stdout();
    assert!(csv.starts_with("line,q1,"), "{csv}");
    assert_eq!(csv.lines().count(), 34, "{csv}");
    assert!(o.stderr().contains("Mean (mm)"), "{}", o.stderr());
    assert_eq!(snapshot(d), before, "no file named `-` or anything else");

    // Where standard output cannot be the output.
    refused(
        d,
        &[
            "evaluate",
            "--robot",
            KUKA,
            "--params",
            "{d}/res.json",
            "--data",
            "{d}/data.csv",
            "--per-point",
            "-",
            "--json",
        ],
        2,
        &["--per-point - and --json both want standard output"],
    );
    refused(
        d,
        &[
            "simulate", "--robot", KUKA, "--truth", TRUTH, "--poses", "5", "--out", "-",
        ],
        2,
        &[
            "--out -: standard output is not accepted here",
            "truth file",
            "./-",
        ],
    );
    refused(
        d,
        &[
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            "{d}/data.csv",
            "--out",
            "-",
        ],
        2,
        &["--out -: standard output is not accepted here"],
    );
}

#[test]
fn absurd_counts_and_sizes_are_usage_errors_not_panics() {
    let dir = inputs();
    let d = dir.path();
    let sim = [
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--out",
        "{d}/s.csv",
    ];
    for (extra, want) in [
        (
            vec!["--poses", "18446744073709551615"],
            "--poses: at most 10000000",
        ),
        (
            vec!["--poses", "4294967296"],
            "--poses: at most 10000000",
        ),
        (
            vec!["--poses", "5", "--validation", "18446744073709551615"],
            "--validation: at most 10000000",
        ),
        (
            vec!["--poses", "6000000", "--validation", "6000000"],
            "--validation: --poses 6000000 and --validation 6000000 are 12000000 poses in all, at most 10000000",
        ),
    ] {
        let mut a = sim.to_vec();
        a.extend(extra);
        refused(d, &a, 2, &[want]);
    }
    let cal = [
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        "{d}/data.csv",
        "--out",
        "{d}/r.json",
    ];
    for (n, want) in [
        ("0", "--max-iterations: at least 1, got 0"),
        (
            "18446744073709551615",
            "--max-iterations: at most 1000000 (a solver that has not converged by then will \
             not), got 18446744073709551615",
        ),
    ] {
        let mut a = cal.to_vec();
        a.extend(["--max-iterations", n]);
        refused(d, &a, 2, &[want]);
    }
    refused(
        d,
        &[
            "compensate",
            "--robot",
            KUKA,
            "--params",
            "{d}/res.json",
            "--joints",
            "{d}/j.csv",
            "--out",
            "{d}/c.csv",
            "--max-iterations",
            "18446744073709551615",
        ],
        2,
        &["--max-iterations 18446744073709551615: at most 100000"],
    );
    // Lengths, masses and compliances far beyond any cell: readings of `inf` otherwise.
    for (extra, want) in [
        (
            vec!["--tracker", "1e300,0,0,0,0,0"],
            "--tracker: x: 1e300 mm is out of range",
        ),
        (
            vec!["--noise-mm", "1e300"],
            "--noise-mm: 1e300 mm is out of range",
        ),
        (
            vec!["--compliance", "1e-7", "--payload-kg", "1e300"],
            "--payload-kg: 1e300 kg is out of range",
        ),
        (
            vec!["--compliance", "1e300", "--payload-kg", "1"],
            "--compliance: value 1: 1e300 rad/(N·m) is out of range",
        ),
        (
            vec!["--outlier-fraction", "0.5", "--outlier-max-mm", "1e300"],
            "--outlier-max-mm: 1e300 mm is out of range",
        ),
    ] {
        let mut a = sim.to_vec();
        a.extend(["--poses", "5"]);
        a.extend(extra);
        // The simulation's own range checks (robocal_core::ranges): bad input, exit 3.
        refused(d, &a, 3, &[want]);
    }
    let mut a = cal.to_vec();
    a.extend(["--objective", "robust", "--robust-scale", "1e300"]);
    refused(d, &a, 2, &["--robust-scale: at most 1000000 mm, got 1e300"]);
    refused(
        d,
        &[
            "compensate",
            "--robot",
            KUKA,
            "--params",
            "{d}/res.json",
            "--joints",
            "{d}/j.csv",
            "--out",
            "{d}/c.csv",
            "--tolerance-mm",
            "1e300",
        ],
        2,
        &["--tolerance-mm 1e300: at most 1000000 mm"],
    );
    // Beyond usize: clap's own usage error.
    let mut a = sim.to_vec();
    a.extend(["--poses", "99999999999999999999999"]);
    refused(d, &a, 2, &["--poses"]);
}
