//! Which parameters the poses can identify (DESIGN.md, "Facts worth knowing").
//!
//! The identification Jacobian (`d p / d theta` for every parameter of the model, stacked over
//! the poses, 3N x n) is reduced to its triangular factor R by Householder QR, block by block, so
//! its size does not grow with N (R^T R = J^T J, and QR keeps the rank test accurate where the
//! normal matrix would square the condition number). Each column is scaled by its norm (the
//! parameter's RMS effect on the tool point), which makes millimetres and radians comparable.
//!
//! The columns are then visited in a priority order, a Gram–Schmidt (pivoted QR) pass with
//! priority pivoting: a column is kept when its distance from the span of the columns already
//! kept, relative to its own length (its *independence*, the sine of the angle to that span), is
//! above `rank_tolerance` (default 1e-6); otherwise the parameter is fixed at its nominal value,
//! and its column is solved against the kept ones to name the parameters it duplicates. The
//! default priority gives the paper's choice: the base frame before `alpha1, a1, d1, phi1`; the
//! tool position before `d_n` and `phi_n`; then the joints in order, so that of two parallel axes'
//! offsets (`d2`, `d3`) the first is kept. Parameters named in `--free` come first of all (so
//! `--free d3` keeps d3 and fixes d2); parameters in `--fix` are left out.

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::identification::householder::fold_rows;
use crate::identification::system::Problem;
use crate::identification::Observations;
use crate::model::{Param, Robot};
use nalgebra::{DMatrix, DVector, Vector3};
use rayon::prelude::*;

/// Default relative rank threshold (see the module docs).
pub const DEFAULT_RANK_TOLERANCE: f64 = 1e-6;

/// The smallest rank threshold accepted. The independence of an exactly redundant parameter
/// (`d1` against `base_z`, `d3` against `d2`) does not compute as 0 but as the rounding left by
/// the QR factorization in double precision, which grows with the number of rows: measured
/// 4e-17 to 2e-15 on the KR 480 demo, the UR5 (1000 poses) and the WAM sets. A threshold must
/// stay clear of that floor, or duplicates are "identified"; 1e-10 leaves four orders of
/// magnitude. (Parameters kept near it are ill-conditioned anyway: see
/// [`MAX_CONDITION_NUMBER`].)
pub const MIN_RANK_TOLERANCE: f64 = 1e-10;

/// The largest condition number of the column-scaled Jacobian of the identified parameters for
/// which double precision still gives their estimates and standard deviations. The solver and
/// the covariance work on the normal matrix `J^T W J`, whose condition is the square: with a
/// condition number `c` the computed variances carry a relative error of about `c^2 * 2.2e-16`,
/// 2% at `c` = 1e7 and no correct digit at 7e7. Good data give 26 (KR 480 demo) to 77 (UR5,
/// WAM).
pub const MAX_CONDITION_NUMBER: f64 = 1e7;

/// Points per QR block.
const BLOCK_POINTS: usize = 128;
/// Points per parallel task, about: the points are split into `ceil(n / TASK_POINTS)` tasks of
/// equal size (an even split keeps both cores of a small machine busy to the end). The split
/// depends on the number of points only, so the factor is the same on any number of threads.
const TASK_POINTS: usize = 512;

/// Settings of the identifiability analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct IdentifiabilityOptions {
    /// Relative threshold on a column's independence (see the module docs).
    pub rank_tolerance: f64,
    /// Parameters held fixed whatever the analysis says (`--fix`).
    pub fix: Vec<Param>,
    /// Parameters given the highest priority (`--free`); an error if one is still not
    /// identifiable.
    pub free: Vec<Param>,
    /// Go on when the identified parameters are ill-conditioned (condition number above
    /// [`MAX_CONDITION_NUMBER`]), with their standard deviations marked unavailable, instead of
    /// failing. For a rank tolerance the user chose deliberately.
    pub allow_ill_conditioned: bool,
}

impl Default for IdentifiabilityOptions {
    fn default() -> Self {
        IdentifiabilityOptions {
            rank_tolerance: DEFAULT_RANK_TOLERANCE,
            fix: Vec::new(),
            free: Vec::new(),
            allow_ill_conditioned: false,
        }
    }
}

/// Why a parameter is not identified.
#[derive(Debug, Clone, PartialEq)]
pub enum FixReason {
    /// Named in `--fix`.
    User,
    /// Its column is zero: it does not move the tool.
    NoEffect,
    /// It moves only what the measurement kind does not see (the tool orientation, for points).
    Unseen {
        /// What it moves and why the measurements miss it, e.g. `tool orientation; points carry
        /// no orientation`.
        what: String,
    },
    /// Its column is (numerically) a combination of identified parameters' columns.
    Duplicate {
        /// The dominant parameters and their coefficients in internal units: a change `dx` of the
        /// fixed parameter moves every point as `sum c * dx` changes of these.
        of: Vec<(Param, f64)>,
        /// The column's independence (below the rank tolerance).
        independence: f64,
    },
    /// Independent in principle, but the data cannot pin it: its standard deviation predicted
    /// at the start of the identification exceeds a third of the largest move a calibration may
    /// plausibly make ([`crate::identification::precision`]).
    Undetermined {
        /// The predicted standard deviation (display unit).
        std: f64,
        /// The limit it exceeds (display unit).
        limit: f64,
    },
    /// Held at the bound of its plausible values ([`crate::model::family::plausible`]): the fit
    /// put it beyond the bound by less than 3 standard deviations, so the data cannot tell it
    /// from the bound ([`crate::identification::bounds`]).
    AtBound {
        /// The value the fit wanted (display unit).
        value: f64,
        /// Its standard deviation (display unit).
        std: f64,
        /// The bound it is held at (display unit).
        bound: f64,
    },
}

/// A parameter held at its nominal value, with the reason.
#[derive(Debug, Clone, PartialEq)]
pub struct FixedParam {
    /// The parameter.
    pub param: Param,
    /// Why.
    pub reason: FixReason,
}

impl FixedParam {
    /// The reason as a sentence, e.g. `same effect as base_z`.
    pub fn describe(&self) -> String {
        match &self.reason {
            FixReason::User => "fixed on request".to_string(),
            FixReason::NoEffect => "no effect on the tool point".to_string(),
            FixReason::Unseen { what } => format!("no effect on the tool point ({what})"),
            FixReason::Undetermined { std, limit } => {
                let u = self.param.unit().as_str();
                format!(
                    "not determined by these data: predicted std {std:.3} {u}, above {limit:.3} \
                     {u} (a third of the largest plausible move)"
                )
            }
            FixReason::AtBound { value, std, bound } => {
                let u = self.param.unit().as_str();
                format!(
                    "held at its plausible bound {bound} {u}: the fit gave {value:.3} +- {std:.3} \
                     {u}, beyond the bound by less than 3 standard deviations"
                )
            }
            FixReason::Duplicate { of, .. } => {
                let names: Vec<String> = of.iter().map(|(p, _)| p.name()).collect();
                match names.len() {
                    0 => "not identifiable from these poses".to_string(),
                    1 => format!("same effect as {}", names[0]),
                    _ => format!(
                        "same effect as a combination of {} and {}",
                        names[..names.len() - 1].join(", "),
                        names[names.len() - 1]
                    ),
                }
            }
        }
    }
}

/// The result of the analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Identifiability {
    /// The identified parameters, in model order.
    pub identified: Vec<Param>,
    /// Each identified parameter's independence when it was accepted (same order).
    pub independence: Vec<f64>,
    /// The fixed parameters, in model order.
    pub fixed: Vec<FixedParam>,
    /// Condition number of the column-scaled Jacobian of the identified parameters.
    pub condition_number: f64,
    /// The threshold used.
    pub rank_tolerance: f64,
    /// RMS effect on the tool point of a unit change of every model parameter (mm per mm or mm
    /// per rad), in model order.
    pub column_rms: Vec<(Param, f64)>,
}

impl Identifiability {
    /// The reason a parameter is fixed, if it is.
    pub fn fixed_reason(&self, p: Param) -> Option<&FixedParam> {
        self.fixed.iter().find(|f| f.param == p)
    }

    /// The identified parameter with the smallest independence, and that independence.
    pub fn least_independent(&self) -> Option<(Param, f64)> {
        self.identified
            .iter()
            .zip(&self.independence)
            .map(|(p, i)| (*p, *i))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether the identified parameters are too nearly dependent for double precision (see
    /// [`MAX_CONDITION_NUMBER`]); also when the condition number is not finite.
    pub fn ill_conditioned(&self) -> bool {
        self.condition_number.is_nan() || self.condition_number > MAX_CONDITION_NUMBER
    }
}

/// The default priority of a robot's parameters (see the module docs and
/// [`crate::model::family::priority`]); `free` first.
pub fn priority_order(robot: &Robot, free: &[Param]) -> Vec<Param> {
    let mut out: Vec<Param> = free.to_vec();
    let mut rest: Vec<(u32, Param)> = robot
        .param_list()
        .iter()
        .filter(|p| !free.contains(p))
        .map(|p| (p.family().priority(robot, *p), *p))
        .collect();
    rest.sort();
    out.extend(rest.into_iter().map(|(_, p)| p));
    out
}

/// The stacked identification Jacobian over the poses of `obs`, reduced: its R factor (n x n,
/// n = all parameters), and each parameter's angular column norm (`sqrt(sum |dw|^2)` over the
/// poses: how much it turns the tool frame, seen by the measurements or not).
pub struct Reduced {
    /// The R factor, `R^T R = J^T J`.
    pub r: DMatrix<f64>,
    /// Per parameter, the root sum of squares of its angular columns over the poses.
    pub angular: Vec<f64>,
}

impl Reduced {
    /// The reduced Jacobian of the parameters at positions `cols` of this one's: that of a model
    /// whose Jacobian columns are these columns at the same poses (a model with a subset of the
    /// parameters, the others at values with no effect on its columns). Its R factor is that of
    /// `R[:, cols]` (`Q R = J` gives `J[:, cols] = Q R[:, cols]`), so column norms and angles,
    /// all that [`analyze_reduced`] reads, are those of the columns themselves.
    pub fn columns(&self, cols: &[usize]) -> Reduced {
        let sub = self.r.select_columns(cols);
        Reduced {
            r: sub.qr().r(),
            angular: cols.iter().map(|&c| self.angular[c]).collect(),
        }
    }
}

/// The R factor (n x n, n = all parameters) of the stacked identification Jacobian over the
/// observations of `obs` (the rows their measurement kind gives), computed blockwise (and in
/// parallel for large sets); see [`Reduced`].
pub fn jacobian_r(robot: &Robot, obs: &Observations) -> Reduced {
    let n = robot.param_count();
    let kind = obs.kind();
    let rows = kind.rows();
    let all = robot.param_list();
    let problem = Problem::new(robot, all, obs, &TrackerFrame::identity());
    let idx: Vec<usize> = (0..obs.len()).collect();
    // Each task folds its blocks of rows into an n x n triangular factor (column-major).
    let r_of = |points: &[usize]| -> (Vec<f64>, Vec<f64>) {
        let mut r = vec![0.0; n * n];
        let mut ang = vec![0.0; n];
        let mut jp = vec![Vector3::zeros(); n];
        let mut jw = vec![Vector3::zeros(); n];
        let mut jr = vec![0.0; rows * n];
        let mut b = vec![0.0; rows * BLOCK_POINTS * n];
        for block in points.chunks(BLOCK_POINTS) {
            let m = rows * block.len();
            let b = &mut b[..m * n];
            for (k, &i) in block.iter().enumerate() {
                problem.model_rows(robot, i, &mut jp, &mut jw, &mut jr);
                for a in 0..rows {
                    for c in 0..n {
                        b[c * m + rows * k + a] = jr[a * n + c];
                    }
                }
                for (s, w) in ang.iter_mut().zip(&jw) {
                    *s += w.norm_squared();
                }
            }
            fold_rows(&mut r, n, b, m);
        }
        (r, ang)
    };
    let tasks = obs.len().div_ceil(TASK_POINTS).max(1);
    let parts: Vec<(Vec<f64>, Vec<f64>)> = if tasks > 1 {
        idx.par_chunks(obs.len().div_ceil(tasks))
            .map(r_of)
            .collect()
    } else {
        vec![r_of(&idx)]
    };
    let mut angular = vec![0.0; n];
    for (_, a) in &parts {
        for (s, v) in angular.iter_mut().zip(a) {
            *s += v;
        }
    }
    // The parts' factors folded in order (the same bits on any number of threads).
    let r = parts
        .into_iter()
        .map(|(r, _)| r)
        .reduce(|mut a, mut b| {
            fold_rows(&mut a, n, &mut b, n);
            a
        })
        .unwrap_or_else(|| vec![0.0; n * n]);
    let r = DMatrix::from_column_slice(n, n, &r);
    Reduced {
        r,
        angular: angular.into_iter().map(f64::sqrt).collect(),
    }
}

/// Decides which parameters of `robot` the poses of `obs` identify (see the module docs).
pub fn analyze(
    robot: &Robot,
    obs: &Observations,
    opts: &IdentifiabilityOptions,
) -> Result<Identifiability> {
    analyze_reduced(robot, obs, opts, &jacobian_r(robot, obs))
}

/// [`analyze`] from the reduced Jacobian `reduced` of `robot` at the poses of `obs`
/// ([`jacobian_r`]), for a second analysis of the same data with other options.
pub fn analyze_reduced(
    robot: &Robot,
    obs: &Observations,
    opts: &IdentifiabilityOptions,
    reduced: &Reduced,
) -> Result<Identifiability> {
    let all = robot.param_list();
    let npts = obs.len().max(1) as f64;
    let norms: Vec<f64> = (0..all.len()).map(|j| reduced.r.column(j).norm()).collect();
    let mut sweep = sweep_columns(robot, obs, opts, reduced, &norms);
    if sweep.kept.is_empty() {
        return Err(nothing_to_identify(&sweep.fixed));
    }
    // The triangular factor T of the kept unit columns (K = Q T, Q = `basis`).
    let k = sweep.kept.len();
    let t = DMatrix::from_fn(k, k, |a, b| sweep.factor[b].get(a).copied().unwrap_or(0.0));
    let mut fixed = std::mem::take(&mut sweep.fixed);
    for &(p, rho) in &sweep.dependent {
        fixed.push(sweep.explain(robot, reduced, &norms, &t, p, rho)?);
    }
    let mut kept = sweep.kept;
    check_free(opts, &fixed)?;
    let condition_number = condition_number(&t);
    // Model order is `Param` order.
    kept.sort_by_key(|(p, _)| *p);
    fixed.sort_by_key(|f| f.param);
    Ok(Identifiability {
        identified: kept.iter().map(|(p, _)| *p).collect(),
        independence: kept.iter().map(|(_, r)| *r).collect(),
        fixed,
        condition_number,
        rank_tolerance: opts.rank_tolerance,
        column_rms: all
            .iter()
            .zip(&norms)
            .map(|(p, v)| (*p, v / npts.sqrt()))
            .collect(),
    })
}

/// What the sweep over the columns in priority order found.
struct Sweep {
    /// Orthonormal basis of the kept columns (Q).
    basis: Vec<DVector<f64>>,
    /// Column m of the triangular factor T of the kept unit columns (K = Q T): their
    /// coefficients on the basis vectors before it, then their independence.
    factor: Vec<Vec<f64>>,
    /// The kept parameters with their independence.
    kept: Vec<(Param, f64)>,
    /// The parameters whose column depends on the kept ones, with their independence.
    dependent: Vec<(Param, f64)>,
    /// The parameters fixed by the user or without effect on the measurements.
    fixed: Vec<FixedParam>,
}

/// The unit column `j` of the reduced Jacobian (zero for a column without effect).
fn unit_column(r: &DMatrix<f64>, norms: &[f64], j: usize) -> DVector<f64> {
    if norms[j] > 0.0 {
        r.column(j) / norms[j]
    } else {
        DVector::zeros(norms.len())
    }
}

/// Gram-Schmidt (twice, for orthogonality) over the unit columns in priority order: a column
/// more independent of those kept before it than the rank tolerance is kept.
fn sweep_columns(
    robot: &Robot,
    obs: &Observations,
    opts: &IdentifiabilityOptions,
    reduced: &Reduced,
    norms: &[f64],
) -> Sweep {
    let Reduced { r, angular } = reduced;
    let blind = obs.kind().blind_to_orientation();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let tol = opts.rank_tolerance;
    let mut sweep = Sweep {
        basis: Vec::new(),
        factor: Vec::new(),
        kept: Vec::new(),
        dependent: Vec::new(),
        fixed: opts
            .fix
            .iter()
            .map(|p| FixedParam {
                param: *p,
                reason: FixReason::User,
            })
            .collect(),
    };
    for p in priority_order(robot, &opts.free) {
        if opts.fix.contains(&p) {
            continue;
        }
        let j = robot.param_position(p).expect("robot parameter");
        if norms[j] <= 1e-12 * max_norm || norms[j] == 0.0 {
            let reason = match blind {
                // It only turns the tool frame, which the measurements do not see.
                Some(why) if angular[j] > 1e-12 * max_norm => FixReason::Unseen {
                    what: format!("tool orientation; {why}"),
                },
                _ => FixReason::NoEffect,
            };
            sweep.fixed.push(FixedParam { param: p, reason });
            continue;
        }
        let mut v = unit_column(r, norms, j);
        let mut coefficients = vec![0.0; sweep.basis.len() + 1];
        for _ in 0..2 {
            for (q, t) in sweep.basis.iter().zip(&mut coefficients) {
                let c = q.dot(&v);
                v.axpy(-c, q, 1.0);
                *t += c;
            }
        }
        let rho = v.norm();
        if rho > tol {
            sweep.basis.push(v / rho);
            *coefficients.last_mut().expect("one entry at least") = rho;
            sweep.factor.push(coefficients);
            sweep.kept.push((p, rho));
        } else {
            sweep.dependent.push((p, rho));
        }
    }
    sweep
}

/// The error when no parameter is left to identify.
fn nothing_to_identify(fixed: &[FixedParam]) -> Error {
    let rest: Vec<String> = fixed
        .iter()
        .filter(|f| f.reason != FixReason::User)
        .map(|f| f.param.name())
        .collect();
    Error::Numerical(if rest.is_empty() {
        "every parameter is held fixed: nothing to identify".to_string()
    } else {
        format!(
            "nothing to identify: the parameters not held fixed ({}) have no effect on the \
             measured points",
            rest.join(", ")
        )
    })
}

impl Sweep {
    /// Explains the dependent column of `p` by the kept ones: the least-squares coefficients of
    /// the kept unit columns K = Q T, c = T^-1 Q^T u (the kept columns have full rank: each one's
    /// independence is above the tolerance, so T's diagonal is), at most four of them, in the
    /// parameters' units.
    fn explain(
        &self,
        robot: &Robot,
        reduced: &Reduced,
        norms: &[f64],
        t: &DMatrix<f64>,
        p: Param,
        rho: f64,
    ) -> Result<FixedParam> {
        let (basis, kept) = (&self.basis, &self.kept);
        let col = |p: Param| robot.param_position(p).expect("robot parameter");
        let j = col(p);
        let u = unit_column(&reduced.r, norms, j);
        let projections = DVector::from_iterator(kept.len(), basis.iter().map(|q| q.dot(&u)));
        let c = t.solve_upper_triangular(&projections).ok_or_else(|| {
            Error::Numerical("identifiability: the kept columns are dependent".to_string())
        })?;
        let cmax = c.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut terms: Vec<(usize, f64)> = c
            .iter()
            .enumerate()
            .filter(|(_, v)| v.abs() >= 0.1 * cmax && v.abs() > 1e-9)
            .map(|(b, v)| (b, *v))
            .collect();
        // Largest coefficient first; equal ones (to 1e-9 of the largest, as rounding leaves
        // them) in parameter order, so the order does not depend on the last bits.
        let rank = |v: f64| -((v.abs() / cmax * 1e9).round() as i64);
        terms.sort_by_key(|&(b, v)| (rank(v), b));
        terms.truncate(4);
        let of = terms
            .into_iter()
            .map(|(b, v)| (kept[b].0, v * norms[j] / norms[col(kept[b].0)]))
            .collect();
        Ok(FixedParam {
            param: p,
            reason: FixReason::Duplicate {
                of,
                independence: rho,
            },
        })
    }
}

/// `--free` parameters must have been kept.
fn check_free(opts: &IdentifiabilityOptions, fixed: &[FixedParam]) -> Result<()> {
    let mut bad = Vec::new();
    for p in &opts.free {
        if let Some(f) = fixed.iter().find(|f| f.param == *p) {
            bad.push(format!("{}: {}", p.name(), f.describe()));
        }
    }
    if bad.is_empty() {
        return Ok(());
    }
    Err(Error::Numerical(format!(
        "`identifiability.free`: cannot identify {} from these poses ({}); free only one of a set of \
         parameters with the same effect",
        if bad.len() == 1 {
            "this parameter"
        } else {
            "these parameters"
        },
        bad.join("; ")
    )))
}

/// The condition number of the kept unit columns: K and T have the same singular values (Q is
/// orthonormal), and T is only k x k.
fn condition_number(t: &DMatrix<f64>) -> f64 {
    let sv = t.singular_values();
    let (smax, smin) = sv
        .iter()
        .fold((0.0f64, f64::INFINITY), |(a, b), v| (a.max(*v), b.min(*v)));
    if sv.is_empty() {
        f64::NAN
    } else if smin > 0.0 {
        smax / smin
    } else {
        f64::INFINITY
    }
}
