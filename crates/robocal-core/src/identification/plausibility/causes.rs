//! The likely cause of a failed check, in words.

use super::diagnosis::{sig, Explanation};
use super::CheckKind;

/// What the likely cause of a failure is made from.
pub(super) struct Causes<'a> {
    pub(super) explanations: &'a [Explanation],
    pub(super) radians: bool,
    pub(super) scale: f64,
    pub(super) failed: Vec<CheckKind>,
    pub(super) max_iterations: usize,
}

impl Causes<'_> {
    /// Gives each failed check its likely cause.
    pub(super) fn attach(&self, checks: &mut [super::Check]) {
        for c in checks.iter_mut().filter(|c| !c.passed) {
            c.cause = Some(self.of(c.kind));
        }
    }

    /// The likely cause of a failed check: the corrections that explain the data if there are
    /// any; else, when the nominal model does not fit the points, a robot description that does
    /// not match them; else what the check alone suggests.
    pub(super) fn of(&self, kind: CheckKind) -> String {
        let failed = |k: CheckKind| self.failed.contains(&k);
        let radians_hint = if self.radians {
            "; the joint values all lie within ±2π while the joint limits span far more: they \
             look like radians"
        } else {
            ""
        };
        if kind == CheckKind::Convergence {
            return format!(
                "the solver stopped at its iteration limit ({}) before converging",
                self.max_iterations
            );
        }
        let data_wide =
            kind != CheckKind::ValidationNominalError || failed(CheckKind::NominalError);
        if data_wide && !self.explanations.is_empty() {
            let all: Vec<String> = self
                .explanations
                .iter()
                .take(3)
                .map(|e| e.describe())
                .collect();
            return all.join("; or ");
        }
        if data_wide && failed(CheckKind::NominalError) {
            let mut extra = String::new();
            if failed(CheckKind::Units) {
                extra.push_str(&format!(
                    "; the points are {} times the model's size, which is no length unit",
                    sig(self.scale)
                ));
            }
            if failed(CheckKind::Handedness) {
                extra.push_str("; they are closer to the model's mirror image than to the model");
            }
            return format!(
                "the robot description does not match the data: a different robot, or joint \
                 values that are not the model's (zero offsets, signs, couplings); no change of \
                 unit, handedness, joint unit, joint sign or J2/J3-style coupling makes the \
                 nominal model fit{extra}{radians_hint}"
            );
        }
        match kind {
            CheckKind::Improvement => "the fit was pulled away from the data: a point with far \
                 too small an uncertainty, a group of inconsistent points (another reflector, \
                 another set-up), or a model family the data cannot support; check the points \
                 the fit lists and the uncertainties"
                .to_string(),
            CheckKind::DiscardedPoints => "a large part of the data disagrees with the rest: \
                 rows of another reflector or tool, another set-up or tracker station, joint \
                 values with an offset on some rows; the points listed as down-weighted show \
                 which"
                .to_string(),
            CheckKind::Residuals => "the model cannot explain the data to anywhere near the \
                 measurement's uncertainty: inconsistent rows (another reflector, a joint offset \
                 on part of the data), an error the model lacks (compliance, backlash), or an \
                 uncertainty far smaller than the measurement's (the tracker model, `sigma_mm`)"
                .to_string(),
            CheckKind::WeightShare => "one point's uncertainty (`sigma_mm`) is so much smaller \
                 than the others' that it alone decides the fit; check its value"
                .to_string(),
            CheckKind::ParameterRanges => "the data ask more of a compliance or transmission \
                 error than a real joint can give: the family absorbs an error of another kind \
                 (a wrong payload, a geometric error the model lacks, outliers), or the poses \
                 hardly excite it. Fix that parameter (identification setting `fix`), leave the \
                 family out, or measure poses that load the joint"
                .to_string(),
            CheckKind::Units => format!(
                "the data are {} times the size of the nominal model, which is no length unit: a \
                 different robot{radians_hint}",
                sig(self.scale)
            ),
            CheckKind::Handedness => format!(
                "the measured points are closer to a mirror image of the model than to the \
                 model: a mirrored (left-handed) tracker frame or a reversed joint sign, together \
                 with a further mismatch; or a different robot{radians_hint}"
            ),
            CheckKind::ValidationNominalError => format!(
                "the validation points do not match the calibration points: measured in another \
                 unit, frame or set-up, or of another robot{radians_hint}"
            ),
            _ => format!(
                "a calibration corrects errors of millimetres and tenths of a degree: a \
                 parameter the poses hardly determine, a wrong nominal value (the tool, a link), \
                 or data of a different robot{radians_hint}"
            ),
        }
    }
}
