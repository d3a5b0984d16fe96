//! Fuzzes robocal import's joint-log parsers (csv, rtde) and the dwell finder: any bytes give
//! rows and dwells or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use robocal_core::io::import::{parse_joints, ImportConfig, JointsFormat, MatchBy};
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let mut config = ImportConfig::new([MatchBy::Order, MatchBy::Time][(first % 2) as usize]);
    config.joints_format = [JointsFormat::Auto, JointsFormat::Csv, JointsFormat::Rtde]
        [(first / 2 % 3) as usize];
    if first / 6 % 2 == 1 {
        config.joint_columns = Some(vec!["A1".into(), "A2".into()]);
    }
    if let Ok(r) = parse_joints(rest, Path::new("fuzz.txt"), &config) {
        assert!(r.rows > 0);
        for d in &r.dwells {
            assert!(d.end_s >= d.start_s && d.q_deg.iter().all(|v| v.is_finite()));
        }
    }
});
