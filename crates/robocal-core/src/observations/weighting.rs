//! Weighted fitting (DESIGN.md, `sigma_mm`): every tracker's uncertainty grows with the distance
//! from the tracker, and 6-DoF data mix millimetres with degrees. A fit weights each
//! observation's rows by `sigma_mean / sigma_i` (weighted least squares, with residuals kept in mm
//! of a typical point), and an orientation row by the mm one degree of orientation error counts
//! as. A point's sigma comes from its `sigma_mm` cell or, without one, from a tracker model
//! `sigma(d) = fixed + per_m * d` with `d` the point's distance from the tracker (the norm of the
//! measured point in the tracker frame).

use super::Observations;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The default weight of orientation rows (mm per degree): the ratio of a 6-DoF probe's typical
/// position uncertainty at a few metres (about 0.03 mm) to its orientation uncertainty (about
/// 0.01 degree), so that one degree of orientation error counts like 3 mm of position error.
pub const DEFAULT_MM_PER_DEG: f64 = 3.0;

/// A tracker's 1-sigma uncertainty per axis as a function of distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TrackerSigma {
    /// The part independent of distance (mm).
    pub fixed_mm: f64,
    /// The part proportional to the distance from the tracker (mm per metre).
    pub per_m_mm: f64,
}

impl TrackerSigma {
    /// A checked model: both parts finite and non-negative, not both zero.
    pub fn new(fixed_mm: f64, per_m_mm: f64) -> Result<TrackerSigma> {
        let ok = |v: f64| v >= 0.0 && v.is_finite() && v <= 1e3;
        if !ok(fixed_mm) || !ok(per_m_mm) || fixed_mm + per_m_mm <= 0.0 {
            return Err(Error::invalid(
                "weighting.tracker",
                format!(
                    "{fixed_mm}, {per_m_mm} is not a tracker uncertainty: a fixed part (mm) and a \
                     part per metre of distance (mm/m), both non-negative and not both zero"
                ),
            ));
        }
        Ok(TrackerSigma { fixed_mm, per_m_mm })
    }

    /// The sigma at `distance_mm` from the tracker (mm).
    pub fn sigma_at(&self, distance_mm: f64) -> f64 {
        self.fixed_mm + self.per_m_mm * distance_mm / 1000.0
    }
}

/// The tracker model a fit applies by default ([`Weighting::automatic`]): a typical laser
/// tracker's 1-sigma per axis, 0.010 mm plus 0.005 mm per metre of distance (the simulation's
/// default tracker; a Leica AT960's specification, 15 um + 6 um/m maximum permissible error, is
/// about twice these sigmas: the weights, ratios of sigmas, depend only on their ratio).
pub const TYPICAL_TRACKER: TrackerSigma = TrackerSigma {
    fixed_mm: 0.010,
    per_m_mm: 0.005,
};

/// The least distance (mm) between the origin of the measurement frame and the robot's base for
/// the data to be taken as given in a tracker's own frame (the tracker at the origin). Nearer,
/// the data are in the robot's base frame or in a frame close to it (a tracker cannot stand
/// inside the robot's base), and a point's distance from the origin says nothing about its
/// distance from the tracker.
pub const TRACKER_FRAME_MIN_DISTANCE_MM: f64 = 500.0;

/// The smallest `sigma_mm` accepted, as a fraction of the median `sigma_mm`: a point ten times
/// more certain than the typical one weighs a hundred of them in a fit, enough to pin the fit to
/// it alone when it is wrong (one point 3 mm off with a sigma a hundredth of the others' dragged
/// a fit to worse than the nominal model). Real uncertainties of one tracker session differ by
/// the distance term, a factor of 2 to 5.
pub const SIGMA_FLOOR_RATIO: f64 = 0.1;

/// The largest `sigma_mm` accepted, as a multiple of the median `sigma_mm`: a point a hundred
/// times less certain than the typical one weighs a ten-thousandth of it, which is leaving it
/// out without saying so; such a point is better removed.
pub const SIGMA_CEILING_RATIO: f64 = 100.0;

/// Checks that every observation's `sigma_mm` lies within [`SIGMA_FLOOR_RATIO`] and
/// [`SIGMA_CEILING_RATIO`] of their median, naming the first that does not (file, line, field).
pub fn check_sigma_spread(obs: &Observations) -> Result<()> {
    let sigmas: Vec<f64> = (0..obs.len()).filter_map(|i| obs.sigma_mm(i)).collect();
    if sigmas.len() != obs.len() || sigmas.is_empty() {
        return Ok(());
    }
    let median = crate::stats::percentile(&sigmas, 0.5);
    for (i, &s) in sigmas.iter().enumerate() {
        let (limit, what) = if s < SIGMA_FLOOR_RATIO * median {
            (SIGMA_FLOOR_RATIO, "below")
        } else if s > SIGMA_CEILING_RATIO * median {
            (SIGMA_CEILING_RATIO, "above")
        } else {
            continue;
        };
        return Err(Error::invalid(
            format!("{}: sigma_mm", obs.describe(obs.line(i))),
            format!(
                "{s} mm is {what} {limit} times the median uncertainty of the points ({median} \
                 mm): its weight would be {:.3e} times a typical point's. A point far more \
                 certain than the others pins the fit to itself, one far less certain is left \
                 out without a word; check the value, or remove the point",
                (median / s).powi(2)
            ),
        ));
    }
    Ok(())
}

/// How a fit weights observations (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weighting {
    /// The tracker model for points without a `sigma_mm` cell; `None` leaves them unweighted
    /// (when no point has a cell), unless `automatic` applies.
    pub tracker: Option<TrackerSigma>,
    /// Without a tracker model and without `sigma_mm` cells: weight by [`TYPICAL_TRACKER`] when
    /// the data are in a tracker's own frame (the registered tracker at least
    /// [`TRACKER_FRAME_MIN_DISTANCE_MM`] from the robot's base, and the nominal model fitting
    /// the data, without which the registered frame means nothing). Default on.
    pub automatic: bool,
    /// How many mm of position error one degree of orientation error counts as.
    pub mm_per_deg: f64,
}

impl Default for Weighting {
    fn default() -> Self {
        Weighting {
            tracker: None,
            automatic: true,
            mm_per_deg: DEFAULT_MM_PER_DEG,
        }
    }
}

/// Where a fit's point weights came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WeightSource {
    /// The measurement file's `sigma_mm` column.
    Column,
    /// The tracker model given in the settings.
    Given,
    /// [`TYPICAL_TRACKER`], the data being in a tracker's frame ([`Weighting::automatic`]).
    Automatic,
    /// None: every point counts the same.
    None,
}

/// The weighting a fit used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AppliedWeighting {
    /// Where the point weights came from.
    pub source: WeightSource,
    /// The tracker model applied (given or automatic).
    pub tracker: Option<TrackerSigma>,
    /// The distance of the registered tracker (the measurement frame's origin) from the robot's
    /// base (mm).
    pub tracker_distance_mm: f64,
}

impl Weighting {
    /// The weighting for data whose registered tracker (the measurement frame's origin) is
    /// `tracker_distance_mm` from the robot's base, `nominal_fits` telling whether the nominal
    /// model fits the data (the fitted tool's test): the tracker model to apply, and where it
    /// comes from.
    pub fn resolve(
        &self,
        obs: &Observations,
        tracker_distance_mm: f64,
        nominal_fits: bool,
    ) -> AppliedWeighting {
        let (source, tracker) = if obs.has_sigma() {
            (WeightSource::Column, None)
        } else if let Some(t) = self.tracker {
            (WeightSource::Given, Some(t))
        } else if self.automatic
            && nominal_fits
            && tracker_distance_mm >= TRACKER_FRAME_MIN_DISTANCE_MM
        {
            (WeightSource::Automatic, Some(TYPICAL_TRACKER))
        } else {
            (WeightSource::None, None)
        };
        AppliedWeighting {
            source,
            tracker,
            tracker_distance_mm,
        }
    }

    /// `obs` with these weights applied: the tracker model's sigmas where the observations have
    /// none, and the orientation weight.
    pub fn apply(&self, obs: &Observations) -> Result<Observations> {
        check_sigma_spread(obs)?;
        let mut out = obs.clone();
        out.set_mm_per_deg(self.mm_per_deg)?;
        if let (Some(t), false) = (self.tracker, obs.has_sigma()) {
            let s = (0..obs.len())
                .map(|i| t.sigma_at(obs.m(i).norm()))
                .collect();
            out.set_sigmas(Some(s))?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn points(with_sigma: bool) -> Observations {
        let mut obs = Observations::new(1);
        for i in 0..3 {
            obs.push(
                &[i as f64],
                Vector3::new(1000.0 * i as f64, 0.0, 0.0),
                i + 2,
            )
            .unwrap();
        }
        if with_sigma {
            obs.set_sigmas(Some(vec![0.01, 0.02, 0.03])).unwrap();
        }
        obs
    }

    /// The typical tracker is the simulation's default one (the weights of simulated data are
    /// then the true noise's).
    #[test]
    fn the_typical_tracker_is_the_simulated_one() {
        assert_eq!(
            TYPICAL_TRACKER.fixed_mm,
            crate::simulation::DEFAULT_NOISE_MM
        );
        assert_eq!(
            TYPICAL_TRACKER.per_m_mm,
            crate::simulation::DEFAULT_NOISE_PER_M
        );
    }

    /// A `sigma_mm` column wins, then a given model; the typical tracker applies only to data
    /// in a tracker's frame that the nominal model fits, and only when automatic.
    #[test]
    fn resolution_order_and_the_tracker_frame_rule() {
        let given = TrackerSigma::new(0.02, 0.01).unwrap();
        let w = Weighting::default();
        let far = TRACKER_FRAME_MIN_DISTANCE_MM;
        let near = far - 1.0;
        assert_eq!(
            w.resolve(&points(true), far, true).source,
            WeightSource::Column
        );
        let g = Weighting {
            tracker: Some(given),
            ..w
        };
        let r = g.resolve(&points(false), near, false);
        assert_eq!((r.source, r.tracker), (WeightSource::Given, Some(given)));
        let r = w.resolve(&points(false), far, true);
        assert_eq!(
            (r.source, r.tracker),
            (WeightSource::Automatic, Some(TYPICAL_TRACKER))
        );
        assert_eq!(
            w.resolve(&points(false), near, true).source,
            WeightSource::None
        );
        // Data the nominal model does not fit: their frame says nothing of the tracker.
        assert_eq!(
            w.resolve(&points(false), far, false).source,
            WeightSource::None
        );
        let off = Weighting {
            automatic: false,
            ..w
        };
        assert_eq!(
            off.resolve(&points(false), far, true).source,
            WeightSource::None
        );
    }
}
