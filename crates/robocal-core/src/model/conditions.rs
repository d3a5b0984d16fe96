//! What a measurement row says about the robot beside its joint values (DESIGN.md,
//! "Measurement CSV additions (real cells)"): the families that read it see it through
//! [`super::RigidPose::conditions`]; forward kinematics under it is
//! [`crate::kinematics::conditions`].

use super::MAX_JOINTS;

/// What a measurement row says about the robot beside its joint values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conditions {
    /// The arm's temperature (deg C); NaN when unknown.
    pub temperature_c: f64,
    /// Each joint's approach direction: +1 or -1, 0 when unknown.
    pub dir: [i8; MAX_JOINTS],
}

impl Conditions {
    /// Nothing known: no temperature, no directions.
    pub const UNKNOWN: Conditions = Conditions {
        temperature_c: f64::NAN,
        dir: [0; MAX_JOINTS],
    };

    /// Whether `other` holds the same conditions (unknown temperatures count as equal).
    pub fn same(&self, other: &Conditions) -> bool {
        self.temperature_c.to_bits() == other.temperature_c.to_bits() && self.dir == other.dir
    }

    /// Whether anything is known.
    pub fn is_unknown(&self) -> bool {
        self.temperature_c.is_nan() && self.dir.iter().all(|d| *d == 0)
    }
}

impl Default for Conditions {
    fn default() -> Self {
        Conditions::UNKNOWN
    }
}
