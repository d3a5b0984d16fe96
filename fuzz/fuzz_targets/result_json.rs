//! Fuzzes the calibration-result reader: any text must give a result or an error, never a panic;
//! applying a result to the KUKA preset must not panic either.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::io::CalibrationResult;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(res) = CalibrationResult::parse(text, Path::new("fuzz.json")) {
        let nominal = robocal_core::preset("kuka-kr480-r3330").expect("preset");
        let _ = res.calibrated_robot(&nominal, Path::new("fuzz.json"));
        let _ = res.tracker_frame();
    }
});
