//! The approximate evaluators: fast (Barnes–Hut) for meshes and point clouds, and 2D Gaussian-
//! smoothed winding numbers of polygons and curves (SVG).
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/mod.rs"]
mod common;

mod curve2d;
mod curve2d_open;
mod curve2d_svg;
mod fast;
mod fast_build;
mod fast_vs_libigl;
