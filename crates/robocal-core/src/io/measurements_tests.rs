//! Tests of [`crate::io::measurements`] (reading) and its writer (`measurements_write`).

use super::*;

fn parse(s: &str, pos: Positions) -> Result<MeasurementSet> {
    parse_measurements(
        s.as_bytes(),
        Path::new("m.csv"),
        &JointSpace::revolute(2),
        pos,
    )
}

#[test]
fn reads_and_carries_extra_columns() {
    let s = parse(
        "id,q1,q2,x,y,z\na,10,20,1,2,3\nb,30,-40,4,5,6\n",
        Positions::Required,
    )
    .unwrap();
    assert_eq!(s.rows.len(), 2);
    assert_eq!(s.extra_columns, vec!["id"]);
    assert_eq!(s.rows[1].extra, vec!["b"]);
    assert_eq!(s.rows[1].line, 3);
    assert!((s.rows[1].q[1] + 40f64.to_radians()).abs() < 1e-15);
    assert_eq!(s.rows[0].p, Some(Vector3::new(1.0, 2.0, 3.0)));
}

#[test]
fn dialects_are_read_and_lines_are_true() {
    let lf = "q1,q2,x,y,z\n\n1,2,7,8,9\n1,5,7,8,9\n";
    for text in [
        lf.to_owned(),
        lf.replace('\n', "\r\n"),
        lf.replace('\n', "\r"),
        lf.replace(',', ";"),
        lf.replace(',', "\t"),
        format!("\u{feff}{}", lf.replace("q", "Q").replace("x,y,z", "X,Y,Z")),
    ] {
        let s = parse(&text, Positions::Required).unwrap();
        assert_eq!(s.rows.iter().map(|r| r.line).collect::<Vec<_>>(), [3, 4]);
        assert_eq!(s.rows[1].q[1], 5f64.to_radians());
    }
    // Errors name the true line, whatever the line endings.
    let bad = "q1,q2,x,y,z\r\n\r\n1,2,7,8,9\r\n1,oops,7,8,9\r\n";
    assert!(err(bad, Positions::Required).contains(":4: field `q2`"));
    assert!(err(&bad.replace("\r\n", "\r"), Positions::Required).contains(":4: field `q2`"));
}

#[test]
fn a_header_that_does_not_match_says_how_it_was_read() {
    let e = err("q1|q2|x|y|z\n1|2|7|8|9\n", Positions::Required);
    assert!(e.contains("read as 1 column separated by commas"), "{e}");
    let e = err("q_1,q_2,x,y,z\n1,2,3,4,5\n", Positions::Required);
    assert!(e.contains("read as 5 columns separated by commas"), "{e}");
    // Names that are robocal's but for separators, units or `joint` are named.
    assert!(e.contains("`q_1` is not `q1`, `q_2` is not `q2`"), "{e}");
    let e = err(
        "Joint1;Joint2;X [mm];y_mm;z\n1;2;3;4;5\n",
        Positions::Required,
    );
    assert!(e.contains("separated by semicolons"), "{e}");
    assert!(
        e.contains("`Joint1` is not `q1`, `Joint2` is not `q2`"),
        "{e}"
    );
    assert!(e.contains("`X [mm]` is not `x`, `y_mm` is not `y`"), "{e}");
    // A joint the robot lacks is no near miss.
    let e = err("q1;q2;j3;x;y;zz\n1;2;3;4;5;6\n", Positions::Required);
    assert!(!e.contains("`j3` is not"), "{e}");
}

/// A decimal comma is read where commas do not separate the columns (`;` or tab), and
/// only there.
#[test]
fn decimal_commas_with_semicolons_or_tabs() {
    for sep in [";", "\t"] {
        let text = "q1;q2;x;y;z\n1,5;2;7,25;8;9\n".replace(';', sep);
        let s = parse(&text, Positions::Required).unwrap();
        assert_eq!(s.rows[0].q[0], 1.5f64.to_radians());
        assert_eq!(s.rows[0].p.unwrap().x, 7.25);
        let bad = "q1;q2;x;y;z\n1,5,1;2;7;8;9\n".replace(';', sep);
        assert!(err(&bad, Positions::Required).contains("`1,5,1` is not a number"));
    }
    // With commas as separators `1,5` is two cells: the row is too long.
    assert!(parse("q1,q2,x,y,z\n1,5,2,7,8,9\n", Positions::Required).is_err());
}

#[test]
fn crlf_and_bom_accepted() {
    let s = parse(
        "\u{feff}q1,q2,x,y,z\r\n10,20,1,2,3\r\n",
        Positions::Required,
    )
    .unwrap();
    assert_eq!(s.rows.len(), 1);
    assert_eq!(s.rows[0].p.unwrap().z, 3.0);
}

fn err(s: &str, pos: Positions) -> String {
    parse(s, pos).unwrap_err().to_string()
}

#[test]
fn rejections_name_line_and_column() {
    let e = err("q1,q2,x,y,z\n1,2,3,4,abc\n", Positions::Required);
    assert!(
        e.contains("m.csv:2: field `z`: `abc` is not a number"),
        "{e}"
    );
    let e = err("q1,q2,x,y,z\n1,2,3,4,5\n1,NaN,3,4,5\n", Positions::Required);
    assert!(e.contains("m.csv:3: field `q2`"), "{e}");
    let e = err("q1,x,y,z\n1,3,4,5\n", Positions::Required);
    assert!(e.contains("field `q2`: missing column"), "{e}");
    let e = err("q1,q2,q3,x,y,z\n1,2,3,3,4,5\n", Positions::Required);
    assert!(e.contains("field `q3`") && e.contains("2 joints"), "{e}");
    let e = err("q1,q2,x,y\n1,2,3,4\n", Positions::Required);
    assert!(e.contains("field `z`: missing column"), "{e}");
    let e = err("q1,q2,x,y,z\n", Positions::Required);
    assert!(e.contains("no data rows"), "{e}");
    let e = err("", Positions::Required);
    assert!(e.contains("empty file"), "{e}");
    let e = err("q1,q2,x,y,z\n1,2,3,4\n", Positions::Required);
    assert!(e.contains("m.csv:2") && e.contains("4 fields"), "{e}");
}

#[test]
fn absurd_magnitudes_name_line_and_column() {
    let e = err(
        "q1,q2,x,y,z\n1,2,3,4,5\n1,1000080,3,4,5\n",
        Positions::Required,
    );
    assert!(
        e.contains("m.csv:3: field `q2`: not a plausible joint value: 1000080 deg is out of range"),
        "{e}"
    );
    let e = err("q1,q2,x,y,z\n1,2,3,4,1e30\n", Positions::Required);
    assert!(
        e.contains("m.csv:2: field `z`: not a plausible tracker reading: 1e30 mm is out of range"),
        "{e}"
    );
    let e = err("q1,q2\n1,-2e5\n", Positions::Ignored);
    assert!(
        e.contains("m.csv:2: field `q2`: not a plausible joint value"),
        "{e}"
    );
    // Multi-turn joints and a tracker 999 m away are fine.
    parse(
        "q1,q2,x,y,z\n36000,-99999,999000,0,-5\n",
        Positions::Required,
    )
    .unwrap();
}

#[test]
fn joint_files_and_warnings() {
    let s = parse("q1,q2\n0.1,0.2\n0.3,-1\n1.2,0.5\n", Positions::Ignored).unwrap();
    assert!(!s.has_positions());
    assert_eq!(s.warnings.len(), 1, "{:?}", s.warnings);
    let s = parse("q1,q2\n10,20\n10,20\n", Positions::Optional).unwrap();
    assert_eq!(s.duplicate_poses(), vec![(2, 3)]);
}

#[test]
fn write_then_read_roundtrip() {
    let s = parse("id,q1,q2,x,y,z\na,10,20,1,2,3\n", Positions::Required).unwrap();
    let p = std::env::temp_dir().join(format!("robocal-m-{}.csv", std::process::id()));
    write_measurements(&p, &s).unwrap();
    let t = read_measurements(&p, &JointSpace::revolute(2), Positions::Required).unwrap();
    std::fs::remove_file(&p).unwrap();
    assert_eq!(t.rows[0].extra, s.rows[0].extra);
    assert!((t.rows[0].q[0] - s.rows[0].q[0]).abs() < 1e-12);
    assert_eq!(t.rows[0].p, s.rows[0].p);
}

fn tracked() -> JointSpace {
    use crate::model::{Controller, JointType};
    let c = Controller::new(vec![1.0, -1.0], vec![100.0, 0.0], vec![]).unwrap();
    JointSpace::new(vec![JointType::Prismatic, JointType::Revolute], Some(c)).unwrap()
}

fn parse_with(s: &str, j: &JointSpace) -> Result<MeasurementSet> {
    parse_measurements(s.as_bytes(), Path::new("m.csv"), j, Positions::Optional)
}

/// A prismatic joint's column is mm, never converted; axis columns go through the controller.
#[test]
fn prismatic_values_and_axis_columns() {
    let j = tracked();
    let s = parse_with("q1,q2\n1500,90\n", &j).unwrap();
    assert_eq!(s.rows[0].q[0], 1500.0);
    assert!((s.rows[0].q[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    // axis1 = 1400 -> q1 = 1500 mm; axis2 = -90 -> q2 = 90 deg.
    let a = parse_with("id,axis2,axis1\nx,-90,1400\n", &j).unwrap();
    assert_eq!(a.rows[0].q, s.rows[0].q);
    assert_eq!(a.extra_columns, vec!["id"]);
    // Written back as model values in display units: mm and degrees.
    let text = String::from_utf8(measurements_csv(&a).unwrap()).unwrap();
    assert_eq!(text, "q1,q2,id\n1500.000000000,90.000000000,x\n");
    // Without a controller map axis values are the joint values.
    let plain = JointSpace::revolute(2);
    let p = parse_with("axis1,axis2\n10,20\n", &plain).unwrap();
    assert!((p.rows[0].q[1] - 20f64.to_radians()).abs() < 1e-15);
    // Small prismatic values do not look like radians; small angles do.
    let w = parse_with("q1,q2\n1,1\n2,2\n3,3\n", &j).unwrap();
    assert_eq!(w.warnings.len(), 1);
    let w = parse_with("q1,q2\n1,10\n2,20\n3,30\n", &j).unwrap();
    assert!(w.warnings.is_empty(), "{:?}", w.warnings);
}

/// Both kinds of joint columns: q is used, and axis must agree with it on every row.
#[test]
fn q_and_axis_columns_must_agree() {
    let j = tracked();
    let s = parse_with("q1,q2,axis1,axis2\n1500,90,1400,-90\n", &j).unwrap();
    assert_eq!(s.rows[0].q[0], 1500.0);
    let e = parse_with("q1,q2,axis1,axis2\n1500,90,1400,-90\n1500,90,1400,90\n", &j)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("m.csv:3: field `axis2`") && e.contains("disagrees"),
        "{e}"
    );
    let e = parse_with("q1,q2,axis1\n1,2,3\n", &j)
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.csv:1: field `axis2`: missing column"), "{e}");
    let e = parse_with("axis1,axis3\n1,2\n", &j)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("field `axis3`") && e.contains("axis1..axis2"),
        "{e}"
    );
    let e = parse_with("id\n1\n", &j).unwrap_err().to_string();
    assert!(
        e.contains("field `q1`: missing column") && e.contains("axis1..axis2"),
        "{e}"
    );
}
