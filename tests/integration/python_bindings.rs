//! The Python bindings (issue 17): `crates/robocal-py/ci.sh` builds the `robocal` package into a
//! fresh virtual environment under `target/python-ci` and runs its pytest suite, which compares
//! Python with this CLI (the same binary these tests run) on the real UR5 data and the demo's
//! data, holds `simulate` and `plan` to the CLI's files for the same seed, times FK,
//! calibration, simulation and planning, and feeds the bindings bad input.
//!
//! The script works in this build's target directory (`CARGO_TARGET_DIR`, found from the
//! binary's path), reuses a venv there that has maturin, numpy and pytest, and reaches PyPI only
//! when asked (`ROBOCAL_PY_ONLINE=1`). Skips, saying why (`skipped: ...` in the test output),
//! when python3 or its venv module is missing or those packages are not available (the
//! script's exit status 77); a failed build or test fails.

use crate::util::root;
use std::process::Command;

/// The script's exit status for "skipped" (as automake's).
const SKIPPED: i32 = 77;

#[test]
fn the_python_package_builds_and_its_suite_passes() {
    let script = root().join("crates/robocal-py/ci.sh");
    let mut cmd = Command::new("bash");
    cmd.arg(&script)
        .env("ROBOCAL_BIN", env!("CARGO_BIN_EXE_robocal"))
        .current_dir(root());
    // The target directory of this build: .../target/release/robocal.
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_robocal"));
    if let Some(target) = bin.parent().and_then(|p| p.parent()) {
        cmd.env("CARGO_TARGET_DIR", target);
    }
    // The real data beside the checkout, as `util::real_data` finds it.
    if std::env::var_os("ROBOCAL_REAL_DATA").is_none() {
        cmd.env("ROBOCAL_REAL_DATA", root().join("../shared/data"));
    }
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", script.display()));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => {
            // The suite's figures (FK and calibration times) for the log.
            for l in stdout.lines().filter(|l| {
                l.starts_with("python-ci:") || l.contains(" passed") || l.contains(" ms")
            }) {
                eprintln!("{l}");
            }
        }
        Some(SKIPPED) => {
            eprintln!(
                "skipped: {}",
                stdout.lines().last().unwrap_or("python-ci skipped")
            );
        }
        code => panic!(
            "{} exited with {code:?}\n--- stdout\n{stdout}\n--- stderr\n{stderr}",
            script.display()
        ),
    }
}
