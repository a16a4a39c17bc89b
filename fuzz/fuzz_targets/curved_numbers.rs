//! Fuzz target: the curved fuzz seeds (`corpus/load_curved/`, compiled in) with some of their
//! numbers replaced by arbitrary `f64`s and integers, through the same check as `load_curved`.
//! Byte-level mutations rarely keep a STEP file parseable while changing its geometry; this
//! keeps the structure and moves the numbers, the class of input that found the radius-1e308
//! hang (a radius, a weight, a knot or a degree out of range). Run from `fuzz/`:
//! `cargo fuzz run --sanitizer none curved_numbers -- -timeout=20`.

#![no_main]

use libfuzzer_sys::fuzz_target;

include!("load_curved_check.rs");
include!("curved_numbers_edit.rs");

fuzz_target!(|data: &[u8]| {
    if let Some(input) = edit_curved_seed(data) {
        check_load_curved(&input);
    }
});
