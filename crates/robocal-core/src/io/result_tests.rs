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
