//! The measured points against a model's shape, free of any frame: the gate's units and
//! handedness checks. They depend only on the data and the model's tool points, so the
//! candidates of a model selection, which share those points, share them too ([`ShapeChecks`]).

use super::diagnosis::{sig, unit_of_scale};
use super::similarity::{fit_similarity, Handedness};
use super::{check, Check, CheckKind, HANDEDNESS_LIMIT, SCALE_GAIN, SCALE_LIMIT};
use crate::model::Robot;
use crate::observations::Observations;

/// The measured points against a model's shape, free of any frame: the best rigid fit, the best
/// uniform scale (units) and the best reflection (handedness).
#[derive(Clone, Copy)]
pub(super) struct Shape {
    /// RMS of the best rigid fit (mm; NaN when the points coincide).
    pub rigid_rms: f64,
    /// The best uniform scale (NaN when the points coincide).
    pub scale: f64,
}

impl Shape {
    /// Fits `obs`'s measured points to `robot`'s tool points, pushing the units and handedness
    /// checks to `checks`.
    pub(super) fn of(obs: &Observations, robot: &Robot, checks: &mut Vec<Check>) -> Shape {
        let measured = obs.measured();
        let model = obs.model_positions(robot);
        let rigid = fit_similarity(measured, &model, Handedness::Rotation, false);
        let scaled = fit_similarity(measured, &model, Handedness::Rotation, true);
        let mirrored = fit_similarity(measured, &model, Handedness::Reflection, true);
        let baseline_rms = rigid.map_or(f64::NAN, |f| f.rms);
        match (rigid, scaled) {
            (Some(r), Some(s)) => {
                let factor = s.scale.max(1.0 / s.scale);
                let gain = r.rms / s.rms;
                let passed = !(factor > SCALE_LIMIT && gain >= SCALE_GAIN);
                let unit = unit_of_scale(s.scale)
                    .filter(|(_, f)| *f != 1.0)
                    .map_or(String::new(), |(u, _)| format!(", the scale of {u}"));
                checks.push(check(
                    CheckKind::Units,
                    factor,
                    SCALE_LIMIT,
                    "factor",
                    passed,
                    format!(
                        "the measured points fit the nominal model best at scale {}{unit} \
                         ({:.3} mm RMS, against {:.3} mm at scale 1); limit: within a factor {} of \
                         1 unless the scale improves the fit less than {}-fold",
                        sig(s.scale),
                        s.rms,
                        r.rms,
                        SCALE_LIMIT,
                        SCALE_GAIN
                    ),
                ));
            }
            _ => checks.push(check(
                CheckKind::Units,
                f64::NAN,
                SCALE_LIMIT,
                "factor",
                true,
                "not measurable: the measured points coincide".into(),
            )),
        }
        match (scaled, mirrored) {
            (Some(s), Some(m)) => {
                let ratio = if s.rms > 0.0 {
                    m.rms / s.rms
                } else {
                    f64::INFINITY
                };
                checks.push(check(
                    CheckKind::Handedness,
                    ratio,
                    HANDEDNESS_LIMIT,
                    "ratio",
                    ratio >= HANDEDNESS_LIMIT,
                    format!(
                        "the best reflection fits the measured points to {:.3} mm RMS, the best \
                         rotation to {:.3} mm (ratio {}); limit: a reflection must not fit better \
                         than {} times the rotation's RMS",
                        m.rms,
                        s.rms,
                        sig(ratio),
                        HANDEDNESS_LIMIT
                    ),
                ));
            }
            _ => checks.push(check(
                CheckKind::Handedness,
                f64::NAN,
                HANDEDNESS_LIMIT,
                "ratio",
                true,
                "not measurable: the measured points coincide".into(),
            )),
        }

        Shape {
            rigid_rms: baseline_rms,
            scale: scaled.map_or(f64::NAN, |s| s.scale),
        }
    }
}

/// The shape checks of a data set against a model's tool points, computed once for the models
/// that share them (a model selection's candidates: [`super::assess_with`]).
pub(crate) struct ShapeChecks {
    pub(super) shape: Shape,
    pub(super) checks: Vec<Check>,
}

impl ShapeChecks {
    /// The checks of `obs`'s measured points against `robot`'s tool points.
    pub(crate) fn of(obs: &Observations, robot: &Robot) -> ShapeChecks {
        let mut checks = Vec::new();
        let shape = Shape::of(obs, robot, &mut checks);
        ShapeChecks { shape, checks }
    }
}
