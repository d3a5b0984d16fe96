//! robocal's Python face: the `robocal._robocal` extension module behind the `robocal` Python
//! package (`python/robocal`), built by maturin (`pyproject.toml`).
//!
//! numpy arrays in and out; the work is robocal-core's own functions, called as the CLI calls
//! them, so Python and the CLI give the same numbers. Library errors become Python exceptions
//! (`errors`) with the library's messages, the settings named as this module's keyword
//! arguments.

mod args;
mod arrays;
mod calibrate;
mod compensate;
mod constraint_model;
mod constraints;
mod errors;
mod evaluate;
mod import;
mod iso9283;
mod options;
mod plan;
mod plan_constraints;
mod result;
mod robot;
mod simulate;
mod simulation;
mod written;

use pyo3::prelude::*;

/// The extension module.
#[pymodule]
fn _robocal(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<robot::PyRobot>()?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate::calibrate_files, m)?)?;
    m.add_function(wrap_pyfunction!(constraints::is_constraint_file, m)?)?;
    m.add_function(wrap_pyfunction!(constraints::calibrate_constraint_file, m)?)?;
    m.add_function(wrap_pyfunction!(
        constraints::calibrate_constraint_arrays,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(
        plan_constraints::plan_constraint_configurations,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(constraints::simulate_constraints, m)?)?;
    m.add_function(wrap_pyfunction!(
        constraint_model::calibrate_constraint_file_model,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate_arrays, m)?)?;
    m.add_function(wrap_pyfunction!(compensate::compensate_arrays, m)?)?;
    m.add_class::<simulation::PySimulation>()?;
    m.add_function(wrap_pyfunction!(simulate::simulate_session, m)?)?;
    m.add_class::<plan::PyPlan>()?;
    m.add_class::<plan::PyQuality>()?;
    m.add_function(wrap_pyfunction!(plan::plan_poses, m)?)?;
    m.add_function(wrap_pyfunction!(result::parse_result, m)?)?;
    m.add_function(wrap_pyfunction!(result::read_result, m)?)?;
    m.add_function(wrap_pyfunction!(result::write_result, m)?)?;
    m.add_function(wrap_pyfunction!(result::result_robots, m)?)?;
    m.add_function(wrap_pyfunction!(import::import_measurements, m)?)?;
    m.add_class::<iso9283::PyIsoPlan>()?;
    m.add_function(wrap_pyfunction!(iso9283::iso9283_plan, m)?)?;
    m.add_function(wrap_pyfunction!(iso9283::iso9283_evaluate, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
