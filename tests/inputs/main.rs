//! Input files: mesh, point-cloud and query loaders (OBJ, OFF, PLY, STL, glTF, CSV, NPY), their
//! strictness on broken and hostile files, the shared corpus manifest and the fuzz corpora.
//!
//! One test binary per area (one optimised link instead of one per file); each file is a module.

#[path = "../common/mod.rs"]
mod common;

mod fuzz_corpus_loaders;
mod gltf;
mod loader_strictness;
mod loaders;
mod manifest;
