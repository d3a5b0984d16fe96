//! Output streams, concurrent runs and file limits: a full standard output or standard error is
//! exit 4 with a message where one can still be printed (never a panic); two runs writing the
//! same outputs at once leave one run's complete set (the other is refused and told why); a
//! file-size limit is exit 4 with the temporaries removed; any legal output name can be written.

use crate::util::fixtures::cell;
use crate::util::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Stdio;

/// `/dev/full` opened for writing: every write fails with "No space left on device".
fn full() -> Stdio {
    Stdio::from(
        std::fs::File::options()
            .write(true)
            .open("/dev/full")
            .expect("/dev/full"),
    )
}

/// Which stream of the child goes to `/dev/full`.
#[derive(Clone, Copy, Debug)]
enum Full {
    Stdout,
    Stderr,
}

/// Runs robocal with `args` and the stream `which` on `/dev/full`; gives the exit code and the
/// other stream.
fn run_full(args: &[&str], which: Full) -> (Option<i32>, String) {
    let mut c = command();
    c.args(args);
    match which {
        Full::Stdout => c.stdout(full()).stderr(Stdio::piped()),
        Full::Stderr => c.stderr(full()).stdout(Stdio::piped()),
    };
    let o = c.output().expect("robocal runs");
    let other = match which {
        Full::Stdout => o.stderr,
        Full::Stderr => o.stdout,
    };
    (
        o.status.code(),
        String::from_utf8_lossy(&other).into_owned(),
    )
}

/// The regular files under `dir` and their bytes.
fn tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return m;
    };
    for e in entries.flatten() {
        let path = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if path.is_dir() {
            for (k, v) in tree(&path) {
                m.insert(format!("{name}/{k}"), v);
            }
        } else {
            m.insert(name, std::fs::read(&path).expect("readable"));
        }
    }
    m
}

/// Every command with a full standard output: exit 4, "writing to standard output" on
/// standard error, no panic; the files it writes are a whole set or nothing, and nothing else
/// (no temporary) is left in its folder.
#[cfg(target_os = "linux")]
#[test]
fn a_full_standard_output_is_exit_4_never_a_panic_nor_half_a_set() {
    let c = cell();
    let data = p(&c.data);
    let result = p(&c.result);
    let joints = p(&c.joints);
    // (arguments with OUT for the command's output folder, the files it writes into OUT)
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["robot", "list"], vec![]),
        (vec!["robot", "show", KUKA], vec![]),
        (
            vec!["fk", "--robot", KUKA, "--joints", "0,-90,90,0,0,0"],
            vec![],
        ),
        (
            vec![
                "simulate",
                "--robot",
                KUKA,
                "--truth",
                TRUTH,
                "--poses",
                "20",
                "--validation",
                "5",
                "--validation-out",
                "OUT/v.csv",
                "--out",
                "OUT/s.csv",
            ],
            vec!["s.csv", "s.truth.json", "v.csv"],
        ),
        (
            vec![
                "calibrate",
                "--robot",
                KUKA,
                "--data",
                data,
                "--out",
                "OUT/r.json",
            ],
            vec!["r.json"],
        ),
        (
            vec![
                "evaluate",
                "--params",
                result,
                "--data",
                data,
                "--per-point",
                "OUT/pp.csv",
            ],
            vec!["pp.csv"],
        ),
        (
            vec![
                "compensate",
                "--params",
                result,
                "--joints",
                joints,
                "--out",
                "OUT/c.csv",
            ],
            vec!["c.csv"],
        ),
        (
            vec![
                "plan",
                "--robot",
                KUKA,
                "--poses",
                "30",
                "--candidates",
                "100",
                "--out",
                "OUT/p.csv",
            ],
            vec!["p.csv"],
        ),
        (
            vec!["report", result, "--out", "OUT/rep"],
            vec!["rep/histogram.svg", "rep/report.html"],
        ),
        (
            vec!["demo", "--out", "OUT/demo"],
            vec![
                "demo/cell.csv",
                "demo/cell.truth.json",
                "demo/commanded.csv",
                "demo/desired.csv",
                "demo/histogram.svg",
                "demo/report.html",
                "demo/result.json",
                "demo/validation.csv",
                "demo/verify.csv",
            ],
        ),
        (
            vec!["export", result, "--format", "urdf", "--out", "OUT/r.urdf"],
            vec!["r.urdf"],
        ),
        (vec!["completions", "bash"], vec![]),
        (vec!["man"], vec![]),
        (vec!["--help"], vec![]),
        (vec!["simulate", "--help"], vec![]),
    ];
    for (args, files) in &cases {
        let d = Dir::new();
        let out = p(d.path()).to_owned();
        let args: Vec<String> = args.iter().map(|a| a.replace("OUT", &out)).collect();
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, stderr) = run_full(&args, Full::Stdout);
        let shown = format!("robocal {}\n--- stderr ---\n{stderr}", args.join(" "));
        assert_eq!(code, Some(4), "{shown}");
        assert!(!stderr.contains("panicked"), "{shown}");
        assert!(
            stderr.contains("error: writing to standard output: No space left on device"),
            "{shown}"
        );
        let written: Vec<String> = tree(d.path()).into_keys().collect();
        assert!(
            written.is_empty() || written == *files,
            "half a set or a temporary left: {written:?}\n{shown}"
        );
    }
}

/// A full standard error: exit 4 (no message can be printed), no panic, for a command that
/// warns; an error whose message cannot be printed keeps its exit code.
#[cfg(target_os = "linux")]
#[test]
fn a_full_standard_error_is_exit_4_never_a_panic() {
    // Joints outside the limits: a warning on standard error before any output.
    let (code, stdout) = run_full(
        &["fk", "--robot", KUKA, "--joints", "400,0,0,0,0,0"],
        Full::Stderr,
    );
    assert_eq!(code, Some(4), "{stdout}");
    // An error whose message cannot be printed keeps its own exit code.
    let (code, _) = run_full(&["robot", "show", "no-such-robot"], Full::Stderr);
    assert_eq!(code, Some(2));
}

/// 20 pairs of `simulate` (CSV, truth JSON and validation CSV) started together with one
/// output: each pair leaves the complete set of one of its runs, and a run that was refused
/// says why (exit 4) and wrote nothing.
#[test]
fn concurrent_simulate_runs_leave_one_runs_complete_set() {
    let d = Dir::new();
    let out = d.join("ss.csv");
    let val = d.join("ss.val.csv");
    let args = |seed: &str| {
        vec![
            "simulate".to_owned(),
            "--robot".into(),
            KUKA.into(),
            "--truth".into(),
            "random".into(),
            "--poses".into(),
            "200".into(),
            "--validation".into(),
            "50".into(),
            "--validation-out".into(),
            p(&val).into(),
            "--seed".into(),
            seed.into(),
            "--out".into(),
            p(&out).into(),
        ]
    };
    concurrent_pairs(d.path(), &args, 3);
}

/// 20 pairs of `demo` started together with one output directory: each pair leaves one run's
/// complete directory (every file from the same seed).
#[test]
fn concurrent_demo_runs_leave_one_runs_complete_directory() {
    let d = Dir::new();
    let out = d.join("dd");
    let args = |seed: &str| {
        vec![
            "demo".to_owned(),
            "--seed".into(),
            seed.into(),
            "--out".into(),
            p(&out).into(),
        ]
    };
    concurrent_pairs(d.path(), &args, 9);
}

/// Runs 20 pairs of the command `args(seed)` for seeds 1 and 2 at once in `dir`; after each,
/// the files in `dir` must be exactly those of one seed's run alone (`files` of them).
fn concurrent_pairs(dir: &Path, args: &dyn Fn(&str) -> Vec<String>, files: usize) {
    let clear = || {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                std::fs::remove_dir_all(p).unwrap();
            } else {
                std::fs::remove_file(p).unwrap();
            }
        }
    };
    let mut reference = Vec::new();
    for seed in ["1", "2"] {
        clear();
        ok(&args(seed));
        let t = tree(dir);
        assert_eq!(t.len(), files, "{:?}", t.keys());
        reference.push(t);
    }
    assert_ne!(reference[0], reference[1]);
    let mut refused = 0;
    for pair in 0..20 {
        clear();
        let children: Vec<_> = ["1", "2"]
            .iter()
            .map(|seed| {
                command()
                    .args(args(seed))
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .expect("robocal runs")
            })
            .collect();
        let mut codes = Vec::new();
        for c in children {
            let o = c.wait_with_output().unwrap();
            let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
            match o.status.code() {
                Some(0) => {}
                Some(4) => {
                    assert!(stderr.contains("another robocal run"), "{stderr}");
                    assert!(stderr.contains("nothing was written"), "{stderr}");
                    refused += 1;
                }
                other => panic!("pair {pair}: exit {other:?}\n{stderr}"),
            }
            codes.push(o.status.code());
        }
        assert!(codes.contains(&Some(0)), "pair {pair}: no run succeeded");
        let t = tree(dir);
        assert!(
            t == reference[0] || t == reference[1],
            "pair {pair} ({codes:?}): a mixed or partial set: {:?}",
            t.keys()
        );
    }
    eprintln!("{refused} of 20 pairs overlapped: the second run was refused");
}

/// A file-size limit (`ulimit -f`, SIGXFSZ): exit 4 with a message, the earlier outputs as they
/// were, no temporary left.
#[cfg(unix)]
#[test]
fn a_file_size_limit_is_exit_4_and_leaves_the_old_outputs() {
    let d = Dir::new();
    let out = d.write("s.csv", "old csv\n");
    d.write("s.truth.json", "old truth\n");
    let before = tree(d.path());
    let script = format!(
        "ulimit -f 16 && exec '{}' simulate --robot {KUKA} --truth {TRUTH} --poses 3000 --out '{}'",
        env!("CARGO_BIN_EXE_robocal"),
        p(&out)
    );
    let o = std::process::Command::new("sh")
        .args(["-c", &script])
        .output()
        .expect("sh runs");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(4), "{stderr}");
    assert!(stderr.contains("File too large"), "{stderr}");
    assert!(stderr.contains("s.csv"), "{stderr}");
    assert_eq!(
        tree(d.path()),
        before,
        "outputs changed or temporaries left"
    );
}

/// An output name of 255 bytes (the longest most file systems allow) is written: the temporary
/// file's name does not grow with it.
#[test]
fn an_output_name_of_255_bytes_is_written() {
    let d = Dir::new();
    let out = d.join(format!("{}.csv", "p".repeat(251)));
    let args = [
        "plan",
        "--robot",
        KUKA,
        "--poses",
        "30",
        "--candidates",
        "100",
        "--out",
    ];
    ok(&[&args[..], &[p(&out)]].concat());
    assert!(out.is_file());
    assert_eq!(tree(d.path()).len(), 1);
}
