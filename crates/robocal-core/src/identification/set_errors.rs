//! The errors of a point set before and after calibration (Tables II and IV), and the points the
//! robust loss down-weighted: what the pipeline ([`super::pipeline`]) reports per point.

use crate::error::Result;
use crate::identification::objective::Loss;
use crate::identification::system::Problem;
use crate::model::Robot;
use crate::observations::Observations;
use crate::registration::Registration;
use crate::stats::ErrorStats;

/// Error norms of one set of points under the nominal and the calibrated model (mm): the
/// nominal model with the registration's frame (Table II), the calibrated one with the frame
/// the identification held.
#[derive(Debug, Clone, PartialEq)]
pub struct SetErrors {
    /// CSV line of each point.
    pub lines: Vec<usize>,
    /// Nominal model (Table II).
    pub before: Vec<f64>,
    /// Calibrated model (Table IV).
    pub after: Vec<f64>,
    /// Orientation errors (deg) before and after, for 6-DoF data.
    pub orientation_deg: Option<(Vec<f64>, Vec<f64>)>,
}

impl SetErrors {
    pub(crate) fn new(
        obs: &Observations,
        reg: &Registration,
        nominal: &Robot,
        frame: &crate::frame::TrackerFrame,
        cal: &Robot,
    ) -> SetErrors {
        let before = Problem::new(nominal, &[], obs, &reg.frame);
        let after = Problem::new(nominal, &[], obs, frame);
        SetErrors {
            lines: (0..obs.len()).map(|i| obs.line(i)).collect(),
            before: before.error_norms(nominal),
            after: after.error_norms(cal),
            orientation_deg: before
                .orientation_errors_deg(nominal)
                .zip(after.orientation_errors_deg(cal)),
        }
    }

    /// [`SetErrors::new`] for the calibration points `obs` that `reg` registered (the same
    /// points in the same order): for point measurements without conditions the errors before
    /// are the registration's residuals (Table II: the same numbers, the same forward pass and
    /// arithmetic), not computed again.
    pub(crate) fn of_calibration(
        obs: &Observations,
        reg: &Registration,
        nominal: &Robot,
        frame: &crate::frame::TrackerFrame,
        cal: &Robot,
    ) -> SetErrors {
        let same = obs.kind().key() == "point"
            && reg.residuals.len() == obs.len()
            && (0..obs.len()).all(|i| obs.conditions(i).is_unknown());
        // A registration of other points or of another model would show at once: the first,
        // middle and last points' errors are computed and must be the residuals, to the bit.
        let n = obs.len();
        let probe = [0, n / 2, n.saturating_sub(1)];
        let agrees = || {
            let Ok(sub) = obs.rows_where(|i| probe.contains(&i)) else {
                return false;
            };
            let e = Problem::new(nominal, &[], &sub, &reg.frame).error_norms(nominal);
            let mut at = probe.to_vec();
            at.dedup();
            e.len() == at.len()
                && e.iter()
                    .zip(&at)
                    .all(|(e, &i)| e.to_bits() == reg.residuals[i].to_bits())
        };
        if !(same && agrees()) {
            return SetErrors::new(obs, reg, nominal, frame, cal);
        }
        let after = Problem::new(nominal, &[], obs, frame);
        SetErrors {
            lines: (0..obs.len()).map(|i| obs.line(i)).collect(),
            before: reg.residuals.clone(),
            after: after.error_norms(cal),
            orientation_deg: None,
        }
    }

    /// The errors of `obs` with a frame of their own for each model: the nominal model with the
    /// rigid frame fitted to it, the calibrated one with the frame fitted to it (data measured
    /// from another tracker station). Returns the errors and the calibrated model's frame.
    pub(crate) fn refit(
        obs: &Observations,
        nominal: &Robot,
        cal: &Robot,
    ) -> Result<(SetErrors, crate::frame::TrackerFrame)> {
        let fb = crate::registration::refit_frame(nominal, obs)?;
        let fa = crate::registration::refit_frame(cal, obs)?;
        let before = Problem::new(nominal, &[], obs, &fb);
        let after = Problem::new(nominal, &[], obs, &fa);
        Ok((
            SetErrors {
                lines: (0..obs.len()).map(|i| obs.line(i)).collect(),
                before: before.error_norms(nominal),
                after: after.error_norms(cal),
                orientation_deg: before
                    .orientation_errors_deg(nominal)
                    .zip(after.orientation_errors_deg(cal)),
            },
            fa,
        ))
    }

    /// Statistics before calibration.
    pub fn before_stats(&self) -> ErrorStats {
        ErrorStats::from_norms(&self.before)
    }

    /// Statistics after calibration.
    pub fn after_stats(&self) -> ErrorStats {
        ErrorStats::from_norms(&self.after)
    }
}

/// A calibration point the robust loss down-weighted.
#[derive(Debug, Clone, PartialEq)]
pub struct DownWeighted {
    /// Index among the calibration points.
    pub index: usize,
    /// CSV line.
    pub line: usize,
    /// Error norm under the calibrated model (mm).
    pub error_mm: f64,
    /// Orientation error under the calibrated model (deg), for 6-DoF rows.
    pub orientation_deg: Option<f64>,
    /// Its weight relative to a perfectly fitting point (1).
    pub weight: f64,
}

impl DownWeighted {
    /// The observations whose residual as the loss sees it (`norms`: position and orientation
    /// rows, weighted; [`Problem::fit_norms`] at the calibrated model) exceeds the robust scale
    /// `c` (mm), worst first: an orientation row far off is listed like a position far off.
    pub(crate) fn list(
        norms: &[f64],
        errors: &SetErrors,
        loss: &Loss,
        c: f64,
    ) -> Vec<DownWeighted> {
        let mut out: Vec<(f64, DownWeighted)> = norms
            .iter()
            .enumerate()
            .filter(|(_, &r)| r > c)
            .map(|(i, &r)| {
                (
                    r,
                    DownWeighted {
                        index: i,
                        line: errors.lines[i],
                        error_mm: errors.after[i],
                        orientation_deg: errors.orientation_deg.as_ref().map(|(_, a)| a[i]),
                        weight: loss.weight(r),
                    },
                )
            })
            .collect();
        out.sort_by(|a, b| b.0.total_cmp(&a.0));
        out.into_iter().map(|(_, d)| d).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{pose, TrackerFrame};
    use crate::model::presets::preset;
    use crate::registration::{register, RegistrationOptions};
    use crate::simulation::{random_poses, PoseSampler, Tracker};
    use rand::SeedableRng;

    /// The calibration points' errors from the registration's residuals are those computed
    /// afresh, to the bit; points the registration did not see, or another model, fall back to
    /// computing them.
    #[test]
    fn calibration_errors_reuse_the_registration_to_the_bit() {
        let truth = preset("kuka-kr480-r3330-table3").unwrap();
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let tracker = Tracker::new(
            TrackerFrame::new(pose(&[3900.0, -2200.0, -350.0, 2.65, 0.007, -0.012])),
            0.01,
            0.005,
        )
        .unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let sampler = PoseSampler {
            floor_z_mm: 0.0,
            footprint_radius_mm: 800.0,
            max_tries_per_pose: 10_000,
        };
        let measure = |n: usize, rng: &mut rand_chacha::ChaCha8Rng| {
            let mut obs = Observations::new(6);
            for (i, q) in random_poses(&truth, n, &sampler, rng)
                .unwrap()
                .iter()
                .enumerate()
            {
                obs.push(q, tracker.measure(&truth.tool_position(q), rng), i + 2)
                    .unwrap();
            }
            obs
        };
        let cal = measure(60, &mut rng);
        let other = measure(60, &mut rng);
        let reg = register(&nominal, &cal, None, &RegistrationOptions::default()).unwrap();
        let frame = TrackerFrame::new(pose(&[3901.0, -2199.0, -350.5, 2.651, 0.007, -0.012]));
        let fresh = SetErrors::new(&cal, &reg, &nominal, &frame, &truth);
        let reused = SetErrors::of_calibration(&cal, &reg, &nominal, &frame, &truth);
        assert_eq!(reused, fresh);
        assert_eq!(reused.before, reg.residuals);
        // Other points of the same count: computed, not taken from the registration.
        let fresh = SetErrors::new(&other, &reg, &nominal, &frame, &truth);
        assert_eq!(
            SetErrors::of_calibration(&other, &reg, &nominal, &frame, &truth),
            fresh
        );
        assert_ne!(fresh.before, reg.residuals);
        // Another nominal model: likewise.
        let fresh = SetErrors::new(&cal, &reg, &truth, &frame, &truth);
        assert_eq!(
            SetErrors::of_calibration(&cal, &reg, &truth, &frame, &truth),
            fresh
        );
        assert_ne!(fresh.before, reg.residuals);
    }
}
