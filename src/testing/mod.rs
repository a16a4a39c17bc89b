//! A testing kit for downstream users: degenerate-mesh generators, an exact inside/outside
//! oracle, and writers for language-neutral corpora (`gwn gen`). See `docs/testing-kit.md`.
//!
//! Compiled with the `testing` feature (which also enables the proptest strategies in
//! `strategies`) or with `testing-kit` (without proptest: seeded generators, oracle and export
//! only; the `gwn` tool's `gwn gen` uses it).
//!
//! - **Generators** ([`Kind`], one [`Case`] = mesh + queries + optional closed-form truth): each
//!   kind is a seeded function (`polycube(seed)`), a byte decoder for cargo-fuzz/arbitrary
//!   (`polycube_from_bytes(&bytes)`) and a proptest strategy (`strategies::polycube()`). Each
//!   kind documents its guarantee on its [`Kind`] variant.
//! - **Exact oracle** ([`exact_winding_number_rational`], [`Oracle`]): big-integer perturbed
//!   predicates written independently of the crate's exact kernel, plus a certified interval for the
//!   boundary term. [`Certified::decide`] is never wrong when it answers; closed consistently
//!   oriented meshes give exact integers.
//! - **The exact evaluator** for bulk use: [`WindingNumber`] (the library's Antipodal
//!   evaluator), via [`exact_evaluator`].
//!
//! | | guarantee | cost |
//! |---|---|---|
//! | [`exact_winding_number_rational`] | interval containing `w(q_ε)`; exact integer on closed meshes; decides inside/outside with certainty whenever it answers | `O(F + B)` big-integer operations per query |
//! | [`WindingNumber`] | exact integer part (χ) on every input; fractional part within ~1e-12 of `w(q_ε)` for dyadic inputs that snap exactly (small integer/dyadic grids with the 60-bit default) | `O(B + log F)` per query, millions per second |

pub mod export;
pub mod generators;
pub mod interval;
pub mod oracle;
pub mod source;
#[cfg(feature = "testing")]
pub mod strategies;

pub use generators::{
    Aabb, Case, Kind, boxes, boxes_from_bytes, fan, fan_from_bytes, inconsistent,
    inconsistent_from_bytes, open, open_from_bytes, polycube, polycube_from_bytes, queries, soup,
    soup_from_bytes, soup_with_tiny_offsets_from_bytes, t_junction, t_junction_from_bytes, tets,
    tets_from_bytes,
};
pub use oracle::{
    Certified, Decision, NARROW_PER_TERM, Oracle, direct_at_perturbed,
    exact_winding_number_integer, exact_winding_number_rational, on_surface, oracle_disagreements,
    ray_disagreements,
};
pub use source::{Source, SplitMix64};

use crate::eval::antipodal::{BuildError, Options, WindingNumber};
use crate::kernel::frame::RayAxis;
/// The fast exact evaluator (re-exported from [`crate::eval::antipodal`]).
use crate::mesh::Mesh;

/// The library's exact evaluator for bulk use (fast next to the oracle), with the 60-bit grid and the given ray: its value is the
/// winding number at the same perturbed point `q_ε` as the oracle's for that ray. Its integer
/// part is exact for every input; its fractional part is accurate to ~1e-12 (not certified).
/// Queries are snapped to the mesh's 60-bit grid first: the kit's dyadic coordinates snap
/// without error.
pub fn exact_evaluator(mesh: &Mesh, ray: RayAxis) -> Result<WindingNumber, BuildError> {
    WindingNumber::with_options(
        mesh,
        Options {
            ray,
            ..Options::default()
        },
    )
}

/// The octahedron's 8 outward faces over the corners `+x, −x, +y, −y, +z, −z` (in that order).
pub const OCTAHEDRON_FACES: [[u32; 3]; 8] = [
    [0, 2, 4],
    [2, 1, 4],
    [1, 3, 4],
    [3, 0, 4],
    [2, 0, 5],
    [1, 2, 5],
    [3, 1, 5],
    [0, 3, 5],
];

/// The unit cube `[0, 1]³` as 12 outward-oriented triangles with the top face (`z = 1`) last:
/// `unit_cube(false)` is closed (`w = 1` inside, 0 outside); `unit_cube(true)` lacks the top face
/// (open, `w = 5/6` at the centre, where the missing face subtends a sixth of the sphere).
pub fn unit_cube(open: bool) -> Mesh {
    const V: [[f64; 3]; 8] = [
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    const T: [[u32; 3]; 12] = [
        [0, 2, 1],
        [0, 3, 2],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
        [4, 5, 6],
        [4, 6, 7],
    ];
    let n = if open { 10 } else { 12 };
    Mesh::from_slices(&V, &T[..n]).expect("valid by construction")
}
