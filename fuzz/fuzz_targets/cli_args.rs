//! Fuzzes the whole command line: argument vectors built from the commands, their flags, the
//! files of a small cell (robot file, measurements, truth, result, targets, joints), special
//! outputs and odd values run through `robocal::run_from`, as the binary does.
//!
//! Asserts, for every vector: no panic (libFuzzer reports it), and the trust properties of
//! issue "Trust": every input file is byte-identical afterwards and no temporary file is left.
//! Run with `-close_fd_mask=3` to keep the commands' printing out of the fuzzer's output.
#![no_main]
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use libfuzzer_sys::fuzz_target;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

const COMMANDS: &[&[&str]] = &[
    &["robot", "show"],
    &["robot", "list"],
    &["fk"],
    &["simulate"],
    &["calibrate"],
    &["evaluate"],
    &["compensate"],
    &["demo"],
    &["report"],
    &["completions"],
    &["man"],
];

const FLAGS: &[&str] = &[
    "--robot", "--data", "--validate", "--out", "--params", "--joints", "--poses", "--seed",
    "--truth", "--objective", "--robust-loss", "--robust-scale", "--fix", "--free", "--beta",
    "--affine", "--rank-tol", "--max-iterations", "--keep-partial", "--accept-implausible",
    "--nominal-limits", "--targets", "--against", "--tracker", "--noise-mm", "--noise-per-m",
    "--validation", "--validation-out", "--no-plane", "--plane-z-mm", "--floor-mm",
    "--footprint-mm", "--length-error-mm", "--angle-error-deg", "--tilt-parallel-axes",
    "--compliance", "--link-masses-kg", "--payload-kg", "--outlier-fraction", "--outlier-min-mm",
    "--outlier-max-mm", "--per-point", "--strict", "--tolerance-mm", "--json", "--paper",
    "--result", "--verify", "--help", "--meta", "--serial", "--tracker", "--reflector",
    "--operator", "--temperature-c", "--measured", "--notes", "--point-table",
];

/// Values worth trying: boundaries, absurd magnitudes, non-numbers, joint lists and names.
const VALUES: &[&str] = &[
    "0", "1", "2", "3", "7", "12", "75", "-1", "-0", "0.5", "1e-17", "1e-15", "1e308", "-1e308",
    "nan", "inf", "4294967296", "18446744073709551615", "99999999999", "", " ", ",", "a",
    "0,0,0,0,0,0", "10,-80,90,0,90,0", "1,2", "nan,0,0,0,0,0", "1e308,0,0,0,0,0",
    "3112.8,-2179.6,1200,125,0,0", "1e308,0,0,0,0,0", "random", "none", "parallel", "2,3",
    "d1,base_z", "alpha1,d1,a1,phi1", "tool_a,tool_b,tool_c", "sum-of-norms", "least-squares",
    "robust", "cauchy", "huber", "kuka-kr480-r3330", "kuka-kr480-r3330-table3", "-", "bash",
    "zsh", "calibrate",
];

/// Paths: fixture inputs (by name, resolved in the cell directory), outputs, special files.
const PATHS: &[&str] = &[
    "robot.toml", "cal.csv", "cal.truth.json", "val.csv", "result.json", "targets.csv",
    "joints.csv", "out.csv", "out.json", "outdir", "link-to-result.json", "null-link",
    "/dev/null", "missing/x.csv", ".",
];

/// The files that must never change.
const INPUTS: &[&str] = &[
    "robot.toml", "cal.csv", "cal.truth.json", "val.csv", "result.json", "targets.csv",
    "joints.csv",
];

#[derive(Arbitrary, Debug)]
enum Tok {
    Flag(u8),
    Value(u8),
    Path(u8),
    Raw(String),
}

#[derive(Arbitrary, Debug)]
struct Input {
    command: u8,
    toks: Vec<Tok>,
}

struct Cell {
    dir: PathBuf,
    originals: Vec<(PathBuf, Vec<u8>)>,
}

fn run(args: &[&str]) -> anyhow::Result<()> {
    let mut v = vec!["robocal".to_string()];
    v.extend(args.iter().map(|s| s.to_string()));
    robocal::run_from(v)
}

/// Builds the cell once: a UR5-like robot file, a simulated data set with its truth, a result
/// of calibrating it, a targets file and a joints file.
fn cell() -> &'static Cell {
    static CELL: OnceLock<Cell> = OnceLock::new();
    CELL.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("robocal-fuzz-cli-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("cell dir");
        std::env::set_current_dir(&dir).expect("chdir");
        std::fs::write(
            "robot.toml",
            include_str!("../../examples/ur5.toml"),
        )
        .expect("robot");
        run(&[
            "simulate", "--robot", "robot.toml", "--truth", "random", "--poses", "40",
            "--validation", "20", "--seed", "3", "--tracker", "1500,-1000,300,125,0,0",
            "--out", "cal.csv", "--validation-out", "val.csv",
        ])
        .expect("simulate");
        run(&[
            "calibrate", "--robot", "robot.toml", "--data", "cal.csv", "--out", "result.json",
        ])
        .expect("calibrate");
        std::fs::write(
            "targets.csv",
            "x,y,z\n400,100,300\n-300,200,400\n1e9,0,0\n",
        )
        .expect("targets");
        std::fs::write(
            "joints.csv",
            "q1,q2,q3,q4,q5,q6\n10,-80,90,0,90,0\n0,-90,0,-90,0,0\n",
        )
        .expect("joints");
        std::os::unix::fs::symlink("result.json", "link-to-result.json").expect("link");
        std::os::unix::fs::symlink("/dev/null", "null-link").expect("null link");
        std::fs::create_dir_all("outdir").expect("outdir");
        let originals = INPUTS
            .iter()
            .map(|p| (dir.join(p), std::fs::read(p).expect("fixture")))
            .collect();
        Cell { dir, originals }
    })
}

fn temporaries(dir: &Path, out: &mut Vec<PathBuf>) {
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if name.ends_with(".tmp") {
                out.push(p.clone());
            }
            if e.file_type().map(|t| t.is_dir()).unwrap_or(false) {
                temporaries(&p, out);
            }
        }
    }
}

fuzz_target!(|input: Input| {
    let cell = cell();
    if input.toks.len() > 14 {
        return;
    }
    let mut args: Vec<String> = COMMANDS[input.command as usize % COMMANDS.len()]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for t in &input.toks {
        args.push(match t {
            Tok::Flag(i) => FLAGS[*i as usize % FLAGS.len()].to_string(),
            Tok::Value(i) => VALUES[*i as usize % VALUES.len()].to_string(),
            Tok::Path(i) => PATHS[*i as usize % PATHS.len()].to_string(),
            Tok::Raw(s) => s.chars().take(40).collect(),
        });
    }
    // Counts that make a run take seconds are refused or capped by robocal itself only above
    // its limits; skip the few mid-size values a raw token could give, to keep runs fast.
    if args.iter().any(|a| {
        a.parse::<f64>()
            .map(|v| v.abs() > 5000.0 && v.abs() < 1e7)
            .unwrap_or(false)
    }) {
        return;
    }
    let refs: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    let _ = run(&refs);
    for (p, bytes) in &cell.originals {
        let now = std::fs::read(p).unwrap_or_default();
        assert!(
            &now == bytes,
            "input {} changed by robocal {}",
            p.display(),
            args.join(" ")
        );
    }
    let mut tmps = Vec::new();
    temporaries(&cell.dir, &mut tmps);
    assert!(tmps.is_empty(), "temporary files left: {tmps:?} by robocal {}", args.join(" "));
    // Fresh outputs for the next run.
    for p in ["out.csv", "out.json", "out.truth.json"] {
        let _ = std::fs::remove_file(cell.dir.join(p));
    }
    let _ = std::fs::remove_dir_all(cell.dir.join("outdir"));
    let _ = std::fs::create_dir_all(cell.dir.join("outdir"));
});
