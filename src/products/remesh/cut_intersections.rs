//! A closed input that only fails [`super::keep_input`] by self-intersecting, cut along its
//! intersections and kept where it bounds `{w > ½}`: the union of overlapping shells (a
//! character's eyes sunk into its head, a model's parts pushed into each other), as a mesh
//! arrangement gives it, instead of a lattice remesh.
//!
//! The input is closed, manifold and oriented, so its `w` is an integer off the surface and
//! jumps by exactly one, up against the normal, across every face that no other face
//! overlaps. ([`super::keep_input`] also calls it on a closed input with edges in four faces
//! that no pull takes apart, where every edge is used as often each way: `w` is an integer
//! off the surface there too; such an edge of the input separates patches like a curve, but
//! carries no value across, step 3.) Then:
//!
//! 1. **Cut.** Every intersecting pair of faces (exact, [`intersecting_pairs_wide`]) must meet
//!    along a segment with two ends, each (by exact signs) an edge of one face piercing the
//!    other's interior, an edge crossing an edge of the other inside both, a corner of one
//!    strictly inside the other, or a vertex the two share (an edge of one lying in the other's
//!    plane gives the first three); not coplanar, no corner on the other's boundary. A
//!    piercing point is named by its edge and the face it pierces, a crossing by its two
//!    edges, so every face through it gets the same vertex; every face through a crossing's
//!    edges, or with a corner inside it, is split there even where it touches the other
//!    surface only at that point. Each cut
//!    face is triangulated with its segments as constraints (a constrained Delaunay
//!    triangulation in the plane of its largest normal component, `spade`); its pieces keep its
//!    orientation.
//! 2. **Patches.** The pieces and the uncut faces, joined across edges in exactly two faces,
//!    form patches; the intersection curves (edges in four faces) separate them. Along a patch
//!    `w` is the same on its front side: moving along it crosses no other surface.
//! 3. **Labels, exact.** A patch is kept when `w = 0` in front of it (so `1` behind). `w` is
//!    read at the point `q = a/2 + b/4 + c/4` of one of its uncut faces `a b c`, when that sum is
//!    exact in `f64` (checked by error-free sums): `q` then lies inside that face and on no
//!    other, and the exact evaluator answers at `q + (ε1, ε2, ε3)` (docs/robustness.md, section
//!    4), in front of the face when the first non-zero component of its normal is positive,
//!    behind it otherwise. A patch without such a face is not labelled (the input is remeshed).
//! 4. **Proof.** The kept pieces, with the new vertices rounded to `f64`, go through
//!    [`super::keep_input`]'s steps 1–3 on their own coordinates: closed, manifold, oriented,
//!    no self-intersection, `w = 0` in front of every face and `1` behind. So the output is
//!    exactly the boundary of a solid; that solid is the input's up to the rounding of the
//!    intersection points (each within a few units in the last place of the exact rational
//!    point).
//!
//! Anything outside this (a degenerate contact, a triple point that makes two segments of one
//! face cross, a patch without a certified point, a rounded output that fails step 4) returns
//! `None`, and the input is remeshed as before.

use std::collections::HashMap;

use glam::DVec3;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use crate::Mesh;
use crate::eval::antipodal::WindingNumber;
use crate::kernel::quantize::common_fixed_point;

use super::intersect::{self, ExactPoint, intersecting_pairs_wide, segment_meets_triangle};
use super::keep_input::{self, NotKept, referenced};
use super::report::TopologyReport;
use super::separate_pinches::SeparatedCounts;

/// At most this many intersecting pairs are cut (the corpus has at most 848); more, and the
/// input is remeshed.
pub const MAX_CUT_PAIRS: usize = 100_000;

/// Faces of one patch tried for a certified value of `w` before giving up.
const MAX_LABEL_TRIES: usize = 8;

/// What [`cut_intersections`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
// Counts grow as the repairs do: built by this crate only, read by fields.
#[non_exhaustive]
pub struct CutCounts {
    /// Pairs of faces that met outside what they share.
    pub intersecting_pairs: usize,
    /// Faces cut along the intersections.
    pub cut_faces: usize,
    /// Faces (uncut, or pieces of cut ones) left out: inside the solid or outside it.
    pub removed_faces: usize,
    /// Vertices made where an edge pierces a face, two edges cross, or three faces meet.
    pub new_vertices: usize,
    /// Points where three faces meet (two segments of each cross there).
    pub triple_points: usize,
}

impl std::fmt::Display for CutCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} intersecting face pairs, {} faces cut, {} new vertices ({} where three faces \
             meet), {} faces left out",
            self.intersecting_pairs,
            self.cut_faces,
            self.new_vertices,
            self.triple_points,
            self.removed_faces
        )
    }
}

/// The cut surface of the module documentation.
#[derive(Clone, Debug)]
pub struct CutSurface {
    /// Vertex positions (the input's, then the piercing points, unreferenced ones dropped).
    pub positions: Vec<[f64; 3]>,
    /// Faces: the input's kept faces and the kept pieces of cut ones.
    pub triangles: Vec<[u32; 3]>,
    /// Output faces that are input faces as they were.
    pub uncut_faces: usize,
    /// Kept pieces touching at a vertex or along an edge, pulled apart.
    pub separated: SeparatedCounts,
    /// What was done.
    pub counts: CutCounts,
}

/// Why [`cut_intersections`] made no cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NotCut {
    /// More than [`MAX_CUT_PAIRS`] intersecting pairs, or the broad phase over its budget.
    TooManyPairs,
    /// Two intersecting faces share an edge (coplanar, folded onto each other).
    SharedEdge,
    /// A corner on the other face's boundary, or an edge through its corner.
    NotGeneral,
    /// Two segments of one face cross (three faces through one point), or a point of the cut
    /// rounds onto or across an edge of its face, or onto another point.
    SegmentsCross,
    /// An edge of the cut surface in other than two or four faces.
    EdgeUse,
    /// A patch with no certified value of `w`, and none across a curve.
    NoCertifiedPoint,
    /// The patches' values of `w` disagree along an intersection curve.
    Labels,
    /// Nothing is left, or the kept pieces, rounded, fail [`super::keep_input`]'s steps 1–3:
    /// the first that fails.
    Proof(&'static str),
}

impl std::fmt::Display for NotCut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotCut::TooManyPairs => write!(f, "too many intersecting pairs to cut"),
            NotCut::SharedEdge => write!(f, "two intersecting faces share an edge"),
            NotCut::NotGeneral => write!(f, "two faces touch in a degenerate way"),
            NotCut::SegmentsCross => {
                write!(
                    f,
                    "intersection segments cross, or round onto an edge, inside a face"
                )
            }
            NotCut::EdgeUse => write!(f, "the cut has edges in other than two or four faces"),
            NotCut::NoCertifiedPoint => write!(f, "a patch has no certified value of w"),
            NotCut::Labels => write!(f, "the values of w disagree along an intersection curve"),
            NotCut::Proof(why) => write!(f, "the cut surface is {why}"),
        }
    }
}

/// An edge as its vertices, the smaller first.
type Edge = (u32, u32);

/// A vertex the cut makes, named by what meets there so that every face through it gets the
/// same one: an edge piercing a face's interior, or two edges crossing inside both (the
/// smaller edge first; mirror-symmetric parts pushed into each other cross that way on their
/// plane of symmetry).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Piercing {
    Face(Edge, u32),
    Edges(Edge, Edge),
}

impl Piercing {
    /// The edges of the input this point lies inside.
    fn edges(self) -> impl Iterator<Item = Edge> {
        let (first, second) = match self {
            Piercing::Face(e, _) => (e, None),
            Piercing::Edges(e, f) => (e, Some(f)),
        };
        std::iter::once(first).chain(second)
    }
}

/// An end of an intersection segment: a piercing point, or a vertex of the input (one the two
/// faces share, or a corner of one strictly inside the other).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum End {
    Pierce(Piercing),
    Vertex(u32),
}

/// How an edge of one face meets another face (see [`piercings`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Contact {
    /// The edge between corners `p` and `q` pierces the other face's interior.
    Interior(usize, usize),
    /// The edge between corners `p` and `q` crosses the other face's edge `k` (from its corner
    /// `k` to `k + 1`) inside both.
    Edge(usize, usize, usize),
    /// Corner `k` lies strictly inside the other face.
    Corner(usize),
}

/// The input (`positions`, their exact fixed-point coordinates `fixed`, `triangles`: closed,
/// manifold, oriented, no zero-area face) cut along its self-intersections and kept where it
/// bounds `{w > ½}`, proved as in the module documentation; else why the cut is not made. Where
/// the kept pieces touch at a vertex or along an edge, they are pulled apart by at most
/// `largest_move` ([`super::separate_pinches`]) before the proof.
pub fn cut_intersections(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
    largest_move: f64,
) -> Result<CutSurface, NotCut> {
    cut_labelling_pieces(positions, fixed, triangles, largest_move, true)
}

/// [`cut_intersections`]; with `read_pieces` false, `w` is read on uncut faces only and every
/// patch of pieces takes its value across a curve (what a patch of slivers does).
fn cut_labelling_pieces(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
    largest_move: f64,
    read_pieces: bool,
) -> Result<CutSurface, NotCut> {
    let budget = keep_input::intersection_budget(triangles.len());
    let pairs = intersecting_pairs_wide(fixed, triangles, budget, MAX_CUT_PAIRS)
        .ok()
        .flatten()
        .ok_or(NotCut::TooManyPairs)?;
    let tri = |f: u32| triangles[f as usize].map(|v| fixed[v as usize]);
    // Step 1: the segments, and the piercing points' positions.
    let mut points: HashMap<Piercing, [f64; 3]> = HashMap::new();
    let mut segments: HashMap<u32, Vec<(u32, [End; 2])>> = HashMap::new();
    // Faces with a corner of another face strictly inside, where the two touch only there.
    let mut touched: Vec<(u32, u32)> = Vec::new();
    for &(f, g) in &pairs {
        let (tf, tg) = (triangles[f as usize], triangles[g as usize]);
        let shared: Vec<u32> = tf.iter().copied().filter(|v| tg.contains(v)).collect();
        let mut ends: Vec<End> = shared.iter().map(|&v| End::Vertex(v)).collect();
        let mut touches = None;
        if shared.len() > 1 {
            return Err(NotCut::SharedEdge);
        }
        for (a, b) in [(f, g), (g, f)] {
            let (ta, tb) = (triangles[a as usize], triangles[b as usize]);
            // With a shared vertex, only the edge opposite it can pierce the other face: the
            // other two leave its plane at the shared vertex.
            let edges = match shared.first() {
                None => piercings(tri(a), tri(b)),
                Some(&v) => {
                    let k = ta.iter().position(|&x| x == v).expect("shared");
                    opposite_edge_piercing(tri(a), tri(b), k)
                }
            }
            .ok_or(NotCut::NotGeneral)?;
            for contact in edges {
                let edge = |p: usize, q: usize| {
                    let (u, v) = (ta[p], ta[q]);
                    (u.min(v), u.max(v))
                };
                let key = match contact {
                    Contact::Corner(k) => {
                        ends.push(End::Vertex(ta[k]));
                        touches = Some((b, ta[k]));
                        continue;
                    }
                    Contact::Interior(p, q) => Piercing::Face(edge(p, q), b),
                    Contact::Edge(p, q, k) => {
                        let (x, y) = (tb[k], tb[(k + 1) % 3]);
                        let (mine, theirs) = (edge(p, q), (x.min(y), x.max(y)));
                        Piercing::Edges(mine.min(theirs), mine.max(theirs))
                    }
                };
                // Two crossing edges are found from both faces.
                if !ends.contains(&End::Pierce(key)) {
                    ends.push(End::Pierce(key));
                }
                points.entry(key).or_insert_with(|| match key {
                    Piercing::Face(e, _) => piercing_point(positions, tb, e),
                    Piercing::Edges(e, f) => crossing_point(positions, e, f),
                });
            }
        }
        let [s, t] = ends[..] else {
            // Faces touching only where their edges cross, or at a corner of one inside the
            // other: no segment, but the point splits those edges in every face through them,
            // or that face (below).
            match ends[..] {
                [End::Pierce(Piercing::Edges(..))] => continue,
                [End::Vertex(v)] if touches.is_some_and(|(_, x)| x == v) => {
                    touched.extend(touches);
                    continue;
                }
                _ => return Err(NotCut::NotGeneral),
            }
        };
        segments.entry(f).or_default().push((g, [s, t]));
        segments.entry(g).or_default().push((f, [s, t]));
    }
    // New vertices after the input's, in a fixed order (the output does not depend on hashing).
    let mut keys: Vec<Piercing> = points.keys().copied().collect();
    keys.sort_unstable();
    let mut all_positions = positions.to_vec();
    let mut vertex_of: HashMap<Piercing, u32> = HashMap::with_capacity(keys.len());
    for key in &keys {
        vertex_of.insert(*key, all_positions.len() as u32);
        all_positions.push(points[key]);
    }
    // Where two edges cross, every face through either is split there, whether or not a
    // segment of it ends there (a face can touch the other surface only at that point).
    let mut on_edge: HashMap<Edge, Vec<u32>> = HashMap::new();
    for key in &keys {
        if let Piercing::Edges(e, f) = key {
            on_edge.entry(*e).or_default().push(vertex_of[key]);
            on_edge.entry(*f).or_default().push(vertex_of[key]);
        }
    }
    // Per face, the points it is split at besides its segments' ends: crossings on its edges,
    // corners of other faces touching it inside.
    let mut split_points: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(f, v) in &touched {
        split_points.entry(f).or_default().push(v);
    }
    if !on_edge.is_empty() {
        for (f, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if let Some(list) = on_edge.get(&(a.min(b), a.max(b))) {
                    split_points
                        .entry(f as u32)
                        .or_default()
                        .extend(list.iter().copied());
                }
            }
        }
    }
    let mut cut: Vec<u32> = segments.keys().copied().collect();
    cut.extend(split_points.keys().filter(|f| !segments.contains_key(f)));
    cut.sort_unstable();
    // Step 1b: triple points, where the segments of two partners cross inside a face. The
    // three faces meet there, so each of them sees two of its segments cross: found three
    // times, or not cut. Each of the three segments is split there.
    let end_at = |e: &End| match e {
        End::Pierce(key) => points[key],
        End::Vertex(v) => positions[*v as usize],
    };
    let mut triples: HashMap<[u32; 3], usize> = HashMap::new();
    for &f in &cut {
        let Some(list) = segments.get(&f) else {
            continue;
        };
        let axes = projection_axes(positions, triangles[f as usize]);
        for (k, &(g, s1)) in list.iter().enumerate() {
            for &(h, s2) in &list[k + 1..] {
                if s1.iter().any(|e| s2.contains(e)) {
                    continue;
                }
                let ends = [s1[0], s1[1], s2[0], s2[1]].map(|e| end_at(&e));
                if segments_cross(ends, axes).ok_or(NotCut::SegmentsCross)? {
                    let mut key = [f, g, h];
                    key.sort_unstable();
                    *triples.entry(key).or_default() += 1;
                }
            }
        }
    }
    let mut triple_keys: Vec<[u32; 3]> = triples.keys().copied().collect();
    triple_keys.sort_unstable();
    let mut splits: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    for key in &triple_keys {
        if triples[key] != 3 {
            return Err(NotCut::SegmentsCross);
        }
        let v = all_positions.len() as u32;
        all_positions.push(triple_point(positions, key.map(|f| triangles[f as usize])));
        for (a, b) in [(key[0], key[1]), (key[0], key[2]), (key[1], key[2])] {
            splits.entry((a, b)).or_default().push(v);
        }
    }
    // Each face's segments as chains of vertices, split at their triple points in order along
    // them (the same order for both faces of a segment: its ends are stored once).
    let id = |e: &End| match e {
        End::Pierce(key) => vertex_of[key],
        End::Vertex(v) => *v,
    };
    let chain = |f: u32, g: u32, [s, e]: [End; 2]| {
        let (a, b) = (id(&s), id(&e));
        let mut chain = vec![a];
        if let Some(inner) = splits.get(&(f.min(g), f.max(g))) {
            let (pa, pb) = (
                DVec3::from(all_positions[a as usize]),
                DVec3::from(all_positions[b as usize]),
            );
            let mut inner: Vec<(f64, u32)> = inner
                .iter()
                .map(|&v| {
                    (
                        (DVec3::from(all_positions[v as usize]) - pa).dot(pb - pa),
                        v,
                    )
                })
                .collect();
            inner.sort_by(|x, y| x.0.total_cmp(&y.0));
            chain.extend(inner.iter().map(|&(_, v)| v));
        }
        chain.push(b);
        chain
    };
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(triangles.len() + 8 * cut.len());
    let mut uncut: Vec<bool> = Vec::with_capacity(faces.capacity());
    // The input face each face is (uncut) or is a piece of.
    let mut origin: Vec<u32> = Vec::with_capacity(faces.capacity());
    let mut is_cut = vec![false; triangles.len()];
    for &f in &cut {
        is_cut[f as usize] = true;
    }
    for (f, t) in triangles.iter().enumerate() {
        if !is_cut[f] {
            faces.push(*t);
            uncut.push(true);
            origin.push(f as u32);
        }
    }
    for &f in &cut {
        let t = triangles[f as usize];
        let mut chains = Vec::new();
        let mut edge_of: HashMap<u32, usize> = HashMap::new();
        let edge_index = |e: Edge| {
            (0..3).find(|&k| {
                let (p, q) = (t[k], t[(k + 1) % 3]);
                e == (p.min(q), p.max(q))
            })
        };
        for &x in split_points.get(&f).into_iter().flatten() {
            // A vertex of the input there is inside `t`; a new one on one of its edges.
            let on = (x as usize).checked_sub(positions.len()).map(|i| keys[i]);
            if let Some(k) = on.and_then(|key| key.edges().find_map(edge_index)) {
                edge_of.insert(x, k);
            }
            chains.push(vec![x]);
        }
        for &(g, ends) in segments.get(&f).into_iter().flatten() {
            for end in ends {
                match end {
                    End::Pierce(key) => {
                        if let Some(k) = key.edges().find_map(edge_index) {
                            edge_of.insert(vertex_of[&key], k);
                        }
                    }
                    // A corner of `t`, or a corner of the other face strictly inside `t`.
                    End::Vertex(_) => {}
                }
            }
            chains.push(chain(f, g, ends));
        }
        let pieces =
            pieces_of_face(&all_positions, t, &chains, &edge_of).ok_or(NotCut::SegmentsCross)?;
        uncut.extend(pieces.iter().map(|_| false));
        origin.extend(pieces.iter().map(|_| f));
        faces.extend(pieces);
    }
    // Step 2: patches across edges in exactly two faces; every other edge in four.
    let mut edge_faces: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(faces.len() * 3);
    for (i, t) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edge_faces
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(i as u32);
        }
    }
    let mut parent: Vec<u32> = (0..faces.len() as u32).collect();
    let mut curve_edges: Vec<[u32; 4]> = Vec::new();
    for (&(u, v), list) in &edge_faces {
        match list[..] {
            [x, y] => super::report::union(&mut parent, x, y),
            // An edge of the input in all four faces (shells sharing it, which the pull could not
            // take apart) separates patches but is no intersection curve: its faces are not two
            // planes crossing, so no value of `w` is carried across it.
            [a, b, c, d]
                if [a, b, c, d].iter().all(|&x| {
                    let t = triangles[origin[x as usize] as usize];
                    t.contains(&u) && t.contains(&v)
                }) => {}
            [a, b, c, d] => curve_edges.push([a, b, c, d]),
            _ => return Err(NotCut::EdgeUse),
        }
    }
    curve_edges.sort_unstable();
    // Step 3: one exact value of `w` per patch.
    let not_evaluated = NotCut::Proof("beyond the evaluator's range");
    let input = Mesh::from_slices(positions, triangles).map_err(|_| not_evaluated)?;
    let wn = WindingNumber::new(&input).map_err(|_| not_evaluated)?;
    // The input faces' boxes, for each read's scan of the faces near it.
    let boxes: Vec<([f64; 3], [f64; 3])> = triangles
        .iter()
        .map(|t| {
            let p = t.map(|v| positions[v as usize]);
            (
                std::array::from_fn(|k| p[0][k].min(p[1][k]).min(p[2][k])),
                std::array::from_fn(|k| p[0][k].max(p[1][k]).max(p[2][k])),
            )
        })
        .collect();
    let mut front: HashMap<u32, i64> = HashMap::new();
    let mut tries: HashMap<u32, usize> = HashMap::new();
    for i in 0..faces.len() {
        let root = super::report::find(&mut parent, i as u32);
        if front.contains_key(&root) || !(read_pieces || uncut[i]) {
            continue;
        }
        // Each try scans the faces near one face: a few per patch.
        let tried = tries.entry(root).or_default();
        if *tried == MAX_LABEL_TRIES {
            continue;
        }
        *tried += 1;
        let (piece, face) = (faces[i], origin[i] as usize);
        if let Some(w) = front_winding(
            &wn,
            &all_positions,
            positions,
            triangles,
            &boxes,
            piece,
            face,
        ) {
            front.insert(root, w);
        }
    }
    // Patches without a certified value (pieces of cut faces only: a lens between two curves,
    // a corner poking through a face) take one across a curve. Near a curve edge the two faces
    // through it are two planes, so `w = w0 + [behind A] + [behind B]` there: a piece of one
    // face on the negative side of the other's plane has `w0 + 1` in front, on the positive
    // side `w0`. Every labelled piece of the edge must give the same `w0`.
    let mut sides: Vec<Option<[(u32, i32); 4]>> = Vec::with_capacity(curve_edges.len());
    for edge in &curve_edges {
        let mut out = [(0, 0); 4];
        let mut known = true;
        for (k, &x) in edge.iter().enumerate() {
            let other = edge
                .iter()
                .find(|&&z| origin[z as usize] != origin[x as usize])
                .ok_or(NotCut::EdgeUse)?;
            let plane = triangles[origin[*other as usize] as usize];
            let root = super::report::find(&mut parent, x);
            match side_of_plane(&all_positions, faces[x as usize], plane, positions) {
                Some(side) => out[k] = (root, side),
                None => known = false,
            }
        }
        sides.push(known.then_some(out));
    }
    let mut changed = true;
    while changed {
        changed = false;
        for pieces in sides.iter().flatten() {
            let behind = |side: i32| i64::from(side < 0);
            let mut w0 = None;
            for &(root, side) in pieces {
                if let Some(&w) = front.get(&root) {
                    if w0.is_some_and(|w0| w0 != w - behind(side)) {
                        return Err(NotCut::Labels);
                    }
                    w0 = Some(w - behind(side));
                }
            }
            let Some(w0) = w0 else { continue };
            for &(root, side) in pieces {
                if let std::collections::hash_map::Entry::Vacant(e) = front.entry(root) {
                    e.insert(w0 + behind(side));
                    changed = true;
                }
            }
        }
    }
    let mut kept = Vec::with_capacity(faces.len());
    let mut kept_uncut = Vec::with_capacity(faces.len());
    for (i, t) in faces.iter().enumerate() {
        let root = super::report::find(&mut parent, i as u32);
        if *front.get(&root).ok_or(NotCut::NoCertifiedPoint)? == 0 {
            kept.push(*t);
            kept_uncut.push(uncut[i]);
        }
    }
    let removed_faces = faces.len() - kept.len();
    let (out_positions, out_triangles) = referenced(&all_positions, &kept);
    // Step 4: the proof, on the rounded coordinates, where kept pieces that touch at a vertex
    // or along an edge are first pulled apart.
    if out_triangles.is_empty() {
        return Err(NotCut::Proof("empty"));
    }
    let topology = TopologyReport::of(&out_positions, &out_triangles);
    let pulled = keep_input::pulled_apart_if_pinched(
        &out_positions,
        &out_triangles,
        &topology,
        largest_move,
    )
    .map_err(|problem| NotCut::Proof(proof_step(problem)))?;
    let (out_positions, out_triangles, separated) = match pulled {
        None => (out_positions, out_triangles, SeparatedCounts::default()),
        Some(pulled) => {
            // An uncut face with a moved vertex is no longer the input's.
            let same =
                |v: u32| out_positions.get(v as usize) == Some(&pulled.positions[v as usize]);
            for (flag, t) in kept_uncut.iter_mut().zip(&pulled.triangles) {
                *flag &= t.iter().all(|&v| same(v));
            }
            (pulled.positions, pulled.triangles, pulled.counts)
        }
    };
    let uncut_faces = kept_uncut.iter().filter(|&&u| u).count();
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let out_fixed = common_fixed_point(&out_positions, bits)
        .ok_or(NotCut::Proof("beyond the exact tests' range"))?;
    keep_input::bounds_its_solid(&out_positions, &out_fixed, &out_triangles)
        .map_err(|e| NotCut::Proof(proof_step(e)))?;
    Ok(CutSurface {
        positions: out_positions,
        triangles: out_triangles,
        uncut_faces,
        separated,
        counts: CutCounts {
            intersecting_pairs: pairs.len(),
            cut_faces: cut.len(),
            removed_faces,
            new_vertices: keys.len() + triple_keys.len(),
            triple_points: triple_keys.len(),
        },
    })
}

/// What the cut surface is, in [`NotCut::Proof`], when it fails `problem`.
fn proof_step(problem: NotKept) -> &'static str {
    match problem {
        NotKept::Empty => "empty",
        NotKept::Open { .. } => "open",
        NotKept::NotManifold { .. } => "not manifold",
        NotKept::Misoriented { .. } => "not consistently oriented",
        NotKept::NotOrientable => "one-sided",
        NotKept::DegenerateFaces { .. } => "made of degenerate faces",
        NotKept::CoincidentVertices { .. } => "pinched at coincident vertices",
        NotKept::CoordinateRange | NotKept::UnevenFaces => "beyond the exact tests' range",
        NotKept::SelfIntersecting { .. } => "self-intersecting after rounding",
        NotKept::Winding { .. } => "not the boundary of w > 1/2",
        NotKept::TooManyFaces { .. } => "too fine",
    }
}

/// The side of the plane of the input face `plane` that the piece `piece` (of another face)
/// lies on, `±1`, decided in `f64` at its centroid with a margin of `10⁻⁹` of its size; `None`
/// within it.
fn side_of_plane(
    all_positions: &[[f64; 3]],
    piece: [u32; 3],
    plane: [u32; 3],
    positions: &[[f64; 3]],
) -> Option<i32> {
    let [a, b, c] = plane.map(|v| DVec3::from(positions[v as usize]));
    let [x, y, z] = piece.map(|v| DVec3::from(all_positions[v as usize]));
    let n = (b - a).cross(c - a);
    let distance = ((x + y + z) / 3.0 - a).dot(n) / n.length();
    let size = (y - x).length().max((z - y).length()).max((x - z).length());
    // NaN (a zero-area plane) fails too.
    if distance.abs().partial_cmp(&(1e-9 * size)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    Some(if distance > 0.0 { 1 } else { -1 })
}

/// How `a` meets `b` ([`Contact`]: an edge piercing its interior, an edge crossing one of its
/// edges inside both, a corner strictly inside it); `None` when a sign is zero otherwise (`a`
/// in `b`'s plane, a corner on its boundary, an edge through a corner of `b`): not in general
/// position.
fn piercings<T: ExactPoint>(a: [T; 3], b: [T; 3]) -> Option<Vec<Contact>> {
    let side = a.map(|p| T::orient(b[0], b[1], b[2], p));
    let mut out = Vec::with_capacity(2);
    match side.iter().filter(|&&s| s == 0).count() {
        0 => {}
        // The two edges from that corner meet the plane only there.
        1 => {
            let k = side.iter().position(|&s| s == 0).expect("one zero");
            if corner_inside(a[k], b)? {
                out.push(Contact::Corner(k));
            }
        }
        // An edge in `b`'s plane, the third corner off it: `a` meets the plane along that edge
        // only. Its ends inside `b` are contacts; where it crosses an edge of `b`, that edge
        // crosses `a`'s plane on it, and is found from `b`.
        2 => {
            for k in (0..3).filter(|&k| side[k] == 0) {
                if corner_inside(a[k], b)? {
                    out.push(Contact::Corner(k));
                }
            }
            return Some(out);
        }
        _ => return None,
    }
    for p in 0..3 {
        let q = (p + 1) % 3;
        if side[p] * side[q] < 0 {
            out.extend(edge_contact(a[p], a[q], b, (p, q))?);
        }
    }
    Some(out)
}

/// [`piercings`] of the edge of `a` opposite its corner `k`, a vertex `b` shares. One end of
/// that edge on `b`'s plane makes the edge from the shared vertex to it lie in the plane: a
/// contact only when that end is strictly inside `b` (the edge then lies in `b`).
fn opposite_edge_piercing<T: ExactPoint>(a: [T; 3], b: [T; 3], k: usize) -> Option<Vec<Contact>> {
    let (p, q) = ((k + 1) % 3, (k + 2) % 3);
    let side = [a[p], a[q]].map(|x| T::orient(b[0], b[1], b[2], x));
    let contact = match side {
        [0, 0] => return None,
        [0, _] => corner_inside(a[p], b)?.then_some(Contact::Corner(p)),
        [_, 0] => corner_inside(a[q], b)?.then_some(Contact::Corner(q)),
        _ if side[0] != side[1] => edge_contact(a[p], a[q], b, (p, q))?,
        _ => None,
    };
    Some(contact.into_iter().collect())
}

/// Whether `v`, on the plane of `b`, lies strictly inside `b` (exact signs in the plane of
/// projection along a nonzero component of `b`'s normal, which keeps inside and outside);
/// `None` on its boundary.
fn corner_inside<T: ExactPoint>(v: T, b: [T; 3]) -> Option<bool> {
    let axes = intersect::plane_axes(T::projection_axis(b[0], b[1], b[2])?);
    let s = [0, 1, 2].map(|i| T::orient2(b[i], b[(i + 1) % 3], v, axes));
    match s.iter().filter(|&&x| x == 0).count() {
        0 => Some(s[0] == s[1] && s[1] == s[2]),
        // On an edge's line: on the edge when the other two agree, else outside.
        1 => {
            let k = s.iter().position(|&x| x == 0).expect("one zero");
            (s[(k + 1) % 3] != s[(k + 2) % 3]).then_some(false)
        }
        _ => None,
    }
}

/// How the segment `p q` (the corners `(i, j)` of its face), whose ends are on opposite sides
/// of `b`'s plane, meets `b`: through its interior, across the inside of one of its edges, or
/// not at all; `None` when it passes through a corner of `b`. Where the segment meets the
/// plane, the three signs are its side of each edge of `b`: all equal inside, one zero (the
/// other two equal) on that edge strictly between its corners, two zeros at a corner.
fn edge_contact<T: ExactPoint>(
    p: T,
    q: T,
    b: [T; 3],
    (i, j): (usize, usize),
) -> Option<Option<Contact>> {
    let s = [
        T::orient(p, q, b[0], b[1]),
        T::orient(p, q, b[1], b[2]),
        T::orient(p, q, b[2], b[0]),
    ];
    let zeros = s.iter().filter(|&&x| x == 0).count();
    Some(match zeros {
        0 => (s[0] == s[1] && s[1] == s[2]).then_some(Contact::Interior(i, j)),
        1 => {
            let k = s.iter().position(|&x| x == 0).expect("one zero");
            let (x, y) = (s[(k + 1) % 3], s[(k + 2) % 3]);
            (x == y).then_some(Contact::Edge(i, j, k))
        }
        _ => return None,
    })
}

/// Where the edges `e` and `f` cross (in `f64`: the exact point rounded, up to the error of
/// the quotient of two cross products), found from `e`'s parameter: the same for every pair of
/// faces that finds it.
fn crossing_point(positions: &[[f64; 3]], (a, b): Edge, (c, d): Edge) -> [f64; 3] {
    let at = |v: u32| DVec3::from(positions[v as usize]);
    let (p, q, r, s) = (at(a), at(b), at(c), at(d));
    // p + t (q − p) = r + u (s − r): crossing both sides with (s − r) leaves t.
    let n = (q - p).cross(s - r);
    let t = ((r - p).cross(s - r).dot(n) / n.dot(n)).clamp(0.0, 1.0);
    (p + t * (q - p)).to_array()
}

/// Where the edge `(u, v)` meets the plane of the face `face` (in `f64`: the exact point
/// rounded, up to the error of the two volumes' quotient).
fn piercing_point(positions: &[[f64; 3]], face: [u32; 3], (u, v): (u32, u32)) -> [f64; 3] {
    let [a, b, c] = face.map(|i| DVec3::from(positions[i as usize]));
    let (p, q) = (
        DVec3::from(positions[u as usize]),
        DVec3::from(positions[v as usize]),
    );
    let n = (b - a).cross(c - a);
    let (dp, dq) = ((p - a).dot(n), (q - a).dot(n));
    let t = (dp / (dp - dq)).clamp(0.0, 1.0);
    (p + t * (q - p)).to_array()
}

/// The pieces of the face `t` cut along its `chains` (vertex paths: intersection segments, split
/// at triple points), oriented as `t`; `edge_of` gives the edge of `t` (`k`: from `t[k]` to
/// `t[k + 1]`) that a chain's end lies on, when it does. `None` when two chains cross or a
/// point rounds onto an edge or another point.
fn pieces_of_face(
    positions: &[[f64; 3]],
    t: [u32; 3],
    chains: &[Vec<u32>],
    edge_of: &HashMap<u32, usize>,
) -> Option<Vec<[u32; 3]>> {
    let (i, j) = projection_axes(positions, t);
    let [a, b, c] = t.map(|v| DVec3::from(positions[v as usize]));
    let flip = (b - a).cross(c - a).to_array()[(i + 2) % 3] < 0.0;
    // Each vertex with the edges of `t` it lies on (bit k: edge t[k] t[k+1]).
    let mut vertices: Vec<(u32, u8)> = vec![(t[0], 0b101), (t[1], 0b011), (t[2], 0b110)];
    let mut on_edge: [Vec<(f64, u32)>; 3] = Default::default();
    for &v in chains.iter().flatten() {
        if vertices.iter().any(|&(w, _)| w == v) {
            continue;
        }
        match edge_of.get(&v) {
            Some(&k) => {
                let (p, q) = (positions[t[k] as usize], positions[t[(k + 1) % 3] as usize]);
                let x = positions[v as usize];
                let along = (0..3).map(|d| (x[d] - p[d]) * (q[d] - p[d])).sum::<f64>();
                on_edge[k].push((along, v));
                vertices.push((v, 1 << k));
            }
            None => vertices.push((v, 0)),
        }
    }
    // A piercing point inside `t` that rounding put on or beyond one of its edges would merge
    // into that edge's chain: exactly inside, on the rounded coordinates, or no cut.
    if vertices.iter().any(|&(v, mask)| {
        mask == 0
            && !strictly_inside(
                t.map(|c| positions[c as usize]),
                positions[v as usize],
                (i, j),
            )
    }) {
        return None;
    }
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(vertices.len());
    for &(v, _) in &vertices {
        let p = positions[v as usize];
        let h = cdt.insert(Point2::new(p[i], p[j])).ok()?;
        if h.index() != handles.len() {
            return None;
        }
        handles.push(h);
    }
    let slot = |v: u32| vertices.iter().position(|&(w, _)| w == v);
    let mut constrain = |x: usize, y: usize| -> Option<()> {
        if cdt.can_add_constraint(handles[x], handles[y]) {
            cdt.add_constraint(handles[x], handles[y]);
            Some(())
        } else {
            None
        }
    };
    for (k, points) in on_edge.iter_mut().enumerate() {
        points.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut chain = vec![k];
        chain.extend(points.iter().map(|&(_, v)| slot(v).expect("listed")));
        chain.push((k + 1) % 3);
        for w in chain.windows(2) {
            constrain(w[0], w[1])?;
        }
    }
    for chain in chains {
        for w in chain.windows(2) {
            constrain(slot(w[0])?, slot(w[1])?)?;
        }
    }
    // Faces outside the chains of `t`'s edges (where a rounded point on an edge fell outside
    // the hull of the others) are reached from the hull across no edge of `t`.
    let on_boundary = |x: usize, y: usize| vertices[x].1 & vertices[y].1 != 0;
    let mut outside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for edge in cdt.convex_hull() {
        let (x, y) = (edge.from().fix().index(), edge.to().fix().index());
        if cdt.is_constraint_edge(edge.as_undirected().fix()) && on_boundary(x, y) {
            continue;
        }
        for face in [edge.face(), edge.rev().face()] {
            if let Some(inner) = face.as_inner() {
                if !outside[inner.fix().index()] {
                    outside[inner.fix().index()] = true;
                    stack.push(inner.fix());
                }
            }
        }
    }
    while let Some(face) = stack.pop() {
        for edge in cdt.face(face).adjacent_edges() {
            let (x, y) = (edge.from().fix().index(), edge.to().fix().index());
            if cdt.is_constraint_edge(edge.as_undirected().fix()) && on_boundary(x, y) {
                continue;
            }
            if let Some(next) = edge.rev().face().as_inner() {
                if !outside[next.fix().index()] {
                    outside[next.fix().index()] = true;
                    stack.push(next.fix());
                }
            }
        }
    }
    let mut pieces = Vec::new();
    for face in cdt.inner_faces() {
        if outside[face.fix().index()] {
            continue;
        }
        let [x, y, z] = face.vertices().map(|h| vertices[h.fix().index()].0);
        pieces.push(if flip { [x, z, y] } else { [x, y, z] });
    }
    Some(pieces)
}

/// The axes of the plane a face is projected on: the two other than its normal's largest
/// component (the face is widest there).
fn projection_axes(positions: &[[f64; 3]], t: [u32; 3]) -> (usize, usize) {
    let [a, b, c] = t.map(|v| DVec3::from(positions[v as usize]));
    let n = (b - a).cross(c - a).abs().to_array();
    let axis = (0..3).max_by(|&i, &j| n[i].total_cmp(&n[j])).unwrap_or(2);
    ((axis + 1) % 3, (axis + 2) % 3)
}

/// Whether the segments `ends[0] ends[1]` and `ends[2] ends[3]`, projected on `axes`, cross
/// (each one's ends strictly on either side of the other's line), in `f64` with a margin of
/// `10⁻¹⁰` of the products; `None` within it. An end on the other's line (within the margin)
/// but clearly beyond that segment's ends is no crossing: the segments of two coplanar faces of
/// one shell (a square's two triangles) lie on one line.
fn segments_cross(ends: [[f64; 3]; 4], (i, j): (usize, usize)) -> Option<bool> {
    let flat = |p: [f64; 3]| [p[i], p[j]];
    let [p, q, r, s] = ends.map(flat);
    // Whether the segment `c d` crosses the line of `a b` strictly (`Some(true)`), stays on
    // one side or meets the line outside `a b` (`Some(false)`), or cannot be told.
    let meets_line = |a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]| {
        let u = [b[0] - a[0], b[1] - a[1]];
        let side = |x: [f64; 2]| {
            let (l, r) = (u[0] * (x[1] - a[1]), u[1] * (x[0] - a[0]));
            let det = l - r;
            (det.abs() > 1e-10 * (l.abs() + r.abs())).then_some(det > 0.0)
        };
        let along = |x: [f64; 2]| {
            ((x[0] - a[0]) * u[0] + (x[1] - a[1]) * u[1]) / (u[0] * u[0] + u[1] * u[1])
        };
        let beyond = |t: f64| !(-1e-9..=1.0 + 1e-9).contains(&t);
        match (side(c), side(d)) {
            (Some(x), Some(y)) => Some(x != y),
            // Both on the line: apart unless they overlap along it.
            (None, None) => {
                let (tc, td) = (along(c), along(d));
                let apart = (tc < -1e-9 && td < -1e-9) || (tc > 1.0 + 1e-9 && td > 1.0 + 1e-9);
                apart.then_some(false)
            }
            (None, Some(_)) => beyond(along(c)).then_some(false),
            (Some(_), None) => beyond(along(d)).then_some(false),
        }
    };
    if !meets_line(p, q, r, s)? {
        return Some(false);
    }
    meets_line(r, s, p, q)
}

/// Where the planes of three faces meet (in `f64`: Cramer's rule on their normals).
fn triple_point(positions: &[[f64; 3]], faces: [[u32; 3]; 3]) -> [f64; 3] {
    let planes = faces.map(|t| {
        let [a, b, c] = t.map(|v| DVec3::from(positions[v as usize]));
        let n = (b - a).cross(c - a);
        (n, n.dot(a))
    });
    let [(n1, d1), (n2, d2), (n3, d3)] = planes;
    let det = n1.dot(n2.cross(n3));
    ((d1 * n2.cross(n3) + d2 * n3.cross(n1) + d3 * n1.cross(n2)) / det).to_array()
}

/// Whether `p` lies strictly inside the triangle `t` projected on the axes `(i, j)` (exact, on
/// the coordinates as they are).
fn strictly_inside(t: [[f64; 3]; 3], p: [f64; 3], axes: (usize, usize)) -> bool {
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let Some(fx) = common_fixed_point(&[t[0], t[1], t[2], p], bits) else {
        return false;
    };
    let orient2 = <[i128; 3]>::orient2;
    let s = orient2(fx[0], fx[1], fx[2], axes);
    s != 0 && (0..3).all(|k| orient2(fx[k], fx[(k + 1) % 3], fx[3], axes) == s)
}

/// `w` just in front of the face `piece` (an input face, or a piece of the input face `face`;
/// `boxes`: the input faces' bounding boxes),
/// or `None` when it is not certified (step 3 of the module documentation).
///
/// Two points `q±` on either side of `face`'s plane (exact signs), a thousandth of the piece's
/// inradius from its centroid along the normal, are joined by a segment that meets `face` and
/// no other input face (exact tests): so `w(q₋) − w(q₊)` is the one jump across `face`, at a
/// point of the piece (the segment is much closer to the centroid than the piece's edges are),
/// and `w` in front is the value on the positive side. A sliver piece is not used.
fn front_winding(
    wn: &WindingNumber,
    all_positions: &[[f64; 3]],
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    boxes: &[([f64; 3], [f64; 3])],
    piece: [u32; 3],
    face: usize,
) -> Option<i64> {
    let corners = triangles[face].map(|v| positions[v as usize]);
    let [a, b, c] = corners.map(DVec3::from);
    let [x, y, z] = piece.map(|v| DVec3::from(all_positions[v as usize]));
    let n = (b - a).cross(c - a).normalize();
    let perimeter = (y - x).length() + (z - y).length() + (x - z).length();
    let inradius = (y - x).cross(z - x).length() / perimeter;
    if inradius.partial_cmp(&(1e-6 * perimeter)) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let centroid = (x + y + z) / 3.0;
    let delta = 1e-3 * inradius;
    let (plus, minus) = (
        (centroid + delta * n).to_array(),
        (centroid - delta * n).to_array(),
    );
    // The input faces whose boxes meet the segment's (widened: the boxes are in `f64`), in one
    // fixed-point scale with `face`'s corners and the two points (exact predicates do not
    // depend on the scale).
    let margin = 2.0 * delta;
    let near: Vec<usize> = (0..triangles.len())
        .filter(|&g| {
            let (lo, hi) = boxes[g];
            g != face
                && (0..3).all(|k| {
                    lo[k] <= plus[k].max(minus[k]) + margin
                        && plus[k].min(minus[k]) - margin <= hi[k]
                })
        })
        .collect();
    let mut local: Vec<[f64; 3]> = vec![corners[0], corners[1], corners[2], plus, minus];
    local.extend(
        near.iter()
            .flat_map(|&g| triangles[g].map(|v| positions[v as usize])),
    );
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let fx = common_fixed_point(&local, bits)?;
    let (f, qp, qm) = ([fx[0], fx[1], fx[2]], fx[3], fx[4]);
    let orient = <[i128; 3]>::orient;
    let (sp, sm) = (orient(f[0], f[1], f[2], qp), orient(f[0], f[1], f[2], qm));
    if sp == 0 || sm != -sp || !segment_meets_triangle(qp, qm, f) {
        return None;
    }
    let crossed = |g: usize| {
        let t = [fx[5 + 3 * g], fx[6 + 3 * g], fx[7 + 3 * g]];
        segment_meets_triangle(qp, qm, t)
    };
    if (0..near.len()).any(crossed) {
        return None;
    }
    let (w_plus, w_minus) = (wn.eval(plus).round() as i64, wn.eval(minus).round() as i64);
    // Up against the normal, `w` grows by one across `face`.
    let (front, back) = if sp > 0 {
        (w_plus, w_minus)
    } else {
        (w_minus, w_plus)
    };
    (back == front + 1).then_some(front)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cube and a tetrahedron poking one corner through its top face: the corner inside the
    /// cube and the part of the face inside the tetrahedron are patches of pieces only, which
    /// take their values across the curve when only uncut faces are read; the cut is the same.
    #[test]
    fn patches_of_pieces_take_their_value_across_the_curve() {
        let cube = crate::testing::unit_cube(false);
        let mut positions = cube.positions().to_vec();
        let mut triangles = cube.triangles().to_vec();
        let tip = [0.5131, 0.4727, 1.1213];
        let base = [
            [0.2113, 0.3019, 0.6871],
            [0.7927, 0.2531, 0.7213],
            [0.5519, 0.8173, 0.7037],
        ];
        let n = positions.len() as u32;
        positions.push(tip);
        positions.extend(base);
        // Outward: the base seen from below is clockwise.
        triangles.extend([
            [n, n + 1, n + 2],
            [n, n + 2, n + 3],
            [n, n + 3, n + 1],
            [n + 1, n + 3, n + 2],
        ]);
        let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
        let fixed = common_fixed_point(&positions, bits).unwrap();
        let read = cut_labelling_pieces(&positions, &fixed, &triangles, 0.0, true).unwrap();
        let across = cut_labelling_pieces(&positions, &fixed, &triangles, 0.0, false).unwrap();
        assert_eq!(read.triangles, across.triangles);
        assert_eq!(read.positions, across.positions);
        // The tetrahedron's three faces through the tip are cut; the top face's two triangles
        // may be cut or not, by where the curve runs.
        assert!(read.counts.cut_faces >= 4, "{:?}", read.counts);
        assert!(read.counts.removed_faces > 0);
    }
}
