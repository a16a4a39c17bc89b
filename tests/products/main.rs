//! Products: slices, voxels, signed distance, tet filtering, face classification, labelling, and
//! bounded work on hostile input (library and CLI).
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/cli.rs"]
mod cli;
#[path = "../common/mod.rs"]
mod common;

mod bounded_work;
mod label;
mod products;
mod remesh;
mod remesh_cli;
mod remesh_coplanar;
mod remesh_cut;
mod remesh_dataset;
mod remesh_keep;
mod remesh_levels;
mod remesh_planar;
mod remesh_reorient;
mod remesh_report;
mod remesh_separate;
mod remesh_simplify;
mod remesh_sub_cell;
