//! Constraint data with the model's families beyond geometry (issue 31): `calibrate` on a
//! constraint file takes `--compliance`, `--harmonics`, `--thermal`, `--backlash` and `--model`
//! as for tracker data (the rows' `temperature_c` and `dir1..dirN` read the same way), prints
//! and records the model choice (`--model auto`, the default), and every reader takes the
//! result with its families.

use crate::util::*;

const KR: &str = "kuka-kr480-r3330";

/// Fixed-point data of a random true robot (4 points x 20 configurations, 0.01 mm) with the
/// distances, and the same rows with a `temperature_c` column (20 to 28 deg C).
struct Data {
    dir: Dir,
    data: std::path::PathBuf,
    warm: std::path::PathBuf,
    dist: std::path::PathBuf,
    /// The mean of `warm`'s temperatures, rounded to 0.1 deg C.
    mean_c: f64,
}

fn data() -> Data {
    let dir = Dir::new();
    let (data, dist) = simulate_constraints(&dir, "point", &[]);
    let text = std::fs::read_to_string(&data).unwrap();
    let mut warm = String::new();
    let mut temps = Vec::new();
    for (i, l) in text.lines().enumerate() {
        if i == 0 {
            warm.push_str(&format!("{l},temperature_c\n"));
        } else {
            let t = 20.0 + (i % 17) as f64 * 0.5;
            temps.push(t);
            warm.push_str(&format!("{l},{t:.1}\n"));
        }
    }
    let mean_c = (temps.iter().sum::<f64>() / temps.len() as f64 * 10.0).round() / 10.0;
    let warm = dir.write("warm.csv", warm);
    Data {
        dir,
        data,
        warm,
        dist,
        mean_c,
    }
}

fn calibrate(
    d: &Data,
    data: &std::path::Path,
    flags: &[&str],
    out: &str,
) -> (Outcome, std::path::PathBuf) {
    let out = d.dir.join(out);
    let mut args = vec![
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(data),
        "--distances",
        p(&d.dist),
        "--out",
        p(&out),
    ];
    args.extend_from_slice(flags);
    (ok(&args), out)
}

#[test]
fn the_default_model_choice_runs_on_constraint_data_and_is_recorded() {
    let d = data();
    let (o, out) = calibrate(&d, &d.data, &[], "auto.json");
    assert!(
        o.stdout().contains("model: geometric (--model auto")
            && o.stdout().contains("geometric + compliance"),
        "{}",
        o.stdout()
    );
    let r = read_json(&out);
    let sel = r["model_selection"]["candidates"].as_array().unwrap();
    assert!(sel.len() >= 3, "{sel:?}");
    assert_eq!(sel.iter().filter(|c| c["chosen"] == true).count(), 1);
    assert!(sel[0]["cv_mean_mm"].as_f64().unwrap() < 0.03, "{sel:?}");
    // --model geometric: the robot as given, no selection.
    let (o, out) = calibrate(&d, &d.data, &["--model", "geometric"], "geo.json");
    assert!(!o.stdout().contains("--model auto"), "{}", o.stdout());
    assert!(read_json(&out)["model_selection"].is_null());
}

#[test]
fn explicit_families_are_fitted_and_every_reader_takes_the_result() {
    let d = data();
    let (o, out) = calibrate(
        &d,
        &d.data,
        &["--compliance", "auto", "--harmonics", "1"],
        "fam.json",
    );
    // The families given are fixed; the geometric model beside them is the reference, and
    // on geometric data they are remarked as fitting the noise.
    assert!(o.stdout().contains("reference"), "{}", o.stdout());
    assert!(o.stdout().contains("remark"), "{}", o.stdout());
    // What constraints cannot see of a family is named.
    assert!(o.stdout().contains("joint compliance:"), "{}", o.stdout());
    let r = read_json(&out);
    let params = r["parameters"].as_object().unwrap();
    for name in ["grav2_o3", "grav3_o4", "tsin1_1", "tcos1_1"] {
        assert_eq!(params[name]["fixed"], false, "{name}: {}", params[name]);
    }
    // evaluate: held-out-style constraint rows under the model with its families.
    let e = ok(&[
        "evaluate",
        "--params",
        p(&out),
        "--data",
        p(&d.data),
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&e.stdout()).unwrap();
    assert_eq!(j["reference"], "constraint");
    let cal = j["calibrated"]["mean_mm"].as_f64().unwrap();
    assert!(cal < 0.03, "{cal}");
    // compensate with the families' deflection.
    let comp = d.dir.join("comp.csv");
    ok(&[
        "compensate",
        "--params",
        p(&out),
        "--joints",
        p(&d.data),
        "--position-only",
        "--out",
        p(&comp),
    ]);
    assert_eq!(read_csv(&comp).1.len(), 80);
    // export: as for a tracker result with families, refused naming them unless the geometry
    // alone is asked for.
    let urdf = d.dir.join("r.urdf");
    let x = robocal(&["export", p(&out), "--format", "urdf", "--out", p(&urdf)]);
    x.assert_code(2);
    assert!(x.stderr().contains("grav2_o3"), "{}", x.stderr());
    for format in ["toml", "urdf"] {
        let f = d.dir.join(format!("r.{format}"));
        ok(&[
            "export",
            p(&out),
            "--format",
            format,
            "--geometry-only",
            "--out",
            p(&f),
        ]);
        assert!(std::fs::read_to_string(&f)
            .unwrap()
            .contains("Feature point:P1"));
    }
    ok(&["fk", "--params", p(&out), "--joints", "0,-90,90,0,30,0"]);
    let rep = d.dir.join("rep");
    let o = ok(&["report", p(&out), "--out", p(&rep)]);
    assert!(
        o.stdout().contains("constraint residuals"),
        "{}",
        o.stdout()
    );
    let html = std::fs::read_to_string(rep.join("report.html")).unwrap();
    assert!(html.contains("grav2_o3") && html.contains("Not identifiable"));
}

#[test]
fn thermal_expansion_reads_the_rows_temperatures() {
    let d = data();
    let (o, out) = calibrate(&d, &d.warm, &["--thermal", "auto"], "warm.json");
    assert!(
        o.stderr()
            .contains(&format!("referred to {:.1} deg C", d.mean_c)),
        "{}",
        o.stderr()
    );
    let r = read_json(&out);
    assert_eq!(r["reference_temperature_c"].as_f64(), Some(d.mean_c));
    assert_eq!(r["parameters"]["thermal_k"]["fixed"], false);
    // evaluate reads the rows' temperatures too.
    let e = ok(&[
        "evaluate",
        "--params",
        p(&out),
        "--data",
        p(&d.warm),
        "--json",
    ]);
    let j: serde_json::Value = serde_json::from_str(&e.stdout()).unwrap();
    assert!(j["calibrated"]["mean_mm"].as_f64().unwrap() < 0.03, "{j}");
    // With --model auto, thermal is a candidate only when the rows have temperatures.
    let (o, _) = calibrate(&d, &d.warm, &[], "a1.json");
    assert!(o.stdout().contains("geometric + thermal"), "{}", o.stdout());
    let (o, _) = calibrate(&d, &d.data, &[], "a2.json");
    assert!(!o.stdout().contains("thermal"), "{}", o.stdout());
}

#[test]
fn families_without_their_columns_are_refused() {
    let d = data();
    for (flag, want) in [("--thermal", "temperature_c"), ("--backlash", "dir1..dirN")] {
        let out = d.dir.join("x.json");
        let o = robocal(&[
            "calibrate",
            "--robot",
            KR,
            "--data",
            p(&d.data),
            "--distances",
            p(&d.dist),
            flag,
            "auto",
            "--out",
            p(&out),
        ]);
        o.assert_code(3);
        assert!(o.stderr().contains(want), "{flag}: {}", o.stderr());
        assert!(!out.exists());
    }
}

#[test]
fn a_sagging_robot_gets_compliance_by_default() {
    // simulate --constraint with gravity in the truth (joints 2 and 3 compliant, the paper's
    // masses and payload), then the default calibrate.
    let dir = Dir::new();
    let (data, dist) = simulate_constraints(
        &dir,
        "point",
        &[
            "--compliance",
            "0,2e-8,2e-8,0,0,0",
            "--link-masses-kg",
            "900,500,400,150,60,20",
            "--payload-kg",
            "300",
        ],
    );
    let truth = read_json(&dir.join("point.truth.json"));
    assert_eq!(truth["settings"]["gravity"]["payload_kg"], 300.0, "{truth}");
    let out = dir.join("r.json");
    let o = ok(&[
        "calibrate",
        "--robot",
        KR,
        "--data",
        p(&data),
        "--distances",
        p(&dist),
        "--out",
        p(&out),
    ]);
    assert!(
        o.stdout().contains("model: geometric + compliance"),
        "{}",
        o.stdout()
    );
    let r = read_json(&out);
    let chosen: Vec<&serde_json::Value> = r["model_selection"]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["chosen"] == true)
        .collect();
    assert_eq!(chosen[0]["families"], serde_json::json!(["compliance"]));
    // Gravity without a mass is refused, as in the tracker mode.
    let o = robocal(&[
        "simulate",
        "--robot",
        KR,
        "--truth",
        "random",
        "--constraint",
        "point",
        "--compliance",
        "1e-8",
        "--out",
        p(&dir.join("x.csv")),
    ]);
    o.assert_code(2);
    assert!(!dir.join("x.csv").exists());
}
