//! The joint fit of the robot's parameters and the features' (Levenberg-Marquardt on the stacked
//! residuals, dense: constraint data sets have hundreds of rows, not millions).
//!
//! Rows, in order: each constraint row's feature rows ([`FeatureEstimate::residual`] at the
//! model's tool point `p(q; theta)`), then one row per known distance, `|c_a - c_b| - D`, then
//! (mixed data) three rows per tracker row, `F m - p(q; theta)` with the tracker frame `F`
//! estimated too (its update `F' = (exp(w), dt) F`: derivatives `-[F m]x` and `I`). The
//! Jacobian's robot columns are the feature rows' derivatives with respect to `p` times the
//! parameters' tool-point screws under the row's conditions ([`Robot::target_screws_in`]: the
//! joint families' deflection and their own columns included, the same as for tracker data);
//! the feature columns are the features' own derivatives.

use super::features::FeatureEstimate;
use crate::error::{Error, Result};
use crate::frame::Frame;
use crate::model::{Param, Robot};
use crate::observations::constraint::ConstraintData;
use nalgebra::{DMatrix, DVector, Vector3};

/// Where each unknown sits in the fit's parameter vector.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    /// The robot parameters identified.
    pub params: Vec<Param>,
    /// Their positions in `robot.params()`.
    pub index: Vec<usize>,
    /// The first column of each feature.
    pub feature_col: Vec<usize>,
    /// The first of the tracker frame's six columns (rotation, then translation), when the
    /// data have tracker rows.
    pub frame_col: Option<usize>,
    /// Number of unknowns.
    pub n: usize,
}

impl Layout {
    pub fn new(robot: &Robot, params: &[Param], features: &[FeatureEstimate]) -> Layout {
        let index = params
            .iter()
            .map(|p| robot.param_position(*p).expect("parameter of the robot"))
            .collect();
        let mut col = params.len();
        let mut feature_col = Vec::with_capacity(features.len());
        for f in features {
            feature_col.push(col);
            col += f.param_count();
        }
        Layout {
            params: params.to_vec(),
            index,
            feature_col,
            frame_col: None,
            n: col,
        }
    }

    /// The layout with the tracker frame's six columns added (mixed data).
    pub fn with_frame(mut self) -> Layout {
        self.frame_col = Some(self.n);
        self.n += 6;
        self
    }
}

/// Number of residual rows of `data` with `features`.
pub(crate) fn row_count(data: &ConstraintData, features: &[FeatureEstimate]) -> usize {
    data.rows
        .iter()
        .map(|r| features[r.feature].rows())
        .sum::<usize>()
        + data.distances.len()
        + 3 * data.tracker.len()
}

/// The residual vector and, when asked, the Jacobian (rows x unknowns) at `robot`, `features`
/// and the tracker `frame` (needed when the data have tracker rows).
pub(crate) fn evaluate(
    robot: &Robot,
    layout: &Layout,
    data: &ConstraintData,
    features: &[FeatureEstimate],
    frame: Option<&Frame>,
    jacobian: bool,
) -> (DVector<f64>, Option<DMatrix<f64>>) {
    let m = row_count(data, features);
    let mut e = DVector::zeros(m);
    let mut j = jacobian.then(|| DMatrix::zeros(m, layout.n));
    let mut jp = vec![Vector3::zeros(); robot.param_count()];
    let mut er = [0.0; 3];
    let mut dp = [Vector3::zeros(); 3];
    let mut df = [0.0; 12];
    let mut row = 0;
    for r in &data.rows {
        let f = &features[r.feature];
        let p = if j.is_some() {
            robot
                .target_screws_in(&r.q, 0, &r.conditions, None, Some(&mut jp), None)
                .0
        } else {
            robot.target_position_in(&r.q, 0, &r.conditions)
        };
        let rows = f.rows();
        let k = f.param_count();
        f.residual(&p, &mut er, &mut dp, &mut df);
        for a in 0..rows {
            e[row + a] = er[a];
            if let Some(j) = &mut j {
                for (c, &i) in layout.index.iter().enumerate() {
                    j[(row + a, c)] = dp[a].dot(&jp[i]);
                }
                let c0 = layout.feature_col[r.feature];
                for b in 0..k {
                    j[(row + a, c0 + b)] = df[a * k + b];
                }
            }
        }
        row += rows;
    }
    for d in &data.distances {
        let v = features[d.from].position - features[d.to].position;
        let len = v.norm();
        let u = if len > 0.0 { v / len } else { Vector3::x() };
        e[row] = len - d.distance_mm;
        if let Some(j) = &mut j {
            for a in 0..3 {
                j[(row, layout.feature_col[d.from] + a)] = u[a];
                j[(row, layout.feature_col[d.to] + a)] = -u[a];
            }
        }
        row += 1;
    }
    if !data.tracker.is_empty() {
        let f = frame.expect("a tracker frame for tracker rows");
        for t in &data.tracker {
            let p = if j.is_some() {
                robot
                    .target_screws_in(&t.q, 0, &t.conditions, None, Some(&mut jp), None)
                    .0
            } else {
                robot.target_position_in(&t.q, 0, &t.conditions)
            };
            let w = f * nalgebra::Point3::from(t.m);
            let r = w.coords - p;
            for a in 0..3 {
                e[row + a] = r[a];
            }
            if let Some(j) = &mut j {
                for (c, &i) in layout.index.iter().enumerate() {
                    for a in 0..3 {
                        j[(row + a, c)] = -jp[i][a];
                    }
                }
                if let Some(c0) = layout.frame_col {
                    // d(w)/d(rotation) = -[w]x; d(w)/d(translation) = I.
                    let wx = w.coords.cross_matrix();
                    for a in 0..3 {
                        for b in 0..3 {
                            j[(row + a, c0 + b)] = -wx[(a, b)];
                        }
                        j[(row + a, c0 + 3 + a)] = 1.0;
                    }
                }
            }
            row += 3;
        }
    }
    (e, j)
}

/// How a fit ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitReport {
    /// Iterations taken.
    pub iterations: usize,
    /// Whether the cost stopped decreasing (relative change below the tolerance).
    pub converged: bool,
    /// The final sum of squared residuals (mm^2).
    pub cost: f64,
}

/// Applies step `dx` to the tracker frame (the layout's frame columns).
pub(crate) fn apply_frame(frame: &mut Frame, layout: &Layout, dx: &[f64]) {
    if let Some(c0) = layout.frame_col {
        let w = nalgebra::Vector3::new(dx[c0], dx[c0 + 1], dx[c0 + 2]);
        let t = nalgebra::Vector3::new(dx[c0 + 3], dx[c0 + 4], dx[c0 + 5]);
        let r = nalgebra::Rotation3::new(w);
        *frame = Frame::from_parts(
            nalgebra::Translation3::from(r * frame.translation.vector + t),
            r * frame.rotation,
        );
    }
}

/// Applies step `dx` to the robot's identified parameters and the features.
fn apply(robot: &mut Robot, layout: &Layout, features: &mut [FeatureEstimate], dx: &DVector<f64>) {
    for (c, p) in layout.params.iter().enumerate() {
        robot.set(*p, robot.get(*p) + dx[c]);
    }
    for (f, &c0) in features.iter_mut().zip(&layout.feature_col) {
        let k = f.param_count();
        f.apply(&dx.as_slice()[c0..c0 + k]);
    }
}

/// Levenberg-Marquardt (Marquardt's diagonal scaling) from the current values; updates `robot`,
/// `features` and the tracker `frame` (mixed data) in place.
pub(crate) fn solve(
    robot: &mut Robot,
    layout: &Layout,
    data: &ConstraintData,
    features: &mut [FeatureEstimate],
    frame: &mut Option<Frame>,
    max_iterations: usize,
) -> Result<FitReport> {
    let mut lambda = 1e-3;
    let (mut e, mut j) = evaluate(robot, layout, data, features, frame.as_ref(), true);
    let mut cost = e.norm_squared();
    let mut converged = false;
    let mut iterations = 0;
    while iterations < max_iterations && !converged {
        iterations += 1;
        let jm = j.take().expect("asked for");
        let a = jm.tr_mul(&jm);
        let g = jm.tr_mul(&e);
        let dmax = a.diagonal().max().max(1e-300);
        loop {
            let mut m = a.clone();
            for i in 0..layout.n {
                m[(i, i)] += lambda * a[(i, i)].max(1e-12 * dmax);
            }
            let Some(ch) = m.cholesky() else {
                lambda *= 10.0;
                if lambda > 1e16 {
                    return Err(Error::Numerical(
                        "constraint fit: the normal equations are singular".into(),
                    ));
                }
                continue;
            };
            let dx = -ch.solve(&g);
            let mut r2 = robot.clone();
            let mut f2 = features.to_vec();
            apply(&mut r2, layout, &mut f2, &dx);
            let mut fr2 = *frame;
            if let Some(fr) = &mut fr2 {
                apply_frame(fr, layout, dx.as_slice());
            }
            let (e2, _) = evaluate(&r2, layout, data, &f2, fr2.as_ref(), false);
            let c2 = e2.norm_squared();
            if c2.is_finite() && c2 <= cost {
                let gain = cost - c2;
                *robot = r2;
                features.clone_from_slice(&f2);
                *frame = fr2;
                converged = gain <= 1e-12 * cost || cost < 1e-24;
                let (e3, j3) = evaluate(robot, layout, data, features, frame.as_ref(), true);
                e = e3;
                j = j3;
                cost = c2;
                lambda = (lambda * 0.1).max(1e-12);
                break;
            }
            lambda *= 10.0;
            if lambda > 1e16 {
                // No step lowers the cost: at the minimum to rounding.
                converged = true;
                j = Some(jm);
                break;
            }
        }
    }
    if !cost.is_finite() {
        return Err(Error::Numerical(
            "constraint fit: the cost is not finite".into(),
        ));
    }
    Ok(FitReport {
        iterations,
        converged,
        cost,
    })
}
