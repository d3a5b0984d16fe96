//! Measurements from another tracker station: when the tracker moved between the calibration
//! and a validation or verification set, the calibration's tracker frame no longer maps the
//! readings into the base frame, and every error grows by the station's move. A fresh rigid frame
//! fitted to the set under a model (the calibrated one, or the nominal one for its own series)
//! takes the move out; without it, a set that clearly comes from another station is an error,
//! not a 600 mm "inaccuracy".

use crate::error::{Error, Result};
use crate::frame::TrackerFrame;
use crate::io::row_extras::ExtrasLayout;
use crate::io::MeasurementSet;
use crate::model::Robot;
use crate::observations::Observations;
use crate::registration::{another_station, refit_frame, STATION_MIN_MM};

/// The measured rows of `set` (those with x,y,z) as observations, with their targets and
/// orientations.
pub fn observations_of(set: &MeasurementSet) -> Result<Observations> {
    let extras = ExtrasLayout::of(set)?;
    let mut obs = Observations::with_source(set.dof(), &set.path);
    for r in &set.rows {
        let Some(m) = r.p else { continue };
        obs.push_with(&r.q, m, extras.read(set, r)?, r.line)?;
    }
    Ok(obs)
}

/// The frames of a set measured from a station of its own: fitted under `nominal` (for the
/// nominal series) and under `calibrated`.
pub fn station_frames(
    nominal: &Robot,
    calibrated: &Robot,
    set: &MeasurementSet,
) -> Result<(TrackerFrame, TrackerFrame)> {
    let obs = observations_of(set)?;
    obs.check_targets(nominal)?;
    Ok((refit_frame(nominal, &obs)?, refit_frame(calibrated, &obs)?))
}

/// Fails ([`Error::Implausible`], the exit code of `calibrate`'s gate) when the measured points of
/// `set` cannot be of `model`'s robot: the plausibility gate's data checks (units, handedness, the
/// error after the best rigid fit; [`crate::identification::plausibility::assess_data`]), with
/// the likely cause. Free of any tracker frame: a set from another station passes.
pub fn check_data_matches(model: &Robot, set: &MeasurementSet) -> Result<()> {
    let obs = observations_of(set)?;
    if obs.len() < 3 {
        return Ok(());
    }
    let p = crate::identification::plausibility::assess_data(model, &obs);
    if p.implausible() {
        return Err(Error::Implausible(format!(
            "{}: these measurements cannot be of the calibrated robot:\n{}",
            set.path.display(),
            p.summary()
        )));
    }
    Ok(())
}

/// Fails when `set` was clearly measured from another station than the calibration's
/// ([`crate::registration::another_station`]): the calibrated model is off by `mean_mm` on
/// average in the calibration's frame. The message tells the refit setting by its name,
/// `refit_frame`.
pub fn check_station(calibrated: &Robot, set: &MeasurementSet, mean_mm: f64) -> Result<()> {
    if mean_mm <= STATION_MIN_MM {
        return Ok(());
    }
    let obs = observations_of(set)?;
    if let Some(there) = another_station(calibrated, &obs, mean_mm) {
        return Err(Error::invalid(
            set.path.display().to_string(),
            format!(
                "these points look measured from another tracker station: in the calibration's \
                 tracker frame the calibrated model is off by {mean_mm:.3} mm on average, with a \
                 frame of their own by {there:.3} mm. If the tracker moved, let the data fit \
                 their own frame (`refit_frame`); otherwise check that the file belongs to this \
                 calibration"
            ),
        ));
    }
    Ok(())
}
