//! Fuzzes the target-file reader of `compensate --targets`: any bytes must give targets or an
//! error, never a panic; reaching the targets must not panic either.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::compensation::parse_targets;
use robocal_core::{Compensator, DampedLeastSquares};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let dof = 1 + (first % 8) as usize;
    // Six joints: the KUKA's (with its controller map, so axis1..axis6 are read too).
    let kuka = robocal_core::preset("kuka-kr480-r3330").expect("preset");
    let joints = if dof == 6 {
        kuka.joint_space().clone()
    } else {
        robocal_core::JointSpace::revolute(dof)
    };
    if let Ok(set) = parse_targets(rest, Path::new("fuzz.csv"), &joints) {
        assert!(!set.rows.is_empty());
        for t in &set.rows {
            assert!(t.p.iter().all(|v| v.is_finite()));
            assert_eq!(t.extra.len(), set.extra_columns.len());
            if let Some(s) = &t.seed {
                assert_eq!(s.len(), dof);
            }
        }
        // With a 6-joint file, solve a few targets on the KUKA (the rest of `compensate`).
        if dof == 6 {
            let nominal = kuka;
            let solver = DampedLeastSquares {
                max_iterations: 20,
                ..DampedLeastSquares::default()
            };
            let comp = Compensator::new(&nominal, &nominal, solver).expect("same robot");
            let rows = &set.rows[..set.rows.len().min(4)];
            if let Ok(out) = comp.reach_all(rows, &()) {
                for c in out {
                    assert!(c.commanded.iter().all(|v| v.is_finite()));
                }
            }
        }
    }
});
