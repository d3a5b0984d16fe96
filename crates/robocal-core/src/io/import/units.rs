//! Length and angle units of imported files, and how a unit written in a header (`[mm]`, `(m)`,
//! `// Units: Meters`) is recognised.

use std::fmt;

/// A length unit of a tracker export.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres (robocal's unit).
    Mm,
    /// Metres.
    M,
    /// Inches (25.4 mm).
    In,
}

impl LengthUnit {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            LengthUnit::Mm => 1.0,
            LengthUnit::M => 1000.0,
            LengthUnit::In => 25.4,
        }
    }

    /// The unit a word names (`mm`, `millimeters`, `m`, `metres`, `in`, `inch`, `"`, any case),
    /// or `None`.
    pub fn from_word(word: &str) -> Option<LengthUnit> {
        let w = word.trim().trim_end_matches('.').to_ascii_lowercase();
        match w.as_str() {
            "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => {
                Some(LengthUnit::Mm)
            }
            "m" | "meter" | "meters" | "metre" | "metres" => Some(LengthUnit::M),
            "in" | "inch" | "inches" | "\"" => Some(LengthUnit::In),
            _ => None,
        }
    }
}

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            LengthUnit::Mm => "mm",
            LengthUnit::M => "m",
            LengthUnit::In => "in",
        })
    }
}

impl std::str::FromStr for LengthUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "mm" => Ok(LengthUnit::Mm),
            "m" => Ok(LengthUnit::M),
            "in" => Ok(LengthUnit::In),
            _ => Err(format!("unknown length unit `{s}` (mm, m or in)")),
        }
    }
}

/// An angle unit of a joint log.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    /// Degrees (robocal's unit).
    Deg,
    /// Radians.
    Rad,
}

impl AngleUnit {
    /// Degrees per unit.
    pub fn to_deg(self) -> f64 {
        match self {
            AngleUnit::Deg => 1.0,
            AngleUnit::Rad => 180.0 / std::f64::consts::PI,
        }
    }

    /// A value in this unit, in degrees (exactly `to_degrees` for radians).
    pub fn deg(self, v: f64) -> f64 {
        match self {
            AngleUnit::Deg => v,
            AngleUnit::Rad => v.to_degrees(),
        }
    }
}

impl fmt::Display for AngleUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            AngleUnit::Deg => "deg",
            AngleUnit::Rad => "rad",
        })
    }
}

impl std::str::FromStr for AngleUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "deg" => Ok(AngleUnit::Deg),
            "rad" => Ok(AngleUnit::Rad),
            _ => Err(format!("unknown angle unit `{s}` (deg or rad)")),
        }
    }
}

/// A header cell split into its lower-case name (inner whitespace collapsed, quotes removed) and
/// the unit written after it in brackets: `X  [mm]` -> (`x`, `mm`); `Z (m)` -> (`z`, `m`) when
/// the parenthesised word is a length unit (`U(95)` keeps its parentheses).
pub fn split_header(cell: &str) -> (String, Option<String>) {
    let c = cell.trim().trim_matches('"').trim();
    let (name, unit) = if let Some(open) = c.rfind('[').filter(|_| c.ends_with(']')) {
        (&c[..open], Some(c[open + 1..c.len() - 1].trim().to_owned()))
    } else if let Some(open) = c.rfind('(').filter(|_| c.ends_with(')')) {
        let inner = c[open + 1..c.len() - 1].trim();
        if LengthUnit::from_word(inner).is_some() && open > 0 {
            (&c[..open], Some(inner.to_owned()))
        } else {
            (c, None)
        }
    } else {
        (c, None)
    };
    let name = name.split_whitespace().collect::<Vec<_>>().join(" ");
    (name.to_lowercase(), unit)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_cells_split_into_name_and_unit() {
        assert_eq!(split_header("X  [mm]"), ("x".into(), Some("mm".into())));
        assert_eq!(
            split_header("U(95)  [mm]"),
            ("u(95)".into(), Some("mm".into()))
        );
        assert_eq!(split_header("U(95)"), ("u(95)".into(), None));
        assert_eq!(split_header(" \"Z (m)\" "), ("z".into(), Some("m".into())));
        assert_eq!(split_header("Time  Stamp"), ("time stamp".into(), None));
        assert_eq!(LengthUnit::from_word("Inches"), Some(LengthUnit::In));
        assert_eq!(LengthUnit::from_word("Millimeters"), Some(LengthUnit::Mm));
        assert_eq!(LengthUnit::from_word("um"), None);
        assert_eq!(AngleUnit::Rad.deg(std::f64::consts::PI), 180.0);
    }
}
