//! Fuzzes what `evaluate` does with a measurement file of commanded poses: the CSV reader, then
//! the desired positions read from its `x_desired,y_desired,z_desired` or `q1_desired..` columns
//! and the error statistics. Any bytes must give statistics or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::evaluation::{evaluate, Against};
use robocal_core::io::{parse_measurements, Positions};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let against = match first % 3 {
        0 => Against::Auto,
        1 => Against::Model,
        _ => Against::Desired,
    };
    let nominal = robocal_core::preset("kuka-kr480-r3330").expect("preset");
    let Ok(set) = parse_measurements(
        rest,
        Path::new("fuzz.csv"),
        nominal.joint_space(),
        Positions::Required,
    ) else {
        return;
    };
    let truth = robocal_core::preset("kuka-kr480-r3330-table3").expect("preset");
    let frame = robocal_core::frame::TrackerFrame::identity();
    if let Ok(ev) = evaluate(&nominal, &truth, &frame, &set, against) {
        for s in &ev.series {
            assert_eq!(s.errors.len(), set.rows.len());
            assert_eq!(s.stats.n, set.rows.len());
        }
    }
});
