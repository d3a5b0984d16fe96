//! Reading a robot: a built-in preset by name, or a TOML robot description from a file (parsed
//! by [`crate::model::robot_file::parse_robot_toml`]).

use crate::error::Result;
use crate::io::input::read_text;
use crate::model::robot_file::parse_robot_toml;
use crate::model::{presets, Robot};
use std::path::Path;

/// Loads a robot named by a preset name, or the path of a TOML robot file (the `--robot
/// NAME|FILE` argument).
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
    let text = read_text(path)?;
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
