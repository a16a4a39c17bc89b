//! What users run on whole fields: slice images ([`png`], [`colormap`]), voxel-grid files
//! ([`npy`], [`vti`]), signed distance ([`sdf`]), inside/outside filtering of tetrahedral meshes
//! ([`tets`]), per-face classification for booleans ([`classify`]), dataset labelling
//! ([`label`], [`npz`]; the per-mesh job machinery in [`dataset`]) and remeshing at `w = ½` ([`remesh`]). The grids themselves are in
//! [`crate::grid`]. See `docs/products.md`.

pub mod classify;
pub mod colormap;
pub mod dataset;
mod json;
pub mod label;
pub mod npy;
pub mod npz;
pub mod png;
pub mod remesh;
pub mod sdf;
pub mod tets;
pub mod vti;
