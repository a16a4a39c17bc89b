//! Faces that overlap in one plane, replaced by what they add up to there: a part standing on a
//! bed's plate (its bottom face on the plate's top face, facing it), a fold of a surface onto
//! itself, two exports of one flat region.
//!
//! Such faces self-intersect in a way the cut ([`super::cut_intersections`]) does not take
//! (coplanar, touching along edges), and the lattice remesh rounds every sharp feature of an
//! input that is otherwise a clean solid. But `w` depends on the faces of one plane only
//! through their sum as a 2-chain: at each point of the plane, the number of faces covering it
//! counted `+1` or `−1` by orientation (their solid angles add up, and a point covered by an
//! up and a down face sees their angles cancel). So the faces of one plane may be replaced by
//! any faces with the same coverage, and `w` does not change off the plane:
//!
//! 1. **Groups.** Pairs of faces that meet and lie in one plane (exact:
//!    [`intersecting_pairs_wide`], every corner of one on the other's plane) are joined into
//!    groups; each group lies in one plane, projected on the two axes of its largest normal
//!    component.
//! 2. **Arrangement.** Every edge of a group's faces is split where another of its edges
//!    crosses it (a new vertex, the exact crossing rounded to `f64` along the edge) or ends on
//!    it (an input vertex; exact orientations decide crossing, touching and overlap). One
//!    exact point crossed by three edges is rounded on each of them: crossings within
//!    [`COINCIDENT`] of the group's size are one vertex.
//! 3. **Coverage.** The group's vertices and those pieces of edges are triangulated with the
//!    pieces as constraints (spade's constrained Delaunay triangulation); every triangle lies
//!    inside or outside each face of the group, so its coverage is the sum of the orientations
//!    of the faces that contain its centroid (an `f64` test with a margin; a centroid within it
//!    of an edge, and the whole replacement is refused).
//! 4. **Faces.** A triangle of coverage `±1` becomes a face of that orientation, `0` none;
//!    `±2` or more is refused (the surface would be doubled there). Contact walls, where a
//!    part's face lies on another's with opposite orientations, have coverage 0 and vanish.
//! 5. **Neighbours.** A face outside the groups with an edge that was split in step 2 is split
//!    at the same vertices ([`super::exact_repair`]'s split), so the surface stays closed.
//!
//! Nothing here is trusted: the caller proves the result as any kept input (closed, manifold,
//! no self-intersection, `w = 0` in front of every face and `1` behind, exactly, on the new
//! coordinates). The solid is the input's up to the rounding of the crossing points (each a
//! few units in the last place from the exact one), as for the cut; where no edges cross
//! properly, every vertex is an input vertex and the solid is the input's exactly.

use std::collections::HashMap;

use glam::DVec3;
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};

use super::exact_repair;
use super::intersect::{ExactPoint, intersecting_pairs_wide};
use super::report::{find, union};

/// Crossings closer than this fraction of their group's size are one point (module
/// documentation, step 2): far above the rounding of one crossing (a few ulps), far below any
/// feature of a mesh.
pub const COINCIDENT: f64 = 1e-12;

/// At most this many intersecting pairs are looked at (the corpus has at most 135,853).
pub const MAX_PAIRS: usize = 1_000_000;

/// What [`merge_coplanar_overlaps`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
// Counts grow as the repairs do: built by this crate only, read by fields.
#[non_exhaustive]
pub struct CoplanarCounts {
    /// Groups of overlapping faces in one plane.
    pub planes: usize,
    /// Faces of those groups replaced.
    pub faces: usize,
    /// Faces made for them.
    pub pieces: usize,
    /// New vertices, where two of their edges cross.
    pub crossings: usize,
    /// Faces outside the groups split at vertices on their edges.
    pub split_neighbours: usize,
}

impl CoplanarCounts {
    /// Whether nothing was changed.
    pub fn is_empty(&self) -> bool {
        *self == CoplanarCounts::default()
    }
}

impl std::fmt::Display for CoplanarCounts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} faces overlapping in {} plane{} replaced by {} ({} new vertices where their \
             edges cross, {} neighbouring faces split)",
            self.faces,
            self.planes,
            if self.planes == 1 { "" } else { "s" },
            self.pieces,
            self.crossings,
            self.split_neighbours
        )
    }
}

/// The result of [`merge_coplanar_overlaps`].
#[derive(Clone, Debug)]
pub struct Merged {
    /// The input's vertex positions, then the crossings (unreferenced ones kept: indices of
    /// the input stay valid).
    pub positions: Vec<[f64; 3]>,
    /// The faces outside the groups (split where needed), then the groups' new faces.
    pub triangles: Vec<[u32; 3]>,
    /// What changed.
    pub counts: CoplanarCounts,
}

/// The surface `positions` (with their exact fixed-point coordinates `fixed`), `triangles`
/// (no zero-area face), with every group of faces that overlap in one plane replaced by faces
/// of the same coverage (module documentation); `None` when no faces overlap in a plane, the
/// intersection search exceeds `budget` or [`MAX_PAIRS`], a group is refused, or no face is
/// left.
pub fn merge_coplanar_overlaps(
    positions: &[[f64; 3]],
    fixed: &[[i128; 3]],
    triangles: &[[u32; 3]],
    budget: u64,
) -> Option<Merged> {
    let pairs = intersecting_pairs_wide(fixed, triangles, budget, MAX_PAIRS).ok()??;
    let corners = |f: u32| triangles[f as usize].map(|v| fixed[v as usize]);
    let mut parent: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut any = false;
    for &(f, g) in &pairs {
        let (s, t) = (corners(f), corners(g));
        if s.iter()
            .all(|&p| <[i128; 3]>::orient(t[0], t[1], t[2], p) == 0)
        {
            union(&mut parent, f, g);
            any = true;
        }
    }
    if !any {
        return None;
    }
    let mut groups: HashMap<u32, Vec<u32>> = HashMap::new();
    for f in 0..triangles.len() as u32 {
        let root = find(&mut parent, f);
        groups.entry(root).or_default().push(f);
    }
    let mut groups: Vec<Vec<u32>> = groups.into_values().filter(|g| g.len() > 1).collect();
    groups.sort_unstable();
    let mut out_positions = positions.to_vec();
    let mut in_group = vec![false; triangles.len()];
    let mut pieces = Vec::new();
    let mut junctions: HashMap<(u32, u32), Vec<u32>> = HashMap::new();
    let mut counts = CoplanarCounts {
        planes: groups.len(),
        ..CoplanarCounts::default()
    };
    let mut work = 0u64;
    for group in &groups {
        for &f in group {
            in_group[f as usize] = true;
        }
        let plane = Plane::of(fixed, triangles[group[0] as usize])?;
        let before = out_positions.len();
        let arrangement = arrangement(
            &plane,
            fixed,
            &mut out_positions,
            triangles,
            group,
            budget - work,
        )?;
        work += arrangement.tested;
        if work > budget {
            return None;
        }
        // Distinct crossings (those that are one point count once).
        let mut crossings: Vec<u32> = arrangement
            .inside
            .iter()
            .flat_map(|(_, inside)| inside.iter().copied())
            .filter(|&v| v as usize >= before)
            .collect();
        crossings.sort_unstable();
        crossings.dedup();
        counts.crossings += crossings.len();
        let (made, inside) =
            covered_triangles(&plane, &out_positions, triangles, group, &arrangement)?;
        counts.faces += group.len();
        counts.pieces += made.len();
        pieces.extend(made);
        for (edge, inside) in inside {
            if !inside.is_empty() {
                junctions.insert(edge, inside);
            }
        }
    }
    let outside: Vec<[u32; 3]> = triangles
        .iter()
        .zip(&in_group)
        .filter(|&(_, &g)| !g)
        .map(|(t, _)| *t)
        .collect();
    let (mut out_triangles, split) = exact_repair::split_at_junctions(&outside, &junctions);
    counts.split_neighbours = split;
    out_triangles.extend(pieces);
    // Nothing left (a closed surface folded flat): its solid is empty, which a remesh says
    // as well; not an input to keep.
    if out_triangles.is_empty() {
        return None;
    }
    Some(Merged {
        positions: out_positions,
        triangles: out_triangles,
        counts,
    })
}

/// The plane of a group: the axes `(i, j)` it is projected on, those after a nonzero normal
/// component `k` in cyclic order (so a face's orientation there is the sign of its normal's
/// component `k`).
struct Plane {
    axes: (usize, usize),
}

impl Plane {
    fn of(fixed: &[[i128; 3]], t: [u32; 3]) -> Option<Plane> {
        let [a, b, c] = t.map(|v| fixed[v as usize]);
        let k = <[i128; 3]>::projection_axis(a, b, c)?;
        Some(Plane {
            axes: ((k + 1) % 3, (k + 2) % 3),
        })
    }

    fn project(&self, p: [f64; 3]) -> [f64; 2] {
        [p[self.axes.0], p[self.axes.1]]
    }
}

/// An edge `(min, max)` and the vertices strictly inside it, from `min` to `max`.
type EdgeVertices = ((u32, u32), Vec<u32>);

/// Step 2: the group's edges, and the vertices strictly inside each (ordered from its lower
/// vertex index to its higher one).
struct Arrangement {
    /// Each edge of the group's faces and the vertices inside it.
    inside: Vec<EdgeVertices>,
    /// Pairs of edges looked at.
    tested: u64,
}

/// The arrangement of the edges of the faces `group` (module documentation, step 2); new
/// vertices are appended to `positions`. `None` when more than `budget` pairs of edges
/// overlap along the first axis.
fn arrangement(
    plane: &Plane,
    fixed: &[[i128; 3]],
    positions: &mut Vec<[f64; 3]>,
    triangles: &[[u32; 3]],
    group: &[u32],
    budget: u64,
) -> Option<Arrangement> {
    let edges = exact_repair::edges_of(triangles, group);
    let p = |v: u32| fixed[v as usize];
    let axes = plane.axes;
    let range = |(a, b): (u32, u32), k: usize| {
        let (x, y) = (p(a)[k], p(b)[k]);
        (x.min(y), x.max(y))
    };
    let boxes: Vec<[(i128, i128); 2]> = edges
        .iter()
        .map(|&e| [range(e, axes.0), range(e, axes.1)])
        .collect();
    // Whether `v` lies strictly inside the edge `e` (exactly: collinear and strictly between
    // its ends along an axis on which they differ).
    let strictly_inside = |v: u32, e: (u32, u32)| {
        let axis = if p(e.0)[axes.0] != p(e.1)[axes.0] {
            axes.0
        } else {
            axes.1
        };
        v != e.0 && v != e.1 && exact_repair::strictly_inside(p(v), p(e.0), p(e.1), axis)
    };
    let mut inside: Vec<Vec<(f64, u32)>> = vec![Vec::new(); edges.len()];
    let along = |positions: &[[f64; 3]], (a, b): (u32, u32), v: u32| {
        let (pa, pb) = (
            DVec3::from(positions[a as usize]),
            DVec3::from(positions[b as usize]),
        );
        (DVec3::from(positions[v as usize]) - pa).dot(pb - pa)
    };
    // A sweep along the first axis: each edge meets the later ones whose range there starts
    // before its own ends.
    let mut order: Vec<usize> = (0..edges.len()).collect();
    order.sort_by_key(|&x| (boxes[x][0].0, x));
    let first_new = positions.len();
    let mut tested = 0u64;
    for (k, &x) in order.iter().enumerate() {
        for &y in &order[k + 1..] {
            let (bx, by) = (boxes[x], boxes[y]);
            if by[0].0 > bx[0].1 {
                break;
            }
            tested += 1;
            if tested > budget {
                return None;
            }
            if bx[1].1 < by[1].0 || by[1].1 < bx[1].0 {
                continue;
            }
            let (e, f) = (edges[x], edges[y]);
            // Touching: an end of one strictly inside the other (also where they overlap
            // along one line).
            let mut touching = false;
            for (v, edge, slot) in [(f.0, e, x), (f.1, e, x), (e.0, f, y), (e.1, f, y)] {
                if strictly_inside(v, edge) {
                    inside[slot].push((along(positions, edge, v), v));
                    touching = true;
                }
            }
            if touching || [e.0, e.1].iter().any(|v| *v == f.0 || *v == f.1) {
                continue;
            }
            let o = [
                <[i128; 3]>::orient2(p(e.0), p(e.1), p(f.0), axes),
                <[i128; 3]>::orient2(p(e.0), p(e.1), p(f.1), axes),
                <[i128; 3]>::orient2(p(f.0), p(f.1), p(e.0), axes),
                <[i128; 3]>::orient2(p(f.0), p(f.1), p(e.1), axes),
            ];
            if o[0] * o[1] < 0 && o[2] * o[3] < 0 {
                let v = positions.len() as u32;
                positions.push(crossing(plane, positions, e, f));
                inside[x].push((along(positions, e, v), v));
                inside[y].push((along(positions, f, v), v));
            }
        }
    }
    let same = coincident(positions, first_new, &inside);
    let inside = edges
        .into_iter()
        .zip(inside)
        .map(|(e, mut list)| {
            list.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut list: Vec<u32> = list.into_iter().map(|(_, v)| same(v)).collect();
            list.dedup();
            (e, list)
        })
        .collect();
    Some(Arrangement { inside, tested })
}

/// One exact point can be the crossing of several pairs of edges (three edges through one
/// point, or two crossing at a vertex inside both), each rounded on its own edge: the vertex
/// each of the points inside the edges stands for, one per cluster within [`COINCIDENT`] of
/// the group's size (the input's vertex when there is one, else the first crossing).
fn coincident(
    positions: &[[f64; 3]],
    first_new: usize,
    inside: &[Vec<(f64, u32)>],
) -> impl Fn(u32) -> u32 + use<> {
    let mut points: Vec<u32> = inside.iter().flatten().map(|&(_, v)| v).collect();
    points.sort_unstable();
    points.dedup();
    let at = |v: u32| positions[v as usize];
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for &v in &points {
        for k in 0..3 {
            lo[k] = lo[k].min(at(v)[k]);
            hi[k] = hi[k].max(at(v)[k]);
        }
    }
    let size = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let eps = COINCIDENT * size;
    let mut by_x = points.clone();
    by_x.sort_by(|&a, &b| at(a)[0].total_cmp(&at(b)[0]).then(a.cmp(&b)));
    let mut rep: HashMap<u32, u32> = HashMap::new();
    let root = |rep: &HashMap<u32, u32>, mut v: u32| {
        while let Some(&r) = rep.get(&v) {
            v = r;
        }
        v
    };
    for (k, &a) in by_x.iter().enumerate() {
        for &b in &by_x[k + 1..] {
            if at(b)[0] - at(a)[0] > eps {
                break;
            }
            // Two input vertices are never one: only crossings are merged.
            if (a as usize) < first_new && (b as usize) < first_new {
                continue;
            }
            let d = (0..3)
                .map(|i| (at(a)[i] - at(b)[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            if d <= eps {
                let (ra, rb) = (root(&rep, a), root(&rep, b));
                if ra != rb {
                    rep.insert(ra.max(rb), ra.min(rb));
                }
            }
        }
    }
    move |v| root(&rep, v)
}

/// Where the edges `e` and `f` (crossing properly in the plane) cross: on `e`, at the
/// parameter of the crossing of their projections, in `f64`.
fn crossing(plane: &Plane, positions: &[[f64; 3]], e: (u32, u32), f: (u32, u32)) -> [f64; 3] {
    let at = |v: u32| DVec3::from(positions[v as usize]);
    let (a, b, c, d) = (at(e.0), at(e.1), at(f.0), at(f.1));
    let two = |p: DVec3| plane.project(p.to_array());
    let cross = |u: [f64; 2], v: [f64; 2]| u[0] * v[1] - u[1] * v[0];
    let sub = |u: [f64; 2], v: [f64; 2]| [u[0] - v[0], u[1] - v[1]];
    let (a2, b2, c2, d2) = (two(a), two(b), two(c), two(d));
    let t = cross(sub(c2, a2), sub(d2, c2)) / cross(sub(b2, a2), sub(d2, c2));
    (a + t.clamp(0.0, 1.0) * (b - a)).to_array()
}

/// Steps 3 and 4: the faces that replace `group`, from its `arrangement`, and the vertices
/// inside each of its edges as the faces use them (a crossing that rounded onto another
/// vertex's position is that vertex).
fn covered_triangles(
    plane: &Plane,
    positions: &[[f64; 3]],
    triangles: &[[u32; 3]],
    group: &[u32],
    arrangement: &Arrangement,
) -> Option<(Vec<[u32; 3]>, Vec<EdgeVertices>)> {
    let two = |v: u32| plane.project(positions[v as usize]);
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut vertices: Vec<u32> = arrangement
        .inside
        .iter()
        .flat_map(|((a, b), inside)| [*a, *b].into_iter().chain(inside.iter().copied()))
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    // The vertex each triangulation vertex is: the first of those inserted at its position.
    let mut vertex_of: Vec<u32> = Vec::with_capacity(vertices.len());
    let mut handle_of: HashMap<u32, usize> = HashMap::with_capacity(vertices.len());
    let mut handles = Vec::with_capacity(vertices.len());
    for &v in &vertices {
        let [x, y] = two(v);
        let h = cdt.insert(Point2::new(x, y)).ok()?;
        if h.index() == vertex_of.len() {
            vertex_of.push(v);
            handles.push(h);
        }
        handle_of.insert(v, h.index());
    }
    let same = |v: u32| vertex_of[handle_of[&v]];
    // Step 3. Across an edge `u → v` of a face (in the face's own order), the face's coverage
    // is one more on the left than on the right: `+1` inside and 0 outside when the face is
    // counter-clockwise in the projection (inside on the left), 0 and `−1` when clockwise.
    // Summed over the group, each piece `x → y` of an edge has a jump `left − right`; the
    // coverage is then 0 outside the triangulation's hull and follows from face to face.
    let mut multiplicity: HashMap<(u32, u32), i32> = HashMap::new();
    for &f in group {
        let t = triangles[f as usize];
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            *multiplicity.entry((u.min(v), u.max(v))).or_default() += if u < v { 1 } else { -1 };
        }
    }
    let mut resolved = Vec::with_capacity(arrangement.inside.len());
    // Each piece as `(x, y)` with `x < y` (triangulation indices), and its jump from `x` to `y`.
    let mut pieces: HashMap<(usize, usize), i32> = HashMap::new();
    for ((a, b), inside) in &arrangement.inside {
        let mut chain: Vec<u32> = std::iter::once(*a)
            .chain(inside.iter().copied())
            .chain(std::iter::once(*b))
            .map(same)
            .collect();
        chain.dedup();
        let m = multiplicity.get(&(*a, *b)).copied().unwrap_or(0);
        for w in chain.windows(2) {
            let (x, y) = (handle_of[&w[0]], handle_of[&w[1]]);
            *pieces.entry((x.min(y), x.max(y))).or_default() += if x < y { m } else { -m };
        }
        let inner: Vec<u32> = chain
            .iter()
            .copied()
            .filter(|&v| v != same(*a) && v != same(*b))
            .collect();
        resolved.push(((*a, *b), inner));
    }
    let mut pieces: Vec<((usize, usize), i32)> = pieces.into_iter().collect();
    pieces.sort_unstable();
    // Each piece as the triangulation made it: its edges in order, or through a vertex that
    // rounding put on it, several.
    let mut jump: HashMap<(usize, usize), i32> = HashMap::new();
    for ((x, y), m) in pieces {
        // No jump: the same coverage on both sides, nothing to keep apart.
        if m == 0 {
            continue;
        }
        // Empty (and nothing changed) when the piece would cross another one: rounding moved
        // a crossing across a piece.
        let edges = cdt.try_add_constraint(handles[x], handles[y]);
        if edges.is_empty() {
            return None;
        }
        let (px, py) = (
            cdt.vertex(handles[x]).position(),
            cdt.vertex(handles[y]).position(),
        );
        for e in edges {
            let e = cdt.directed_edge(e);
            let (from, to) = (e.from(), e.to());
            let (pf, pt) = (from.position(), to.position());
            let forward = (pt.x - pf.x) * (py.x - px.x) + (pt.y - pf.y) * (py.y - px.y) > 0.0;
            let (f, t) = (from.fix().index(), to.fix().index());
            let m = if forward { m } else { -m };
            *jump.entry((f, t)).or_default() += m;
            *jump.entry((t, f)).or_default() -= m;
        }
    }
    let jump_of = |e: spade::handles::DirectedEdgeHandle<'_, _, _, _, _>| {
        let (x, y) = (e.from().fix().index(), e.to().fix().index());
        jump.get(&(x, y)).copied().unwrap_or(0)
    };
    let mut coverage: Vec<Option<i32>> = vec![None; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for edge in cdt.convex_hull() {
        // The right face's coverage is the left one's minus the jump.
        let (inner, value) = match (edge.face().as_inner(), edge.rev().face().as_inner()) {
            (None, Some(inner)) => (inner, -jump_of(edge)),
            (Some(inner), None) => (inner, jump_of(edge)),
            _ => return None,
        };
        let slot = &mut coverage[inner.fix().index()];
        match *slot {
            Some(known) if known != value => return None,
            Some(_) => {}
            None => {
                *slot = Some(value);
                stack.push(inner.fix());
            }
        }
    }
    while let Some(face) = stack.pop() {
        let here = coverage[face.index()]?;
        for edge in cdt.face(face).adjacent_edges() {
            let edge = if edge.face().fix().index() == face.index() {
                edge
            } else {
                edge.rev()
            };
            let value = here - jump_of(edge);
            match edge.rev().face().as_inner() {
                None if value != 0 => return None,
                None => {}
                Some(next) => match coverage[next.fix().index()] {
                    Some(known) if known != value => return None,
                    Some(_) => {}
                    None => {
                        coverage[next.fix().index()] = Some(value);
                        stack.push(next.fix());
                    }
                },
            }
        }
    }
    // Step 4. Spade's faces are counter-clockwise in the projection: the orientation of
    // coverage +1.
    let mut out = Vec::new();
    for face in cdt.inner_faces() {
        let ids = face.vertices().map(|h| vertex_of[h.fix().index()]);
        match coverage[face.fix().index()]? {
            0 => {}
            1 => out.push(ids),
            -1 => out.push([ids[0], ids[2], ids[1]]),
            _ => return None,
        }
    }
    Some((out, resolved))
}
