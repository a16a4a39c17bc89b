//! Simplification of the extracted surface by half-edge collapses on the fixed-point vertices.
//!
//! A collapse `u → v` removes the vertex `u` and moves its faces to `v`, which keeps its exact
//! fixed-point position, so the exact predicates of [`super::intersect`] apply unchanged.
//! Collapses run in the order of a quadric error (the area-weighted mean squared distance of `v`
//! to the planes of the faces merged into `u`, plus a small length term so that flat regions
//! collapse short edges first), from a priority queue with lazy invalidation, in rounds: the
//! cheapest vertices whose closed 1-rings have disjoint boxes are planned in parallel and
//! collapsed in cost order ([`Simplifier::run`] says why the plans stay valid). The selection
//! is serial and the round size a constant: the result is the same on every run and for every
//! thread count. Collapses stop at a face target, except those of (near) zero quadric error,
//! which go on past it ([`Simplifier::run_flat`]): a flat region's collapses all cost 0, and the
//! target alone left flat regions as dense as curved ones.
//!
//! Faces are chords of the surface, so a simplified convex part lies inside the input and a
//! concave one outside. After the collapses, [`Simplifier::relocate`] moves each kept vertex
//! towards the minimum of its quadric (the planes of the marching-tetrahedra faces merged into
//! it, or with [`simplify_with_planes`] the input's planes at the merged vertices and their
//! rings), rounded to the fixed-point grid and by at most `max_distance`, where the moved faces
//! pass the same checks (flip, size, distance, intersection); the topology does not change.
//! The input's planes bring vertices back onto sharp edges that the marching-tetrahedra faces
//! cut off (those faces' own planes are chamfers, whose minimum is on the chamfer).
//!
//! A collapse is made only if it keeps every guarantee of the surface; it is refused when
//! - **link** ([`Refusal::Link`]): `u` and `v` have other common neighbours than the two
//!   vertices opposite their edge, or both faces over those two exist (a tetrahedron): the
//!   collapse would pinch the surface or create a duplicate face. Otherwise the collapse of an
//!   edge of a closed 2-manifold leaves a closed 2-manifold of the same topology (Dey, Edelsbrunner
//!   et al., "Topology preserving edge contraction"), and consistently oriented: each moved face
//!   keeps its vertex order;
//! - **flip** ([`Refusal::Flip`]): a moved face `(u, a, b) → (v, a, b)` would be degenerate
//!   (collinear, exact cross product 0) or turn by 90° or more (exact sign of the dot product of
//!   the old and new normals);
//! - **size** ([`Refusal::FaceTooLarge`]): a new face's box would exceed
//!   [`SimplifyOptions::max_face_extent`] cells along an axis (bounds the spatial index's work);
//! - **distance** ([`Refusal::Distance`]): `u`, or a vertex removed earlier into one of `u`'s faces,
//!   would be farther than [`SimplifyOptions::max_distance`] cells from the new faces (computed
//!   in `f64`: a geometric tolerance, not a topological guarantee). Every removed vertex stays
//!   within that distance of the surface, which bounds how far the simplified surface moves from
//!   the marching-tetrahedra one;
//! - **intersection** ([`Refusal::Intersection`]): a new face meets, outside what they share, any
//!   other face of the surface ([`super::intersect::faces_intersect`], exact) whose box overlaps
//!   it, or another new face. The marching-tetrahedra surface has no self-intersection
//!   (`docs/remesh.md`) and no collapse adds one, so neither does the result.
//!
//! The input must be a closed, edge- and vertex-manifold, consistently oriented surface without
//! collinear faces (what [`super::extract`] and [`super::place`] produce); any other input is
//! returned unchanged ([`SimplifyStats::skipped`]).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::intersect::{MAX_COORDINATE, faces_intersect};
use rayon::prelude::*;

use super::lattice::{KeyMap, KeySet};

mod lattice_diagonals;
mod slabs;
use crate::kernel::predicates::cross_exact;

type P = [i64; 3];
type Q = [i32; 3];

/// Default [`SimplifyOptions::max_distance`], in finest cells.
pub const DEFAULT_MAX_DISTANCE: f64 = 0.5;

/// Default [`SimplifyOptions::max_face_extent`], in finest cells.
pub const DEFAULT_MAX_FACE_EXTENT: u32 = 6;

/// Default [`SimplifyOptions::max_flat_face_extent`], in finest cells. Large flat faces
/// answer for hundreds of removed vertices each, re-checked at every collapse next to them,
/// so they are made in a second flat stage, once every other collapse is done
/// ([`Simplifier::run_flat`]): openscad-toomanyvertices at res 256 keeps 3,842 faces (31,260
/// with no large faces) for 27.5 M distance checks of removed vertices (17.6 M with none, 100 M
/// with large faces allowed from the start; docs/benchmarks.md, "Large flat faces in a second
/// stage").
pub const DEFAULT_MAX_FLAT_FACE_EXTENT: u32 = 32;

/// Default [`SimplifyOptions::target_fraction_of_marching_cubes`].
pub const DEFAULT_TARGET_FRACTION: f64 = 0.45;

/// Default [`SimplifyOptions::lattice_diagonal_error`], in finest cells. The pass over the
/// lattice diagonals takes no global cost order, so without a bound a diagonal vertex at a sharp
/// edge went into a neighbour across it, whose quadric then held the planes of both sides and
/// refused later flat collapses: cgal-blade at res 128 kept 12,818 faces (8,062 before the pass)
/// and cgal-cheese 145,174 (97,504; agreement 99.894 % against 99.927 %). With 0.03 cell those
/// collapses are left to the cost-ordered ones (blade 10,446 faces, cheese 116,080 and
/// 99.918 %), and on curved parts at fine resolutions few are (the bunny at res 256: 16.8k of
/// its 487k diagonal vertices left, time unchanged within the VM's spread).
pub const DEFAULT_DIAGONAL_ERROR: f64 = 0.03;

/// Default [`SimplifyOptions::slab_cells`].
pub const DEFAULT_SLAB_CELLS: u32 = 32;

/// Default [`SimplifyOptions::flat_tolerance`], in finest cells.
pub const DEFAULT_FLAT_TOLERANCE: f64 = 0.01;

/// Weight of the squared edge length (lattice units) added to the quadric error: in flat
/// regions, where the quadric is 0 for every target, short edges collapse first (rounder faces).
const LENGTH_WEIGHT: f64 = 1e-3;

/// A round of [`Simplifier::run`] also ends once this many popped vertices had to wait for
/// the next one (their ring box meets a selected one's). Where cheap collapses cluster, popping
/// on would pay a heap push and pop per waiting vertex and take collapses far out of cost
/// order: without the bound the bunny at res 128 took 1.3 waits per collapse and ~30 % more
/// CPU than one collapse at a time (4 × with rounds of 4096 and 4-cell conflict buckets); with
/// it, 7–15 % more (`examples/simplify_bench.rs`, docs/benchmarks.md).
const MAX_DEFERRED: usize = 32;

/// Weight of `|p − p_v|²` (lattice units) against the area-normalised quadric in
/// [`Simplifier::relocate`]: directions along which the planes vary less than this stay put.
/// Chosen on the bunny at res 64 (occupancy agreement 99.897 % at 0.05, 99.908 % at 0.01,
/// 99.904 % at 0.003, moves of at most a quarter cell).
const RELOCATION_STIFFNESS: f64 = 0.01;

/// Shortest move, in finest cells, that [`Simplifier::relocate`] makes: a shorter one changes the
/// surface by less than this, and is not worth its intersection check. On the bunny at res 256,
/// 35k of the 76k moves were below 0.01 cells (20k below 0.005). Not more: on a convex surface
/// every move is outward, so skipped moves add up to a bias; at 0.01 the sphere's volume after
/// relocation at res 16 is the same as with every move (2.609e-2 lost against 2.608e-2; at 0.02,
/// 2.735e-2), and the bunny's occupancy agreement at res 128 is within 10⁻⁴.
const MIN_RELOCATION: f64 = 0.01;

/// Rounds of [`Simplifier::run`] with fewer collapses (or vertices to re-cost) than this
/// are planned on the calling thread, the same plans: flat regions' rounds are small (their
/// cheapest collapses are neighbours, which wait for each other), and handing them to the
/// thread pool cost more than it gained (the cube at res 1024: 17 % of the profile's samples
/// in the kernel's thread switches). Always parallel / below 64 / below 256, 2 threads: the
/// cube at res 512 6.2 / 5.2 / 4.9 s; curved inputs within the machine's noise either way
/// (docs/benchmarks.md, "Small rounds on the calling thread").
const PARALLEL_ROUND: usize = 256;

/// Most collapses planned together (in parallel) in one round of [`Simplifier::run`]. A
/// constant, so that the result does not depend on the thread count; small enough that a
/// round stays close to the global cost order.
const ROUND: usize = 1024;

/// Options of [`simplify`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimplifyOptions {
    /// Largest distance, in finest cells, from a removed vertex to the simplified surface.
    pub max_distance: f64,
    /// Largest extent of a face's bounding box along any axis, in finest cells.
    pub max_face_extent: u32,
    /// The same for the new faces of a collapse whose faces all lie in one plane (a box's
    /// side, a printer bed), in the flat phase's last stage ([`Simplifier::run_flat`]): they
    /// cover what the old ones did, so only the spatial index's work grows with them (they
    /// need no intersection check, and their few large faces sit in the index's large size
    /// classes). At most [`SimplifyOptions::max_face_extent`] has no effect.
    pub max_flat_face_extent: u32,
    /// Stop once the face count is at most this fraction of a dense marching cubes' on the same
    /// corner classes (the remesher's [`super::RemeshStats::marching_cubes_faces`]; [`simplify`]
    /// itself takes a face count); 0: collapse as far as the other bounds allow. Collapses run
    /// cheapest first, so stopping early keeps the flattest regions simplified and the curved
    /// ones closest to the marching-tetrahedra surface.
    pub target_fraction_of_marching_cubes: f64,
    /// After the collapses, move each kept vertex towards the minimum of its quadric (the planes
    /// merged into it: see [`SimplifyOptions::input_planes`]), by at most
    /// [`SimplifyOptions::max_distance`], rounded to the fixed-point grid, where every check
    /// still passes ([`Simplifier::relocate`]): faces are chords, and this moves them back
    /// towards the surface instead of inside convex parts and outside concave ones.
    pub relocate: bool,
    /// Where the remesher knows the input triangle a vertex was placed on (a verified crossing,
    /// [`super::place::Placement::planes`]), relocate towards the input's planes instead of
    /// the marching-tetrahedra faces' ([`simplify_with_planes`]): the faces cut sharp edges
    /// off, the input's planes put the vertices back on them.
    pub input_planes: bool,
    /// Once the target is reached, collapses whose quadric error (the root of the area-weighted
    /// mean squared distance of the kept vertex to the planes merged into the removed one) is at
    /// most this many finest cells go on, cheapest first, until none is left: flat regions
    /// (a box's sides, a printer bed) keep only the faces the other bounds need, where the
    /// target alone would leave them as dense as curved ones. 0: stop at the target.
    pub flat_tolerance: f64,
    /// Before the quadric-ordered collapses, remove the vertices that lie on the face and body
    /// diagonals of the lattice's cubes (where the marching-tetrahedra surface of
    /// [`super::extract`] has 70 % of its vertices and marching cubes has none) by collapses
    /// whose checks stay inside one or two cubes (`simplify/lattice_diagonals.rs`). Same guarantees, a
    /// fraction of the time; skipped when the input is not such a surface.
    pub lattice_diagonals: bool,
    /// Largest quadric error (root mean square distance of the kept vertex to the removed one's
    /// planes, in finest cells) of a collapse in that pass; larger ones are left to the
    /// cost-ordered collapses ([`DEFAULT_DIAGONAL_ERROR`] says why).
    pub lattice_diagonal_error: f64,
    /// The cubes of that pass, in finest cells: the cells of the lattice whose Freudenthal
    /// split the marching tetrahedra followed (the remesher's regular cells, larger than the
    /// resolution's with [`super::RemeshOptions::planar_levels`]). 1 by default.
    pub lattice_cube_cells: u32,
    /// Before the global collapses, cut the surface across its longest axis into slabs about
    /// this many finest cells thick (an even number of them, 2 to 8, about equal in faces; none
    /// if the surface is less than two slabs thick) and collapse inside each slab, all slabs at
    /// once, each with its own simplifier (`simplify/slabs.rs`): the same checks and guarantees, the work
    /// of the slabs in parallel and each in a smaller memory. The result depends on this, not
    /// on the thread count. 0: no slabs.
    pub slab_cells: u32,
    /// Stop collapsing and relocating once this instant has passed (checked between rounds):
    /// the surface is then valid but less simplified than the options ask, which is why the
    /// remesher returns none at all past its deadline ([`super::RemeshOptions::deadline`]).
    pub deadline: Option<std::time::Instant>,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        SimplifyOptions {
            max_distance: DEFAULT_MAX_DISTANCE,
            max_face_extent: DEFAULT_MAX_FACE_EXTENT,
            max_flat_face_extent: DEFAULT_MAX_FLAT_FACE_EXTENT,
            target_fraction_of_marching_cubes: DEFAULT_TARGET_FRACTION,
            relocate: true,
            input_planes: true,
            flat_tolerance: DEFAULT_FLAT_TOLERANCE,
            lattice_diagonals: true,
            lattice_diagonal_error: DEFAULT_DIAGONAL_ERROR,
            lattice_cube_cells: 1,
            slab_cells: DEFAULT_SLAB_CELLS,
            deadline: None,
        }
    }
}

/// Why a collapse `u → v` was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Refusal {
    /// `u` or `v` was removed, or `u v` is not an edge with exactly two faces.
    NotAnEdge,
    /// The link condition fails (the surface would pinch or get a duplicate face).
    Link,
    /// A new face would be larger than [`SimplifyOptions::max_face_extent`].
    FaceTooLarge,
    /// A moved face would become degenerate or turn by 90° or more.
    Flip,
    /// A removed vertex would be farther than [`SimplifyOptions::max_distance`] from the surface.
    Distance,
    /// A new face would meet another face of the surface.
    Intersection,
}

/// Counters of one [`simplify`] run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SimplifyStats {
    /// Faces before.
    pub faces_before: usize,
    /// Faces after.
    pub faces_after: usize,
    /// Collapses made.
    pub collapses: usize,
    /// Rounds of collapses planned together ([`Simplifier::run`]).
    pub rounds: usize,
    /// Of [`SimplifyStats::collapses`], those of lattice-diagonal vertices made cube by cube
    /// before the others ([`SimplifyOptions::lattice_diagonals`]).
    pub diagonal_collapses: usize,
    /// Lattice-diagonal vertices that the cube-by-cube pass had to leave (every local collapse
    /// refused); the quadric-ordered collapses may still remove them.
    pub diagonals_left: usize,
    /// Slabs the surface was cut into for the parallel collapses ([`SimplifyOptions::slab_cells`];
    /// 0: none).
    pub slabs: usize,
    /// Of [`SimplifyStats::collapses`], those made inside the slabs.
    pub slab_collapses: usize,
    /// Vertices moved by the relocation.
    pub relocated: usize,
    /// Relocations refused by the checks (flip, size, distance or intersection).
    pub relocations_refused: usize,
    /// Collapses refused, by reason: link, face size, flip, distance, intersection.
    pub refused: [usize; 5],
    /// Of [`SimplifyStats::collapses`], those that kept the surface as a point set (`u`'s
    /// faces all in one plane, or along a straight crease), which need no intersection check
    /// (`Simplifier::star_is_flat` and `Simplifier::star_is_a_straight_crease` say why).
    pub flat_star_collapses: usize,
    /// The input was not a closed oriented manifold without collinear faces: left unchanged.
    pub skipped: bool,
}

/// The result of [`simplify`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Simplified {
    /// Triangles over the kept vertices (indices into [`Simplified::vertices`]).
    pub triangles: Vec<[u32; 3]>,
    /// For each kept vertex, its index in the input.
    pub vertices: Vec<u32>,
    /// For each kept vertex, its fixed-point position (the input's unless relocated).
    pub points: Vec<P>,
    /// Counters.
    pub stats: SimplifyStats,
}

/// Simplifies the closed surface `triangles` over the exact `points` (fixed point,
/// `ticks_per_cell` units per finest cell) by half-edge collapses that keep it closed, manifold,
/// oriented, of the same topology and free of self-intersections (see the module documentation).
/// Collapses stop once at most `target_faces` faces are left (0: no target).
pub fn simplify(
    points: &[P],
    triangles: &[[u32; 3]],
    ticks_per_cell: i64,
    options: &SimplifyOptions,
    target_faces: usize,
) -> Simplified {
    simplify_with_planes(
        points.to_vec(),
        triangles.to_vec(),
        ticks_per_cell,
        options,
        target_faces,
        None,
    )
}

/// [`simplify`], with the input's planes (`planes`: one entry per point, lattice units, unit
/// normal; the remesher gives the plane of the input triangle each vertex was placed on) as the
/// relocation's quadrics: each face stands for the planes at its three corners (its own where a
/// corner has none), a vertex's quadric sums its faces', and collapses merge them as they merge
/// the cost quadrics. A marching-tetrahedra surface cuts a sharp edge off with faces whose
/// planes are chamfers, so the faces' quadrics relocate vertices onto the chamfer; the input's
/// planes of both sides, met in a ring, put them on the edge. The collapses' costs keep the
/// faces' planes (ranked by the input's, the flat phase stopped early on finely tessellated
/// curved inputs: up to 80 % more faces, for no better distance). Only relocation targets
/// change; every check, hence every guarantee, is the same.
pub fn simplify_with_planes(
    points: Vec<P>,
    triangles: Vec<[u32; 3]>,
    ticks_per_cell: i64,
    options: &SimplifyOptions,
    target_faces: usize,
    planes: Option<Vec<Option<[f64; 4]>>>,
) -> Simplified {
    let planes = planes.filter(|p| p.len() == points.len());
    match Simplifier::new_unindexed(points, triangles, ticks_per_cell, options, planes) {
        Ok(mut s) => {
            let diagonals = options
                .lattice_diagonals
                .then_some(options.lattice_diagonal_error);
            let flat = target_faces > 0 && options.flat_tolerance > 0.0;
            // The collapses first in slabs (when the surface is thick enough), then globally
            // (`slabs` says why the checks are the same). The flat collapses run in the slabs
            // too, once a slab reached its share of the target: globally, their rounds stay
            // small (flat regions' collapses all cost about the same, so the cheapest ones are
            // neighbours and wait for each other): on cgal-fandisk_large at res 256, 38.8k flat
            // collapses in 1,789 rounds took a third of the simplification's time.
            let slabs = s.slabs(options.slab_cells);
            // Past the deadline every later stage is skipped (each round loop also stops):
            // the surface stays valid, and the remesher returns none.
            s.in_slabs(&slabs, |slab, share, foreign| {
                if slab.past_deadline() {
                    return;
                }
                if let Some(max_error) = diagonals {
                    slab.collapse_lattice_diagonals(max_error);
                }
                slab.run(Simplifier::slab_target(target_faces, share, foreign));
                if flat && !slab.past_deadline() {
                    slab.flat_stage(options.flat_tolerance, false);
                }
            });
            if s.past_deadline() {
                return s.finish();
            }
            if slabs.is_empty()
                && let Some(max_error) = diagonals
            {
                s.collapse_lattice_diagonals(max_error);
            }
            s.run(target_faces);
            if s.past_deadline() {
                return s.finish();
            }
            if flat {
                // Large flat faces only here, after the slabs: a slab cannot make a face across
                // its planes, and the strips of large faces it leaves along them are hard to
                // collapse further — the README's box at res 256 kept 7,698 faces with the
                // second stage in the slabs, 3,806 with it here, in the same time
                // (docs/benchmarks.md, "Large flat faces in a second stage").
                let large = s.max_flat_extent > s.max_extent;
                if slabs.is_empty() && large {
                    s.flat_stage(options.flat_tolerance, false);
                }
                s.flat_stage(options.flat_tolerance, large);
            }
            if options.relocate && !s.past_deadline() {
                s.relocate();
            }
            s.finish()
        }
        Err((points, triangles)) => Simplified {
            vertices: (0..points.len() as u32).collect(),
            points,
            stats: SimplifyStats {
                faces_before: triangles.len(),
                faces_after: triangles.len(),
                skipped: true,
                ..SimplifyStats::default()
            },
            triangles,
        },
    }
}

/// The state of a simplification: a face list with removed faces marked dead, vertex-to-face
/// lists, the removed vertices each face answers for, quadrics, and a spatial index of the faces.
#[derive(Debug)]
pub struct Simplifier {
    /// The vertices now (moved by [`Simplifier::relocate`]).
    points: Vec<P>,
    /// `points` in lattice units.
    at: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    alive: Vec<bool>,
    vertex_faces: Vec<Vec<u32>>,
    removed: Vec<bool>,
    /// Per face: the removed vertices it answers for (each within `max_distance` of it).
    support: Vec<Vec<u32>>,
    /// Per vertex: area-weighted plane quadric (10 coefficients) and total area.
    quadric: Vec<[f64; 11]>,
    /// Per vertex, with planes given ([`simplify_with_planes`]): the quadric of the input's
    /// planes, merged along the same collapses, which only the relocation reads (the costs keep
    /// the faces' planes: ranked by the input's, the flat phase stopped early on finely
    /// tessellated curved inputs, up to 80 % more faces, for no better distance). Empty
    /// without planes: the relocation reads `quadric`.
    relocation_quadric: Vec<[f64; 11]>,
    /// Faces by size class `k` (box extent at most `2^k` cells) and the bucket (`2^(k+1)` cells)
    /// of their box's minimum corner: a face of class `k` meeting a box `lo..=hi` has its
    /// minimum corner in `lo − 2^k cells..=hi`, so a query visits a few buckets per class and
    /// only faces of about its size.
    /// The boxes in the lists are the face boxes in units of `2^shift` ticks, rounded outward
    /// to `i32` (half the bytes to scan; exact when `shift` is 0, as for every remesher
    /// output below 2^30 ticks): a prefilter, the exact box test follows.
    grids: Vec<KeyMap<Vec<(u32, Q, Q)>>>,
    /// Whether `grids` holds every live face: built on first need
    /// ([`Simplifier::build_index`]), since the pass over the lattice diagonals needs none and
    /// removes 70 % of the faces first.
    indexed: bool,
    shift: u32,
    ticks: i64,
    /// Fixed-point units per lattice cube of the pass over the lattice diagonals
    /// ([`SimplifyOptions::lattice_cube_cells`] cells).
    cube_ticks: i64,
    max_extent: i64,
    /// The same for a flat star's new faces ([`SimplifyOptions::max_flat_face_extent`]), in
    /// the flat phase's second stage ([`Simplifier::large_flat_faces`]).
    max_flat_extent: i64,
    /// Whether flat stars may make faces up to `max_flat_extent` now (the second stage of
    /// [`Simplifier::run_flat`]); otherwise every face keeps within `max_extent`.
    large_flat_faces: bool,
    /// Squared distance bound, lattice units.
    max_distance2: f64,
    /// While set ([`Simplifier::run_flat`]): the largest quadric error (squared, lattice units)
    /// of a collapse that may be made.
    flat_limit: Option<f64>,
    /// In a slab's simplifier ([`slabs`]): the open slab its collapses must stay inside.
    slab: Option<slabs::Slab>,
    /// [`SimplifyOptions::deadline`].
    deadline: Option<std::time::Instant>,
    stats: SimplifyStats,
}

/// What a collapse changes, computed by [`Simplifier::plan`].
#[derive(Debug)]
struct Plan {
    /// Faces of `u` (all die).
    old: Vec<u32>,
    /// The new faces.
    new: Vec<[u32; 3]>,
    /// Per new face, the removed vertices it will answer for.
    support: Vec<Vec<u32>>,
    /// The kept vertex.
    v: u32,
    /// The neighbours of `u` (their best collapses change), when known.
    ring: Vec<u32>,
    /// Whether the collapse kept the surface as a point set (`u`'s faces in one plane, or a
    /// straight crease: [`Simplifier::collapse_keeps_the_surface`]; no intersection check was
    /// needed).
    keeps_surface: bool,
}

impl Simplifier {
    /// The state for `triangles` over `points`; `None` when the input is not a closed, edge- and
    /// vertex-manifold, consistently oriented surface without collinear faces, or has a
    /// coordinate the exact predicates cannot take.
    pub fn new(
        points: &[P],
        triangles: &[[u32; 3]],
        ticks_per_cell: i64,
        options: &SimplifyOptions,
    ) -> Option<Simplifier> {
        let mut s = Simplifier::new_unindexed(
            points.to_vec(),
            triangles.to_vec(),
            ticks_per_cell,
            options,
            None,
        )
        .ok()?;
        s.build_index();
        Some(s)
    }

    /// [`Simplifier::new`] without the spatial index (built by [`Simplifier::build_index`]).
    /// Takes the surface by value (a res-256 surface is 3M faces: copies would double it) and
    /// gives it back when it cannot be simplified; `planes` is dropped once the relocation
    /// quadrics are built.
    #[allow(clippy::type_complexity)]
    fn new_unindexed(
        points: Vec<P>,
        triangles: Vec<[u32; 3]>,
        ticks_per_cell: i64,
        options: &SimplifyOptions,
        planes: Option<Vec<Option<[f64; 4]>>>,
    ) -> Result<Simplifier, (Vec<P>, Vec<[u32; 3]>)> {
        if ticks_per_cell <= 0
            || !(options.max_distance.is_finite() && options.max_distance >= 0.0)
            || points
                .iter()
                .any(|p| p.iter().any(|c| c.unsigned_abs() >= MAX_COORDINATE as u64))
            || triangles
                .iter()
                .any(|t| t.iter().any(|&v| v as usize >= points.len()))
        {
            return Err((points, triangles));
        }
        let scale = 1.0 / ticks_per_cell as f64;
        let at: Vec<[f64; 3]> = points.iter().map(|p| p.map(|c| c as f64 * scale)).collect();
        // The topology check alongside the face lists and quadrics (two threads: it is the
        // larger half of the set-up).
        let (report, lists) = rayon::join(
            || super::report::TopologyReport::of(&at, &triangles),
            || {
                if triangles.par_iter().any(|t| {
                    let p = t.map(|v| points[v as usize]);
                    cross_exact(sub(p[1], p[0]), sub(p[2], p[0])) == [0; 3]
                }) {
                    return None;
                }
                let mut vertex_faces = vec![Vec::new(); points.len()];
                for (f, t) in triangles.iter().enumerate() {
                    for &v in t {
                        vertex_faces[v as usize].push(f as u32);
                    }
                }
                // Each vertex's planes summed in face order, as one pass over the faces would.
                let quadric: Vec<[f64; 11]> = vertex_faces
                    .par_iter()
                    .map(|faces| {
                        let mut q = [0.0; 11];
                        for &f in faces {
                            let t = triangles[f as usize];
                            for (a, b) in q.iter_mut().zip(plane_quadric(t.map(|v| at[v as usize])))
                            {
                                *a += b;
                            }
                        }
                        q
                    })
                    .collect();
                // With given planes, the relocation's: a face stands for the planes at its
                // three corners (a third of its area each; its own plane where a corner has
                // none), so a vertex next to a sharp edge holds the planes of both sides
                // through its ring.
                let relocation_quadric: Vec<[f64; 11]> = match &planes {
                    None => Vec::new(),
                    Some(planes) => vertex_faces
                        .par_iter()
                        .map(|faces| {
                            let mut q = [0.0; 11];
                            for &f in faces {
                                let t = triangles[f as usize];
                                let own = plane_quadric(t.map(|v| at[v as usize]));
                                for &w in &t {
                                    let third = match planes[w as usize] {
                                        Some(plane) if plane.iter().all(|x| x.is_finite()) => {
                                            weighted_plane_quadric(plane, own[10] / 3.0)
                                        }
                                        _ => own.map(|x| x / 3.0),
                                    };
                                    for (a, b) in q.iter_mut().zip(third) {
                                        *a += b;
                                    }
                                }
                            }
                            q
                        })
                        .collect(),
                };
                Some((vertex_faces, quadric, relocation_quadric))
            },
        );
        if !(report.closed && report.edge_manifold && report.vertex_manifold && report.oriented)
            || report.degenerate_faces > 0
        {
            return Err((points, triangles));
        }
        let Some((vertex_faces, quadric, relocation_quadric)) = lists else {
            return Err((points, triangles));
        };
        drop(planes);
        let largest = points
            .iter()
            .flat_map(|p| p.iter().map(|c| c.unsigned_abs()))
            .max()
            .unwrap_or(0);
        let shift = (64 - largest.leading_zeros()).saturating_sub(30);
        let max_extent = i64::from(options.max_face_extent.max(1)).saturating_mul(ticks_per_cell);
        let max_flat_extent = i64::from(options.max_flat_face_extent)
            .saturating_mul(ticks_per_cell)
            .max(max_extent);
        let (vertices, faces) = (points.len(), triangles.len());
        Ok(Simplifier {
            points,
            at,
            faces: triangles,
            alive: vec![true; faces],
            vertex_faces,
            removed: vec![false; vertices],
            support: vec![Vec::new(); faces],
            quadric,
            relocation_quadric,
            grids: Vec::new(),
            indexed: false,
            shift,
            ticks: ticks_per_cell,
            cube_ticks: ticks_per_cell.saturating_mul(i64::from(options.lattice_cube_cells.max(1))),
            max_extent,
            max_flat_extent,
            large_flat_faces: false,
            max_distance2: (options.max_distance * options.max_distance),
            flat_limit: None,
            slab: None,
            deadline: options.deadline,
            stats: SimplifyStats {
                faces_before: faces,
                ..SimplifyStats::default()
            },
        })
    }

    /// Whether [`SimplifyOptions::deadline`] has passed.
    fn past_deadline(&self) -> bool {
        self.deadline
            .is_some_and(|at| std::time::Instant::now() > at)
    }

    /// Indexes every live face, once.
    fn build_index(&mut self) {
        if !self.indexed {
            self.indexed = true;
            for f in 0..self.faces.len() as u32 {
                if self.alive[f as usize] {
                    self.index(f, true);
                }
            }
        }
    }

    /// Greedy collapses in quadric-error order until none is allowed or at most `target_faces`
    /// faces are left, in rounds: each round takes the cheapest vertices whose neighbourhoods
    /// are pairwise disjoint in space ([`ROUND`] at most, until [`MAX_DEFERRED`] popped
    /// vertices had to wait), plans their collapses in parallel against the surface at the start
    /// of the round, and makes them in cost order.
    ///
    /// Why the plans stay valid: a plan for `u` reads only the faces and vertex lists of `u`'s
    /// closed 1-ring and the faces meeting the box of that ring (every new face lies in it);
    /// a collapse of `u'` writes only faces and vertices of its own closed 1-ring, all inside
    /// its ring's box. Two rounds members have disjoint closed ring boxes, so neither sees the
    /// other's changes. The selection and the order of the changes are serial, so the result
    /// does not depend on the thread count.
    pub fn run(&mut self, target_faces: usize) {
        self.collapse_rounds(target_faces);
    }

    /// More collapses after [`Simplifier::run`], in the same rounds and order, restricted to
    /// those whose quadric error is at most `tolerance` cells (see
    /// [`SimplifyOptions::flat_tolerance`]), until none is left; then again with flat stars
    /// allowed to make faces up to [`SimplifyOptions::max_flat_face_extent`]
    /// (the second stage). Every check applies as in [`Simplifier::run`].
    ///
    /// Why two stages: a removed vertex is re-checked at every collapse whose star holds the
    /// face answering for it, and a large flat face answers for hundreds. Allowed from the
    /// start, large faces form while the small collapses around them are still to come, and
    /// each of those re-checks them all (openscad-toomanyvertices at res 256: 100 M distance
    /// checks in 1.55 M flat plans, 10,890 faces); made last, from faces already 6 cells wide,
    /// far fewer collapses meet them (27.5 M checks, 3,842 faces).
    pub fn run_flat(&mut self, tolerance: f64) {
        self.flat_stage(tolerance, false);
        if self.max_flat_extent > self.max_extent {
            self.flat_stage(tolerance, true);
        }
    }

    /// One stage of [`Simplifier::run_flat`]: the flat collapses, with flat stars allowed to
    /// make faces up to [`SimplifyOptions::max_flat_face_extent`] if `large_faces` (else every
    /// face keeps within [`SimplifyOptions::max_face_extent`]).
    fn flat_stage(&mut self, tolerance: f64, large_faces: bool) {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return;
        }
        self.flat_limit = Some(tolerance * tolerance);
        self.large_flat_faces = large_faces;
        self.collapse_rounds(0);
        self.large_flat_faces = false;
        self.flat_limit = None;
    }

    fn collapse_rounds(&mut self, target_faces: usize) {
        self.build_index();
        let n = self.points.len();
        // Lazy invalidation: an entry counts only if its version is the vertex's. `queued` is the
        // cost of the vertex's valid entry, if any: a vertex whose best cost did not change keeps
        // its entry (popping it re-examines every target anyway).
        let mut version = vec![0u32; n];
        let mut queued: Vec<Option<u64>> = vec![None; n];
        let costs: Vec<Option<f64>> = (0..n as u32)
            .into_par_iter()
            .map(|u| self.best_cost(u))
            .collect();
        let mut heap: BinaryHeap<Reverse<(u64, u32, u32)>> = BinaryHeap::with_capacity(2 * n);
        for (u, c) in costs.into_iter().enumerate() {
            if let Some(c) = c {
                heap.push(Reverse((c.to_bits(), u as u32, 0)));
                queued[u] = Some(c.to_bits());
            }
        }
        let mut taken = KeySet::<u64>::default();
        let mut selected: Vec<u32> = Vec::with_capacity(ROUND);
        let mut deferred = Vec::new();
        let mut touched: Vec<u32> = Vec::new();
        loop {
            if self.past_deadline() {
                break;
            }
            let faces_now = self.stats.faces_before - 2 * self.stats.collapses;
            taken.clear();
            selected.clear();
            while selected.len() < ROUND
                && deferred.len() < MAX_DEFERRED
                && faces_now - 2 * selected.len() > target_faces
            {
                let Some(Reverse(entry)) = heap.pop() else {
                    break;
                };
                let (_, u, ver) = entry;
                if self.removed[u as usize] || ver != version[u as usize] {
                    continue;
                }
                let (lo, hi) = self.ring_box(u);
                let bucket = 2 * self.ticks;
                let mut free = true;
                for_buckets(lo, hi, bucket, |key| free &= !taken.contains(&key));
                if !free {
                    deferred.push(Reverse(entry));
                    continue;
                }
                for_buckets(lo, hi, bucket, |key| {
                    taken.insert(key);
                });
                queued[u as usize] = None;
                selected.push(u);
            }
            if selected.is_empty() {
                break;
            }
            self.stats.rounds += 1;
            let plans: Vec<(Option<Plan>, [usize; 5])> = if selected.len() < PARALLEL_ROUND {
                selected.iter().map(|&u| self.plan_best(u)).collect()
            } else {
                selected.par_iter().map(|&u| self.plan_best(u)).collect()
            };
            touched.clear();
            for (&u, (plan, refused)) in selected.iter().zip(plans) {
                for (a, b) in self.stats.refused.iter_mut().zip(refused) {
                    *a += b;
                }
                if let Some(plan) = plan {
                    touched.extend(plan.ring.iter().copied());
                    self.apply(u, plan);
                }
            }
            touched.sort_unstable();
            touched.dedup();
            let best_of = |x: &u32| self.best_cost(*x).map(f64::to_bits);
            let best: Vec<Option<u64>> = if touched.len() < PARALLEL_ROUND {
                touched.iter().map(best_of).collect()
            } else {
                touched.par_iter().map(best_of).collect()
            };
            for (&x, best) in touched.iter().zip(best) {
                if best != queued[x as usize] || best.is_none() {
                    version[x as usize] += 1;
                    queued[x as usize] = best;
                    if let Some(c) = best {
                        heap.push(Reverse((c, x, version[x as usize])));
                    }
                }
            }
            heap.extend(deferred.drain(..));
        }
    }

    /// The first allowed collapse of `u` into a neighbour, cheapest first, and the refusals
    /// on the way (link, face size, flip, distance, intersection).
    fn plan_best(&self, u: u32) -> (Option<Plan>, [usize; 5]) {
        self.plan_cheapest(u, |v| self.flat_enough(u, v), None)
    }

    /// The first collapse of `u` into a neighbour `v` with `admissible(v)` that passes the
    /// checks (with `cubes`, the cube-local intersection check of [`lattice_diagonals`]),
    /// cheapest first, and the refusals on the way (link, face size, flip, distance,
    /// intersection).
    fn plan_cheapest(
        &self,
        u: u32,
        admissible: impl Fn(u32) -> bool,
        cubes: Option<&lattice_diagonals::CubeFaces>,
    ) -> (Option<Plan>, [usize; 5]) {
        let mut refused = [0; 5];
        // Once per vertex, not per target: the ring does not depend on the target.
        if !self.may_collapse(u) {
            return (None, refused);
        }
        let ring = self.neighbours(u);
        let mut candidates: Vec<(u64, u32)> = ring
            .iter()
            .filter(|&&v| admissible(v))
            .map(|&v| (self.cost(u, v), v))
            .filter(|&(c, _)| c <= self.max_distance2)
            .map(|(c, v)| (c.to_bits(), v))
            .collect();
        candidates.sort_unstable();
        for &(_, v) in &candidates {
            match self.plan_with_ring(u, v, &ring, cubes) {
                Ok(mut plan) => {
                    plan.ring = ring;
                    return (Some(plan), refused);
                }
                Err(r) => {
                    let k = match r {
                        Refusal::NotAnEdge => continue,
                        Refusal::Link => 0,
                        Refusal::FaceTooLarge => 1,
                        Refusal::Flip => 2,
                        Refusal::Distance => 3,
                        Refusal::Intersection => 4,
                    };
                    refused[k] += 1;
                }
            }
        }
        (None, refused)
    }

    /// The box of `u` and its neighbours.
    fn ring_box(&self, u: u32) -> (P, P) {
        let p = self.points[u as usize];
        let (mut lo, mut hi) = (p, p);
        for &f in &self.vertex_faces[u as usize] {
            for x in self.faces[f as usize] {
                let q = self.points[x as usize];
                for a in 0..3 {
                    lo[a] = lo[a].min(q[a]);
                    hi[a] = hi[a].max(q[a]);
                }
            }
        }
        (lo, hi)
    }

    /// Moves each kept vertex `v` towards the minimum of its quadric (the
    /// planes merged into it) plus `RELOCATION_STIFFNESS·|p − p_v|²` (which keeps it put along
    /// the directions the planes leave free), by at most `max_distance`, rounded to the
    /// fixed-point grid; the move is made only if `v`'s faces pass the checks of a collapse
    /// (size, flip against their present normals, every removed vertex they answer for within
    /// `max_distance`, no intersection with each other or any other face). Same rounds as
    /// [`Simplifier::run`]: vertices with disjoint ring boxes (the new position included) are
    /// planned in parallel and moved in a fixed scattered order of their indices.
    pub fn relocate(&mut self) {
        self.build_index();
        // Vertices that need a move, in a scattered order: consecutive indices are neighbours
        // (extraction order), so index order would make most of a round wait for a conflict.
        // Each vertex's target, once: a vertex moves at most once, and the moves of others do
        // not change its target (its quadric and position).
        let mut pending: Vec<(u32, P)> = (0..self.points.len() as u32)
            .into_par_iter()
            .filter_map(|v| Some((v, self.relocation_target(v)?)))
            .collect();
        pending.sort_unstable_by_key(|&(v, _)| (v.wrapping_mul(0x9e37_79b1), v));
        let mut taken = KeySet::<u64>::default();
        let mut selected: Vec<(u32, P)> = Vec::with_capacity(ROUND);
        let mut deferred: Vec<(u32, P)> = Vec::new();
        let bucket = 2 * self.ticks;
        while !pending.is_empty() && !self.past_deadline() {
            taken.clear();
            selected.clear();
            deferred.clear();
            let mut rest = pending.iter();
            for &(v, target) in rest.by_ref() {
                let (mut lo, mut hi) = self.ring_box(v);
                for a in 0..3 {
                    lo[a] = lo[a].min(target[a]);
                    hi[a] = hi[a].max(target[a]);
                }
                let mut free = true;
                for_buckets(lo, hi, bucket, |key| free &= !taken.contains(&key));
                if !free {
                    deferred.push((v, target));
                    if deferred.len() == ROUND {
                        break;
                    }
                    continue;
                }
                for_buckets(lo, hi, bucket, |key| {
                    taken.insert(key);
                });
                selected.push((v, target));
                if selected.len() == ROUND {
                    break;
                }
            }
            deferred.extend(rest.copied());
            std::mem::swap(&mut pending, &mut deferred);
            let plans: Vec<Option<Vec<Vec<u32>>>> = selected
                .par_iter()
                .map(|&(v, target)| self.plan_move(v, target))
                .collect();
            for (&(v, target), plan) in selected.iter().zip(plans) {
                match plan {
                    Some(support) => self.apply_move(v, target, support),
                    None => self.stats.relocations_refused += 1,
                }
            }
        }
    }

    /// Where [`Simplifier::relocate`] would move `v` (fixed point), if anywhere.
    fn relocation_target(&self, v: u32) -> Option<P> {
        let q = self
            .relocation_quadric
            .get(v as usize)
            .unwrap_or(&self.quadric[v as usize]);
        let w = q[10];
        if w.is_nan() || w <= 0.0 || self.removed[v as usize] {
            return None;
        }
        let p0 = self.at[v as usize];
        let k = RELOCATION_STIFFNESS;
        // (A/w + k I) p = −b/w + k p0, by Cramer's rule (the matrix is positive definite).
        let m = [
            [q[0] / w + k, q[1] / w, q[2] / w],
            [q[1] / w, q[4] / w + k, q[5] / w],
            [q[2] / w, q[5] / w, q[7] / w + k],
        ];
        let r = [
            -q[3] / w + k * p0[0],
            -q[6] / w + k * p0[1],
            -q[8] / w + k * p0[2],
        ];
        let det3 = |m: [[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let d = det3(m);
        if d.is_nan() || d == 0.0 {
            return None;
        }
        let mut p = [0.0; 3];
        for (c, x) in p.iter_mut().enumerate() {
            let mut mc = m;
            for row in 0..3 {
                mc[row][c] = r[row];
            }
            *x = det3(mc) / d;
        }
        let mut step = [p[0] - p0[0], p[1] - p0[1], p[2] - p0[2]];
        let len = (step[0] * step[0] + step[1] * step[1] + step[2] * step[2]).sqrt();
        if !len.is_finite() || len < MIN_RELOCATION {
            return None;
        }
        let limit = self.max_distance2.sqrt();
        if len > limit {
            step = step.map(|x| x * limit / len);
        }
        let origin = self.points[v as usize];
        let target: P =
            std::array::from_fn(|a| origin[a] + (step[a] * self.ticks as f64).round() as i64);
        (target != origin
            && target
                .iter()
                .all(|c| c.unsigned_abs() < (1u64 << (30 + self.shift)).min(MAX_COORDINATE as u64)))
        .then_some(target)
    }

    /// The faces of `v` with `v` at `target`, if they pass every check: per face, the removed
    /// vertices it will answer for.
    fn plan_move(&self, v: u32, target: P) -> Option<Vec<Vec<u32>>> {
        let old = &self.vertex_faces[v as usize];
        let p = |x: u32| {
            if x == v {
                target
            } else {
                self.points[x as usize]
            }
        };
        let mut exact: Vec<[P; 3]> = Vec::with_capacity(old.len());
        for &f in old {
            let t = self.faces[f as usize];
            let moved = t.map(p);
            // A flat region's larger faces ([`SimplifyOptions::max_flat_face_extent`]) may
            // move, but not grow.
            let before = face_extent(t.map(|x| self.points[x as usize]));
            if face_extent(moved) > self.max_extent.max(before) {
                return None;
            }
            let after = normal(moved);
            if after == [0; 3] || dot_sign(normal(t.map(|x| self.points[x as usize])), after) <= 0 {
                return None;
            }
            exact.push(moved);
        }
        let scale = 1.0 / self.ticks as f64;
        let triangles: Vec<[[f64; 3]; 3]> = exact
            .iter()
            .map(|t| t.map(|q| q.map(|c| c as f64 * scale)))
            .collect();
        let mut support = vec![Vec::new(); old.len()];
        for x in old
            .iter()
            .flat_map(|&f| self.support[f as usize].iter().copied())
        {
            let (best, d2) = nearest_triangle(self.at[x as usize], &triangles);
            if d2.is_nan() || d2 > self.max_distance2 {
                return None;
            }
            support[best].push(x);
        }
        if self.meets_other_faces(&exact, old) {
            return None;
        }
        Some(support)
    }

    /// Moves `v` to `target` (planned by [`Simplifier::plan_move`] on the current surface).
    fn apply_move(&mut self, v: u32, target: P, support: Vec<Vec<u32>>) {
        let faces = std::mem::take(&mut self.vertex_faces[v as usize]);
        for &f in &faces {
            self.index(f, false);
        }
        self.points[v as usize] = target;
        let scale = 1.0 / self.ticks as f64;
        self.at[v as usize] = target.map(|c| c as f64 * scale);
        for (&f, s) in faces.iter().zip(support) {
            self.index(f, true);
            self.support[f as usize] = s;
        }
        self.vertex_faces[v as usize] = faces;
        self.stats.relocated += 1;
    }

    /// The surface: kept vertices renumbered in input order, live faces in creation order.
    pub fn finish(mut self) -> Simplified {
        let mut index = vec![u32::MAX; self.points.len()];
        let mut vertices = Vec::new();
        for (v, &gone) in self.removed.iter().enumerate() {
            if !gone && !self.vertex_faces[v].is_empty() {
                index[v] = vertices.len() as u32;
                vertices.push(v as u32);
            }
        }
        let triangles: Vec<[u32; 3]> = self
            .faces
            .iter()
            .zip(&self.alive)
            .filter(|(_, a)| **a)
            .map(|(t, _)| t.map(|v| index[v as usize]))
            .collect();
        self.stats.faces_after = triangles.len();
        Simplified {
            triangles,
            points: vertices.iter().map(|&v| self.points[v as usize]).collect(),
            vertices,
            stats: self.stats,
        }
    }

    /// Counters so far.
    pub fn stats(&self) -> SimplifyStats {
        self.stats
    }

    /// Collapses `u` into `v` if every check passes.
    pub fn collapse(&mut self, u: u32, v: u32) -> Result<(), Refusal> {
        let plan = self.plan(u, v)?;
        self.apply(u, plan);
        Ok(())
    }

    /// Makes the collapse `plan` of `u` (computed on the current surface).
    fn apply(&mut self, u: u32, plan: Plan) {
        let v = plan.v;
        self.stats.flat_star_collapses += usize::from(plan.keeps_surface);
        for &f in &plan.old {
            self.alive[f as usize] = false;
            self.index(f, false);
            for x in self.faces[f as usize] {
                if x != u {
                    self.vertex_faces[x as usize].retain(|&g| g != f);
                }
            }
        }
        self.vertex_faces[u as usize].clear();
        self.removed[u as usize] = true;
        for (t, support) in plan.new.into_iter().zip(plan.support) {
            let f = self.faces.len() as u32;
            self.faces.push(t);
            self.alive.push(true);
            self.support.push(support);
            for x in t {
                self.vertex_faces[x as usize].push(f);
            }
            self.index(f, true);
        }
        for &f in &plan.old {
            self.support[f as usize] = Vec::new();
        }
        let qu = self.quadric[u as usize];
        for (a, b) in self.quadric[v as usize].iter_mut().zip(&qu) {
            *a += b;
        }
        if let Some(&qu) = self.relocation_quadric.get(u as usize) {
            for (a, b) in self.relocation_quadric[v as usize].iter_mut().zip(&qu) {
                *a += b;
            }
        }
        self.stats.collapses += 1;
    }

    /// Whether `u → v` passes every check, without making it.
    pub fn check(&self, u: u32, v: u32) -> Result<(), Refusal> {
        self.plan(u, v).map(|_| ())
    }

    /// The live faces now (vertex indices of the input).
    pub fn faces(&self) -> Vec<[u32; 3]> {
        self.faces
            .iter()
            .zip(&self.alive)
            .filter(|(_, a)| **a)
            .map(|(t, _)| *t)
            .collect()
    }

    fn plan(&self, u: u32, v: u32) -> Result<Plan, Refusal> {
        if u as usize >= self.points.len() || !self.may_collapse(u) {
            return Err(Refusal::NotAnEdge);
        }
        self.plan_with_ring(u, v, &self.neighbours(u), None)
    }

    /// [`Simplifier::plan`] with `nu`, the sorted distinct neighbours of `u`, already known.
    /// With `cubes`, the intersection check is the cube-local one of [`lattice_diagonals`]
    /// (only for the lattice-diagonal vertices of a marching-tetrahedra surface).
    fn plan_with_ring(
        &self,
        u: u32,
        v: u32,
        nu: &[u32],
        cubes: Option<&lattice_diagonals::CubeFaces>,
    ) -> Result<Plan, Refusal> {
        if u == v
            || u as usize >= self.points.len()
            || v as usize >= self.points.len()
            || self.removed[u as usize]
            || self.removed[v as usize]
        {
            return Err(Refusal::NotAnEdge);
        }
        let old: &[u32] = &self.vertex_faces[u as usize];
        let mut opposite = [u32::MAX; 2];
        let mut shared = 0;
        for &f in old {
            let t = self.faces[f as usize];
            if t.contains(&v) {
                if shared == 2 {
                    return Err(Refusal::NotAnEdge);
                }
                opposite[shared] = t[0] ^ t[1] ^ t[2] ^ u ^ v;
                shared += 1;
            }
        }
        if shared != 2 {
            return Err(Refusal::NotAnEdge);
        }
        // Link condition: the common neighbours are exactly the two opposite vertices, and the
        // edge between them is not in both links (the tetrahedron). Each of `v`'s neighbours is
        // counted once: the first face of `v` that holds it (no sorted list of them: this runs
        // for every candidate of every collapse).
        let faces_of_v = &self.vertex_faces[v as usize];
        let mut common = 0;
        for (i, &f) in faces_of_v.iter().enumerate() {
            for y in self.faces[f as usize] {
                if y != v
                    && nu.binary_search(&y).is_ok()
                    && !faces_of_v[..i]
                        .iter()
                        .any(|&g| self.faces[g as usize].contains(&y))
                {
                    common += 1;
                }
            }
        }
        if common != 2 {
            return Err(Refusal::Link);
        }
        let has_face = |x: u32, a: u32, b: u32| {
            self.vertex_faces[x as usize].iter().any(|&f| {
                let t = self.faces[f as usize];
                t.contains(&a) && t.contains(&b)
            })
        };
        let (w1, w2) = (opposite[0], opposite[1]);
        if has_face(u, w1, w2) && has_face(v, w1, w2) {
            return Err(Refusal::Link);
        }
        let p = |x: u32| self.points[x as usize];
        let mut new = Vec::with_capacity(old.len());
        // Known once asked: whether the collapse keeps the surface (`u`'s star flat or a
        // straight crease; then its new faces may be larger).
        let mut keeps_surface = None;
        for &f in old {
            let t = self.faces[f as usize];
            if t.contains(&v) {
                continue;
            }
            let n = t.map(|x| if x == u { v } else { x });
            let extent = face_extent(n.map(p));
            if extent > self.max_extent
                && (!self.large_flat_faces
                    || extent > self.max_flat_extent
                    || !*keeps_surface
                        .get_or_insert_with(|| self.collapse_keeps_the_surface(u, v, old)))
            {
                return Err(Refusal::FaceTooLarge);
            }
            let before = normal(t.map(p));
            let after = normal(n.map(p));
            if after == [0; 3] || dot_sign(before, after) <= 0 {
                return Err(Refusal::Flip);
            }
            new.push(n);
        }
        // Distance: u and every vertex u's faces answer for, to the nearest new face. What the
        // bound needs is that each removed vertex stays within `max_distance` of the face that
        // answers for it (checked again whenever that face changes); the nearest is only the
        // best guess. In a flat star (or a straight crease) the new faces cover what the old
        // ones did, and a large
        // flat face answers for hundreds of vertices: each first tries the face that replaces
        // its own (one distance instead of a search; the collapse is refused exactly when it
        // was: that face within the bound means the nearest is too), which halved the flat
        // phase with 32-cell flat faces (docs/benchmarks.md, "Large faces in flat regions").
        let triangles: Vec<[[f64; 3]; 3]> =
            new.iter().map(|t| t.map(|x| self.at[x as usize])).collect();
        let mut support = vec![Vec::new(); new.len()];
        let keeps =
            *keeps_surface.get_or_insert_with(|| self.collapse_keeps_the_surface(u, v, old));
        let mut replacing = 0;
        let points = std::iter::once((u, None)).chain(old.iter().flat_map(|&f| {
            let r = (!self.faces[f as usize].contains(&v)).then(|| {
                replacing += 1;
                replacing - 1
            });
            self.support[f as usize].iter().map(move |&x| (x, r))
        }));
        for (x, r) in points {
            let q = self.at[x as usize];
            if let Some(r) = r.filter(|_| keeps) {
                if point_triangle_distance2(q, &triangles[r]) <= self.max_distance2 {
                    support[r].push(x);
                    continue;
                }
            }
            let (best, d2) = nearest_triangle(q, &triangles);
            if d2.is_nan() || d2 > self.max_distance2 {
                return Err(Refusal::Distance);
            }
            support[best].push(x);
        }
        // Intersections: new faces against each other and against the live faces near them,
        // unless the collapse keeps the surface, where the new faces cover what the old ones did.
        let exact: Vec<[P; 3]> = new.iter().map(|t| t.map(p)).collect();
        let meets = match cubes {
            None if keeps => {
                debug_assert!(
                    !self.meets_other_faces(&exact, old),
                    "a collapse of {u} that keeps the surface meets another face"
                );
                false
            }
            None => self.meets_other_faces(&exact, old),
            Some(cubes) => cubes.refuses(self, u, &new, &exact, old, keeps),
        };
        if meets {
            return Err(Refusal::Intersection);
        }
        Ok(Plan {
            keeps_surface: keeps,
            old: old.to_vec(),
            new,
            support,
            v,
            ring: Vec::new(),
        })
    }

    /// Whether the faces `star` of a vertex `u` (all of them, so all hold `u`) have parallel
    /// normals with positive dot products, exactly: they lie in one plane through `u`, with one
    /// orientation. Then a collapse of `u` that passes the flip check needs no intersection
    /// check:
    /// 1. the star tiles the polygon `L` bounded by `u`'s link: its faces are positively
    ///    oriented in the plane around `u`, so they wind `k ≥ 1` times around it, and `k ≥ 2`
    ///    would overlap two of them, a self-intersection of the surface, which it has none of;
    /// 2. the new faces `(v, a_i, a_i+1)`, one per link edge away from `v`, are positively
    ///    oriented too (the flip check: non-degenerate, positive dot product with the old
    ///    normal), and a fan from `v` over `L`'s edges covers each point `x` as many times,
    ///    counted with orientation, as `L` winds around `x`: once inside, never outside. All
    ///    positive, they tile `L` too, and their directions from `v` turn strictly, so no
    ///    vertex of `L` lies on a new edge and no two new faces meet outside what they share;
    /// 3. a face `g` outside the star (not holding `u`) met the old faces only in vertices and
    ///    edges it shares with them, all on `L`'s boundary; a new face meets that boundary only in
    ///    its own vertices and boundary edges, so `g` meets a new face only where they share a
    ///    vertex or an edge.
    ///
    /// The surface as a point set does not change. Conservative: `false` where an exact cross
    /// product of normals would overflow `i128` (coordinates of 2^30 ticks and more).
    fn star_is_flat(&self, star: &[u32]) -> bool {
        let p = |x: u32| self.points[x as usize];
        let Some(&first) = star.first() else {
            return false;
        };
        let n0 = normal(self.faces[first as usize].map(p));
        n0 != [0; 3]
            && star.iter().all(|&f| {
                let n = normal(self.faces[f as usize].map(p));
                same_direction(n0, n)
            })
    }

    /// Whether the collapse `u → v` (of `u`'s faces `star`) leaves the surface the same point
    /// set, so that, having passed the flip check, it needs no intersection check and may make
    /// large faces: `u`'s star is flat ([`Simplifier::star_is_flat`]), or it is a straight
    /// crease that `u` moves along ([`Simplifier::star_is_a_straight_crease`]).
    fn collapse_keeps_the_surface(&self, u: u32, v: u32, star: &[u32]) -> bool {
        self.star_is_flat(star) || self.star_is_a_straight_crease(u, v, star)
    }

    /// Whether `u`'s faces `star` lie in two planes, each with one orientation (exactly
    /// parallel normals, positive dot products), meeting along the edges `u v` and `u w` only,
    /// with `u` strictly inside the segment `v w` (exactly collinear). A box's edge: collapsing
    /// `u` along it keeps the surface, by the argument of [`Simplifier::star_is_flat`] applied
    /// to each plane's half of the star, a fan from edge `u v` to edge `u w` that tiles the
    /// polygon `v, a_1, …, a_k, w` (its boundary runs from `w` back to `v` through `u`, a
    /// straight segment since `u` lies on it): the new faces `(v, a_i, a_i+1)` and
    /// `(v, a_k, w)`, positively oriented (the flip check), tile it too; the segment `v w` was
    /// covered by the edges `v u` and `u w`, whose only faces are in the star, so no face
    /// outside the star meets it but in `v` or `w`. Conservative like `star_is_flat`.
    fn star_is_a_straight_crease(&self, u: u32, v: u32, star: &[u32]) -> bool {
        let p = |x: u32| self.points[x as usize];
        let normal_of = |f: u32| normal(self.faces[f as usize].map(p));
        // No list of normals: this runs for every plan whose star is not flat, and a curved
        // star leaves at its third face, in neither of the first two planes.
        let Some(&first) = star.first() else {
            return false;
        };
        let a = normal_of(first);
        let mut b = None;
        for &f in &star[1..] {
            let n = normal_of(f);
            if same_direction(a, n) {
                continue;
            }
            match b {
                None => b = Some(n),
                Some(b) if same_direction(b, n) => {}
                Some(_) => return false,
            }
        }
        let Some(b) = b else {
            return false;
        };
        if a == [0; 3] || b == [0; 3] || parallel(a, b) {
            return false;
        }
        // Every face is in plane `a` or plane `b`; `true` for `b`.
        let plane = |f: u32| !same_direction(a, normal_of(f));
        // The crease edges: `u x` whose two faces (x after u in one, before u in the other)
        // lie in different planes.
        let (mut crease, mut count) = ([u32::MAX; 2], 0);
        for &f in star {
            let t = self.faces[f as usize];
            let Some(k) = t.iter().position(|&y| y == u) else {
                return false;
            };
            let x = t[(k + 1) % 3];
            let Some(j) = star.iter().position(|&g| {
                let s = self.faces[g as usize];
                s.iter()
                    .position(|&y| y == u)
                    .is_some_and(|k| s[(k + 2) % 3] == x)
            }) else {
                return false;
            };
            if plane(f) != plane(star[j]) {
                if count == 2 {
                    return false;
                }
                crease[count] = x;
                count += 1;
            }
        }
        let w = match crease {
            [x, w] if count == 2 && x == v => w,
            [w, x] if count == 2 && x == v => w,
            _ => return false,
        };
        let (pu, pv, pw) = (p(u), p(v), p(w));
        let (dv, dw) = (sub(pv, pu), sub(pw, pu));
        let dot: i128 = (0..3).map(|k| i128::from(dv[k]) * i128::from(dw[k])).sum();
        cross_exact(dv, dw) == [0; 3] && dot < 0
    }

    /// Whether the faces `exact` (replacing the faces `old`) meet each other or any other live
    /// face outside what they share.
    fn meets_other_faces(&self, exact: &[[P; 3]], old: &[u32]) -> bool {
        debug_assert!(
            self.indexed,
            "the spatial index is built before any global check"
        );
        let boxes: Vec<(P, P)> = exact.iter().map(|t| face_box(*t)).collect();
        for i in 0..exact.len() {
            for j in i + 1..exact.len() {
                if boxes_overlap(boxes[i], boxes[j]) && faces_intersect(exact[i], exact[j]) {
                    return true;
                }
            }
        }
        let mut lo = [i64::MAX; 3];
        let mut hi = [i64::MIN; 3];
        for (l, h) in &boxes {
            for a in 0..3 {
                lo[a] = lo[a].min(l[a]);
                hi[a] = hi[a].max(h[a]);
            }
        }
        let (qlo, qhi) = coarse((lo, hi), self.shift);
        let p = |x: u32| self.points[x as usize];
        let mut meets = false;
        for (k, grid) in self.grids.iter().enumerate() {
            let reach = lo.map(|c| c - (self.ticks << k));
            let bucket = self.ticks << (k + 1);
            for_buckets(reach, hi, bucket, |key| {
                if meets {
                    return;
                }
                let Some(list) = grid.get(&key) else {
                    return;
                };
                for (g, l, h) in list {
                    // Tested where they are found, with an early exit: no candidate list.
                    if !(0..3).all(|a| l[a] <= qhi[a] && qlo[a] <= h[a]) || old.contains(g) {
                        continue;
                    }
                    let tg = self.faces[*g as usize].map(p);
                    let bg = face_box(tg);
                    if exact
                        .iter()
                        .zip(&boxes)
                        .any(|(t, b)| boxes_overlap(*b, bg) && faces_intersect(*t, tg))
                    {
                        meets = true;
                        return;
                    }
                }
            });
            if meets {
                return true;
            }
        }
        false
    }

    /// Sorted distinct neighbours of `x`.
    fn neighbours(&self, x: u32) -> Vec<u32> {
        let mut n: Vec<u32> = self.vertex_faces[x as usize]
            .iter()
            .flat_map(|&f| self.faces[f as usize])
            .filter(|&y| y != x)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    }

    /// The ordering error of `u → v`: the quadric error ([`Simplifier::quadric_error`]) plus
    /// the length term.
    fn cost(&self, u: u32, v: u32) -> f64 {
        let [x, y, z] = self.at[v as usize];
        let pu = self.at[u as usize];
        let len2 = (x - pu[0]).powi(2) + (y - pu[1]).powi(2) + (z - pu[2]).powi(2);
        self.quadric_error(u, v) + LENGTH_WEIGHT * len2
    }

    /// Whether `u → v` may be made now: always, except in [`Simplifier::run_flat`], where its
    /// quadric error must be within the flat tolerance.
    fn flat_enough(&self, u: u32, v: u32) -> bool {
        self.flat_limit
            .is_none_or(|limit| self.quadric_error(u, v) <= limit)
    }

    /// The area-weighted mean squared distance of `v` to the planes merged into `u` (lattice
    /// units²).
    fn quadric_error(&self, u: u32, v: u32) -> f64 {
        let q = &self.quadric[u as usize];
        let [x, y, z] = self.at[v as usize];
        let e = q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9];
        (e / q[10].max(f64::MIN_POSITIVE)).max(0.0)
    }

    fn best_cost(&self, u: u32) -> Option<f64> {
        if self.removed[u as usize] || !self.may_collapse(u) {
            return None;
        }
        // Over the faces rather than the sorted ring (no allocation: this runs for every
        // neighbour of every collapse): on the closed oriented manifold the simplifier keeps,
        // each neighbour follows `u` in exactly one of its faces, so one term per neighbour.
        self.vertex_faces[u as usize]
            .iter()
            .map(|&f| {
                let t = self.faces[f as usize];
                let i = t.iter().position(|&x| x == u).unwrap_or(0);
                t[(i + 1) % 3]
            })
            .filter(|&v| v != u && self.flat_enough(u, v))
            .map(|v| self.cost(u, v))
            .filter(|&c| c <= self.max_distance2)
            .min_by(f64::total_cmp)
    }

    /// Adds face `f` to (or removes it from) the spatial index.
    fn index(&mut self, f: u32, insert: bool) {
        if !self.indexed {
            return;
        }
        let (lo, hi) = face_box(self.faces[f as usize].map(|x| self.points[x as usize]));
        let extent = (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0);
        let mut k = 0;
        while (self.ticks << k) < extent {
            k += 1;
        }
        if self.grids.len() <= k {
            self.grids.resize_with(k + 1, KeyMap::default);
        }
        let bucket = self.ticks << (k + 1);
        let key = bucket_key(lo.map(|c| c.div_euclid(bucket)));
        let (qlo, qhi) = coarse((lo, hi), self.shift);
        let list = self.grids[k].entry(key).or_default();
        if insert {
            list.push((f, qlo, qhi));
        } else if let Some(i) = list.iter().position(|e| e.0 == f) {
            list.swap_remove(i);
        }
    }
}

/// The box `lo..=hi` in units of `2^shift`, rounded outward (`shift` leaves the coordinates
/// below `2^30`).
fn coarse((lo, hi): (P, P), shift: u32) -> (Q, Q) {
    (
        lo.map(|c| (c >> shift) as i32),
        hi.map(|c| (-((-c) >> shift)) as i32),
    )
}

/// Calls `f` with the key of every bucket (side `bucket`) that the box `lo..=hi` overlaps.
fn for_buckets(lo: P, hi: P, bucket: i64, mut f: impl FnMut(u64)) {
    let b = |c: i64| c.div_euclid(bucket);
    for z in b(lo[2])..=b(hi[2]) {
        for y in b(lo[1])..=b(hi[1]) {
            for x in b(lo[0])..=b(hi[0]) {
                f(bucket_key([x, y, z]));
            }
        }
    }
}

/// A bucket key: 21 bits per axis (bucket coordinates are below `2^20` for lattice coordinates
/// below `2^21` cells; wrapping only merges far buckets, which costs box tests, never a miss).
fn bucket_key(b: P) -> u64 {
    let m = |c: i64| (c as u64) & ((1 << 21) - 1);
    m(b[0]) | (m(b[1]) << 21) | (m(b[2]) << 42)
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// Exact `(b − a) × (c − a)`.
fn normal(t: [P; 3]) -> [i128; 3] {
    cross_exact(sub(t[1], t[0]), sub(t[2], t[0]))
}

/// Whether the `i128` vectors are exactly parallel (or one is zero); conservative: `false`
/// where a product would overflow.
fn parallel(a: [i128; 3], b: [i128; 3]) -> bool {
    (0..3).all(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        match (a[i].checked_mul(b[j]), a[j].checked_mul(b[i])) {
            (Some(x), Some(y)) => x == y,
            _ => false,
        }
    })
}

/// Whether `b` is exactly a positive multiple of `a` (both nonzero; conservative like
/// [`parallel`]).
fn same_direction(a: [i128; 3], b: [i128; 3]) -> bool {
    parallel(a, b) && dot_sign(a, b) > 0
}

/// Exact sign of `a · b` for `i128` vectors (components below `2^123`): an `f64` filter, then
/// arbitrary precision.
fn dot_sign(a: [i128; 3], b: [i128; 3]) -> i32 {
    let products: [f64; 3] = std::array::from_fn(|k| a[k] as f64 * b[k] as f64);
    let sum: f64 = products.iter().sum();
    let bound: f64 = 8.0 * f64::EPSILON * products.iter().map(|x| x.abs()).sum::<f64>();
    if sum > bound {
        return 1;
    }
    if sum < -bound {
        return -1;
    }
    // Exact: in `i128` when it does not overflow (small coordinates, the common case), else in
    // arbitrary precision.
    let small = (0..3).try_fold(0i128, |s, k| {
        a[k].checked_mul(b[k]).and_then(|p| s.checked_add(p))
    });
    if let Some(v) = small {
        return v.signum() as i32;
    }
    use num_bigint::BigInt;
    let exact: BigInt = (0..3)
        .map(|k| BigInt::from(a[k]) * BigInt::from(b[k]))
        .sum();
    match exact.sign() {
        num_bigint::Sign::Plus => 1,
        num_bigint::Sign::Minus => -1,
        num_bigint::Sign::NoSign => 0,
    }
}

/// The largest extent of a face's box along an axis.
fn face_extent(t: [P; 3]) -> i64 {
    let (lo, hi) = face_box(t);
    (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0)
}

fn face_box(t: [P; 3]) -> (P, P) {
    (
        std::array::from_fn(|a| t[0][a].min(t[1][a]).min(t[2][a])),
        std::array::from_fn(|a| t[0][a].max(t[1][a]).max(t[2][a])),
    )
}

fn boxes_overlap((alo, ahi): (P, P), (blo, bhi): (P, P)) -> bool {
    (0..3).all(|a| alo[a] <= bhi[a] && blo[a] <= ahi[a])
}

/// The area-weighted quadric of the plane of `t`: 10 coefficients of `(n·x + d)²` times the
/// area, and the area.
fn plane_quadric(t: [[f64; 3]; 3]) -> [f64; 11] {
    use crate::base::vec3::{cross, norm, sub};
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let len = norm(n);
    if len == 0.0 || !len.is_finite() {
        return [0.0; 11];
    }
    let [a, b, c] = n.map(|x| x / len);
    let d = -(a * t[0][0] + b * t[0][1] + c * t[0][2]);
    weighted_plane_quadric([a, b, c, d], 0.5 * len)
}

/// The 10 coefficients of `w·(n·x + d)²` for the plane `[n, d]` (`|n| = 1`), and `w`.
fn weighted_plane_quadric([a, b, c, d]: [f64; 4], w: f64) -> [f64; 11] {
    [
        w * a * a,
        w * a * b,
        w * a * c,
        w * a * d,
        w * b * b,
        w * b * c,
        w * b * d,
        w * c * c,
        w * c * d,
        w * d * d,
        w,
    ]
}

/// The triangle of `triangles` nearest to `q` (the first of equals) and its squared distance
/// (`∞` when there is none, or when every distance is NaN).
fn nearest_triangle(q: [f64; 3], triangles: &[[[f64; 3]; 3]]) -> (usize, f64) {
    let mut best = (0, f64::INFINITY);
    for (k, t) in triangles.iter().enumerate() {
        // The squared distance to the triangle's box bounds the distance to the triangle from
        // below, so a triangle whose box is no nearer than the best so far is skipped (a third
        // of the arithmetic: supports in flat regions answer for dozens of vertices). Where
        // rounding puts the two within an ulp the earlier triangle keeps the vertex; either
        // way the distance checked against the bound is the kept triangle's own.
        let box_distance2: f64 = (0..3)
            .map(|a| {
                let lo = t[0][a].min(t[1][a]).min(t[2][a]);
                let hi = t[0][a].max(t[1][a]).max(t[2][a]);
                let d = (lo - q[a]).max(q[a] - hi).max(0.0);
                d * d
            })
            .sum();
        if box_distance2 >= best.1 {
            continue;
        }
        let d2 = point_triangle_distance2(q, t);
        if d2 < best.1 {
            best = (k, d2);
        }
    }
    best
}

/// Squared distance from `p` to the closed triangle `t` (Ericson, "Real-Time Collision
/// Detection", 5.1.5).
pub fn point_triangle_distance2(p: [f64; 3], t: &[[f64; 3]; 3]) -> f64 {
    let s = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: [f64; 3], y: [f64; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let [a, b, c] = *t;
    let (ab, ac, ap) = (s(b, a), s(c, a), s(p, a));
    let closest = |q: [f64; 3]| {
        let d = s(p, q);
        dot(d, d)
    };
    let along =
        |o: [f64; 3], e: [f64; 3], k: f64| [o[0] + k * e[0], o[1] + k * e[1], o[2] + k * e[2]];
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return closest(a);
    }
    let bp = s(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return closest(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return closest(along(a, ab, d1 / (d1 - d3)));
    }
    let cp = s(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return closest(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return closest(along(a, ac, d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return closest(along(b, s(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = va + vb + vc;
    if denom.is_nan() || denom <= 0.0 {
        // Degenerate (collinear) triangle: the nearest of its edges.
        return [(a, b), (b, c), (c, a)]
            .iter()
            .map(|&(x, y)| {
                let e = s(y, x);
                let l = dot(e, e);
                let k = if l > 0.0 {
                    (dot(s(p, x), e) / l).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                closest(along(x, e, k))
            })
            .fold(f64::INFINITY, f64::min);
    }
    let (v, w) = (vb / denom, vc / denom);
    closest([
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cube 4 ticks wide whose edge from corner 0 to corner 1 is split at its middle, vertex
    /// 8: its faces lie in the bottom (`z = 0`) and the front (`y = 0`), meeting along the
    /// edges 8–0 and 8–1.
    fn cube_with_a_split_edge(middle: P) -> Simplifier {
        let mut points: Vec<P> = (0..8)
            .map(|i: i64| [(i & 1) * 4, (i >> 1 & 1) * 4, (i >> 2 & 1) * 4])
            .collect();
        points.push(middle);
        let faces = [
            [0, 2, 3],
            [0, 3, 8],
            [8, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 8, 5],
            [8, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
        ];
        Simplifier::new(&points, &faces, 1, &SimplifyOptions::default())
            .expect("a closed oriented manifold")
    }

    #[test]
    fn a_collapse_along_a_straight_crease_keeps_the_surface() {
        let s = cube_with_a_split_edge([2, 0, 0]);
        let star = |x: u32| s.vertex_faces[x as usize].clone();
        // Along the edge, either way: the crease.
        assert!(s.star_is_a_straight_crease(8, 1, &star(8)));
        assert!(s.star_is_a_straight_crease(8, 0, &star(8)));
        assert!(s.collapse_keeps_the_surface(8, 1, &star(8)));
        // Into a vertex of one plane only (the surface would change), from a corner (three
        // planes), and a flat star is not a crease.
        assert!(!s.star_is_a_straight_crease(8, 3, &star(8)));
        assert!(!s.star_is_a_straight_crease(8, 5, &star(8)));
        assert!(!s.star_is_a_straight_crease(0, 8, &star(0)));
        assert!(!s.star_is_a_straight_crease(1, 8, &star(1)));
        assert!(!s.star_is_flat(&star(8)));
    }

    #[test]
    fn a_bent_crease_is_not_straight() {
        // The middle vertex off the edge: its faces no longer lie in two planes.
        for middle in [[2, 1, 0], [2, 0, 1], [2, 1, 1]] {
            let s = cube_with_a_split_edge(middle);
            let star = s.vertex_faces[8].clone();
            assert!(!s.star_is_a_straight_crease(8, 1, &star), "{middle:?}");
            assert!(!s.collapse_keeps_the_surface(8, 0, &star), "{middle:?}");
        }
    }
}
