//! The settings of a simulated measurement session, validated before any work is done.

use super::backlash::BacklashModel;
use super::gravity::GravityModel;
use super::outliers::OutlierModel;
use super::poses::PoseSampler;
use super::repeatability::RepeatabilityModel;
use super::thermal::ThermalModel;
use crate::error::{Error, Result};
use crate::io::result::FrameVec;
use crate::model::Robot;
use crate::ranges::{self, in_range};
use serde::{Deserialize, Serialize};

/// The default pose of the tracker in the robot's base frame (mm, deg): 3.8 m away horizontally
/// and 1.2 m up (about 4 m from the base origin), turned by 125 degrees about its vertical axis,
/// levelled. A point m read by the tracker is `pose(frame) * m` in the base frame.
pub const DEFAULT_TRACKER_FRAME: [f64; 6] = [3112.8, -2179.6, 1200.0, 125.0, 0.0, 0.0];

/// The default tracker noise: 0.010 mm + 0.005 mm per metre of distance, per axis (ASME
/// B89.4.19-style figures).
pub const DEFAULT_NOISE_MM: f64 = 0.010;
/// See [`DEFAULT_NOISE_MM`].
pub const DEFAULT_NOISE_PER_M: f64 = 0.005;

/// The default footprint radius as a fraction of the chain's total length (see
/// [`SimulationConfig::footprint_radius`]).
pub const FOOTPRINT_FRACTION: f64 = 0.15;

/// Everything that defines a simulated session except the robots: poses, tracker, noise,
/// non-geometric errors and the seed. All lengths in mm, angles in degrees.
///
/// Build it from [`SimulationConfig::default`] and set the fields, then call
/// [`SimulationConfig::validate`] (the simulation functions call it too).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimulationConfig {
    /// The seed of every random choice. The same seed gives the same truth robot (for a
    /// `random` truth), the same poses and the same noise.
    pub seed: u64,
    /// Number of random calibration poses (set `calibration`).
    pub poses: usize,
    /// Number of random validation poses (set `validation`), drawn independently of the
    /// calibration poses.
    pub validation_poses: usize,
    /// Whether to add the paper's three plane points (set `plane`).
    pub plane_points: bool,
    /// Height of the plane of the three plane points (mm, base frame); `None`: the median tool
    /// height of random poses.
    pub plane_z_mm: Option<f64>,
    /// Tool points below this height (mm, base frame) are rejected.
    pub floor_z_mm: f64,
    /// Tool points closer than this to the base z axis (mm) are rejected; `None`:
    /// [`FOOTPRINT_FRACTION`] of the chain's total length.
    pub footprint_radius_mm: Option<f64>,
    /// Pose of the tracker frame in the base frame (mm, deg).
    pub tracker_frame: FrameVec,
    /// Constant part of the tracker's noise: standard deviation per axis (mm).
    pub noise_mm: f64,
    /// Distance-proportional part of the noise: standard deviation per axis per metre from the
    /// tracker (mm/m).
    pub noise_per_m: f64,
    /// Gravity-induced joint deflection (off when `None`).
    pub gravity: Option<GravityModel>,
    /// Gross outliers (off when `None`).
    pub outliers: Option<OutlierModel>,
    /// The robot's repeatability: a random error per joint and per move (off when `None`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub repeatability: Option<RepeatabilityModel>,
    /// Gear play: joints stop short on the side they came from, the poses visited in row
    /// order (off when `None`; see [`BacklashModel`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub backlash: Option<BacklashModel>,
    /// Thermal growth of the arm warming up over the session (off when `None`; see
    /// [`ThermalModel`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thermal: Option<ThermalModel>,
    /// The tracker set-up: 0 measures from `tracker_frame`, k >= 1 from a fresh station
    /// elsewhere (see [`super::station_frame`]).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub station: u32,
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

impl Default for SimulationConfig {
    /// Seed 1, 75 calibration poses and the plane points, no validation poses, floor at z = 0,
    /// automatic footprint, the default tracker and noise, no non-geometric errors.
    fn default() -> Self {
        let t = DEFAULT_TRACKER_FRAME;
        SimulationConfig {
            seed: 1,
            poses: 75,
            validation_poses: 0,
            plane_points: true,
            plane_z_mm: None,
            floor_z_mm: 0.0,
            footprint_radius_mm: None,
            tracker_frame: FrameVec {
                x: t[0],
                y: t[1],
                z: t[2],
                a: t[3],
                b: t[4],
                c: t[5],
            },
            noise_mm: DEFAULT_NOISE_MM,
            noise_per_m: DEFAULT_NOISE_PER_M,
            gravity: None,
            outliers: None,
            repeatability: None,
            backlash: None,
            thermal: None,
            station: 0,
        }
    }
}

impl SimulationConfig {
    /// Checks every setting against the nominal robot: finite, and within its plausible range
    /// ([`crate::ranges`]: lengths within ±1 km, noise and sizes not negative). Errors name the
    /// setting (the field of this struct). The number of poses is checked by [`super::simulate`], which needs
    /// it (measuring given joints does not).
    pub fn validate(&self, nominal: &Robot) -> Result<()> {
        in_range("noise_mm", self.noise_mm, &ranges::SIZE_MM)?;
        in_range("noise_per_m", self.noise_per_m, &ranges::NOISE_PER_M)?;
        let t = &self.tracker_frame;
        let (l, a) = (&ranges::LENGTH, &ranges::ANGLE);
        for (k, v, range) in [
            ("x", t.x, l),
            ("y", t.y, l),
            ("z", t.z, l),
            ("A", t.a, a),
            ("B", t.b, a),
            ("C", t.c, a),
        ] {
            range
                .check(v)
                .map_err(|msg| Error::invalid("tracker_frame", format!("{k}: {msg}")))?;
        }
        in_range("floor_z_mm", self.floor_z_mm, &ranges::LENGTH)?;
        if let Some(r) = self.footprint_radius_mm {
            in_range("footprint_radius_mm", r, &ranges::SIZE_MM)?;
        }
        if let Some(z) = self.plane_z_mm {
            in_range("plane_z_mm", z, &ranges::LENGTH)?;
        }
        if let Some(g) = &self.gravity {
            g.validate(nominal.dof())?;
        }
        if let Some(o) = &self.outliers {
            o.validate()?;
        }
        if let Some(r) = &self.repeatability {
            r.validate(nominal.dof())?;
        }
        self.validate_real_cell(nominal.dof())?;
        Ok(())
    }

    /// The footprint radius used (mm): the configured one, or [`FOOTPRINT_FRACTION`] of the
    /// chain's total length `sum(|a_i| + |d_i|) + |tool translation|` (an upper bound of its
    /// reach): about 750 mm for the KR 480 R3330, 180 mm for a UR5.
    pub fn footprint_radius(&self, nominal: &Robot) -> f64 {
        self.footprint_radius_mm
            .unwrap_or_else(|| FOOTPRINT_FRACTION * nominal.reach_mm())
    }

    /// The pose sampler of these settings for `nominal`.
    pub fn sampler(&self, nominal: &Robot) -> PoseSampler {
        PoseSampler {
            floor_z_mm: self.floor_z_mm,
            footprint_radius_mm: self.footprint_radius(nominal),
            ..PoseSampler::default()
        }
    }
}
