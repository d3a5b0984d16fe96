//! A fresh tracker set-up: the tracker carried away and set up again, as between a calibration
//! and a verification measured another day. The readings of such a session are in a new frame
//! that must be registered again (`evaluate --refit-frame`), and that registration's own error
//! adds to what the session measures.
//!
//! # Model
//! Station 0 is the configured tracker frame. Station k >= 1 is that frame turned about the
//! robot's base z axis by an angle of 15 to 45 degrees (either way), its horizontal distance to
//! the base axis scaled by 0.85..1.15, its height moved by -300..300 mm and its own heading
//! turned by a further -5..5 degrees; the draws come from their own random stream of the
//! session's seed and k, so station k of a seed is always the same place.

use super::config::SimulationConfig;
use crate::error::{Error, Result};
use crate::io::result::FrameVec;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The random stream of station set-ups (apart from the cell's [`super::Stream`]s).
const STATION_STREAM: u64 = 0x5747;

/// The largest station number.
pub const MAX_STATION: u32 = 1000;

/// The tracker frame of station `station` set up from `frame` (see the module documentation).
pub fn station_frame(frame: &FrameVec, seed: u64, station: u32) -> FrameVec {
    if station == 0 {
        return *frame;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (u64::from(station) << 32));
    rng.set_stream(STATION_STREAM);
    let turn: f64 = rng.gen_range(15.0..=45.0) * if rng.gen_bool(0.5) { 1.0 } else { -1.0 };
    let scale: f64 = rng.gen_range(0.85..=1.15);
    let dz: f64 = rng.gen_range(-300.0..=300.0);
    let heading: f64 = rng.gen_range(-5.0..=5.0);
    let (s, c) = turn.to_radians().sin_cos();
    let (x, y) = (frame.x * scale, frame.y * scale);
    FrameVec {
        x: c * x - s * y,
        y: s * x + c * y,
        z: frame.z + dz,
        a: frame.a + turn + heading,
        b: frame.b,
        c: frame.c,
    }
}

impl SimulationConfig {
    /// The tracker frame the session measures from: `tracker_frame` set up as station
    /// `station` ([`station_frame`]).
    pub fn station_tracker_frame(&self) -> FrameVec {
        station_frame(&self.tracker_frame, self.seed, self.station)
    }

    /// Checks the settings of this file's effects (backlash, thermal growth, station) against a
    /// robot with `dof` joints.
    pub(super) fn validate_real_cell(&self, dof: usize) -> Result<()> {
        if let Some(b) = &self.backlash {
            b.validate(dof)?;
        }
        if let Some(t) = &self.thermal {
            t.validate_for(dof)?;
        }
        if self.station > MAX_STATION {
            return Err(Error::invalid(
                "station",
                format!("{}: at most {MAX_STATION}", self.station),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fresh_station_is_elsewhere_and_repeatable() {
        let c = SimulationConfig::default();
        assert_eq!(c.station_tracker_frame(), c.tracker_frame);
        let s1 = SimulationConfig {
            station: 1,
            ..c.clone()
        };
        let f1 = s1.station_tracker_frame();
        assert_eq!(f1, s1.station_tracker_frame());
        let t = c.tracker_frame;
        let r0 = (t.x * t.x + t.y * t.y).sqrt();
        let r1 = (f1.x * f1.x + f1.y * f1.y).sqrt();
        assert!((0.85 * r0 - 1e-9..=1.15 * r0 + 1e-9).contains(&r1));
        let turn = (f1.y.atan2(f1.x) - t.y.atan2(t.x)).to_degrees().abs();
        assert!((15.0 - 1e-9..=45.0 + 1e-9).contains(&turn), "{turn}");
        let f2 = SimulationConfig {
            station: 2,
            ..c.clone()
        }
        .station_tracker_frame();
        assert_ne!(f1, f2);
        assert!(SimulationConfig {
            station: MAX_STATION + 1,
            ..c
        }
        .validate_real_cell(6)
        .is_err());
    }
}
