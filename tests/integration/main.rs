//! robocal's integration tests: one test binary (built and linked once), one runner and fixtures
//! made once per run, in the manner of ripgrep's `tests/`.
//!
//! Adding tests: put them in a module here, not in a new `tests/*.rs` (each of those is a binary
//! of its own that links the whole CLI again).
//! 1. Write `tests/integration/NAME.rs` (a file of the old layout: `git mv tests/NAME.rs
//!    tests/integration/`) and declare it below with `mod NAME;`.
//! 2. Start it with `use crate::util::*;` and run robocal through the one runner: `robocal(&args)`
//!    gives a [`util::Outcome`] (`.stdout()`, `.stderr()`, `.code()`, `.assert_ok()`,
//!    `.assert_code(c)`, which print the command and both streams when they fail); `ok(&args)`
//!    runs and asserts success. Drop the file's own `robocal()`/`stdout()`/`stderr()`/`p()`
//!    helpers, `tempfile::tempdir()` becomes [`util::Dir::new`].
//! 3. Data sets or results another module already makes are in [`util::fixtures`] (made once,
//!    read-only: copy a file into your `Dir` before changing it); add one there when two tests
//!    would run the same `simulate` or `calibrate`.
//!
//! Run one module with `cargo test --release --test integration cli_calibrate::`.

mod util;

mod cli_bad_input;
mod cli_bad_input_accepted;
mod cli_bad_input_numerical;
mod cli_bad_input_paths;
mod cli_calibrate;
mod cli_compensate;
mod cli_compensate_pose;
mod cli_compliance;
mod cli_constraint_families;
mod cli_constraint_mixed;
mod cli_constraint_plan;
mod cli_constraint_readers;
mod cli_constraints;
mod cli_demo;
mod cli_evaluate;
mod cli_import;
mod cli_import_limits;
mod cli_interrupted;
mod cli_iso9283;
mod cli_iso9283_plan;
mod cli_joints;
mod cli_model_screen;
mod cli_plan;
mod cli_programs;
mod cli_programs_uses;
mod cli_real_cell;
mod cli_report;
mod cli_result_self_contained;
mod cli_robot;
mod cli_settings;
mod cli_shell;
mod cli_simulate;
mod cli_stations;
mod cli_streams;
#[cfg(unix)]
mod cli_trust_files;
mod cli_trust_fits;
mod cli_trust_gate;
mod cli_trust_readers;
mod cli_urdf;
mod python_bindings;
mod readme_commands;
mod readme_figures;
mod report_browser;
