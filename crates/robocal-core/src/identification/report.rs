//! The result JSON of a calibration (DESIGN.md contract plus robocal's own keys).
//!
//! Contract keys: `parameters` (with `std` for identified and `reason` for fixed parameters),
//! `tracker_frame` (the registration frame F; the calibrated base frame B is among the
//! parameters) and `errors`. Further keys: `settings`, `registration`, `identifiability`,
//! `solver`, `uncertainty`, `downweighted_points`, `points` (per-point errors), `plausibility`
//! (the gate's checks) and `status` (with `partial_reason` or `implausible_reason`).

use crate::identification::identifiability::FixReason;
use crate::identification::objective::Loss;
use crate::identification::pipeline::{Calibration, SetErrors};
use crate::io::result::{BeforeAfter, ErrorTables, FrameVec, RobotInfo};
use crate::io::CalibrationResult;
use crate::model::{Param, Unit};
use crate::registration::{InitialFrame, RegistrationObjective};
use serde_json::{json, Map, Value};

/// Display-unit factor of a parameter (1 for mm, degrees per radian for angles).
fn unit_factor(p: Param) -> f64 {
    match p.unit() {
        Unit::Mm => 1.0,
        Unit::Deg => 180.0 / std::f64::consts::PI,
    }
}

fn loss_json(l: &Loss) -> Value {
    match *l {
        Loss::SumOfNorms { delta } => json!({"loss": "sum-of-norms", "smoothing_mm": delta}),
        Loss::Squared => json!({"loss": "least-squares"}),
        Loss::Huber { k } => json!({"loss": "huber", "scale_mm": k}),
        Loss::Cauchy { c } => json!({"loss": "cauchy", "scale_mm": c}),
    }
}

fn points_json(s: &SetErrors) -> Value {
    Value::Array(
        (0..s.before.len())
            .map(|i| json!({"line": s.lines[i], "before_mm": s.before[i], "after_mm": s.after[i]}))
            .collect(),
    )
}

impl Calibration {
    /// The result file's content. `extra_settings` (e.g. the CLI's file names) are merged into
    /// the `settings` object.
    pub fn to_result(&self, extra_settings: Map<String, Value>) -> CalibrationResult {
        let mut parameters = CalibrationResult::parameter_entries(&self.nominal, &self.calibrated);
        for (name, e) in parameters.iter_mut() {
            let p = self
                .calibrated
                .param_by_name(name)
                .expect("names come from the robot");
            if self.covariance.identifies(p) {
                e.fixed = false;
                e.std = self
                    .covariance
                    .std_of(p)
                    .map(|sd| p.unit().from_internal(sd));
                if let Some(why) = &self.covariance.unavailable {
                    e.reason = Some(format!("identified; standard deviation unavailable: {why}"));
                }
            } else {
                e.fixed = true;
                e.reason = Some(
                    self.identifiability
                        .fixed_reason(p)
                        .map_or("fixed".to_string(), |f| f.describe()),
                );
            }
        }
        let errors = ErrorTables {
            calibration: BeforeAfter {
                before: self.calibration.before_stats(),
                after: self.calibration.after_stats(),
            },
            validation: self.validation.as_ref().map(|v| BeforeAfter {
                before: v.before_stats(),
                after: v.after_stats(),
            }),
        };
        let id = &self.identifiability;
        let rms = |p: Param| {
            id.column_rms
                .iter()
                .find(|(q, _)| *q == p)
                .map_or(f64::NAN, |(_, v)| *v / unit_factor(p))
        };
        let identified: Vec<Value> = id
            .identified
            .iter()
            .zip(&id.independence)
            .map(|(p, ind)| {
                json!({
                    "name": p.name(),
                    "independence": ind,
                    "rms_effect_mm_per_unit": rms(*p),
                    "unit": p.unit().as_str(),
                })
            })
            .collect();
        let fixed: Vec<Value> = id
            .fixed
            .iter()
            .map(|f| {
                let mut o = json!({"name": f.param.name(), "reason": f.describe()});
                match &f.reason {
                    FixReason::User => o["kind"] = json!("user"),
                    FixReason::NoEffect | FixReason::Unseen { .. } => {
                        o["kind"] = json!("no_effect")
                    }
                    FixReason::Duplicate { of, independence } => {
                        o["kind"] = json!("duplicate");
                        o["independence"] = json!(independence);
                        o["duplicates"] = Value::Array(
                            of.iter()
                                .map(|(q, c)| {
                                    json!({
                                        "name": q.name(),
                                        "coefficient": c * unit_factor(*q) / unit_factor(f.param),
                                    })
                                })
                                .collect(),
                        );
                    }
                }
                o
            })
            .collect();
        let reg = &self.registration;
        let initial = match reg.initial {
            InitialFrame::Plane {
                n,
                tilt_deg,
                frame,
                max_error_mm,
            } => json!({
                "source": "plane points",
                "points": n,
                "plane_tilt_deg": tilt_deg,
                "frame": FrameVec::from_tracker_frame(&frame),
                "max_error_mm": max_error_mm,
            }),
            InitialFrame::LeastSquares => json!({"source": "least-squares fit"}),
        };
        let mut registration = json!({
            "objective": match reg.objective {
                RegistrationObjective::SumOfNorms => "sum-of-norms",
                RegistrationObjective::LeastSquares => "least-squares",
            },
            "initial": initial,
            "iterations": reg.iterations,
            "frame": FrameVec::from_tracker_frame(&reg.frame),
            "stats": reg.stats,
        });
        if let Some(a) = &reg.affine {
            registration["affine"] = json!({
                "t": a.tr.parameters(),
                "singular_values": a.tr.singular_values(),
                "iterations": a.iterations,
                "stats": a.stats,
            });
        }
        let stages: Vec<Value> = self
            .stages
            .iter()
            .map(|s| {
                let mut o = loss_json(&s.loss);
                let r = &s.report;
                o["termination"] = json!(r.termination.describe());
                o["converged"] = json!(r.termination.converged());
                o["iterations"] = json!(r.iterations);
                o["evaluations"] = json!(r.evaluations);
                o["initial_objective"] = json!(r.initial_objective);
                o["final_objective"] = json!(r.final_objective);
                o["final_gradient"] = json!(r.final_gradient);
                o["last_step_mm"] = json!(r.last_step_mm);
                o
            })
            .collect();
        let last = self.solver();
        let s = &self.settings;
        let mut settings = json!({
            "objective": s.objective.name(),
            "robust_scale_mm": self.robust_scale_mm,
            "affine_registration": s.affine_registration,
            "rank_tolerance": s.identifiability.rank_tolerance,
            "fix": s.identifiability.fix.iter().map(|p| p.name()).collect::<Vec<_>>(),
            "free": s.identifiability.free.iter().map(|p| p.name()).collect::<Vec<_>>(),
            "max_iterations": s.solver.max_iterations,
            "step_tolerance_mm": s.solver.step_tolerance_mm,
            "gradient_tolerance": s.solver.gradient_tolerance,
            "objective_tolerance": s.solver.objective_tolerance,
            "beta": (0..self.nominal.dof())
                .filter(|&i| self.nominal.beta_enabled(i))
                .map(|i| format!("beta{}", i + 1))
                .collect::<Vec<_>>(),
        });
        if let Value::Object(o) = &mut settings {
            o.extend(extra_settings);
        }
        let correlations: Vec<Value> = self
            .covariance
            .most_correlated(10)
            .into_iter()
            .map(|c| json!({"a": c.a.name(), "b": c.b.name(), "rho": c.rho}))
            .collect();
        let stds: Map<String, Value> = self
            .covariance
            .params
            .iter()
            .zip(self.covariance.std())
            .map(|(p, sd)| {
                let v = if sd.is_finite() {
                    json!(p.unit().from_internal(sd))
                } else {
                    Value::Null
                };
                (p.name(), v)
            })
            .collect();
        let mut extra = Map::new();
        extra.insert("settings".into(), settings);
        extra.insert("registration".into(), registration);
        extra.insert(
            "identifiability".into(),
            json!({
                "rank_tolerance": id.rank_tolerance,
                "condition_number": id.condition_number,
                "condition_limit": crate::identification::MAX_CONDITION_NUMBER,
                "ill_conditioned": id.ill_conditioned(),
                "n_identified": id.identified.len(),
                "n_fixed": id.fixed.len(),
                "identified": identified,
                "fixed": fixed,
            }),
        );
        extra.insert(
            "solver".into(),
            json!({
                "objective": s.objective.name(),
                "termination": last.termination.describe(),
                "converged": last.termination.converged(),
                "iterations": self.stages.iter().map(|s| s.report.iterations).sum::<usize>(),
                "final_objective": last.final_objective,
                "stages": stages,
            }),
        );
        let mut uncertainty = json!({
            "sigma_mm": self.covariance.sigma_mm,
            "std": stds,
            "most_correlated": correlations,
        });
        if let Some(why) = &self.covariance.unavailable {
            uncertainty["std_unavailable"] = json!(why);
        }
        extra.insert("uncertainty".into(), uncertainty);
        extra.insert(
            "downweighted_points".into(),
            Value::Array(
                self.downweighted
                    .iter()
                    .map(|d| json!({"line": d.line, "error_mm": d.error_mm, "weight": d.weight}))
                    .collect(),
            ),
        );
        let mut points = json!({"calibration": points_json(&self.calibration)});
        if let Some(v) = &self.validation {
            points["validation"] = points_json(v);
        }
        extra.insert("points".into(), points);
        // A result is a calibration only when the solver converged and the fit passed the
        // plausibility gate; otherwise it is marked partial or implausible so that no reader
        // takes it for one.
        let termination = &self.solver().termination;
        extra.insert("plausibility".into(), self.plausibility.to_json());
        if !termination.converged() {
            extra.insert("status".into(), json!(crate::io::result::STATUS_PARTIAL));
            extra.insert(
                "partial_reason".into(),
                json!(format!("the solver {}", termination.describe())),
            );
        } else if self.plausibility.implausible() {
            extra.insert(
                "status".into(),
                json!(crate::io::result::STATUS_IMPLAUSIBLE),
            );
            extra.insert(
                "implausible_reason".into(),
                json!(self.plausibility.summary()),
            );
        } else {
            extra.insert("status".into(), json!(crate::io::result::STATUS_CALIBRATED));
        }
        CalibrationResult {
            robot: RobotInfo::of(&self.nominal),
            parameters,
            tracker_frame: FrameVec::from_tracker_frame(&self.registration.frame),
            errors,
            extra,
        }
    }
}
