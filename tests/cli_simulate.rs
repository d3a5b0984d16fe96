//! `robocal simulate`: reproducibility, the exact rigid case, the noise model, joint files,
//! truth files, non-geometric errors and bad input (clear errors, nothing written).

use nalgebra::{Point3, Vector3};
use robocal_core::io::measurements::{read_measurements, MeasurementSet, Positions};
use robocal_core::io::result::FrameVec;
use robocal_core::preset;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn robocal(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robocal"))
        .args(args)
        .output()
        .expect("run robocal")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name)
        .display()
        .to_string()
}

fn s(p: &Path) -> String {
    p.display().to_string()
}

/// Runs `robocal simulate` with the nominal KR 480 and `args`, expecting success.
fn simulate_ok(args: &[&str]) {
    let mut all = vec!["simulate", "--robot", "kuka-kr480-r3330"];
    all.extend_from_slice(args);
    let o = robocal(&all);
    assert!(o.status.success(), "{all:?}: {}", stderr(&o));
}

fn read(p: &Path) -> MeasurementSet {
    read_measurements(p, 6, Positions::Required).unwrap()
}

fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn tracker_frame(v: &serde_json::Value) -> robocal_core::Frame {
    let f: FrameVec = serde_json::from_value(v["tracker_frame"].clone()).unwrap();
    f.to_frame()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn same_seed_identical_bytes_other_seed_other_data() {
    // Three cells written under the same file name in three directories: the same arguments
    // (and seed) twice, then another seed.
    let dirs: Vec<_> = (0..3).map(|_| tempfile::tempdir().unwrap()).collect();
    let out: Vec<PathBuf> = dirs.iter().map(|d| d.path().join("cell.csv")).collect();
    for (o, seed) in out.iter().zip(["5", "5", "6"]) {
        simulate_ok(&[
            "--truth",
            "random",
            "--poses",
            "30",
            "--validation",
            "10",
            "--seed",
            seed,
            "--outlier-fraction",
            "0.1",
            "--compliance",
            "1e-7",
            "--payload-kg",
            "300",
            "--out",
            &s(o),
        ]);
    }
    let bytes = |p: &Path| std::fs::read(p).unwrap();
    let truth = |p: &Path| p.with_extension("truth.json");
    assert!(bytes(&out[0]) == bytes(&out[1]), "CSV files differ");
    assert!(
        bytes(&truth(&out[0])) == bytes(&truth(&out[1])),
        "truth files differ"
    );
    let (ma, mc) = (read(&out[0]), read(&out[2]));
    assert_eq!(ma.rows.len(), 43);
    for (x, y) in ma.rows.iter().zip(&mc.rows) {
        assert_ne!(x.q, y.q);
        assert_ne!(x.p, y.p);
    }
    assert_ne!(
        json(&truth(&out[0]))["parameters"],
        json(&truth(&out[2]))["parameters"]
    );
}

/// Truth = nominal, zero noise: the readings are exactly the nominal tool positions moved
/// rigidly into the tracker frame given by --tracker.
#[test]
fn nominal_truth_without_noise_is_the_rigidly_moved_nominal() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("exact.csv");
    simulate_ok(&[
        "--truth",
        "kuka-kr480-r3330",
        "--poses",
        "60",
        "--seed",
        "3",
        "--noise-mm",
        "0",
        "--noise-per-m",
        "0",
        "--tracker",
        "-2500,3100,900,-60,0.5,-0.3",
        "--out",
        &s(&out),
    ]);
    let truth = json(&out.with_extension("truth.json"));
    let f = tracker_frame(&truth);
    let fv = &truth["tracker_frame"];
    assert_eq!(fv["x"], -2500.0);
    assert_eq!(fv["a"], -60.0);
    let r = preset("kuka-kr480-r3330").unwrap();
    let m = read(&out);
    assert_eq!(m.rows.len(), 63);
    for row in &m.rows {
        let expected = (f.inverse() * Point3::from(r.tool_position(&row.q))).coords;
        // The CSV holds 6 decimals of a millimetre.
        assert!(
            (row.p.unwrap() - expected).norm() < 2e-6,
            "line {}",
            row.line
        );
    }
    // Every parameter's true value is its nominal value.
    for (name, e) in truth["parameters"].as_object().unwrap() {
        assert_eq!(e["nominal"], e["calibrated"], "{name}");
    }
}

/// Over 10,000 points the spread of readings minus exact positions matches sigma within 5%.
#[test]
fn noise_spread_matches_sigma_over_10000_points() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("noise.csv");
    simulate_ok(&[
        "--truth",
        "kuka-kr480-r3330",
        "--poses",
        "10000",
        "--no-plane",
        "--noise-mm",
        "0.02",
        "--noise-per-m",
        "0.01",
        "--out",
        &s(&out),
    ]);
    let truth = json(&out.with_extension("truth.json"));
    let f = tracker_frame(&truth);
    let r = preset("kuka-kr480-r3330").unwrap();
    let m = read(&out);
    assert_eq!(m.rows.len(), 10_000);
    let (mut ss, mut sigma2) = (Vector3::zeros(), 0.0);
    for row in &m.rows {
        let p = r.tool_position(&row.q);
        let dist_m = (p - f.translation.vector).norm() / 1000.0;
        let sigma = 0.02 + 0.01 * dist_m;
        let e = row.p.unwrap() - (f.inverse() * Point3::from(p)).coords;
        ss += e.component_mul(&e);
        sigma2 += sigma * sigma;
    }
    for k in 0..3 {
        let ratio = (ss[k] / sigma2).sqrt();
        assert!((ratio - 1.0).abs() < 0.05, "axis {k}: spread/sigma {ratio}");
    }
}

#[test]
fn sets_ids_and_a_separate_validation_file() {
    let d = tempfile::tempdir().unwrap();
    let (out, val) = (d.path().join("cell.csv"), d.path().join("cell-val.csv"));
    simulate_ok(&[
        "--truth",
        "kuka-kr480-r3330-table3",
        "--poses",
        "75",
        "--validation",
        "73",
        "--seed",
        "9",
        "--out",
        &s(&out),
        "--validation-out",
        &s(&val),
    ]);
    assert_eq!(
        files_in(d.path()),
        ["cell-val.csv", "cell.csv", "cell.truth.json"]
    );
    let m = read(&out);
    assert_eq!(m.extra_columns, ["id", "set"]);
    let sets: Vec<&str> = m.rows.iter().map(|r| r.extra[1].as_str()).collect();
    assert_eq!(sets.iter().filter(|x| **x == "plane").count(), 3);
    assert_eq!(sets.iter().filter(|x| **x == "calibration").count(), 75);
    assert_eq!(m.rows[0].extra[0], "P1");
    assert_eq!(m.rows[3].extra[0], "C1");
    let v = read(&val);
    assert_eq!(v.rows.len(), 73);
    assert!(v.rows.iter().all(|r| r.extra[1] == "validation"));
    assert_eq!(v.rows[72].extra[0], "V73");
    let truth = json(&out.with_extension("truth.json"));
    assert_eq!(truth["sets"]["validation"]["file"], "cell-val.csv");
    assert_eq!(truth["sets"]["calibration"]["rows"], 75);
    assert_eq!(truth["parameters"]["d4"]["calibrated"], 1525.997);
    assert_eq!(truth["parameters"]["d4"]["nominal"], 1525.0);
    // The plane points share one nominal height.
    let r = preset("kuka-kr480-r3330").unwrap();
    let z = truth["plane_z_mm"].as_f64().unwrap();
    for row in &m.rows[..3] {
        assert!((r.tool_position(&row.q).z - z).abs() < 1e-5);
    }
}

/// The verification workflow: measure given joints in the same virtual cell (same seed, or the
/// truth file), keeping the rows' order and extra columns.
#[test]
fn joints_file_is_measured_in_the_same_cell() {
    let d = tempfile::tempdir().unwrap();
    let first = d.path().join("first.csv");
    simulate_ok(&[
        "--truth",
        "random",
        "--tilt-parallel-axes",
        "--poses",
        "12",
        "--seed",
        "21",
        "--noise-mm",
        "0",
        "--noise-per-m",
        "0",
        "--out",
        &s(&first),
    ]);
    // A joint file: the first file's joints in reverse order, with a column of our own, and the
    // old x,y,z (which must be replaced).
    let m = read(&first);
    let mut text = String::from("name,q1,q2,q3,q4,q5,q6,x,y,z\n");
    for (i, r) in m.rows.iter().enumerate().rev() {
        let q: Vec<String> =
            r.q.iter()
                .map(|v| format!("{:.9}", v.to_degrees()))
                .collect();
        text.push_str(&format!("pt{i},{},0,0,0\n", q.join(",")));
    }
    let joints = d.path().join("joints.csv");
    std::fs::write(&joints, text).unwrap();
    let truth_json = first.with_extension("truth.json");
    for (i, truth) in [String::from("random"), s(&truth_json)].iter().enumerate() {
        let out = d.path().join(format!("again{i}.csv"));
        let mut args = vec![
            "--truth",
            truth,
            "--joints",
            &s(&joints),
            "--noise-mm",
            "0",
            "--noise-per-m",
            "0",
            "--out",
        ]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
        args.push(s(&out));
        if i == 0 {
            args.extend(["--seed", "21", "--tilt-parallel-axes"].map(String::from));
        }
        simulate_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
        let again = read(&out);
        assert_eq!(again.extra_columns, ["name"]);
        assert_eq!(again.rows.len(), m.rows.len());
        for (k, r) in again.rows.iter().enumerate() {
            let orig = &m.rows[m.rows.len() - 1 - k];
            assert_eq!(r.extra, [format!("pt{}", m.rows.len() - 1 - k)]);
            assert!(
                (r.p.unwrap() - orig.p.unwrap()).norm() < 2e-6,
                "truth {truth}"
            );
        }
        let t = json(&out.with_extension("truth.json"));
        assert_eq!(t["sets"]["measured"]["rows"], 15);
        assert_eq!(t["joints_file"], s(&joints));
    }
}

#[test]
fn outliers_and_gravity_are_recorded() {
    let d = tempfile::tempdir().unwrap();
    let (plain, bad) = (d.path().join("plain.csv"), d.path().join("bad.csv"));
    let common = [
        "--truth",
        "kuka-kr480-r3330-table3",
        "--poses",
        "50",
        "--no-plane",
        "--seed",
        "4",
        "--noise-mm",
        "0",
        "--noise-per-m",
        "0",
    ];
    let mut a: Vec<&str> = common.to_vec();
    let pa = s(&plain);
    a.extend(["--out", &pa]);
    simulate_ok(&a);
    let mut b: Vec<&str> = common.to_vec();
    let pb = s(&bad);
    b.extend([
        "--out",
        &pb,
        "--outlier-fraction",
        "0.1",
        "--outlier-min-mm",
        "3",
        "--outlier-max-mm",
        "4",
    ]);
    simulate_ok(&b);
    let (mp, mb) = (read(&plain), read(&bad));
    let truth = json(&bad.with_extension("truth.json"));
    let outliers = truth["outliers"].as_array().unwrap();
    assert_eq!(outliers.len(), 5);
    let lines: Vec<usize> = outliers
        .iter()
        .map(|o| o["line"].as_u64().unwrap() as usize)
        .collect();
    for (x, y) in mp.rows.iter().zip(&mb.rows) {
        let moved = (x.p.unwrap() - y.p.unwrap()).norm();
        if lines.contains(&y.line) {
            assert!((3.0 - 1e-5..=4.0 + 1e-5).contains(&moved), "{moved}");
        } else {
            assert!(moved < 1e-9, "line {} moved {moved}", y.line);
        }
    }
    // Gravity: every point moves, and the truth file says by how much.
    let g = d.path().join("g.csv");
    let mut c: Vec<&str> = common.to_vec();
    let pg = s(&g);
    c.extend([
        "--out",
        &pg,
        "--compliance",
        "1e-7",
        "--link-masses-kg",
        "0,400,250,100,30,10",
        "--payload-kg",
        "480",
    ]);
    simulate_ok(&c);
    let mg = read(&g);
    let truth = json(&g.with_extension("truth.json"));
    let max = truth["gravity_effect"]["max_mm"].as_f64().unwrap();
    let mut largest: f64 = 0.0;
    for (x, y) in mp.rows.iter().zip(&mg.rows) {
        let moved = (x.p.unwrap() - y.p.unwrap()).norm();
        assert!(moved > 1e-3);
        largest = largest.max(moved);
    }
    assert!((largest - max).abs() < 1e-5, "{largest} vs {max}");
}

/// Every bad input: non-zero exit with a clear message, and no file written.
#[test]
fn bad_input_is_rejected_and_nothing_is_written() {
    let d = tempfile::tempdir().unwrap();
    let below = d.path().join("below.toml");
    std::fs::write(
        &below,
        "convention = \"mdh\"\nbase = [0, 0, -500, 0, 0, 0]\n\
         [[joints]]\nalpha = 0\nd = 0\na = 100\nlimits = [-10, 10]\n\
         [[joints]]\nalpha = 0\nd = 0\na = 100\nlimits = [-10, 10]\n",
    )
    .unwrap();
    let joints = d.path().join("joints.csv");
    std::fs::write(&joints, "q1,q2,q3,q4,q5,q6\n1,2,3,4,5,6\n1,2,x,4,5,6\n").unwrap();
    let out = s(&d.path().join("out.csv"));
    let (below, joints) = (s(&below), s(&joints));
    let wam = example("wam.toml");
    let kr = "kuka-kr480-r3330";
    let t3 = "kuka-kr480-r3330-table3";
    let cases: Vec<(Vec<&str>, i32, &str)> = vec![
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--noise-mm",
                "-0.01",
            ],
            3,
            "--noise-mm",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--noise-per-m",
                "-1",
            ],
            3,
            "--noise-per-m",
        ),
        (
            vec!["--robot", kr, "--truth", t3, "--poses", "0"],
            3,
            "--poses: must be at least 1",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--outlier-fraction",
                "1.5",
            ],
            3,
            "--outlier-fraction",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--outlier-fraction",
                "-0.1",
            ],
            3,
            "--outlier-fraction",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--floor-mm",
                "100000",
            ],
            3,
            "no acceptable pose",
        ),
        (
            vec![
                "--robot",
                &below,
                "--truth",
                &below,
                "--poses",
                "5",
                "--no-plane",
            ],
            3,
            "no acceptable pose",
        ),
        (
            vec!["--robot", kr, "--truth", &wam, "--poses", "5"],
            3,
            "7 joints",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                "random",
                "--poses",
                "5",
                "--length-error-mm",
                "-1",
            ],
            3,
            "--length-error-mm",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--angle-error-deg",
                "0.1",
            ],
            2,
            "only to --truth random",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--compliance",
                "1e-7",
            ],
            3,
            "needs a mass",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--compliance",
                "1,2",
            ],
            2,
            "--compliance: 2 values",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--validation-out",
                "v.csv",
            ],
            2,
            "--validation-out",
        ),
        (
            vec![
                "--robot",
                kr,
                "--truth",
                t3,
                "--poses",
                "5",
                "--tracker",
                "1,2,3",
            ],
            2,
            "--tracker",
        ),
        (
            vec!["--robot", kr, "--truth", t3, "--joints", &joints],
            3,
            "joints.csv:3: field `q3`",
        ),
        (
            vec!["--robot", kr, "--truth", "no-such-robot", "--poses", "5"],
            2,
            "no-such-robot",
        ),
    ];
    for (args, code, msg) in cases {
        let mut all = vec!["simulate", "--out", &out];
        all.extend(&args);
        let o = robocal(&all);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(msg), "{args:?}: `{msg}` not in {err}");
        assert_eq!(
            files_in(d.path()),
            ["below.toml", "joints.csv"],
            "{args:?} wrote something"
        );
    }
    // A missing output directory: I/O error, exit 4.
    let o = robocal(&[
        "simulate",
        "--robot",
        kr,
        "--truth",
        t3,
        "--poses",
        "5",
        "--out",
        "/nonexistent-robocal-dir/x.csv",
    ]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
}

#[test]
fn an_existing_result_is_not_touched_by_a_failed_run() {
    let d = tempfile::tempdir().unwrap();
    let out: PathBuf = d.path().join("cell.csv");
    simulate_ok(&[
        "--truth",
        "kuka-kr480-r3330-table3",
        "--poses",
        "5",
        "--out",
        &s(&out),
    ]);
    let before = (
        std::fs::read(&out).unwrap(),
        std::fs::read(out.with_extension("truth.json")).unwrap(),
    );
    let o = robocal(&[
        "simulate",
        "--robot",
        "kuka-kr480-r3330",
        "--truth",
        "kuka-kr480-r3330-table3",
        "--poses",
        "5",
        "--seed",
        "2",
        "--floor-mm",
        "99999",
        "--out",
        &s(&out),
    ]);
    assert_eq!(o.status.code(), Some(3));
    assert_eq!(std::fs::read(&out).unwrap(), before.0);
    assert_eq!(
        std::fs::read(out.with_extension("truth.json")).unwrap(),
        before.1
    );
    assert_eq!(files_in(d.path()), ["cell.csv", "cell.truth.json"]);
}
