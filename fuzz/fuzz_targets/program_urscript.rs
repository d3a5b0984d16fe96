//! Fuzzes the URScript program reader of `compensate --program X.script`: any text must give a
//! compensated script or an error, never a panic (see `programs_common.rs`).
#![no_main]
use libfuzzer_sys::fuzz_target;
#[path = "programs_common.rs"]
mod common;
use common::check_program;
use robocal_core::programs::Format;

fuzz_target!(|data: &[u8]| {
    check_program(Format::UrScript, data, &["fuzz.script"]);
});
