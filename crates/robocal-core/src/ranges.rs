//! The plausible magnitude of every kind of number robocal reads (files and settings), in one
//! place. A finite value outside its range is not a measurement or a robot but a mistake (a units
//! error, a mistyped exponent, a corrupted file): it is rejected naming its field, because it
//! would otherwise turn into NaN statistics or infinite cells downstream.
//!
//! Each limit is generous for real equipment and tight enough that the arithmetic downstream
//! (squares, sums, sines) keeps its precision; the reason is given beside each.

use crate::error::{Error, Result};
use crate::unit::Unit;

/// A closed interval of accepted values, with the unit and the kind of quantity for messages.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
    /// The unit (`mm`, `deg`, ...), for messages.
    pub unit: &'static str,
    /// What the quantity is (`a length`, ...), for messages.
    pub what: &'static str,
    /// Why the limit is where it is, in a few words, for messages.
    pub why: &'static str,
}

/// Lengths and positions: link lengths, base and tool translations, tracker frame, measured and
/// target points, noise, error sizes. ±1 km: the largest robots and gantries span tens of metres
/// and laser trackers reach 80 to 160 m, yet 1e6 mm keeps sums of squares exact to far below a
/// micrometre (1e6 × 2^-52 ≈ 2e-10 mm).
pub const LENGTH: Range = Range {
    min: -1e6,
    max: 1e6,
    unit: "mm",
    what: "a length",
    why: "1 km",
};

/// Geometric angles: DH angles (alpha, phi, beta), the A, B, C of the base, tool and tracker
/// frames, angle error sizes. ±10 turns: every orientation is within one turn, so ten leave room
/// for any way of writing one (0..360, ±180, offsets on offsets), while a mistyped exponent or a
/// value in the wrong unit lands far outside.
pub const ANGLE: Range = Range {
    min: -3600.0,
    max: 3600.0,
    unit: "deg",
    what: "an angle",
    why: "10 turns",
};

/// Joint values and joint limits (measurement, joint and target files, robot files): ±1e5 deg
/// (about 278 turns), for multi-turn axes such as turntables and endless wrists; a sine of
/// 1e5 deg (1745 rad) is still exact to 4e-13.
pub const JOINT: Range = Range {
    min: -1e5,
    max: 1e5,
    unit: "deg",
    what: "a joint value",
    why: "about 278 turns",
};

/// Error statistics (mean, standard deviation, maximum, RMS, percentile of error norms): a
/// distance between two points within [`LENGTH`], never negative.
pub const ERROR: Range = Range {
    min: 0.0,
    max: 1e6,
    unit: "mm",
    what: "an error",
    why: "1 km",
};

/// Sizes that cannot be negative (standard deviations, distances): [`LENGTH`]'s bound.
pub const SIZE_MM: Range = Range {
    min: 0.0,
    max: 1e6,
    unit: "mm",
    what: "a size",
    why: "1 km",
};

/// Angle sizes that cannot be negative (standard deviations of angles): [`ANGLE`]'s bound.
pub const SIZE_DEG: Range = Range {
    min: 0.0,
    max: 3600.0,
    unit: "deg",
    what: "an angle size",
    why: "10 turns",
};

/// Identified joint compliances and their uncertainties (display µrad/(N·m)): ±1e6 µrad/(N·m),
/// [`COMPLIANCE`]'s bound of 1 rad per N·m; real joints have 0.01 to 10 µrad/(N·m).
pub const COMPLIANCE_UNITS: Range = Range {
    min: -1e6,
    max: 1e6,
    unit: "urad/Nm",
    what: "a compliance",
    why: "1 rad per N·m",
};

/// Lumped gravity coefficients (display µrad per metre of lever arm): ±1e9 µrad/m, a joint
/// turned by 1 rad per mm of lever; real arms have 1 to 1e4 µrad/m.
pub const LUMPED_GRAVITY: Range = Range {
    min: -1e9,
    max: 1e9,
    unit: "urad/m",
    what: "a lumped gravity coefficient",
    why: "1 rad per mm of lever arm",
};

/// Distance-proportional tracker noise (mm per metre of distance): up to 1000 mm/m, a noise as
/// large as the distance itself; real trackers have 0.005 mm/m.
pub const NOISE_PER_M: Range = Range {
    min: 0.0,
    max: 1e3,
    unit: "mm/m",
    what: "a distance-proportional noise",
    why: "as large as the distance itself",
};

/// Controller coupling factors (a joint's share of another axis's value): up to ±1000, far
/// beyond the gear ratios between coupled axes (about 1, as FANUC's J2/J3 or a wrist's
/// differential), while a mistyped exponent lands outside.
pub const COUPLING: Range = Range {
    min: -1e3,
    max: 1e3,
    unit: "times",
    what: "a coupling factor",
    why: "a thousand times the other axis",
};

/// Masses (links, payload): up to 1000 t, far beyond the heaviest robot payloads (a few tonnes).
pub const MASS: Range = Range {
    min: 0.0,
    max: 1e6,
    unit: "kg",
    what: "a mass",
    why: "1000 t",
};

/// Thermal expansion coefficients (display ppm/K): ±1e6 ppm/K, a length doubling per kelvin;
/// real structures have -1 to 25 ppm/K.
pub const EXPANSION: Range = Range {
    min: -1e6,
    max: 1e6,
    unit: "ppm/K",
    what: "an expansion coefficient",
    why: "a length doubling per kelvin",
};

/// Joint compliances: up to 1 rad per N·m (a spring a 1 N·m torque turns by 57 degrees); real
/// joints have 1e-8 to 1e-5 rad/(N·m).
pub const COMPLIANCE: Range = Range {
    min: 0.0,
    max: 1.0,
    unit: "rad/(N·m)",
    what: "a compliance",
    why: "1 rad per N·m",
};

/// How far beyond a joint limit a value still counts as within it (deg): files hold joint values
/// rounded to 9 decimals of a degree, so a pose drawn or solved exactly at a limit may read back
/// up to 5e-10 deg beyond it. 1e-6 deg is 0.0036 arc seconds, far below any robot's resolution.
pub const LIMIT_TOLERANCE_DEG: f64 = 1e-6;

impl Range {
    /// The range of a model parameter's display value: [`LENGTH`] for mm, [`ANGLE`] for deg,
    /// [`COMPLIANCE_UNITS`] and [`LUMPED_GRAVITY`] for the compliance family's coefficients.
    pub fn for_unit(unit: Unit) -> &'static Range {
        match unit {
            Unit::Mm => &LENGTH,
            Unit::Deg => &ANGLE,
            Unit::MicroradPerNm => &COMPLIANCE_UNITS,
            Unit::MicroradPerM => &LUMPED_GRAVITY,
            Unit::PpmPerK => &EXPANSION,
        }
    }

    /// The range of a non-negative size in `unit` ([`SIZE_MM`] or [`SIZE_DEG`]; the
    /// coefficients' own bound for the compliance family's units).
    pub fn size_for_unit(unit: Unit) -> &'static Range {
        match unit {
            Unit::Mm => &SIZE_MM,
            Unit::Deg => &SIZE_DEG,
            Unit::MicroradPerNm => &COMPLIANCE_UNITS,
            Unit::MicroradPerM => &LUMPED_GRAVITY,
            Unit::PpmPerK => &EXPANSION,
        }
    }

    /// Whether `v` is finite and within the range.
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite() && v >= self.min && v <= self.max
    }

    /// `v` if it is within the range; otherwise what is wrong, e.g. `1e308 mm is out of range
    /// (a length must be within ±1e6 mm, 1 km)`. Callers add the file, line and field.
    pub fn check(&self, v: f64) -> Result<f64, String> {
        if self.contains(v) {
            return Ok(v);
        }
        if !v.is_finite() {
            return Err(format!("{v} is not a finite number"));
        }
        Err(format!(
            "{} {} is out of range ({} must be within {} {}, {})",
            fmt_value(v),
            self.unit,
            self.what,
            self.bounds(),
            self.unit,
            self.why
        ))
    }

    /// The bounds as text: `±1e6` or `0..1e6`.
    pub fn bounds(&self) -> String {
        if self.min == -self.max {
            format!("±{}", fmt_value(self.max))
        } else {
            format!("{}..{}", fmt_value(self.min), fmt_value(self.max))
        }
    }
}

/// A number as a person would write it: plain for ordinary magnitudes, with an exponent for huge
/// or tiny ones and round bounds (`1e308` and `1e6`, not 309 or 7 digits).
pub fn fmt_value(v: f64) -> String {
    let a = v.abs();
    let round = a >= 1e5 && a.log10().fract() == 0.0;
    if a != 0.0 && (round || !(1e-4..1e9).contains(&a)) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Checks a setting against its plausible range; `name` names it in the error
/// ([`Error::Invalid`]).
pub(crate) fn in_range(name: &str, v: f64, range: &Range) -> Result<()> {
    range
        .check(v)
        .map(|_| ())
        .map_err(|msg| Error::invalid(name, msg))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_messages() {
        assert_eq!(LENGTH.check(999_999.0), Ok(999_999.0));
        assert_eq!(LENGTH.check(-1e6), Ok(-1e6));
        let e = LENGTH.check(1e308).unwrap_err();
        assert_eq!(
            e,
            "1e308 mm is out of range (a length must be within ±1e6 mm, 1 km)"
        );
        let e = ANGLE.check(-1e300).unwrap_err();
        assert!(e.starts_with("-1e300 deg is out of range"), "{e}");
        assert!(JOINT
            .check(1_000_080.0)
            .unwrap_err()
            .contains("1000080 deg"));
        assert!(JOINT.check(99_999.5).is_ok());
        let e = ERROR.check(-0.5).unwrap_err();
        assert!(
            e.contains("-0.5 mm") && e.contains("within 0..1e6 mm"),
            "{e}"
        );
        assert!(SIZE_MM
            .check(f64::NAN)
            .unwrap_err()
            .contains("not a finite"));
        assert!(COMPLIANCE.check(1e-7).is_ok() && COMPLIANCE.check(2.0).is_err());
        assert!(MASS.check(-1.0).is_err() && NOISE_PER_M.check(0.005).is_ok());
        assert_eq!(Range::for_unit(Unit::Mm), &LENGTH);
        assert_eq!(Range::for_unit(Unit::Deg), &ANGLE);
        assert_eq!(fmt_value(0.25), "0.25");
        assert_eq!(fmt_value(3600.0), "3600");
        assert_eq!(fmt_value(1e-9), "1e-9");
    }
}
