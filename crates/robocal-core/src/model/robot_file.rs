//! TOML robot descriptions and the `--robot NAME|FILE` argument.
//!
//! ```toml
//! name = "ur5"
//! convention = "dh"            # "mdh" (Craig, the paper's Table I) or "dh" (standard)
//! base = [0, 0, 0, 0, 0, 0]    # optional frame vector x, y, z (mm), A, B, C (deg)
//! tool = [0, 0, 31, 0, 0, 0]   # nominal tool vector T0, same units (optional, default zero)
//!
//! [[joints]]                   # one table per joint, base to tip
//! alpha = 90                   # deg
//! d = 89.159                   # mm
//! a = 0                        # mm
//! phi = 0                      # deg, offset added to the joint value (optional, default 0)
//! limits = [-360, 360]         # deg, model joint values (optional, default [-360, 360])
//! beta = 0                     # deg, Hayati tilt (optional; giving it makes beta a parameter)
//! ```

use super::{presets, Convention, JointLimit, Link, Robot};
use crate::error::{Error, Result};
use crate::ranges;
use serde::Deserialize;
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotFile {
    name: Option<String>,
    convention: Spanned<String>,
    base: Option<Spanned<Vec<Spanned<f64>>>>,
    tool: Option<Spanned<Vec<Spanned<f64>>>>,
    joints: Vec<JointEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointEntry {
    alpha: Spanned<f64>,
    d: Spanned<f64>,
    a: Spanned<f64>,
    phi: Option<Spanned<f64>>,
    beta: Option<Spanned<f64>>,
    limits: Option<Spanned<Vec<Spanned<f64>>>>,
}

/// Default joint range (degrees) when a robot file gives none.
pub const DEFAULT_LIMIT_DEG: f64 = 360.0;

fn line_of(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|b| **b == b'\n')
        .count()
        + 1
}

/// Loads `--robot NAME|FILE`: a preset name, or the path of a TOML robot file.
pub fn load_robot(arg: &str) -> Result<Robot> {
    if presets::PRESETS.contains(&arg) {
        return presets::preset(arg);
    }
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") || arg.contains(std::path::MAIN_SEPARATOR) {
        return load_robot_file(path);
    }
    presets::preset(arg)
}

/// Reads a TOML robot description.
pub fn load_robot_file(path: &Path) -> Result<Robot> {
    let text = crate::io::input::read_text(path)?;
    parse_robot_toml(&text, path)
}

/// Parses a TOML robot description; `path` is only used in error messages.
pub fn parse_robot_toml(text: &str, path: &Path) -> Result<Robot> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let file: RobotFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map(|s| line_of(text, s.start));
        let field = e.span().and_then(|s| {
            let start = text.get(..s.start)?.rfind('\n').map_or(0, |p| p + 1);
            let end = text[s.start..]
                .find('\n')
                .map_or(text.len(), |p| s.start + p);
            let l = &text[start..end];
            l.split_once('=')
                .map(|(k, _)| k.trim().to_owned())
                .filter(|k| !k.is_empty() && !k.starts_with('['))
        });
        Error::Parse {
            path: path.to_owned(),
            line,
            field,
            message: e.message().trim().to_owned(),
        }
    })?;
    let err = |span: std::ops::Range<usize>, field: String, msg: String| Error::Parse {
        path: path.to_owned(),
        line: Some(line_of(text, span.start)),
        field: Some(field),
        message: msg,
    };
    // Every number must be finite and within the plausible range of its kind (crate::ranges).
    let value = |v: &Spanned<f64>, field: String, range: &ranges::Range| -> Result<f64> {
        range
            .check(*v.get_ref())
            .map_err(|msg| err(v.span(), field, msg))
    };
    let length = |v: &Spanned<f64>, field: String| value(v, field, &ranges::LENGTH);
    let angle = |v: &Spanned<f64>, field: String| value(v, field, &ranges::ANGLE);
    let convention = match file.convention.get_ref().as_str() {
        "mdh" => Convention::Mdh,
        "dh" => Convention::Dh,
        other => {
            return Err(err(
                file.convention.span(),
                "convention".into(),
                format!("`{other}` is not a convention: use \"mdh\" (modified DH, Craig) or \"dh\" (standard DH)"),
            ))
        }
    };
    if file.joints.is_empty() {
        return Err(Error::parse(
            path,
            None,
            Some("joints"),
            "no [[joints]] table: a robot needs at least one joint",
        ));
    }
    if file.joints.len() > super::MAX_JOINTS {
        return Err(Error::parse(
            path,
            None,
            Some("joints"),
            format!(
                "{} joints; at most {} are supported",
                file.joints.len(),
                super::MAX_JOINTS
            ),
        ));
    }
    let frame_vec = |v: &Option<Spanned<Vec<Spanned<f64>>>>, name: &str| -> Result<[f64; 6]> {
        let Some(v) = v else { return Ok([0.0; 6]) };
        if v.get_ref().len() != 6 {
            return Err(err(
                v.span(),
                name.into(),
                format!(
                    "expected 6 numbers [x, y, z, A, B, C] (mm, deg), got {}",
                    v.get_ref().len()
                ),
            ));
        }
        let mut out = [0.0; 6];
        for (k, x) in v.get_ref().iter().enumerate() {
            let range = if k < 3 {
                &ranges::LENGTH
            } else {
                &ranges::ANGLE
            };
            out[k] = value(x, format!("{name}[{k}]"), range)?;
        }
        Ok(crate::frame::vec_deg_to_rad(&out))
    };
    let base = frame_vec(&file.base, "base")?;
    let tool0 = frame_vec(&file.tool, "tool")?;
    let mut links = Vec::with_capacity(file.joints.len());
    let mut limits = Vec::with_capacity(file.joints.len());
    let mut betas = Vec::new();
    for (i, j) in file.joints.iter().enumerate() {
        let f = |name: &str| format!("joints[{}].{name}", i + 1);
        let phi = match &j.phi {
            Some(v) => angle(v, f("phi"))?,
            None => 0.0,
        };
        let beta = match &j.beta {
            Some(v) => {
                betas.push(i);
                angle(v, f("beta"))?
            }
            None => 0.0,
        };
        links.push(Link {
            alpha: angle(&j.alpha, f("alpha"))?.to_radians(),
            d: length(&j.d, f("d"))?,
            a: length(&j.a, f("a"))?,
            phi: phi.to_radians(),
            beta: beta.to_radians(),
        });
        let (min, max) = match &j.limits {
            None => (-DEFAULT_LIMIT_DEG, DEFAULT_LIMIT_DEG),
            Some(l) => {
                if l.get_ref().len() != 2 {
                    return Err(err(
                        l.span(),
                        f("limits"),
                        format!(
                            "expected [min, max] in degrees, got {} numbers",
                            l.get_ref().len()
                        ),
                    ));
                }
                let min = value(&l.get_ref()[0], f("limits"), &ranges::JOINT)?;
                let max = value(&l.get_ref()[1], f("limits"), &ranges::JOINT)?;
                if min > max {
                    return Err(err(
                        l.span(),
                        f("limits"),
                        format!("min {min} deg is greater than max {max} deg"),
                    ));
                }
                (min, max)
            }
        };
        limits.push(JointLimit {
            min: min.to_radians(),
            max: max.to_radians(),
        });
    }
    let name = file.name.unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "robot".into())
    });
    let mut robot = Robot::new(name, convention, links, limits, base, tool0)
        .map_err(|e| Error::parse(path, None, None, e.to_string()))?;
    for i in betas {
        robot.enable_beta(i)?;
    }
    Ok(robot)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
name = "two"
convention = "dh"
tool = [0, 0, 10, 0, 0, 0]
[[joints]]
alpha = 90
d = 100
a = 0
[[joints]]
alpha = 0
d = 0
a = 300
limits = [-90, 90]
beta = 0
"#;

    fn parse(s: &str) -> Result<Robot> {
        parse_robot_toml(s, Path::new("robot.toml"))
    }

    #[test]
    fn parses_good_file() {
        let r = parse(GOOD).unwrap();
        assert_eq!(r.dof(), 2);
        assert_eq!(r.name(), "two");
        assert!(r.beta_enabled(1));
        assert!(!r.beta_enabled(0));
        assert!((r.limits()[1].max - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert_eq!(r.param_count(), 4 * 2 + 1 + 12);
    }

    fn expect_err(s: &str, needles: &[&str]) {
        let e = parse(s).expect_err("must fail").to_string();
        assert!(e.starts_with("robot.toml"), "{e}");
        for n in needles {
            assert!(e.contains(n), "`{e}` lacks `{n}`");
        }
    }

    #[test]
    fn missing_field() {
        expect_err(
            &GOOD.replace("d = 100\n", ""),
            &["missing field `d`", "robot.toml:"],
        );
    }

    #[test]
    fn wrong_type() {
        expect_err(
            &GOOD.replace("d = 100", "d = \"abc\""),
            &[":7", "field `d`", "invalid type"],
        );
    }

    #[test]
    fn nan_value() {
        expect_err(
            &GOOD.replace("a = 300", "a = nan"),
            &[":12", "joints[2].a", "not a finite"],
        );
    }

    #[test]
    fn absurd_magnitudes() {
        expect_err(
            &GOOD.replace("a = 300", "a = 1e300"),
            &[
                ":12",
                "field `joints[2].a`",
                "1e300 mm is out of range",
                "±1e6 mm",
            ],
        );
        expect_err(
            &GOOD.replace("alpha = 90", "alpha = 1e5"),
            &[":6", "field `joints[1].alpha`", "1e5 deg is out of range"],
        );
        expect_err(
            &GOOD.replace("[-90, 90]", "[-90, 2e5]"),
            &[
                ":13",
                "field `joints[2].limits`",
                "a joint value must be within ±1e5 deg",
            ],
        );
        expect_err(
            &GOOD.replace("[0, 0, 10, 0, 0, 0]", "[0, 0, 10, 0, -1e9, 0]"),
            &[":4", "field `tool[4]`", "-1e9 deg is out of range"],
        );
        expect_err(
            &format!("base = [2e6, 0, 0, 0, 0, 0]\n{GOOD}"),
            &[":1", "field `base[0]`", "2000000 mm is out of range"],
        );
        // Multi-turn axes are fine.
        parse(&GOOD.replace("[-90, 90]", "[-3600, 3600]")).unwrap();
    }

    #[test]
    fn limits_min_above_max() {
        expect_err(
            &GOOD.replace("[-90, 90]", "[90, -90]"),
            &[":13", "joints[2].limits", "greater than max"],
        );
    }

    #[test]
    fn unknown_field_and_convention() {
        expect_err(
            &GOOD.replace("beta = 0", "bta = 0"),
            &["unknown field `bta`"],
        );
        expect_err(&GOOD.replace("\"dh\"", "\"xyz\""), &["convention", "`xyz`"]);
    }

    #[test]
    fn bad_frame_vector_length() {
        expect_err(
            &GOOD.replace("[0, 0, 10, 0, 0, 0]", "[0, 0, 10]"),
            &["tool", "6 numbers"],
        );
    }

    #[test]
    fn no_joints() {
        expect_err("convention = \"mdh\"\njoints = []\n", &["joints"]);
    }

    #[test]
    fn unknown_preset() {
        let e = load_robot("kuka-kr999").err().unwrap().to_string();
        assert!(e.contains("unknown robot preset `kuka-kr999`"), "{e}");
        assert!(e.contains("kuka-kr480-r3330"), "{e}");
    }

    #[test]
    fn missing_file() {
        let e = load_robot("no/such/robot.toml").err().unwrap().to_string();
        assert!(e.contains("no/such/robot.toml"), "{e}");
    }
}
