//! Fuzzes the KUKA KRL program readers of `compensate --program X.src`: the bytes are a `.src`,
//! then (after a 0 byte) its `.dat`, then (after another) a `$config.dat`. Any text must give a
//! compensated program or an error, never a panic; and what comes back must account for the
//! program (one text per file, every target and motion listed, nothing changed where nothing was
//! compensated).
#![no_main]
use libfuzzer_sys::fuzz_target;
#[path = "programs_common.rs"]
mod common;
use common::check_program;
use robocal_core::programs::Format;

fuzz_target!(|data: &[u8]| {
    check_program(Format::Krl, data, &["fuzz.src", "fuzz.dat", "config.dat"]);
});
