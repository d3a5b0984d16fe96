//! An interrupted or killed run leaves no temporary file behind and keeps the old output; the
//! temporaries of killed runs are removed at the next write, and only those robocal made.
#![cfg(unix)]

use crate::cli_trust_files::{inputs, temporaries};
use crate::util::fixtures::many_poses;
use crate::util::*;
use std::path::Path;

/// The command that compensates the 200,000 poses of [`many_poses`] into `out`: a run long
/// enough to be interrupted while its temporary file is open.
fn long_compensation(d: &Path, out: &Path) -> Vec<String> {
    [
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&d.join("res.json")),
        "--joints",
        p(many_poses()),
        "--out",
        p(out),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

/// The records of temporaries process `pid` has (`$TMPDIR/robocal-UID/temporaries/PID-*`), and
/// whether one of them is complete (device and inode, then the temporary's path).
fn records(pid: u32) -> (usize, bool) {
    // SAFETY: getuid has no preconditions and cannot fail.
    let uid = unsafe { libc::getuid() };
    let dir = std::env::temp_dir()
        .join(format!("robocal-{uid}"))
        .join("temporaries");
    let Ok(entries) = std::fs::read_dir(dir) else {
        return (0, false);
    };
    let mine: Vec<_> = entries
        .flatten()
        .filter(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(&format!("{pid}-"))
        })
        .collect();
    let complete = mine.iter().any(|e| {
        std::fs::read_to_string(e.path())
            .is_ok_and(|t| t.split_once('\n').is_some_and(|(_, p)| p.ends_with(".tmp")))
    });
    (mine.len(), complete)
}

/// Starts `args`, waits until its temporary file for `out` exists (and its record, when
/// `recorded`), sends `signal`; gives the exit status, stderr and the process id.
fn interrupt_when(
    args: &[String],
    out: &Path,
    signal: i32,
    recorded: bool,
) -> (Option<i32>, Option<i32>, String, u32) {
    use std::os::unix::process::ExitStatusExt;
    let child = command()
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let dir = out.parent().unwrap();
    let prefix = format!(".robocal-{}-", child.id());
    let start = std::time::Instant::now();
    while !temporaries(dir).iter().any(|n| n.starts_with(&prefix)) {
        assert!(
            start.elapsed() < std::time::Duration::from_secs(60),
            "no temporary file {prefix}*.tmp in {}",
            dir.display()
        );
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    // The record that proves the temporary robocal's is written just after it.
    while recorded && !records(child.id()).1 {
        assert!(
            start.elapsed() < std::time::Duration::from_secs(60),
            "no complete record of the temporary of process {}",
            child.id()
        );
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    let pid = child.id();
    // SAFETY: sends a signal to the child started above.
    let r = unsafe { libc::kill(pid as i32, signal) };
    assert_eq!(r, 0);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o.status.code(), o.status.signal(), err, pid)
}

/// [`interrupt_when`] its temporary and the temporary's record exist.
fn interrupt(args: &[String], out: &Path, signal: i32) -> (Option<i32>, Option<i32>, String) {
    let (code, sig, err, _) = interrupt_when(args, out, signal, true);
    (code, sig, err)
}

/// An interrupted compensation: exit 130, the message naming `signal` and the one temporary
/// removed, `out` as it was ("old output") and no temporary left in `d`.
fn assert_interrupted(code: Option<i32>, err: &str, signal: &str, out: &Path, d: &Path) {
    assert_eq!(code, Some(130), "{signal}: {err}");
    assert!(
        err.contains(&format!(
            "error: interrupted by {signal}; 1 unfinished temporary file(s) removed"
        )),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(out).unwrap(), "old output\n");
    assert_eq!(temporaries(d), Vec::<String>::new(), "{signal}");
}

#[test]
fn sigint_and_sigterm_remove_the_temporary_and_keep_the_old_output() {
    let dir = inputs();
    let d = dir.path();
    let out = d.join("out.csv");
    std::fs::write(&out, "old output\n").unwrap();
    let args = long_compensation(d, &out);
    for (signal, name) in [(libc::SIGINT, "SIGINT"), (libc::SIGTERM, "SIGTERM")] {
        let (code, _, err) = interrupt(&args, &out, signal);
        assert!(!err.contains("panicked"), "{err}");
        assert_interrupted(code, &err, name, &out, d);
    }
}

/// A signal that comes as soon as the temporary exists, before its record may, removes both
/// (the handler waits for the step that creates them; a unit test of `io::open_temporaries`
/// holds such a step open to show the wait, which signals from here seldom hit).
#[test]
fn a_signal_as_the_temporary_is_created_removes_it_and_its_record() {
    let dir = inputs();
    let d = dir.path();
    let out = d.join("out.csv");
    std::fs::write(&out, "old output\n").unwrap();
    let args = long_compensation(d, &out);
    for _ in 0..3 {
        for (signal, name) in [(libc::SIGINT, "SIGINT"), (libc::SIGTERM, "SIGTERM")] {
            let (code, _, err, pid) = interrupt_when(&args, &out, signal, false);
            assert_interrupted(code, &err, name, &out, d);
            assert_eq!(records(pid).0, 0, "{name}: the temporary's record is left");
        }
    }
}

/// A signal while nothing is being written (a calibration of 200,000 poses, after its first
/// line) ends the run at once, from whichever thread it reaches.
#[test]
fn a_signal_while_computing_ends_the_run_and_writes_nothing() {
    use std::io::BufRead;
    let dir = inputs();
    let d = dir.path();
    let out = d.join("res.json");
    let old = std::fs::read_to_string(&out).unwrap();
    let mut child = command()
        .args([
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            p(many_poses()),
            "--model",
            "geometric",
            "--out",
            p(&out),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.contains("200000 calibration point(s)"), "{first}");
    // SAFETY: sends a signal to the child started above.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(
        err.contains("error: interrupted by SIGTERM; 0 unfinished temporary file(s) removed"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&out).unwrap(), old);
    assert_eq!(temporaries(d), Vec::<String>::new());
}

#[test]
fn temporaries_of_killed_runs_are_removed_at_the_next_write() {
    let dir = inputs();
    let d = dir.path();
    let out = d.join("out.csv");
    std::fs::write(&out, "old output\n").unwrap();
    // SIGKILL cannot be caught: its temporary stays until the next run that writes a file.
    let args = long_compensation(d, &out);
    let (_, signal, _) = interrupt(&args, &out, libc::SIGKILL);
    assert_eq!(signal, Some(libc::SIGKILL));
    assert_eq!(temporaries(d).len(), 1);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "old output\n");
    // Files named like temporaries of a process that cannot exist, which robocal did not make
    // (no record of them): a user's, never removed.
    let users = [
        ".out.csv.999999999.tmp",
        ".robocal-999999999-0000000000000001.tmp",
    ];
    for name in users {
        std::fs::write(d.join(name), "the user's").unwrap();
    }
    let o = robocal(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "5",
        "--out",
        p(&out),
    ]);
    o.assert_ok();
    // The killed run's temporary is gone (its record proved it robocal's); the user's files stay.
    assert_eq!(temporaries(d), users);
    for name in users {
        assert_eq!(std::fs::read_to_string(d.join(name)).unwrap(), "the user's");
    }
}
