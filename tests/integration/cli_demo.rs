//! `robocal demo` (the paper's experiment in one command) and `robocal report`.

use crate::util::*;
use std::path::{Path, PathBuf};

/// The numbers of the first line starting with `label` after the line containing `table`.
fn row(out: &str, table: &str, label: &str) -> Vec<f64> {
    let start = out
        .find(table)
        .unwrap_or_else(|| panic!("no {table:?} in\n{out}"));
    let line = out[start..]
        .lines()
        .find(|l| l.starts_with(label))
        .unwrap_or_else(|| panic!("no {label:?} row in {table:?}"));
    line[label.len()..]
        .split_whitespace()
        .map(|v| v.parse().unwrap_or_else(|_| panic!("{v:?} in {line:?}")))
        .collect()
}

/// Checks that the HTML is a complete page whose elements open and close in order (void
/// elements aside) and returns it.
fn well_formed_html(path: &Path) -> String {
    let html = std::fs::read_to_string(path).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    let mut stack: Vec<String> = Vec::new();
    let mut rest = html.as_str();
    while let Some(i) = rest.find('<') {
        rest = &rest[i + 1..];
        let end = rest.find('>').expect("unterminated tag");
        let tag = &rest[..end];
        rest = &rest[end + 1..];
        if tag.starts_with('!') || tag.starts_with('?') || tag.ends_with('/') {
            continue;
        }
        let name: String = tag
            .trim_start_matches('/')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect();
        if matches!(name.as_str(), "meta" | "br" | "hr" | "img" | "link") {
            continue;
        }
        if tag.starts_with('/') {
            assert_eq!(stack.pop().as_deref(), Some(name.as_str()), "</{name}>");
        } else {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed: {stack:?}");
    html
}

/// The `robocal ...` commands the demo prints (continuation lines joined), as argument lists.
fn printed_commands(out: &str) -> Vec<Vec<String>> {
    let mut cmds = Vec::new();
    let mut cur = String::new();
    let from = out
        .find("Each step by hand")
        .expect("the steps are printed");
    for line in out[from..].lines() {
        let l = line.trim();
        if cur.is_empty() && !l.starts_with("robocal ") {
            continue;
        }
        cur.push_str(l.trim_end_matches('\\'));
        cur.push(' ');
        if !l.ends_with('\\') {
            cmds.push(cur.split_whitespace().skip(1).map(String::from).collect());
            cur.clear();
        }
    }
    cmds
}

const FILES: [&str; 7] = [
    "cell.csv",
    "validation.csv",
    "cell.truth.json",
    "desired.csv",
    "result.json",
    "commanded.csv",
    "verify.csv",
];

/// The demo's ideal cell (`--ideal`, the cell of earlier versions): the verification lands
/// within 20% of the prediction, and the elasto-geometric calibration removes the sag.
#[test]
fn the_ideal_demo_verifies_within_its_prediction() {
    let tmp = Dir::new();
    let dir = tmp.join("ideal");
    let out = ok(&["demo", "--seed", "1", "--ideal", "--out", p(&dir)]).stdout();
    let after = row(&out, "Table IV.", "Mean (mm)");
    let ver = row(&out, "Table V.", "Mean (mm)");
    assert_eq!(ver[2], after[0]);
    assert!(
        (ver[0] - ver[2]).abs() <= 0.2 * ver[2],
        "verification {} vs prediction {}",
        ver[0],
        ver[2]
    );
    for label in ["Validation mean (mm)", "Verification mean (mm)"] {
        let v = row(&out, "Beyond the paper", label);
        assert_eq!(v.len(), 2, "{label}: {v:?}");
        assert!(v[1] < 0.5 * v[0] && v[1] < 0.08, "{label}: {v:?}");
    }
    assert!(!out.contains("backlash"), "{out}");
    assert!(!printed_commands(&out)
        .iter()
        .flatten()
        .any(|a| a == "--station"));
}

/// The demo with a fixed seed, in its default honest cell: its tables (the paper's ranges), the
/// geometric calibration verifying well above its prediction and the real cell's families
/// closing the gap, its files and report, and the printed commands, which give the same files
/// again when run by hand.
#[test]
fn demo_prints_the_papers_tables_and_its_commands_reproduce_the_files() {
    let tmp = Dir::new();
    let dir = tmp.join("demo");
    assert!(!p(&dir).contains(' '), "the test splits commands on spaces");
    let out = ok(&["demo", "--seed", "1", "--out", p(&dir)]).stdout();

    // Table II: ours, paper, ours, paper (calibration, validation points).
    let before = row(&out, "Table II.", "Mean (mm)");
    assert_eq!(before.len(), 4, "{before:?}");
    assert_eq!((before[1], before[3]), (1.619, 1.603));
    for b in [before[0], before[2]] {
        assert!((1.0..2.5).contains(&b), "before calibration {b}");
    }
    let after = row(&out, "Table IV.", "Mean (mm)");
    assert_eq!((after[1], after[3]), (0.174, 0.242));
    // The honest cell's backlash and heat add to what the geometric model leaves.
    assert!(
        after[0] < 0.3 && after[2] < 0.4,
        "after calibration {after:?}"
    );
    // Table V: verification (ours, paper), prediction (ours, paper).
    let ver = row(&out, "Table V.", "Mean (mm)");
    assert_eq!((ver[1], ver[3]), (0.293, 0.174));
    assert_eq!(
        ver[2], after[0],
        "the prediction is Table IV's calibration points"
    );
    // The honest cell: the geometric calibration verifies well above its prediction, as the
    // paper's did.
    assert!(
        ver[0] >= 1.3 * ver[2],
        "verification {} vs prediction {}",
        ver[0],
        ver[2]
    );
    assert_eq!(row(&out, "Table V.", "points"), [75.0, 75.0, 75.0, 75.0]);
    // Beside the paper: geometric, elasto-geometric, and with backlash and thermal expansion,
    // each against the calibration's prediction at new poses; the last verifies within 15% of
    // its prediction.
    let ratio = row(&out, "Beyond the paper", "Verification / prediction");
    assert_eq!(ratio.len(), 3, "{ratio:?}");
    assert!(ratio[2] <= 1.15 && ratio[2] < ratio[0], "{ratio:?}");
    let v = row(&out, "Beyond the paper", "Verification mean (mm)");
    assert!(v[2] < 0.25 * v[0], "{v:?}");
    assert!(
        out.contains("--compliance auto --payload-kg 300")
            && out.contains("--backlash auto --thermal auto"),
        "{out}"
    );
    // Table III: every parameter, the fixed ones marked and explained.
    let t3 = &out[out.find("Table III.").unwrap()..out.find("Table IV.").unwrap()];
    let params: Vec<&str> = t3
        .lines()
        .filter(|l| matches!(l.split_whitespace().nth(1), Some("mm" | "deg")))
        .collect();
    assert_eq!(params.len(), 36, "{t3}");
    assert_eq!(params.iter().filter(|l| l.contains('*')).count(), 10);
    assert!(t3.contains("d1       same effect as base_z"), "{t3}");
    assert!(out
        .trim_end()
        .ends_with(&format!("report: {}", dir.join("report.html").display())));

    // The files, the result matching the printed tables, the report.
    for f in FILES.iter().chain(&["report.html", "histogram.svg"]) {
        let m = std::fs::metadata(dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        assert!(m.len() > 100, "{f} is {} bytes", m.len());
    }
    let res: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("result.json")).unwrap()).unwrap();
    let mean = |set: &str, when: &str| {
        let v = res["errors"][set][when]["mean_mm"].as_f64().unwrap();
        (v * 1000.0).round() / 1000.0
    };
    assert_eq!(mean("calibration", "before"), before[0]);
    assert_eq!(mean("validation", "after"), after[2]);
    let html = well_formed_html(&dir.join("report.html"));
    for label in [
        "Before calibration (Table II)",
        "After calibration, predicted (Table IV)",
        "Verification, measured after compensation (Table V)",
        "Fixed parameters",
        "Cal. − true",
        &format!("{:.3}", ver[0]),
    ] {
        assert!(html.contains(label), "report lacks {label:?}");
    }
    assert_eq!(
        html.matches("<svg").count(),
        5,
        "histogram, components, reach, joints, map"
    );
    let svg = std::fs::read_to_string(dir.join("histogram.svg")).unwrap();
    assert!(svg.starts_with("<?xml") && svg.trim_end().ends_with("</svg>"));

    // Each printed step, run by hand, writes the same files again.
    let saved: Vec<Vec<u8>> = FILES
        .iter()
        .map(|f| std::fs::read(dir.join(f)).unwrap())
        .collect();
    let cmds = printed_commands(&out);
    let names: Vec<&str> = cmds.iter().map(|c| c[0].as_str()).collect();
    assert_eq!(
        names,
        [
            "simulate",
            "calibrate",
            "compensate",
            "simulate",
            "evaluate",
            "report"
        ]
    );
    for c in &cmds {
        let args: Vec<&str> = c.iter().map(String::as_str).collect();
        let o = robocal(&args);
        o.assert_ok();
        if c[0] == "evaluate" {
            let m = row(&o.stdout(), "verification", "Mean (mm)");
            assert!((m[0] - ver[0]).abs() <= 0.0005 + 1e-9, "{m:?} vs {ver:?}");
        }
    }
    for (f, bytes) in FILES.iter().zip(&saved) {
        assert!(
            std::fs::read(dir.join(f)).unwrap() == *bytes,
            "{f} differs when made by hand"
        );
    }
    let by_hand = well_formed_html(&dir.join("by-hand/report.html"));
    assert!(by_hand.contains("Verification, measured after compensation (Table V)"));
    assert!(by_hand.contains(&format!("{:.3}", ver[0])));
}

#[test]
fn demo_into_a_file_is_an_io_error_and_writes_nothing() {
    let tmp = Dir::new();
    let f = tmp.write("x", "keep");
    let o = robocal(&["demo", "--out", p(&f)]);
    o.assert_code(4);
    assert!(o.stderr().contains("not a directory"));
    assert_eq!(std::fs::read_to_string(&f).unwrap(), "keep");
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 1);
}

/// Simulated data calibrated by `robocal calibrate`, then `robocal report` on the result: the
/// robot and the data files come from the result; without the data the reach plot is left out.
#[test]
fn report_of_a_calibrate_result() {
    let tmp = Dir::new();
    let d = tmp.path();
    let (cell, val, res) = (d.join("cell.csv"), d.join("val.csv"), d.join("r.json"));
    ok(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        "kuka-kr480-r3330-table3",
        "--poses",
        "60",
        "--validation",
        "40",
        "--seed",
        "9",
        "--out",
        p(&cell),
        "--validation-out",
        p(&val),
    ]);
    ok(&[
        "calibrate",
        "--robot",
        "kuka-kr480-r3330",
        "--data",
        p(&cell),
        "--validate",
        p(&val),
        "--out",
        p(&res),
    ]);
    let out_dir = d.join("rep");
    let out = ok(&["report", p(&res), "--out", p(&out_dir)]).stdout();
    assert!(
        out.contains("Before calibration (Table II): calibration points mean"),
        "{out}"
    );
    let html = well_formed_html(&out_dir.join("report.html"));
    assert_eq!(
        html.matches("<svg").count(),
        5,
        "histogram, components, reach plot, joints and map"
    );
    assert!(html.contains("Validation points") && html.contains("same effect as base_z"));
    assert!(
        !html.contains("Paper: Samak"),
        "no paper figures without --paper"
    );
    let r: serde_json::Value = serde_json::from_slice(&std::fs::read(&res).unwrap()).unwrap();
    let after = r["errors"]["validation"]["after"]["mean_mm"]
        .as_f64()
        .unwrap();
    assert!(html.contains(&format!("{after:.3}")));
    assert!(out_dir.join("histogram.svg").is_file());

    // The recorded data files gone: notes, tables and histogram, no reach plot.
    std::fs::rename(&cell, d.join("moved.csv")).unwrap();
    std::fs::remove_file(&val).unwrap();
    let o = robocal(&["report", p(&res), "--paper", "--out", p(&d.join("rep2"))]);
    o.assert_ok();
    assert!(o.stderr().contains("--data"), "{}", o.stderr());
    assert!(o.stderr().contains("--validate"), "{}", o.stderr());
    let html = well_formed_html(&d.join("rep2/report.html"));
    assert_eq!(html.matches("<svg").count(), 1);
    assert!(html.contains("Paper: Samak et al. 2019, Table II"));
    // ... unless given again.
    let html2 = {
        ok(&[
            "report",
            p(&res),
            "--data",
            p(&d.join("moved.csv")),
            "--out",
            p(&d.join("rep3")),
        ]);
        well_formed_html(&d.join("rep3/report.html"))
    };
    assert_eq!(html2.matches("<svg").count(), 5);

    // Errors: another robot (exit 3), a missing result (4), a bad data file (3).
    let o = robocal(&[
        "report",
        p(&res),
        "--robot",
        concat!(env!("CARGO_MANIFEST_DIR"), "/examples/ur5.toml"),
        "--out",
        p(&d.join("x")),
    ]);
    o.assert_code(3);
    let o = robocal(&["report", p(&d.join("nope.json")), "--out", p(&d.join("x"))]);
    o.assert_code(4);
    std::fs::write(d.join("bad.csv"), "q1,q2\n1,2\n").unwrap();
    let o = robocal(&[
        "report",
        p(&res),
        "--data",
        p(&d.join("bad.csv")),
        "--out",
        p(&d.join("x")),
    ]);
    o.assert_code(3);
    assert!(o.stderr().contains("bad.csv"), "{}", o.stderr());
    assert!(!d.join("x").exists(), "nothing written on errors");
}

/// A result that neither embeds nor records its robot needs --robot.
#[test]
fn report_needs_a_robot() {
    let tmp = Dir::new();
    let d = tmp.path();
    let demo = d.join("demo");
    ok(&["demo", "--seed", "2", "--out", p(&demo)]);
    let mut r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(demo.join("result.json")).unwrap()).unwrap();
    r["settings"].as_object_mut().unwrap().remove("robot_arg");
    // Nor does it embed it (a result from before results embedded their robot).
    for k in ["base", "tool", "tool_correction", "joints", "controller"] {
        r["robot"].as_object_mut().unwrap().remove(k);
    }
    let res: PathBuf = d.join("r.json");
    std::fs::write(&res, serde_json::to_string(&r).unwrap()).unwrap();
    let o = robocal(&["report", p(&res), "--out", p(&d.join("x"))]);
    o.assert_code(2);
    assert!(o.stderr().contains("give --robot"), "{}", o.stderr());
    ok(&[
        "report",
        p(&res),
        "--robot",
        "kuka-kr480-r3330",
        "--verify",
        p(&demo.join("verify.csv")),
        "--out",
        p(&d.join("x")),
    ]);
    let html = well_formed_html(&d.join("x/report.html"));
    assert!(html.contains("Verification, measured after compensation (Table V)"));
}
