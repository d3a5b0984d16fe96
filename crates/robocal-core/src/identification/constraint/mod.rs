//! Calibration without a laser tracker (issue 31): from rows that put the tool point at fixed,
//! unknown points, on fixed spheres or on fixed planes ([`crate::observations::constraint`]),
//! with known distances between points or sphere centres, the robot's parameters and the
//! features' own are estimated jointly ([`fit`]), in the robot's base frame: there is no
//! tracker frame to register.
//!
//! The robot's parameters are those of the model as given: its geometry and the families
//! beyond it the caller enabled (joint compliance, transmission harmonics, backlash, thermal
//! expansion), which act through the same kinematics as for tracker data (the rows' conditions,
//! `temperature_c` and `dir1..dirN`, read the same way). A thermal model is referred to the
//! rows' mean temperature. [`select`] chooses the families the data support, as `--model auto`
//! does for tracker data.
//!
//! What such data cannot see is said, not hidden:
//! - **the base pose**, always: the features sit at unknown places, which take up any move of
//!   the base, so the base frame parameters are held at their nominal values and every
//!   parameter that only duplicates them is fixed too (the structural analysis of
//!   [`crate::identification::identifiability`] on the nominal tool points names them). The
//!   result is "up to the base pose".
//! - **the robot's scale**, without a known distance or a sphere of known radius: scaling every
//!   length of the robot and of the features leaves every residual unchanged. The calibration
//!   then refuses, naming what to add, unless a result up to scale is accepted explicitly
//!   ([`ConstraintOptions::accept_unknown_scale`]), which holds the longest link length at its
//!   nominal value.
//! - **directions the features do not see** (a plane sees the tool point only along its
//!   normal): after the fit, the column-scaled Jacobian's smallest singular directions below
//!   [`ConstraintOptions::weak_tolerance`] are named, their largest robot parameter fixed, and
//!   the fit repeated.

pub mod features;
pub mod fit;
mod gate;
pub mod result;
pub mod selection;
mod unseen;

pub use features::FeatureEstimate;
pub use fit::FitReport;
pub use selection::{calibrate_constraints_auto, cross_validate_constraints, select};

use crate::error::{Error, Result};
use crate::identification::ModelSelection;
use crate::model::family::{backlash, thermal};
use crate::model::{Param, Robot, Unit};
use crate::observations::constraint::{ConstraintData, CONSTRAINT_COLUMN};
use fit::Layout;
use nalgebra::DVector;
use unseen::{column_name, feature_advice, structural, unseen_family_parameters, weakest};

/// Settings of a constraint calibration.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintOptions {
    /// Accept a result up to scale when the data have no known length (else an error).
    pub accept_unknown_scale: bool,
    /// The structural analysis's rank tolerance ([`crate::identification::identifiability::IdentifiabilityOptions::rank_tolerance`]).
    pub rank_tolerance: f64,
    /// A singular value of the column-scaled Jacobian below this times the largest is a
    /// direction the data do not see.
    pub weak_tolerance: f64,
    /// Most Levenberg-Marquardt iterations per fit.
    pub max_iterations: usize,
}

impl Default for ConstraintOptions {
    fn default() -> Self {
        ConstraintOptions {
            accept_unknown_scale: false,
            rank_tolerance: crate::identification::identifiability::DEFAULT_RANK_TOLERANCE,
            weak_tolerance: 1e-5,
            max_iterations: 200,
        }
    }
}

impl ConstraintOptions {
    /// Rejects tolerances outside (0, 1) and zero iterations.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("rank_tolerance", self.rank_tolerance),
            ("weak_tolerance", self.weak_tolerance),
        ] {
            if !(v > 0.0 && v < 1.0) {
                return Err(Error::invalid(name, format!("{v} is not within (0, 1)")));
            }
        }
        if self.max_iterations == 0 {
            return Err(Error::invalid("max_iterations", "must be at least 1"));
        }
        Ok(())
    }
}

/// Where the calibration's length scale comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Scale {
    /// From the data: known distances and/or spheres of known radius.
    Known {
        /// What gives it (`3 known distances, sphere S's radius`).
        from: String,
    },
    /// Not determined: held by a link length kept at its nominal value (accepted explicitly).
    Assumed {
        /// The parameter held.
        held: Param,
    },
}

/// A robot parameter the calibration did not identify, with why.
#[derive(Debug, Clone, PartialEq)]
pub struct Fixed {
    /// The parameter.
    pub param: Param,
    /// Why it is held at its nominal value.
    pub reason: String,
}

/// The result of a constraint calibration.
#[derive(Debug, Clone)]
pub struct ConstraintCalibration {
    /// The model fitted, at its start values: the nominal robot with the families fitted (a
    /// thermal model referred to the data's mean temperature).
    pub nominal: Robot,
    /// The calibrated robot (the families fitted included; base frame as the nominal's).
    pub robot: Robot,
    /// The robot parameters identified.
    pub identified: Vec<Param>,
    /// The robot parameters held at their nominal values, with why.
    pub fixed: Vec<Fixed>,
    /// The features as estimated (base frame of the calibrated model).
    pub features: Vec<FeatureEstimate>,
    /// Where the scale comes from.
    pub scale: Scale,
    /// Directions the data cannot see, in words (always the base pose first).
    pub unseen: Vec<String>,
    /// RMS of the rows' residuals (mm; a point row's residual is the 3-vector's norm).
    pub residual_rms_mm: f64,
    /// Largest row residual (mm).
    pub residual_max_mm: f64,
    /// Each feature's RMS residual (mm), in feature order.
    pub feature_rms_mm: Vec<f64>,
    /// Each known distance's residual, fitted minus given (mm), in file order.
    pub distance_residuals_mm: Vec<f64>,
    /// The tracker frame registered by the tracker rows of mixed data (a measured point `m`
    /// maps to `frame * m` in the base frame); `None` without tracker rows (up to the base
    /// pose).
    pub frame: Option<crate::frame::Frame>,
    /// Each tracker row's residual norm (mm), in file order (mixed data).
    pub tracker_residuals_mm: Vec<f64>,
    /// Condition number of the column-scaled Jacobian of the final fit.
    pub condition_number: f64,
    /// How the final fit ended.
    pub fit: FitReport,
    /// The plausibility gate's failed checks, adapted to constraint data (empty: passed): a
    /// parameter moved beyond its plausible range
    /// ([`crate::model::family::plausible`]), a sphere's radius or a feature's distance from
    /// the base beyond what the robot could touch.
    pub implausible: Vec<String>,
    /// The automatic model choice that chose this model ([`calibrate_constraints_auto`]), if
    /// one did.
    pub model_selection: Option<ModelSelection>,
}

/// What every result says about its frame.
pub const UP_TO_BASE: &str = "the base pose (6 degrees of freedom): constraint data have no \
     reference frame (the fixed features sit at unknown places, which take up any move of the \
     base), so the base frame is held at its nominal value and the calibration is up to the \
     base pose: positions are right relative to each other and to the constrained features, not \
     absolutely";

/// `nominal` as a constraint calibration fits it: its families as given, a thermal model
/// referred to the rows' mean temperature (an error without temperatures), backlash only with
/// approach directions.
pub fn fitted_model(nominal: &Robot, data: &ConstraintData) -> Result<Robot> {
    let mut robot = nominal.clone();
    if thermal::reference_c(&robot).is_some() {
        let Some(t) = data.mean_temperature_c() else {
            return Err(Error::invalid(
                "thermal",
                "thermal expansion needs the rows' temperatures (a temperature_c column, deg C)",
            ));
        };
        thermal::set_reference_c(&mut robot, t)?;
    }
    if !backlash::joints(&robot).is_empty() && !data.has_directions() {
        return Err(Error::invalid(
            "backlash",
            "backlash needs the rows' approach directions (dir1..dirN columns, +1 or -1)",
        ));
    }
    Ok(robot)
}

/// Calibrates `nominal` (its geometry and the families it has) from constraint data (see the
/// module docs).
pub fn calibrate_constraints(
    nominal: &Robot,
    data: &ConstraintData,
    opts: &ConstraintOptions,
) -> Result<ConstraintCalibration> {
    check_input(nominal, data, opts)?;
    let start_robot = fitted_model(nominal, data)?;
    let start_features = start_values(&start_robot, data)?;
    let scale = scale_of(&start_robot, data, opts)?;
    let (mut identified, mut fixed) = structural(&start_robot, data, opts)?;
    if let Scale::Assumed { held } = &scale {
        identified.retain(|p| p != held);
        fixed.push(Fixed {
            param: *held,
            reason: "holds the robot's scale (no known distance or radius: the result is up to \
                     scale, accepted explicitly)"
                .into(),
        });
    }
    let start_frame = start_frame(&start_robot, data)?;
    let mut unseen = unseen_at_start(data, &scale, &fixed);
    // Fit; fix what the data turn out not to see; fit again.
    loop {
        let mut robot = start_robot.clone();
        let mut features = start_features.clone();
        let mut frame = start_frame;
        let mut layout = Layout::new(&robot, &identified, &features);
        if frame.is_some() {
            layout = layout.with_frame();
        }
        let report = fit::solve(
            &mut robot,
            &layout,
            data,
            &mut features,
            &mut frame,
            opts.max_iterations,
        )?;
        let (e, j) = fit::evaluate(&robot, &layout, data, &features, frame.as_ref(), true);
        let j = j.expect("asked for");
        let (cond, weak) = weakest(&j, opts.weak_tolerance);
        if let Some(v) = weak {
            let (param, reason) = unseen_direction(&v, &layout, &features, &mut identified, cond)?;
            unseen.push(format!("{}: {reason}", param.name()));
            fixed.push(Fixed { param, reason });
            if identified.is_empty() {
                return Err(Error::Numerical(
                    "the constraints determine none of the robot's parameters".into(),
                ));
            }
            continue;
        }
        let residuals = Residuals::of(&e, data, &features);
        let implausible = gate::checks(
            &start_robot,
            &robot,
            &features,
            data,
            &residuals.distances_mm,
        );
        let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len().max(1) as f64).sqrt();
        return Ok(ConstraintCalibration {
            nominal: start_robot,
            robot,
            identified,
            fixed,
            residual_rms_mm: rms(&residuals.norms),
            residual_max_mm: residuals.norms.iter().cloned().fold(0.0, f64::max),
            feature_rms_mm: residuals.feature_rms_mm,
            features,
            scale,
            unseen,
            distance_residuals_mm: residuals.distances_mm,
            frame,
            tracker_residuals_mm: residuals.tracker_mm,
            condition_number: cond,
            fit: report,
            implausible,
            model_selection: None,
        });
    }
}

/// The options, and rows for a robot of `nominal`'s joints in the counts each feature needs.
fn check_input(nominal: &Robot, data: &ConstraintData, opts: &ConstraintOptions) -> Result<()> {
    opts.validate()?;
    if data.rows.is_empty() {
        return Err(Error::invalid("constraint data", "no rows"));
    }
    if data.dof != nominal.dof() {
        return Err(Error::JointCount {
            context: data.describe(0),
            expected: nominal.dof(),
            got: data.dof,
        });
    }
    data.check_counts()
}

/// What fixes the robot's scale: the data's known lengths, else (accepted explicitly) the
/// robot's longest link held at its nominal value; without either, an error.
fn scale_of(robot: &Robot, data: &ConstraintData, opts: &ConstraintOptions) -> Result<Scale> {
    match scale_source(data) {
        Some(from) => Ok(Scale::Known { from }),
        None if opts.accept_unknown_scale => Ok(Scale::Assumed {
            held: longest_length(robot)?,
        }),
        None => Err(Error::Numerical(
            "the robot's scale is not determined by these data: scaling every length of the \
             robot and of the features leaves every residual unchanged, so the model could be \
             off by millimetres while the residuals look perfect. Add a known distance \
             between two fixed points or sphere centres (a distances file: from,to,\
             distance_mm), or a sphere of known radius (its radius_mm), or accept a result \
             up to scale explicitly"
                .into(),
        )),
    }
}

/// What constraint data cannot see before any fit: the base frame (or what tracker rows
/// register), the scale when it is held, and the families' parameters fixed structurally.
fn unseen_at_start(data: &ConstraintData, scale: &Scale, fixed: &[Fixed]) -> Vec<String> {
    let mut unseen = vec![if data.tracker.is_empty() {
        UP_TO_BASE.to_string()
    } else {
        format!(
            "the base frame's own parameters: the {} tracker row(s) register the base to the \
             tracker frame (estimated with the robot, as for tracker data), which takes up any \
             move of the base, so they are held at their nominal values",
            data.tracker.len()
        )
    }];
    if let Scale::Assumed { held } = scale {
        unseen.push(format!(
            "the robot's scale: no known length in the data; {} is held at its nominal value",
            held.name()
        ));
    }
    unseen.extend(unseen_family_parameters(fixed));
    unseen
}

/// The robot parameter with the largest share of the unseen direction `v` of the fit's
/// Jacobian, taken out of `identified`, with the reason it is fixed (what its effect is nearly
/// that of). An error when the direction is the features' own (no robot parameter in it).
fn unseen_direction(
    v: &[f64],
    layout: &Layout,
    features: &[FeatureEstimate],
    identified: &mut Vec<Param>,
    cond: f64,
) -> Result<(Param, String)> {
    let Some((c, _)) = (0..identified.len())
        .map(|c| (c, v[c].abs()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|(_, w)| *w > 1e-3)
    else {
        return Err(Error::Numerical(format!(
            "the features' own parameters are not determined by these data (condition \
             number {cond:.3e}); {}",
            feature_advice(features)
        )));
    };
    let p = identified.remove(c);
    let mut others: Vec<(String, f64)> = (0..layout.n)
        .filter(|&k| k != c && v[k].abs() > 0.1 * v[c].abs())
        .map(|k| (column_name(layout, features, k), v[k].abs()))
        .collect();
    others.sort_by(|a, b| b.1.total_cmp(&a.1));
    let with: Vec<String> = others.into_iter().take(4).map(|o| o.0).collect();
    let reason = format!(
        "not seen by these constraints{}{}",
        if with.is_empty() {
            String::new()
        } else {
            format!(" (its effect is nearly that of {})", with.join(", "))
        },
        if features
            .iter()
            .all(|f| f.kind == crate::observations::constraint::ConstraintKind::Plane)
        {
            "; a plane sees the tool point only along its normal"
        } else {
            ""
        }
    );
    Ok((p, reason))
}

/// The fit's residuals by kind of row.
struct Residuals {
    /// The error norm of each constraint row (mm).
    norms: Vec<f64>,
    /// RMS of each feature's rows (mm).
    feature_rms_mm: Vec<f64>,
    /// Each known distance's residual (mm, signed).
    distances_mm: Vec<f64>,
    /// Each tracker row's error norm (mm).
    tracker_mm: Vec<f64>,
}

impl Residuals {
    /// Splits the residual vector `e` (constraint rows, then distances, then tracker rows).
    fn of(e: &DVector<f64>, data: &ConstraintData, features: &[FeatureEstimate]) -> Residuals {
        let mut norms = Vec::with_capacity(data.rows.len());
        let mut per_feature = vec![(0.0, 0usize); features.len()];
        let mut row = 0;
        for r in &data.rows {
            let k = features[r.feature].rows();
            let n = e.rows(row, k).norm();
            row += k;
            norms.push(n);
            per_feature[r.feature].0 += n * n;
            per_feature[r.feature].1 += 1;
        }
        let distances_mm = e.as_slice()[row..row + data.distances.len()].to_vec();
        let tracker_mm = (0..data.tracker.len())
            .map(|i| e.rows(row + data.distances.len() + 3 * i, 3).norm())
            .collect();
        Residuals {
            norms,
            feature_rms_mm: per_feature
                .iter()
                .map(|(s, n)| (s / (*n).max(1) as f64).sqrt())
                .collect(),
            distances_mm,
            tracker_mm,
        }
    }
}

/// The features' start values from the nominal tool points of their rows.
fn start_values(robot: &Robot, data: &ConstraintData) -> Result<Vec<FeatureEstimate>> {
    data.features
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let pts: Vec<_> = data
                .rows_of(k)
                .map(|r| robot.target_position_in(&r.q, 0, &r.conditions))
                .collect();
            FeatureEstimate::start(f.kind, &f.name, f.radius_mm, &pts)
                .map_err(|m| data.parse_error(f.first_line, CONSTRAINT_COLUMN, m))
        })
        .collect()
}

/// The tracker frame's start value for mixed data: the rigid fit of the tracker rows' points to
/// the nominal tool points (`None` without tracker rows).
fn start_frame(robot: &Robot, data: &ConstraintData) -> Result<Option<crate::frame::Frame>> {
    if data.tracker.is_empty() {
        return Ok(None);
    }
    let m: Vec<_> = data.tracker.iter().map(|t| t.m).collect();
    let p: Vec<_> = data
        .tracker
        .iter()
        .map(|t| robot.target_position_in(&t.q, 0, &t.conditions))
        .collect();
    let f = crate::registration::rigid::fit_rigid(&m, &p, None).map_err(|e| {
        data.parse_error(
            data.tracker[0].line,
            "x",
            format!("the tracker rows cannot register the tracker frame: {e}"),
        )
    })?;
    Ok(Some(*f.pose()))
}

/// What gives the data a length scale, if anything.
fn scale_source(data: &ConstraintData) -> Option<String> {
    let mut from = Vec::new();
    if !data.tracker.is_empty() {
        from.push(format!("{} tracker row(s)", data.tracker.len()));
    }
    if !data.distances.is_empty() {
        from.push(format!(
            "{} known distance{}",
            data.distances.len(),
            if data.distances.len() == 1 { "" } else { "s" }
        ));
    }
    for f in &data.features {
        if let Some(r) = f.radius_mm {
            from.push(format!("sphere {}'s radius {r} mm", f.name));
        }
    }
    (!from.is_empty()).then(|| from.join(", "))
}

/// The robot's longest link length (`a` or `d`): the one held when the scale is accepted as
/// unknown.
fn longest_length(robot: &Robot) -> Result<Param> {
    robot
        .param_list()
        .iter()
        .filter(|p| p.family_id() == Param::d(0).family_id() && p.unit() == Unit::Mm)
        .max_by(|a, b| robot.get(**a).abs().total_cmp(&robot.get(**b).abs()))
        .copied()
        .ok_or_else(|| Error::invalid("robot", "has no link length to hold the scale"))
}

#[cfg(test)]
mod tests;

#[cfg(test)]
mod family_tests;
