//! Data sets and results made once per test run (on first use, by `robocal simulate` and
//! `robocal calibrate`) and shared by the tests that read them. Tests only read these files: a
//! test that changes one works on its own copy in its own [`Dir`](super::Dir).
//!
//! They live in `target/tmp/robocal-fixtures-PID/`; a run removes the folders that runs no longer
//! alive left behind (a static is never dropped, so a run cannot remove its own).

use super::bad_input::{head, json_with, with_cell};
use super::{ok, p, root, KUKA, TRUTH};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The folder of this run's fixtures (made on first use, after removing dead runs' folders).
fn fixtures_root() -> &'static Path {
    static ROOT: OnceLock<PathBuf> = OnceLock::new();
    ROOT.get_or_init(|| {
        let base = Path::new(env!("CARGO_TARGET_TMPDIR"));
        let prefix = "robocal-fixtures-";
        if let Ok(entries) = std::fs::read_dir(base) {
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                let pid = name
                    .strip_prefix(prefix)
                    .and_then(|s| s.parse::<u32>().ok());
                if pid.is_some_and(|pid| !alive(pid)) {
                    let _ = std::fs::remove_dir_all(e.path());
                }
            }
        }
        let dir = base.join(format!("{prefix}{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("fixtures folder");
        dir
    })
}

/// Whether process `pid` exists (then its fixtures stay).
#[cfg(unix)]
fn alive(pid: u32) -> bool {
    if pid == std::process::id() {
        return true;
    }
    // SAFETY: signal 0 sends nothing; it only asks whether the process exists.
    let r = unsafe { libc::kill(pid as libc::pid_t, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

#[cfg(not(unix))]
fn alive(_pid: u32) -> bool {
    true
}

/// A new folder `name` for one fixture.
fn fixture_dir(name: &str) -> PathBuf {
    let d = fixtures_root().join(name);
    std::fs::create_dir_all(&d).expect("fixture folder");
    d
}

/// A small simulated cell and good files made from it: the inputs the bad-input tests spoil
/// one way at a time.
pub struct Cell {
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

impl Cell {
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

/// The small cell (made on first use).
pub fn cell() -> &'static Cell {
    static CELL: OnceLock<Cell> = OnceLock::new();
    CELL.get_or_init(make_cell)
}

fn make_cell() -> Cell {
    let dir = fixture_dir("cell");
    let data = dir.join("cal.csv");
    ok(&[
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
    let truth = dir.join("cal.truth.json");
    let result = dir.join("result.json");
    ok(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&result),
    ]);
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
    std::fs::copy(root().join("examples/kr480-r3330.toml"), &robot_toml).expect("copy robot file");
    Cell {
        data,
        truth,
        result,
        joints,
        targets,
        robot_toml,
    }
}

/// The plausibility gate's good data: a simulated KR 480 cell (plane + 75 calibration points,
/// 30 validation points) and UR5 data.
pub struct GateData {
    /// The KR 480's plane and calibration points.
    pub cell: PathBuf,
    /// Its validation points.
    pub validation: PathBuf,
    /// 80 points of a simulated UR5.
    pub ur5: PathBuf,
}

/// The gate's data (made on first use).
pub fn gate_data() -> &'static GateData {
    static DATA: OnceLock<GateData> = OnceLock::new();
    DATA.get_or_init(|| {
        let dir = fixture_dir("gate");
        let cell = dir.join("cell.csv");
        let validation = dir.join("validation.csv");
        ok(&[
            "simulate",
            "--robot",
            KUKA,
            "--truth",
            "random",
            "--poses",
            "75",
            "--validation",
            "30",
            "--seed",
            "3",
            "--out",
            p(&cell),
            "--validation-out",
            p(&validation),
        ]);
        let ur5 = dir.join("ur5.csv");
        ok(&[
            "simulate",
            "--robot",
            &super::example("ur5.toml"),
            "--truth",
            "random",
            "--poses",
            "80",
            "--seed",
            "4",
            "--tracker",
            "1500,-1000,300,125,0,0",
            "--out",
            p(&ur5),
        ]);
        GateData {
            cell,
            validation,
            ur5,
        }
    })
}

/// A joint file of 200,000 poses (with positions, no plane points): input of a compensation
/// long enough to be interrupted while its temporary file is open.
pub fn many_poses() -> &'static Path {
    static MANY: OnceLock<PathBuf> = OnceLock::new();
    MANY.get_or_init(|| {
        let dir = fixture_dir("many");
        let joints = dir.join("many.csv");
        ok(&[
            "simulate",
            "--robot",
            KUKA,
            "--truth",
            TRUTH,
            "--poses",
            "200000",
            "--no-plane",
            "--out",
            p(&joints),
        ]);
        std::fs::remove_file(dir.join("many.truth.json")).unwrap();
        joints
    })
}

/// `robocal calibrate` on a real data set: its grid calibrated, its random poses validated.
pub struct RealFit {
    /// What calibrate printed.
    pub stdout: String,
    /// The result JSON.
    pub result: Value,
}

/// The calibration of the real data set of `robot` ("ur5" or "wam", with `examples/ROBOT.toml`)
/// in the folder `data` ([`super::real_data`]), made on first use.
pub fn real_fit(data: &Path, robot: &str) -> &'static RealFit {
    static UR5: OnceLock<RealFit> = OnceLock::new();
    static WAM: OnceLock<RealFit> = OnceLock::new();
    let fit = match robot {
        "ur5" => &UR5,
        "wam" => &WAM,
        _ => panic!("no real data set of {robot}"),
    };
    fit.get_or_init(|| {
        let out = fixture_dir("real").join(format!("{robot}.json"));
        let o = ok(&[
            "calibrate",
            "--robot",
            &super::example(&format!("{robot}.toml")),
            "--data",
            p(&data.join(format!("jacobi_{robot}_grid.csv"))),
            "--validate",
            p(&data.join(format!("jacobi_{robot}_random.csv"))),
            "--out",
            p(&out),
        ]);
        RealFit {
            stdout: o.stdout(),
            result: super::read_json(&out),
        }
    })
}

/// The KR 480 robot file with three reflectors (target 1 is the paper's T0).
pub fn three_reflectors(dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/kr480-r3330.toml"),
    )
    .unwrap();
    let line = text.lines().find(|l| l.starts_with("tool = [")).unwrap();
    let inner = &line[line.find('[').unwrap() + 1..line.find(']').unwrap()];
    let v: Vec<f64> = inner
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let mut t2 = v.clone();
    t2[0] += 180.0;
    let mut t3 = v.clone();
    t3[1] += 160.0;
    let list = |v: &[f64]| {
        format!(
            "[{}]",
            v.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    let tools = format!("tools = [{}, {}, {}]", list(&v), list(&t2), list(&t3));
    let out = text.replacen(line, &format!("{line}\n{tools}"), 1);
    let path = dir.join("kr3.toml");
    std::fs::write(&path, out).unwrap();
    path
}
