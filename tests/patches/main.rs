//! Curved patches and STEP models: the patch evaluator against tessellations and closed forms,
//! seams, the teapot, STEP fixtures and models.
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/patch_points.rs"]
mod patch_points;

mod fuzz_corpus_curved;
mod patches;
mod patches_props;
mod patches_seams;
mod patches_teapot;
mod step_fixtures;
mod step_models;
