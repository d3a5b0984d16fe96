//! The likely cause of an implausible fit, found by trying the usual mistakes one at a time.
//!
//! Each hypothesis undoes one mistake in the data — positions in another unit, a mirrored tracker
//! frame, joint values in radians, a reversed joint sign, a joint coupling the data lack — and
//! fits the nominal model to the corrected points by the best similarity transform (free scale,
//! rotation or reflection). A hypothesis explains the data when that fit is as good as a
//! plausible robot's (its RMS within the nominal-error limit) and at least twice as good as the
//! plain rigid fit, with a scale of 1 or of a known unit. What no hypothesis explains is put down
//! to a robot description that does not match the data.

use super::similarity::{fit_similarity, Handedness};
use crate::model::Robot;
use crate::observations::Observations;
use nalgebra::Vector3;

/// Units positions are commonly given in, as the scale that turns them into millimetres.
pub const KNOWN_UNITS: [(&str, f64); 5] = [
    ("metres", 1000.0),
    ("centimetres", 10.0),
    ("inches", 25.4),
    ("feet", 304.8),
    ("micrometres", 0.001),
];

/// A scale within this factor of a known unit's (or of 1) counts as that unit: robots' geometric
/// errors change the best scale by well under 5% (measured: at most 0.3% on real data, 1.7% with
/// ten times realistic errors).
pub const UNIT_MATCH_FACTOR: f64 = 1.05;

/// Largest number of points the hypotheses are fitted to (an even subsample of larger sets: the
/// diagnosis compares fits that differ by factors, not by per cent).
const MAX_POINTS: usize = 2000;

/// A way the joint values of a file can differ from the model's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointMistake {
    /// Radians written where degrees are expected.
    Radians,
    /// The sign of this joint (0-based) is reversed.
    Sign(usize),
    /// `joint` (0-based) is given without its coupling to `with`: the model's value is
    /// `sign * given + k * q_with` (e.g. FANUC's J2/J3: q3 = -(J2 + J3), sign -1, k -1).
    Coupling {
        /// The coupled joint.
        joint: usize,
        /// The joint it is coupled to.
        with: usize,
        /// Sign applied to the value given.
        sign: f64,
        /// Coefficient of the other joint.
        k: f64,
    },
}

impl JointMistake {
    /// Undoes the mistake on one joint vector (radians).
    fn correct(&self, q: &mut [f64]) {
        match *self {
            JointMistake::Radians => {
                for v in q.iter_mut() {
                    *v = v.to_degrees();
                }
            }
            JointMistake::Sign(i) => q[i] = -q[i],
            JointMistake::Coupling {
                joint,
                with,
                sign,
                k,
            } => q[joint] = sign * q[joint] + k * q[with],
        }
    }

    /// A phrase for messages.
    pub fn describe(&self) -> String {
        match *self {
            JointMistake::Radians => "the joint values are in radians, not degrees".into(),
            JointMistake::Sign(i) => format!("the sign of joint {} is reversed", i + 1),
            JointMistake::Coupling {
                joint,
                with,
                sign,
                k,
            } => {
                let (j, w) = (joint + 1, with + 1);
                let rule = match (sign < 0.0, k < 0.0) {
                    (true, true) => format!("q{j} = -(q{w} + value given)"),
                    (false, true) => format!("q{j} = value given - q{w}"),
                    (false, false) => format!("q{j} = value given + q{w}"),
                    (true, false) => format!("q{j} = q{w} - value given"),
                };
                format!(
                    "joint {j} is given without its coupling to joint {w} (the model needs \
                     {rule}, like a FANUC J2/J3 coupling)"
                )
            }
        }
    }
}

/// One explanation of the data: what was corrected and how well the model then fits.
#[derive(Debug, Clone, PartialEq)]
pub struct Explanation {
    /// The joint mistake undone, if any.
    pub joints: Option<JointMistake>,
    /// Whether the measured points had to be mirrored.
    pub mirrored: bool,
    /// The unit the positions appear to be in and its scale to mm, if not mm.
    pub unit: Option<(&'static str, f64)>,
    /// The best scale found.
    pub scale: f64,
    /// RMS of the fit with the mistake undone (mm).
    pub rms_mm: f64,
}

impl Explanation {
    /// A sentence for messages, e.g. `the positions are in metres (best scale 1000.02)`.
    pub fn describe(&self) -> String {
        let mut parts = Vec::new();
        if let Some((unit, _)) = self.unit {
            parts.push(format!(
                "the positions are in {unit}, not millimetres (best scale {})",
                sig(self.scale)
            ));
        }
        if self.mirrored {
            parts.push(
                "the measured points are mirrored (the tracker frame is left-handed: one axis \
                 reversed)"
                    .to_string(),
            );
        }
        if let Some(j) = &self.joints {
            parts.push(j.describe());
        }
        format!(
            "{}: corrected so, the nominal model fits the points to {:.3} mm RMS",
            parts.join(", and "),
            self.rms_mm
        )
    }
}

/// A number to four significant digits.
pub fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

/// The known unit a scale corresponds to, if any.
pub fn unit_of_scale(scale: f64) -> Option<(&'static str, f64)> {
    KNOWN_UNITS
        .into_iter()
        .find(|(_, f)| (scale / f).ln().abs() <= UNIT_MATCH_FACTOR.ln())
}

/// The joint mistakes tried: radians, each joint's sign, and for each pair of consecutive joints
/// the three usual couplings of the second to the first.
pub fn joint_mistakes(dof: usize) -> Vec<JointMistake> {
    let mut out = vec![JointMistake::Radians];
    out.extend((0..dof).map(JointMistake::Sign));
    for j in 1..dof {
        for (sign, k) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0)] {
            out.push(JointMistake::Coupling {
                joint: j,
                with: j - 1,
                sign,
                k,
            });
        }
    }
    out
}

/// The explanations of `obs` against `nominal` that bring its fit within `limit_mm` RMS and at
/// least halve `baseline_rms_mm` (the plain rigid fit's RMS), best first.
pub fn explain(
    nominal: &Robot,
    obs: &Observations,
    baseline_rms_mm: f64,
    limit_mm: f64,
) -> Vec<Explanation> {
    let stride = obs.len().div_ceil(MAX_POINTS).max(1);
    let idx: Vec<usize> = (0..obs.len()).step_by(stride).collect();
    let measured: Vec<Vector3<f64>> = idx.iter().map(|&i| *obs.m(i)).collect();
    let mut q = vec![0.0; obs.dof()];
    let mut out = Vec::new();
    let mistakes = std::iter::once(None).chain(joint_mistakes(obs.dof()).into_iter().map(Some));
    for mistake in mistakes {
        let target: Vec<Vector3<f64>> = idx
            .iter()
            .map(|&i| {
                q.copy_from_slice(obs.q(i));
                if let Some(m) = &mistake {
                    m.correct(&mut q);
                }
                nominal.tool_position(&q)
            })
            .collect();
        for mirrored in [false, true] {
            let hand = if mirrored {
                Handedness::Reflection
            } else {
                Handedness::Rotation
            };
            let Some(fit) = fit_similarity(&measured, &target, hand, true) else {
                continue;
            };
            let unit = unit_of_scale(fit.scale);
            let unit_scale = (fit.scale.ln().abs()) <= UNIT_MATCH_FACTOR.ln();
            if mistake.is_none() && !mirrored && unit_scale {
                continue; // nothing undone: not an explanation
            }
            if !(unit_scale || unit.is_some()) {
                continue;
            }
            if fit.rms <= limit_mm && fit.rms <= 0.5 * baseline_rms_mm {
                out.push(Explanation {
                    joints: mistake,
                    mirrored,
                    unit: if unit_scale { None } else { unit },
                    scale: fit.scale,
                    rms_mm: fit.rms,
                });
            }
        }
    }
    // A joint mistake that changes nothing (e.g. the sign of a last joint with the tool on its
    // axis) rides along with the real explanation: keep it only where it clearly helps.
    let plain: Vec<Explanation> = out.iter().filter(|e| e.joints.is_none()).cloned().collect();
    out.retain(|e| {
        e.joints.is_none()
            || !plain
                .iter()
                .any(|p| p.mirrored == e.mirrored && p.unit == e.unit && p.rms_mm <= 1.5 * e.rms_mm)
    });
    out.sort_by(|a, b| a.rms_mm.total_cmp(&b.rms_mm));
    out
}
