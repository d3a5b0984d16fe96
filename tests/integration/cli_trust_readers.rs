//! Strict readers: data never move silently. Unknown `set` labels, `--validate` naming the
//! `--data` file, JSON with text after the document or a key twice, absurd finite magnitudes,
//! result statuses robocal does not write, and joint values outside the robot's limits. Each
//! failing run must exit with its code, name the file, line and field, leave every file of its
//! directory as it was (inputs byte-identical, earlier outputs untouched, nothing new) and not
//! panic (`expect_failure`).

use crate::util::bad_input::*;
use crate::util::fixtures::{cell, Cell};
use crate::util::{ok, p, Dir, KUKA, TRUTH};
use serde_json::{json, Value};
use std::path::Path;

/// How a command reads the bad file `F`.
#[derive(Clone, Copy, Debug)]
enum Run {
    Cal,
    CalVal,
    Eval,
    EvalDesired,
    CompJ,
    CompT,
    SimJ,
    CalRobot,
    FkParams,
    ShowParams,
    EvalParams,
    CompParams,
    ReportParams,
    ReportData,
    SimTruth,
}

use Run::*;

const JOINT_FILES: &[Run] = &[Cal, CalVal, Eval, CompJ, SimJ];
const MEASURED: &[Run] = &[Cal, CalVal, Eval];
const RESULT: &[Run] = &[FkParams, ShowParams, EvalParams, CompParams, ReportParams];

/// The command line of `run` with the bad file `f`, outputs in the case directory `d`.
fn args(run: Run, f: &str, d: &Path, fx: &Cell) -> Vec<String> {
    let template = match run {
        Cal => "calibrate --robot KUKA --data F --out OUT.json",
        CalVal => "calibrate --robot KUKA --data DATA --validate F --out OUT.json",
        Eval => "evaluate --robot KUKA --params RESULT --data F --per-point PP.csv",
        EvalDesired => "evaluate --robot KUKA --params RESULT --data F --against desired",
        CompJ => "compensate --robot KUKA --params RESULT --joints F --out OUT.csv",
        CompT => "compensate --robot KUKA --params RESULT --targets F --out OUT.csv",
        SimJ => "simulate --robot KUKA --truth TRUTH --joints F --out OUT.csv",
        CalRobot => "calibrate --robot F --data DATA --out OUT.json",
        FkParams => "fk --robot KUKA --params F --joints 0,-90,90,0,45,0",
        ShowParams => "robot show KUKA --params F",
        EvalParams => "evaluate --robot KUKA --params F --data DATA --per-point PP.csv",
        CompParams => "compensate --robot KUKA --params F --joints JOINTS --out OUT.csv",
        ReportParams => "report F --robot KUKA --out REPORT",
        ReportData => "report RESULT --robot KUKA --data F --out REPORT",
        SimTruth => "simulate --robot KUKA --truth F --poses 5 --out OUT.csv",
    };
    expand(template, f, d, fx)
}

/// One bad input file: its name, content, the commands that read it, the exit code and what
/// stderr must contain (`{F}` is the file's path).
struct Case {
    file: &'static str,
    make: fn(&Cell) -> (Vec<u8>, Vec<String>),
    runs: &'static [Run],
    code: i32,
}

/// The 1-based line of the first line of `text` containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    1 + text
        .lines()
        .position(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no `{needle}`"))
}

/// `text` with `insert` put in as a line of its own before line `line` (1-based).
fn insert_line(text: &str, line: usize, insert: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(line - 1, insert);
    lines.join("\n") + "\n"
}

fn set(v: &mut Value, path: &[&str], x: Value) {
    let mut t = v;
    for k in &path[..path.len() - 1] {
        t = &mut t[*k];
    }
    t[path[path.len() - 1]] = x;
}

/// A changed JSON file, and the message naming the line of `needle` (its first line containing
/// it) and the field.
fn json_case(text: String, needle: &str, field: &str, msg: &str) -> (Vec<u8>, Vec<String>) {
    let l = line_of(&text, needle);
    (
        text.into_bytes(),
        vec![format!("{{F}}:{l}: field `{field}`: {msg}")],
    )
}

/// `data` with the q2 of `lines` moved by `by` degrees.
fn shifted_q2(fx: &Cell, lines: &[usize], by: f64) -> String {
    let mut t = fx.text(&fx.data);
    for &l in lines {
        let q2: f64 = t
            .lines()
            .nth(l - 1)
            .unwrap()
            .split(',')
            .nth(1)
            .unwrap()
            .parse()
            .unwrap();
        t = with_cell(&t, l, "q2", &format!("{}", q2 + by));
    }
    t
}

#[rustfmt::skip]
const CASES: &[Case] = &[
    // ---- set labels ----
    Case { file: "labels.csv", runs: &[Cal, CalVal, ReportData], code: 3, make: |f| {
        let t = with_cell(&f.data_with_cell(6, "set", "validaton"), 9, "set", "plain");
        (t.into_bytes(), vec!["{F}:6: field `set`: unknown set `validaton` (2 rows of this file have an unknown set): the sets are plane, calibration, validation (or val)".into()])
    } },
    // ---- JSON strictness: result ----
    Case { file: "trailing.json", runs: RESULT, code: 3, make: |f| {
        let t = f.text(&f.result);
        let n = t.lines().count();
        ((t + "x\n").into_bytes(), vec![format!("{{F}}:{}: not a robocal result: text after the end of the JSON document", n + 1)])
    } },
    Case { file: "two-results.json", runs: RESULT, code: 3, make: |f| {
        let t = f.text(&f.result);
        let n = t.lines().count();
        (format!("{t}{t}").into_bytes(), vec![format!("{{F}}:{}: not a robocal result: text after the end", n + 1)])
    } },
    Case { file: "dup-a2.json", runs: RESULT, code: 3, make: |f| {
        let t = f.text(&f.result);
        let l = line_of(&t, "\"a3\": {");
        let t = insert_line(&t, l, "    \"a2\": {\"nominal\": 500.0, \"calibrated\": 512.0, \"unit\": \"mm\", \"fixed\": false},");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `parameters.a2`: not a robocal result: the key `a2` appears twice")])
    } },
    Case { file: "dup-calibrated.json", runs: RESULT, code: 3, make: |f| {
        let t = f.text(&f.result);
        let l = line_of(&t, "\"calibrated\": ");
        let t = insert_line(&t, l + 1, "      \"calibrated\": 1.0,");
        (t.into_bytes(), vec![format!("{{F}}:{}: field `parameters.alpha1.calibrated`: not a robocal result: the key `calibrated` appears twice", l + 1)])
    } },
    Case { file: "dup-status.json", runs: RESULT, code: 3, make: |f| {
        let t = insert_line(&f.text(&f.result), 2, "  \"status\": \"calibrated\",");
        let l = 1 + t.lines().enumerate().filter(|(_, x)| x.contains("\"status\":")).nth(1).unwrap().0;
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `status`: not a robocal result: the key `status` appears twice")])
    } },
    // ---- JSON strictness: truth ----
    Case { file: "trailing.truth.json", runs: &[SimTruth], code: 3, make: |f| {
        let t = f.text(&f.truth);
        let n = t.lines().count();
        (format!("{t}{t}").into_bytes(), vec![format!("{{F}}:{}: not a robocal truth file: text after the end", n + 1)])
    } },
    Case { file: "dup-x.truth.json", runs: &[SimTruth], code: 3, make: |f| {
        let t = f.text(&f.truth);
        let l = line_of(&t, "\"tracker_frame\": {");
        let t = insert_line(&t, l + 1, "    \"x\": 0.0,");
        (t.into_bytes(), vec![format!("{{F}}:{}: field `tracker_frame.x`: not a robocal truth file: the key `x` appears twice", l + 2)])
    } },
    // ---- absurd magnitudes: result, truth ----
    Case { file: "tracker-1e308.json", runs: RESULT, code: 3, make: |f|
        json_case(f.result_with(|v| set(v, &["tracker_frame", "x"], json!(1e308))), "1e+308", "tracker_frame.x", "1e308 mm is out of range (a length must be within ±1e6 mm, 1 km)") },
    Case { file: "a2-1e300.json", runs: RESULT, code: 3, make: |f| {
        let t = f.result_with(|v| set(v, &["parameters", "a2", "calibrated"], json!(1e300)));
        let l = line_of(&t, "1e+300");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `parameters.a2.calibrated`: 1e300 mm is out of range")])
    } },
    Case { file: "alpha-deg.json", runs: RESULT, code: 3, make: |f| {
        let t = f.result_with(|v| set(v, &["parameters", "alpha2", "nominal"], json!(-9e9)));
        let l = line_of(&t, "-9000000000");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `parameters.alpha2.nominal`: -9e9 deg is out of range (an angle must be within ±3600 deg")])
    } },
    Case { file: "stats.json", runs: RESULT, code: 3, make: |f| {
        let t = f.result_with(|v| set(v, &["errors", "calibration", "after", "mean_mm"], json!(-1.5)));
        let l = line_of(&t, "-1.5");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `errors.calibration.after.mean_mm`: -1.5 mm is out of range (an error must be within 0..1e6 mm")])
    } },
    Case { file: "tracker.truth.json", runs: &[SimTruth], code: 3, make: |f| {
        let t = f.truth_with(|v| set(v, &["tracker_frame", "z"], json!(-1e308)));
        let l = line_of(&t, "-1e+308");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `tracker_frame.z`: -1e308 mm is out of range")])
    } },
    Case { file: "a2.truth.json", runs: &[SimTruth], code: 3, make: |f| {
        let t = f.truth_with(|v| set(v, &["parameters", "a2", "calibrated"], json!(1e300)));
        let l = line_of(&t, "1e+300");
        (t.into_bytes(), vec![format!("{{F}}:{l}: field `parameters.a2.calibrated`: 1e300 mm is out of range")])
    } },
    // ---- status ----
    Case { file: "bogus.json", runs: RESULT, code: 3, make: |f|
        json_case(f.result_with(|v| set(v, &["status"], json!("bogus"))), "\"bogus\"", "status", "`bogus` is not a status robocal writes (calibrated, partial, implausible)") },
    Case { file: "no-status.json", runs: RESULT, code: 3, make: |f| {
        let t = f.result_with(|v| { v.as_object_mut().unwrap().remove("status"); });
        (t.into_bytes(), vec!["{F}: field `status`: missing".into()])
    } },
    // ---- absurd magnitudes: CSV ----
    Case { file: "q2-huge.csv", runs: JOINT_FILES, code: 3, make: |f|
        (f.data_with_cell(6, "q2", "1000080").into_bytes(), vec!["{F}:6: field `q2`: not a plausible joint value: 1000080 deg is out of range (a joint value must be within ±1e5 deg".into()]) },
    Case { file: "x-huge.csv", runs: MEASURED, code: 3, make: |f|
        (f.data_with_cell(8, "x", "-2e6").into_bytes(), vec!["{F}:8: field `x`: not a plausible tracker reading: -2000000 mm is out of range".into()]) },
    Case { file: "target-huge.csv", runs: &[CompT], code: 3, make: |f|
        (with_cell(&f.text(&f.targets), 3, "z", "1e300").into_bytes(), vec!["{F}:3: field `z`: not a plausible target: 1e300 mm is out of range".into()]) },
    Case { file: "desired-huge.csv", runs: &[EvalDesired], code: 3, make: |_|
        (b"q1,q2,q3,q4,q5,q6,x,y,z,x_desired,y_desired,z_desired\n0,-90,90,0,45,0,1,2,3,1e300,2,3\n".to_vec(), vec!["{F}:2: field `x_desired`: 1e300 mm is out of range".into()]) },
    // ---- absurd magnitudes: robot TOML ----
    Case { file: "huge-a.toml", runs: &[CalRobot], code: 3, make: |f| {
        let t = f.text(&f.robot_toml);
        let l = line_of(&t, "a = 1300");
        (t.replacen("a = 1300", "a = 1e300", 1).into_bytes(), vec![format!("{{F}}:{l}: field `joints[3].a`: 1e300 mm is out of range")])
    } },
    // ---- joint limits ----
    Case { file: "limits.csv", runs: &[Cal, CalVal, Eval], code: 3, make: |f| {
        let t = shifted_q2(f, &[7, 9], 360.0);
        (t.into_bytes(), vec![
            "{F}:7: field `q2`: ".into(),
            "deg is outside the joint limits of robot `kuka-kr480-r3330` (q2: -130..20 deg); 2 rows of this file are outside the limits: line 7 (q2 = ".into(),
            "line 9 (q2 = ".into(),
            "give --nominal-limits to use these rows".into(),
        ])
    } },
];

fn case_dir(root: &Path, k: usize, run: Run) -> std::path::PathBuf {
    let d = root.join(format!("case{k:03}-{run:?}"));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn every_untrusted_input_fails_naming_file_line_and_field_and_writes_nothing() {
    let fx = cell();
    let root = Dir::new();
    let mut runs = 0;
    for (k, c) in CASES.iter().enumerate() {
        let (bytes, wants) = (c.make)(fx);
        for &run in c.runs {
            let d = case_dir(root.path(), k, run);
            let f = d.join(c.file);
            std::fs::write(&f, &bytes).unwrap();
            let wants: Vec<String> = wants.iter().map(|w| w.replace("{F}", p(&f))).collect();
            let label = format!("{} via {run:?}", c.file);
            expect_failure(&label, &d, &args(run, p(&f), &d, fx), c.code, &wants);
            assert!(!d.join("report").exists(), "{label}: report written");
            runs += 1;
        }
    }
    eprintln!(
        "{} untrusted files, {runs} failing runs checked",
        CASES.len()
    );
}

#[test]
fn validate_must_be_another_file_than_data() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let data = d.join("data.csv");
    std::fs::copy(&fx.data, &data).unwrap();
    let hard = d.join("hard-link.csv");
    std::fs::hard_link(&data, &hard).unwrap();
    let soft = d.join("soft-link.csv");
    std::os::unix::fs::symlink(&data, &soft).unwrap();
    let dotted = format!("{}/./data.csv", p(d));
    for validate in [p(&data), dotted.as_str(), p(&hard), p(&soft)] {
        let args: Vec<String> = [
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            p(&data),
            "--validate",
            validate,
            "--out",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([p(&d.join("out.json")).to_owned()])
        .collect();
        let wants = vec![format!(
            "--validate {validate}: this is the --data file {} (the same file)",
            p(&data)
        )];
        expect_failure(validate, d, &args, 2, &wants);
    }
}

#[test]
fn simulate_refuses_absurd_numbers_and_readings_no_reader_would_accept() {
    let dir = Dir::new();
    let d = dir.path();
    let cases: &[(&str, &str)] = &[
        ("--tracker 1e308,0,0,0,0,0", "--tracker: x: 1e308 mm is out of range (a length must be within ±1e6 mm, 1 km)"),
        ("--tracker 0,0,0,0,1e9,0", "--tracker: B: 1e9 deg is out of range"),
        ("--noise-mm 1e300", "--noise-mm: 1e300 mm is out of range"),
        ("--noise-per-m 5000", "--noise-per-m: 5000 mm/m is out of range"),
        ("--floor-mm -1e9", "--floor-mm: -1e9 mm is out of range"),
        ("--plane-z-mm 3e6", "--plane-z-mm: 3000000 mm is out of range"),
        ("--footprint-mm 1e300", "--footprint-mm: 1e300 mm is out of range"),
        ("--compliance 1e3 --payload-kg 10", "--compliance: value 1: 1000 rad/(N·m) is out of range"),
        ("--compliance 1e-7 --payload-kg 1e300", "--payload-kg: 1e300 kg is out of range"),
        ("--outlier-fraction 0.1 --outlier-max-mm 1e300", "--outlier-max-mm: 1e300 mm is out of range"),
        // Every setting plausible, but the tracker 1 km away puts readings beyond 1 km.
        ("--tracker 999999,0,0,0,0,0", "is out of range (a length must be within ±1e6 mm, 1 km): the tracker frame, the noise or the robot put the simulated reading beyond what a measurement file may hold"),
    ];
    let out = p(&d.join("out.csv")).to_owned();
    for (extra, want) in cases {
        let mut args: Vec<String> =
            format!("simulate --robot {KUKA} --truth {TRUTH} --poses 5 {extra} --out")
                .split(' ')
                .map(str::to_owned)
                .collect();
        args.push(out.clone());
        expect_failure(extra, d, &args, 3, &[want.to_string()]);
    }
    for (extra, want) in [
        (
            "--length-error-mm 1e300",
            "--length-error-mm: 1e300 mm is out of range",
        ),
        (
            "--angle-error-deg 1e6",
            "--angle-error-deg: 1e6 deg is out of range",
        ),
    ] {
        let mut args: Vec<String> =
            format!("simulate --robot {KUKA} --truth random --poses 5 {extra} --out")
                .split(' ')
                .map(str::to_owned)
                .collect();
        args.push(out.clone());
        expect_failure(extra, d, &args, 3, &[want.to_string()]);
    }
    // fk's joints too.
    let args: Vec<String> = format!("fk --robot {KUKA} --joints 0,1e300,0,0,0,0")
        .split(' ')
        .map(str::to_owned)
        .collect();
    expect_failure(
        "fk",
        d,
        &args,
        2,
        &["--joints: value 2: 1e300 deg is out of range".into()],
    );
}

#[test]
fn accepted_set_labels_and_statuses() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    // Any case, surrounding spaces, `val`, and an empty cell (a calibration point).
    let t = with_cell(&fx.data_with_cell(2, "set", "PLANE"), 6, "set", "");
    let t = with_cell(&with_cell(&t, 7, "set", " Val "), 8, "set", "Validation");
    let data = d.join("labels.csv");
    std::fs::write(&data, &t).unwrap();
    let out = d.join("r.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&out),
    ]);
    assert!(
        o.stdout()
            .contains("28 calibration point(s), 3 plane point(s), 2 validation point(s)"),
        "{}",
        o.stdout()
    );
    assert_eq!(std::fs::read_to_string(&data).unwrap(), t);
    // Every status robocal writes reads.
    for status in ["calibrated", "partial", "implausible"] {
        let f = d.join(format!("{status}.json"));
        std::fs::write(&f, fx.result_with(|v| set(v, &["status"], json!(status)))).unwrap();
        ok(&[
            "fk",
            "--robot",
            KUKA,
            "--params",
            p(&f),
            "--joints",
            "0,-90,90,0,45,0",
        ]);
    }
}

#[test]
fn nominal_limits_turn_the_error_into_a_warning_recorded_in_the_result() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let data = d.join("limits.csv");
    let text = shifted_q2(fx, &[7, 9], 360.0);
    std::fs::write(&data, &text).unwrap();
    let out = d.join("r.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&out),
        "--nominal-limits",
    ]);
    let err = o.stderr();
    let want = format!(
        "warning: {}: 2 row(s) with joint values outside the limits of robot `{KUKA}`: line 7 (q2 = ",
        p(&data)
    );
    assert!(
        err.contains(&want) && err.contains("line 9 (q2 = "),
        "{err}"
    );
    let r: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(r["settings"]["nominal_limits"], json!(true));
    assert_eq!(
        r["settings"]["rows_outside_limits"],
        json!([{"file": p(&data), "rows": 2, "lines": [7, 9]}])
    );
    // Without the flag the result records that the limits were enforced.
    let v: Value = serde_json::from_str(&fx.text(&fx.result)).unwrap();
    assert_eq!(v["settings"]["nominal_limits"], json!(false));
    assert!(v["settings"].get("rows_outside_limits").is_none());

    // evaluate: a warning, and the count in --json.
    let o = ok(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--data",
        p(&data),
        "--json",
        "--nominal-limits",
    ]);
    assert!(o.stderr().contains(&want), "{}", o.stderr());
    let j: Value = serde_json::from_str(&o.stdout()).unwrap();
    assert_eq!(j["rows_outside_limits"], json!(2));

    // compensate and simulate measure such rows and name each with its file and line.
    let joints = d.join("joints.csv");
    let jt = shifted_q2(fx, &[7, 9], 360.0);
    std::fs::write(&joints, &jt).unwrap();
    let o = ok(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--joints",
        p(&joints),
        "--out",
        p(&d.join("c.csv")),
    ]);
    let err = o.stderr();
    assert!(
        err.contains(&format!(
            "{}: 2 desired pose(s) outside the joint limits",
            p(&joints)
        )) && err.contains("line 7 (q2), line 9 (q2)"),
        "{err}"
    );
    let o = ok(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--joints",
        p(&joints),
        "--out",
        p(&d.join("s.csv")),
    ]);
    let err = o.stderr();
    for l in [7, 9] {
        assert!(
            err.contains(&format!("{}:{l}: q2 outside the joint limits", p(&joints))),
            "{err}"
        );
    }
    assert_eq!(std::fs::read_to_string(&data).unwrap(), text);
    assert_eq!(std::fs::read_to_string(&joints).unwrap(), jt);
}
