//! Fuzz target: arbitrary bytes through every mesh loader (and the points loader); must never
//! panic. Run from `fuzz/`: `cargo fuzz run --sanitizer none load_mesh`.

#![no_main]

use libfuzzer_sys::fuzz_target;

include!("load_mesh_check.rs");

fuzz_target!(|data: &[u8]| check_load_mesh(data));
