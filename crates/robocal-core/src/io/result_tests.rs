//! Tests of the result file: its statuses, checks and writing.
use super::*;
use crate::io::result_sections::PointEntry;
use serde_json::{json, Value};

fn good() -> Value {
    let nom = crate::model::presets::preset("kuka-kr480-r3330").unwrap();
    let s = ErrorStats::from_norms(&[1.0, 2.0]);
    let r = CalibrationResult::new(
        RobotInfo::of(&nom),
        CalibrationResult::parameter_entries(&nom, &nom),
        FrameVec::from_tracker_frame(&TrackerFrame::identity()),
        ErrorTables {
            calibration: BeforeAfter {
                before: s,
                after: s,
            },
            validation: Some(BeforeAfter {
                before: s,
                after: s,
            }),
        },
        Status::Calibrated,
    );
    serde_json::to_value(&r).unwrap()
}

fn parse(v: &Value) -> std::result::Result<CalibrationResult, String> {
    let text = serde_json::to_string_pretty(v).unwrap();
    CalibrationResult::parse(&text, Path::new("r.json")).map_err(|e| e.to_string())
}

fn line_of(v: &Value, needle: &str) -> usize {
    let text = serde_json::to_string_pretty(v).unwrap();
    1 + text.lines().position(|l| l.contains(needle)).unwrap()
}

/// `points` is written as declared, not through a sorted `Value`: its keys must come out
/// in the order every other section's do.
#[test]
fn points_are_written_with_sorted_keys() {
    let p = |line, before_mm, after_mm| PointEntry {
        after_mm,
        before_mm,
        line,
    };
    let points = Points {
        calibration: vec![p(2, 1.5, 0.01), p(3, f64::NAN, 0.02)],
        validation: Some(vec![p(9, 2.5, 0.03)]),
    };
    let direct = serde_json::to_string_pretty(&points).unwrap();
    let via_value = serde_json::to_string_pretty(&serde_json::to_value(&points).unwrap());
    assert_eq!(direct, via_value.unwrap());
}

#[test]
fn status_must_be_one_robocal_writes() {
    let mut v = good();
    for s in KNOWN_STATUSES {
        v["status"] = json!(s);
        parse(&v).unwrap();
    }
    v["status"] = json!("bogus");
    let l = line_of(&v, "\"status\"");
    let e = parse(&v).unwrap_err();
    assert!(
        e.contains(&format!(
            "r.json:{l}: field `status`: `bogus` is not a status"
        )) && e.contains("calibrated, partial, implausible"),
        "{e}"
    );
    v["status"] = json!(1);
    assert!(parse(&v).unwrap_err().contains("1 is not a status"));
    v.as_object_mut().unwrap().remove("status");
    let e = parse(&v).unwrap_err();
    assert!(e.contains("r.json: field `status`: missing"), "{e}");
}

#[test]
fn absurd_magnitudes_are_range_errors_naming_the_field() {
    let cases: [(&[&str], Value, &str, &str); 6] = [
        (
            &["parameters", "a2", "calibrated"],
            json!(1e300),
            "parameters.a2.calibrated",
            "1e300 mm is out of range",
        ),
        (
            &["parameters", "alpha2", "nominal"],
            json!(-1e5),
            "parameters.alpha2.nominal",
            "-1e5 deg is out of range",
        ),
        (
            &["parameters", "d4", "std"],
            json!(-0.1),
            "parameters.d4.std",
            "-0.1 mm is out of range",
        ),
        (
            &["tracker_frame", "x"],
            json!(1e308),
            "tracker_frame.x",
            "1e308 mm is out of range",
        ),
        (
            &["tracker_frame", "c"],
            json!(4000.0),
            "tracker_frame.c",
            "4000 deg is out of range",
        ),
        (
            &["errors", "validation", "after", "rms_mm"],
            json!(2e6),
            "errors.validation.after.rms_mm",
            "2000000 mm is out of range",
        ),
    ];
    for (at, x, field, want) in cases {
        let mut v = good();
        let mut t = &mut v;
        for k in &at[..at.len() - 1] {
            t = &mut t[*k];
        }
        t[at[at.len() - 1]] = x;
        let e = parse(&v).unwrap_err();
        assert!(
            e.contains(&format!("field `{field}`: {want}")),
            "{field}: {e}"
        );
        assert!(e.starts_with("r.json:"), "{e}");
    }
    let mut v = good();
    v["tracker_frame"]["x"] = json!(999_999.0);
    v["parameters"]["a2"]["calibrated"] = json!(-999_999.0);
    parse(&v).unwrap();
}

/// A fresh directory for the writing tests.
fn scratch(tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("robocal-result-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn good_result() -> CalibrationResult {
    serde_json::from_value(good()).unwrap()
}

/// The direct read-back of `write` is the reading path's: the same result and robot, and on text
/// the reading path refuses, its message.
#[test]
fn read_back_of_own_text_is_the_reading_path() {
    let r = good_result();
    let text = r.to_text().unwrap();
    let path = Path::new("r.json");
    assert!(crate::io::json_keys::find_duplicate_key(&text)
        .unwrap()
        .is_none());
    let (fast, fast_nominal) = r.read_back(&text, path).unwrap();
    let (slow, slow_nominal) = CalibrationResult::parse_with_nominal(&text, path).unwrap();
    assert_eq!(fast, slow);
    assert_eq!(fast, r);
    assert_eq!(fast_nominal.is_some(), slow_nominal.is_some());
    let mut bad = r.clone();
    bad.parameters["a2"].calibrated = f64::NAN;
    let text = bad.to_text().unwrap();
    let fast = bad.read_back(&text, path).unwrap_err().to_string();
    let slow = CalibrationResult::parse(&text, path)
        .unwrap_err()
        .to_string();
    assert_eq!(fast, slow);
    assert!(fast.contains("parameters.a2.calibrated"), "{fast}");
}

/// Only the flattened `extra` keys can repeat a key in the text robocal writes (see
/// `read_back`): an extra key naming a field is caught, and the result is not written.
#[test]
fn an_extra_key_repeating_a_field_is_not_written() {
    let mut r = good_result();
    r.extra
        .insert("status".to_owned(), serde_json::json!("calibrated"));
    let text = r.to_text().unwrap();
    let dup = crate::io::json_keys::find_duplicate_key(&text).unwrap();
    assert_eq!(dup.map(|d| d.path), Some("status".to_owned()));
    let dir = scratch("dup");
    let out = dir.join("r.json");
    let e = r.write(&out).unwrap_err().to_string();
    assert!(e.contains("appears twice") && e.contains("status"), "{e}");
    assert!(!out.exists());
    // Extra keys of their own are kept and read back.
    let mut r = good_result();
    r.extra.insert("note".to_owned(), serde_json::json!("x"));
    r.write(&out).unwrap();
    assert_eq!(CalibrationResult::read(&out).unwrap(), r);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// What robocal writes, robocal reads: a value its readers refuse is not written.
#[test]
fn a_result_out_of_range_is_not_written() {
    let dir = scratch("range");
    let out = dir.join("r.json");
    let mut r = good_result();
    r.parameters["a2"].calibrated = 1e300;
    let e = r.write(&out).unwrap_err();
    assert!(matches!(e, Error::Implausible(_)), "{e}");
    let e = e.to_string();
    assert!(e.contains("field `parameters.a2.calibrated`"), "{e}");
    assert!(!out.exists());
    good_result().write(&out).unwrap();
    assert_eq!(CalibrationResult::read(&out).unwrap(), good_result());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A calibration's result on simulated data (a perturbed KR 480 measured with a little noise,
/// with validation points).
fn simulated_result() -> CalibrationResult {
    use crate::identification::{calibrate, CalibrationData, CalibrationSettings, Observations};
    use crate::simulation::{random_poses, PoseSampler};
    use rand::{Rng, SeedableRng};
    let nominal = crate::model::presets::preset("kuka-kr480-r3330").unwrap();
    let mut truth = nominal.clone();
    for (k, p) in nominal.params().into_iter().enumerate().take(12) {
        let v = truth.get_display(p) + 0.01 * (k as f64 - 5.5);
        truth.set_display(p, v);
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mut set = |n: usize, first_line: usize| {
        let mut obs = Observations::new(6);
        for (i, q) in random_poses(&nominal, n, &PoseSampler::default(), &mut rng)
            .unwrap()
            .iter()
            .enumerate()
        {
            let noise = nalgebra::Vector3::from_fn(|_, _| rng.gen_range(-0.02..0.02));
            obs.push(q, truth.tool_position(q) + noise, first_line + i)
                .unwrap();
        }
        obs
    };
    let (cal, val) = (set(60, 2), set(20, 2));
    let data = CalibrationData {
        calibration: &cal,
        plane: None,
        validation: Some(&val),
    };
    calibrate(&nominal, data, &CalibrationSettings::default(), &())
        .unwrap()
        .to_result()
}

/// The sorted sections whose types declare their fields in alphabetical order are written
/// directly, not through a `serde_json::Value` (the speed), and either way the text is the same
/// (the bytes).
#[test]
fn sorted_sections_are_written_directly_with_the_same_text() {
    use crate::io::result_key_order::keys_sorted;
    let r = simulated_result();
    let same = |name: &str, v: &dyn erased::Section| {
        assert_eq!(v.direct(), v.via_value(), "{name}");
    };
    let p = r.prediction.as_ref().expect("prediction");
    assert!(!p.map.is_empty());
    assert!(keys_sorted(p), "prediction");
    same("prediction", p);
    let i = r.identifiability.as_ref().expect("identifiability");
    assert!(!i.fixed.is_empty() && !i.identified.is_empty());
    assert!(keys_sorted(i), "identifiability");
    same("identifiability", i);
    let u = r.uncertainty.as_ref().expect("uncertainty");
    assert!(keys_sorted(u), "uncertainty");
    same("uncertainty", u);
    let pl = r.plausibility.as_ref().expect("plausibility");
    assert!(keys_sorted(pl), "plausibility");
    same("plausibility", pl);
    // The sections that keep the `Value` path (a tag or a flattened entry out of order) are
    // still checked for the same text had they been written directly.
    let s = r.solver.as_ref().expect("solver");
    assert!(!keys_sorted(s));
    // The whole file reads back as written.
    let text = r.to_text().unwrap();
    let back = CalibrationResult::parse(&text, Path::new("r.json")).unwrap();
    assert_eq!(back.to_text().unwrap(), text);
}

mod erased {
    /// A section written both ways: pretty text of the value as it serializes, and of its
    /// `serde_json::Value` (keys sorted).
    pub(super) trait Section {
        fn direct(&self) -> String;
        fn via_value(&self) -> String;
    }

    impl<T: serde::Serialize> Section for T {
        fn direct(&self) -> String {
            serde_json::to_string_pretty(self).unwrap()
        }
        fn via_value(&self) -> String {
            serde_json::to_string_pretty(&serde_json::to_value(self).unwrap()).unwrap()
        }
    }
}

/// The read-back of `write` skims the per-point sections (`io::result_skim`): it does not build
/// them, the reading path afterwards does (every value, a NaN written as null included), and a
/// map position its readers would refuse stops the write in memory.
#[test]
fn the_read_back_skims_the_per_point_sections() {
    use crate::io::result_prediction::{MapEntry, PredictionSection};
    use crate::io::result_sections::Points;
    let mut r = good_result();
    let entry = |line: usize, after_mm: f64| PointEntry {
        after_mm,
        before_mm: 1.5,
        line,
    };
    r.points = Some(Points {
        calibration: vec![entry(2, 0.25), entry(3, f64::NAN)],
        validation: Some(vec![entry(7, 0.5)]),
    });
    let spot = MapEntry {
        mean_mm: 0.1,
        model_mm: 0.05,
        x: 1000.0,
        y: -20.0,
        z: 1500.0,
    };
    r.prediction = Some(PredictionSection {
        map: vec![spot; 3],
        mean_mm: 0.1,
        std_mm: 0.02,
        rms_mm: 0.11,
        noise_sigma_mm: 0.03,
        model_rms_mm: 0.04,
    });
    let path = Path::new("r.json");
    let text = r.to_text().unwrap();
    let (back, _) = r.read_back(&text, path).unwrap();
    assert!(back.points.is_none());
    assert!(back.prediction.as_ref().unwrap().map.is_empty());
    let read = CalibrationResult::parse(&text, path).unwrap();
    let points = read.points.as_ref().unwrap();
    assert_eq!(points.calibration.len(), 2);
    assert_eq!(points.calibration[0], entry(2, 0.25));
    assert!(points.calibration[1].after_mm.is_nan());
    assert_eq!(points.validation.as_deref(), Some(&[entry(7, 0.5)][..]));
    assert_eq!(read.prediction.as_ref().unwrap().map, vec![spot; 3]);
    let dir = scratch("skim");
    let out = dir.join("r.json");
    r.write(&out).unwrap();
    let lines = |r: &CalibrationResult| -> Vec<usize> {
        r.points
            .as_ref()
            .unwrap()
            .calibration
            .iter()
            .map(|p| p.line)
            .collect()
    };
    assert_eq!(lines(&CalibrationResult::read(&out).unwrap()), vec![2, 3]);
    std::fs::remove_file(&out).unwrap();
    r.prediction.as_mut().unwrap().map[1].y = f64::NAN;
    let e = r.write(&out).unwrap_err().to_string();
    assert!(e.contains("prediction.map[1]"), "{e}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The per-point sections written apart (`io::result_deferred`) give the bytes of serializing
/// the whole result: a calibration's result, and entries of every kind of number (NaN and
/// infinities written as null, signed zero, the smallest and largest doubles, exponents) with
/// empty, missing and one-entry lists.
#[test]
fn per_point_sections_written_apart_are_the_serialized_bytes() {
    use crate::io::result_prediction::{MapEntry, PredictionSection};
    use crate::io::result_sections::Points;
    let same = |r: &CalibrationResult, split: bool| {
        let d = deferred::split(r, || r.serialized_text()).unwrap();
        assert_eq!(d.is_some(), split);
        let whole = r.serialized_text().unwrap();
        assert_eq!(r.to_text().unwrap(), whole);
        if let Some(d) = d {
            assert_eq!(d.text(), whole);
            // The skeleton is the text with the sections as placeholders.
            assert!(d.skeleton.len() < whole.len());
            assert!(!d.skeleton.contains("after_mm") && !d.skeleton.contains("model_mm"));
        }
    };
    same(&simulated_result(), true);
    let odd = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -0.0,
        0.0,
        f64::MIN_POSITIVE,
        5e-324,
        f64::MAX,
        -1e16,
        1e-7,
        123456789.125,
        0.1 + 0.2,
    ];
    let entry = |k: usize| PointEntry {
        after_mm: odd[k % odd.len()],
        before_mm: odd[(k * 7 + 3) % odd.len()],
        line: [0, 1, 17, usize::MAX][k % 4],
    };
    let spot = |k: usize| MapEntry {
        mean_mm: odd[(k + 1) % odd.len()],
        model_mm: odd[(k * 5) % odd.len()],
        x: odd[(k + 4) % odd.len()],
        y: -odd[(k + 9) % odd.len()],
        z: odd[k % odd.len()],
    };
    let prediction = |n: usize| PredictionSection {
        map: (0..n).map(spot).collect(),
        mean_mm: 0.1,
        std_mm: f64::NAN,
        rms_mm: 0.11,
        noise_sigma_mm: 0.03,
        model_rms_mm: 0.04,
    };
    let lists: [(usize, Option<usize>); 5] = [
        (0, None),
        (0, Some(0)),
        (1, Some(1)),
        (30, None),
        (5, Some(29)),
    ];
    for (k, (cal, val)) in lists.into_iter().enumerate() {
        for with_map in [0, 1, 25] {
            let mut r = good_result();
            r.points = Some(Points {
                calibration: (0..cal).map(|i| entry(i + k)).collect(),
                validation: val.map(|n| (0..n).map(|i| entry(3 * i + 1)).collect()),
            });
            r.prediction = Some(prediction(with_map));
            same(&r, true);
            r.points = None;
            same(&r, with_map > 0);
            r.prediction = None;
            same(&r, false);
        }
    }
    // Extra keys: serialized whole.
    let mut r = simulated_result();
    r.extra.insert("points".to_owned(), json!(null));
    same(&r, false);
}

/// The skeleton `write` reads back is the text read with the per-point sections skimmed: the
/// same result, field for field.
#[test]
fn the_skeleton_reads_as_the_skimmed_text() {
    let r = simulated_result();
    let path = Path::new("r.json");
    let d = deferred::split(&r, || r.serialized_text())
        .unwrap()
        .unwrap();
    let skeleton: CalibrationResult = serde_json::from_str(&d.skeleton).unwrap();
    let (skimmed, _) = r.read_back(&d.text(), path).unwrap();
    // Compared as text: a NaN (written null) is not equal to itself.
    assert_eq!(
        skeleton.serialized_text().unwrap(),
        skimmed.serialized_text().unwrap()
    );
    assert!(skeleton.points.is_none());
    assert!(skeleton.prediction.as_ref().unwrap().map.is_empty());
    r.skeleton_readable(&d.skeleton, path).unwrap();
    // Written in pieces, the file is the text.
    let dir = scratch("skeleton");
    let out = dir.join("r.json");
    r.write(&out).unwrap();
    assert_eq!(std::fs::read_to_string(&out).unwrap(), r.to_text().unwrap());
    // What the whole text's reading refuses, the skeleton's does too, and `write` then gives
    // the whole text's message.
    let mut bad = r.clone();
    bad.tracker_frame.a = 1e9;
    let d = deferred::split(&bad, || bad.serialized_text())
        .unwrap()
        .unwrap();
    assert!(bad.skeleton_readable(&d.skeleton, path).is_err());
    let whole = CalibrationResult::parse(&d.text(), path)
        .unwrap_err()
        .to_string();
    std::fs::remove_file(&out).unwrap();
    let e = bad.write(&out).unwrap_err().to_string();
    assert!(!out.exists());
    assert!(e.ends_with(&whole), "{e}\n{whole}");
    assert!(e.contains("tracker_frame.a"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
