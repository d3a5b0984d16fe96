//! Thermal growth in the virtual cell: the arm warms up while it works, and its links and base
//! column grow with its temperature.
//!
//! # Model
//! - Row r of a session is measured at `time_s = r * seconds_per_pose` (seconds since the
//!   session started; the rows in file order).
//! - The arm's temperature follows a first-order warm-up curve,
//!   `T(t) = ambient_c + rise_c * (1 - exp(-(start_s + t) / time_constant_s))`, quantized to
//!   [`TEMPERATURE_STEP_C`] (what the measurement file holds is what was applied). `start_s`
//!   places the session on the curve: 0 starts cold, a later session of the same day starts
//!   warm.
//! - Every length of the chain (each link's `d` and `a`; the base column of a floor robot is
//!   `d1`) scales by `exp(k (T - ambient_c))`, `k` the linear expansion coefficient (1/K): to first order the
//!   textbook `1 + k dT` (the two differ by less than 1e-8 of a length for 100 K), and exactly
//!   what the calibration family `thermal` models, so that a reference temperature can be chosen
//!   freely. The true robot's geometry holds at `ambient_c`.
//!
//! Published figures: a robot's structure warms by 5 to 15 K within one to three hours of work,
//! its drift reaching tenths of a millimetre; [`ThermalModel::for_robot`] gives a default per
//! robot class.

use crate::error::{Error, Result};
#[cfg(test)]
use crate::model::family::thermal::grows;
use crate::model::family::thermal::scaled_links;
#[cfg(test)]
use crate::model::Param;
use crate::model::Robot;
use serde::{Deserialize, Serialize};

/// The resolution of a simulated temperature (deg C).
pub const TEMPERATURE_STEP_C: f64 = 1e-4;

/// The largest accepted expansion coefficient (1/K): ten times that of aluminium.
pub const MAX_EXPANSION_PER_K: f64 = 2.5e-4;

/// The warm-up of a simulated arm (see the module documentation).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ThermalModel {
    /// The cold arm's temperature, the one at which the true robot's geometry holds (deg C).
    pub ambient_c: f64,
    /// How far the arm warms once in steady work (K).
    pub rise_c: f64,
    /// The warm-up's time constant (s).
    pub time_constant_s: f64,
    /// The time between two measured poses (s): motion, settling and the tracker's reading.
    pub seconds_per_pose: f64,
    /// Where on the warm-up curve the session starts (s since the arm started to work; 0: cold).
    pub start_s: f64,
    /// The linear expansion coefficient of the structure (1/K; steel and cast iron 1.15e-5,
    /// aluminium 2.3e-5).
    pub expansion_per_k: f64,
    /// How much each link warms relative to the arm's measured temperature (one factor per
    /// link, within `0..=MAX_LINK_GAIN`): link j's lengths grow by
    /// `exp(k g_j (T - ambient_c))`. `None`: every link as measured (`g_j` = 1), the arm warming
    /// evenly. Real arms warm unevenly (the links next to the motors and reducers more than the
    /// sensor's spot, a long cast link less); the calibration family `thermal` with one
    /// coefficient per link models that exactly (`k_j = k g_j`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link_gain: Option<Vec<f64>>,
}

/// The largest accepted relative warm-up of a link ([`ThermalModel::link_gain`]): a link that
/// warms five times more than the arm's measured temperature says measures the wrong spot.
pub const MAX_LINK_GAIN: f64 = 5.0;

impl ThermalModel {
    /// The default for the robot's class, by its reach ([`Robot::reach_mm`]), starting cold at
    /// 20 deg C:
    /// - at least 2000 mm (cast-iron and steel heavy-payload arms such as the KR 480 R3330):
    ///   15 K rise, 3600 s time constant, 20 s per pose, 1.15e-5 / K;
    /// - 1000 to 2000 mm: 6 K, 2400 s, 15 s per pose, 1.15e-5 / K;
    /// - below 1000 mm (aluminium arms such as a UR5): 5 K, 1800 s, 10 s per pose, 2.3e-5 / K.
    ///
    /// Why 15 K for the heavy class, against the published anchors: the drift a warm-up causes
    /// at the tool is `k * rise * distance from the base`, 0.57 mm at the KR 480's 3.3 m reach
    /// with 15 K (0.30 mm with the 8 K this default had before). Vocetka et al. (Appl. Sci.
    /// 2021) report warm-up drifts of up to an order of magnitude above a robot's
    /// repeatability; the KR 480's datasheet repeatability is 0.08 mm, so its drift may reach
    /// 0.8 mm, and 8 K (0.30 mm, under 4 times) sat at the mild end. Le Reun et al. (Robotica
    /// 2022) measured 0.15 mm of thermal scatter over 6.5 h on an IRB 4600 (2.55 m, 60 kg
    /// payload), about three times its repeatability; an arm with drives for 480 kg dissipates
    /// far more in its motors and reducers, so its structure warms more (robot structures warm
    /// by 5 to 15 K over hours of work; the largest drives at the top of that). A cold arm
    /// then warms from 20 to 28.5 deg C during the 50 min of the paper's 151 points (24.8 on
    /// average), and a verification four hours into the day runs at 34.7 deg C, 10 K warmer
    /// than the calibration's mean.
    pub fn for_robot(robot: &Robot) -> ThermalModel {
        let reach = robot.reach_mm();
        let (rise_c, time_constant_s, seconds_per_pose, expansion_per_k) = if reach >= 2000.0 {
            (15.0, 3600.0, 20.0, 1.15e-5)
        } else if reach >= 1000.0 {
            (6.0, 2400.0, 15.0, 1.15e-5)
        } else {
            (5.0, 1800.0, 10.0, 2.3e-5)
        };
        ThermalModel {
            ambient_c: 20.0,
            rise_c,
            time_constant_s,
            seconds_per_pose,
            start_s: 0.0,
            expansion_per_k,
            link_gain: None,
        }
    }

    /// Checks every setting: temperatures within -50..150 deg C, a rise within -100..100 K,
    /// times positive (the start not negative) and below a year, the coefficient within
    /// `0..=MAX_EXPANSION_PER_K`, one link gain per joint of the robot (`dof`), each within
    /// `0..=MAX_LINK_GAIN`. Errors name the setting (`thermal.FIELD`).
    pub fn validate_for(&self, dof: usize) -> Result<()> {
        self.validate()?;
        let Some(g) = &self.link_gain else {
            return Ok(());
        };
        let name = "thermal.link_gain";
        if g.len() != dof {
            return Err(Error::invalid(
                name,
                format!(
                    "{} values for a robot with {dof} links (one per link)",
                    g.len()
                ),
            ));
        }
        for (i, v) in g.iter().enumerate() {
            if !(v.is_finite() && (0.0..=MAX_LINK_GAIN).contains(v)) {
                return Err(Error::invalid(
                    format!("{name} (link {})", i + 1),
                    format!("{v} is outside 0..{MAX_LINK_GAIN}"),
                ));
            }
        }
        Ok(())
    }

    /// [`ThermalModel::validate_for`] without the link gains' count.
    pub fn validate(&self) -> Result<()> {
        let year = 3.2e7;
        let checks: [(&str, f64, f64, f64); 6] = [
            ("thermal.ambient_c", self.ambient_c, -50.0, 150.0),
            ("thermal.rise_c", self.rise_c, -100.0, 100.0),
            ("thermal.time_constant_s", self.time_constant_s, 1e-3, year),
            ("thermal.seconds_per_pose", self.seconds_per_pose, 0.0, year),
            ("thermal.start_s", self.start_s, 0.0, year),
            (
                "thermal.expansion_per_k",
                self.expansion_per_k,
                0.0,
                MAX_EXPANSION_PER_K,
            ),
        ];
        for (name, v, lo, hi) in checks {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(Error::invalid(name, format!("{v} is outside {lo}..{hi}")));
            }
        }
        let hot = self.ambient_c + self.rise_c;
        if !(-50.0..=150.0).contains(&hot) {
            return Err(Error::invalid(
                "thermal.rise_c",
                format!("the arm would reach {hot} deg C, outside -50..150 deg C"),
            ));
        }
        Ok(())
    }

    /// Seconds since the session started at row `r` (0-based).
    pub fn time_s(&self, r: usize) -> f64 {
        r as f64 * self.seconds_per_pose
    }

    /// The arm's temperature (deg C, quantized to [`TEMPERATURE_STEP_C`]) at `time_s` seconds
    /// into the session.
    pub fn temperature_c(&self, time_s: f64) -> f64 {
        let t = self.start_s + time_s;
        let v = self.ambient_c + self.rise_c * (1.0 - (-t / self.time_constant_s).exp());
        // The value a file holds (4 decimals), so that data read back give the same growth.
        let q = (v / TEMPERATURE_STEP_C).round() * TEMPERATURE_STEP_C;
        format!("{q:.4}").parse().unwrap_or(q)
    }

    /// `robot` at temperature `temperature_c`: link j's `d` and `a` scaled by
    /// `exp(k g_j (T - ambient_c))` (`g_j` its [`ThermalModel::link_gain`], 1 without).
    pub fn grown(&self, robot: &Robot, temperature_c: f64) -> Robot {
        let dt = temperature_c - self.ambient_c;
        let s: Vec<f64> = (0..robot.dof())
            .map(|j| {
                let g = self
                    .link_gain
                    .as_ref()
                    .and_then(|g| g.get(j).copied())
                    .unwrap_or(1.0);
                (self.expansion_per_k * g * dt).exp()
            })
            .collect();
        scaled_links(robot, &s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::preset;

    #[test]
    fn warms_up_and_grows() {
        let kr = preset("kuka-kr480-r3330").unwrap();
        let m = ThermalModel::for_robot(&kr);
        m.validate().unwrap();
        assert_eq!(m.temperature_c(0.0), 20.0);
        let hot = m.temperature_c(1e6);
        assert!((hot - 20.0 - m.rise_c).abs() < 1e-9, "{hot}");
        let tau = m.temperature_c(3600.0);
        assert!((tau - (20.0 + m.rise_c * (1.0 - (-1.0_f64).exp()))).abs() <= 1e-4);
        // At +8 K every grown length is longer by k * 8 to first order.
        let g = m.grown(&kr, 28.0);
        let ps: Vec<Param> = kr.params().into_iter().filter(|p| grows(*p)).collect();
        assert!(!ps.iter().any(|p| p.name() == "base_z"));
        assert!(ps.iter().any(|p| p.name() == "d1"));
        assert!(ps.iter().any(|p| p.name() == "a2"));
        for p in kr.params() {
            let (a, b) = (kr.get(p), g.get(p));
            if grows(p) {
                assert!(
                    (b / a - 1.0 - 8.0 * 1.15e-5).abs() < 1e-8 || a == 0.0,
                    "{}",
                    p.name()
                );
            } else {
                assert_eq!(a, b, "{}", p.name());
            }
        }
    }

    #[test]
    fn bad_settings_are_named() {
        let kr = preset("kuka-kr480-r3330").unwrap();
        let ok = ThermalModel::for_robot(&kr);
        for (m, name) in [
            (
                ThermalModel {
                    time_constant_s: 0.0,
                    ..ok.clone()
                },
                "thermal.time_constant_s",
            ),
            (
                ThermalModel {
                    expansion_per_k: 1.0,
                    ..ok.clone()
                },
                "thermal.expansion_per_k",
            ),
            (
                ThermalModel {
                    start_s: f64::NAN,
                    ..ok.clone()
                },
                "thermal.start_s",
            ),
            (
                ThermalModel {
                    rise_c: 99.0,
                    ambient_c: 90.0,
                    ..ok.clone()
                },
                "thermal.rise_c",
            ),
        ] {
            let e = m.validate().unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }
}
