//! The settings of a pose plan as a user gives them (the `robocal plan` flags, the
//! `robocal.plan` keyword arguments), checked once, here: [`PlanBuilder::build`] refuses every
//! bad setting naming it, so that the command line and the Python bindings refuse the same
//! input with the same message. Counts outside their limits are [`Error::Usage`]; values outside
//! their plausible ranges are [`Error::Invalid`].

use super::{tracker_range, Criterion, PlanSettings, DEFAULT_CANDIDATES};
use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::io::result::FrameVec;
use crate::model::Robot;
use crate::simulation::{SimulationConfig, DEFAULT_NOISE_MM, DEFAULT_NOISE_PER_M};

/// Most candidates (and poses): 200,000 take about 150 MB for a six-joint robot.
pub const MAX_CANDIDATES: usize = 200_000;

/// The largest tracker noise of a plan (mm, and mm per metre).
pub const MAX_PLAN_NOISE: f64 = 1000.0;

/// Everything a plan is given, unchecked: set the fields, then [`PlanBuilder::build`].
#[derive(Debug, Clone)]
pub struct PlanBuilder {
    /// Poses to choose (besides the included ones).
    pub poses: usize,
    /// Random candidates to choose from.
    pub candidates: usize,
    /// Seed of the candidates.
    pub seed: u64,
    /// What the plan optimizes.
    pub criterion: Criterion,
    /// The tracker's pose in the base frame; `None`: the simulation's default (and no
    /// distance-dependent noise).
    pub tracker_frame: Option<FrameVec>,
    /// The tracker's working range (min, max), mm.
    pub tracker_range: Option<(f64, f64)>,
    /// Poses measured anyway (joint values, internal units).
    pub include: Vec<Vec<f64>>,
    /// Lowest tool point (mm).
    pub floor_z_mm: f64,
    /// Smallest distance of the tool point from the base axis (mm); `None`: automatic.
    pub footprint_radius_mm: Option<f64>,
    /// Tracker noise, constant part (mm).
    pub noise_mm: f64,
    /// Tracker noise per metre (mm/m).
    pub noise_per_m: f64,
}

impl Default for PlanBuilder {
    /// 75 poses from the default candidates, seed 1, I-optimal, the default noise.
    fn default() -> Self {
        PlanBuilder {
            poses: 75,
            candidates: DEFAULT_CANDIDATES,
            seed: 1,
            criterion: Criterion::IOptimal,
            tracker_frame: None,
            tracker_range: None,
            include: Vec::new(),
            floor_z_mm: 0.0,
            footprint_radius_mm: None,
            noise_mm: DEFAULT_NOISE_MM,
            noise_per_m: DEFAULT_NOISE_PER_M,
        }
    }
}

impl PlanBuilder {
    /// Checks every setting for `robot` and returns the plan's settings: the counts
    /// ([`Error::Usage`]), then the noise, floor, footprint, tracker and range against their
    /// plausible ranges ([`Error::Invalid`]).
    pub fn build(self, robot: &Robot) -> Result<PlanSettings> {
        Error::check_count(
            "poses",
            self.poses as u64,
            1,
            MAX_CANDIDATES as u64,
            "no calibration measures more",
        )?;
        Error::check_count(
            "candidates",
            self.candidates as u64,
            self.poses as u64,
            MAX_CANDIDATES as u64,
            "memory and time grow with the candidates",
        )?;
        if !(self.noise_mm > 0.0 && self.noise_mm <= MAX_PLAN_NOISE) {
            return Err(Error::invalid(
                "noise_mm",
                format!(
                    "{}: not a positive length up to {MAX_PLAN_NOISE} mm",
                    self.noise_mm
                ),
            ));
        }
        if !(0.0..=MAX_PLAN_NOISE).contains(&self.noise_per_m) {
            return Err(Error::invalid(
                "noise_per_m",
                format!("{}: not within 0..{MAX_PLAN_NOISE} mm/m", self.noise_per_m),
            ));
        }
        let cfg = SimulationConfig {
            floor_z_mm: self.floor_z_mm,
            footprint_radius_mm: self.footprint_radius_mm,
            tracker_frame: self
                .tracker_frame
                .unwrap_or(SimulationConfig::default().tracker_frame),
            ..SimulationConfig::default()
        };
        cfg.validate(robot)?;
        let t = cfg.tracker_frame;
        let frame = TrackerFrame::from_vector_deg(&[t.x, t.y, t.z, t.a, t.b, t.c]);
        let range = match self.tracker_range {
            Some((min, max)) => {
                if max > crate::ranges::LENGTH.max {
                    return Err(Error::invalid(
                        "tracker_range",
                        format!("{min}..{max} mm: at most {} mm", crate::ranges::LENGTH.max),
                    ));
                }
                Some(tracker_range(&frame, min, max)?)
            }
            None => None,
        };
        Ok(PlanSettings {
            poses: self.poses,
            candidates: self.candidates,
            seed: self.seed,
            sampler: cfg.sampler(robot),
            tracker_range: range,
            include: self.include,
            noise_mm: self.noise_mm,
            noise_per_m: self.noise_per_m,
            tracker_origin: self.tracker_frame.map(|_| frame.origin()),
            criterion: self.criterion,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_bad_setting_is_refused_naming_it() {
        let kr = crate::preset("kuka-kr480-r3330").unwrap();
        assert!(PlanBuilder::default().build(&kr).is_ok());
        let d = PlanBuilder::default;
        let cases: Vec<(PlanBuilder, &str, bool)> = vec![
            (
                PlanBuilder { poses: 0, ..d() },
                "poses: at least 1, got 0",
                true,
            ),
            (
                PlanBuilder {
                    poses: 300_000,
                    candidates: 400_000,
                    ..d()
                },
                "poses: at most 200000 (no calibration measures more), got 300000",
                true,
            ),
            (
                PlanBuilder {
                    candidates: 50,
                    ..d()
                },
                "candidates: at least 75, got 50",
                true,
            ),
            (
                PlanBuilder {
                    noise_mm: 0.0,
                    ..d()
                },
                "noise_mm: 0: not a positive length",
                false,
            ),
            (
                PlanBuilder {
                    noise_per_m: f64::NAN,
                    ..d()
                },
                "noise_per_m: NaN",
                false,
            ),
            (
                PlanBuilder {
                    floor_z_mm: 1e300,
                    ..d()
                },
                "floor_z_mm",
                false,
            ),
            (
                PlanBuilder {
                    tracker_range: Some((5000.0, 100.0)),
                    ..d()
                },
                "tracker_range: 5000..100 mm is not a range",
                false,
            ),
        ];
        for (b, want, usage) in cases {
            let e = b.build(&kr).unwrap_err();
            let m = e.to_string();
            assert!(m.contains(want), "`{want}` not in `{m}`");
            assert_eq!(matches!(e, Error::Usage { .. }), usage, "{m}");
        }
    }
}
