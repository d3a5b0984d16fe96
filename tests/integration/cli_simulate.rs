//! `robocal simulate`: reproducibility, the exact rigid case, the noise model, joint files,
//! truth files, non-geometric errors and bad input (clear errors, nothing written).

use crate::util::*;
use nalgebra::Vector3;
use robocal_core::frame::TrackerFrame;
use robocal_core::io::measurements::{read_measurements, MeasurementSet, Positions};
use robocal_core::io::result::FrameVec;
use robocal_core::preset;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Runs `robocal simulate` with `spec` (whitespace-separated arguments without paths) followed
/// by `paths` (option, path) pairs, which may contain any character.
fn sim(spec: &str, paths: &[(&str, &Path)]) -> Outcome {
    let mut args: Vec<OsString> = vec!["simulate".into()];
    args.extend(spec.split_whitespace().map(OsString::from));
    for (opt, p) in paths {
        args.push(opt.into());
        args.push(p.into());
    }
    robocal(&args)
}

/// [`sim`] with the nominal KR 480, expecting success.
fn sim_ok(spec: &str, paths: &[(&str, &Path)]) {
    sim(&format!("--robot kuka-kr480-r3330 {spec}"), paths).assert_ok();
}

fn read(p: &Path) -> MeasurementSet {
    read_measurements(
        p,
        &robocal_core::JointSpace::revolute(6),
        Positions::Required,
    )
    .unwrap()
}

fn truth_of(csv: &Path) -> serde_json::Value {
    let p = csv.with_extension("truth.json");
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

fn tracker_frame(v: &serde_json::Value) -> TrackerFrame {
    let f: FrameVec = serde_json::from_value(v["tracker_frame"].clone()).unwrap();
    f.to_tracker_frame()
}

#[test]
fn same_seed_identical_bytes_other_seed_other_data() {
    // Three cells written under the same file name in three directories: the same arguments
    // (and seed) twice, then another seed.
    let dirs: Vec<_> = (0..3).map(|_| Dir::new()).collect();
    let out: Vec<PathBuf> = dirs.iter().map(|d| d.join("cell.csv")).collect();
    for (o, seed) in out.iter().zip(["5", "5", "6"]) {
        sim_ok(
            &format!(
                "--truth random --poses 30 --validation 10 --seed {seed} --outlier-fraction 0.1 \
                 --compliance 1e-7 --payload-kg 300"
            ),
            &[("--out", o)],
        );
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
        truth_of(&out[0])["parameters"],
        truth_of(&out[2])["parameters"]
    );
}

/// Truth = nominal, zero noise: the readings are exactly the nominal tool positions moved
/// rigidly into the tracker frame given by --tracker.
#[test]
fn nominal_truth_without_noise_is_the_rigidly_moved_nominal() {
    let d = Dir::new();
    let out = d.join("exact.csv");
    sim_ok(
        "--truth kuka-kr480-r3330 --poses 60 --seed 3 --noise-mm 0 --noise-per-m 0 \
         --tracker -2500,3100,900,-60,0.5,-0.3",
        &[("--out", &out)],
    );
    let truth = truth_of(&out);
    let f = tracker_frame(&truth);
    assert_eq!(truth["tracker_frame"]["x"], -2500.0);
    assert_eq!(truth["tracker_frame"]["a"], -60.0);
    let r = preset("kuka-kr480-r3330").unwrap();
    let m = read(&out);
    assert_eq!(m.rows.len(), 63);
    for row in &m.rows {
        let expected = f.to_tracker(&r.tool_position(&row.q));
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
    let d = Dir::new();
    let out = d.join("noise.csv");
    sim_ok(
        "--truth kuka-kr480-r3330 --poses 10000 --no-plane --noise-mm 0.02 --noise-per-m 0.01",
        &[("--out", &out)],
    );
    let f = tracker_frame(&truth_of(&out));
    let r = preset("kuka-kr480-r3330").unwrap();
    let m = read(&out);
    assert_eq!(m.rows.len(), 10_000);
    let (mut ss, mut sigma2) = (Vector3::zeros(), 0.0);
    for row in &m.rows {
        let p = r.tool_position(&row.q);
        let dist_m = (p - f.origin()).norm() / 1000.0;
        let sigma = 0.02 + 0.01 * dist_m;
        let e = row.p.unwrap() - f.to_tracker(&p);
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
    let d = Dir::new();
    let (out, val) = (d.join("cell.csv"), d.join("cell-val.csv"));
    sim_ok(
        "--truth kuka-kr480-r3330-table3 --poses 75 --validation 73 --seed 9",
        &[("--out", &out), ("--validation-out", &val)],
    );
    assert_eq!(
        files_in(d.path()),
        ["cell-val.csv", "cell.csv", "cell.truth.json"]
    );
    let m = read(&out);
    assert_eq!(m.extra_columns, ["id", "set"]);
    let count = |set: &str| m.rows.iter().filter(|r| r.extra[1] == set).count();
    assert_eq!((count("plane"), count("calibration")), (3, 75));
    assert_eq!(
        (m.rows[0].extra[0].as_str(), m.rows[3].extra[0].as_str()),
        ("P1", "C1")
    );
    let v = read(&val);
    assert_eq!(v.rows.len(), 73);
    assert!(v.rows.iter().all(|r| r.extra[1] == "validation"));
    assert_eq!(v.rows[72].extra[0], "V73");
    let truth = truth_of(&out);
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
    let d = Dir::new();
    let first = d.join("first.csv");
    let exact = "--noise-mm 0 --noise-per-m 0";
    sim_ok(
        &format!("--truth random --tilt-parallel-axes --poses 12 --seed 21 {exact}"),
        &[("--out", &first)],
    );
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
    let joints = d.write("joints.csv", text);
    let truth_json = first.with_extension("truth.json");
    let by_seed = format!("--truth random --seed 21 --tilt-parallel-axes {exact}");
    let runs: [(&str, Vec<(&str, &Path)>); 2] = [
        (&by_seed, vec![]),
        (exact, vec![("--truth", truth_json.as_path())]),
    ];
    for (i, (spec, extra)) in runs.iter().enumerate() {
        let out = d.join(format!("again{i}.csv"));
        let mut paths = extra.clone();
        paths.extend([("--joints", joints.as_path()), ("--out", out.as_path())]);
        sim_ok(spec, &paths);
        let again = read(&out);
        assert_eq!(again.extra_columns, ["name"]);
        assert_eq!(again.rows.len(), m.rows.len());
        for (k, r) in again.rows.iter().enumerate() {
            let j = m.rows.len() - 1 - k;
            assert_eq!(r.extra, [format!("pt{j}")]);
            assert!(
                (r.p.unwrap() - m.rows[j].p.unwrap()).norm() < 2e-6,
                "run {i}"
            );
        }
        let t = truth_of(&out);
        assert_eq!(t["sets"]["measured"]["rows"], 15);
        assert_eq!(t["joints_file"], joints.display().to_string());
        assert_eq!(t["parameters"], truth_of(&first)["parameters"]);
    }
}

#[test]
fn joint_values_outside_the_limits_are_measured_with_a_warning() {
    let d = Dir::new();
    let joints = d.join("j.csv");
    std::fs::write(
        &joints,
        "q1,q2,q3,q4,q5,q6\n0,-40,30,0,20,0\n0,-40,30,0,150,0\n",
    )
    .unwrap();
    let out = d.join("m.csv");
    let o = sim(
        "--robot kuka-kr480-r3330 --truth kuka-kr480-r3330-table3",
        &[("--joints", &joints), ("--out", &out)],
    );
    o.assert_ok();
    assert!(
        o.stderr().contains("j.csv:3: q5 outside the joint limits"),
        "{}",
        o.stderr()
    );
    assert_eq!(read(&out).rows.len(), 2);
    let w = truth_of(&out)["warnings"].to_string();
    assert!(w.contains("j.csv:3: q5"), "{w}");
}

#[test]
fn outliers_and_gravity_are_recorded() {
    let d = Dir::new();
    let (plain, bad, grav) = (d.join("plain.csv"), d.join("bad.csv"), d.join("g.csv"));
    let common = "--truth kuka-kr480-r3330-table3 --poses 50 --no-plane --seed 4 --noise-mm 0 \
                  --noise-per-m 0";
    sim_ok(common, &[("--out", &plain)]);
    sim_ok(
        &format!("{common} --outlier-fraction 0.1 --outlier-min-mm 3 --outlier-max-mm 4"),
        &[("--out", &bad)],
    );
    let (mp, mb) = (read(&plain), read(&bad));
    let truth = truth_of(&bad);
    let outliers = truth["outliers"].as_array().unwrap();
    assert_eq!(outliers.len(), 5);
    let lines: Vec<u64> = outliers
        .iter()
        .map(|o| o["line"].as_u64().unwrap())
        .collect();
    for (x, y) in mp.rows.iter().zip(&mb.rows) {
        let moved = (x.p.unwrap() - y.p.unwrap()).norm();
        if lines.contains(&(y.line as u64)) {
            assert!((3.0 - 1e-5..=4.0 + 1e-5).contains(&moved), "{moved}");
        } else {
            assert!(moved < 1e-9, "line {} moved {moved}", y.line);
        }
    }
    // Gravity: every point moves, and the truth file says by how much.
    sim_ok(
        &format!(
            "{common} --compliance 1e-7 --link-masses-kg 0,400,250,100,30,10 --payload-kg 480"
        ),
        &[("--out", &grav)],
    );
    let mg = read(&grav);
    let max = truth_of(&grav)["gravity_effect"]["max_mm"]
        .as_f64()
        .unwrap();
    let mut largest: f64 = 0.0;
    for (x, y) in mp.rows.iter().zip(&mg.rows) {
        let moved = (x.p.unwrap() - y.p.unwrap()).norm();
        assert!(moved > 1e-3);
        largest = largest.max(moved);
    }
    assert!((largest - max).abs() < 1e-5, "{largest} vs {max}");
}

/// A bad-input case: arguments, (option, path) pairs, exit code, expected message.
type Case<'a> = (String, Vec<(&'a str, &'a Path)>, i32, &'a str);

/// Every bad input: non-zero exit with a clear message, and no file written.
#[test]
fn bad_input_is_rejected_and_nothing_is_written() {
    let d = Dir::new();
    let below = d.join("below.toml");
    std::fs::write(
        &below,
        "convention = \"mdh\"\nbase = [0, 0, -500, 0, 0, 0]\n\
         [[joints]]\nalpha = 0\nd = 0\na = 100\nlimits = [-10, 10]\n\
         [[joints]]\nalpha = 0\nd = 0\na = 100\nlimits = [-10, 10]\n",
    )
    .unwrap();
    let joints = d.write(
        "joints.csv",
        "q1,q2,q3,q4,q5,q6\n1,2,3,4,5,6\n1,2,x,4,5,6\n",
    );
    let bad_truth = d.write("bad.truth.json", "{\n  \"robot\": 3,\n}\n");
    let wam = root().join("examples/wam.toml");
    let out = d.join("out.csv");
    let kr = "--robot kuka-kr480-r3330 --truth kuka-kr480-r3330-table3";
    let cases: Vec<Case> = vec![
        (
            format!("{kr} --poses 5 --noise-mm -0.01"),
            vec![],
            3,
            "--noise-mm",
        ),
        (
            format!("{kr} --poses 5 --noise-per-m -1"),
            vec![],
            3,
            "--noise-per-m",
        ),
        (
            format!("{kr} --poses 0"),
            vec![],
            2,
            "--poses: at least 1, got 0",
        ),
        (
            format!("{kr} --poses 5 --outlier-fraction 1.5"),
            vec![],
            3,
            "--outlier-fraction",
        ),
        (
            format!("{kr} --poses 5 --outlier-fraction -0.1"),
            vec![],
            3,
            "--outlier-fraction",
        ),
        (
            format!("{kr} --poses 5 --floor-mm 100000"),
            vec![],
            3,
            "no acceptable pose",
        ),
        (
            "--poses 5 --no-plane".into(),
            vec![("--robot", &below), ("--truth", &below)],
            3,
            "no acceptable pose",
        ),
        (
            "--robot kuka-kr480-r3330 --poses 5".into(),
            vec![("--truth", &wam)],
            3,
            "7 joints",
        ),
        (
            "--robot kuka-kr480-r3330 --poses 5".into(),
            vec![("--truth", &bad_truth)],
            3,
            "bad.truth.json:2: field `robot`: not a robocal truth file",
        ),
        (
            "--robot kuka-kr480-r3330 --truth random --poses 5 --length-error-mm -1".into(),
            vec![],
            3,
            "--length-error-mm",
        ),
        (
            format!("{kr} --poses 5 --angle-error-deg 0.1"),
            vec![],
            2,
            "only to --truth random",
        ),
        (
            format!("{kr} --poses 5 --compliance 1e-7"),
            vec![],
            3,
            "needs a mass",
        ),
        (
            format!("{kr} --poses 5 --compliance 1,2"),
            vec![],
            2,
            "--compliance: 2 values",
        ),
        (
            format!("{kr} --poses 5 --validation-out v.csv"),
            vec![],
            2,
            "--validation-out",
        ),
        (
            format!("{kr} --poses 5 --tracker 1,2,3"),
            vec![],
            2,
            "--tracker",
        ),
        (
            kr.to_string(),
            vec![("--joints", &joints)],
            3,
            "joints.csv:3: field `q3`",
        ),
        (
            "--robot kuka-kr480-r3330 --truth no-such-robot --poses 5".into(),
            vec![],
            2,
            "no-such-robot",
        ),
    ];
    for (spec, mut paths, code, msg) in cases {
        paths.push(("--out", &out));
        let o = sim(&spec, &paths);
        let err = o.stderr();
        o.assert_code(code);
        assert!(err.contains(msg), "{spec}: `{msg}` not in {err}");
        assert_eq!(
            files_in(d.path()),
            ["bad.truth.json", "below.toml", "joints.csv"],
            "{spec} wrote something"
        );
    }
    // A missing output directory: I/O error, exit 4.
    let o = sim(
        &format!("{kr} --poses 5"),
        &[("--out", Path::new("/nonexistent-robocal-dir/x.csv"))],
    );
    o.assert_code(4);
}

#[test]
fn an_existing_result_is_not_touched_by_a_failed_run() {
    let d = Dir::new();
    let out = d.join("cell.csv");
    let truth = out.with_extension("truth.json");
    sim_ok(
        "--truth kuka-kr480-r3330-table3 --poses 5",
        &[("--out", &out)],
    );
    let before = (std::fs::read(&out).unwrap(), std::fs::read(&truth).unwrap());
    let o = sim(
        "--robot kuka-kr480-r3330 --truth kuka-kr480-r3330-table3 --poses 5 --seed 2 \
         --floor-mm 99999",
        &[("--out", &out)],
    );
    o.assert_code(3);
    assert!(std::fs::read(&out).unwrap() == before.0);
    assert!(std::fs::read(&truth).unwrap() == before.1);
    assert_eq!(files_in(d.path()), ["cell.csv", "cell.truth.json"]);
}
