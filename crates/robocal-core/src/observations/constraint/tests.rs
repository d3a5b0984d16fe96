use super::*;
use crate::io::{parse_measurements, Positions};
use crate::model::JointSpace;

fn read(text: &str) -> Result<ConstraintData> {
    let set = parse_measurements(
        text.as_bytes(),
        Path::new("c.csv"),
        &JointSpace::revolute(2),
        Positions::Ignored,
    )?;
    ConstraintData::from_measurements(&set)
}

fn err(text: &str) -> String {
    read(text).unwrap_err().to_string()
}

#[test]
fn reads_points_spheres_and_planes() {
    let d = read(
        "q1,q2,constraint,radius_mm\n1,2,point:A,\n3,4,point:A,\n5,6,sphere:S,25\n7,8,sphere:S,25\n\
         9,1,sphere:S,25\n2,3,sphere:S,25\n1,1,plane:F,\n2,2,plane:F,\n3,1,plane:F,\n",
    )
    .unwrap();
    assert_eq!(d.features.len(), 3);
    assert_eq!(d.features[1].radius_mm, Some(25.0));
    assert_eq!(d.features[2].kind, ConstraintKind::Plane);
    assert_eq!(d.rows.len(), 9);
    assert_eq!(d.rows[4].feature, 1);
    assert_eq!(d.rows[4].line, 6);
    assert!((d.rows[0].q[1] - 2f64.to_radians()).abs() < 1e-15);
    assert!(d.has_known_length());
}

#[test]
fn bad_rows_are_errors_naming_file_line_and_column() {
    let e = err("q1,q2,constraint\n1,2,point:A\n3,4,point:A\n5,6,point:B\n");
    assert!(
        e.contains("c.csv:4") && e.contains("constraint") && e.contains("point:B"),
        "{e}"
    );
    assert!(e.contains("used on 1 row"), "{e}");
    let e = err(
        "q1,q2,constraint,radius_mm\n1,2,sphere:S,25\n3,4,sphere:S,26\n5,6,sphere:S,25\n7,8,sphere:S,25\n",
    );
    assert!(
        e.contains("c.csv:3") && e.contains("radius_mm") && e.contains("line 2"),
        "{e}"
    );
    let e = err("q1,q2,x,y,z,constraint\n1,2,,,,point:A\n3,4,1,2,3,point:A\n");
    assert!(
        e.contains("c.csv:3") && e.contains("`x`") && e.contains("no measured position"),
        "{e}"
    );
    let e = err("q1,q2,constraint\n1,2,circle:A\n3,4,circle:A\n");
    assert!(
        e.contains("c.csv:2") && e.contains("unknown constraint kind `circle`"),
        "{e}"
    );
    let e = err("q1,q2,constraint\n1,2,point:\n");
    assert!(e.contains("has no name"), "{e}");
    let e = err("q1,q2,constraint,radius_mm\n1,2,point:A,3\n3,4,point:A,3\n");
    assert!(e.contains("not a sphere"), "{e}");
    let e = err("q1,q2,constraint\n1,2,point:A\n3,4,plane:A\n");
    assert!(e.contains("already the point"), "{e}");
    let e = err("q1,q2,constraint\n1,2,point:A\n3,4,\n");
    assert!(
        e.contains("c.csv:3") && e.contains("tracker row with x,y,z"),
        "{e}"
    );
    // Mixed data: a tracker row needs all of x,y,z, as numbers; at least three of them.
    let pts = "1,2,point:A,,,\n3,4,point:A,,,\n";
    let e = err(&format!("q1,q2,constraint,x,y,z\n{pts}5,6,,1,,3\n"));
    assert!(
        e.contains("c.csv:4") && e.contains("field `y`") && e.contains("tracker row"),
        "{e}"
    );
    let e = err(&format!("q1,q2,constraint,x,y,z\n{pts}5,6,,1,a,3\n"));
    assert!(
        e.contains("c.csv:4") && e.contains("`a` is not a number"),
        "{e}"
    );
    let e = err(&format!(
        "q1,q2,constraint,x,y,z\n{pts}5,6,,1,2,3\n7,8,,4,5,6\n"
    ));
    assert!(
        e.contains("c.csv:4") && e.contains("2 tracker row(s)") && e.contains("at least 3"),
        "{e}"
    );
}

#[test]
fn distances_are_checked() {
    let d = read(
        "q1,q2,constraint\n1,2,point:A\n3,4,point:A\n5,6,point:B\n7,8,point:B\n1,1,plane:F\n\
         2,2,plane:F\n3,1,plane:F\n",
    )
    .unwrap();
    let p = |t: &str| parse_distances(t.as_bytes(), Path::new("d.csv"), &d);
    let ok = p("from,to,distance_mm\nA,B,1000.5\n").unwrap();
    assert_eq!((ok[0].from, ok[0].to, ok[0].distance_mm), (0, 1, 1000.5));
    for (text, want) in [
        (
            "from,to,distance_mm\nA,C,10\n",
            "d.csv:2: field `to`: `C` is not a point",
        ),
        ("from,to,distance_mm\nA,B,-3\n", "not a positive length"),
        (
            "from,to,distance_mm\nA,B,3\nB,A,3\n",
            "d.csv:3: field `from`: the distance between",
        ),
        ("from,to,distance_mm\nA,F,3\n", "is a plane"),
        ("from,to,distance_mm\nA,A,3\n", "to itself"),
        ("from,to,mm\nA,B,3\n", "field `distance_mm`: missing column"),
        ("from,to,distance_mm\n", "no data rows"),
    ] {
        let e = p(text).unwrap_err().to_string();
        assert!(e.contains(want), "{text}: {e}");
    }
}
