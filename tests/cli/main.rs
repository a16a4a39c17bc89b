//! The `gwn` binary: methods and options per job, `info`, `gen`, `curve`, weld and tolerance
//! options, exit codes and messages on bad input.
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/cli.rs"]
mod cli;
#[path = "../common/mod.rs"]
mod common;

mod cli_reliability;
mod cli_tolerance;
mod cli_weld;
mod curve;
mod curve2d_cli;
mod generate;
mod info;
mod methods;
mod patch_tolerance;
mod readme;
