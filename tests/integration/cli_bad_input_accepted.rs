//! Inputs that look odd but are accepted: CRLF line endings with a UTF-8 byte-order mark (every
//! input type gives exactly what its LF twin gives), joint values that look like radians (a
//! warning, the run goes on) and duplicated rows outside calibration.

use crate::util::bad_input::crlf_bom;
use crate::util::fixtures::cell;
use crate::util::*;
use std::path::{Path, PathBuf};

/// Writes `crlf_bom(text of good)` next to the case files.
fn crlf_copy(dir: &Path, good: &Path, name: &str) -> PathBuf {
    let f = dir.join(name);
    let text = std::fs::read_to_string(good).unwrap();
    std::fs::write(&f, crlf_bom(&text)).unwrap();
    assert!(std::fs::read(&f).unwrap().starts_with(b"\xef\xbb\xbf"));
    f
}

#[test]
fn crlf_and_byte_order_mark_are_accepted_by_every_reader() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let data = crlf_copy(d, &fx.data, "data.csv");
    let joints = crlf_copy(d, &fx.joints, "joints.csv");
    let targets = crlf_copy(d, &fx.targets, "targets.csv");
    let robot = crlf_copy(d, &fx.robot_toml, "robot.toml");
    let result = crlf_copy(d, &fx.result, "result.json");
    let truth = crlf_copy(d, &fx.truth, "cell.truth.json");

    // Measurement CSV: the same calibration and the same statistics.
    let out = d.join("r.json");
    ok(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&out),
    ]);
    let params = |f: &Path| {
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
        v["parameters"].clone()
    };
    assert_eq!(params(&out), params(&fx.result));
    let eval = |data: &Path, res: &Path| {
        let o = ok(&[
            "evaluate",
            "--robot",
            KUKA,
            "--params",
            p(res),
            "--data",
            p(data),
            "--json",
        ]);
        let mut v: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
        let o = v.as_object_mut().unwrap();
        o.remove("data");
        o.remove("params");
        v
    };
    let reference = eval(&fx.data, &fx.result);
    assert_eq!(eval(&data, &fx.result), reference);
    // Result JSON.
    assert_eq!(eval(&fx.data, &result), reference);
    let fk = |res: &Path| {
        ok(&[
            "fk",
            "--robot",
            KUKA,
            "--params",
            p(res),
            "--joints",
            "10,-80,70,5,30,0",
            "--json",
        ])
        .stdout()
    };
    assert_eq!(fk(&result), fk(&fx.result));

    // Joints and targets CSV: byte-identical commanded files.
    let compensate = |flag: &str, input: &Path, out: &Path| {
        ok(&[
            "compensate",
            "--robot",
            KUKA,
            "--params",
            p(&fx.result),
            flag,
            p(input),
            "--out",
            p(out),
        ]);
        std::fs::read(out).unwrap()
    };
    assert_eq!(
        compensate("--joints", &joints, &d.join("c1.csv")),
        compensate("--joints", &fx.joints, &d.join("c2.csv"))
    );
    assert_eq!(
        compensate("--targets", &targets, &d.join("t1.csv")),
        compensate("--targets", &fx.targets, &d.join("t2.csv"))
    );

    // simulate --joints and --truth FILE.truth.json: byte-identical measurements.
    let simulate = |truth: &Path, extra: &[&str], out: &Path| {
        let mut a = vec![
            "simulate",
            "--robot",
            KUKA,
            "--truth",
            p(truth),
            "--seed",
            "4",
        ];
        a.extend_from_slice(extra);
        a.extend_from_slice(&["--out", p(out)]);
        ok(&a);
        std::fs::read(out).unwrap()
    };
    assert_eq!(
        simulate(&fx.truth, &["--joints", p(&joints)], &d.join("s1.csv")),
        simulate(&fx.truth, &["--joints", p(&fx.joints)], &d.join("s2.csv"))
    );
    assert_eq!(
        simulate(&truth, &["--poses", "5"], &d.join("s3.csv")),
        simulate(&fx.truth, &["--poses", "5"], &d.join("s4.csv"))
    );

    // Robot TOML: the same model.
    let show = |r: &Path| ok(&["robot", "show", p(r)]).stdout();
    assert_eq!(show(&robot), show(&fx.robot_toml));
}

#[test]
fn joint_values_that_look_like_radians_are_warned_about_and_the_run_goes_on() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let to_radians = |text: &str, joints: usize| -> String {
        let mut out = String::new();
        for (k, line) in text.lines().enumerate() {
            if k == 0 {
                out.push_str(line);
            } else {
                let cells: Vec<String> = line
                    .split(',')
                    .enumerate()
                    .map(|(i, c)| {
                        if i < joints {
                            format!("{:.9}", c.parse::<f64>().unwrap().to_radians())
                        } else {
                            c.to_owned()
                        }
                    })
                    .collect();
                out.push_str(&cells.join(","));
            }
            out.push('\n');
        }
        out
    };
    let data = d.join("radians.csv");
    std::fs::write(
        &data,
        to_radians(&std::fs::read_to_string(&fx.data).unwrap(), 6),
    )
    .unwrap();
    let joints = d.join("radians.joints.csv");
    std::fs::write(
        &joints,
        to_radians(&std::fs::read_to_string(&fx.joints).unwrap(), 6),
    )
    .unwrap();
    let warning = |f: &Path| format!("warning: {}: every joint value is within ±", p(f));
    // evaluate measures the points against the calibrated robot: calibrate's gate (exit 6)
    // names the cause after the warning.
    let o = robocal(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--data",
        p(&data),
    ]);
    o.assert_code(6);
    assert!(o.stderr().contains(&warning(&data)), "{}", o.stderr());
    assert!(
        o.stderr().contains("the joint values are in radians"),
        "{}",
        o.stderr()
    );
    let runs: Vec<(Vec<String>, PathBuf)> = vec![
        (
            vec![
                "compensate",
                "--robot",
                KUKA,
                "--params",
                p(&fx.result),
                "--joints",
                p(&joints),
                "--out",
                p(&d.join("c.csv")),
            ],
            joints.clone(),
        ),
        (
            vec![
                "simulate",
                "--robot",
                KUKA,
                "--truth",
                TRUTH,
                "--joints",
                p(&joints),
                "--out",
                p(&d.join("s.csv")),
            ],
            joints.clone(),
        ),
    ]
    .into_iter()
    .map(|(a, f)| (a.into_iter().map(str::to_owned).collect(), f))
    .collect();
    for (args, f) in runs {
        let o = robocal(&args);
        let err = o.stderr();
        o.assert_ok();
        assert!(err.contains(&warning(&f)), "{args:?}: {err}");
        assert!(
            err.contains("they look like radians, but files hold degrees"),
            "{err}"
        );
    }
    assert!(d.join("c.csv").exists() && d.join("s.csv").exists());
    // calibrate warns before it starts; such data then fail on their own merits (the frame fit
    // misses by metres), which the warning explains.
    let o = robocal(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(&data),
        "--out",
        p(&d.join("r.json")),
    ]);
    assert!(o.stderr().contains(&warning(&data)), "{}", o.stderr());
    // Degrees do not trigger it.
    let o = ok(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--data",
        p(&fx.data),
    ]);
    assert!(!o.stderr().contains("radians"), "{}", o.stderr());
}

#[test]
fn duplicated_rows_are_kept_outside_calibration() {
    let fx = cell();
    let dir = Dir::new();
    let d = dir.path();
    let text = std::fs::read_to_string(&fx.joints).unwrap();
    let row = text.lines().nth(2).unwrap().to_owned();
    let joints = d.join("dup.csv");
    std::fs::write(&joints, format!("{text}{row}\n")).unwrap();
    let out = d.join("c.csv");
    ok(&[
        "compensate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--joints",
        p(&joints),
        "--out",
        p(&out),
    ]);
    let lines: Vec<String> = std::fs::read_to_string(&out)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect();
    assert_eq!(lines.len(), 7);
    assert_eq!(
        lines[2], lines[6],
        "the repeat gets the same commanded joints"
    );

    let data_text = std::fs::read_to_string(&fx.data).unwrap();
    let row = data_text.lines().nth(10).unwrap().to_owned();
    let data = d.join("dup-data.csv");
    std::fs::write(&data, format!("{data_text}{row}\n")).unwrap();
    let o = ok(&[
        "evaluate",
        "--robot",
        KUKA,
        "--params",
        p(&fx.result),
        "--data",
        p(&data),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    assert_eq!(v["n"], 34);
}
