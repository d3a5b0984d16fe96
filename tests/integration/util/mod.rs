//! What every test module shares: the one runner (the robocal binary run with arguments, its exit
//! status and both streams captured, and assertions that print the command and both streams when
//! they fail), a temporary directory per test, the paths of the repository's examples and of the
//! optional real data, and small readers of the files robocal writes. The data sets and results
//! several tests need are made once per test run in [`fixtures`].

pub mod bad_input;
pub mod fixtures;
pub mod library;

use serde_json::Value;
use std::collections::BTreeMap;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};

/// Simulates constraint data of `kind` (`simulate --constraint`, the Table I robot, a random
/// truth, 0.01 mm noise, then `extra`) into `dir` (with the distances file for points and
/// spheres); returns the data and distances paths.
pub fn simulate_constraints(dir: &Dir, kind: &str, extra: &[&str]) -> (PathBuf, PathBuf) {
    let data = dir.join(format!("{kind}.csv"));
    let dist = dir.join(format!("{kind}.distances.csv"));
    let mut args = vec![
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        "random",
        "--constraint",
        kind,
        "--noise-mm",
        "0.01",
        "--out",
        p(&data),
    ];
    if kind != "plane" {
        args.extend(["--distances-out", p(&dist)]);
    }
    args.extend(extra);
    ok(&args);
    (data, dist)
}

/// The nominal robot of most tests (the paper's Table I).
pub const KUKA: &str = "kuka-kr480-r3330";
/// The robot that really moves in the simulated cells (the paper's Table III).
pub const TRUTH: &str = "kuka-kr480-r3330-table3";

/// A command for the robocal binary cargo built for these tests. [`robocal`] runs it; tests that
/// need the child process itself (signals, a closed pipe) spawn it.
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
}

/// A finished run of robocal: its arguments, exit status and both streams.
pub struct Outcome {
    args: Vec<String>,
    /// How the process ended.
    pub status: ExitStatus,
    stdout: Vec<u8>,
    stderr: Vec<u8>,
}

/// Runs robocal with `args` and waits for it.
pub fn robocal<S: AsRef<OsStr>>(args: &[S]) -> Outcome {
    let o = command().args(args).output().expect("robocal runs");
    Outcome {
        args: args
            .iter()
            .map(|a| a.as_ref().to_string_lossy().into_owned())
            .collect(),
        status: o.status,
        stdout: o.stdout,
        stderr: o.stderr,
    }
}

/// Runs robocal with `args` and asserts that it succeeded ([`Outcome::assert_ok`]).
#[track_caller]
pub fn ok<S: AsRef<OsStr>>(args: &[S]) -> Outcome {
    let o = robocal(args);
    o.assert_ok();
    o
}

impl Outcome {
    /// Standard output as text.
    pub fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.stdout).into_owned()
    }

    /// Standard error as text.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.stderr).into_owned()
    }

    /// Standard output followed by standard error.
    pub fn text(&self) -> String {
        self.stdout() + &self.stderr()
    }

    /// The exit code (`None` when a signal ended the process).
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }

    /// Whether the exit code is 0.
    pub fn success(&self) -> bool {
        self.status.success()
    }

    /// The command line, how it ended and both streams: the message of a failed assertion.
    pub fn describe(&self) -> String {
        format!(
            "command: robocal {}\nstatus: {}\n--- stdout ---\n{}\n--- stderr ---\n{}",
            self.args.join(" "),
            self.status,
            self.stdout(),
            self.stderr()
        )
    }

    /// Asserts exit code 0 and no panic message.
    #[track_caller]
    pub fn assert_ok(&self) -> &Self {
        assert!(self.success(), "expected success\n{}", self.describe());
        assert!(
            !self.stderr().contains("panicked"),
            "panic reported\n{}",
            self.describe()
        );
        self
    }

    /// Asserts the exit code `code`.
    #[track_caller]
    pub fn assert_code(&self, code: i32) -> &Self {
        assert_eq!(
            self.code(),
            Some(code),
            "expected exit code {code}\n{}",
            self.describe()
        );
        self
    }
}

/// A temporary directory of one test, removed with everything in it when dropped.
pub struct Dir(tempfile::TempDir);

impl Dir {
    /// A new empty directory.
    pub fn new() -> Dir {
        Dir(tempfile::Builder::new()
            .prefix("robocal-test-")
            .tempdir()
            .expect("temporary directory"))
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        self.0.path()
    }

    /// The path of `name` in it.
    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.path().join(name)
    }

    /// Writes `contents` to `name` in it; gives the file's path.
    pub fn write(&self, name: impl AsRef<Path>, contents: impl AsRef<[u8]>) -> PathBuf {
        let f = self.join(name);
        std::fs::write(&f, contents).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        f
    }
}

impl Default for Dir {
    fn default() -> Self {
        Dir::new()
    }
}

/// A path as `&str` (every path of the tests is UTF-8).
pub fn p(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// The repository's root (the robocal package).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The path of `examples/NAME`.
pub fn example(name: &str) -> String {
    root().join("examples").join(name).display().to_string()
}

/// The real data sets of ../shared/data (see its README); `None` (and a printed reason) when the
/// folder is absent.
pub fn real_data() -> Option<PathBuf> {
    // ROBOCAL_REAL_DATA names the folder where the repository is not beside shared/ (a git
    // worktree elsewhere).
    let d = std::env::var_os("ROBOCAL_REAL_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("../shared/data"));
    if d.join("jacobi_ur5_grid.csv").is_file() {
        Some(d)
    } else {
        eprintln!(
            "skipped: real data not found at {} (optional; see README.md, section Real data)",
            d.display()
        );
        None
    }
}

/// A JSON file.
pub fn read_json(path: &Path) -> Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A CSV file as its header and rows of cells.
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

/// The index of column `name` of `header`.
pub fn col(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
}

/// A cell as a number.
pub fn num(s: &str) -> f64 {
    s.parse()
        .unwrap_or_else(|_| panic!("`{s}` is not a number"))
}

/// The names in a directory, sorted.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// What a directory entry is, for comparing a directory before and after a run.
#[derive(Debug, PartialEq)]
pub enum Entry {
    /// A regular file and its content.
    File(Vec<u8>),
    /// A symbolic link and its target.
    Link(PathBuf),
    /// A directory.
    Dir,
    /// A device, FIFO or socket (never read).
    Special,
}

/// Every entry of `dir` (hidden ones included: temporaries), without reading FIFOs or devices.
pub fn snapshot(dir: &Path) -> BTreeMap<String, Entry> {
    std::fs::read_dir(dir)
        .expect("readable dir")
        .map(|e| {
            let e = e.expect("entry");
            let t = e.file_type().expect("file type");
            let entry = if t.is_symlink() {
                Entry::Link(std::fs::read_link(e.path()).expect("readable link"))
            } else if t.is_file() {
                Entry::File(std::fs::read(e.path()).expect("readable file"))
            } else if t.is_dir() {
                Entry::Dir
            } else {
                Entry::Special
            };
            (e.file_name().to_string_lossy().into_owned(), entry)
        })
        .collect()
}
