//! The units of values at robocal's interfaces (files, reports): millimetres and degrees, stored
//! internally as millimetres and radians; and the units of the non-geometric coefficients (joint
//! compliance, [`crate::model::family::compliance`]). At the ground floor so that the model and
//! the range checks below it can both use it.

/// The unit a parameter is shown in at the interfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Unit {
    /// Millimetres (stored as millimetres).
    #[serde(rename = "mm")]
    Mm,
    /// Degrees (stored as radians).
    #[serde(rename = "deg")]
    Deg,
    /// A joint compliance, microradians per newton metre (stored as rad/(N·m)).
    #[serde(rename = "urad/Nm")]
    MicroradPerNm,
    /// A lumped gravity coefficient: the joint's deflection per metre of lever arm of a lumped
    /// mass's weight, microradians per metre (stored as rad/mm).
    #[serde(rename = "urad/m")]
    MicroradPerM,
    /// A thermal expansion coefficient, parts per million per kelvin (stored as 1/K).
    #[serde(rename = "ppm/K")]
    PpmPerK,
}

impl Unit {
    /// Converts an internal value (mm or rad) to this unit.
    pub fn from_internal(self, v: f64) -> f64 {
        match self {
            Unit::Mm => v,
            Unit::Deg => v.to_degrees(),
            Unit::MicroradPerNm => v * 1e6,
            Unit::MicroradPerM => v * 1e9,
            Unit::PpmPerK => v * 1e6,
        }
    }

    /// Converts a value in this unit to internal units (mm or rad).
    pub fn to_internal(self, v: f64) -> f64 {
        match self {
            Unit::Mm => v,
            Unit::Deg => v.to_radians(),
            Unit::MicroradPerNm => v * 1e-6,
            Unit::MicroradPerM => v * 1e-9,
            Unit::PpmPerK => v * 1e-6,
        }
    }

    /// `"mm"`, `"deg"`, `"urad/Nm"` or `"urad/m"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Deg => "deg",
            Unit::MicroradPerNm => "urad/Nm",
            Unit::MicroradPerM => "urad/m",
            Unit::PpmPerK => "ppm/K",
        }
    }

    /// Whether values in this unit are angles (degrees), which wrap around a full turn.
    pub fn is_angle(self) -> bool {
        self == Unit::Deg
    }
}
