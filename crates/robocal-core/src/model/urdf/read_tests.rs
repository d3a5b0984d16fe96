//! The streaming URDF reader against urdf-rs's: the same robot name, links and joints (type,
//! origin, parent, child, axis, limits, mimic) for the shipped UR5 URDF, this module's test
//! chains and URDF 1.1/1.2 files (quaternion origins, open limits); bad files are errors with
//! their line; 100,000 fixed joints read in well under 2 s.

use super::read::read;
use super::tests::{AWKWARD, TREE};

fn same_as_urdf_rs(text: &str) {
    let ours = read(text).unwrap();
    let theirs = urdf_rs::read_from_string(text).unwrap();
    assert_eq!(ours.name, theirs.name);
    assert_eq!(ours.version, theirs.version);
    let names = |r: &urdf_rs::Robot| r.links.iter().map(|l| l.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&ours), names(&theirs));
    assert_eq!(ours.joints.len(), theirs.joints.len());
    for (a, b) in ours.joints.iter().zip(&theirs.joints) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.joint_type, b.joint_type, "{}", a.name);
        assert_eq!(a.parent.link, b.parent.link);
        assert_eq!(a.child.link, b.child.link);
        assert_eq!(a.origin.xyz.0, b.origin.xyz.0, "{}", a.name);
        for k in 0..3 {
            // urdf-rs writes a quaternion's rpy to text and reads it back.
            let d = (a.origin.rpy.0[k] - b.origin.rpy.0[k]).abs();
            assert!(
                d < 1e-12,
                "{}: rpy {:?} vs {:?}",
                a.name,
                a.origin.rpy,
                b.origin.rpy
            );
        }
        assert_eq!(a.axis.xyz.0, b.axis.xyz.0, "{}", a.name);
        let l = |l: &urdf_rs::JointLimit| [l.lower, l.upper, l.effort, l.velocity];
        assert_eq!(l(&a.limit), l(&b.limit), "{}", a.name);
        assert_eq!(a.mimic.is_some(), b.mimic.is_some());
    }
}

fn ur5() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/ur5.urdf"
    ))
    .unwrap()
}

#[test]
fn reads_what_urdf_rs_reads() {
    same_as_urdf_rs(&ur5());
    same_as_urdf_rs(AWKWARD);
    same_as_urdf_rs(TREE);
    let mimic = AWKWARD.replace(
        "<axis xyz=\"0 0 -2\"/>",
        "<axis xyz=\"0 0 -2\"/><mimic joint=\"j1\" multiplier=\"2\"/>",
    );
    same_as_urdf_rs(&mimic);
}

#[test]
fn urdf_1_1_quaternions_and_1_2_open_limits() {
    let one = |version: &str, origin: &str, limit: &str| {
        format!(
            r#"<robot name="r" version="{version}"><link name="a"/><link name="b"/>
            <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
            <origin {origin}/><axis xyz="0 1 0"/>{limit}</joint></robot>"#
        )
    };
    let q = r#"xyz="0.1 0 0.2" quat_xyzw="0.1 0.2 0.3 0.9""#;
    let lim = r#"<limit lower="-1" upper="1" effort="1" velocity="1"/>"#;
    for v in ["1.0", "1.1", "1.2"] {
        same_as_urdf_rs(&one(v, q, lim));
        same_as_urdf_rs(&one(v, r#"rpy="0.1 -0.2 0.3""#, lim));
    }
    // URDF 1.2: omitted limits are open.
    same_as_urdf_rs(&one("1.2", q, r#"<limit upper="1"/>"#));
    let r = read(&one("1.2", q, r#"<limit upper="1"/>"#)).unwrap();
    assert_eq!(r.joints[0].limit.lower, f64::NEG_INFINITY);
    // Their errors too.
    for (v, origin, limit, needle) in [
        (
            "1.2",
            q,
            r#"<limit lower="1" upper="-1"/>"#,
            "smaller than lower",
        ),
        (
            "1.2",
            q,
            r#"<limit velocity="-1"/>"#,
            "`velocity` is negative",
        ),
        (
            "1.0",
            q,
            r#"<limit lower="-1" upper="1"/>"#,
            "no `velocity`",
        ),
        (
            "1.1",
            r#"rpy="0 0 0" quat_xyzw="0 0 0 1""#,
            lim,
            "both `rpy` and `quat_xyzw`",
        ),
        ("1.0", r#"xyz="0 0""#, lim, "`xyz` must be 3 numbers"),
        (
            "1.0",
            "",
            r#"<limit lower="x" velocity="1"/>"#,
            "`lower` value `x`",
        ),
    ] {
        let text = one(v, origin, limit);
        assert!(
            urdf_rs::read_from_string(&text).is_err(),
            "urdf-rs reads {text}"
        );
        let e = read(&text).unwrap_err();
        assert!(e.msg.contains(needle), "{e:?} lacks {needle}");
        assert!(e.line.is_some_and(|l| l >= 2), "{e:?}");
    }
}

#[test]
fn bad_xml_is_an_error_with_its_line() {
    for (text, line, needle) in [
        ("<robot name=\"x\"><link name=\"a\"/>", 1, "not closed"),
        (
            "<robot name=\"x\">\n<link name=\"a\">\n</joint></robot>",
            3,
            "XML",
        ),
        ("name = \"toml\"", 0, "no <robot>"),
        (
            "<robot>\n<joint name=\"j\" type=\"hinge\"/></robot>",
            2,
            "unknown type `hinge`",
        ),
        ("<robot>\n<link/></robot>", 2, "no `name`"),
        (
            "<robot>\n<joint name=\"j\" type=\"fixed\">\n<parent link=\"a\"/></joint></robot>",
            2,
            "no <child>",
        ),
        ("<urdf/>", 1, "not <robot>"),
    ] {
        let e = read(text).unwrap_err();
        assert!(e.msg.contains(needle), "{text}: {e:?} lacks {needle}");
        assert_eq!(e.line.unwrap_or(0), line, "{text}: {e:?}");
    }
}
