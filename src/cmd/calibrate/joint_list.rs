//! The joints a joint-family flag names (`--compliance`, `--backlash`): one parser for both.

use crate::exit;
use robocal_core::Robot;

/// A joint-family flag's joints (0-based, sorted, once each): `none` (or absent) none, `auto`
/// those `auto` gives, else a comma list of joint numbers 1..dof.
pub(super) fn joint_list(
    flag: &str,
    arg: Option<&str>,
    robot: &Robot,
    auto: impl FnOnce(&Robot) -> Vec<usize>,
) -> anyhow::Result<Vec<usize>> {
    let list = match arg.unwrap_or("none").trim() {
        "none" | "" => return Ok(Vec::new()),
        "auto" => return Ok(auto(robot)),
        list => list,
    };
    let mut out = Vec::new();
    for part in list.split(',') {
        let j: usize = part.trim().parse().map_err(|_| {
            exit::usage(format!(
                "{flag}: `{part}` is not `auto`, `none` or a joint number"
            ))
        })?;
        if j == 0 || j > robot.dof() {
            return Err(exit::usage(format!(
                "{flag}: joint {j} does not exist (robot `{}` has joints 1..{})",
                robot.name(),
                robot.dof()
            )));
        }
        if !out.contains(&(j - 1)) {
            out.push(j - 1);
        }
    }
    out.sort_unstable();
    Ok(out)
}
