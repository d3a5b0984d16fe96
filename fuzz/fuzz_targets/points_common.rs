//! What the points-import fuzz targets share: the first byte picks the named format or `auto`
//! and the length unit, the rest is the export; any bytes give points or an error, never a
//! panic, and the points given are finite.

use robocal_core::io::import::{parse_points, ImportConfig, LengthUnit, MatchBy, PointsFormat};
use std::path::Path;

/// Parses `data` as a points export of `format` (or detected) and checks what comes back.
pub fn check_points(format: PointsFormat, data: &[u8]) {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let mut config = ImportConfig::new(MatchBy::Order);
    config.points_format = if first % 2 == 0 { format } else { PointsFormat::Auto };
    config.length_unit = [None, Some(LengthUnit::Mm), Some(LengthUnit::M), Some(LengthUnit::In)]
        [(first / 2 % 4) as usize];
    if let Ok(t) = parse_points(rest, Path::new("fuzz.txt"), &config) {
        assert!(!t.rows.is_empty());
        for r in &t.rows {
            assert!(r.p.iter().all(|v| v.is_finite()));
            assert!(r.abc_deg.map_or(true, |a| a.iter().all(|v| v.is_finite())));
        }
    }
}
