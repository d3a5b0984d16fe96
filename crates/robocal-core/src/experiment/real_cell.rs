//! The honest cell of the experiment: the paper's cell with what a real cell adds (backlash,
//! thermal growth of an arm warming up) and a verification measured later, warm, from a tracker
//! set up anew. Its geometric calibration verifies well above its prediction, as the paper's
//! did; a model with the backlash and thermal families closes most of the gap.

use super::ExperimentConfig;
use crate::error::Result;
use crate::io::MeasurementSet;
use crate::kinematics::Conditions;
use crate::model::family::{backlash, thermal};
use crate::model::Robot;
use crate::simulation::{
    direction_column, BacklashModel, RepeatabilityModel, SimulationConfig, ThermalModel,
};

/// When the verification starts on the warm-up curve (s since the arm started working): a
/// later session of the same day, four hours in, the arm warm (within 0.3 K of its plateau
/// with the KR 480's one-hour time constant).
pub const VERIFICATION_START_S: f64 = 4.0 * 3600.0;

/// The real cell's verification settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RealCell {
    /// The tracker station the verification is measured from (see
    /// [`crate::simulation::station_frame`]); its frame is registered again.
    pub verification_station: u32,
    /// Where on the warm-up curve the verification starts (s).
    pub verification_start_s: f64,
}

impl ExperimentConfig {
    /// The paper's experiment ([`ExperimentConfig::paper`]) in an honest cell: the KR 480's
    /// class defaults of repeatability ([`RepeatabilityModel::default_for`], in both sessions),
    /// backlash ([`BacklashModel::for_robot`]) and thermal growth ([`ThermalModel::for_robot`],
    /// from cold), every pose of the verification approached from below (`dir1..dirN` = +1 in
    /// the desired joints), measured later in the day, warm ([`VERIFICATION_START_S`]), from
    /// tracker station 1.
    pub fn honest(seed: u64) -> Result<ExperimentConfig> {
        let mut c = ExperimentConfig::paper(seed)?;
        let thermal = ThermalModel::for_robot(&c.nominal);
        c.session.repeatability = Some(RepeatabilityModel::default_for(&c.nominal));
        c.session.backlash = Some(BacklashModel::for_robot(&c.nominal));
        c.session.thermal = Some(thermal);
        c.real_cell = Some(RealCell {
            verification_station: 1,
            verification_start_s: VERIFICATION_START_S,
        });
        Ok(c)
    }

    /// The same experiment calibrated with the families of the real cell: backlash on every
    /// joint and thermal expansion (referred to the calibration data's mean temperature when
    /// the experiment runs).
    pub fn with_real_cell_families(&self) -> Result<ExperimentConfig> {
        let mut c = self.clone();
        let all: Vec<usize> = (0..c.nominal.dof()).collect();
        backlash::enable(&mut c.nominal, &all)?;
        thermal::enable(&mut c.nominal, thermal::DEFAULT_REFERENCE_C)?;
        Ok(c)
    }
}

/// The verification session of a real cell: another station, later on the warm-up curve.
pub(super) fn verification_session(
    c: &ExperimentConfig,
    mut s: SimulationConfig,
) -> SimulationConfig {
    if let Some(r) = &c.real_cell {
        s.station = r.verification_station;
        if let Some(t) = &mut s.thermal {
            t.start_s = r.verification_start_s;
        }
    }
    s
}

/// Marks every desired pose as approached from below (`dir1..dirN` = +1) when the cell has
/// backlash: the verification program approaches each pose from that side.
pub(super) fn approach_from_below(c: &ExperimentConfig, set: &mut MeasurementSet) {
    if c.session.backlash.is_none() {
        return;
    }
    for j in 0..set.dof() {
        set.extra_columns.push(direction_column(j));
    }
    for r in &mut set.rows {
        r.extra
            .extend((0..set.joints.dof()).map(|_| "1".to_owned()));
    }
}

/// The conditions the compensation assumes: the arm's temperature when the verification starts
/// (what a sensor reads before the program runs) and every joint approached from below.
pub(super) fn compensation_conditions(c: &ExperimentConfig) -> Conditions {
    let mut out = Conditions::UNKNOWN;
    if let (Some(t), Some(r)) = (&c.session.thermal, &c.real_cell) {
        let at = ThermalModel {
            start_s: r.verification_start_s,
            ..t.clone()
        };
        out.temperature_c = at.temperature_c(0.0);
    }
    if c.session.backlash.is_some() {
        out.dir = [1; crate::model::MAX_JOINTS];
    }
    out
}

/// `model` with its thermal reference at the calibration rows' mean temperature, when it has
/// the family.
pub(super) fn refer_to_data(
    model: &Robot,
    data: &crate::identification::SplitData,
) -> Result<Robot> {
    let mut m = model.clone();
    if thermal::reference_c(&m).is_some() {
        let cd = crate::identification::CalibrationData {
            calibration: &data.calibration,
            plane: None,
            validation: None,
        };
        if let Some(t) = crate::identification::selection::reference_temperature_c(&cd) {
            thermal::set_reference_c(&mut m, t)?;
        }
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::{run_experiment, Experiment};
    use crate::model::family::compliance;

    /// The noise floor of the validation points: the mean distance between their readings and
    /// the exact ones (what the true model itself would show).
    fn floor(e: &Experiment) -> f64 {
        let m = &e.session.measurements;
        let k = m.extra_columns.iter().position(|c| c == "set").unwrap();
        let d: Vec<f64> = m
            .rows
            .iter()
            .zip(&e.session.exact)
            .filter(|(r, _)| r.extra[k] == "validation")
            .map(|(r, x)| (r.p.unwrap() - x).norm())
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    }

    fn ratio(e: &Experiment) -> f64 {
        e.verified().mean_mm / e.predicted().mean_mm
    }

    /// Verification against the result's own prediction for new poses.
    fn ratio_to_prediction(e: &Experiment) -> f64 {
        e.verified().mean_mm / e.result.prediction.as_ref().unwrap().mean_mm
    }

    fn validation(e: &Experiment) -> f64 {
        e.result.errors.validation.unwrap().after.mean_mm
    }

    #[test]
    fn the_honest_cell_verifies_above_its_prediction_and_the_families_close_the_gap() {
        let honest = ExperimentConfig::honest(1).unwrap();
        let geo = run_experiment(honest.clone(), &()).unwrap();
        let mut fam_cfg = honest.with_real_cell_families().unwrap();
        let joints = compliance::auto_joints(&fam_cfg.nominal);
        compliance::enable(&mut fam_cfg.nominal, &joints, Some(300.0)).unwrap();
        let fam = run_experiment(fam_cfg, &()).unwrap();
        let ideal = run_experiment(ExperimentConfig::paper(1).unwrap(), &()).unwrap();
        eprintln!(
            "ideal: verified {:.4} predicted {:.4} ratio {:.3}",
            ideal.verified().mean_mm,
            ideal.predicted().mean_mm,
            ratio(&ideal)
        );
        for (name, e) in [("geometric", &geo), ("families", &fam)] {
            eprintln!(
                "{name}: verified {:.4} predicted {:.4} ratio {:.3} (to the result's prediction \
                 {:.4}: {:.3}); validation {:.4}, floor {:.4}",
                e.verified().mean_mm,
                e.predicted().mean_mm,
                ratio(e),
                e.result.prediction.as_ref().unwrap().mean_mm,
                ratio_to_prediction(e),
                validation(e),
                floor(e)
            );
        }
        // The geometric calibration verifies well above its prediction at new poses (the
        // paper: +68% above Table IV, +21% above its validation at new poses).
        assert!(
            ratio_to_prediction(&geo) >= 1.3,
            "geometric {}",
            ratio_to_prediction(&geo)
        );
        // The families verify within 15% of the calibration's prediction at new poses.
        assert!(
            ratio_to_prediction(&fam) <= 1.15,
            "families {}",
            ratio_to_prediction(&fam)
        );
        // The families close most of the gap: a fifth of the geometric verification error,
        // validation within 1.3 times the tracker's noise floor.
        assert!(fam.verified().mean_mm < 0.25 * geo.verified().mean_mm);
        assert!(validation(&fam) <= 1.3 * floor(&fam));
    }

    /// The mean distance between the verification's readings and the exact positions: its
    /// tracker's noise, from its own station.
    fn verification_floor(e: &Experiment) -> f64 {
        let d: Vec<f64> = e
            .verify
            .rows
            .iter()
            .zip(&e.verification.exact)
            .map(|(r, x)| (r.p.unwrap() - x).norm())
            .collect();
        d.iter().sum::<f64>() / d.len() as f64
    }

    /// Over seeds 1..8: the geometric calibration verifies on average at least 1.3 times its
    /// prediction at new poses; the real cell's families verify on average within 15% of
    /// theirs, each seed within 1.5 times (a fresh station farther from the poses reads noisier
    /// than the calibration's tracker did, which no prediction from the calibration can know),
    /// and validate within 1.3 times the true model's floor.
    #[test]
    fn over_seeds_the_families_verify_as_predicted() {
        let (mut geo, mut fam) = (Vec::new(), Vec::new());
        for seed in 1..=8 {
            let honest = ExperimentConfig::honest(seed).unwrap();
            let g = run_experiment(honest.clone(), &()).unwrap();
            let mut cfg = honest.with_real_cell_families().unwrap();
            let joints = compliance::auto_joints(&cfg.nominal);
            compliance::enable(&mut cfg.nominal, &joints, Some(300.0)).unwrap();
            let e = run_experiment(cfg, &()).unwrap();
            let p = e.result.prediction.as_ref().unwrap();
            eprintln!(
                "seed {seed}: geometric verified {:.4} predicted {:.4} ({:.3}); families \
                 verified {:.4} predicted {:.4} ({:.3}); Table IV {:.4} ({:.3}); verification \
                 floor {:.4}; validation {:.4}, floor {:.4}",
                g.verified().mean_mm,
                g.result.prediction.as_ref().unwrap().mean_mm,
                ratio_to_prediction(&g),
                e.verified().mean_mm,
                p.mean_mm,
                ratio_to_prediction(&e),
                e.predicted().mean_mm,
                ratio(&e),
                verification_floor(&e),
                validation(&e),
                floor(&e)
            );
            assert!(
                validation(&e) <= 1.3 * floor(&e),
                "seed {seed}: validation {} vs floor {}",
                validation(&e),
                floor(&e)
            );
            geo.push(ratio_to_prediction(&g));
            fam.push(ratio_to_prediction(&e));
        }
        let mean = |r: &[f64]| r.iter().sum::<f64>() / r.len() as f64;
        let (g, f) = (mean(&geo), mean(&fam));
        eprintln!("mean verification / prediction over 8 seeds: geometric {g:.3}, families {f:.3}");
        assert!(g >= 1.3, "geometric {g}: {geo:?}");
        assert!((0.85..=1.15).contains(&f), "{f}");
        assert!(fam.iter().all(|r| (0.7..1.5).contains(r)), "{fam:?}");
    }
}
