//! Bad input across every command and input type: each case is one bad file, the commands that
//! read it, the exit code (README "Errors and exit codes") and what the message must say (file,
//! line, field). Every failing run must leave its directory as it was: earlier outputs unchanged,
//! no new or temporary files.

use crate::util::bad_input::*;
use crate::util::fixtures::{cell, Cell};
use crate::util::{p, Dir};
use serde_json::{json, Value};
use std::path::Path;

/// How a command reads the bad file `F` (the good files come from the fixture; outputs go to the
/// case directory `D`).
#[derive(Clone, Copy, Debug)]
enum Run {
    /// `calibrate --data F`
    Cal,
    /// `calibrate --validate F`
    CalVal,
    /// `evaluate --data F --per-point D/per_point.csv`
    Eval,
    /// `evaluate --data F --against desired`
    EvalDesired,
    /// `compensate --joints F`
    CompJ,
    /// `compensate --targets F`
    CompT,
    /// `simulate --joints F`
    SimJ,
    /// `robot show F`
    Show,
    /// `fk --robot F`
    FkRobot,
    /// `calibrate --robot F`
    CalRobot,
    /// `simulate --robot F`
    SimRobot,
    /// `fk --params F`
    FkParams,
    /// `robot show KUKA --params F`
    ShowParams,
    /// `evaluate --params F`
    EvalParams,
    /// `compensate --params F`
    CompParams,
    /// `simulate --truth F`
    SimTruth,
}

use Run::*;

const EVERY: [Run; 16] = [
    Cal,
    CalVal,
    Eval,
    EvalDesired,
    CompJ,
    CompT,
    SimJ,
    Show,
    FkRobot,
    CalRobot,
    SimRobot,
    FkParams,
    ShowParams,
    EvalParams,
    CompParams,
    SimTruth,
];

/// The command line of `run` with the bad file `f`: a template whose words `F` (the bad file),
/// `DATA`, `RESULT`, `JOINTS` (the fixture's good files), `OUT.json`, `OUT.csv` and `PP.csv`
/// (outputs in the case directory `d`) are replaced.
fn args(run: Run, f: &str, d: &Path, fx: &Cell) -> Vec<String> {
    let template = match run {
        Cal => "calibrate --robot KUKA --data F --out OUT.json",
        CalVal => "calibrate --robot KUKA --data DATA --validate F --out OUT.json",
        Eval => "evaluate --robot KUKA --params RESULT --data F --per-point PP.csv",
        EvalDesired => "evaluate --robot KUKA --params RESULT --data F --against desired",
        CompJ => "compensate --robot KUKA --params RESULT --joints F --out OUT.csv",
        CompT => "compensate --robot KUKA --params RESULT --targets F --out OUT.csv",
        SimJ => "simulate --robot KUKA --truth TRUTH --joints F --out OUT.csv",
        Show => "robot show F",
        FkRobot => "fk --robot F --joints 0,-90,90,0,45,0",
        CalRobot => "calibrate --robot F --data DATA --out OUT.json",
        SimRobot => "simulate --robot F --truth TRUTH --poses 5 --out OUT.csv",
        FkParams => "fk --robot KUKA --params F --joints 0,-90,90,0,45,0",
        ShowParams => "robot show KUKA --params F",
        EvalParams => "evaluate --robot KUKA --params F --data DATA --per-point PP.csv",
        CompParams => "compensate --robot KUKA --params F --joints JOINTS --out OUT.csv",
        SimTruth => "simulate --robot KUKA --truth F --poses 5 --out OUT.csv",
    };
    expand(template, f, d, fx)
}

/// One bad input file.
struct Case {
    /// Its name (the extension matters for `--robot` and `--truth`).
    file: &'static str,
    /// Its content.
    make: fn(&Cell) -> Vec<u8>,
    /// The commands that read it.
    runs: &'static [Run],
    /// The exit code.
    code: i32,
    /// What stderr must contain; `{F}` is the file's path.
    wants: &'static [&'static str],
}

const MEASURED: &[Run] = &[Cal, CalVal, Eval];
const JOINT_FILES: &[Run] = &[Cal, CalVal, Eval, CompJ, SimJ];
const ROBOT_FILE: &[Run] = &[Show, FkRobot, CalRobot, SimRobot];
const RESULT: &[Run] = &[FkParams, ShowParams, EvalParams, CompParams];

fn b(s: impl Into<String>) -> Vec<u8> {
    s.into().into_bytes()
}

fn set(v: &mut Value, path: &[&str], x: Value) {
    let mut t = v;
    for k in &path[..path.len() - 1] {
        t = &mut t[*k];
    }
    t[path[path.len() - 1]] = x;
}

fn remove(v: &mut Value, path: &[&str]) {
    let mut t = v;
    for k in &path[..path.len() - 1] {
        t = &mut t[*k];
    }
    t.as_object_mut()
        .expect("object")
        .remove(path[path.len() - 1]);
}

const ROBOT_TOML: &str = "convention = \"mdh\"\n[[joints]]\nalpha = 0\nd = 100\na = 0\n\
                          [[joints]]\nalpha = 90\nd = 0\na = 300\nlimits = [-90, 90]\n";

#[rustfmt::skip]
const CASES: &[Case] = &[
    // ---- measurement CSV (calibrate --data, evaluate --data); joint files share the reader ----
    Case { file: "empty.csv", make: |_| b(""), runs: &[Cal, Eval, CompJ, CompT, SimJ], code: 3,
           wants: &["{F}:1: empty file: expected a header row"] },
    Case { file: "header-only.csv", make: |f| b(f.data_head(1)), runs: JOINT_FILES, code: 3,
           wants: &["{F}: no data rows after the header"] },
    Case { file: "blank-lines.csv", make: |f| b(f.data_head(1) + "\n\n,,,,,,,,,,\n"), runs: JOINT_FILES, code: 3,
           wants: &["{F}: no data rows after the header"] },
    Case { file: "no-z.csv", make: |_| b("q1,q2,q3,q4,q5,q6,x,y\n0,0,0,0,0,0,1,2\n"), runs: MEASURED, code: 3,
           wants: &["{F}:1: field `z`: missing column"] },
    Case { file: "no-q6.csv", make: |_| b("q1,q2,q3,q4,q5,x,y,z\n0,0,0,0,0,1,2,3\n"), runs: JOINT_FILES, code: 3,
           wants: &["{F}:1: field `q6`: missing column", "6 joints"] },
    Case { file: "q7.csv", make: |_| b("q1,q2,q3,q4,q5,q6,q7,x,y,z\n0,0,0,0,0,0,0,1,2,3\n"), runs: JOINT_FILES, code: 3,
           wants: &["{F}:1: field `q7`", "the robot has 6 joints"] },
    Case { file: "q0.csv", make: |_| b("q0,q1,q2,q3,q4,q5,q6,x,y,z\n0,0,0,0,0,0,0,1,2,3\n"), runs: MEASURED, code: 3,
           wants: &["{F}:1: field `q0`"] },
    Case { file: "twice.csv", make: |_| b("q1,q2,q3,q4,q5,q6,x,y,z,x\n0,0,0,0,0,0,1,2,3,4\n"), runs: MEASURED, code: 3,
           wants: &["{F}:1: field `x`: column appears twice"] },
    Case { file: "unnamed.csv", make: |_| b("q1,q2,q3,q4,q5,q6,x,y,z,\n0,0,0,0,0,0,1,2,3,4\n"), runs: MEASURED, code: 3,
           wants: &["{F}:1: column 10 has an empty name"] },
    Case { file: "short-row.csv", make: |f| b(f.data_head(3) + "1,2,3\n"), runs: JOINT_FILES, code: 3,
           wants: &["{F}:4: 3 fields, but the header has 11"] },
    Case { file: "long-row.csv", make: |f| { let t = f.data_head(3); let last = t.lines().last().unwrap().to_owned(); b(t + &last + ",extra\n") },
           runs: JOINT_FILES, code: 3, wants: &["{F}:4: 12 fields, but the header has 11"] },
    Case { file: "text-cell.csv", make: |f| b(f.data_with_cell(3, "x", "12.5mm")), runs: MEASURED, code: 3,
           wants: &["{F}:3: field `x`: `12.5mm` is not a number"] },
    Case { file: "comma-decimal.csv", make: |f| b(f.data_with_cell(5, "q2", "\"12,5\"")), runs: JOINT_FILES, code: 3,
           wants: &["{F}:5: field `q2`: `12,5` is not a number"] },
    Case { file: "nan.csv", make: |f| b(f.data_with_cell(4, "y", "NaN")), runs: MEASURED, code: 3,
           wants: &["{F}:4: field `y`: `NaN` is not a finite number"] },
    Case { file: "inf-joint.csv", make: |f| b(f.data_with_cell(6, "q4", "-inf")), runs: JOINT_FILES, code: 3,
           wants: &["{F}:6: field `q4`: `-inf` is not a finite number"] },
    Case { file: "overflow.csv", make: |f| b(f.data_with_cell(6, "q1", "1e999")), runs: JOINT_FILES, code: 3,
           wants: &["{F}:6: field `q1`: `1e999` is not a finite number"] },
    Case { file: "empty-cell.csv", make: |f| b(f.data_with_cell(7, "z", "")), runs: MEASURED, code: 3,
           wants: &["{F}:7: field `z`: empty cell"] },
    Case { file: "latin1.csv", make: |f| { let mut v = b(f.data_head(3)); v.extend_from_slice(b"0,0,0,0,0,0,1,2,3,caf\xe9,calibration\n"); v },
           runs: JOINT_FILES, code: 3, wants: &["{F}:4: not valid UTF-8 text"] },
    Case { file: "quote.csv", make: |f| b(f.data_head(3) + "1,2,3,4,5,6,7,8,9,\"P9,calibration\n"), runs: MEASURED, code: 3,
           wants: &["{F}:4:", "fields, but the header has 11"] },
    Case { file: "dup-row.csv", make: |f| { let t = f.data_head(20); let l = t.lines().nth(9).unwrap().to_owned(); b(t + &l + "\n") },
           runs: &[Cal], code: 3, wants: &["{F}:21", "duplicated pose", "line 10"] },
    Case { file: "absurd.csv", make: |f| b(f.data_with_cell(9, "x", "1e30")), runs: &[Cal], code: 3,
           wants: &["{F}:9", "not a plausible tracker reading"] },
    Case { file: "two-plane.csv", make: |f| { let t = f.text(&f.data); let mut l: Vec<&str> = t.lines().collect(); l.remove(3); b(l.join("\n") + "\n") },
           runs: &[Cal], code: 3, wants: &["plane points", "2 row(s) with set = plane"] },
    Case { file: "few.csv", make: |f| b(f.data_head(16)), runs: &[Cal], code: 5,
           wants: &["12 calibration points for 26 identifiable parameters"] },
    Case { file: "commanded.csv", make: |f| b(format!("status,{}", f.text(&f.joints).replace('\n', "\nconverged,").trim_end_matches("converged,"))),
           runs: &[CompJ], code: 3, wants: &["{F}:1: field `status`", "output of compensate has a column of this name"] },
    Case { file: "no-desired.csv", make: |f| b(f.text(&f.data)), runs: &[EvalDesired], code: 3,
           wants: &["{F}:1: field `x_desired`: missing column: comparing with desired positions needs x_desired,y_desired,z_desired"] },
    Case { file: "half-desired.csv", make: |f| b(f.text(&f.data).replacen(",id,set", ",x_desired,set", 1)), runs: &[EvalDesired], code: 3,
           wants: &["{F}:1: field `y_desired`: missing column"] },
    Case { file: "text-desired.csv", make: |_| b("q1,q2,q3,q4,q5,q6,x,y,z,x_desired,y_desired,z_desired\n0,0,0,0,0,0,1,2,3,P1,2,3\n"), runs: &[EvalDesired], code: 3,
           wants: &["{F}:2: field `x_desired`: `P1` is not a finite number"] },
    // ---- targets CSV (compensate --targets) ----
    Case { file: "t-no-z.csv", make: |_| b("x,y\n1,2\n"), runs: &[CompT], code: 3,
           wants: &["{F}:1: field `z`: missing column (targets need x,y,z"] },
    Case { file: "t-header.csv", make: |_| b("x,y,z,id\n"), runs: &[CompT], code: 3,
           wants: &["{F}: no data rows after the header"] },
    Case { file: "t-some-q.csv", make: |_| b("x,y,z,q1,q2\n1,2,3,4,5\n"), runs: &[CompT], code: 3,
           wants: &["{F}:1: field `q3`: missing column: a start configuration needs all of q1..q6"] },
    Case { file: "t-q9.csv", make: |_| b("x,y,z,q9\n1,2,3,4\n"), runs: &[CompT], code: 3,
           wants: &["{F}:1: field `q9`", "6 joints"] },
    Case { file: "t-inf.csv", make: |f| b(with_cell(&f.text(&f.targets), 3, "y", "inf")), runs: &[CompT], code: 3,
           wants: &["{F}:3: field `y`: `inf` is not a finite number"] },
    Case { file: "t-text.csv", make: |f| b(with_cell(&f.text(&f.targets), 4, "z", "1.2.3")), runs: &[CompT], code: 3,
           wants: &["{F}:4: field `z`: `1.2.3` is not a number"] },
    Case { file: "t-short.csv", make: |f| b(f.text(&f.targets) + "1,2\n"), runs: &[CompT], code: 3,
           wants: &["{F}:7: 2 fields, but the header has 4"] },
    // ---- robot TOML (--robot FILE) ----
    Case { file: "empty.toml", make: |_| b(""), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:1: missing field `convention`"] },
    Case { file: "syntax.toml", make: |_| b("convention = \"mdh\"\n[[joints]\nalpha = 0\n"), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:2:", "invalid table header"] },
    Case { file: "unknown-key.toml", make: |_| b(ROBOT_TOML.replace("a = 300", "a = 300\nlenght = 2")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:", "unknown field `lenght`"] },
    Case { file: "wrong-type.toml", make: |_| b(ROBOT_TOML.replace("d = 100", "d = \"100 mm\"")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:4: field `d`: invalid type: string"] },
    Case { file: "missing-a.toml", make: |_| b(ROBOT_TOML.replacen("\na = 0\n", "\n", 1)), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:", "missing field `a`"] },
    Case { file: "nan.toml", make: |_| b(ROBOT_TOML.replace("a = 300", "a = nan")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:9: field `joints[2].a`: NaN is not a finite number"] },
    Case { file: "inf-limit.toml", make: |_| b(ROBOT_TOML.replace("[-90, 90]", "[-inf, 90]")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:10: field `joints[2].limits`: -inf is not a finite number"] },
    Case { file: "limits-order.toml", make: |_| b(ROBOT_TOML.replace("[-90, 90]", "[90, -90]")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:10: field `joints[2].limits`: min 90 deg is greater than max -90 deg"] },
    Case { file: "limits-3.toml", make: |_| b(ROBOT_TOML.replace("[-90, 90]", "[-90, 0, 90]")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:10: field `joints[2].limits`: expected [min, max] in degrees, got 3 numbers"] },
    Case { file: "no-joints.toml", make: |_| b("convention = \"mdh\"\njoints = []\n"), runs: ROBOT_FILE, code: 3,
           wants: &["{F}: field `joints`: no [[joints]] table"] },
    Case { file: "convention.toml", make: |_| b(ROBOT_TOML.replace("\"mdh\"", "\"craig\"")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:1: field `convention`: `craig` is not a convention"] },
    Case { file: "base-3.toml", make: |_| b(format!("base = [0, 0, 1]\n{ROBOT_TOML}")), runs: ROBOT_FILE, code: 3,
           wants: &["{F}:1: field `base`: expected 6 numbers"] },
    Case { file: "latin1.toml", make: |_| { let mut v = b("name = \"caf"); v.push(0xe9); v.extend_from_slice(format!("\"\n{ROBOT_TOML}").as_bytes()); v },
           runs: ROBOT_FILE, code: 3, wants: &["{F}:1: not valid UTF-8 text"] },
    // ---- result JSON (--params) ----
    Case { file: "empty.json", make: |_| b(""), runs: RESULT, code: 3,
           wants: &["{F}:1: not a robocal result: EOF while parsing"] },
    Case { file: "array.json", make: |_| b("[1, 2]\n"), runs: RESULT, code: 3,
           wants: &["{F}:1: not a robocal result: invalid type: sequence"] },
    Case { file: "truncated.json", make: |f| b(f.text(&f.result)[..2000].to_owned()), runs: RESULT, code: 3,
           wants: &["{F}:", "not a robocal result: EOF while parsing"] },
    Case { file: "text-value.json", make: |f| b(f.result_with(|v| set(v, &["parameters", "a2", "calibrated"], json!("500.1")))), runs: RESULT, code: 3,
           wants: &["{F}:", "field `parameters.a2.calibrated`", "invalid type: string \"500.1\", expected f64"] },
    Case { file: "huge-number.json", make: |f| b(f.text(&f.result).replacen("\"calibrated\": ", "\"calibrated\": 1e999, \"x\": ", 1)), runs: RESULT, code: 3,
           wants: &["{F}:", "number out of range"] },
    Case { file: "nan-literal.json", make: |f| b(f.text(&f.result).replacen("\"x\": ", "\"x\": NaN, \"x0\": ", 1)), runs: RESULT, code: 3,
           wants: &["{F}:", "not a robocal result: expected value"] },
    Case { file: "no-a3.json", make: |f| b(f.result_with(|v| remove(v, &["parameters", "a3"]))), runs: RESULT, code: 3,
           wants: &["{F}: field `parameters`: parameter `a3` is missing"] },
    Case { file: "no-frame.json", make: |f| b(f.result_with(|v| remove(v, &["tracker_frame"]))), runs: RESULT, code: 3,
           wants: &["{F}:", "missing field `tracker_frame`"] },
    Case { file: "unit.json", make: |f| b(f.result_with(|v| set(v, &["parameters", "d4", "unit"], json!("deg")))), runs: RESULT, code: 3,
           wants: &["{F}: field `parameters.d4.unit`: expected mm"] },
    Case { file: "bad-unit.json", make: |f| b(f.result_with(|v| set(v, &["parameters", "d4", "unit"], json!("inch")))), runs: RESULT, code: 3,
           wants: &["{F}:", "field `parameters.d4.unit`", "unknown variant `inch`"] },
    Case { file: "a9.json", make: |f| b(f.result_with(|v| { let e = v["parameters"]["a3"].clone(); set(v, &["parameters", "a9"], e) })), runs: RESULT, code: 3,
           wants: &["{F}: field `parameters.a9`: not a parameter of robot `kuka-kr480-r3330`"] },
    Case { file: "dof.json", make: |f| b(f.result_with(|v| set(v, &["robot", "dof"], json!(7)))), runs: RESULT, code: 3,
           wants: &["{F}: field `robot.dof`: result is for a 7-joint robot"] },
    Case { file: "dh.json", make: |f| b(f.result_with(|v| set(v, &["robot", "convention"], json!("dh")))), runs: RESULT, code: 3,
           wants: &["{F}: field `robot.convention`: result uses dh parameters, the robot given uses mdh"] },
    Case { file: "other-robot.json", make: |f| b(f.result_with(|v| set(v, &["parameters", "a2", "nominal"], json!(510.0)))), runs: RESULT, code: 3,
           wants: &["{F}: field `parameters.a2.nominal`: the result was made for a robot with nominal a2 = 510 mm"] },
    Case { file: "partial.json", make: |f| b(f.result_with(|v| { set(v, &["status"], json!("partial")); set(v, &["solver", "converged"], json!(false)) })),
           runs: &[CompParams], code: 3, wants: &["--params {F}: a partial result, not a calibration"] },
    // ---- truth JSON (simulate --truth FILE.json) ----
    Case { file: "empty.truth.json", make: |_| b(""), runs: &[SimTruth], code: 3,
           wants: &["{F}:1: not a robocal truth file: EOF while parsing"] },
    Case { file: "result-as.truth.json", make: |f| b(f.text(&f.result)), runs: &[SimTruth], code: 3,
           wants: &["{F}:", "not a robocal truth file: missing field"] },
    Case { file: "no-a3.truth.json", make: |f| b(f.truth_with(|v| remove(v, &["parameters", "a3"]))), runs: &[SimTruth], code: 3,
           wants: &["{F}: field `parameters`: parameter `a3` is missing"] },
    Case { file: "dof.truth.json", make: |f| b(f.truth_with(|v| set(v, &["robot", "dof"], json!(7)))), runs: &[SimTruth], code: 3,
           wants: &["{F}: field `robot.dof`: truth robot `kuka-kr480-r3330-table3` has 7 joints"] },
    Case { file: "dh.truth.json", make: |f| b(f.truth_with(|v| set(v, &["robot", "convention"], json!("dh")))), runs: &[SimTruth], code: 3,
           wants: &["{F}: field `robot.convention`"] },
    Case { file: "other.truth.json", make: |f| b(f.truth_with(|v| set(v, &["parameters", "d4", "nominal"], json!(1500.0)))), runs: &[SimTruth], code: 3,
           wants: &["{F}: field `parameters.d4.nominal`", "wrong --robot or wrong truth file"] },
    Case { file: "text.truth.json", make: |f| b(f.truth_with(|v| set(v, &["tracker_frame", "x"], json!("far")))), runs: &[SimTruth], code: 3,
           wants: &["{F}:", "field `tracker_frame.x`", "invalid type: string \"far\""] },
];

fn case_dir(root: &Path, k: usize, run: Run) -> std::path::PathBuf {
    let d = root.join(format!("case{k:03}-{run:?}"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn every_bad_input_fails_with_its_message_and_code_and_writes_nothing() {
    let fx = cell();
    let root = Dir::new();
    let mut runs = 0;
    for (k, c) in CASES.iter().enumerate() {
        for &run in c.runs {
            let d = case_dir(root.path(), k, run);
            let f = d.join(c.file);
            std::fs::write(&f, (c.make)(fx)).unwrap();
            let wants: Vec<String> = c.wants.iter().map(|w| w.replace("{F}", p(&f))).collect();
            let label = format!("{} via {run:?}", c.file);
            expect_failure(&label, &d, &args(run, p(&f), &d, fx), c.code, &wants);
            runs += 1;
        }
    }
    let files = CASES.iter().filter(|c| !c.runs.is_empty()).count();
    assert!(files >= 40, "{files} bad files");
    eprintln!("{files} bad input files, {runs} failing runs checked");
}

#[test]
fn missing_files_and_directories_fail_with_exit_code_4_for_every_reader() {
    let fx = cell();
    let root = Dir::new();
    for (k, run) in EVERY.iter().enumerate() {
        // A path that does not exist. `.toml` / `.json` so that --robot / --truth take it as a file.
        let d = case_dir(root.path(), k, *run);
        let ext = match run {
            Show | FkRobot | CalRobot | SimRobot => "toml",
            FkParams | ShowParams | EvalParams | CompParams | SimTruth => "json",
            _ => "csv",
        };
        let missing = d.join(format!("missing.{ext}"));
        let wants = vec![format!("{}: No such file or directory", p(&missing))];
        let label = format!("missing file via {run:?}");
        expect_failure(&label, &d, &args(*run, p(&missing), &d, fx), 4, &wants);
        // A directory where a file is expected.
        let dir = d.join(format!("adir.{ext}"));
        std::fs::create_dir(&dir).unwrap();
        let wants = vec![format!("{}: is a directory, expected a file", p(&dir))];
        let label = format!("directory via {run:?}");
        expect_failure(&label, &d, &args(*run, p(&dir), &d, fx), 4, &wants);
    }
}

#[test]
fn unreadable_file_fails_with_exit_code_4() {
    use std::os::unix::fs::PermissionsExt;
    let fx = cell();
    let dir = Dir::new();
    let f = dir.join("locked.csv");
    std::fs::copy(&fx.data, &f).unwrap();
    std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o000)).unwrap();
    if std::fs::read(&f).is_ok() {
        // Root (or a capability) reads through mode 000: nothing to test here. The directory
        // case of the test above covers an input that cannot be read.
        eprintln!("skipped: running as root, chmod 000 does not stop reads");
        return;
    }
    let wants = vec![format!("{}: Permission denied", p(&f))];
    for run in [Cal, Eval, CompJ, SimJ] {
        expect_failure(
            "unreadable",
            dir.path(),
            &args(run, p(&f), dir.path(), fx),
            4,
            &wants,
        );
    }
}
