//! Each family's plausible range: how far a calibration of a real robot can move a parameter
//! from where the identification starts, and which values it can take at all.
//!
//! One table serves three readers: the identifiability analysis fixes a parameter whose
//! predicted standard deviation exceeds a third of its plausible move
//! ([`crate::identification::precision`]), the plausibility gate refuses a fit that moves an
//! identified parameter beyond it or leaves it outside its values
//! ([`crate::identification::plausibility`]), and the fit holds a bounded parameter (a physical
//! compliance, never negative) at its bound when the data cannot tell it from the bound.

use crate::model::{Param, Robot, Unit};

/// No identified length (link, base or tool) may move by more than this fraction of the reach.
/// The registration absorbs the rigid motion between the tracker and the base, so the base moves
/// only by the residual corrections (and what it absorbs of d1, a1, alpha1, phi1), the same size
/// as the links'; the tool moves by the uncertainty of its nominal value, a few millimetres, so
/// it shares the limit. Good data: at most 1.08% (real WAM, tool_z 11 mm), 0.17% (simulated,
/// realistic errors), 1.7% (10 times realistic); bad data: 27.6% and more.
pub const LENGTH_MOVE_FRACTION: f64 = 0.05;

/// No identified geometric angle may move by more than this (degrees). Good data: at most 3.18
/// degrees (real WAM alpha6, where a 104 mm wrist-to-tool distance is a short lever), 0.46
/// (simulated, realistic errors), 4.5 (10 times realistic); bad data: 82 degrees and more where
/// angles move at all.
pub const ANGLE_MOVE_DEG: f64 = 10.0;

/// The largest joint deflection (degrees) a family acting through the joints may cause at the
/// robot's reach: gravity sag of real arms is hundredths of a degree (a KR 480 under 300 kg:
/// about 0.04 degrees; a cable-driven WAM: about 0.3), a gear's transmission error about one
/// arc minute (0.017 degrees). One degree leaves a margin of 3 to 60 over those.
pub const JOINT_DEFLECTION_DEG: f64 = 1.0;

/// The largest physical joint compliance (µrad/(N·m)): 1e-3 rad/(N·m), a joint that a 1 N·m
/// torque turns by 0.057 degrees; real joints have 0.01 to 10 µrad/(N·m).
pub const COMPLIANCE_MAX_URAD_PER_NM: f64 = 1000.0;

/// The largest plausible thermal expansion coefficient (ppm/K): ten times aluminium's 23 ppm/K.
pub const THERMAL_MAX_PPM_PER_K: f64 = 250.0;

/// A parameter's plausible range (display units, see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plausible {
    /// The largest move from the identification's starting value.
    pub max_move: f64,
    /// The smallest value (`-inf` when unbounded).
    pub min: f64,
    /// The largest value (`+inf` when unbounded).
    pub max: f64,
    /// Why the range is where it is, in a few words, for messages.
    pub why: &'static str,
    /// Whether the gate bounds this parameter's move on its own. The lumped gravity coefficients
    /// of one joint trade against each other (neighbouring points' levers are nearly
    /// proportional), so a single one may be large while their sum, the joint's deflection,
    /// stays small: for them the gate bounds the deflection over the poses instead
    /// ([`JOINT_DEFLECTION_DEG`]); their move still sets the identifiability limit.
    pub individual: bool,
}

impl Plausible {
    /// A range bounded only by its move.
    pub const fn moving(max_move: f64, why: &'static str) -> Plausible {
        Plausible {
            max_move,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
            why,
            individual: true,
        }
    }

    /// The range of a parameter of `unit`, the default of every family: [`LENGTH_MOVE_FRACTION`]
    /// of the reach for lengths, [`ANGLE_MOVE_DEG`] for angles, [`COMPLIANCE_MAX_URAD_PER_NM`]
    /// (never negative) for compliances, one degree at the reach for lumped coefficients.
    pub fn of_unit(robot: &Robot, unit: Unit) -> Plausible {
        match unit {
            Unit::Mm => Plausible::moving(
                LENGTH_MOVE_FRACTION * robot.reach_mm(),
                "5% of the robot's reach",
            ),
            Unit::Deg => Plausible::moving(ANGLE_MOVE_DEG, "10 degrees"),
            // Units of the families acting through the joints, which give their own ranges:
            // the deflection bound at the reach, for any coefficient.
            Unit::MicroradPerNm => Plausible {
                max_move: COMPLIANCE_MAX_URAD_PER_NM,
                min: 0.0,
                max: COMPLIANCE_MAX_URAD_PER_NM,
                why: "1e-3 rad per N·m, never negative",
                individual: true,
            },
            Unit::MicroradPerM => Plausible {
                individual: false,
                ..Plausible::moving(
                    deflection_per_m(robot),
                    "1 degree of joint deflection at the robot's reach",
                )
            },
            Unit::PpmPerK => Plausible {
                min: -THERMAL_MAX_PPM_PER_K,
                max: THERMAL_MAX_PPM_PER_K,
                ..Plausible::moving(
                    THERMAL_MAX_PPM_PER_K,
                    "250 ppm/K, ten times aluminium's expansion",
                )
            },
        }
    }

    /// Whether `value` lies within `[min, max]`.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }
}

/// [`JOINT_DEFLECTION_DEG`] per metre of the robot's reach (µrad/m): the largest lumped gravity
/// coefficient, whose deflection is the coefficient times the lever arm.
pub fn deflection_per_m(robot: &Robot) -> f64 {
    JOINT_DEFLECTION_DEG.to_radians() * 1e6 / (robot.reach_mm() / 1000.0)
}

/// The plausible range of `p` on `robot` (its family's, see
/// [`super::ParameterFamily::plausible`]).
pub fn of(robot: &Robot, p: Param) -> Plausible {
    p.family().plausible(robot, p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::family::{compliance, transmission};
    use crate::model::presets::preset;

    fn kuka() -> Robot {
        preset("kuka-kr480-r3330").unwrap()
    }

    /// Geometric parameters keep the gate's limits; every family gives a finite, positive move.
    #[test]
    fn every_parameter_of_every_family_has_a_finite_range() {
        let mut r = kuka();
        compliance::enable(&mut r, &[1, 2], Some(300.0)).unwrap();
        transmission::enable(&mut r, &[0, 1, 2, 3, 4, 5], 2).unwrap();
        for p in r.params() {
            let g = of(&r, p);
            assert!(
                g.max_move.is_finite() && g.max_move > 0.0,
                "{}: {g:?}",
                p.name()
            );
        }
        let a2 = of(&r, Param::a(1));
        assert_eq!(a2.max_move, LENGTH_MOVE_FRACTION * r.reach_mm());
        assert_eq!(of(&r, Param::alpha(1)).max_move, ANGLE_MOVE_DEG);
    }

    /// A physical compliance is never negative and bounded by the deflection under its payload;
    /// lumped coefficients are bounded through the joint deflection, not one by one.
    #[test]
    fn compliance_ranges_follow_the_payload_and_the_lever() {
        let mut r = kuka();
        compliance::enable(&mut r, &[1], Some(300.0)).unwrap();
        let c2 = r
            .params()
            .into_iter()
            .find(|p| p.name() == "compliance2")
            .unwrap();
        let g = of(&r, c2);
        assert_eq!(g.min, 0.0);
        assert!(!g.contains(-1e-9) && g.contains(0.0));
        // One degree at the lever of the tool about joint 2 under 300 kg.
        let lever = compliance::lever_bound_mm(&r, 1, r.dof());
        let expect =
            JOINT_DEFLECTION_DEG.to_radians() * 1e6 / (300.0 * compliance::G0 * lever / 1000.0);
        assert!((g.max - expect.min(COMPLIANCE_MAX_URAD_PER_NM)).abs() < 1e-9 * g.max);
        // A payload of 0.1 g leaves only the absolute bound.
        compliance::enable(&mut r, &[1], Some(1e-4)).unwrap();
        assert_eq!(of(&r, c2).max, COMPLIANCE_MAX_URAD_PER_NM);
        // Without a payload: lumped coefficients, either sign, not bounded one by one.
        compliance::enable(&mut r, &[1], None).unwrap();
        let lumped: Vec<Param> = r
            .params()
            .into_iter()
            .filter(|p| p.name().starts_with("grav"))
            .collect();
        assert!(!lumped.is_empty());
        for p in lumped {
            let g = of(&r, p);
            assert!(!g.individual && g.min == f64::NEG_INFINITY, "{}", p.name());
        }
    }

    #[test]
    fn transmission_amplitudes_are_bounded_by_a_degree() {
        let mut r = kuka();
        transmission::enable(&mut r, &[0], 1).unwrap();
        let p = r
            .params()
            .into_iter()
            .find(|p| p.name() == "tcos1_1")
            .unwrap();
        assert_eq!(of(&r, p).max_move, JOINT_DEFLECTION_DEG);
    }
}
