//! Fuzzes robocal import's `text` points parser: any bytes give points or an error, never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
#[path = "points_common.rs"]
mod common;
use robocal_core::io::import::PointsFormat;

fuzz_target!(|data: &[u8]| common::check_points(PointsFormat::Text, data));
