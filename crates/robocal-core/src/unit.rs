//! The units of values at robocal's interfaces (files, reports): millimetres and degrees, stored
//! internally as millimetres and radians. At the ground floor so that the model and the range
//! checks below it can both use it.

/// The unit a parameter is shown in at the interfaces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Unit {
    /// Millimetres (stored as millimetres).
    #[serde(rename = "mm")]
    Mm,
    /// Degrees (stored as radians).
    #[serde(rename = "deg")]
    Deg,
}

impl Unit {
    /// Converts an internal value (mm or rad) to this unit.
    pub fn from_internal(self, v: f64) -> f64 {
        match self {
            Unit::Mm => v,
            Unit::Deg => v.to_degrees(),
        }
    }

    /// Converts a value in this unit to internal units (mm or rad).
    pub fn to_internal(self, v: f64) -> f64 {
        match self {
            Unit::Mm => v,
            Unit::Deg => v.to_radians(),
        }
    }

    /// `"mm"` or `"deg"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::Mm => "mm",
            Unit::Deg => "deg",
        }
    }
}
