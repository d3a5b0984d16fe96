//! `robocal import`: a simulated session written in each vendor's layout, imported and
//! calibrated, gives the parameters of the simulator's own CSV; time matching finds the clock
//! offset and pairs every point with its dwell; bad inputs are exit 3 with nothing written; the
//! shipped examples are what the simulator and the layout writers make.

mod layouts;

use crate::util::*;
use layouts::Session;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};

/// `robocal simulate` of `poses` poses (no plane points), with a 6-DoF probe if `probe`.
fn simulate(dir: &Dir, name: &str, poses: usize, seed: u64, probe: bool) -> PathBuf {
    let out = dir.join(name);
    let mut args = vec![
        "simulate".to_owned(),
        "--robot".into(),
        KUKA.into(),
        "--truth".into(),
        TRUTH.into(),
        "--poses".into(),
        poses.to_string(),
        "--no-plane".into(),
        "--seed".into(),
        seed.to_string(),
        "--out".into(),
        p(&out).into(),
    ];
    if probe {
        args.extend(["--orientation-sigma-deg".into(), "0.001".into()]);
    }
    ok(&args);
    out
}

/// `robocal import` with `args` (after `import`), writing `out`.
fn import(args: &[&str], out: &Path) -> Outcome {
    let mut a = vec!["import", "--out", p(out)];
    a.extend_from_slice(args);
    robocal(&a)
}

/// The calibrated parameters of a measurement CSV (geometric model).
fn calibrated(dir: &Dir, data: &Path) -> Vec<(String, f64)> {
    let out = dir.join(format!(
        "{}.json",
        data.file_name().unwrap().to_string_lossy()
    ));
    ok(&[
        "calibrate",
        "--robot",
        KUKA,
        "--data",
        p(data),
        "--model",
        "geometric",
        "--out",
        p(&out),
    ]);
    let json = read_json(&out);
    json["parameters"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v["calibrated"].as_f64().unwrap()))
        .collect()
}

fn assert_same_parameters(what: &str, a: &[(String, f64)], b: &[(String, f64)]) {
    assert_eq!(a.len(), b.len(), "{what}");
    for ((na, va), (nb, vb)) in a.iter().zip(b) {
        assert_eq!(na, nb, "{what}");
        assert!((va - vb).abs() <= 1e-9, "{what}: {na} {va} vs {vb}");
    }
}

#[test]
fn every_layout_round_trips_to_the_simulators_calibration() {
    let dir = Dir::new();
    let sim = simulate(&dir, "sim.csv", 40, 11, false);
    let s = Session::read(&sim);
    let base = calibrated(&dir, &sim);
    let cases: Vec<(&str, String, &str, String, Vec<&str>)> = vec![
        (
            "sa",
            layouts::sa(&s),
            "joints.csv",
            layouts::joints_q(&s),
            vec!["--match", "name"],
        ),
        (
            "xyz",
            layouts::xyz(&s),
            "kuka.csv",
            layouts::joints_kuka(&s),
            vec![
                "--match",
                "name",
                "--length-unit",
                "in",
                "--joint-columns",
                "A1,A2,A3,A4,A5,A6",
                "--name-column",
                "Point",
                "--robot",
                KUKA,
            ],
        ),
        (
            "txt",
            layouts::text(&s),
            "joints.txt",
            layouts::joints_text(&s),
            vec!["--match", "order", "--length-unit", "mm"],
        ),
        (
            "csv",
            layouts::csv(&s),
            "joints.csv",
            layouts::joints_q(&s),
            vec!["--match", "name"],
        ),
    ];
    for (ext, points, jname, joints, args) in cases {
        let pf = dir.write(format!("points.{ext}"), points);
        let jf = dir.write(format!("{ext}-{jname}"), joints);
        let out = dir.join(format!("imported-{ext}.csv"));
        let mut a = vec!["--points", p(&pf), "--joints", p(&jf)];
        a.extend(args.iter().copied());
        let o = import(&a, &out);
        o.assert_ok();
        assert!(o.stdout().contains("paired by"), "{}", o.stdout());
        assert!(o.stdout().contains("40 of 40 points"), "{}", o.stdout());
        assert_same_parameters(ext, &calibrated(&dir, &out), &base);
    }

    // A 6-DoF probe in a Leica export (quaternions), paired by order, and by time with an RTDE
    // log.
    let sim = simulate(&dir, "probe.csv", 30, 12, true);
    let s = Session::read(&sim);
    let base = calibrated(&dir, &sim);
    let times: Vec<f64> = (0..s.rows.len())
        .map(|k| 3600.0 + 10.0 * k as f64)
        .collect();
    let lf = dir.write("probe-leica.csv", layouts::leica(&s, &times, false));
    let jf = dir.write("probe-joints.csv", layouts::joints_q(&s));
    let out = dir.join("imported-leica.csv");
    let o = import(
        &["--points", p(&lf), "--joints", p(&jf), "--match", "order"],
        &out,
    );
    o.assert_ok();
    assert!(
        o.stdout().contains("read as leica (detected"),
        "{}",
        o.stdout()
    );
    let (h, _) = read_csv(&out);
    for c in ["a", "b", "c", "temperature_c", "time_s"] {
        col(&h, c);
    }
    assert_same_parameters("leica", &calibrated(&dir, &out), &base);

    let poses: Vec<Vec<f64>> = s
        .rows
        .iter()
        .map(|r| s.q(r).iter().map(|v| num(v)).collect())
        .collect();
    let n = poses.len();
    let moves: Vec<f64> = (0..n).map(|k| 1.5 + (k * 7 % 5) as f64 * 0.4).collect();
    let (log, mids) = layouts::rtde(&poses, &moves, &vec![1.5; n], 125.0, 1000.0);
    let times: Vec<f64> = mids.iter().map(|m| m - 1000.0 + 3600.0).collect();
    let lf = dir.write("probe-timed.csv", layouts::leica(&s, &times, false));
    let rf = dir.write("probe-rtde.txt", log);
    let out = dir.join("imported-rtde.csv");
    import(
        &["--points", p(&lf), "--joints", p(&rf), "--match", "time"],
        &out,
    )
    .assert_ok();
    assert_same_parameters("rtde", &calibrated(&dir, &out), &base);
}

/// A session of `n` poses and its joint log at 125 Hz: irregular moves and dwells, one pose the
/// tracker missed and one extra stop; tracker times with 3 ms jitter and a clock 5 hours ahead.
struct Timed {
    points: PathBuf,
    log: PathBuf,
    offset: f64,
    /// Dwell middles (log clock) of the missed point and the extra stop.
    unmeasured: [f64; 2],
    session: Session,
    missed: usize,
}

/// 11.10.2022 00:00 as seconds since 1970 (the day of [`layouts::leica_time`]).
const MIDNIGHT: f64 = 1_665_446_400.0;

fn timed(dir: &Dir) -> Timed {
    let sim = simulate(dir, "timed.csv", 30, 21, false);
    let s = Session::read(&sim);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut poses: Vec<Vec<f64>> = s
        .rows
        .iter()
        .map(|r| s.q(r).iter().map(|v| num(v)).collect())
        .collect();
    let extra_at = 17;
    let extra: Vec<f64> = poses[extra_at - 1]
        .iter()
        .zip(&poses[extra_at])
        .map(|(a, b)| 0.5 * (a + b))
        .collect();
    poses.insert(extra_at, extra);
    let n = poses.len();
    let moves: Vec<f64> = (0..n).map(|_| rng.gen_range(1.5..4.0)).collect();
    let dwells: Vec<f64> = (0..n).map(|_| rng.gen_range(1.0..2.5)).collect();
    let t0 = 8123.25;
    let (log, mids) = layouts::rtde(&poses, &moves, &dwells, 125.0, t0);
    let offset = 5.0 * 3600.0 + 0.3717;
    let missed = 9;
    let mut tracker_times = Vec::new();
    let mut rows = Vec::new();
    for (k, r) in s.rows.iter().enumerate() {
        let dwell = if k >= extra_at { k + 1 } else { k };
        if k == missed {
            continue;
        }
        let jitter: f64 =
            0.003 * (rng.gen::<f64>() + rng.gen::<f64>() + rng.gen::<f64>() - 1.5) * 2.0;
        tracker_times.push(mids[dwell] + offset + jitter);
        rows.push(r.clone());
    }
    // The export's time stamps are dates: seconds after 11.10.2022 00:00.
    let kept = Session {
        header: s.header.clone(),
        rows,
    };
    let points = dir.write(
        "timed-leica.csv",
        layouts::leica(&kept, &tracker_times, true),
    );
    let log = dir.write("timed-rtde.txt", log);
    Timed {
        points,
        log,
        offset: MIDNIGHT + offset,
        unmeasured: [mids[missed], mids[extra_at]],
        session: s,
        missed,
    }
}

#[test]
fn time_matching_finds_the_offset_and_pairs_every_point() {
    let dir = Dir::new();
    let t = timed(&dir);
    let out = dir.join("paired.csv");
    let o = import(
        &[
            "--points",
            p(&t.points),
            "--joints",
            p(&t.log),
            "--match",
            "time",
        ],
        &out,
    );
    o.assert_ok();
    let text = o.stdout();
    assert!(
        text.contains("paired by time: 29 of 29 points; 0 points and 2 dwells left unpaired"),
        "{text}"
    );
    let found: f64 = text
        .split("clock offset (tracker minus joint log): ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .map(num)
        .unwrap();
    assert!(
        (found - t.offset).abs() < 0.010,
        "found {found}, true {}",
        t.offset
    );
    // The unpaired dwells are the missed point's and the extra stop's.
    let listed: Vec<&str> = text
        .lines()
        .filter(|l| l.contains("joints without a point: dwell"))
        .collect();
    assert_eq!(listed.len(), 2, "{text}");
    for (l, mid) in listed.iter().zip(t.unmeasured) {
        let span = l.split("dwell ").nth(1).unwrap().split(' ').next().unwrap();
        let (a, b) = span.split_once("..").unwrap();
        assert!(num(a) < mid && mid < num(b), "{l} should hold {mid}");
    }
    // Every point got its own pose's joints.
    let (h, rows) = read_csv(&out);
    assert_eq!(rows.len(), 29);
    let s = &t.session;
    let expected: Vec<&Vec<String>> = s
        .rows
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != t.missed)
        .map(|(_, r)| r)
        .collect();
    for (r, e) in rows.iter().zip(expected) {
        for (k, q) in s.q(e).iter().enumerate() {
            let got = num(&r[col(&h, &format!("q{}", k + 1))]);
            assert!((got - num(q)).abs() < 1e-9, "{got} vs {q}");
        }
        assert_eq!(&r[col(&h, "x")], s.get(e, "x"));
    }
    col(&h, "sigma_mm");
    // The offset given pairs the same.
    let out2 = dir.join("given.csv");
    let off = format!("{}", t.offset);
    import(
        &[
            "--points",
            p(&t.points),
            "--joints",
            p(&t.log),
            "--match",
            "time",
            "--time-offset",
            &off,
        ],
        &out2,
    )
    .assert_ok();
    let (_, rows2) = read_csv(&out2);
    let qcols: Vec<usize> = (1..=6).map(|k| col(&h, &format!("q{k}"))).collect();
    for (a, b) in rows.iter().zip(&rows2) {
        for &c in &qcols {
            assert_eq!(a[c], b[c]);
        }
    }
}

/// `robocal import` on bad input: exit 3, the message holds `says`, nothing written.
fn rejects(dir: &Dir, args: &[&str], says: &[&str]) {
    let out = dir.join("never.csv");
    let o = import(args, &out);
    o.assert_code(3);
    let e = o.stderr();
    for s in says {
        assert!(e.contains(s), "expected `{s}` in: {e}");
    }
    assert!(!out.exists(), "{} written", out.display());
}

#[test]
fn bad_inputs_are_exit_3_with_nothing_written() {
    let dir = Dir::new();
    let sim = simulate(&dir, "bad.csv", 12, 31, true);
    let s = Session::read(&sim);
    let times: Vec<f64> = (0..s.rows.len()).map(|k| 100.0 + 5.0 * k as f64).collect();
    let leica = layouts::leica(&s, &times, true);
    let joints = dir.write("joints.csv", layouts::joints_q(&s));
    let j = p(&joints);

    // A truncated export: the last row cut in the middle.
    let cut = &leica[..leica.len() - 60];
    let f = dir.write("truncated.csv", cut);
    rejects(
        &dir,
        &["--points", p(&f), "--joints", j, "--match", "order"],
        &["truncated.csv:13", "fields where the header"],
    );

    // A quaternion that is not unit.
    let mut lines: Vec<String> = leica.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[3].split(',').map(String::from).collect();
    cells[6] = format!("{}", num(&cells[6]) * 1.2 + 0.1);
    lines[3] = cells.join(",");
    let f = dir.write("quat.csv", lines.join("\n"));
    rejects(
        &dir,
        &["--points", p(&f), "--joints", j, "--match", "order"],
        &["quat.csv:4: field `Q0..Q3`", "not 1"],
    );

    // Mismatched counts.
    let good = dir.write("good.csv", &leica);
    let short: String = layouts::joints_q(&s)
        .lines()
        .take(s.rows.len())
        .map(|l| format!("{l}\n"))
        .collect();
    let f = dir.write("short.csv", short);
    rejects(
        &dir,
        &["--points", p(&good), "--joints", p(&f), "--match", "order"],
        &["12 points", "11 rows", "counts must agree"],
    );

    // A joint log without dwells: always moving.
    let mut log = String::from(
        "timestamp actual_q_0 actual_q_1 actual_q_2 actual_q_3 actual_q_4 actual_q_5\n",
    );
    for k in 0..2000 {
        let v = 0.001 * k as f64;
        log.push_str(&format!("{} {v} {v} {v} {v} {v} {v}\n", k as f64 * 0.008));
    }
    let f = dir.write("moving.txt", log);
    rejects(
        &dir,
        &["--points", p(&good), "--joints", p(&f), "--match", "time"],
        &["no dwells", "--dwell-min-s", "--still-deg"],
    );

    // Unit mix-ups: a file in metres said to be in millimetres, and metres read as millimetres.
    let sa = dir.write("m.sa", layouts::sa(&s));
    rejects(
        &dir,
        &[
            "--points",
            p(&sa),
            "--joints",
            j,
            "--match",
            "name",
            "--length-unit",
            "mm",
        ],
        &["in m", "--length-unit says mm"],
    );
    let metres: String = s
        .rows
        .iter()
        .map(|r| s.xyz(r).map(|v| format!("{}", num(v) / 1000.0)).join(" ") + "\n")
        .collect();
    let f = dir.write("metres.txt", metres);
    rejects(
        &dir,
        &[
            "--points",
            p(&f),
            "--joints",
            j,
            "--match",
            "order",
            "--length-unit",
            "mm",
        ],
        &["lie within", "--length-unit"],
    );
    rejects(
        &dir,
        &["--points", p(&f), "--joints", j, "--match", "order"],
        &["does not say its length unit", "--length-unit"],
    );

    // A decimal comma with comma separators.
    let f = dir.write("comma.csv", "x,y,z\n1,5,2,5,3,5\n");
    rejects(
        &dir,
        &["--points", p(&f), "--joints", j, "--match", "order"],
        &["comma.csv:2", "decimal commas with comma separators"],
    );

    // Pairing by name without names in the export.
    rejects(
        &dir,
        &["--points", p(&good), "--joints", j, "--match", "name"],
        &["good.csv:2", "no name", "--match"],
    );
}

/// The files of `examples/import/`: one simulated session of the KR 480 (30 poses, a 6-DoF
/// probe) in every layout, and its first 12 poses as a timed Leica export with a 125 Hz RTDE log.
fn example_files(dir: &Dir) -> Vec<(&'static str, String)> {
    let sim = simulate(dir, "example.csv", 30, 28, true);
    let s = Session::read(&sim);
    let times: Vec<f64> = (0..s.rows.len())
        .map(|k| 15.0 * 3600.0 + 12.5 * k as f64)
        .collect();
    let first = Session {
        header: s.header.clone(),
        rows: s.rows[..12].to_vec(),
    };
    let poses: Vec<Vec<f64>> = first
        .rows
        .iter()
        .map(|r| first.q(r).iter().map(|v| num(v)).collect())
        .collect();
    let moves: Vec<f64> = (0..12).map(|k| 0.8 + (k * 7 % 5) as f64 * 0.2).collect();
    let dwells: Vec<f64> = (0..12).map(|k| 0.7 + (k * 3 % 4) as f64 * 0.1).collect();
    let (log, mids) = layouts::rtde(&poses, &moves, &dwells, 125.0, 52_417.5);
    // The tracker's clock runs 1 h 12 min 3.25 s ahead of the robot's (plus 2 ms here and there).
    let timed: Vec<f64> = mids
        .iter()
        .enumerate()
        .map(|(k, m)| m - 52_417.5 + 9.0 * 3600.0 + 4323.25 + [0.0, 0.002, -0.002][k % 3])
        .collect();
    vec![
        ("kr480-leica.csv", layouts::leica(&s, &times, true)),
        ("kr480-joints.csv", layouts::joints_q(&s)),
        ("kr480-sa.txt", layouts::sa(&s)),
        ("kr480-points.xyz", layouts::xyz(&s)),
        ("kr480-kuka-axes.csv", layouts::joints_kuka(&s)),
        ("kr480-points.txt", layouts::text(&s)),
        ("kr480-joints.txt", layouts::joints_text(&s)),
        ("kr480-points.csv", layouts::csv(&s)),
        (
            "kr480-timed-leica.csv",
            layouts::leica(&first, &timed, true),
        ),
        ("kr480-rtde.txt", log),
    ]
}

/// `examples/import/` is what [`example_files`] makes; `ROBOCAL_WRITE_EXAMPLE=1` rewrites it.
#[test]
fn the_shipped_import_examples_are_the_generator() {
    let dir = Dir::new();
    let shipped = root().join("examples/import");
    for (name, made) in example_files(&dir) {
        let f = shipped.join(name);
        if std::env::var_os("ROBOCAL_WRITE_EXAMPLE").is_some() {
            std::fs::create_dir_all(&shipped).unwrap();
            std::fs::write(&f, &made).unwrap();
            continue;
        }
        let have = std::fs::read_to_string(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(
            have == made,
            "{name}: regenerate with ROBOCAL_WRITE_EXAMPLE=1"
        );
    }
}
