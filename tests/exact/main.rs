//! Exact evaluation: the kernel and the exact evaluator against closed forms, the direct sum and
//! the rational oracle (bit identity, input bits, agreement), the `Evaluator` interface, grids,
//! gradients and the testing kit.
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/mod.rs"]
mod common;

mod agreement;
mod beside_edge;
mod boundary_hierarchy;
mod closed_form;
mod evaluator;
mod exactness;
mod gradient;
mod grid;
mod input_bits;
mod parity;
mod testing_kit;
