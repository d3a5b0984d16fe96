//! Fixtures and helpers of the bad-input tests (`tests/cli_bad_input*.rs`): one small simulated
//! cell per test binary (made with `robocal simulate` and `robocal calibrate`), and a runner that
//! checks a failed command's exit code, message and that it wrote nothing.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The nominal robot of the fixtures.
pub const KUKA: &str = "kuka-kr480-r3330";
/// The true robot of the simulated cell.
pub const TRUTH: &str = "kuka-kr480-r3330-table3";

/// Runs robocal with `args`.
pub fn robocal<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .expect("robocal runs")
}

/// Standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A path as `&str`.
pub fn p(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// Good input files, made once per test binary.
pub struct Fixture {
    /// The directory holding them (kept for the life of the test binary).
    pub dir: PathBuf,
    /// Measurement CSV: 3 plane points and 30 calibration points of the simulated cell, with
    /// `id` and `set` columns.
    pub data: PathBuf,
    /// Its truth file.
    pub truth: PathBuf,
    /// The result of `robocal calibrate` on `data`.
    pub result: PathBuf,
    /// A joint file (`q1..q6`, degrees): 5 poses of `data`.
    pub joints: PathBuf,
    /// A target file (`x,y,z`, mm, base frame): the nominal tool points of `joints`.
    pub targets: PathBuf,
    /// A copy of `examples/kr480-r3330.toml` (the preset as a file).
    pub robot_toml: PathBuf,
}

impl Fixture {
    /// The text of a good file.
    pub fn text(&self, path: &Path) -> String {
        std::fs::read_to_string(path).expect("fixture readable")
    }

    /// `data` with the cell of `column` on 1-based `line` replaced by `value`.
    pub fn data_with_cell(&self, line: usize, column: &str, value: &str) -> String {
        with_cell(&self.text(&self.data), line, column, value)
    }

    /// `data` cut to its first `lines` lines (header included).
    pub fn data_head(&self, lines: usize) -> String {
        head(&self.text(&self.data), lines)
    }

    /// The result JSON, changed by `edit`.
    pub fn result_with(&self, edit: impl Fn(&mut serde_json::Value)) -> String {
        json_with(&self.text(&self.result), edit)
    }

    /// The truth JSON, changed by `edit`.
    pub fn truth_with(&self, edit: impl Fn(&mut serde_json::Value)) -> String {
        json_with(&self.text(&self.truth), edit)
    }
}

/// `text` (CSV with a header) with the cell of `column` on 1-based `line` replaced.
pub fn with_cell(text: &str, line: usize, column: &str, value: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let k = lines[0]
        .split(',')
        .position(|c| c == column)
        .unwrap_or_else(|| panic!("no column {column}"));
    let mut cells: Vec<String> = lines[line - 1].split(',').map(str::to_owned).collect();
    cells[k] = value.to_owned();
    lines[line - 1] = cells.join(",");
    lines.join("\n") + "\n"
}

/// The first `n` lines of `text`.
pub fn head(text: &str, n: usize) -> String {
    text.lines().take(n).map(|l| format!("{l}\n")).collect()
}

/// Pretty JSON of `text` changed by `edit`.
pub fn json_with(text: &str, edit: impl Fn(&mut serde_json::Value)) -> String {
    let mut v: serde_json::Value = serde_json::from_str(text).expect("fixture JSON");
    edit(&mut v);
    serde_json::to_string_pretty(&v).expect("JSON")
}

/// CRLF line endings and a UTF-8 byte-order mark.
pub fn crlf_bom(text: &str) -> String {
    format!("\u{feff}{}", text.replace('\n', "\r\n"))
}

static FIXTURE: OnceLock<Fixture> = OnceLock::new();

/// The fixture of this test binary (made on first use).
pub fn fixture() -> &'static Fixture {
    FIXTURE.get_or_init(make_fixture)
}

fn make_fixture() -> Fixture {
    let dir = tempfile::Builder::new()
        .prefix("robocal-bad-input-")
        .tempdir()
        .expect("temp dir")
        .keep();
    let data = dir.join("cal.csv");
    let o = robocal(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "30",
        "--seed",
        "11",
        "--out",
        p(&data),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let truth = dir.join("cal.truth.json");
    let result = dir.join("result.json");
    let o = robocal(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&result),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&data).expect("data");
    let nominal = robocal_core::preset(KUKA).expect("preset");
    let mut joints_csv = String::from("q1,q2,q3,q4,q5,q6\n");
    let mut targets_csv = String::from("x,y,z,id\n");
    for (k, line) in text.lines().skip(4).take(5).enumerate() {
        let q: Vec<&str> = line.split(',').take(6).collect();
        joints_csv.push_str(&q.join(","));
        joints_csv.push('\n');
        let qr: Vec<f64> = q
            .iter()
            .map(|v| v.parse::<f64>().expect("number").to_radians())
            .collect();
        let t = nominal.tool_position(&qr);
        targets_csv.push_str(&format!("{:.6},{:.6},{:.6},t{k}\n", t.x, t.y, t.z));
    }
    let joints = dir.join("joints.csv");
    std::fs::write(&joints, joints_csv).expect("write");
    let targets = dir.join("targets.csv");
    std::fs::write(&targets, targets_csv).expect("write");
    let robot_toml = dir.join("kr480.toml");
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/kr480-r3330.toml"),
        &robot_toml,
    )
    .expect("copy robot file");
    Fixture {
        dir,
        data,
        truth,
        result,
        joints,
        targets,
        robot_toml,
    }
}

/// Every file of a directory with its content.
pub fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .expect("readable dir")
        .map(|e| {
            let e = e.expect("entry");
            let content = if e.path().is_dir() {
                b"<dir>".to_vec()
            } else {
                std::fs::read(e.path()).expect("readable file")
            };
            (e.file_name().to_string_lossy().into_owned(), content)
        })
        .collect()
}

/// Outputs that exist before every failing run (an earlier run's results): a failed run must
/// leave them as they are and add nothing.
pub const OLD_OUTPUTS: [&str; 4] = ["out.json", "out.csv", "out.truth.json", "per_point.csv"];

/// Runs `args` in `dir` (which holds the bad input and [`OLD_OUTPUTS`]) and checks that it fails
/// with `code`, that stderr has every string of `wants`, that nothing panicked, and that the
/// directory is exactly as before. Returns stderr.
pub fn expect_failure(label: &str, dir: &Path, args: &[String], code: i32, wants: &[String]) {
    for name in OLD_OUTPUTS {
        let f = dir.join(name);
        if !f.exists() {
            std::fs::write(&f, format!("old {name}\n")).expect("write old output");
        }
    }
    let before = snapshot(dir);
    let o = robocal(args);
    let err = stderr(&o);
    assert_eq!(
        o.status.code(),
        Some(code),
        "{label}: exit code; args {args:?}\nstderr: {err}\nstdout: {}",
        stdout(&o)
    );
    assert!(!err.contains("panicked"), "{label}: panic: {err}");
    assert!(err.contains("error: "), "{label}: no error line: {err}");
    for w in wants {
        assert!(
            err.contains(w.as_str()),
            "{label}: stderr lacks `{w}`; args {args:?}\nstderr: {err}"
        );
    }
    let after = snapshot(dir);
    assert_eq!(
        before.keys().collect::<Vec<_>>(),
        after.keys().collect::<Vec<_>>(),
        "{label}: files added or removed"
    );
    for (name, content) in &before {
        assert!(
            after[name] == *content,
            "{label}: {name} changed by a failed run"
        );
    }
}

/// A command line from a template: the words `F` (the bad file), `KUKA`, `TRUTH`, `DATA`,
/// `RESULT`, `JOINTS` (the fixture's good files) and `OUT.json`, `OUT.csv`, `PP.csv`, `REPORT`
/// (outputs in the case directory `d`) are replaced; other words are kept.
pub fn expand(template: &str, f: &str, d: &Path, fx: &Fixture) -> Vec<String> {
    let out = |name: &str| p(&d.join(name)).to_owned();
    template
        .split(' ')
        .map(|w| match w {
            "F" => f.to_owned(),
            "KUKA" => KUKA.to_owned(),
            "TRUTH" => TRUTH.to_owned(),
            "DATA" => p(&fx.data).to_owned(),
            "RESULT" => p(&fx.result).to_owned(),
            "JOINTS" => p(&fx.joints).to_owned(),
            "OUT.json" => out("out.json"),
            "OUT.csv" => out("out.csv"),
            "PP.csv" => out("per_point.csv"),
            "REPORT" => out("report"),
            w => w.to_owned(),
        })
        .collect()
}
