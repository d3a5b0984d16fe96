//! The "true" robot of a virtual cell: a given robot (preset, file or an earlier truth file), or
//! the nominal robot with seeded random geometric errors.

use crate::error::{Error, Result};
use crate::model::{Param, Robot, Unit};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Sizes of the random geometric errors of a `random` truth robot.
///
/// Every parameter of the nominal robot gets independent Gaussian noise: lengths (`d`, `a`,
/// `base_x/y/z`, `tool_x/y/z`) with standard deviation `length_sigma_mm`, angles (`alpha`, `phi`,
/// `beta`, `base_a/b/c`, `tool_a/b/c`) with `angle_sigma_deg`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GeometricErrors {
    /// Standard deviation of the length errors (mm).
    pub length_sigma_mm: f64,
    /// Standard deviation of the angle errors (degrees).
    pub angle_sigma_deg: f64,
    /// Also give the truth robot a Hayati tilt `beta` on every joint whose axis is nominally
    /// parallel to the previous one (the parameter modified DH lacks, DESIGN.md): the nominal
    /// model then cannot represent the truth exactly, as with a real robot.
    #[serde(default)]
    pub tilt_parallel_axes: bool,
}

impl Default for GeometricErrors {
    /// 0.5 mm and 0.03 degrees: errors of the size of the paper's Table III against Table I.
    fn default() -> Self {
        GeometricErrors {
            length_sigma_mm: 0.5,
            angle_sigma_deg: 0.03,
            tilt_parallel_axes: false,
        }
    }
}

impl GeometricErrors {
    /// Rejects negative or non-finite sigmas.
    pub fn validate(&self) -> Result<()> {
        for (name, v, range) in [
            (
                "truth.length_sigma_mm",
                self.length_sigma_mm,
                &crate::ranges::SIZE_MM,
            ),
            (
                "truth.angle_sigma_deg",
                self.angle_sigma_deg,
                &crate::ranges::SIZE_DEG,
            ),
        ] {
            if !v.is_finite() || v < 0.0 {
                return Err(Error::invalid(
                    name,
                    format!("{v} is not a valid standard deviation (must be >= 0)"),
                ));
            }
            crate::ranges::in_range(name, v, range)?;
        }
        Ok(())
    }

    /// The nominal robot with random errors drawn from `rng` (parameters in [`Robot::params`]
    /// order, so the same RNG state gives the same robot).
    pub fn apply<R: Rng + ?Sized>(&self, nominal: &Robot, rng: &mut R) -> Result<Robot> {
        self.validate()?;
        let mut r = nominal.clone();
        if self.tilt_parallel_axes {
            r.enable_beta_for_parallel_axes();
        }
        for p in r.params() {
            let sigma = match p.unit() {
                Unit::Mm => self.length_sigma_mm,
                Unit::Deg => self.angle_sigma_deg.to_radians(),
                // Non-geometric coefficients are not geometric errors.
                Unit::MicroradPerNm | Unit::MicroradPerM | Unit::PpmPerK => 0.0,
            };
            let z: f64 = StandardNormal.sample(rng);
            r.set(p, r.get(p) + sigma * z);
        }
        r.set_name(format!("{} with random errors", nominal.name()));
        Ok(r)
    }
}

/// Where the true robot comes from.
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)] // built once per session; boxing would only burden callers
pub enum TruthSpec {
    /// A given robot (a preset such as `kuka-kr480-r3330-table3`, a robot file, or the robot of
    /// an earlier truth file).
    Robot(Robot),
    /// The nominal robot with seeded random geometric errors.
    Random(GeometricErrors),
}

impl TruthSpec {
    /// A short description for the truth file: the robot's name, or `random`.
    pub fn label(&self) -> String {
        match self {
            TruthSpec::Robot(r) => r.name().to_owned(),
            TruthSpec::Random(_) => "random".to_owned(),
        }
    }
}

/// Checks that a truth robot can stand for the nominal one: same joint count, convention and
/// joint types (the joint values commanded on the nominal model drive the truth robot).
pub fn check_truth_matches(nominal: &Robot, truth: &Robot) -> Result<()> {
    if truth.dof() != nominal.dof() {
        return Err(Error::invalid(
            "truth",
            format!(
                "truth robot `{}` has {} joints, the nominal robot `{}` has {}",
                truth.name(),
                truth.dof(),
                nominal.name(),
                nominal.dof()
            ),
        ));
    }
    if truth.convention() != nominal.convention() {
        return Err(Error::invalid(
            "truth",
            format!(
                "truth robot `{}` uses {} parameters, the nominal robot `{}` uses {}",
                truth.name(),
                truth.convention().as_str(),
                nominal.name(),
                nominal.convention().as_str()
            ),
        ));
    }
    if truth.joint_types() != nominal.joint_types() {
        let list = |r: &Robot| {
            r.joint_types()
                .iter()
                .map(|t| t.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        return Err(Error::invalid(
            "truth",
            format!(
                "truth robot `{}` has joints {}, the nominal robot `{}` has {}",
                truth.name(),
                list(truth),
                nominal.name(),
                list(nominal)
            ),
        ));
    }
    Ok(())
}

/// The parameters in which two robots of the same shape differ, with the difference
/// `truth - nominal` in display units (mm or deg). Parameters only the truth has (e.g. a tilt
/// `beta`) are compared with zero.
pub fn parameter_differences(nominal: &Robot, truth: &Robot) -> Vec<(Param, f64)> {
    truth
        .params()
        .into_iter()
        .map(|p| (p, truth.get_display(p) - nominal.get_display_or_zero(p)))
        .filter(|(_, d)| *d != 0.0)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;
    use rand::SeedableRng;

    #[test]
    fn random_errors_have_the_requested_size() {
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let e = GeometricErrors {
            length_sigma_mm: 0.4,
            angle_sigma_deg: 0.02,
            tilt_parallel_axes: false,
        };
        let mut lengths = Vec::new();
        let mut angles = Vec::new();
        for seed in 0..200 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let t = e.apply(&nominal, &mut rng).unwrap();
            for (p, d) in parameter_differences(&nominal, &t) {
                match p.unit() {
                    Unit::Mm => lengths.push(d),
                    Unit::Deg => angles.push(d),
                    _ => {}
                }
            }
        }
        let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        // 18 length and 18 angle parameters per robot, 200 robots: 3600 samples each.
        assert_eq!(lengths.len(), 3600);
        assert_eq!(angles.len(), 3600);
        assert!(
            (rms(&lengths) / 0.4 - 1.0).abs() < 0.05,
            "{}",
            rms(&lengths)
        );
        assert!((rms(&angles) / 0.02 - 1.0).abs() < 0.05, "{}", rms(&angles));
    }

    #[test]
    fn tilt_adds_beta_on_parallel_axes() {
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let e = GeometricErrors {
            tilt_parallel_axes: true,
            ..GeometricErrors::default()
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let t = e.apply(&nominal, &mut rng).unwrap();
        assert!(t.beta_enabled(2), "axes 2 and 3 are parallel");
        assert_ne!(t.get(Param::beta(2)), 0.0);
        assert_eq!(t.param_count(), 37);
        check_truth_matches(&nominal, &t).unwrap();
    }

    #[test]
    fn rejects_bad_sigmas_and_other_shapes() {
        let e = GeometricErrors {
            length_sigma_mm: -1.0,
            ..GeometricErrors::default()
        };
        let msg = e.validate().unwrap_err().to_string();
        assert!(msg.contains("truth.length_sigma_mm"), "{msg}");
        let kr = preset("kuka-kr480-r3330").unwrap();
        let ur5 = crate::model::robot_file::parse_robot_toml(
            "convention = \"mdh\"\n[[joints]]\nalpha = 0\nd = 0\na = 0\n",
            std::path::Path::new("one.toml"),
        )
        .unwrap();
        let msg = check_truth_matches(&kr, &ur5).unwrap_err().to_string();
        assert!(msg.contains("1 joints") && msg.contains("has 6"), "{msg}");
    }
}
