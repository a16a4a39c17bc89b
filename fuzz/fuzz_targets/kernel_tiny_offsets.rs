//! Fuzzes the exact kernel at queries a tiny distance from degenerate meshes of the integer grid
//! −4..4 (`gwn::testing::soup_with_tiny_offsets_from_bytes`: offsets `±2^-e` down to the
//! subnormals, next to edges on coordinate planes): off the surface, every ray direction must
//! give the same value, to 1e-10 (`gwn::testing::ray_disagreements`), and on and off it each
//! ray's value must lie within 1e-10 of the rational oracle's narrow interval for that ray
//! (`gwn::testing::oracle_disagreements`). Its corpus is replayed by
//! `cargo test` (`tests/exact/input_bits.rs`). Run:
//! `cargo fuzz run --sanitizer none kernel_tiny_offsets -- -max_total_time=60`.
#![no_main]

use gwn::testing::{oracle_disagreements, ray_disagreements, soup_with_tiny_offsets_from_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some(case) = soup_with_tiny_offsets_from_bytes(data) else {
        return;
    };
    let bad = ray_disagreements(&case.mesh, &case.queries, 1e-10);
    assert!(bad.is_empty(), "{bad:?}");
    let bad = oracle_disagreements(&case.mesh, &case.queries, 1e-10);
    assert!(bad.is_empty(), "the oracle: {bad:?}");
});
