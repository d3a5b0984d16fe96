//! The result JSON of a calibration (DESIGN.md contract plus robocal's own keys).
//!
//! Contract keys: `parameters` (with `std` for identified and `reason` for fixed parameters),
//! `tracker_frame` (the registration frame F; the calibrated base frame B is among the
//! parameters) and `errors`. Further keys: `settings`, `registration`, `identifiability`,
//! `solver`, `uncertainty`, `downweighted_points`, `points` (per-point errors), `plausibility`
//! (the gate's checks) and `status` (with `partial_reason` or `implausible_reason`), each a
//! typed section of [`crate::io::result_sections`].

use crate::identification::identifiability::{FixReason, FixedParam};
use crate::identification::objective::{Loss, Objective, RobustLoss};
use crate::identification::param_vector::ParamVector;
use crate::identification::pipeline::{Calibration, SetErrors};
use crate::io::result::{BeforeAfter, ErrorTables, FrameVec, ParamEntry, RobotInfo, Status};
use crate::io::result_sections::{
    AffineEntry, CorrelationEntry, DownweightedEntry, DuplicateEntry, FixKind, FixedEntry,
    Identifiability, IdentifiedEntry, InitialFrameEntry, LossEntry, ObjectiveName, PointEntry,
    Points, Registration, RegistrationObjectiveName, Settings, Solver, StageEntry, Uncertainty,
};
use crate::io::CalibrationResult;
use crate::model::Param;
use crate::registration::{InitialFrame, RegistrationObjective};

/// Display-unit factor of a parameter (1 for mm, degrees per radian for angles).
fn unit_factor(p: Param) -> f64 {
    p.unit().from_internal(1.0)
}

fn loss_entry(l: &Loss) -> LossEntry {
    match *l {
        Loss::SumOfNorms { delta } => LossEntry::SumOfNorms {
            smoothing_mm: delta,
        },
        Loss::Squared => LossEntry::LeastSquares,
        Loss::Huber { k } => LossEntry::Huber { scale_mm: k },
        Loss::Cauchy { c } => LossEntry::Cauchy { scale_mm: c },
        Loss::Adaptive { k } => LossEntry::Adaptive { scale_mm: k },
    }
}

/// The result file's name of an objective.
fn objective_name(objective: &Objective) -> ObjectiveName {
    match objective {
        Objective::SumOfNorms => ObjectiveName::SumOfNorms,
        Objective::LeastSquares => ObjectiveName::LeastSquares,
        Objective::Robust(RobustLoss::Cauchy) => ObjectiveName::RobustCauchy,
        Objective::Robust(RobustLoss::Huber) => ObjectiveName::RobustHuber,
        Objective::Adaptive => ObjectiveName::Adaptive,
    }
}

fn point_entries(s: &SetErrors) -> Vec<PointEntry> {
    (0..s.before.len())
        .map(|i| PointEntry {
            line: s.lines[i],
            before_mm: s.before[i],
            after_mm: s.after[i],
        })
        .collect()
}

/// The result file's entry of a parameter the identifiability fixed.
fn fixed_entry(f: &FixedParam) -> FixedEntry {
    let (kind, independence, duplicates) = match &f.reason {
        FixReason::User => (FixKind::User, None, None),
        FixReason::NoEffect | FixReason::Unseen { .. } => (FixKind::NoEffect, None, None),
        FixReason::Undetermined { .. } => (FixKind::Undetermined, None, None),
        FixReason::AtBound { .. } => (FixKind::AtBound, None, None),
        FixReason::Duplicate { of, independence } => (
            FixKind::Duplicate,
            Some(*independence),
            Some(
                of.iter()
                    .map(|(q, c)| DuplicateEntry {
                        name: q.name(),
                        coefficient: c * unit_factor(*q) / unit_factor(f.param),
                    })
                    .collect(),
            ),
        ),
    };
    FixedEntry {
        name: f.param.name(),
        reason: f.describe(),
        kind,
        independence,
        duplicates,
    }
}

impl Calibration {
    /// The result file's content. The `settings` record the calibration's own settings; the
    /// caller adds its file names (`robot_arg`, `data`, `validate`, ...) to them.
    pub fn to_result(&self) -> CalibrationResult {
        let pv = self.param_vector();
        // A result is a calibration only when the solver converged and the fit passed the
        // plausibility gate; otherwise it is marked partial or implausible so that no reader
        // takes it for one.
        let termination = &self.solver().termination;
        let (status, partial_reason, implausible_reason) = if !termination.converged() {
            (
                Status::Partial,
                Some(format!("the solver {}", termination.describe())),
                None,
            )
        } else if self.plausibility.implausible() {
            (Status::Implausible, None, Some(self.plausibility.summary()))
        } else {
            (Status::Calibrated, None, None)
        };
        let mut result = CalibrationResult::new(
            RobotInfo::of(&self.nominal),
            self.parameter_entries(&pv),
            FrameVec::from_tracker_frame(self.tracker_frame()),
            self.error_tables(),
            status,
        );
        result.partial_reason = partial_reason;
        result.implausible_reason = implausible_reason;
        result.settings = Some(self.settings_section());
        result.model_selection = self
            .model_selection
            .as_ref()
            .map(crate::io::result_selection::ModelSelectionSection::of);
        result.registration = Some(self.registration_section());
        result.identifiability = Some(self.identifiability_section(&pv));
        result.solver = Some(self.solver_section());
        result.uncertainty = Some(self.uncertainty_section());
        result.downweighted_points = Some(
            self.downweighted
                .iter()
                .map(|d| DownweightedEntry {
                    line: d.line,
                    error_mm: d.error_mm,
                    orientation_deg: d.orientation_deg,
                    weight: d.weight,
                })
                .collect(),
        );
        result.points = Some(Points {
            calibration: point_entries(&self.calibration),
            validation: self.validation.as_ref().map(point_entries),
        });
        result.plausibility = Some(self.plausibility.to_section());
        result.orientation_errors = self.orientation_errors();
        result.prediction = self.prediction.as_ref().map(Into::into);
        crate::io::result_payload::record(&mut result, &self.calibrated);
        crate::io::result_thermal::record(&mut result, &self.calibrated);
        result
    }

    /// `parameters`: nominal and calibrated values, with the standard deviation of the
    /// identified ones and the reason of the fixed ones.
    fn parameter_entries(&self, pv: &ParamVector) -> indexmap::IndexMap<String, ParamEntry> {
        let mut parameters = CalibrationResult::parameter_entries(&self.nominal, &self.calibrated);
        for (name, e) in parameters.iter_mut() {
            let entry = pv.by_name(name).expect("names come from the robot");
            match &entry.fixed {
                None => {
                    e.fixed = false;
                    e.std = entry.std.map(|sd| entry.display(sd));
                    if let Some(why) = &self.covariance.unavailable {
                        e.reason =
                            Some(format!("identified; standard deviation unavailable: {why}"));
                    }
                }
                Some(f) => {
                    e.fixed = true;
                    e.reason = Some(f.describe());
                }
            }
        }
        parameters
    }

    /// `errors`: Tables II and IV, on the calibration and the validation points.
    fn error_tables(&self) -> ErrorTables {
        ErrorTables {
            calibration: BeforeAfter {
                before: self.calibration.before_stats(),
                after: self.calibration.after_stats(),
            },
            validation: self.validation.as_ref().map(|v| BeforeAfter {
                before: v.before_stats(),
                after: v.after_stats(),
            }),
        }
    }

    /// `identifiability`: the identified parameters with their independence and effect, the
    /// fixed ones with the reason.
    fn identifiability_section(&self, pv: &ParamVector) -> Identifiability {
        let id = &self.identifiability;
        let rms = |p: Param| {
            pv.get(p)
                .and_then(|e| e.rms_effect)
                .map_or(f64::NAN, |v| v / unit_factor(p))
        };
        Identifiability {
            rank_tolerance: id.rank_tolerance,
            condition_number: id.condition_number,
            condition_limit: crate::identification::MAX_CONDITION_NUMBER,
            ill_conditioned: id.ill_conditioned(),
            n_identified: id.identified.len(),
            n_fixed: id.fixed.len(),
            identified: id
                .identified
                .iter()
                .zip(&id.independence)
                .map(|(p, ind)| IdentifiedEntry {
                    name: p.name(),
                    independence: *ind,
                    rms_effect_mm_per_unit: rms(*p),
                    unit: p.unit(),
                })
                .collect(),
            fixed: id.fixed.iter().map(fixed_entry).collect(),
        }
    }

    /// `registration`: the measurement frame (eq. 8-11), its initial frame, the affine fit and
    /// the tool fit.
    fn registration_section(&self) -> Registration {
        let reg = &self.registration;
        let initial = match reg.initial {
            InitialFrame::Plane {
                n,
                tilt_deg,
                frame,
                max_error_mm,
            } => InitialFrameEntry::Plane {
                points: n,
                plane_tilt_deg: tilt_deg,
                frame: FrameVec::from_tracker_frame(&frame),
                max_error_mm,
            },
            InitialFrame::LeastSquares => InitialFrameEntry::LeastSquares,
        };
        Registration {
            objective: match reg.objective {
                RegistrationObjective::SumOfNorms => RegistrationObjectiveName::SumOfNorms,
                RegistrationObjective::LeastSquares => RegistrationObjectiveName::LeastSquares,
            },
            initial,
            iterations: reg.iterations,
            frame: FrameVec::from_tracker_frame(&reg.frame),
            stats: reg.stats,
            affine: reg.affine.as_ref().map(|a| AffineEntry {
                t: a.tr.parameters().to_vec(),
                singular_values: a.tr.singular_values().to_vec(),
                iterations: a.iterations,
                stats: a.stats,
            }),
            tool_fit: Some(crate::io::result_sections::ToolFitEntry {
                frame: FrameVec::from_tracker_frame(&self.tool_fit.frame),
                tools: self
                    .tool_fit
                    .tools
                    .iter()
                    .map(crate::frame::vec_rad_to_deg)
                    .collect(),
                iterations: self.tool_fit.iterations,
                converged: self.tool_fit.converged,
                applied: self.tool_fit.applied,
                stats: self.tool_fit.stats,
            }),
            validation_frame: self
                .validation_frame
                .as_ref()
                .map(FrameVec::from_tracker_frame),
        }
    }

    /// `settings`: the calibration's own settings (the caller adds its file names).
    fn settings_section(&self) -> Settings {
        let s = &self.settings;
        Settings {
            objective: objective_name(&s.objective),
            robust_scale_mm: self.robust_scale_mm,
            affine_registration: s.affine_registration,
            rank_tolerance: s.identifiability.rank_tolerance,
            fix: s.identifiability.fix.iter().map(|p| p.name()).collect(),
            free: s.identifiability.free.iter().map(|p| p.name()).collect(),
            max_iterations: s.solver.max_iterations,
            step_tolerance_mm: s.solver.step_tolerance_mm,
            gradient_tolerance: s.solver.gradient_tolerance,
            objective_tolerance: s.solver.objective_tolerance,
            beta: (0..self.nominal.dof())
                .filter(|&i| self.nominal.beta_enabled(i))
                .map(|i| format!("beta{}", i + 1))
                .collect(),
            robot_arg: None,
            data: None,
            validate: None,
            nominal_limits: None,
            rows_outside_limits: None,
            weighting: Some(self.weighting),
            other: Default::default(),
        }
    }

    /// `solver`: the whole solve (its iterations summed over the stages, the last stage's
    /// termination) and each stage.
    fn solver_section(&self) -> Solver {
        let last = self.solver();
        let stages = self
            .stages
            .iter()
            .map(|s| {
                let r = &s.report;
                StageEntry {
                    loss: loss_entry(&s.loss),
                    termination: r.termination.describe(),
                    converged: r.termination.converged(),
                    iterations: r.iterations,
                    evaluations: r.evaluations,
                    initial_objective: r.initial_objective,
                    final_objective: r.final_objective,
                    final_gradient: r.final_gradient,
                    last_step_mm: r.last_step_mm,
                    points: s.points,
                }
            })
            .collect();
        Solver {
            objective: objective_name(&self.settings.objective),
            termination: last.termination.describe(),
            converged: last.termination.converged(),
            iterations: self.stages.iter().map(|s| s.report.iterations).sum(),
            final_objective: last.final_objective,
            stages,
        }
    }

    /// `uncertainty`: the parameters' standard deviations and the most correlated pairs.
    fn uncertainty_section(&self) -> Uncertainty {
        let most_correlated = self
            .covariance
            .most_correlated(10)
            .into_iter()
            .map(|c| CorrelationEntry {
                a: c.a.name(),
                b: c.b.name(),
                rho: c.rho,
            })
            .collect();
        let std = self
            .covariance
            .params
            .iter()
            .zip(self.covariance.std())
            .map(|(p, sd)| (p.name(), sd.is_finite().then(|| p.unit().from_internal(sd))))
            .collect();
        Uncertainty {
            sigma_mm: self.covariance.sigma_mm,
            std,
            most_correlated,
            std_unavailable: self.covariance.unavailable.clone(),
        }
    }

    /// `orientation_errors`, when the rows measured orientations (6-DoF).
    fn orientation_errors(&self) -> Option<crate::io::result_cell::OrientationErrors> {
        use crate::io::result_cell::{AngleBeforeAfter, AngleStats, OrientationErrors};
        let pair = |b: &[f64], a: &[f64]| AngleBeforeAfter {
            before: AngleStats::of(b),
            after: AngleStats::of(a),
        };
        self.calibration
            .orientation_deg
            .as_ref()
            .map(|(b, a)| OrientationErrors {
                calibration: pair(b, a),
                validation: self
                    .validation
                    .as_ref()
                    .and_then(|v| v.orientation_deg.as_ref())
                    .map(|(b, a)| pair(b, a)),
            })
    }
}
