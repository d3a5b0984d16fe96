//! The real cell's families on the command line: a simulated session with backlash and thermal
//! growth calibrated with `--backlash auto --thermal auto`; `evaluate` reads the data's
//! temperature and approach directions; `compensate --temperature-c` folds the arm's
//! temperature and the approach from below into the commanded joints and writes the directions
//! it assumes (`dir1..dirN`).

use crate::util::*;
use std::path::Path;

/// `evaluate --json` of `res` on `data`.
fn evaluated(res: &Path, data: &Path) -> serde_json::Value {
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
    serde_json::from_str(&o.stdout()).unwrap()
}

#[test]
fn evaluate_reads_the_conditions_and_compensate_folds_them_and_writes_the_approach() {
    let dir = Dir::new();
    let (cell, val) = (dir.join("cell.csv"), dir.join("val.csv"));
    ok(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "60",
        "--validation",
        "40",
        "--seed",
        "5",
        "--backlash-deg",
        "auto",
        "--thermal",
        "auto",
        "--out",
        p(&cell),
        "--validation-out",
        p(&val),
    ]);
    let (fam, geo) = (dir.join("fam.json"), dir.join("geo.json"));
    let calibrate = |out: &Path, families: &[&str]| {
        let mut a = vec![
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            p(&cell),
            "--model",
            "geometric",
            "--out",
            p(out),
        ];
        a.extend_from_slice(families);
        ok(&a);
    };
    calibrate(&fam, &["--backlash", "auto", "--thermal", "auto"]);
    calibrate(&geo, &[]);

    // evaluate under each row's temperature and approach: the families follow the cell, the
    // geometric model cannot.
    let (vf, vg) = (evaluated(&fam, &val), evaluated(&geo, &val));
    let mean = |v: &serde_json::Value| v["calibrated"]["mean_mm"].as_f64().unwrap();
    let (f, g) = (mean(&vf), mean(&vg));
    eprintln!("validation by evaluate: families {f:.4} mm, geometric {g:.4} mm");
    assert!(f < 0.6 * g && f < 0.08, "families {f} vs geometric {g}");
    // What each family explains: the calibrated model without it is worse on these data; the
    // geometric result has nothing to take away.
    let without = |k: &str| vf["calibrated_without"][k]["mean_mm"].as_f64().unwrap();
    let (t, b) = (without("thermal"), without("backlash"));
    eprintln!("families without the temperature {t:.4} mm, without the directions {b:.4} mm");
    assert!(t > f && b > f, "{t} {b} vs {f}");
    assert!(vg.get("calibrated_without").is_none());

    // The desired poses: the validation joints alone.
    let (h, rows) = read_csv(&val);
    let desired = dir.join("desired.csv");
    let mut text = String::from("q1,q2,q3,q4,q5,q6\n");
    for r in &rows {
        let q: Vec<&str> = (1..=6)
            .map(|j| r[col(&h, &format!("q{j}"))].as_str())
            .collect();
        text.push_str(&q.join(","));
        text.push('\n');
    }
    std::fs::write(&desired, text).unwrap();
    let compensate = |res: &Path, t: Option<&str>, out: &Path| {
        let mut a = vec![
            "compensate",
            "--robot",
            KUKA,
            "--params",
            p(res),
            "--joints",
            p(&desired),
            "--position-only",
            "--out",
            p(out),
        ];
        if let Some(t) = t {
            a.extend_from_slice(&["--temperature-c", t]);
        }
        robocal(&a)
    };
    let (warm, reference) = (dir.join("warm.csv"), dir.join("reference.csv"));
    compensate(&fam, Some("27.5"), &warm).assert_ok();
    let o = compensate(&fam, None, &reference);
    o.assert_ok();
    assert!(
        o.stderr().contains("reference temperature"),
        "{}",
        o.stderr()
    );
    // The approach the commanded joints assume is written beside them.
    let (hw, warm_rows) = read_csv(&warm);
    for j in 1..=6 {
        let k = col(&hw, &format!("dir{j}"));
        assert!(warm_rows.iter().all(|r| r[k] == "1"), "dir{j}");
    }
    // The warm arm is longer: its commanded joints differ from those at the reference.
    let (hr, ref_rows) = read_csv(&reference);
    let mut most = 0.0_f64;
    for (a, b) in warm_rows.iter().zip(&ref_rows) {
        for j in 1..=6 {
            let q = format!("q{j}");
            most = most.max((num(&a[col(&hw, &q)]) - num(&b[col(&hr, &q)])).abs());
        }
    }
    eprintln!("largest joint change, 27.5 deg C against the reference: {most:.5} deg");
    assert!(most > 5e-4, "{most}");

    // A temperature no robot has, and one for a calibration without thermal expansion: usage
    // errors naming the flag, nothing written.
    for (res, t, needle) in [
        (&fam, "500", "--temperature-c 500"),
        (&geo, "25", "no thermal expansion"),
    ] {
        let out = dir.join("never.csv");
        let o = compensate(res, Some(t), &out);
        o.assert_code(2);
        assert!(o.stderr().contains(needle), "{}", o.stderr());
        assert!(!out.exists());
    }
}

/// `evaluate` of the honest demo's verification (measured from another station, registered
/// again): the gap to the prediction split in quadrature into the registration's share and
/// what is left, with the repeatability beside the prediction's noise.
#[test]
fn evaluate_splits_the_verification_gap() {
    let dir = Dir::new();
    let demo = dir.join("demo");
    ok(&["demo", "--seed", "1", "--out", p(&demo)]);
    let (res, verify) = (demo.join("result.json"), demo.join("verify.csv"));
    let run = |extra: &[&str]| {
        let mut a = vec![
            "evaluate",
            "--params",
            p(&res),
            "--data",
            p(&verify),
            "--refit-frame",
        ];
        a.extend_from_slice(extra);
        robocal(&a)
    };
    let o = run(&["--json"]);
    o.assert_ok();
    let v: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    let g = &v["gap"];
    let f = |x: &serde_json::Value| x.as_f64().unwrap();
    let (ver, pred, gap, left) = (
        f(&g["verified_rms_mm"]),
        f(&g["predicted_rms_mm"]),
        f(&g["gap_rms_mm"]),
        f(&g["left_rms_mm"]),
    );
    let s = &g["station"];
    let (n, sigma, station) = (f(&s["points"]), f(&s["residual_sigma_mm"]), f(&s["rms_mm"]));
    eprintln!(
        "verification {ver:.4} mm RMS, predicted {pred:.4}, gap {gap:.4}: station {station:.4} \
         ({n} points, sigma {sigma:.4}), left {left:.4}; repeatability {}",
        g["repeatability"]
    );
    // The measured RMS is evaluate's own; the prediction the result's.
    assert_eq!(ver, f(&v["desired"]["rms_mm"]));
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&res).unwrap()).unwrap();
    assert_eq!(pred, f(&r["prediction"]["rms_mm"]));
    // The parts add in quadrature; the registration of 75 points takes a small share.
    assert!((gap * gap - (ver * ver - pred * pred)).abs() < 1e-12);
    assert!((left * left + station * station - gap * gap).abs() < 1e-12);
    assert_eq!(n, 75.0);
    assert!((station - sigma * (6.0 / n).sqrt()).abs() < 1e-12);
    assert!(station > 0.0 && station < 0.5 * gap, "{station} vs {gap}");
    // Repeatability: the class default, or the given RP as an isotropic scatter's RMS.
    let rep = f(&g["repeatability"]["rms_mm"]);
    assert!(rep > 0.0 && rep < f(&g["repeatability"]["predicted_noise_rms_mm"]));
    let o = run(&["--json", "--repeatability-mm", "0.08"]);
    let w: serde_json::Value = serde_json::from_str(&o.stdout()).unwrap();
    let given = f(&w["gap"]["repeatability"]["rms_mm"]);
    assert!(
        (given - 3.0_f64.sqrt() * 0.08 / 3.6161).abs() < 1e-12,
        "{given}"
    );
    // The table says it in words; a repeatability that is none is a usage error.
    let text = run(&[]).stdout();
    assert!(
        text.contains("the fresh station's registration (75 points"),
        "{text}"
    );
    for bad in ["-1", "0", "nan"] {
        let o = run(&["--repeatability-mm", bad]);
        o.assert_code(2);
        assert!(
            o.stderr().contains("--repeatability-mm: repeatability_mm"),
            "{}",
            o.stderr()
        );
    }
}

/// An arm that warms unevenly (`simulate --thermal-link-gain`), measured across its whole
/// warm-up without noise: `calibrate --thermal per-link` recovers each link's coefficient (the
/// simulated 11.5 ppm/K times its gain), link 5 (no length) fixed with its reason; the lumped
/// coefficient leaves an error the per-link model does not.
#[test]
fn per_link_thermal_follows_an_uneven_warm_up() {
    let dir = Dir::new();
    let (cell, val) = (dir.join("cell.csv"), dir.join("val.csv"));
    ok(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "300",
        "--validation",
        "40",
        "--seed",
        "4",
        "--noise-mm",
        "0",
        "--noise-per-m",
        "0",
        "--thermal",
        "auto",
        "--thermal-rise-c",
        "30",
        "--seconds-per-pose",
        "30",
        "--thermal-link-gain",
        "0.6,1.5,1.3,0.8,0,1.1",
        "--out",
        p(&cell),
        "--validation-out",
        p(&val),
    ]);
    let fit = |thermal: &str| {
        let out = dir.join(format!("{thermal}.json"));
        ok(&[
            "calibrate",
            "--robot",
            KUKA,
            "--data",
            p(&cell),
            "--validate",
            p(&val),
            "--model",
            "geometric",
            "--objective",
            "least-squares",
            "--thermal",
            thermal,
            "--out",
            p(&out),
        ]);
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
        v
    };
    let (per, lumped) = (fit("per-link"), fit("auto"));
    let val_mean = |v: &serde_json::Value| {
        v["errors"]["validation"]["after"]["mean_mm"]
            .as_f64()
            .unwrap()
    };
    let (vp, vl) = (val_mean(&per), val_mean(&lumped));
    eprintln!("uneven warm-up: validation {vp:.5} mm per link, {vl:.5} mm lumped");
    assert!(vp < 0.2 * vl && vp < 0.005, "{vp} vs {vl}");
    let k = |j: usize| &per["parameters"][format!("thermal_k{j}")];
    assert_eq!(k(5)["fixed"], true, "{}", k(5));
    for (j, g) in [(1, 0.6), (2, 1.5), (3, 1.3), (4, 0.8), (6, 1.1)] {
        let got = k(j)["calibrated"].as_f64().unwrap();
        let want = 11.5 * g;
        eprintln!("thermal_k{j}: {got:.4} ppm/K, simulated {want:.4}");
        assert!(
            (got - want).abs() < 0.02 * want,
            "thermal_k{j}: {got} vs {want}"
        );
    }
    // A gain for a link the robot does not have is refused by name.
    let o = robocal(&[
        "simulate",
        "--robot",
        KUKA,
        "--truth",
        TRUTH,
        "--poses",
        "10",
        "--thermal",
        "auto",
        "--thermal-link-gain",
        "1,1,1",
        "--out",
        p(&dir.join("never.csv")),
    ]);
    assert_ne!(o.code(), Some(0));
    assert!(o.stderr().contains("thermal.link_gain"), "{}", o.stderr());
    assert!(!dir.join("never.csv").exists());
}
