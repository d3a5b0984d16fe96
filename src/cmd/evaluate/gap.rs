//! A verification's gap to the calibration's prediction, split in quadrature (RMS error norms)
//! into what the fresh tracker station's registration adds (with `--refit-frame`), what is left
//! for the cell's conditions the model lacks or that changed since the calibration, and the
//! repeatability's size beside the prediction's noise, which already holds it (see
//! [`robocal_core::evaluation::gap`]). What the model's condition families explain (the data's
//! temperature, approach directions) is printed beside it by `conditions`.

use robocal_core::evaluation::gap::{repeatability_rms, rms_of_rp, station_share, StationShare};
use robocal_core::evaluation::observations_of;
use robocal_core::frame::TrackerFrame;
use robocal_core::io::{CalibrationResult, MeasurementSet};
use robocal_core::simulation::RepeatabilityModel;
use robocal_core::Robot;

/// The split of one verification.
pub(super) struct Gap {
    /// RMS error norm measured (mm).
    pub verified_rms_mm: f64,
    /// RMS error norm the calibration predicted at new poses (mm).
    pub predicted_rms_mm: f64,
    /// The registration's share, when the frame was fitted to these data.
    pub station: Option<StationShare>,
    /// The repeatability's RMS displacement at these poses (mm), and where the figure comes
    /// from.
    pub repeatability_mm: f64,
    /// `given RP` or the class default.
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
/// prediction; `frame`: the frame fitted to these data (`--refit-frame`), if any;
/// `rp_mm`: the robot's ISO 9283 pose repeatability, else the class default of `nominal`'s
/// reach. `None` when the result has no prediction.
pub(super) fn split(
    nominal: &Robot,
    calibrated: &Robot,
    res: &CalibrationResult,
    set: &MeasurementSet,
    verified_rms_mm: f64,
    frame: Option<&TrackerFrame>,
    rp_mm: Option<f64>,
) -> anyhow::Result<Option<Gap>> {
    let Some(p) = res.prediction.as_ref().filter(|p| p.rms_mm.is_finite()) else {
        return Ok(None);
    };
    let station = match frame {
        Some(f) => station_share(calibrated, f, &observations_of(set)?),
        None => None,
    };
    let (repeatability_mm, repeatability_source) = match rp_mm {
        Some(rp) => (rms_of_rp(rp), format!("RP {rp} mm, given")),
        None => {
            let m = RepeatabilityModel::default_for(nominal);
            let qs = set.rows.iter().map(|r| r.q.as_slice());
            (
                repeatability_rms(nominal, qs, &m.std_deg),
                "the class default".to_owned(),
            )
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

/// Prints the split.
pub(super) fn print(g: &Gap) -> anyhow::Result<()> {
    outln!(
        "the gap to the prediction, in quadrature (RMS error norm): verification {:.4} mm, \
         predicted {:.4} mm, gap {:.4} mm, of which",
        g.verified_rms_mm,
        g.predicted_rms_mm,
        g.total_mm()
    )?;
    if let Some(s) = &g.station {
        outln!(
            "  {:.4} mm  the fresh station's registration ({} points, residual {:.4} mm per axis: \
             sigma sqrt(6/n))",
            s.rms_mm,
            s.points,
            s.residual_sigma_mm
        )?;
    }
    outln!(
        "  {:.4} mm  left: the conditions the model lacks or that changed since the calibration \
         (temperature, approach directions, load, ...)",
        g.left_mm()
    )?;
    outln!(
        "repeatability ({}): {:.4} mm RMS at these poses, inside the prediction's noise ({:.4} mm \
         RMS): the calibration's residuals hold it",
        g.repeatability_source,
        g.repeatability_mm,
        g.predicted_noise_mm
    )?;
    Ok(())
}
