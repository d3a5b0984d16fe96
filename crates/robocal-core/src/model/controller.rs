//! The controller's axis map (DESIGN.md, "Robot file additions", `[controller]`): how the values a
//! robot controller shows (`axis1..axisN`) relate to the model's joint values (`q1..qn`).
//!
//! `q_i = sign_i * axis_i + offset_i + sum over coupling rows (i, j, k) of k * axis_j`
//!
//! in display units (degrees for a revolute joint, mm for a prismatic one; a coupling factor
//! relates display values). That is an affine map `q = M axis + offset` with
//! `M = diag(sign) + C`; [`Controller::new`] builds `M` and its inverse once and refuses a map
//! that cannot be inverted, so both directions are exact matrix products afterwards.
//!
//! Examples: the KUKA presets `sign = [-1, 1, 1, -1, 1, -1]` (q = -A1, A2, A3, -A4, A5, -A6); a
//! FANUC-style J2/J3 coupling `q3 = -(J2 + J3)`: `sign3 = -1` and the coupling row `(3, 2, -1)`.

use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// One coupling term: model joint `joint` gets `factor * axis_{axis}` added (0-based indices).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// The model joint that receives the term (0-based).
    pub joint: usize,
    /// The controller axis whose value is added (0-based).
    pub axis: usize,
    /// The factor (display units of the joint per display unit of the axis).
    pub factor: f64,
}

/// Smallest ratio of the map's smallest to largest singular value accepted as invertible.
const MIN_CONDITION_RATIO: f64 = 1e-9;

/// The map between controller axes and model joint values (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    sign: Vec<f64>,
    offset: Vec<f64>,
    coupling: Vec<Coupling>,
    /// `M`: q = M axis + offset.
    to_model: DMatrix<f64>,
    /// `M^-1`: axis = M^-1 (q - offset).
    to_controller: DMatrix<f64>,
}

impl Controller {
    /// The identity map for `n` joints (what applies to a robot without a `[controller]`).
    pub fn identity(n: usize) -> Controller {
        Controller {
            sign: vec![1.0; n],
            offset: vec![0.0; n],
            coupling: Vec::new(),
            to_model: DMatrix::identity(n, n),
            to_controller: DMatrix::identity(n, n),
        }
    }

    /// Builds the map and checks it: one sign (+1 or -1) and one finite offset (display units)
    /// per joint, coupling indices within the joints and not coupling a joint with its own axis
    /// (that is what the sign is for), finite factors, and an invertible map. Errors name the
    /// field (`controller.sign`, `controller.offset`, `controller.coupling`) and the entry.
    pub fn new(sign: Vec<f64>, offset: Vec<f64>, coupling: Vec<Coupling>) -> Result<Controller> {
        let n = sign.len();
        if n == 0 {
            return Err(Error::invalid("controller.sign", "no joints"));
        }
        if offset.len() != n {
            return Err(Error::invalid(
                "controller.offset",
                format!("{} offsets for {n} signs", offset.len()),
            ));
        }
        if let Some((i, s)) = sign
            .iter()
            .enumerate()
            .find(|(_, s)| **s != 1.0 && **s != -1.0)
        {
            return Err(Error::invalid(
                format!("controller.sign[{}]", i + 1),
                format!("{s} is not +1 or -1"),
            ));
        }
        // The range of a joint value (degrees, or mm for a prismatic joint: the smaller bound
        // of the two, 1e5, serves both).
        for (i, o) in offset.iter().enumerate() {
            crate::ranges::JOINT
                .check(*o)
                .map_err(|m| Error::invalid(format!("controller.offset[{}]", i + 1), m))?;
        }
        let mut m = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&sign));
        for (r, c) in coupling.iter().enumerate() {
            let field = format!("controller.coupling[{}]", r + 1);
            if c.joint >= n || c.axis >= n {
                return Err(Error::invalid(
                    field,
                    format!(
                        "joint {} / axis {}: indices must lie in 1..{n}",
                        c.joint + 1,
                        c.axis + 1
                    ),
                ));
            }
            if c.joint == c.axis {
                return Err(Error::invalid(
                    field,
                    format!(
                        "couples joint {} with its own axis; use sign (and offset) for that",
                        c.joint + 1
                    ),
                ));
            }
            crate::ranges::COUPLING
                .check(c.factor)
                .map_err(|m| Error::invalid(field.clone(), format!("factor: {m}")))?;
            m[(c.joint, c.axis)] += c.factor;
        }
        let sv = m.clone().singular_values();
        let (lo, hi) = (sv.min(), sv.max());
        if !lo.is_finite() || lo <= MIN_CONDITION_RATIO * hi {
            return Err(Error::invalid(
                "controller.coupling",
                format!(
                    "the map from controller axes to joint values is singular (smallest singular \
                     value {lo:.3e}, largest {hi:.3e}): two joints would follow one axis, so \
                     joint values could not be turned back into axis values"
                ),
            ));
        }
        let inv = m
            .clone()
            .try_inverse()
            .ok_or_else(|| Error::invalid("controller.coupling", "the map cannot be inverted"))?;
        Ok(Controller {
            sign,
            offset,
            coupling,
            to_model: m,
            to_controller: inv,
        })
    }

    /// Number of joints (= axes).
    pub fn dof(&self) -> usize {
        self.sign.len()
    }

    /// The signs, one per joint.
    pub fn sign(&self) -> &[f64] {
        &self.sign
    }

    /// The offsets (display units: degrees, or mm for a prismatic joint), one per joint.
    pub fn offset(&self) -> &[f64] {
        &self.offset
    }

    /// The coupling terms.
    pub fn coupling(&self) -> &[Coupling] {
        &self.coupling
    }

    /// The matrix `M` of `q = M axis + offset`.
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.to_model
    }

    /// Whether the map is the identity (all signs +1, no offsets, no coupling).
    pub fn is_identity(&self) -> bool {
        self.sign.iter().all(|s| *s == 1.0)
            && self.offset.iter().all(|o| *o == 0.0)
            && self.coupling.iter().all(|c| c.factor == 0.0)
    }

    /// Model joint values from controller axis values (both in display units).
    ///
    /// Panics if `axis` does not have [`Controller::dof`] entries (callers check counts).
    pub fn to_model(&self, axis: &[f64]) -> Vec<f64> {
        assert_eq!(axis.len(), self.dof(), "axis vector length");
        (0..self.dof())
            .map(|i| {
                self.offset[i]
                    + (0..self.dof())
                        .map(|j| self.to_model[(i, j)] * axis[j])
                        .sum::<f64>()
            })
            .collect()
    }

    /// Controller axis values from model joint values (both in display units): the inverse of
    /// [`Controller::to_model`].
    ///
    /// Panics if `q` does not have [`Controller::dof`] entries (callers check counts).
    pub fn to_controller(&self, q: &[f64]) -> Vec<f64> {
        assert_eq!(q.len(), self.dof(), "joint vector length");
        (0..self.dof())
            .map(|i| {
                (0..self.dof())
                    .map(|j| self.to_controller[(i, j)] * (q[j] - self.offset[j]))
                    .sum::<f64>()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip(c: &Controller, axes: &[Vec<f64>]) {
        for a in axes {
            let q = c.to_model(a);
            let back = c.to_controller(&q);
            for (x, y) in a.iter().zip(&back) {
                assert!(
                    (x - y).abs() <= 1e-12 * (1.0 + x.abs()),
                    "{a:?} -> {q:?} -> {back:?}"
                );
            }
        }
    }

    fn samples(n: usize) -> Vec<Vec<f64>> {
        (0..50)
            .map(|k| {
                (0..n)
                    .map(|i| ((k * 7 + i * 13) % 37) as f64 * 9.7 - 170.0)
                    .collect()
            })
            .collect()
    }

    #[test]
    fn kuka_signs() {
        let c =
            Controller::new(vec![-1.0, 1.0, 1.0, -1.0, 1.0, -1.0], vec![0.0; 6], vec![]).unwrap();
        let q = c.to_model(&[10.0, 20.0, 30.0, 40.0, 50.0, 60.0]);
        assert_eq!(q, vec![-10.0, 20.0, 30.0, -40.0, 50.0, -60.0]);
        roundtrip(&c, &samples(6));
        assert!(!c.is_identity());
        assert!(Controller::identity(6).is_identity());
    }

    #[test]
    fn fanuc_j2_j3_coupling() {
        // q3 = -(J2 + J3): sign3 = -1, coupling (3, 2, -1).
        let mut sign = vec![1.0; 6];
        sign[2] = -1.0;
        let c = Controller::new(
            sign,
            vec![0.0, 0.0, 0.0, 0.0, 0.0, 180.0],
            vec![Coupling {
                joint: 2,
                axis: 1,
                factor: -1.0,
            }],
        )
        .unwrap();
        let q = c.to_model(&[1.0, 20.0, 5.0, 0.0, 0.0, 0.0]);
        assert_eq!(q, vec![1.0, 20.0, -25.0, 0.0, 0.0, 180.0]);
        roundtrip(&c, &samples(6));
    }

    #[test]
    fn bad_maps_are_refused() {
        let e = |r: Result<Controller>| r.unwrap_err().to_string();
        assert!(e(Controller::new(vec![1.0, 0.5], vec![0.0; 2], vec![]))
            .contains("controller.sign[2]: 0.5 is not +1 or -1"));
        assert!(e(Controller::new(vec![1.0; 2], vec![0.0; 3], vec![]))
            .contains("controller.offset: 3 offsets for 2 signs"));
        let c = |joint, axis, factor| Coupling {
            joint,
            axis,
            factor,
        };
        assert!(e(Controller::new(
            vec![1.0; 2],
            vec![0.0; 2],
            vec![c(2, 0, 1.0)]
        ))
        .contains("controller.coupling[1]"));
        assert!(e(Controller::new(
            vec![1.0; 2],
            vec![0.0; 2],
            vec![c(1, 1, 1.0)]
        ))
        .contains("its own axis"));
        // q1 = a1 + a2, q2 = a1 + a2: singular.
        let s = e(Controller::new(
            vec![1.0; 2],
            vec![0.0; 2],
            vec![c(0, 1, 1.0), c(1, 0, 1.0)],
        ));
        assert!(
            s.contains("controller.coupling") && s.contains("singular"),
            "{s}"
        );
    }
}
