//! Registration of the measurement frame (paper, section II.C): the pose of the laser tracker's
//! frame in the robot's base frame (the ACS), fitted to the nominal model.
//!
//! Three steps:
//! 1. an initial frame from the paper's three points on a plane parallel to the base plane
//!    (`plane.rs`), or, without plane points, the closed-form least-squares fit;
//! 2. the rigid frame fitted to every calibration point: closed form (Kabsch/Horn, `rigid.rs`,
//!    one case of the Procrustes fit of `procrustes.rs`) for least squares, refined by
//!    reweighting to minimize the sum of error norms (the paper's objective, eq. 11) otherwise;
//! 3. optionally the paper's 12-parameter affine Tr (eq. 8-11, [`Affine`]), as a diagnostic: its
//!    residuals and the scale/shear it needed are reported, but the tracker frame stays rigid
//!    (a tracker measures lengths; an affine map would absorb link-length errors the
//!    identification must see).
//!
//! The residuals of the fitted frame under the nominal model are the paper's Table II.

mod affine;
mod plane;
pub(crate) mod procrustes;
pub(crate) mod rigid;
mod tool_fit;

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::model::Robot;
use crate::observations::Observations;
use crate::stats::ErrorStats;

use affine::fit_affine_sum_of_norms;
pub use affine::Affine;
use plane::{plane_frame, plane_tilt_deg};
pub(crate) use rigid::IrlsOptions;
use rigid::{fit_rigid, fit_rigid_sum_of_norms, residual_norms};
pub use tool_fit::{fit_tools, ToolFit, MAX_ALTERNATIONS, TOOL_TOLERANCE_MM};
pub(crate) use tool_fit::{fit_tools_from, nominal_flanges, tool_points};

/// What the rigid fit minimizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RegistrationObjective {
    /// The sum of error norms (eq. 11), robust to a few bad points.
    SumOfNorms,
    /// The sum of squared errors (closed form).
    LeastSquares,
}

/// Registration settings.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RegistrationOptions {
    /// Objective of the rigid fit.
    pub objective: RegistrationObjective,
    /// Also fit the paper's affine Tr (eq. 8-11) and report it.
    pub affine: bool,
    /// Iteration limits of the reweighted fits.
    pub irls: IrlsOptions,
}

impl Default for RegistrationOptions {
    fn default() -> Self {
        RegistrationOptions {
            objective: RegistrationObjective::SumOfNorms,
            affine: false,
            irls: IrlsOptions::default(),
        }
    }
}

/// Where the starting frame came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InitialFrame {
    /// The paper's three plane points (`n` >= 3 rows with `set` = `plane`); `tilt_deg` is the
    /// angle between their nominal plane and the base plane.
    Plane {
        /// Number of plane points used.
        n: usize,
        /// Tilt of the nominal plane against the base plane (deg).
        tilt_deg: f64,
        /// The frame they gave.
        frame: TrackerFrame,
        /// Largest residual of the calibration points under that frame (mm).
        max_error_mm: f64,
    },
    /// No plane points: the closed-form least-squares fit of the calibration points.
    LeastSquares,
}

/// The affine Tr of eq. 8-11 and its residuals.
#[derive(Debug, Clone, PartialEq)]
pub struct AffineReport {
    /// The fitted map.
    pub tr: Affine,
    /// Reweighting iterations.
    pub iterations: usize,
    /// Residual norms of the calibration points (mm).
    pub residuals: Vec<f64>,
    /// Their statistics.
    pub stats: ErrorStats,
}

/// A fitted measurement frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// The fitted tracker frame: a measured point m maps to `frame.to_base(m)`.
    pub frame: TrackerFrame,
    /// The starting frame.
    pub initial: InitialFrame,
    /// The objective used.
    pub objective: RegistrationObjective,
    /// Reweighting iterations (0 for the closed form).
    pub iterations: usize,
    /// Residual norms `|frame m_i - p_nom(q_i)|` of the calibration points (mm): Table II.
    pub residuals: Vec<f64>,
    /// Their statistics.
    pub stats: ErrorStats,
    /// The affine Tr, when asked for.
    pub affine: Option<AffineReport>,
}

/// Fits the measurement frame of `cal` to the nominal model `robot` (see the module docs).
/// `plane` holds the paper's plane points, if measured (empty or `None` otherwise).
#[cfg(test)]
pub(crate) fn register(
    robot: &Robot,
    cal: &Observations,
    plane: Option<&Observations>,
    opts: &RegistrationOptions,
) -> Result<Registration> {
    register_to(robot, cal, plane, opts, None)
}

/// [`register`] given `nominal`, the nominal tool point of every calibration point
/// ([`Observations::model_positions`]) when already computed.
pub(crate) fn register_to(
    robot: &Robot,
    cal: &Observations,
    plane: Option<&Observations>,
    opts: &RegistrationOptions,
    nominal: Option<Vec<nalgebra::Vector3<f64>>>,
) -> Result<Registration> {
    if cal.len() < 3 {
        return Err(Error::invalid(
            "calibration data",
            format!(
                "{} points; registration needs at least 3 (and identification many more)",
                cal.len()
            ),
        ));
    }
    let nominal = match nominal {
        Some(p) if p.len() == cal.len() => p,
        _ => cal.model_positions(robot),
    };
    let measured = cal.measured();
    let ls = fit_rigid(measured, &nominal, None)?;
    let initial = match plane.filter(|p| !p.is_empty()) {
        None => InitialFrame::LeastSquares,
        Some(p) if p.len() < 3 => {
            return Err(Error::invalid(
                "plane points",
                format!(
                    "{} row(s) with set = plane; the initial frame needs 3 points on a plane \
                     parallel to the base plane",
                    p.len()
                ),
            ))
        }
        Some(p) => {
            let pn = p.model_positions(robot);
            let f = if p.len() == 3 {
                plane_frame(&[*p.m(0), *p.m(1), *p.m(2)], &[pn[0], pn[1], pn[2]])?
            } else {
                fit_rigid(p.measured(), &pn, None)?
            };
            let max_error_mm = residual_norms(&f, measured, &nominal)
                .into_iter()
                .fold(0.0, f64::max);
            InitialFrame::Plane {
                n: p.len(),
                tilt_deg: plane_tilt_deg(&[pn[0], pn[1], pn[2]]),
                frame: f,
                max_error_mm,
            }
        }
    };
    let start = match initial {
        InitialFrame::Plane { frame, .. } => frame,
        InitialFrame::LeastSquares => ls,
    };
    let (frame, iterations) = match opts.objective {
        RegistrationObjective::LeastSquares => (ls, 0),
        RegistrationObjective::SumOfNorms => {
            fit_rigid_sum_of_norms(measured, &nominal, &start, &opts.irls)?
        }
    };
    let residuals = residual_norms(&frame, measured, &nominal);
    let stats = ErrorStats::from_norms(&residuals);
    let affine = if opts.affine {
        let (tr, it) = fit_affine_sum_of_norms(
            measured,
            &nominal,
            &Affine::from_frame(frame.pose()),
            &opts.irls,
        )?;
        let res: Vec<f64> = measured
            .iter()
            .zip(&nominal)
            .map(|(m, p)| (tr.apply(m) - p).norm())
            .collect();
        Some(AffineReport {
            tr,
            iterations: it,
            stats: ErrorStats::from_norms(&res),
            residuals: res,
        })
    } else {
        None
    };
    Ok(Registration {
        frame,
        initial,
        objective: opts.objective,
        iterations,
        residuals,
        stats,
        affine,
    })
}

/// The rigid tracker frame that best maps `obs`'s measured points onto `robot`'s model points
/// (least squares): for data measured from another tracker station, evaluated under a model
/// whose frame is known only for the calibration's station.
pub fn refit_frame(robot: &Robot, obs: &Observations) -> Result<TrackerFrame> {
    if obs.len() < 3 {
        return Err(Error::invalid(
            "validation data",
            format!(
                "{} points; a frame of their own needs at least 3",
                obs.len()
            ),
        ));
    }
    fit_rigid(obs.measured(), &obs.model_positions(robot), None)
}

/// How much better a frame of their own must explain a set of points, and by how much (mm),
/// before they are taken for data from another tracker station.
pub const STATION_FACTOR: f64 = 10.0;
/// See [`STATION_FACTOR`].
pub const STATION_MIN_MM: f64 = 1.0;

/// Whether the points of `obs`, on which `robot` is off by `here_mm` on average in the frame
/// they were mapped with, look measured from another tracker station: a rigid frame of their own
/// ([`refit_frame`]) brings the mean down by [`STATION_FACTOR`] and by more than
/// [`STATION_MIN_MM`]. Returns that frame's mean error (mm) when they do; `None` when they do not
/// or cannot tell (fewer than 3 points, a frame that cannot be fitted).
pub fn another_station(robot: &Robot, obs: &Observations, here_mm: f64) -> Option<f64> {
    if here_mm <= STATION_MIN_MM || obs.len() < 3 {
        return None;
    }
    let own = refit_frame(robot, obs).ok()?;
    let there = obs
        .model_positions(robot)
        .iter()
        .zip(obs.measured())
        .map(|(p, m)| (own.to_base(m) - p).norm())
        .sum::<f64>()
        / obs.len() as f64;
    (here_mm > STATION_FACTOR * there && here_mm - there > STATION_MIN_MM).then_some(there)
}
