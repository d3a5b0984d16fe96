//! Exports reproduce the calibrated forward kinematics: the robot file read back and the URDF
//! imported again (and evaluated as a URDF chain) give the calibrated tool frames to 1e-6 mm.

use super::*;
use crate::model::urdf::{self, ChainSelection};
use std::path::Path;

fn example(name: &str) -> Robot {
    crate::load_robot_file(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples")
            .join(name),
    )
    .unwrap()
}

/// `robot` with every parameter moved a little (as a calibration would), tool correction too.
fn calibrated(mut robot: Robot) -> Robot {
    let v: Vec<f64> = robot
        .values()
        .iter()
        .enumerate()
        .map(|(k, x)| x + 1e-3 * ((k * 7 % 11) as f64 - 5.0))
        .collect();
    robot.set_values(&v).unwrap();
    robot
}

fn worst_gap(a: &Robot, b: &Robot) -> f64 {
    urdf::spread_joints(a, 200)
        .iter()
        .map(|q| {
            (0..a.target_count())
                .map(|t| urdf::frame_difference_mm(&a.target_pose(q, t), &b.target_pose(q, t)))
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

#[test]
fn toml_and_urdf_exports_reproduce_the_calibrated_kinematics() {
    let mut with_beta = calibrated(example("kr480-r3330.toml"));
    with_beta.enable_beta(2).unwrap();
    with_beta.set(Param::parse("beta3").unwrap(), 0.001);
    for cal in [
        calibrated(example("ur5.toml")),
        calibrated(example("kr480-track.toml")),
        calibrated(example("fanuc-like.toml")),
        calibrated(example("wam.toml")),
        with_beta,
    ] {
        let nominal = geometric_nominal(&cal).unwrap();
        assert!(
            worst_gap(&cal, &nominal) == 0.0,
            "folding the tool is exact"
        );
        let notes = vec!["exported -- by a test".to_owned(), "second line".to_owned()];
        let toml = export(&nominal, ExportFormat::Toml, &notes).unwrap();
        assert!(
            toml.starts_with("# exported -- by a test\n# second line\n"),
            "{toml}"
        );
        let back = crate::parse_robot_toml(&toml, Path::new("out.toml")).unwrap();
        let gap = worst_gap(&cal, &back);
        assert!(
            gap < 1e-9,
            "{}: TOML export differs by {gap:e} mm",
            cal.name()
        );
        assert_eq!(back.controller(), cal.controller());

        let xml = export(&nominal, ExportFormat::Urdf, &notes).unwrap();
        assert!(xml.contains("exported - - by a test"), "{xml}");
        let sel = ChainSelection {
            base_link: None,
            tip_link: Some("tcp".into()),
        };
        let chain = urdf::parse_urdf_chain(&xml, Path::new("out.urdf"), &sel).unwrap();
        let imported = urdf::chain_robot(&chain, Path::new("out.urdf")).unwrap();
        assert_eq!(imported.joint_types(), cal.joint_types());
        let mut worst = 0.0f64;
        for q in urdf::spread_joints(&cal, 200) {
            worst = worst
                .max(urdf::frame_difference_mm(
                    &chain.tip_pose(&q),
                    &cal.tool_pose(&q),
                ))
                .max(urdf::frame_difference_mm(
                    &imported.tool_pose(&q),
                    &cal.tool_pose(&q),
                ));
        }
        assert!(
            worst < 1e-6,
            "{}: URDF export differs by {worst:e} mm",
            cal.name()
        );
        for (a, b) in imported.limits().iter().zip(cal.limits()) {
            assert!((a.min - b.min).abs() < 1e-9 && (a.max - b.max).abs() < 1e-9);
        }
    }
}
