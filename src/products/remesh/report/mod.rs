//! What is measured about a remeshed surface: its topology (closed, edge- and vertex-manifold,
//! oriented, Euler characteristic, components; from the triangles alone, so it serves any other
//! mesh as well), the sampled Hausdorff distance to the input (to where the input bounds the
//! solid, and to a tessellation standing for a curved input) and the occupancy agreement; and
//! the whole report of one run, [`RemeshReport`] (`measure.rs`), which `gwn remesh` prints and
//! the Python module returns.

use rayon::prelude::*;

mod measure;
mod timing;
pub use measure::{
    AGREEMENT_SEED, DistanceReference, HAUSDORFF_SEED, MAX_SAMPLES, RemeshReport, ReportPhase,
    SIDE_TEST_OFFSET_CELLS, TooManySamples,
};
pub use timing::{PhaseClock, PhaseSeconds};

/// The topology of a triangle surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TopologyReport {
    /// Vertices used by some triangle.
    pub vertices: usize,
    /// Triangles.
    pub faces: usize,
    /// Distinct undirected edges.
    pub edges: usize,
    /// Edges with one triangle.
    pub boundary_edges: usize,
    /// Edges with more than two triangles.
    pub nonmanifold_edges: usize,
    /// Vertices whose link (the ring of their triangles) is not one cycle or path.
    pub nonmanifold_vertices: usize,
    /// Two-triangle edges traversed in the same direction by both (orientation flips).
    pub misoriented_edges: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate_faces: usize,
    /// Connected components (triangles sharing a vertex are connected).
    pub components: usize,
    /// `V − E + F`.
    pub euler_characteristic: i64,
    /// No boundary edge.
    pub closed: bool,
    /// No edge with more than two triangles.
    pub edge_manifold: bool,
    /// Every vertex link is one cycle or path.
    pub vertex_manifold: bool,
    /// No misoriented edge.
    pub oriented: bool,
}

impl TopologyReport {
    /// The report of `triangles` (indices into `positions`, which only sizes the tables).
    ///
    /// Each undirected edge is counted at its lower vertex, from a list of the edges there
    /// (higher vertex, direction), so the vertices are independent and run in parallel: a hash
    /// table of the edges made this serial, and it checks every raw surface the simplifier
    /// takes (a million faces at res 256).
    pub fn of(positions: &[[f64; 3]], triangles: &[[u32; 3]]) -> TopologyReport {
        let n = positions.len();
        let mut r = TopologyReport {
            faces: triangles.len(),
            ..TopologyReport::default()
        };
        r.degenerate_faces = triangles
            .par_iter()
            .filter(|t| t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            .count();
        // Edge `(a, b)` of a triangle, at vertex min(a, b): (max(a, b), whether a < b).
        let at_lower = per_vertex(n, triangles, |t, k| {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            (a.min(b), (a.max(b), a < b))
        });
        let mut used = vec![false; n];
        for t in triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        r.vertices = used.iter().filter(|&&u| u).count();
        let counts = (0..n)
            .into_par_iter()
            .map_init(Vec::new, |list: &mut Vec<(u32, bool)>, v| {
                list.clear();
                list.extend_from_slice(at_lower.of(v));
                list.sort_unstable();
                let mut c = EdgeCounts::default();
                for run in list.chunk_by(|x, y| x.0 == y.0) {
                    c.edges += 1;
                    match run.len() {
                        1 => c.boundary += 1,
                        // Sorted: `false` first, so one of each is `[false, true]`.
                        2 => c.misoriented += usize::from(run[0].1 == run[1].1),
                        _ => c.nonmanifold += 1,
                    }
                }
                c
            })
            .reduce(EdgeCounts::default, EdgeCounts::add);
        r.edges = counts.edges;
        r.boundary_edges = counts.boundary;
        r.misoriented_edges = counts.misoriented;
        r.nonmanifold_edges = counts.nonmanifold;
        let mut parent: Vec<u32> = (0..n as u32).collect();
        for v in 0..n {
            for &(w, _) in at_lower.of(v) {
                union(&mut parent, v as u32, w);
            }
        }
        r.components = (0..n as u32)
            .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
            .count();
        r.nonmanifold_vertices = nonmanifold_vertices(n, triangles);
        r.euler_characteristic = r.vertices as i64 - r.edges as i64 + r.faces as i64;
        r.closed = r.boundary_edges == 0;
        r.edge_manifold = r.nonmanifold_edges == 0;
        r.vertex_manifold = r.nonmanifold_vertices == 0;
        r.oriented = r.misoriented_edges == 0;
        r
    }

    /// The report as one JSON object (`extra` are further `"key": value` members, already
    /// formatted, appended as they are).
    pub fn to_json(&self, extra: &[(&str, String)]) -> String {
        let mut s = format!(
            "{{\"closed\": {}, \"edge_manifold\": {}, \"vertex_manifold\": {}, \"oriented\": {}, \
             \"euler_characteristic\": {}, \"components\": {}, \"vertices\": {}, \"faces\": {}, \
             \"edges\": {}, \"boundary_edges\": {}, \"nonmanifold_edges\": {}, \
             \"nonmanifold_vertices\": {}, \"misoriented_edges\": {}, \"degenerate_faces\": {}",
            self.closed,
            self.edge_manifold,
            self.vertex_manifold,
            self.oriented,
            self.euler_characteristic,
            self.components,
            self.vertices,
            self.faces,
            self.edges,
            self.boundary_edges,
            self.nonmanifold_edges,
            self.nonmanifold_vertices,
            self.misoriented_edges,
            self.degenerate_faces
        );
        for (k, v) in extra {
            s.push_str(&format!(", \"{k}\": {v}"));
        }
        s.push('}');
        s
    }
}

impl std::fmt::Display for TopologyReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let yes = |b: bool| if b { "yes" } else { "NO" };
        write!(
            f,
            "{} faces, {} vertices; closed: {} ({} boundary edges); edge-manifold: {} ({}); \
             vertex-manifold: {} ({}); oriented: {} ({} flipped edges); Euler characteristic {}; \
             {} component(s)",
            self.faces,
            self.vertices,
            yes(self.closed),
            self.boundary_edges,
            yes(self.edge_manifold),
            self.nonmanifold_edges,
            yes(self.vertex_manifold),
            self.nonmanifold_vertices,
            yes(self.oriented),
            self.misoriented_edges,
            self.euler_characteristic,
            self.components
        )
    }
}

pub(in crate::products::remesh) fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let p = parent[parent[v as usize] as usize];
        parent[v as usize] = p;
        v = p;
    }
    v
}

pub(in crate::products::remesh) fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra as usize] = rb;
    }
}

/// Edge counts of [`TopologyReport::of`] at some vertices.
#[derive(Clone, Copy, Default)]
struct EdgeCounts {
    edges: usize,
    boundary: usize,
    misoriented: usize,
    nonmanifold: usize,
}

impl EdgeCounts {
    fn add(self, o: EdgeCounts) -> EdgeCounts {
        EdgeCounts {
            edges: self.edges + o.edges,
            boundary: self.boundary + o.boundary,
            misoriented: self.misoriented + o.misoriented,
            nonmanifold: self.nonmanifold + o.nonmanifold,
        }
    }
}

/// Items listed per vertex (compressed rows): `item(t, k)` gives the vertex and the item for
/// corner `k` of triangle `t`, three per triangle.
struct PerVertex<T> {
    start: Vec<usize>,
    items: Vec<T>,
}

impl<T: Copy + Default> PerVertex<T> {
    fn of(&self, v: usize) -> &[T] {
        &self.items[self.start[v]..self.start[v + 1]]
    }
}

fn per_vertex<T: Copy + Default>(
    n: usize,
    triangles: &[[u32; 3]],
    item: impl Fn([u32; 3], usize) -> (u32, T),
) -> PerVertex<T> {
    let mut start = vec![0usize; n + 1];
    for t in triangles {
        for k in 0..3 {
            start[item(*t, k).0 as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut items = vec![T::default(); start[n]];
    for t in triangles {
        for k in 0..3 {
            let (v, x) = item(*t, k);
            items[fill[v as usize]] = x;
            fill[v as usize] += 1;
        }
    }
    PerVertex { start, items }
}

/// Vertices whose link is not a single cycle or path: the opposite edges of the vertex's
/// triangles must form one connected graph with every node of degree at most 2.
fn nonmanifold_vertices(n: usize, triangles: &[[u32; 3]]) -> usize {
    let opposite = per_vertex(n, triangles, |t, k| {
        (t[k], (t[(k + 1) % 3], t[(k + 2) % 3]))
    });
    (0..n)
        .into_par_iter()
        .map_init(LinkScratch::default, |s, v| {
            let link = opposite.of(v);
            usize::from(!link.is_empty() && !s.is_one_cycle_or_path(link))
        })
        .sum()
}

/// Buffers of [`nonmanifold_vertices`], reused across the vertices of one thread.
#[derive(Default)]
struct LinkScratch {
    nodes: Vec<u32>,
    degree: Vec<u32>,
    parent: Vec<u32>,
}

impl LinkScratch {
    /// Whether the edges `link` form one connected graph with every node of degree at most 2.
    fn is_one_cycle_or_path(&mut self, link: &[(u32, u32)]) -> bool {
        let LinkScratch {
            nodes,
            degree,
            parent,
        } = self;
        nodes.clear();
        for &(a, b) in link {
            nodes.push(a);
            nodes.push(b);
        }
        nodes.sort_unstable();
        nodes.dedup();
        degree.clear();
        degree.resize(nodes.len(), 0);
        parent.clear();
        parent.extend(0..nodes.len() as u32);
        let local = |x: u32| nodes.binary_search(&x).unwrap_or(0) as u32;
        for &(a, b) in link {
            let (la, lb) = (local(a), local(b));
            degree[la as usize] += 1;
            degree[lb as usize] += 1;
            union(parent, la, lb);
        }
        let roots = (0..nodes.len() as u32)
            .filter(|&i| find(parent, i) == i)
            .count();
        roots == 1 && degree.iter().all(|&d| d <= 2)
    }
}

/// Occupancy agreement: of `samples` points drawn uniformly (seeded) in `bounds`, the fraction
/// with the same class `w > ½` under `input` and `output` (`None` when `samples` is 0). Points
/// near the surface count too, so at cell size `h` expect a shortfall of the order of
/// `area · h / volume`.
pub fn occupancy_agreement<A, B>(
    input: &A,
    output: &B,
    bounds: crate::base::bounding_box::BoundingBox,
    samples: usize,
    seed: u64,
) -> Option<f64>
where
    A: crate::eval::Evaluator + ?Sized,
    B: crate::eval::Evaluator + ?Sized,
{
    if samples == 0 {
        return None;
    }
    let mut rng = crate::base::splitmix::SplitMix64(seed);
    let mut next = move || rng.unit();
    let points: Vec<[f64; 3]> = (0..samples)
        .map(|_| std::array::from_fn(|a| bounds.min[a] + next() * (bounds.max[a] - bounds.min[a])))
        .collect();
    let wi = input.eval_batch(&points);
    let wo = output.eval_batch(&points);
    let agree = wi
        .iter()
        .zip(&wo)
        .filter(|(a, b)| super::inside(**a) == super::inside(**b))
        .count();
    Some(agree as f64 / samples as f64)
}

/// The winding number of an empty surface: 0 everywhere. The output side of
/// [`occupancy_agreement`] when a remesh is empty, and the evaluator that
/// [`SignedDistance`](crate::products::sdf::SignedDistance) needs and the unsigned distance of
/// [`hausdorff_distance`] never asks.
pub struct NoSurface;

impl crate::eval::Evaluator for NoSurface {
    fn eval(&self, _q: [f64; 3]) -> f64 {
        0.0
    }
}

/// Symmetric Hausdorff distance between two triangle meshes, sampled: the largest distance from
/// a point of one to the other, over `samples` points per mesh drawn uniformly by area (seeded).
/// A lower bound of the true distance that converges to it as samples grow; `None` when either
/// mesh has no triangle.
pub fn hausdorff_distance(
    a: &crate::Mesh,
    b: &crate::Mesh,
    samples: usize,
    seed: u64,
) -> Option<f64> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let from_a: Vec<[f64; 3]> = surface_samples(&triangles_of(a), samples, seed)
        .into_iter()
        .map(|(p, _)| p)
        .collect();
    Some(farthest(&from_a, b).max(farthest_from_surface(b, a, samples, seed ^ 0x5bd1_e995)))
}

/// [`hausdorff_distance`] with the input's side restricted to where the input bounds the solid
/// `w > ½`: the remesher drops inner faces, double walls and the parts of self-intersecting
/// shells inside the solid because `w` says so, and the plain distance counts each of them as
/// a miss (cgal-mpi at res 256: 55.9 cells). An input sample on face `f` counts where `w` of
/// `input_w` at `p ± offset·n_f` (`n_f` the face's unit normal) is above ½ on one side only;
/// the output's samples are measured against the whole input (so that side is a lower bound of
/// the distance to the boundary part). The same seeds as [`hausdorff_distance`], so the two
/// share their samples.
pub fn hausdorff_to_solid_boundary<E: crate::eval::Evaluator + ?Sized>(
    input: &crate::Mesh,
    input_w: &E,
    output: &crate::Mesh,
    samples: usize,
    seed: u64,
    offset: f64,
) -> Option<BoundaryHausdorff> {
    if input.is_empty() || output.is_empty() {
        return None;
    }
    let triangles = triangles_of(input);
    let sampled = surface_samples(&triangles, samples, seed);
    let unit_normal = |t: &[[f64; 3]; 3]| {
        use crate::base::vec3::{cross, norm, sub};
        let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let l = norm(n);
        n.map(|c| c / l)
    };
    let sides: Vec<[f64; 3]> = sampled
        .iter()
        .flat_map(|&(p, f)| {
            let n = unit_normal(&triangles[f]);
            [1.0, -1.0].map(|s| std::array::from_fn(|k| p[k] + s * offset * n[k]))
        })
        .collect();
    let w = input_w.eval_batch(&sides);
    // Each input sample's distance once: its maximum over all samples is the plain distance's
    // input side, over the bounding ones this one's.
    let points: Vec<[f64; 3]> = sampled.iter().map(|&(p, _)| p).collect();
    let distances = distances_to(&points, output);
    let (mut all, mut bounding, mut count) = (0.0f64, 0.0f64, 0usize);
    for (d, w) in distances.iter().zip(w.chunks_exact(2)) {
        all = all.max(*d);
        if super::inside(w[0]) != super::inside(w[1]) {
            bounding = bounding.max(*d);
            count += 1;
        }
    }
    let output_side = farthest_from_surface(output, input, samples, seed ^ 0x5bd1_e995);
    Some(BoundaryHausdorff {
        distance: bounding.max(output_side),
        plain: all.max(output_side),
        boundary_fraction: count as f64 / sampled.len().max(1) as f64,
    })
}

/// A triangle mesh that stands for a curved input (a Bézier patch set or a trimmed B-rep model)
/// in [`hausdorff_to_solid_boundary`], with the longest parameter-grid segment it was built
/// with. A chord of length `L` on a curvature radius `R` is `L²/8R` off the surface: at half a
/// cell, under 1/32 of a cell where `R` is above a cell.
#[cfg(feature = "patch")]
#[derive(Clone, Debug)]
pub struct CurvedSurface {
    /// The tessellation (its own `w` makes the side tests: the samples lie on its faces, and
    /// its chords can be farther from the true surface than the tests' offset).
    pub mesh: crate::Mesh,
    /// The grid's spacing (world units): no patch's box diagonal over its grid steps exceeds it
    /// (a bound on the grid's segments unless a patch's arc is much longer than its box). Half
    /// a cell, or more where that would take more than [`MAX_CURVED_DISTANCE_TRIANGLES`].
    pub segment: f64,
}

/// Most triangles a [`CurvedSurface`] has: with the distance queries' hierarchy and the side
/// tests' evaluator a triangle costs ~700 bytes at the peak (the teapot at res 128, 0.92 M
/// triangles: 851 MB peak against the remesh's 84 MB; spring.step with half-cell segments,
/// 3.6 M: 1.45 GB against 0.19 GB), so finer tessellations get longer segments instead.
#[cfg(feature = "patch")]
pub const MAX_CURVED_DISTANCE_TRIANGLES: usize = 300_000;

/// The largest diagonal of a patch's control-point box.
#[cfg(feature = "patch")]
fn box_diagonal(points: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for x in points {
        for a in 0..3 {
            lo[a] = lo[a].min(x[a]);
            hi[a] = hi[a].max(x[a]);
        }
    }
    (0..3).map(|a| (hi[a] - lo[a]).powi(2)).sum::<f64>().sqrt()
}

/// The [`CurvedSurface`] that stands for a curved input in the report's distance
/// ([`patch_surface_for_distance`], [`step_surface_for_distance`]); `None` for meshes and point
/// clouds.
#[cfg(feature = "patch")]
pub fn curved_surface_for_distance(
    input: &crate::input::Input,
    cell_size: f64,
) -> Option<CurvedSurface> {
    match input {
        crate::input::Input::Patches(set) => patch_surface_for_distance(set, cell_size),
        #[cfg(feature = "io")]
        crate::input::Input::Step(model) => step_surface_for_distance(model, cell_size),
        _ => None,
    }
}

/// A Bézier patch set's [`CurvedSurface`]: `k × k` quads per patch
/// ([`crate::patch::tessellate::tessellate`], welded) with `k` such that the largest patch's
/// segments are at most half a cell, fewer where the budget says so. `None` for a cell size
/// that is not finite and positive, or a tessellation that is not a mesh.
#[cfg(feature = "patch")]
pub fn patch_surface_for_distance(
    set: &crate::patch::PatchSet,
    cell_size: f64,
) -> Option<CurvedSurface> {
    if !(cell_size.is_finite() && cell_size > 0.0) || set.patches().is_empty() {
        return None;
    }
    let largest = set
        .patches()
        .iter()
        .map(|p| box_diagonal(p.points()))
        .fold(0.0f64, f64::max);
    let fine = (2.0 * largest / cell_size).ceil().max(1.0);
    let budget = (MAX_CURVED_DISTANCE_TRIANGLES as f64 / (2.0 * set.patches().len() as f64))
        .sqrt()
        .floor()
        .max(1.0);
    let k = fine.min(budget);
    let mesh = crate::patch::tessellate::tessellate(set, k as usize).ok()?;
    Some(CurvedSurface {
        mesh,
        segment: largest / k,
    })
}

/// A trimmed B-rep model's [`CurvedSurface`]: every face's patches with segments of at most
/// half a cell (longer where the budget says so), the grid triangles whose centres are inside
/// the face's loops ([`crate::patch::step::tessellate::trimmed_triangles`]; along a trimming
/// curve a staircase up to a segment off it, so distances there are known to within a
/// segment). `None` as for a patch set.
#[cfg(all(feature = "patch", feature = "io"))]
pub fn step_surface_for_distance(
    model: &crate::patch::step::StepModel,
    cell_size: f64,
) -> Option<CurvedSurface> {
    use crate::patch::step::tessellate::{grid_triangles, trimmed_triangles};
    if !(cell_size.is_finite() && cell_size > 0.0) {
        return None;
    }
    let budget = MAX_CURVED_DISTANCE_TRIANGLES as f64;
    let mut segment = 0.5 * cell_size;
    // The count falls as the segment's inverse square, rounded up per patch: a few rounds.
    for _ in 0..8 {
        let count = grid_triangles(model, segment);
        if count <= budget {
            let mesh = trimmed_triangles(model, segment, MAX_CURVED_DISTANCE_TRIANGLES)?.ok()?;
            return Some(CurvedSurface { mesh, segment });
        }
        segment *= 1.05 * (count / budget).sqrt();
    }
    None
}

/// The result of [`hausdorff_to_solid_boundary`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundaryHausdorff {
    /// The sampled symmetric distance.
    pub distance: f64,
    /// [`hausdorff_distance`] on the same samples (every input sample counted).
    pub plain: f64,
    /// The fraction of the input's samples where it bounds the solid.
    pub boundary_fraction: f64,
}

fn triangles_of(mesh: &crate::Mesh) -> Vec<[[f64; 3]; 3]> {
    (0..mesh.triangles().len())
        .map(|f| mesh.triangle_positions(f))
        .collect()
}

/// The largest distance from `points` to the surface `to` (0 for no points).
fn farthest(points: &[[f64; 3]], to: &crate::Mesh) -> f64 {
    distances_to(points, to).into_iter().fold(0.0, f64::max)
}

/// The distance from each of `points` to the surface `to`.
fn distances_to(points: &[[f64; 3]], to: &crate::Mesh) -> Vec<f64> {
    use rayon::prelude::*;
    let distance = crate::products::sdf::SignedDistance::with_evaluator(to, NoSurface);
    points.par_iter().map(|&p| distance.unsigned(p)).collect()
}

/// The largest distance to `to` from `samples` points on `from`.
fn farthest_from_surface(from: &crate::Mesh, to: &crate::Mesh, samples: usize, seed: u64) -> f64 {
    let points: Vec<[f64; 3]> = surface_samples(&triangles_of(from), samples, seed)
        .into_iter()
        .map(|(p, _)| p)
        .collect();
    farthest(&points, to)
}

/// `samples` points uniform by area on `triangles` (seeded SplitMix64), each with its triangle.
fn surface_samples(
    triangles: &[[[f64; 3]; 3]],
    samples: usize,
    seed: u64,
) -> Vec<([f64; 3], usize)> {
    let mut points: Vec<([f64; 3], usize)> = Vec::with_capacity(samples);
    let area = |t: &[[f64; 3]; 3]| {
        use crate::base::vec3::{cross, norm, sub};
        0.5 * norm(cross(sub(t[1], t[0]), sub(t[2], t[0])))
    };
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0;
    for t in triangles {
        let a = area(t);
        total += if a.is_finite() { a } else { 0.0 };
        cumulative.push(total);
    }
    if total <= 0.0 {
        return points;
    }
    let mut rng = crate::base::splitmix::SplitMix64(seed);
    let mut next = move || rng.unit();
    for _ in 0..samples {
        let x = next() * total;
        let f = cumulative
            .partition_point(|&c| c <= x)
            .min(triangles.len() - 1);
        let (mut r1, mut r2) = (next(), next());
        if r1 + r2 > 1.0 {
            (r1, r2) = (1.0 - r1, 1.0 - r2);
        }
        let t = &triangles[f];
        let p =
            std::array::from_fn(|k| t[0][k] + r1 * (t[1][k] - t[0][k]) + r2 * (t[2][k] - t[0][k]));
        points.push((p, f));
    }
    points
}
