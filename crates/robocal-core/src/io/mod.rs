//! File formats: measurement CSV, atomic output, calibration results, robot files.

pub mod atomic;
pub mod claims;
pub(crate) mod columns;
pub(crate) mod csv_lines;
pub(crate) mod csv_reader;
pub(crate) mod csv_text;
pub mod export;
pub mod import;
pub mod input;
pub mod inputs;
pub mod joint_limits;
pub mod json_keys;
pub mod measurements;
mod measurements_write;
mod open_temporaries;
mod plain_decimal;
pub mod result;
pub mod result_cell;
pub mod result_constraint;
mod result_format;
mod result_key_order;
pub mod result_payload;
pub mod result_plausibility;
pub mod result_prediction;
pub mod result_robot;
pub mod result_sections;
pub mod result_selection;
mod result_skim;
pub mod result_thermal;
pub mod robot;
pub mod row_conditions;
pub mod row_extras;
pub mod set_label;
mod target;
mod temporaries;

pub use atomic::{
    commit_all, remove_temporaries, resolve_output, write_all_atomic, write_atomic, AtomicFile,
};
pub use claims::claim_outputs;
pub use measurements::{
    parse_measurements, read_measurements, write_measurements, Measurement, MeasurementReader,
    MeasurementSet, Positions,
};
pub use result::CalibrationResult;
pub use set_label::SetLabel;
