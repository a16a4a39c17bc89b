//! Inputs that already are the surface a remesh aims for: kept as they are, bit for bit.
//!
//! A remesh returns a closed, edge- and vertex-manifold, consistently oriented surface without
//! self-intersections that bounds `{w > ½}` with its normals pointing out of it. Many inputs
//! already are one (clean scans, CAD exports, most printable models): for them the best answer
//! is the input itself (Hausdorff distance 0, occupancy agreement 100 %, the input's own
//! faces), and the test is linear in the input instead of in the surface's area in cells.
//! [`keep_input`] keeps a mesh only when it proves all of this exactly, on the coordinates the
//! user gave, after [`exact_repair`] (zero-area faces out, faces split at the vertices on their
//! boundary edges: `w` unchanged off the surface, no vertex moved; second copies of faces
//! written twice the same way in one plane out: `{w > ½}` unchanged):
//!
//! 1. **Topology** ([`TopologyReport`]): every edge in exactly two faces, used once each way;
//!    every vertex's faces one fan; no face that repeats a vertex; no two vertices at one
//!    position.
//! 2. **Embedding** ([`self_intersections_wide`]): the coordinates, written as integers
//!    times one power of two (below `2^125`, else not kept: a coordinate of `1` beside one of
//!    `1e-30`), go through the exact triangle–triangle test of the remesher's output (its
//!    predicates widened to those integers): no collinear face, and no two faces
//!    meeting outside the vertex or edge they share. So the components are disjoint closed
//!    surfaces, each splitting space in two, and `w` jumps by exactly one across every face, up
//!    against its normal.
//! 3. **Winding**: `w` then takes one value on each region between components, and the faces are
//!    the boundary of `{w > ½}`, oriented out of it, exactly when every face has `w = 0` in
//!    front and `1` behind. Per component `C` that is two exact facts: the value `o` just outside
//!    `C`, and `C`'s orientation `s` (the sign of the volume it encloses,
//!    [`closed_surface_orientation`]); `C` is right when `(o, s)` is `(0, +1)` (a solid's outer
//!    wall) or `(1, −1)` (a cavity's wall). `o` is the exact evaluator's value at `C`'s
//!    lexicographically largest vertex `v`: the evaluator answers at `v + (ε1, ε2, ε3)` (docs/
//!    robustness.md, section 4), a point lexicographically above all of `C`, hence outside its
//!    convex hull, and infinitely close to `v`, which no other component touches. Where some
//!    component is wrong but every one has `o ≤ 0` and `o + s ≤ 0` (wound inward), `{w > ½}`
//!    is empty: `w` is constant along each side of a component (the collar there is connected
//!    and meets no other), so those values and `0` far away are all it takes. The output is
//!    then empty, proved ([`InputCheck::BoundsNothing`]), with no lattice. So is an open sheet
//!    whose faces lie in one plane and meet only where they share corners and edges
//!    (`a_sheet_in_one_plane`, [`InputCheck::Planar`]; tried before step 1).
//! 4. **Size**: the input has at most the face count the remesh would aim for, the simplifier's
//!    fraction of a dense marching cubes' count at this resolution, estimated from the input's
//!    area: marching cubes puts a vertex on every lattice edge the surface crosses (the faces'
//!    areas projected along each axis, over the cell faces across it) and a closed surface has
//!    about twice as many faces as vertices. A finer input than that is remeshed, unless it has
//!    at most [`ALWAYS_KEPT_FACES`] (the estimate is near 0 for parts thinner than a cell,
//!    which a remesh would lose).
//!
//! What is kept is the input with bit-identical vertices merged and the repairs made: its
//! referenced vertices in their order, and its faces in theirs. Where the repaired mesh fails
//! step 1, the reason given is the input's own first problem there (what `gwn info` counts on
//! the file), unless the repairs left another kind of problem: then that one (a zero-area face
//! taken out is no reason, the open surface left after it is).
//!
//! Three ways on when a step fails, each proved by the same steps on its result:
//! - where solids touch at a vertex or along an edge (step 1 fails for several fans or
//!   four-face edges), [`super::separate_pinches`] pulls them apart by at most a 64th of a cell
//!   (in a second pass at the midpoints of edges pinched flat), after
//!   [`exact_repair::split_at_contacts`] has made a vertex lying inside another solid's edge a
//!   vertex of both;
//! - where closed shells pass through each other (step 2), [`super::cut_intersections`] cuts
//!   them along their intersections and keeps their union;
//! - where that still fails for a self-intersection or a pinch, faces overlapping in one plane
//!   (a part standing on a plate) are replaced by what they add up to there
//!   ([`super::coplanar_overlaps`]), and both ways above are tried again on the result.
//!
//! Whether the last two are tried goes by what the repaired surface failed for (or, where it
//! failed step 1, the input's own first problem too), not by the reason the user is told: an
//! input whose first problem is a zero-area face, taken out by the repairs, still gets them
//! where the rest has a pinch or crossing faces.

use rayon::slice::ParallelSliceMut;

use crate::Mesh;
use crate::base::bounding_box::BoundingBox;
use crate::eval::antipodal::WindingNumber;
use crate::kernel::predicates::closed_surface_orientation;
use crate::kernel::quantize::common_fixed_point;
use crate::mesh::signed_boundary::signed_boundary;

use super::coplanar_overlaps;
use super::cut_intersections::cut_intersections;
use super::exact_repair;
use super::intersect::{self, IntersectError, self_intersections_wide};
use super::lattice::Lattice;
use super::report::TopologyReport;
use super::separate_pinches::{
    LARGEST_MOVE_IN_CELLS, Separated, SeparatedCounts, separate_pinches, split_at_midpoints,
};
use super::{RemeshOptions, RemeshStats, Remeshed};

/// Inputs of at most this many faces are never too fine to keep: the estimate of step 4 is
/// near 0 for a part thinner than a cell (a needle, a sheet-thin plate), which a remesh would
/// lose, while keeping it costs no more than this many faces.
pub const ALWAYS_KEPT_FACES: usize = 10_000;

/// Why [`keep_input`] remeshed instead of keeping the input (the first reason found: the size
/// first, as it is the cheapest, then the module's steps in order).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NotKept {
    /// The mesh has no faces.
    Empty,
    /// Edges in one face only.
    Open {
        /// How many.
        boundary_edges: usize,
    },
    /// Edges in more than two faces, or vertices whose faces are not one fan.
    NotManifold {
        /// Edges in three faces or more.
        edges: usize,
        /// Vertices whose faces form several fans.
        vertices: usize,
    },
    /// Edges used twice in the same direction.
    Misoriented {
        /// How many.
        edges: usize,
    },
    /// A component whose faces cannot be turned to agree across every edge: one-sided, which
    /// a closed surface can only be while passing through itself
    /// ([`super::reorient::keep_reoriented`]).
    NotOrientable,
    /// Faces that repeat a vertex or whose corners are collinear.
    DegenerateFaces {
        /// How many.
        faces: usize,
    },
    /// Distinct vertices at one position (a pinch the indices do not show).
    CoincidentVertices {
        /// Vertices beyond the first at their position.
        vertices: usize,
    },
    /// The coordinates need more than 60 bits in one fixed-point scale (the exact test's range).
    CoordinateRange,
    /// Faces of too uneven sizes for the intersection test's broad phase.
    UnevenFaces,
    /// Faces that meet outside what they share.
    SelfIntersecting {
        /// Pairs of faces.
        pairs: usize,
        /// Why the input was not cut along them instead ([`super::cut_intersections`]), when
        /// that was tried.
        not_cut: Option<super::cut_intersections::NotCut>,
    },
    /// A component with the wrong winding number around it: nested in another of the same
    /// orientation, or an inward-facing shell outside any solid.
    Winding {
        /// `w` just outside the component.
        outside: i64,
        /// Its orientation: `+1` outward, `−1` inward.
        orientation: i32,
    },
    /// More faces than the remesh would aim for at this resolution.
    TooManyFaces {
        /// The input's faces.
        faces: usize,
        /// The remesh's target (estimated).
        target: usize,
    },
}

impl std::fmt::Display for NotKept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            NotKept::Empty => write!(f, "it has no faces"),
            NotKept::Open { boundary_edges } => {
                write!(f, "it is open ({boundary_edges} boundary edges)")
            }
            NotKept::NotManifold { edges, vertices } => write!(
                f,
                "it is not manifold ({edges} edges in more than two faces, {vertices} vertices \
                 with several fans)"
            ),
            NotKept::Misoriented { edges } => {
                write!(f, "its faces are not consistently oriented ({edges} edges)")
            }
            NotKept::NotOrientable => write!(
                f,
                "its faces cannot be oriented consistently (a one-sided component)"
            ),
            NotKept::DegenerateFaces { faces } => write!(f, "it has {faces} degenerate faces"),
            NotKept::CoincidentVertices { vertices } => write!(
                f,
                "{vertices} of its vertices repeat the position of another (not welded)"
            ),
            NotKept::CoordinateRange => write!(
                f,
                "its coordinates span more than 60 bits (the exact intersection test's range)"
            ),
            NotKept::UnevenFaces => write!(
                f,
                "its face sizes are too uneven for the intersection test's broad phase"
            ),
            NotKept::SelfIntersecting { pairs, not_cut } => {
                write!(f, "it self-intersects ({pairs} pairs of faces")?;
                match not_cut {
                    Some(why) => write!(f, "; not cut along them: {why})"),
                    None => write!(f, ")"),
                }
            }
            NotKept::Winding {
                outside,
                orientation,
            } => write!(
                f,
                "a component has w = {outside} outside it and {} inside: not the boundary of \
                 w > 1/2",
                outside + i64::from(orientation)
            ),
            NotKept::TooManyFaces { faces, target } => write!(
                f,
                "it has {faces} faces, more than the remesh's target of about {target} at this \
                 resolution"
            ),
        }
    }
}

/// What happened to the input before the lattice ([`RemeshStats::input`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InputCheck {
    /// The input is the output ([`keep_input`]), after the repairs of [`exact_repair`].
    Kept {
        /// What they changed.
        repairs: exact_repair::RepairCounts,
        /// Solids touching at vertices or edges pulled apart ([`super::separate_pinches`]):
        /// empty when the input's own coordinates were kept, bit for bit.
        separated: SeparatedCounts,
    },
    /// The input, closed but self-intersecting, was cut along its intersections and kept where
    /// it bounds `{w > ½}` ([`super::cut_intersections`]), after the repairs of
    /// [`exact_repair`].
    Cut {
        /// What the repairs changed.
        repairs: exact_repair::RepairCounts,
        /// Pinches pulled apart before the cut ([`super::separate_pinches`]).
        separated: SeparatedCounts,
        /// What the cut did.
        cut: super::cut_intersections::CutCounts,
        /// Output faces that are input faces as they were.
        uncut_faces: usize,
    },
    /// Some of the input's components were kept as they are and the rest remeshed
    /// ([`super::keep_parts`]), as the whole was not kept, for `why`.
    PartlyKept {
        /// Components kept.
        kept_components: usize,
        /// The input's components.
        components: usize,
        /// Faces kept.
        kept_faces: usize,
        /// Why the whole input was not kept.
        why: NotKept,
    },
    /// The input, closed, with its faces turned to face out of the parity method's solid and
    /// kept ([`super::reorient::keep_reoriented`]), after the repairs of [`exact_repair`].
    Reoriented {
        /// What the repairs changed.
        repairs: exact_repair::RepairCounts,
        /// Faces turned (of the repaired faces).
        turned_faces: usize,
    },
    /// The input was remeshed, for this reason.
    Remeshed(NotKept),
    /// `{w > ½}` is empty, proved on the input (after the repairs of [`exact_repair`]): an
    /// open sheet whose faces all lie in one plane and meet only at the corners and edges they
    /// share (exact), so `|w| < ½` everywhere off it (`a_sheet_in_one_plane`). The output is
    /// empty, without a lattice.
    Planar {
        /// What the repairs changed.
        repairs: exact_repair::RepairCounts,
    },
    /// `{w > ½}` is empty, proved on the input (after the repairs, pinches pulled apart): a
    /// closed, manifold, oriented surface without self-intersections whose every component has
    /// `w ≤ 0` on both of its sides (wound inward), so `w ≤ 0` everywhere. The output is empty,
    /// without a lattice; `why` is the first component that does not bound `{w > ½}`.
    BoundsNothing {
        /// What the repairs changed.
        repairs: exact_repair::RepairCounts,
        /// The first component's verdict of step 3 ([`NotKept::Winding`]).
        why: NotKept,
    },
}

impl InputCheck {
    /// Whether the input was kept whole (its faces turned, under the parity method).
    pub fn is_kept(&self) -> bool {
        matches!(
            self,
            InputCheck::Kept { .. } | InputCheck::Reoriented { .. }
        )
    }

    /// Whether the output is made of the input's own surface, whole (faces turned or not) or
    /// cut at its self-intersections, without a lattice.
    pub fn is_input_surface(&self) -> bool {
        matches!(
            self,
            InputCheck::Kept { .. } | InputCheck::Reoriented { .. } | InputCheck::Cut { .. }
        )
    }

    /// Its name in reports and manifests: `kept`, `reoriented`, `cut`, `partly kept`,
    /// `remeshed`, `bounds nothing` or `planar`.
    pub fn name(&self) -> &'static str {
        match self {
            InputCheck::Kept { .. } => "kept",
            InputCheck::Reoriented { .. } => "reoriented",
            InputCheck::Cut { .. } => "cut",
            InputCheck::PartlyKept { .. } => "partly kept",
            InputCheck::Remeshed(_) => "remeshed",
            InputCheck::BoundsNothing { .. } => "bounds nothing",
            InputCheck::Planar { .. } => "planar",
        }
    }

    /// Whether the output was decided without a lattice: the input's own surface, or nothing
    /// ([`InputCheck::BoundsNothing`]).
    pub fn skipped_the_lattice(&self) -> bool {
        self.is_input_surface()
            || matches!(
                self,
                InputCheck::BoundsNothing { .. } | InputCheck::Planar { .. }
            )
    }
}

/// Why a remesh of a mesh with faces came out empty, for a user told so (`gwn remesh`,
/// `gwn.remesh`, each naming its own option for the way out): an empty output is right where
/// `{w > ½}` is empty, but rarely what was meant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WhyEmpty {
    /// The input winds inward (`w = -1` inside it): the parity method remeshes the solid it
    /// encloses.
    WindsInward,
    /// A surface without volume (open sheets: thickening closes them into thin solids), or
    /// parts thinner than a cell (a finer resolution).
    NoVolume,
}

impl WhyEmpty {
    /// The reason for an empty remesh of `mesh` (with the run's `bounds` and `options`): from
    /// the run's [`RemeshStats::input`](super::RemeshStats::input), or, where keeping was not
    /// tried (`--always-remesh`), from [`keep_input`]'s check run now for its verdict alone
    /// (whatever the input's size): an inward input is told so either way.
    pub fn of_mesh(
        mesh: &Mesh,
        bounds: BoundingBox,
        options: &RemeshOptions,
        input: Option<InputCheck>,
    ) -> WhyEmpty {
        if input.is_some() {
            return WhyEmpty::of(input);
        }
        // No face target: the size (step 4) is no reason here.
        let mut check = *options;
        check.simplify = Some(super::simplify::SimplifyOptions {
            target_fraction_of_marching_cubes: f64::INFINITY,
            ..options.simplify.unwrap_or_default()
        });
        check.deadline = None;
        match keep_input(mesh, bounds, &check) {
            Ok(out) => WhyEmpty::of(out.stats.input),
            Err(why) => WhyEmpty::of(Some(InputCheck::Remeshed(why))),
        }
    }

    /// The reason, from the run's [`RemeshStats::input`](super::RemeshStats::input).
    pub fn of(input: Option<InputCheck>) -> WhyEmpty {
        match input {
            Some(
                InputCheck::BoundsNothing { .. }
                | InputCheck::Remeshed(NotKept::Winding {
                    outside: 0,
                    orientation: -1,
                }),
            ) => WhyEmpty::WindsInward,
            _ => WhyEmpty::NoVolume,
        }
    }
}

impl WhyEmpty {
    /// Its short name in manifests: `winds inward` or `no volume`.
    pub fn name(&self) -> &'static str {
        match self {
            WhyEmpty::WindsInward => "winds inward",
            WhyEmpty::NoVolume => "no volume",
        }
    }
}

impl std::fmt::Display for WhyEmpty {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            WhyEmpty::WindsInward => {
                "the input winds inward (w = -1 inside it, faces turned the wrong way)"
            }
            WhyEmpty::NoVolume => {
                "a surface without volume (an open sheet), or parts thinner than a cell"
            }
        })
    }
}

/// The input itself as the remesh of `mesh` (triangles whose `w > ½` solid is meant, with
/// `bounds` and `options` as the remesh would take them), when it provably already is that
/// surface (see the [module documentation](self)); else why not. `options.simplify` sets the
/// face target (without it, only inputs of at most [`ALWAYS_KEPT_FACES`] are kept;
/// [`super::remesh_mesh`] does not try then: a raw lattice surface was asked for).
///
/// ```
/// use gwn::Mesh;
/// use gwn::products::remesh::{RemeshOptions, keep_input::{InputCheck, NotKept, keep_input}};
/// // A unit cube, outward.
/// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7],[4,5,6],[4,6,7]];
/// let cube = Mesh::from_slices(&p, &t)?;
/// let options = RemeshOptions::with_resolution(64);
/// let bounds = cube.bounding_box().unwrap();
/// let kept = keep_input(&cube, bounds, &options).unwrap();
/// assert_eq!(kept.triangles, t);
/// // Inward, it bounds no solid (w = -1 inside): the output is empty, proved.
/// let flipped: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
/// let inward = Mesh::from_slices(&p, &flipped)?;
/// let empty = keep_input(&inward, bounds, &options).unwrap();
/// assert!(empty.triangles.is_empty());
/// assert!(matches!(
///     empty.stats.input,
///     Some(InputCheck::BoundsNothing { why: NotKept::Winding { outside: 0, orientation: -1 }, .. })
/// ));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn keep_input(
    mesh: &Mesh,
    bounds: BoundingBox,
    options: &RemeshOptions,
) -> Result<Remeshed, NotKept> {
    let Prepared {
        positions,
        fixed,
        original,
        repaired,
        lattice,
    } = prepared(mesh, bounds, options)?;
    let mut repairs = repaired.counts;
    // An open sheet in one plane: nothing to keep and, proved, nothing to find.
    if !original.closed && a_sheet_in_one_plane(&fixed, &repaired.triangles) {
        let input = InputCheck::Planar { repairs };
        return Ok(without_a_lattice(Vec::new(), Vec::new(), &lattice, input));
    }
    // A face written twice the same way, all such in one plane: the second copies out, which
    // changes `w` by less than ½ where the rest's `w` is an integer (`{w > ½}` unchanged). A
    // repeated face puts its edges in more than two faces, so a clean input skips the search.
    let repeats = if original.edge_manifold {
        None
    } else {
        exact_repair::without_repeats_in_one_plane(&fixed, &repaired.triangles)
    };
    let repaired_triangles = match repeats {
        Some((triangles, repeated)) => {
            repairs.repeated_faces = repeated;
            triangles
        }
        None => repaired.triangles,
    };
    let (positions, fixed, triangles) = if !repairs.is_empty() {
        referenced_exact(&positions, &fixed, &repaired_triangles)
    } else {
        (positions, fixed, repaired_triangles)
    };
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let first_problem = topology_problem(&original);
    // What the user is told: the input's own first problem where the repaired surface failed
    // step 1 or was pulled apart (what `gwn info` counts on the file), unless the repairs left
    // another kind (a zero-area face taken out is no reason, the open or non-manifold surface
    // left after it is); else what the later step found. Which ways on are tried does not
    // depend on it (`mendable`).
    let repaired_problem = if repairs.is_empty() {
        first_problem
    } else {
        topology_problem(&TopologyReport::of(&positions, &triangles))
    };
    let told = |r: Refused| {
        let e = match first_problem {
            Some(problem) if r.in_topology => problem,
            _ => r.found,
        };
        match repaired_problem {
            Some(left)
                if Some(e) == first_problem
                    && std::mem::discriminant(&left) != std::mem::discriminant(&e) =>
            {
                left
            }
            _ => e,
        }
    };
    let finest = lattice.h.into_iter().fold(f64::INFINITY, f64::min);
    let largest_move = finest * LARGEST_MOVE_IN_CELLS;
    let kept = |positions: &[[f64; 3]], fixed: &[[i128; 3]], triangles: &[[u32; 3]]| {
        kept_or_cut(positions, fixed, triangles, largest_move)
    };
    // Solids touching where a vertex of one lies inside an edge of another: that edge's faces
    // split there (exact, `w` unchanged) make the contact a shared vertex or edge, which the
    // pull can take apart. The surface, and how many faces were split; else `e`.
    let split_at_contacts =
        |positions: &[[f64; 3]], fixed: &[[i128; 3]], triangles: &[[u32; 3]], e: Refused| {
            let budget = intersection_budget(triangles.len());
            let meeting =
                intersect::intersecting_faces_wide(fixed, triangles, budget).map_err(|_| e)?;
            let faces: Vec<u32> = (0..triangles.len() as u32)
                .filter(|&f| meeting[f as usize])
                .collect();
            let (split, split_faces) =
                exact_repair::split_at_contacts(fixed, triangles, &faces, budget).ok_or(e)?;
            let surface = kept(positions, fixed, &split).map_err(|_| e)?;
            Ok((surface, split_faces))
        };
    let (surface, split_faces) = match kept(&positions, &fixed, &triangles) {
        Ok(surface) => (surface, 0),
        Err(e) if e.mendable(first_problem) => {
            // Faces overlapping in one plane (a part standing on a plate, a fold) first:
            // replaced by what they add up to there, then the same steps, the contact split
            // included; where there are none, or that fails, the contact split alone.
            let budget = intersection_budget(triangles.len());
            let merged =
                coplanar_overlaps::merge_coplanar_overlaps(&positions, &fixed, &triangles, budget)
                    .and_then(|merged| {
                        let (positions, triangles) =
                            referenced(&merged.positions, &merged.triangles);
                        let fixed = common_fixed_point(&positions, bits)?;
                        let done = match kept(&positions, &fixed, &triangles) {
                            Ok(surface) => Ok((surface, 0)),
                            Err(e) if e.mendable(first_problem) => {
                                split_at_contacts(&positions, &fixed, &triangles, e)
                            }
                            Err(e) => Err(e),
                        };
                        Some((done.ok()?, merged.counts))
                    });
            match merged {
                Some((done, counts)) => {
                    repairs.coplanar = counts;
                    done
                }
                None => split_at_contacts(&positions, &fixed, &triangles, e).map_err(told)?,
            }
        }
        Err(e) => return Err(told(e)),
    };
    repairs.split_faces += split_faces;
    let input = match (surface.cut, surface.bounds_nothing) {
        (_, Some(why)) => InputCheck::BoundsNothing { repairs, why },
        (None, None) => InputCheck::Kept {
            repairs,
            separated: surface.separated,
        },
        (Some((cut, uncut_faces)), None) => InputCheck::Cut {
            repairs,
            separated: surface.separated,
            cut,
            uncut_faces,
        },
    };
    let (positions, triangles) = (surface.positions, surface.triangles);
    Ok(without_a_lattice(positions, triangles, &lattice, input))
}

/// An output decided without a lattice (the input's surface, or nothing): `input` says how.
pub(super) fn without_a_lattice(
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    lattice: &Lattice,
    input: InputCheck,
) -> Remeshed {
    Remeshed {
        positions,
        triangles,
        fixed: Vec::new(),
        ticks_per_cell: 0,
        cell_size: lattice.largest_cell(),
        cell_sizes: lattice.h,
        stats: RemeshStats {
            input: Some(input),
            ..RemeshStats::default()
        },
    }
}

/// A surface's vertices, their exact fixed-point coordinates, and its faces.
pub(super) type ExactSurface = (Vec<[f64; 3]>, Vec<[i128; 3]>, Vec<[u32; 3]>);

/// The vertices `triangles` refer to, their exact coordinates, and the triangles renumbered to
/// them ([`referenced`] on both).
pub(super) fn referenced_exact(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
) -> ExactSurface {
    let (kept, renumbered) = referenced(fixed, triangles);
    let (positions, _) = referenced(positions, triangles);
    (positions, kept, renumbered)
}

/// The input as [`keep_input`] and [`super::reorient::keep_reoriented`] take it (see the
/// [module documentation](self)): welded, its size checked (step 4), its referenced vertices in
/// their order with their exact coordinates in one scale, and [`exact_repair::repair`] made on
/// them. Both repairs leave `w` and the crossing parity unchanged off the surface (a zero-area
/// face is crossed by no ray in general position, a split face by a ray through exactly one
/// piece, and a cancelled pair by a ray through both or neither).
pub(super) struct Prepared {
    /// The welded input's referenced vertices, in their order.
    pub positions: Vec<[f64; 3]>,
    /// Their coordinates as integers in one scale: exact for the repairs, the intersection
    /// test (narrow or wide predicates, as they fit) and the orientations.
    pub fixed: Vec<[i128; 3]>,
    /// The welded input's topology, before the repairs.
    pub original: TopologyReport,
    /// The repaired faces, on `positions`, and what the repairs changed.
    pub repaired: exact_repair::Repaired,
    /// The remesh's lattice (its finest cell caps how far a pull may move a vertex).
    pub lattice: Lattice,
}

/// [`Prepared`] for `mesh`, or why it is not kept before any exact test: no faces, more than
/// the remesh's face target, coordinates beyond the exact tests' range.
pub(super) fn prepared(
    mesh: &Mesh,
    bounds: BoundingBox,
    options: &RemeshOptions,
) -> Result<Prepared, NotKept> {
    if mesh.triangles().is_empty() {
        return Err(NotKept::Empty);
    }
    // Vertices at one position are one point of the surface (and of the exact evaluator's
    // boundary by position), whatever the file's indices say.
    let (mesh, _) = mesh.welded();
    let triangles = mesh.triangles();
    let lattice = Lattice::new(bounds, options.resolution).ok_or(NotKept::CoordinateRange)?;
    let target = options
        .simplify
        .map(|s| s.target_fraction_of_marching_cubes * marching_cubes_faces(&mesh, lattice.h))
        .unwrap_or(0.0);
    if triangles.len() > ALWAYS_KEPT_FACES && triangles.len() as f64 > target {
        return Err(NotKept::TooManyFaces {
            faces: triangles.len(),
            target: target as usize,
        });
    }
    // The referenced vertices, in their order, and their coordinates as integers in one scale:
    // exact for the repairs, the intersection test (narrow or wide predicates, as they fit)
    // and the orientations.
    let (positions, triangles) = referenced(mesh.positions(), triangles);
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let original = TopologyReport::of(&positions, &triangles);
    let Some(fixed) = common_fixed_point(&positions, bits) else {
        return Err(topology_problem(&original).unwrap_or(NotKept::CoordinateRange));
    };
    // Zero-area faces out, T-junctions split: `w` is the same everywhere off the surface.
    let repaired = exact_repair::repair(
        &fixed,
        &triangles,
        original.closed,
        1000 * triangles.len() as u64,
    );
    Ok(Prepared {
        positions,
        fixed,
        original,
        repaired,
        lattice,
    })
}

/// The surface [`keep_input`] gives for a repaired input, and how it was made.
struct KeptSurface {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    /// Pinches pulled apart (before the cut, and in it).
    separated: SeparatedCounts,
    /// The cut's counts and its uncut faces, when the input was cut.
    cut: Option<(super::cut_intersections::CutCounts, usize)>,
    /// Step 3's verdict, when the surface provably bounds nothing (then it has no faces).
    bounds_nothing: Option<NotKept>,
}

/// Why [`kept_or_cut`] refused a surface.
#[derive(Clone, Copy, Debug)]
struct Refused {
    /// The first problem the steps found on the surface (the pulled-apart one, after a pull).
    found: NotKept,
    /// Whether it failed step 1 or was pulled apart first: then the input's own first problem
    /// is what the user is told.
    in_topology: bool,
}

impl Refused {
    /// Whether [`keep_input`]'s ways on (coplanar replacement, contact split) are worth trying:
    /// where the surface, or the input before its repairs (`first_problem`), fails for faces
    /// meeting where they should not — touching solids (more than two faces at an edge, several
    /// fans at a vertex) or faces crossing. Faces overlapping in one plane show as either,
    /// before the repairs or after.
    fn mendable(&self, first_problem: Option<NotKept>) -> bool {
        let meeting = |e: NotKept| {
            matches!(
                e,
                NotKept::SelfIntersecting { .. } | NotKept::NotManifold { .. }
            )
        };
        meeting(self.found) || (self.in_topology && first_problem.is_some_and(meeting))
    }
}

/// Steps 1–3 on a repaired input (`positions`, their exact coordinates `fixed`, `triangles`),
/// its pinches pulled apart when only they fail step 1, and its self-intersections cut when
/// only they fail step 2; else why not.
fn kept_or_cut(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
    largest_move: f64,
) -> Result<KeptSurface, Refused> {
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let topology = TopologyReport::of(positions, triangles);
    let in_topology = |found: NotKept| Refused {
        found,
        in_topology: true,
    };
    let pulled = match pulled_apart_if_pinched(positions, triangles, &topology, largest_move) {
        Ok(pulled) => pulled,
        // Shells sharing edges in a way the pull cannot take apart (one wall running inside
        // another solid from a shared edge: four faces there, not two solid wedges). Where
        // every edge is used as often each way, `w` is an integer off the surface and jumps
        // by one across every face, and the cut's labels pick the faces with `w = 0` in front
        // (the shared edges separate its patches), with its proof on what they make.
        Err(problem @ NotKept::NotManifold { .. })
            if topology.closed && signed_boundary(triangles.iter().copied()).is_empty() =>
        {
            let cut = cut_intersections(positions, fixed, triangles, largest_move)
                .map_err(|_| in_topology(problem))?;
            return Ok(KeptSurface {
                positions: cut.positions,
                triangles: cut.triangles,
                separated: cut.separated,
                cut: Some((cut.counts, cut.uncut_faces)),
                bounds_nothing: None,
            });
        }
        Err(problem) => return Err(in_topology(problem)),
    };
    let was_pulled = pulled.is_some();
    let given = |found: NotKept| Refused {
        found,
        in_topology: was_pulled,
    };
    let (positions, fixed, triangles, separated) = match pulled {
        None => (
            positions.to_vec(),
            fixed.to_vec(),
            triangles.to_vec(),
            SeparatedCounts::default(),
        ),
        Some(pulled) => {
            let fixed = common_fixed_point(&pulled.positions, bits)
                .ok_or(given(NotKept::CoordinateRange))?;
            (pulled.positions, fixed, pulled.triangles, pulled.counts)
        }
    };
    // Step 2, then step 3's facts per component: its verdict, or that `w > ½` is nowhere.
    let windings = embedded(&fixed, &triangles).and_then(|()| {
        let surface =
            Mesh::from_slices(&positions, &triangles).map_err(|_| NotKept::CoordinateRange)?;
        component_windings(&surface, &fixed)
    });
    match windings.map(|w| (winding_verdict(&w), bounds_nothing(&w))) {
        Ok((Ok(()), _)) => Ok(KeptSurface {
            positions,
            triangles,
            separated,
            cut: None,
            bounds_nothing: None,
        }),
        // Wound inward: the lattice would find `w > ½` nowhere, and need not look.
        Ok((Err(why), true)) => Ok(KeptSurface {
            positions: Vec::new(),
            triangles: Vec::new(),
            separated,
            cut: None,
            bounds_nothing: Some(why),
        }),
        Ok((Err(e), false)) => Err(given(e)),
        // Overlapping shells: their union, cut out of them, when that is provably the answer.
        Err(NotKept::SelfIntersecting { pairs, .. }) => {
            let cut =
                cut_intersections(&positions, &fixed, &triangles, largest_move).map_err(|why| {
                    given(NotKept::SelfIntersecting {
                        pairs,
                        not_cut: Some(why),
                    })
                })?;
            Ok(KeptSurface {
                positions: cut.positions,
                triangles: cut.triangles,
                separated: separated.and(cut.separated),
                cut: Some((cut.counts, cut.uncut_faces)),
                bounds_nothing: None,
            })
        }
        Err(e) => Err(given(e)),
    }
}

/// Steps 2 and 3 of the module documentation on a surface that passed step 1 (with no
/// zero-area face), with its vertices' exact fixed-point coordinates `fixed`: no two at one
/// position, no self-intersection, and `w = 0` in front of every face and `1` behind.
pub(super) fn bounds_its_solid(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
) -> Result<(), NotKept> {
    embedded(fixed, triangles)?;
    let surface = Mesh::from_slices(positions, triangles).map_err(|_| NotKept::CoordinateRange)?;
    check_winding(&surface, fixed)
}

/// Step 2 of the module documentation on a surface that passed step 1 (with no zero-area
/// face), with its vertices' exact fixed-point coordinates `fixed`: no two vertices at one
/// position, and no two faces meeting outside what they share.
pub(super) fn embedded(fixed: &[[i128; 3]], triangles: &[[u32; 3]]) -> Result<(), NotKept> {
    // Distinct vertices at one position would pass the topology (different indices) and the
    // intersection test (coincident positions count as shared) while pinching the surface.
    let mut sorted = fixed.to_vec();
    sorted.par_sort_unstable();
    let coincident = sorted.windows(2).filter(|w| w[0] == w[1]).count();
    if coincident > 0 {
        return Err(NotKept::CoincidentVertices {
            vertices: coincident,
        });
    }
    // The report's budget: linear on evenly sized faces, refused when it would not be.
    let si = self_intersections_wide(fixed, triangles, intersection_budget(triangles.len()))
        .map_err(not_kept_for)?;
    if si.degenerate_faces > 0 {
        return Err(NotKept::DegenerateFaces {
            faces: si.degenerate_faces,
        });
    }
    if si.pairs > 0 {
        return Err(NotKept::SelfIntersecting {
            pairs: si.pairs,
            not_cut: None,
        });
    }
    Ok(())
}

/// Step 1's verdict on a surface with this `topology`, where a failure for its pinches only
/// (solids touching at a vertex or along an edge) is mended by [`separate_pinches`]: nothing to
/// do, the surface pulled apart (closed, manifold and oriented), or the first problem. Edges
/// the pull leaves in four faces (their wedges one fan at each end) are split at their
/// midpoints ([`split_at_midpoints`]) and pulled apart there by a second pass.
pub(super) fn pulled_apart_if_pinched(
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    topology: &TopologyReport,
    largest_move: f64,
) -> Result<Option<Separated>, NotKept> {
    let problem = match topology_problem(topology) {
        None => return Ok(None),
        Some(problem @ NotKept::NotManifold { .. }) => problem,
        Some(problem) => return Err(problem),
    };
    let clean =
        |s: &Separated| topology_problem(&TopologyReport::of(&s.positions, &s.triangles)).is_none();
    let first = separate_pinches(positions, triangles, largest_move);
    let (between, between_triangles) = match &first {
        Some(s) if clean(s) => return Ok(first),
        Some(s) => (&s.positions[..], &s.triangles[..]),
        None => (positions, triangles),
    };
    // Edges still in four faces (pinched flat: one fan at each end, so no vertex to split),
    // split at their midpoints and pulled apart there by a second pass.
    let split = split_at_midpoints(between, between_triangles).ok_or(problem)?;
    let (p, midpoints) = (&split.positions, split.counts.midpoints);
    let second = separate_pinches(p, &split.triangles, largest_move)
        .filter(clean)
        .ok_or(problem)?;
    let mut counts = second.counts;
    counts.midpoints = midpoints;
    // A midpoint rounded to `f32` left its edge by that much before the pull moved it.
    counts.largest_move += split.counts.largest_move;
    if let Some(first) = &first {
        // The first pass counted each split edge, the second its two halves.
        counts.edges = first.counts.edges;
        counts.vertices += first.counts.vertices;
        counts.added_vertices += first.counts.added_vertices;
        // Each vertex the second pass split kept its index for one of its fans, moved; where
        // none of them had moved in the first pass (split, or a copy), no vertex moved twice.
        let moved_first = |v: usize| v >= positions.len() || between[v] != positions[v];
        let twice = (0..between.len()).any(|v| second.positions[v] != p[v] && moved_first(v));
        counts.largest_move = if twice {
            first.counts.largest_move + counts.largest_move
        } else {
            first.counts.largest_move.max(counts.largest_move)
        };
    } else {
        counts.edges = midpoints;
    }
    Ok(Some(Separated { counts, ..second }))
}

/// The candidate pairs the intersection tests may take: linear on evenly sized faces.
pub(super) fn intersection_budget(faces: usize) -> u64 {
    1000 * faces as u64 + 1_000_000
}

/// Why an intersection test that refused keeps nothing.
pub(super) fn not_kept_for(e: IntersectError) -> NotKept {
    match e {
        IntersectError::TooManyCandidates { .. } => NotKept::UnevenFaces,
        IntersectError::CoordinateTooLarge { .. }
        | IntersectError::CoordinateSpan
        | IntersectError::BadIndex { .. } => NotKept::CoordinateRange,
    }
}

/// The first reason of step 1 not to keep a mesh with this topology.
pub(super) fn topology_problem(topology: &TopologyReport) -> Option<NotKept> {
    if topology.degenerate_faces > 0 {
        return Some(NotKept::DegenerateFaces {
            faces: topology.degenerate_faces,
        });
    }
    if !topology.closed {
        return Some(NotKept::Open {
            boundary_edges: topology.boundary_edges,
        });
    }
    if !(topology.edge_manifold && topology.vertex_manifold) {
        return Some(NotKept::NotManifold {
            edges: topology.nonmanifold_edges,
            vertices: topology.nonmanifold_vertices,
        });
    }
    if !topology.oriented {
        return Some(NotKept::Misoriented {
            edges: topology.misoriented_edges,
        });
    }
    None
}

/// The `values` of the vertices `triangles` refer to, in their order, and the triangles
/// renumbered to them.
pub(super) fn referenced<V: Copy>(values: &[V], triangles: &[[u32; 3]]) -> (Vec<V>, Vec<[u32; 3]>) {
    let mut index = vec![u32::MAX; values.len()];
    for &v in triangles.iter().flatten() {
        index[v as usize] = 0;
    }
    let mut kept = Vec::new();
    for (v, value) in values.iter().enumerate() {
        if index[v] == 0 {
            index[v] = kept.len() as u32;
            kept.push(*value);
        }
    }
    let triangles = triangles
        .iter()
        .map(|t| t.map(|v| index[v as usize]))
        .collect();
    (kept, triangles)
}

/// Step 3 of the module documentation on a closed, manifold, oriented, embedded `surface` with
/// its exact fixed-point vertices.
pub(super) fn check_winding(surface: &Mesh, fixed: &[[i128; 3]]) -> Result<(), NotKept> {
    winding_verdict(&component_windings(surface, fixed)?)
}

/// Step 3's facts `(o, s)` ([`component_winding`]) of every component of a closed, manifold,
/// oriented, embedded `surface` with its exact fixed-point vertices, in [`components`]' order.
fn component_windings(surface: &Mesh, fixed: &[[i128; 3]]) -> Result<Vec<(i64, i32)>, NotKept> {
    // The evaluator's own perturbation is what step 3 relies on: build it with the defaults
    // (ray `+z`), whatever evaluator the caller remeshes with.
    let wn = WindingNumber::new(surface).map_err(|_| NotKept::CoordinateRange)?;
    Ok(components(surface.triangles())
        .iter()
        .map(|faces| component_winding(&wn, surface, fixed, faces))
        .collect())
}

/// Step 3's verdict on the facts of [`component_windings`]: the first component that is not a
/// wall of `{w > ½}` facing out of it.
fn winding_verdict(windings: &[(i64, i32)]) -> Result<(), NotKept> {
    match windings.iter().find(|&&(o, s)| !winds_right(o, s)) {
        Some(&(outside, orientation)) => Err(NotKept::Winding {
            outside,
            orientation,
        }),
        None => Ok(()),
    }
}

/// Whether `w ≤ 0` everywhere, from the facts of [`component_windings`] on a surface that
/// passed steps 1 and 2 (closed, manifold, oriented, embedded): off the surface `w` changes only
/// across a component, and is constant along each side of one (its collar on that side is
/// connected and meets no other component), so every value it takes is `0` (far away) or one of
/// `o` and `o + s` for some component with `w = o` just outside it and orientation `s`.
fn bounds_nothing(windings: &[(i64, i32)]) -> bool {
    windings.iter().all(|&(o, s)| o.max(o + i64::from(s)) <= 0)
}

/// Whether `triangles` (no zero-area face), on the exact coordinates `fixed`, all lie in one
/// plane and meet only at the corners and edges they share (the exact intersection test): then
/// `|w| < ½` everywhere off them. Off the plane, every face subtends a solid angle of one sign
/// per orientation, and their interiors are disjoint, so are the cones from the point over
/// them: `|w| ≤ Σ|Ω_f| / 4π = Ω(∪ f) / 4π`, and a bounded region of a plane subtends less than
/// the half space's `2π`. In the plane, off the faces, every `Ω_f` is 0; on a face, the exact
/// evaluator answers at a point just off the plane (its perturbation), where the bound holds.
pub(super) fn a_sheet_in_one_plane(fixed: &[[i128; 3]], triangles: &[[u32; 3]]) -> bool {
    let Some(&first) = triangles.first() else {
        return false;
    };
    let [a, b, c] = first.map(|v| fixed[v as usize]);
    if <[i128; 3] as intersect::ExactPoint>::projection_axis(a, b, c).is_none() {
        return false;
    }
    let in_plane = triangles
        .iter()
        .flatten()
        .all(|&v| <[i128; 3] as intersect::ExactPoint>::orient(a, b, c, fixed[v as usize]) == 0);
    in_plane
        && self_intersections_wide(fixed, triangles, intersection_budget(triangles.len()))
            .is_ok_and(|si| si.pairs == 0 && si.degenerate_faces == 0)
}

/// The faces of each connected component (faces sharing a vertex are connected), each list in
/// increasing order, the lists in the order of their first face.
pub(super) fn components(triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let n = triangles
        .iter()
        .flatten()
        .max()
        .map_or(0, |&v| v as usize + 1);
    let mut parent: Vec<u32> = (0..n as u32).collect();
    for &[a, b, c] in triangles {
        super::report::union(&mut parent, a, b);
        super::report::union(&mut parent, b, c);
    }
    let mut slot = vec![u32::MAX; n];
    let mut lists: Vec<Vec<u32>> = Vec::new();
    for (f, t) in triangles.iter().enumerate() {
        let root = super::report::find(&mut parent, t[0]) as usize;
        if slot[root] == u32::MAX {
            slot[root] = lists.len() as u32;
            lists.push(Vec::new());
        }
        lists[slot[root] as usize].push(f as u32);
    }
    lists
}

/// `(o, s)` of step 3 for the component of `surface` made of `faces`: `wn` is the exact
/// evaluator of all of `surface`, `fixed` its vertices' exact coordinates.
pub(super) fn component_winding(
    wn: &WindingNumber,
    surface: &Mesh,
    fixed: &[[i128; 3]],
    faces: &[u32],
) -> (i64, i32) {
    let (triangles, positions) = (surface.triangles(), surface.positions());
    let component = faces.iter().map(|&f| triangles[f as usize]);
    let top = top_vertex(positions, component.clone());
    // `w` there is an integer (no boundary: χ alone); compare it as one.
    let outside = wn.eval(positions[top as usize]).round() as i64;
    let orientation = closed_surface_orientation(fixed, component, fixed[top as usize]);
    (outside, orientation)
}

/// The lexicographically largest vertex of some faces (finite coordinates): a point of theirs
/// above all of them, hence outside their convex hull.
pub(super) fn top_vertex(positions: &[[f64; 3]], faces: impl Iterator<Item = [u32; 3]>) -> u32 {
    let lex = |v: u32| {
        let p = positions[v as usize];
        (p[0], p[1], p[2])
    };
    faces
        .flatten()
        .max_by(|&a, &b| lex(a).partial_cmp(&lex(b)).expect("finite coordinates"))
        .expect("a component has faces")
}

/// Whether a component with `w = outside` just outside it and this orientation is a wall of
/// `{w > ½}` facing out of it: a solid's outer wall, or a cavity's.
pub(super) fn winds_right(outside: i64, orientation: i32) -> bool {
    matches!((outside, orientation), (0, 1) | (1, -1))
}

/// Triangles of a dense marching cubes on the lattice of spacing `h` around `mesh` (estimated):
/// twice the lattice edges it crosses, `Σ_faces Σ_k |projected area along k| / (h_i h_j)`.
pub(super) fn marching_cubes_faces(mesh: &Mesh, h: [f64; 3]) -> f64 {
    let p = mesh.positions();
    let crossed: f64 = mesh
        .triangles()
        .iter()
        .map(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|v| p[v as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            0.5 * (n[0].abs() / (h[1] * h[2])
                + n[1].abs() / (h[2] * h[0])
                + n[2].abs() / (h[0] * h[1]))
        })
        .sum();
    2.0 * crossed
}
