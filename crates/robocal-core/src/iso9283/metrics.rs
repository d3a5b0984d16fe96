//! The pose characteristics of ISO 9283 (section 7): accuracy AP, repeatability RP, distance
//! accuracy AD and repeatability RD, and the drift of AP and RP, from the attained poses of a
//! test (base frame) and the commanded ones.
//!
//! Per pose, with the attained positions `p_j` (j = 1..n) and the commanded position `c`:
//! - barycentre `G = mean(p_j)`; `AP = |G - c|`, with its components `AP_x, AP_y, AP_z = G - c`;
//! - `l_j = |p_j - G|`, `RP = mean(l) + 3 s(l)`, `s` the sample standard deviation (n - 1).
//!
//! Orientations (6-DoF data) are compared as rotations, never as differences of A, B, C
//! (DESIGN.md): the error of attained orientation `R_j` against the commanded `R_c` is the
//! rotation vector `e_j = log(R_j R_c^T)` (base frame, degrees); its components about the base
//! axes x, y, z are `a, b, c`. `AP_a, AP_b, AP_c` are the components of `mean(e_j)` (for the
//! small errors of a robot, the mean orientation's error to second order), `AP_angle` its norm,
//! and `RP_a = 3 s(e_a)` (likewise b, c).
//!
//! Distances between poses i and k: `D_c = |c_i - c_k|`, `D_j = |p_ij - p_kj|` per cycle,
//! `AD = mean(D_j) - D_c` (signed), `RD = 3 s(D_j)`.
//!
//! Drift, when every sample carries a time (s): the samples of a pose in time order, AP and RP
//! of the earliest third and of the latest third; `dAP = |AP_late - AP_early|`, likewise dRP.

use super::spec::{Spec, TrackerMpe};
use crate::error::{Error, Result};
use crate::frame::{rotation_vector, Frame};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

/// One attained pose of the test.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// The cycle (1-based).
    pub cycle: usize,
    /// The attained position (mm, base frame).
    pub position: Vector3<f64>,
    /// The attained orientation (base frame), for 6-DoF data.
    pub rotation: Option<Matrix3<f64>>,
    /// When it was measured (s since the test started), if known.
    pub time_s: Option<f64>,
}

/// Everything measured at one pose of the test.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseSamples {
    /// The pose number (1..5 for P1..P5).
    pub pose: usize,
    /// The commanded pose (base frame).
    pub commanded: Frame,
    /// The attained poses, one per cycle.
    pub samples: Vec<Sample>,
}

/// The orientation characteristics of a pose (degrees).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OrientationResult {
    /// Components of the mean orientation error about the base x, y, z axes (deg).
    pub ap_a_deg: f64,
    /// See [`OrientationResult::ap_a_deg`].
    pub ap_b_deg: f64,
    /// See [`OrientationResult::ap_a_deg`].
    pub ap_c_deg: f64,
    /// The angle of the mean orientation error (deg).
    pub ap_angle_deg: f64,
    /// `3 s` of the error's component about x (deg).
    pub rp_a_deg: f64,
    /// `3 s` of the error's component about y (deg).
    pub rp_b_deg: f64,
    /// `3 s` of the error's component about z (deg).
    pub rp_c_deg: f64,
}

/// The drift of a pose's AP and RP over the test (samples with times).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Drift {
    /// Hours between the first and the last sample.
    pub hours: f64,
    /// `|AP_late - AP_early|` (mm).
    pub dap_mm: f64,
    /// `|RP_late - RP_early|` (mm).
    pub drp_mm: f64,
}

/// The characteristics of one pose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseResult {
    /// The pose number (1..5).
    pub pose: usize,
    /// Number of attained poses.
    pub n: usize,
    /// The commanded position (mm, base frame).
    pub commanded_mm: [f64; 3],
    /// The barycentre G of the attained positions (mm, base frame).
    pub barycentre_mm: [f64; 3],
    /// Position accuracy `|G - commanded|` (mm).
    pub ap_mm: f64,
    /// `G_x - commanded_x` (mm).
    pub ap_x_mm: f64,
    /// `G_y - commanded_y` (mm).
    pub ap_y_mm: f64,
    /// `G_z - commanded_z` (mm).
    pub ap_z_mm: f64,
    /// Position repeatability `mean(l) + 3 s(l)` (mm).
    pub rp_mm: f64,
    /// `mean(l)` (mm).
    pub l_mean_mm: f64,
    /// `s(l)`, sample standard deviation (mm).
    pub l_std_mm: f64,
    /// Orientation characteristics (6-DoF data only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientationResult>,
    /// The tracker's maximum permissible error at this pose (mm).
    pub tracker_mpe_mm: f64,
    /// RP is below the tracker's MPE here: the tracker cannot resolve it (RP is then an upper
    /// bound set by the instrument, not the robot's figure).
    pub rp_below_tracker: bool,
    /// Drift of AP and RP (samples with times only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drift: Option<Drift>,
    /// Whether AP and RP are within the spec (`None` without a spec).
    pub pass: Option<bool>,
}

/// Distance accuracy and repeatability between two poses.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DistanceResult {
    /// The first pose (1..5).
    pub from: usize,
    /// The second pose.
    pub to: usize,
    /// The commanded distance (mm).
    pub commanded_mm: f64,
    /// The mean attained distance (mm).
    pub mean_mm: f64,
    /// `mean - commanded` (mm, signed).
    pub ad_mm: f64,
    /// `3 s` of the attained distances (mm).
    pub rd_mm: f64,
}

/// The whole evaluation of a test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// Per pose, in pose order.
    pub poses: Vec<PoseResult>,
    /// Between P1 and P2 (the contract's `distance`).
    pub distance: DistanceResult,
    /// Between every pair of poses.
    pub distances: Vec<DistanceResult>,
    /// The spec, if given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spec: Option<Spec>,
    /// The tracker's uncertainty model used.
    pub tracker: TrackerMpe,
    /// Whether every pose passes (`None` without a spec).
    pub pass: Option<bool>,
}

/// Mean and sample standard deviation (n - 1) of `v` (at least two values).
pub fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let ss = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
    (m, (ss / (n - 1.0)).sqrt())
}

/// Barycentre, AP vector and RP (with mean and std of l) of positions against `commanded`.
fn position_figures(
    points: &[Vector3<f64>],
    commanded: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>, f64, f64, f64) {
    let n = points.len() as f64;
    let g = points.iter().fold(Vector3::zeros(), |a, p| a + p) / n;
    let l: Vec<f64> = points.iter().map(|p| (p - g).norm()).collect();
    let (lm, ls) = mean_std(&l);
    (g, g - commanded, lm + 3.0 * ls, lm, ls)
}

fn orientation(ps: &PoseSamples) -> Option<OrientationResult> {
    let rc = ps.commanded.rotation.matrix();
    let errs: Option<Vec<Vector3<f64>>> = ps
        .samples
        .iter()
        .map(|s| s.rotation.map(|r| rotation_vector(&(r * rc.transpose()))))
        .collect();
    let errs = errs?;
    let mean = errs.iter().fold(Vector3::zeros(), |a, e| a + e) / errs.len() as f64;
    let three_s = |k: usize| {
        let v: Vec<f64> = errs.iter().map(|e| e[k].to_degrees()).collect();
        3.0 * mean_std(&v).1
    };
    Some(OrientationResult {
        ap_a_deg: mean.x.to_degrees(),
        ap_b_deg: mean.y.to_degrees(),
        ap_c_deg: mean.z.to_degrees(),
        ap_angle_deg: mean.norm().to_degrees(),
        rp_a_deg: three_s(0),
        rp_b_deg: three_s(1),
        rp_c_deg: three_s(2),
    })
}

fn drift(ps: &PoseSamples) -> Option<Drift> {
    let mut timed: Vec<(f64, Vector3<f64>)> = ps
        .samples
        .iter()
        .map(|s| s.time_s.map(|t| (t, s.position)))
        .collect::<Option<_>>()?;
    if timed.len() < 6 {
        return None;
    }
    timed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = timed.len() / 3;
    let c = ps.commanded.translation.vector;
    let figures = |part: &[(f64, Vector3<f64>)]| {
        let pts: Vec<Vector3<f64>> = part.iter().map(|x| x.1).collect();
        let (_, ap, rp, _, _) = position_figures(&pts, &c);
        (ap.norm(), rp)
    };
    let (ap0, rp0) = figures(&timed[..k]);
    let (ap1, rp1) = figures(&timed[timed.len() - k..]);
    Some(Drift {
        hours: (timed[timed.len() - 1].0 - timed[0].0) / 3600.0,
        dap_mm: (ap1 - ap0).abs(),
        drp_mm: (rp1 - rp0).abs(),
    })
}

/// The characteristics of one pose. `tracker_origin` is where the tracker stands (mm, base
/// frame), for its distance-dependent MPE. Fails with fewer than two samples.
pub fn evaluate_pose(
    ps: &PoseSamples,
    tracker: &TrackerMpe,
    tracker_origin: &Vector3<f64>,
    spec: Option<&Spec>,
) -> Result<PoseResult> {
    if ps.samples.len() < 2 {
        return Err(Error::invalid(
            format!("pose P{}", ps.pose),
            format!(
                "{} attained pose(s): repeatability needs at least 2 (ISO 9283: 30 cycles)",
                ps.samples.len()
            ),
        ));
    }
    let pts: Vec<Vector3<f64>> = ps.samples.iter().map(|s| s.position).collect();
    let c = ps.commanded.translation.vector;
    let (g, ap, rp, lm, ls) = position_figures(&pts, &c);
    let mpe = tracker.at_distance_mm((g - tracker_origin).norm());
    let pass = spec.map(|s| s.passes(ap.norm(), rp));
    Ok(PoseResult {
        pose: ps.pose,
        n: pts.len(),
        commanded_mm: [c.x, c.y, c.z],
        barycentre_mm: [g.x, g.y, g.z],
        ap_mm: ap.norm(),
        ap_x_mm: ap.x,
        ap_y_mm: ap.y,
        ap_z_mm: ap.z,
        rp_mm: rp,
        l_mean_mm: lm,
        l_std_mm: ls,
        orientation: orientation(ps),
        tracker_mpe_mm: mpe,
        rp_below_tracker: rp < mpe,
        drift: drift(ps),
        pass,
    })
}

/// Distance accuracy and repeatability between poses `a` and `b`, over the cycles both were
/// measured in. Fails with fewer than two common cycles.
pub fn evaluate_distance(a: &PoseSamples, b: &PoseSamples) -> Result<DistanceResult> {
    let mut d = Vec::new();
    for sa in &a.samples {
        if let Some(sb) = b.samples.iter().find(|s| s.cycle == sa.cycle) {
            d.push((sa.position - sb.position).norm());
        }
    }
    if d.len() < 2 {
        return Err(Error::invalid(
            format!("distance P{}-P{}", a.pose, b.pose),
            format!("{} common cycle(s): at least 2 needed", d.len()),
        ));
    }
    let dc = (a.commanded.translation.vector - b.commanded.translation.vector).norm();
    let (m, s) = mean_std(&d);
    Ok(DistanceResult {
        from: a.pose,
        to: b.pose,
        commanded_mm: dc,
        mean_mm: m,
        ad_mm: m - dc,
        rd_mm: 3.0 * s,
    })
}

/// The whole evaluation: every pose (in the given order, sorted by pose number), the distance
/// P1-P2 and every pair, pass/fail against `spec`. Needs poses 1 and 2.
pub fn evaluate(
    poses: &[PoseSamples],
    tracker: &TrackerMpe,
    tracker_origin: &Vector3<f64>,
    spec: Option<&Spec>,
) -> Result<Evaluation> {
    tracker.validate()?;
    if let Some(s) = spec {
        s.validate()?;
    }
    let mut sorted: Vec<&PoseSamples> = poses.iter().collect();
    sorted.sort_by_key(|p| p.pose);
    let results = sorted
        .iter()
        .map(|p| evaluate_pose(p, tracker, tracker_origin, spec))
        .collect::<Result<Vec<_>>>()?;
    let mut distances = Vec::new();
    for i in 0..sorted.len() {
        for k in i + 1..sorted.len() {
            distances.push(evaluate_distance(sorted[i], sorted[k])?);
        }
    }
    let distance = distances
        .iter()
        .find(|d| d.from == 1 && d.to == 2)
        .copied()
        .ok_or_else(|| Error::invalid("poses", "the distance P1-P2 needs poses P1 and P2"))?;
    let pass = spec.map(|_| results.iter().all(|r| r.pass == Some(true)));
    Ok(Evaluation {
        poses: results,
        distance,
        distances,
        spec: spec.copied(),
        tracker: *tracker,
        pass,
    })
}
