//! Fuzzes the measurement CSV reader: any bytes must give rows or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::io::{parse_measurements, Positions};
use robocal_core::model::{Controller, Coupling, JointSpace, JointType};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let dof = 1 + (first % 8) as usize;
    let positions = match first / 8 % 3 {
        0 => Positions::Required,
        1 => Positions::Optional,
        _ => Positions::Ignored,
    };
    // Joint 1 prismatic and a controller map with a coupling, on some inputs: the axis columns
    // and the per-joint units get fuzzed too.
    let mut types = vec![JointType::Revolute; dof];
    if first / 24 % 2 == 1 {
        types[0] = JointType::Prismatic;
    }
    let controller = (first / 48 % 2 == 1 && dof >= 2).then(|| {
        let sign = (0..dof).map(|i| if i % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let coupling = vec![Coupling {
            joint: 1,
            axis: 0,
            factor: -1.0,
        }];
        Controller::new(sign, vec![0.0; dof], coupling).expect("valid map")
    });
    let joints = JointSpace::new(types, controller).expect("same joint count");
    if let Ok(set) = parse_measurements(rest, Path::new("fuzz.csv"), &joints, positions) {
        assert!(!set.rows.is_empty());
        for r in &set.rows {
            assert_eq!(r.q.len(), dof);
            assert!(r.q.iter().all(|v| v.is_finite()));
            assert_eq!(r.extra.len(), set.extra_columns.len());
        }
        let _ = set.duplicate_poses();
    }
});
