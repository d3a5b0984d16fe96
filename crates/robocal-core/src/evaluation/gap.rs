//! What a verification adds to the calibration's prediction beyond the model: the fresh
//! tracker station's registration and the robot's repeatability, each as the RMS error norm
//! (mm) it is expected to add at the verified poses. Independent effects add in quadrature:
//! `rms_verified^2 = rms_predicted^2 + sum of the shares^2 + what is left`.
//!
//! - The station: a frame of its own fitted (least squares, 6 parameters) to `n` points whose
//!   per-axis residual is `sigma` is off by `delta` with covariance `sigma^2 (J^T J)^-1`; at the
//!   points it was fitted to that adds `E mean_i |J_i delta|^2 = sigma^2 tr(J (J^T J)^-1 J^T) / n
//!   = 6 sigma^2 / n`, an RMS of `sigma sqrt(6 / n)`. `sigma^2` is the fit's sum of squared
//!   residuals over its `3n - 6` degrees of freedom.
//! - Repeatability: an independent error per joint and per move of standard deviation `s_j`
//!   moves the tool point by `sum_j e_j J_j(q)` (`J_j` the joint's column), of mean square
//!   `sum_j s_j^2 |J_j(q)|^2`, averaged over the poses. The calibration's residuals hold the
//!   calibration session's own draw, so the prediction's noise already contains it.

use crate::error::Result;
use crate::evaluation::observations_of;
use crate::frame::TrackerFrame;
use crate::io::{CalibrationResult, MeasurementSet};
use crate::model::{JointType, Robot};
use crate::observations::Observations;
use nalgebra::Vector3;

/// The ISO 9283 pose repeatability `RP = mean + 3 std` of the distances of an isotropic
/// Gaussian scatter of per-axis standard deviation `s` is `RP_PER_SIGMA * s`:
/// `sqrt(8 / pi) + 3 sqrt(3 - 8 / pi)`.
pub const RP_PER_SIGMA: f64 = 3.6161;

/// The registration's share of a verification measured from a station of its own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationShare {
    /// Points the frame was fitted to.
    pub points: usize,
    /// Per-axis residual of the fit (mm): `sqrt(sum |r|^2 / (3n - 6))`.
    pub residual_sigma_mm: f64,
    /// The RMS error norm the fitted frame's own error adds (mm): `sigma sqrt(6 / n)`.
    pub rms_mm: f64,
}

/// The share of the frame `frame` fitted to `obs` under `model` (see the module docs); `None`
/// with fewer than 3 points.
pub fn station_share(
    model: &Robot,
    frame: &TrackerFrame,
    obs: &Observations,
) -> Option<StationShare> {
    let n = obs.len();
    if n < 3 {
        return None;
    }
    let at = obs.model_positions(model);
    let ss: f64 = (0..n)
        .map(|i| (frame.to_tracker(&at[i]) - obs.m(i)).norm_squared())
        .sum();
    let sigma = (ss / (3 * n - 6).max(1) as f64).sqrt();
    Some(StationShare {
        points: n,
        residual_sigma_mm: sigma,
        rms_mm: sigma * (6.0 / n as f64).sqrt(),
    })
}

/// The RMS displacement of the tool point (mm) a random error per joint and per move of
/// standard deviation `std` (deg, mm for a prismatic joint; one per joint) gives at the joint
/// vectors `qs` (see the module docs). 0 without poses.
pub fn repeatability_rms<'a>(
    robot: &Robot,
    qs: impl IntoIterator<Item = &'a [f64]>,
    std: &[f64],
) -> f64 {
    let s: Vec<f64> = std
        .iter()
        .enumerate()
        .map(|(j, v)| match robot.joint_type(j) {
            JointType::Revolute => v.to_radians(),
            JointType::Prismatic => *v,
        })
        .collect();
    let mut jq = vec![Vector3::zeros(); robot.dof()];
    let (mut sum, mut n) = (0.0, 0usize);
    for q in qs {
        robot.tool_screw_jacobians(q, Some(&mut jq), None, None);
        sum += jq
            .iter()
            .zip(&s)
            .map(|(c, s)| s * s * c.norm_squared())
            .sum::<f64>();
        n += 1;
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

/// The largest accepted pose repeatability (mm): ten times that of the least repeatable
/// industrial arms.
pub const MAX_RP_MM: f64 = 10.0;

/// Checks a pose repeatability `rp_mm` (ISO 9283 RP, mm): finite, above 0, at most
/// [`MAX_RP_MM`]. The error names the setting `repeatability_mm`.
pub fn check_rp(rp_mm: f64) -> crate::error::Result<()> {
    if rp_mm.is_finite() && rp_mm > 0.0 && rp_mm <= MAX_RP_MM {
        Ok(())
    } else {
        Err(crate::error::Error::invalid(
            "repeatability_mm",
            format!("{rp_mm} is not a pose repeatability within 0..{MAX_RP_MM} mm"),
        ))
    }
}

/// The RMS error norm (mm) of an isotropic scatter of repeatability `rp_mm` (ISO 9283 RP):
/// `sqrt(3) RP / RP_PER_SIGMA`.
pub fn rms_of_rp(rp_mm: f64) -> f64 {
    3.0_f64.sqrt() * rp_mm / RP_PER_SIGMA
}

/// The robot's repeatability, for [`split`].
#[derive(Debug, Clone, PartialEq)]
pub enum Repeatability {
    /// An ISO 9283 pose repeatability RP (mm), given.
    Rp(f64),
    /// A standard deviation per joint and move (deg), and where it comes from (e.g. the
    /// robot class's default, `simulation::RepeatabilityModel::default_for`).
    PerJoint {
        /// 1-sigma per joint (deg).
        std_deg: Vec<f64>,
        /// In words, for the report.
        source: String,
    },
}

/// The split of one verification.
pub struct Gap {
    /// RMS error norm measured (mm).
    pub verified_rms_mm: f64,
    /// RMS error norm the calibration predicted at new poses (mm).
    pub predicted_rms_mm: f64,
    /// The registration's share, when the frame was fitted to these data.
    pub station: Option<StationShare>,
    /// The repeatability's RMS displacement at these poses (mm), and where the figure comes
    /// from.
    pub repeatability_mm: f64,
    /// Where the repeatability figure comes from (`RP .. mm, given`, the class default).
    pub repeatability_source: String,
    /// The prediction's noise as an RMS error norm (mm): `sqrt(3) sigma`.
    pub predicted_noise_mm: f64,
}

impl Gap {
    /// The gap in quadrature: `sqrt(max(0, verified^2 - predicted^2))` (mm).
    pub fn total_mm(&self) -> f64 {
        (self.verified_rms_mm.powi(2) - self.predicted_rms_mm.powi(2))
            .max(0.0)
            .sqrt()
    }

    /// What the station does not explain of the gap (mm, in quadrature).
    pub fn left_mm(&self) -> f64 {
        let s = self.station.map_or(0.0, |s| s.rms_mm);
        (self.total_mm().powi(2) - s * s).max(0.0).sqrt()
    }

    /// The split as JSON.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "verified_rms_mm": self.verified_rms_mm,
            "predicted_rms_mm": self.predicted_rms_mm,
            "gap_rms_mm": self.total_mm(),
            "station": self.station.map(|s| serde_json::json!({
                "points": s.points,
                "residual_sigma_mm": s.residual_sigma_mm,
                "rms_mm": s.rms_mm,
            })),
            "left_rms_mm": self.left_mm(),
            "repeatability": {
                "rms_mm": self.repeatability_mm,
                "source": self.repeatability_source,
                "predicted_noise_rms_mm": self.predicted_noise_mm,
            },
        })
    }
}

/// The split of the verification `set` (RMS error norm `verified_rms_mm`) against `res`'s
/// prediction; `frame`: the frame fitted to these data (a fresh station registered again), if
/// any; `repeatability`: the robot's, given as an ISO 9283 RP or per joint. `None` when the
/// result has no prediction.
pub fn split(
    nominal: &Robot,
    calibrated: &Robot,
    res: &CalibrationResult,
    set: &MeasurementSet,
    verified_rms_mm: f64,
    frame: Option<&TrackerFrame>,
    repeatability: Repeatability,
) -> Result<Option<Gap>> {
    let Some(p) = res.prediction.as_ref().filter(|p| p.rms_mm.is_finite()) else {
        return Ok(None);
    };
    let station = match frame {
        Some(f) => station_share(calibrated, f, &observations_of(set)?),
        None => None,
    };
    let (repeatability_mm, repeatability_source) = match repeatability {
        Repeatability::Rp(rp) => (rms_of_rp(rp), format!("RP {rp} mm, given")),
        Repeatability::PerJoint { std_deg, source } => {
            let qs = set.rows.iter().map(|r| r.q.as_slice());
            (repeatability_rms(nominal, qs, &std_deg), source)
        }
    };
    Ok(Some(Gap {
        verified_rms_mm,
        predicted_rms_mm: p.rms_mm,
        station,
        repeatability_mm,
        repeatability_source,
        predicted_noise_mm: 3.0_f64.sqrt() * p.noise_sigma_mm,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;
    use crate::simulation::{
        random_poses, stream_rng, PoseSampler, RepeatabilityModel, Stream, Tracker,
    };

    #[test]
    fn rp_of_a_gaussian_scatter() {
        let (a, b) = ((8.0 / std::f64::consts::PI).sqrt(), 3.0);
        let want = a + b * (3.0 - a * a).sqrt();
        assert!((RP_PER_SIGMA - want).abs() < 1e-4, "{want}");
    }

    /// Monte Carlo: the repeatability's RMS displacement and the registration's share agree with
    /// the formulas to a few percent.
    #[test]
    fn the_shares_match_a_monte_carlo() {
        let kr = preset("kuka-kr480-r3330").unwrap();
        let mut rng = stream_rng(3, Stream::Calibration);
        let qs = random_poses(&kr, 60, &PoseSampler::default(), &mut rng).unwrap();
        // Repeatability: the class default, drawn 200 times at every pose.
        let rep = RepeatabilityModel::default_for(&kr);
        let want = repeatability_rms(&kr, qs.iter().map(Vec::as_slice), &rep.std_deg);
        let (mut ss, mut n) = (0.0, 0);
        for k in 0..200 {
            let moved = rep.attained(&kr, &qs, k);
            for (q, m) in qs.iter().zip(&moved) {
                ss += (kr.tool_position(m) - kr.tool_position(q)).norm_squared();
                n += 1;
            }
        }
        let got = (ss / f64::from(n)).sqrt();
        eprintln!("repeatability RMS: formula {want:.5} mm, Monte Carlo {got:.5} mm");
        assert!((got / want - 1.0).abs() < 0.03, "{got} vs {want}");
        // The station: noisy readings of exact points, a frame fitted to each draw; the error
        // the fitted frame adds at the points, against sigma sqrt(6 / n).
        let truth = crate::io::result::FrameVec {
            x: 3000.0,
            y: -2000.0,
            z: 1200.0,
            a: 125.0,
            b: 0.0,
            c: 0.0,
        }
        .to_tracker_frame();
        let sigma = 0.05;
        let tracker = Tracker::new(truth, sigma, 0.0).unwrap();
        let exact: Vec<Vector3<f64>> = qs.iter().map(|q| kr.tool_position(q)).collect();
        let (mut added, mut predicted) = (0.0, 0.0);
        let draws = 200;
        let mut noise = stream_rng(4, Stream::Noise);
        for _ in 0..draws {
            let m: Vec<Vector3<f64>> = exact
                .iter()
                .map(|p| tracker.measure(p, &mut noise))
                .collect();
            let mut obs = Observations::new(kr.dof());
            for (i, (q, p)) in qs.iter().zip(&m).enumerate() {
                obs.push(q, *p, i + 2).unwrap();
            }
            let f = crate::registration::refit_frame(&kr, &obs).unwrap();
            let share = station_share(&kr, &f, &obs).unwrap();
            predicted += share.rms_mm.powi(2);
            added += exact
                .iter()
                .map(|p| (f.to_tracker(p) - truth.to_tracker(p)).norm_squared())
                .sum::<f64>()
                / exact.len() as f64;
        }
        let (added, predicted) = (
            (added / f64::from(draws)).sqrt(),
            (predicted / f64::from(draws)).sqrt(),
        );
        eprintln!("station: formula {predicted:.5} mm, Monte Carlo {added:.5} mm");
        assert!(
            (added / predicted - 1.0).abs() < 0.05,
            "{added} vs {predicted}"
        );
    }
}
