//! Fuzzes the measurement CSV reader: any bytes must give rows or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::io::{parse_measurements, Positions};
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
    if let Ok(set) = parse_measurements(rest, Path::new("fuzz.csv"), dof, positions) {
        assert!(!set.rows.is_empty());
        for r in &set.rows {
            assert_eq!(r.q.len(), dof);
            assert!(r.q.iter().all(|v| v.is_finite()));
            assert_eq!(r.extra.len(), set.extra_columns.len());
        }
        let _ = set.duplicate_poses();
    }
});
