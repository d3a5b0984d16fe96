//! Thermal expansion: the arm's lengths grow with its temperature. One lumped coefficient `k`
//! (the family's parameter `thermal_k`, in ppm/K) scales every link's `d` and `a` (the base
//! column of a floor robot is `d1`):
//!
//! ```text
//! L(T) = L * exp(k (T - T_ref))        (to first order L * (1 + k (T - T_ref)))
//! ```
//!
//! where `T` is the row's `temperature_c` and `T_ref` the reference temperature at which the
//! model's lengths hold (stored with the family, written in the result). The exponential makes
//! the reference a free choice: moving it rescales the lengths exactly and leaves `k` as it is.
//! Rows without a temperature are taken at the reference.
//!
//! Jacobian column: `dp/dk = (T - T_ref) * sum_L L(T) * dp/dL`, the lengths' own columns (each a
//! translation along a frame's axis) weighted by their grown values. With one temperature for
//! all rows the column is zero, and the identifiability analysis fixes `k`.

use super::{put, FamilyId, ParameterFamily, PoseFrames};
use crate::error::{Error, Result};
use crate::model::{Param, Robot, Unit};
use nalgebra::Vector3;

/// The family's key in the robot's family store.
pub const KEY: &str = "thermal";
/// This family's registry position.
pub const ID: FamilyId = FamilyId::new(8);

/// The largest plausible coefficient (ppm/K): [`super::plausible::THERMAL_MAX_PPM_PER_K`].
pub const MAX_PPM_PER_K: f64 = super::plausible::THERMAL_MAX_PPM_PER_K;

// Store layout: [k (1/K), reference temperature (deg C)].
const K: usize = 0;
const REFERENCE: usize = 1;

/// The thermal expansion family (see the module docs).
pub struct Thermal;

fn param() -> Param {
    Param::new(ID, 0, 0)
}

impl ParameterFamily for Thermal {
    fn beyond_geometry(&self, robot: &Robot) -> bool {
        // The lengths at one temperature are geometry; their growth with it is not.
        robot.family_values(KEY).is_some()
    }

    fn key(&self) -> &'static str {
        KEY
    }

    fn templates(&self) -> &'static [&'static str] {
        &["thermal_k"]
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::PpmPerK
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        if robot.family_values(KEY).is_some() {
            out.push(param());
        }
    }

    fn get(&self, robot: &Robot, _p: Param) -> f64 {
        robot.family_values(KEY).map_or(0.0, |v| v[K])
    }

    fn set(&self, robot: &mut Robot, _p: Param, value: f64) {
        if let Some(v) = robot.family_values_mut(KEY) {
            v[K] = value;
        }
    }

    fn priority(&self, _robot: &Robot, _p: Param) -> u32 {
        super::priority::NON_GEOMETRIC + 70_000
    }

    /// Within `-`[`MAX_PPM_PER_K`]`..`[`MAX_PPM_PER_K`]: structures of steel, cast iron,
    /// aluminium and carbon fibre lie within -1..25 ppm/K; the lumped coefficient also absorbs
    /// how unevenly the arm warms, hence the margin.
    fn plausible(&self, robot: &Robot, _p: Param) -> super::plausible::Plausible {
        super::plausible::Plausible::of_unit(robot, crate::model::Unit::PpmPerK)
    }

    fn enable(&self, robot: &mut Robot, _p: Param) -> Result<()> {
        if robot.family_values(KEY).is_none() {
            robot.set_family_values(KEY, Some(vec![0.0, DEFAULT_REFERENCE_C]))?;
        }
        Ok(())
    }

    fn columns(
        &self,
        robot: &Robot,
        pose: &PoseFrames,
        dp: &mut [Vector3<f64>],
        mut dw: Option<&mut [Vector3<f64>]>,
    ) {
        let Some(v) = robot.family_values(KEY) else {
            return;
        };
        let dt = pose.rigid.conditions.temperature_c - v[REFERENCE];
        let mut col = Vector3::zeros();
        if dt.is_finite() && dt != 0.0 {
            let s = (v[K] * dt).exp();
            for (i, l) in robot.links().iter().enumerate() {
                let z: Vector3<f64> = pose.axis[i].rotation.matrix().column(2).into();
                let x: Vector3<f64> = pose.link[i].rotation.matrix().column(0).into();
                col += z * l.d + x * l.a;
            }
            col *= s * dt;
        }
        dp[0] = col;
        put(&mut dw, 0, Vector3::zeros());
    }
}

/// The reference temperature a model takes when the family is enabled without one (deg C).
pub const DEFAULT_REFERENCE_C: f64 = 20.0;

/// Makes the lumped coefficient a parameter of `robot` (at 0), the model's lengths holding at
/// `reference_c` (deg C, within -50..150).
pub fn enable(robot: &mut Robot, reference_c: f64) -> Result<()> {
    if !(reference_c.is_finite() && (-50.0..=150.0).contains(&reference_c)) {
        return Err(Error::invalid(
            "reference_temperature_c",
            format!("{reference_c} is not a temperature within -50..150 deg C"),
        ));
    }
    robot.set_family_values(KEY, Some(vec![0.0, reference_c]))
}

/// The temperature at which `robot`'s lengths hold (deg C), when it models thermal expansion.
pub fn reference_c(robot: &Robot) -> Option<f64> {
    robot.family_values(KEY).map(|v| v[REFERENCE])
}

/// Sets the reference temperature of a model with the family (see [`enable`]); does nothing
/// without it.
pub fn set_reference_c(robot: &mut Robot, reference_c: f64) -> Result<()> {
    let Some(k) = robot.family_values(KEY).map(|v| v[K]) else {
        return Ok(());
    };
    enable(robot, reference_c)?;
    if let Some(v) = robot.family_values_mut(KEY) {
        v[K] = k;
    }
    Ok(())
}

/// The factor `exp(k (T - T_ref))` the lengths of `robot` take at `temperature_c`, when the
/// family is on, the temperature known and the factor not 1.
pub fn scale(robot: &Robot, temperature_c: f64) -> Option<f64> {
    let v = robot.family_values(KEY)?;
    let dt = temperature_c - v[REFERENCE];
    (dt.is_finite() && dt != 0.0 && v[K] != 0.0).then(|| (v[K] * dt).exp())
}

/// Whether `p` is one of the lengths thermal growth scales: a link's `d` or `a`. The base frame
/// `B` is where the robot stands in the cell (its offset from the measurement frame's origin is
/// no length of the arm), so it does not grow.
pub fn grows(p: Param) -> bool {
    p.family_id() == super::link::ID && (p.template() == 1 || p.template() == 2)
}

/// `robot` with every length thermal growth scales ([`grows`]) multiplied by `s`.
pub fn scaled_lengths(robot: &Robot, s: f64) -> Robot {
    let mut r = robot.clone();
    for p in robot.params().into_iter().filter(|p| grows(*p)) {
        r.set(p, robot.get(p) * s);
    }
    r
}
