//! What every points parser produces: the rows of a tracker export in robocal's units (mm,
//! degrees, deg C, seconds), how the file was read, and the checks common to all formats (the
//! length unit, a 6-DoF probe's quaternion, plausible positions).

use super::lines::Dialect;
use super::units::LengthUnit;
use super::PointsFormat;
use crate::error::{Error, Result};
use crate::ranges;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::path::{Path, PathBuf};

/// A U(95) expanded uncertainty over the 1-sigma per-axis uncertainty robocal's `sigma_mm` holds:
/// `sqrt(chi2_3(0.95)) = sqrt(7.8147) = 2.7955`, the radius that holds 95% of the points of a
/// 3D Gaussian with that sigma on each axis (the tracker's U(95) is the radius of a sphere).
pub const U95_PER_SIGMA: f64 = 2.795_483_482_915_108;

/// The largest deviation from 1 of a probe quaternion's norm that is rounding, not an error.
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-4;

/// Points closer together than this (mm, diagonal of their bounding box) are not a calibration:
/// the file's unit is wrong (metres read as millimetres).
pub const MIN_SPREAD_MM: f64 = 10.0;

/// One measured point of a tracker export.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRow {
    /// 1-based line in the file.
    pub line: usize,
    /// The point's name, where the export has one.
    pub name: Option<String>,
    /// Position (mm, tracker frame).
    pub p: [f64; 3],
    /// A 6-DoF probe's orientation as A, B, C (deg), from its quaternion.
    pub abc_deg: Option<[f64; 3]>,
    /// 1-sigma uncertainty per axis (mm), from an expanded uncertainty U(95).
    pub sigma_mm: Option<f64>,
    /// Temperature (deg C).
    pub temperature_c: Option<f64>,
    /// Measurement time (s, the tracker's clock).
    pub time_s: Option<f64>,
}

/// A tracker export as read.
#[derive(Debug, Clone)]
pub struct PointTable {
    /// The file.
    pub path: PathBuf,
    /// The format it was read as.
    pub format: PointsFormat,
    /// Delimiter, decimal mark, header line.
    pub dialect: Dialect,
    /// The unit of the file's lengths.
    pub length_unit: LengthUnit,
    /// Where the unit came from (a header, the option, robocal's default).
    pub unit_source: String,
    /// Columns read but not used.
    pub ignored_columns: Vec<String>,
    /// The points, in file order.
    pub rows: Vec<PointRow>,
    /// Lines of rows the export marks deleted (left out).
    pub deleted_lines: Vec<usize>,
}

/// The length unit of a file: what the file says, else what the option says, else a format's
/// default; a file and an option that disagree, or neither when the format has no default, are
/// errors that name `--length-unit`.
pub fn resolve_length_unit(
    path: &Path,
    from_file: Option<(LengthUnit, String)>,
    given: Option<LengthUnit>,
    default: Option<(LengthUnit, &str)>,
) -> Result<(LengthUnit, String)> {
    match (from_file, given, default) {
        (Some((f, where_)), Some(g), _) if f != g => Err(Error::parse(
            path,
            None,
            None,
            format!(
                "the file says its lengths are in {f} ({where_}) but the `length_unit` setting says {g}; \
                 correct or drop the `length_unit` setting"
            ),
        )),
        (Some((f, where_)), _, _) => Ok((f, where_)),
        (None, Some(g), _) => Ok((g, "the `length_unit` setting".into())),
        (None, None, Some((d, why))) => Ok((d, why.into())),
        (None, None, None) => Err(Error::parse(
            path,
            None,
            None,
            "the file does not say its length unit; give the `length_unit` setting (mm, m or in)",
        )),
    }
}

/// A probe quaternion `(q0, q1, q2, q3)` (scalar first) as A, B, C in degrees. A norm further
/// from 1 than [`QUATERNION_NORM_TOLERANCE`] is an error (a column mix-up or a broken export).
pub fn quaternion_abc(path: &Path, line: usize, q: [f64; 4]) -> Result<[f64; 3]> {
    let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
    if (n - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(Error::parse(
            path,
            Some(line),
            Some("Q0..Q3"),
            format!(
                "the quaternion ({}, {}, {}, {}) has norm {n:.6}, not 1: not a rotation",
                q[0], q[1], q[2], q[3]
            ),
        ));
    }
    let u = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let f = crate::frame::frame(*u.to_rotation_matrix().matrix(), Vector3::zeros());
    let v = crate::frame::frame_vector(&f);
    Ok([v[3].to_degrees(), v[4].to_degrees(), v[5].to_degrees()])
}

/// Checks that converts every row's lengths to mm and checks them: each coordinate within
/// robocal's length range, and the points spread over more than [`MIN_SPREAD_MM`] (metres read
/// as millimetres are not).
pub fn finish(mut table: PointTable) -> Result<PointTable> {
    let path = table.path.clone();
    if table.rows.is_empty() {
        return Err(Error::parse(&path, None, None, "no points in the file"));
    }
    let k = table.length_unit.to_mm();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for r in &mut table.rows {
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let v = r.p[i] * k;
            if !ranges::LENGTH.contains(v) {
                return Err(Error::parse(
                    &path,
                    Some(r.line),
                    Some(axis),
                    format!(
                        "{v} mm is beyond {} ({}): is the length unit right ({} from {})? \
                         see the `length_unit` setting",
                        ranges::LENGTH.why,
                        ranges::LENGTH.bounds(),
                        table.length_unit,
                        table.unit_source
                    ),
                ));
            }
            r.p[i] = v;
            lo[i] = lo[i].min(v);
            hi[i] = hi[i].max(v);
        }
        if let Some(s) = r.sigma_mm.as_mut() {
            *s *= k;
        }
    }
    let spread = (0..3).map(|i| (hi[i] - lo[i]).powi(2)).sum::<f64>().sqrt();
    if table.rows.len() >= 3 && spread < MIN_SPREAD_MM {
        return Err(Error::parse(
            &path,
            None,
            None,
            format!(
                "the {} points lie within {spread:.3} mm of each other, read as {} ({}): \
                 are the lengths in another unit? give the `length_unit` setting (mm, m or in)",
                table.rows.len(),
                table.length_unit,
                table.unit_source
            ),
        ));
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_to_abc_and_norm_check() {
        let p = Path::new("f");
        let abc = [30.0f64, -20.0, 70.0];
        let r = crate::frame::pose(&[
            0.0,
            0.0,
            0.0,
            abc[0].to_radians(),
            abc[1].to_radians(),
            abc[2].to_radians(),
        ]);
        let q = UnitQuaternion::from_rotation_matrix(&r.rotation);
        let got = quaternion_abc(p, 3, [q.w, q.i, q.j, q.k]).unwrap();
        for i in 0..3 {
            assert!((got[i] - abc[i]).abs() < 1e-9, "{got:?}");
        }
        let e = quaternion_abc(p, 3, [1.2, 0.0, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("f:3: field `Q0..Q3`") && e.contains("norm 1.2"),
            "{e}"
        );
    }

    #[test]
    fn u95_conversion_is_the_95_percent_radius_of_a_3d_gaussian() {
        // Monte Carlo-free check: chi-square with 3 degrees of freedom, CDF at U95^2 is 0.95.
        // CDF(x) = erf(sqrt(x/2)) - sqrt(2x/pi) exp(-x/2).
        let x = U95_PER_SIGMA * U95_PER_SIGMA;
        let erf = |z: f64| {
            // Abramowitz-Stegun 7.1.26 is too coarse; integrate exp(-t^2) by Simpson.
            let n = 2000;
            let h = z / n as f64;
            let f = |t: f64| (-t * t).exp();
            let mut s = f(0.0) + f(z);
            for i in 1..n {
                s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            s * h / 3.0 * 2.0 / std::f64::consts::PI.sqrt()
        };
        let cdf =
            erf((x / 2.0).sqrt()) - (2.0 * x / std::f64::consts::PI).sqrt() * (-x / 2.0).exp();
        assert!((cdf - 0.95).abs() < 1e-9, "{cdf}");
    }

    #[test]
    fn units_resolve_or_name_the_option() {
        let p = Path::new("f");
        let mm = Some((LengthUnit::Mm, "header".to_owned()));
        assert!(
            resolve_length_unit(p, mm.clone(), Some(LengthUnit::M), None)
                .unwrap_err()
                .to_string()
                .contains("the `length_unit` setting")
        );
        assert_eq!(
            resolve_length_unit(p, mm, None, None).unwrap().0,
            LengthUnit::Mm
        );
        assert!(resolve_length_unit(p, None, None, None)
            .unwrap_err()
            .to_string()
            .contains("give the `length_unit` setting"));
    }
}
