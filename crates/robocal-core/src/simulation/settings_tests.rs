//! Tests of [`super::SimulationBuilder`]: each bad setting refused naming it, with the right
//! kind of error; the settings built are the fields.

use super::*;
use crate::preset;

fn kr() -> Robot {
    preset("kuka-kr480-r3330").unwrap()
}

fn err(b: &SimulationBuilder, truth: TruthSource) -> Error {
    b.build(&kr(), truth).unwrap_err()
}

#[test]
fn each_bad_setting_is_refused_naming_it() {
    let ok = SimulationBuilder {
        poses: Some(10),
        ..SimulationBuilder::default()
    };
    assert!(ok.build(&kr(), TruthSource::Random).is_ok());
    let table3 = || TruthSource::Robot(preset("kuka-kr480-r3330-table3").unwrap());
    let cases: Vec<(SimulationBuilder, TruthSource, &str, bool)> = vec![
        (
            SimulationBuilder::default(),
            TruthSource::Random,
            "poses: give",
            true,
        ),
        (
            SimulationBuilder {
                poses: Some(0),
                ..ok.clone()
            },
            TruthSource::Random,
            "poses: at least 1, got 0",
            true,
        ),
        (
            SimulationBuilder {
                poses: Some(6_000_000),
                validation_poses: 6_000_000,
                ..ok.clone()
            },
            TruthSource::Random,
            "12000000 poses in all, at most 10000000",
            true,
        ),
        (
            SimulationBuilder {
                length_sigma_mm: Some(1.0),
                ..ok.clone()
            },
            table3(),
            "apply only to `truth` random",
            true,
        ),
        (
            SimulationBuilder {
                payload_kg: Some(3.0),
                ..ok.clone()
            },
            TruthSource::Random,
            "gravity.payload_kg: models gravity",
            true,
        ),
        (
            SimulationBuilder {
                poses: None,
                joints_given: true,
                validation_poses: 3,
                ..ok.clone()
            },
            TruthSource::Random,
            "validation_poses: not with given joints",
            true,
        ),
        (
            SimulationBuilder {
                compliance_rad_per_nm: Some(vec![1e-7; 4]),
                payload_kg: Some(3.0),
                ..ok.clone()
            },
            TruthSource::Random,
            "4 values; give one for all joints or one per joint (6)",
            true,
        ),
        (
            SimulationBuilder {
                noise_mm: -1.0,
                ..ok.clone()
            },
            TruthSource::Random,
            "noise_mm: ",
            false,
        ),
        (
            SimulationBuilder {
                orientation_sigma_deg: Some(20.0),
                ..ok.clone()
            },
            TruthSource::Random,
            "orientation_sigma_deg: 20: not an angle noise in [0, 10] deg",
            false,
        ),
        (
            SimulationBuilder {
                all_targets: true,
                ..ok.clone()
            },
            TruthSource::Random,
            "targets: robot `",
            true,
        ),
        (
            SimulationBuilder {
                length_sigma_mm: Some(-1.0),
                ..ok.clone()
            },
            TruthSource::Random,
            "truth.length_sigma_mm",
            false,
        ),
    ];
    for (b, t, want, usage) in cases {
        let e = err(&b, t);
        let m = e.to_string();
        assert!(m.contains(want), "`{want}` not in `{m}`");
        assert_eq!(matches!(e, Error::Usage { .. }), usage, "{m}");
        if !usage {
            assert!(matches!(e, Error::Invalid { .. }), "{m}");
        }
    }
}

/// The builder gives the configuration the fields say: a truth file's tracker unless one is
/// given, the class defaults, per-joint values spread to every joint.
#[test]
fn the_settings_are_the_fields() {
    let nominal = kr();
    let tracker = FrameVec {
        x: 1.0,
        y: 2.0,
        z: 3.0,
        a: 4.0,
        b: 5.0,
        c: 6.0,
    };
    let b = SimulationBuilder {
        poses: Some(5),
        compliance_rad_per_nm: Some(vec![1e-7]),
        payload_kg: Some(10.0),
        backlash: Some(PerJoint::ClassDefault),
        ..SimulationBuilder::default()
    };
    let file = TruthSource::File {
        robot: preset("kuka-kr480-r3330-table3").unwrap(),
        tracker,
    };
    let s = b.build(&nominal, file.clone()).unwrap();
    assert_eq!(s.config.tracker_frame, tracker);
    assert_eq!(
        s.config.gravity.unwrap().compliance_rad_per_nm,
        vec![1e-7; 6]
    );
    assert_eq!(s.config.backlash, Some(BacklashModel::for_robot(&nominal)));
    let given = FrameVec { x: 9.0, ..tracker };
    let s = SimulationBuilder {
        tracker_frame: Some(given),
        ..b
    }
    .build(&nominal, file)
    .unwrap();
    assert_eq!(s.config.tracker_frame, given);
}
