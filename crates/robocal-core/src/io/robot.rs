//! Reading a robot: a built-in preset by name, a TOML robot description from a file (parsed
//! by [`crate::model::robot_file::parse_robot_toml`]), or the serial chain of a URDF file
//! ([`crate::model::urdf`], chosen with a [`ChainSelection`]).

use crate::error::{Error, Result};
use crate::io::input::read_text;
use crate::model::robot_file::parse_robot_toml;
use crate::model::urdf::{self, ChainSelection};
use crate::model::{presets, Robot};
use std::path::Path;

/// Loads a robot named by a preset name, or the path of a TOML robot file or a URDF file (the
/// `--robot NAME|FILE` argument). A URDF's chain is its only one; see [`load_robot_with`].
pub fn load_robot(arg: &str) -> Result<Robot> {
    load_robot_with(arg, &ChainSelection::default())
}

/// Whether a robot argument names a URDF file: it ends in `.urdf` (any case).
pub fn is_urdf_arg(arg: &str) -> bool {
    Path::new(arg)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
}

/// [`load_robot`] with the chain of a URDF named (settings `base_link`, `tip_link`). Naming
/// links for a preset or a TOML robot file is an error (they have one chain).
pub fn load_robot_with(arg: &str, chain: &ChainSelection) -> Result<Robot> {
    let robot = if presets::PRESETS.contains(&arg) {
        None
    } else {
        let path = Path::new(arg);
        (path.exists()
            || arg.ends_with(".toml")
            || is_urdf_arg(arg)
            || arg.contains(std::path::MAIN_SEPARATOR))
        .then_some(path)
    };
    let Some(path) = robot else {
        if chain.is_given() {
            return Err(links_without_urdf(arg));
        }
        return presets::preset(arg);
    };
    let text = read_text(path)?;
    if is_urdf_arg(arg) || urdf::looks_like_urdf(&text) {
        return urdf::parse_urdf(&text, path, chain);
    }
    if chain.is_given() {
        return Err(links_without_urdf(arg));
    }
    parse_robot_toml(&text, path)
}

fn links_without_urdf(arg: &str) -> Error {
    Error::invalid(
        "base_link",
        format!(
            "`{arg}` is not a URDF file: `base_link` and `tip_link` choose the chain of a URDF \
             robot only"
        ),
    )
}

/// Reads a robot description file: TOML, or a URDF (by its `.urdf` name or its `<` start; its
/// only chain).
pub fn load_robot_file(path: &Path) -> Result<Robot> {
    let text = read_text(path)?;
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("urdf"))
        || urdf::looks_like_urdf(&text)
    {
        return urdf::parse_urdf(&text, path, &ChainSelection::default());
    }
    parse_robot_toml(&text, path)
}

#[cfg(test)]
mod tests {
    use super::*;

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
