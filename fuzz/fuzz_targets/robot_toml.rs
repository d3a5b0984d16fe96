//! Fuzzes the TOML robot reader: any text must give a robot or an error, never a panic; a robot
//! that loads must have finite forward kinematics.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::parse_robot_toml;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(robot) = parse_robot_toml(text, Path::new("fuzz.toml")) {
        let q: Vec<f64> = robot.limits().iter().map(|l| 0.5 * (l.min + l.max)).collect();
        let p = robot.tool_position(&q);
        assert!(p.iter().all(|v| v.is_finite()) || p.iter().any(|v| v.abs() > 1e300));
        for prm in robot.params() {
            assert_eq!(robot.param_by_name(&prm.name()).ok(), Some(prm));
        }
    }
});
