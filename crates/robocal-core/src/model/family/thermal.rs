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
//! Per link ([`enable_per_link`]): one coefficient per link, `thermal_k{j}` scaling link j's
//! `d` and `a`, for an arm that does not warm evenly (the links next to the motors and
//! reducers warm more than the measured temperature says, a long cast link less): link j's
//! lengths grow by `exp(k_j (T - T_ref))`. A link without length (`d` and `a` both zero) has no
//! effect, and one whose growth moves the tool point as a combination of the others' does
//! (a link's `d` along the same axis as the next one's, say) is not separable from them: the
//! identifiability analysis fixes those coefficients and says which.
//!
//! Jacobian column: `dp/dk = (T - T_ref) * sum_L L(T) * dp/dL`, the lengths' own columns (each a
//! translation along a frame's axis) weighted by their grown values (per link: the sum over that
//! link's two lengths). With one temperature for all rows the column is zero, and the
//! identifiability analysis fixes `k`.

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

// Store layout: [k (1/K), reference temperature (deg C)] for the lumped coefficient; per link
// [0, reference temperature, k_1 .. k_n] (1/K).
const K: usize = 0;
const REFERENCE: usize = 1;
const LINKS: usize = 2;

/// The thermal expansion family (see the module docs).
pub struct Thermal;

fn param() -> Param {
    Param::new(ID, 0, 0)
}

/// The store's slot of parameter `p` (template 0: the lumped `thermal_k`; 1: `thermal_k{j}`).
fn slot(p: Param) -> usize {
    if p.template() == 1 {
        LINKS + p.index()
    } else {
        K
    }
}

/// Whether the store `v` holds one coefficient per link.
fn is_per_link(v: &[f64]) -> bool {
    v.len() > LINKS
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
        &["thermal_k", "thermal_k{j}"]
    }

    fn unit(&self, _p: Param) -> Unit {
        Unit::PpmPerK
    }

    fn params(&self, robot: &Robot, out: &mut Vec<Param>) {
        match robot.family_values(KEY) {
            Some(v) if is_per_link(v) => {
                out.extend((0..robot.dof()).map(|i| Param::new(ID, 1, i as u16)));
            }
            Some(_) => out.push(param()),
            None => {}
        }
    }

    fn get(&self, robot: &Robot, p: Param) -> f64 {
        robot
            .family_values(KEY)
            .and_then(|v| v.get(slot(p)).copied())
            .unwrap_or(0.0)
    }

    fn set(&self, robot: &mut Robot, p: Param, value: f64) {
        if let Some(v) = robot.family_values_mut(KEY) {
            if let Some(x) = v.get_mut(slot(p)) {
                *x = value;
            }
        }
    }

    fn priority(&self, _robot: &Robot, p: Param) -> u32 {
        super::priority::NON_GEOMETRIC + 70_000 + 100 * p.template() as u32 + p.index() as u32
    }

    /// Within `-`[`MAX_PPM_PER_K`]`..`[`MAX_PPM_PER_K`]: structures of steel, cast iron,
    /// aluminium and carbon fibre lie within -1..25 ppm/K; the lumped coefficient also absorbs
    /// how unevenly the arm warms, hence the margin.
    fn plausible(&self, robot: &Robot, _p: Param) -> super::plausible::Plausible {
        super::plausible::Plausible::of_unit(robot, crate::model::Unit::PpmPerK)
    }

    fn enable(&self, robot: &mut Robot, p: Param) -> Result<()> {
        let reference = reference_c(robot).unwrap_or(DEFAULT_REFERENCE_C);
        match (p.template(), robot.family_values(KEY).map(is_per_link)) {
            (0, None) => enable(robot, reference),
            (1, None | Some(false)) if p.index() < robot.dof() => enable_per_link(robot, reference),
            _ => Ok(()),
        }
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
        let known = dt.is_finite() && dt != 0.0;
        // Link i's growth: its two lengths' columns weighted by their grown values.
        let link = |i: usize, k: f64| -> Vector3<f64> {
            let l = &robot.links()[i];
            let z: Vector3<f64> = pose.axis[i].rotation.matrix().column(2).into();
            let x: Vector3<f64> = pose.link[i].rotation.matrix().column(0).into();
            (z * l.d + x * l.a) * ((k * dt).exp() * dt)
        };
        if is_per_link(v) {
            for i in 0..robot.dof() {
                dp[i] = if known {
                    link(i, v[LINKS + i])
                } else {
                    Vector3::zeros()
                };
                put(&mut dw, i, Vector3::zeros());
            }
            return;
        }
        let mut col = Vector3::zeros();
        if known {
            for i in 0..robot.dof() {
                col += link(i, v[K]);
            }
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

/// Makes one coefficient per link (`thermal_k{j}`, at 0) parameters of `robot` instead of the
/// lumped one, the model's lengths holding at `reference_c` (deg C, within -50..150).
pub fn enable_per_link(robot: &mut Robot, reference_c: f64) -> Result<()> {
    enable(robot, reference_c)?;
    let mut v = vec![0.0; LINKS + robot.dof()];
    v[REFERENCE] = reference_c;
    robot.set_family_values(KEY, Some(v))
}

/// Whether `robot` models thermal expansion with one coefficient per link.
pub fn per_link(robot: &Robot) -> bool {
    robot.family_values(KEY).is_some_and(is_per_link)
}

/// The temperature at which `robot`'s lengths hold (deg C), when it models thermal expansion.
pub fn reference_c(robot: &Robot) -> Option<f64> {
    robot.family_values(KEY).map(|v| v[REFERENCE])
}

/// Sets the reference temperature of a model with the family (see [`enable`]), its
/// coefficients kept; does nothing without it.
pub fn set_reference_c(robot: &mut Robot, reference_c: f64) -> Result<()> {
    let Some(mut v) = robot.family_values(KEY).map(<[f64]>::to_vec) else {
        return Ok(());
    };
    // Checks the temperature.
    enable(&mut robot.clone(), reference_c)?;
    v[REFERENCE] = reference_c;
    robot.set_family_values(KEY, Some(v))
}

/// The factor `exp(k_j (T - T_ref))` each link's lengths take at `temperature_c` (the lumped
/// `k` for every link), when the family is on, the temperature known and some factor not 1.
pub fn link_scales(robot: &Robot, temperature_c: f64) -> Option<Vec<f64>> {
    let v = robot.family_values(KEY)?;
    let dt = temperature_c - v[REFERENCE];
    if !(dt.is_finite() && dt != 0.0) {
        return None;
    }
    let s: Vec<f64> = (0..robot.dof())
        .map(|i| {
            let k = if is_per_link(v) { v[LINKS + i] } else { v[K] };
            (k * dt).exp()
        })
        .collect();
    s.iter().any(|x| *x != 1.0).then_some(s)
}

/// Whether `p` is one of the lengths thermal growth scales: a link's `d` or `a`. The base frame
/// `B` is where the robot stands in the cell (its offset from the measurement frame's origin is
/// no length of the arm), so it does not grow.
pub fn grows(p: Param) -> bool {
    p.family_id() == super::link::ID && (p.template() == 1 || p.template() == 2)
}

/// `robot` with every length thermal growth scales ([`grows`]) multiplied by `s`.
pub fn scaled_lengths(robot: &Robot, s: f64) -> Robot {
    scaled_links(robot, &vec![s; robot.dof()])
}

/// `robot` with link j's lengths (`d` and `a`) multiplied by `s[j]`.
pub fn scaled_links(robot: &Robot, s: &[f64]) -> Robot {
    let mut r = robot.clone();
    for p in robot.params().into_iter().filter(|p| grows(*p)) {
        r.set(p, robot.get(p) * s[p.index()]);
    }
    r
}
