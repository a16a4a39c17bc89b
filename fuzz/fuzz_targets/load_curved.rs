//! Fuzz target: arbitrary bytes through the STEP and Bézier-patch readers and their evaluators;
//! must never panic or hang. Run from `fuzz/`: `cargo fuzz run --sanitizer none load_curved`.

#![no_main]

use libfuzzer_sys::fuzz_target;

include!("load_curved_check.rs");

fuzz_target!(|data: &[u8]| check_load_curved(data));
