//! Fuzzes the truth-file reader of `simulate --truth FILE.truth.json`: any text must give a truth
//! file or an error, never a panic; applying it to the KUKA preset must not panic either.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::simulation::TruthFile;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(tf) = TruthFile::parse(text, Path::new("fuzz.truth.json")) {
        let nominal = robocal_core::preset("kuka-kr480-r3330").expect("preset");
        if let Ok(robot) = tf.truth_robot(&nominal, Path::new("fuzz.truth.json")) {
            let q = vec![0.1; robot.dof()];
            let _ = robot.tool_position(&q);
        }
        let _ = tf.tracker_frame.to_tracker_frame();
        let _ = tf.settings.validate(&nominal);
    }
});
