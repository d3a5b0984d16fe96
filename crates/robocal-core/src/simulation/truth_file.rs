//! The truth file `FILE.truth.json` written beside a simulated measurement file: the true
//! parameters (in the result JSON's `parameters` layout, `calibrated` holding the true value),
//! the true tracker frame, the settings used and what was injected (outliers, gravity).

use super::config::SimulationConfig;
use super::truth::{check_truth_matches, GeometricErrors};
use crate::error::{Error, Result};
use crate::io::result::{FrameVec, ParamEntry, RobotInfo};
use crate::model::{Param, Robot};
use crate::stats::ErrorStats;
use indexmap::IndexMap;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A reading displaced as a gross outlier.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OutlierRecord {
    /// The 1-based line of the row in the measurement file it was written to (header = line 1).
    pub line: usize,
    /// The row's `id`, if the file has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// The row's `set`, if the file has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set: Option<String>,
    /// The displacement added to the reading (mm, tracker frame).
    pub displacement_mm: [f64; 3],
}

/// The content of a truth file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthFile {
    /// What wrote the file (`robocal-core <version>`).
    pub generator: String,
    /// The true robot: name, joint count, convention.
    pub robot: RobotInfo,
    /// The nominal robot's name.
    pub nominal: String,
    /// Where the truth came from: a preset or file name, or `random`.
    pub truth: String,
    /// Every parameter of the true robot: `nominal` from the nominal robot, `calibrated` the
    /// true value (mm or deg). `fixed` is always false.
    pub parameters: IndexMap<String, ParamEntry>,
    /// The true pose of the tracker frame in the base frame: a reading m maps to
    /// `pose(tracker_frame) * m`.
    pub tracker_frame: FrameVec,
    /// The settings used (seed, poses, tracker, noise, gravity, outliers).
    pub settings: SimulationConfig,
    /// The sizes of the random geometric errors (`random` truth only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometric_errors: Option<GeometricErrors>,
    /// The joint file measured (`--joints`), as given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub joints_file: Option<String>,
    /// Rows per `set` (`plane`, `calibration`, `validation`) and the file each went to.
    pub sets: IndexMap<String, SetInfo>,
    /// Height of the plane of the plane points (mm, base frame, nominal model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plane_z_mm: Option<f64>,
    /// The readings displaced as gross outliers.
    pub outliers: Vec<OutlierRecord>,
    /// How far gravity deflection moved the tool points (mm), when enabled.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gravity_effect: Option<ErrorStats>,
    /// Things worth knowing (joint values outside the limits, ...).
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// Where a set of rows was written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetInfo {
    /// Number of rows.
    pub rows: usize,
    /// The file name (without directory) the rows are in.
    pub file: String,
}

impl TruthFile {
    /// The true parameters of `truth` against `nominal`, in the result JSON's layout.
    pub fn parameter_entries(nominal: &Robot, truth: &Robot) -> IndexMap<String, ParamEntry> {
        crate::io::CalibrationResult::parameter_entries(nominal, truth)
    }

    /// Pretty JSON with a final newline.
    pub fn to_json(&self) -> Result<String> {
        let mut s = serde_json::to_string_pretty(self)
            .map_err(|e| Error::Numerical(format!("cannot serialize truth file: {e}")))?;
        s.push('\n');
        Ok(s)
    }

    /// Reads a truth file, naming the file and line on malformed JSON.
    pub fn read(path: &Path) -> Result<TruthFile> {
        let text = crate::io::input::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses truth-file JSON; `path` is used in messages (file, line and field). The true
    /// parameters and the tracker frame must be within their plausible ranges
    /// ([`crate::ranges`]).
    pub fn parse(text: &str, path: &Path) -> Result<TruthFile> {
        let tf: TruthFile = crate::io::input::parse_json(text, path, "robocal truth file")?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        crate::io::result::check_parameters(&tf.parameters, text, path)?;
        crate::io::result::check_frame(&tf.tracker_frame, "tracker_frame", text, path)?;
        Ok(tf)
    }

    /// The true robot: `nominal` with every parameter set to its true value. Fails, naming the
    /// file and field, if the file was made for a robot of another shape or names a parameter
    /// the robot lacks. Tilt parameters (`beta`) in the file are enabled.
    pub fn truth_robot(&self, nominal: &Robot, path: &Path) -> Result<Robot> {
        let bad = |field: &str, msg: String| Error::parse(path, None, Some(field), msg);
        if self.robot.dof != nominal.dof() {
            return Err(bad(
                "robot.dof",
                format!(
                    "truth robot `{}` has {} joints, the nominal robot `{}` has {}",
                    self.robot.name,
                    self.robot.dof,
                    nominal.name(),
                    nominal.dof()
                ),
            ));
        }
        if self.robot.convention != nominal.convention().as_str() {
            return Err(bad(
                "robot.convention",
                format!(
                    "truth robot `{}` uses {} parameters, the nominal robot `{}` uses {}",
                    self.robot.name,
                    self.robot.convention,
                    nominal.name(),
                    nominal.convention().as_str()
                ),
            ));
        }
        self.robot
            .check_joint_types(nominal, path, "the truth robot")?;
        // The file's nominal values must be this robot's: a truth file made for another robot of
        // the same shape would otherwise simulate nonsense.
        for p in nominal.params() {
            let name = p.name();
            let Some(e) = self.parameters.get(&name) else {
                continue;
            };
            let mine = nominal.get_display(p);
            if !e.nominal.is_finite() || (e.nominal - mine).abs() > 1e-6 + 1e-9 * mine.abs() {
                return Err(bad(
                    &format!("parameters.{name}.nominal"),
                    format!(
                        "the truth file was made for a nominal robot (`{}`) with {name} = {} {}, \
                         but robot `{}` has {mine} {}: wrong nominal robot or wrong truth file",
                        self.nominal,
                        e.nominal,
                        e.unit.as_str(),
                        nominal.name(),
                        p.unit().as_str()
                    ),
                ));
            }
        }
        let mut r = nominal.clone();
        r.set_name(self.robot.name.clone());
        for name in self.parameters.keys() {
            if let Some(p) = Param::parse(name) {
                r.enable_param(p)?;
            }
        }
        for (name, e) in &self.parameters {
            let p = r.param_by_name(name).map_err(|_| {
                bad(
                    &format!("parameters.{name}"),
                    format!("not a parameter of robot `{}`", nominal.name()),
                )
            })?;
            if e.unit != p.unit() {
                return Err(bad(
                    &format!("parameters.{name}.unit"),
                    format!("expected {}", p.unit().as_str()),
                ));
            }
            if !e.calibrated.is_finite() {
                return Err(bad(
                    &format!("parameters.{name}.calibrated"),
                    "not a finite number".into(),
                ));
            }
            r.set_display(p, e.calibrated);
        }
        if let Some(p) = r
            .params()
            .into_iter()
            .find(|p| !self.parameters.contains_key(&p.name()))
        {
            return Err(bad("parameters", format!("parameter `{p}` is missing")));
        }
        check_truth_matches(nominal, &r)?;
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::preset;
    use crate::simulation::{simulate, SimulationConfig, TruthSpec};

    fn table3_file() -> TruthFile {
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let truth = TruthSpec::Robot(preset("kuka-kr480-r3330-table3").unwrap());
        let cfg = SimulationConfig {
            poses: 2,
            plane_points: false,
            ..SimulationConfig::default()
        };
        simulate(&nominal, &truth, &cfg, &())
            .unwrap()
            .truth_file(&[])
    }

    #[test]
    fn truth_robot_checks_the_file_against_the_nominal_robot() {
        let nominal = preset("kuka-kr480-r3330").unwrap();
        let p = Path::new("t.truth.json");
        let tf = table3_file();
        let r = tf.truth_robot(&nominal, p).unwrap();
        assert_eq!(r.get_display(Param::d(3)), 1525.997);
        assert_eq!(r.name(), "kuka-kr480-r3330-table3");

        let mut missing = tf.clone();
        missing.parameters.shift_remove("a3");
        let e = missing.truth_robot(&nominal, p).unwrap_err().to_string();
        assert!(
            e.contains("t.truth.json") && e.contains("`a3` is missing"),
            "{e}"
        );

        let mut unknown = tf.clone();
        let entry = unknown.parameters["a3"].clone();
        unknown.parameters.insert("a9".into(), entry);
        let e = unknown.truth_robot(&nominal, p).unwrap_err().to_string();
        assert!(e.contains("parameters.a9"), "{e}");

        let mut conv = tf.clone();
        conv.robot.convention = "dh".into();
        let e = conv.truth_robot(&nominal, p).unwrap_err().to_string();
        assert!(e.contains("robot.convention"), "{e}");

        let mut shifted = tf.clone();
        shifted.parameters.get_mut("a2").unwrap().nominal += 1.0;
        let e = shifted.truth_robot(&nominal, p).unwrap_err().to_string();
        assert!(e.contains("parameters.a2.nominal"), "{e}");

        let mut other = tf.clone();
        other.robot.dof = 7;
        let e = other.truth_robot(&nominal, p).unwrap_err().to_string();
        assert!(e.contains("robot.dof") && e.contains("7 joints"), "{e}");
    }
}
