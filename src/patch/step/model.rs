//! A trimmed B-rep model ready for evaluation: per face its Bézier patches and trimming
//! polygon in `(u, v)`; for the whole model the surface boundary (edge uses that no other use
//! cancels) as rational Bézier curves.

use std::cmp::Ordering;
use std::collections::{BTreeMap, HashMap};

use super::super::curve::{Homogeneous, eval_with_derivative};
use super::super::model::Patch;
use super::super::ray_hits::BoxedPatch;
use super::StepError;
use super::brep::{EdgePcurve, Reader, Topology, reverse};
use super::nurbs::{euc, point_at};
use super::part21::Part21;
use super::surface::{ParamMap, Surface, invert_curve};
use super::trim::{Segment, Trim};
use crate::base::vec3::{dot, norm, sub};

/// Chord tolerance of the trimming polygons, relative to the model's diagonal: a loop's
/// polygon in `(u, v)`, mapped back to 3D, stays this close to the edge curves.
pub const TRIM_CHORD: f64 = 2e-7;
/// Near-boundary margin of ray hits, relative to the diagonal: a hit this close to a trimming
/// loop (in 3D, to first order) makes the evaluator choose another ray. Ten times the chord
/// tolerance, so the polygons of two faces sharing an edge cannot disagree outside it
/// (nor can faces whose surfaces miss the shared edge by up to this much, as in
/// `sliced_cylinder.step`, where the cylinder's radius is 10.0000038 and its circles' 10).
pub const HIT_MARGIN: f64 = 2e-6;
/// Edge uses left over after exact cancellation (same `EDGE_CURVE`, opposite directions) are
/// matched geometrically: two uses cancel when their end points swap and three interior points
/// of one lie on the other, all within this tolerance relative to the diagonal, and their
/// tangents are opposite. For files that store each face in its own shell with its own copy
/// of every edge (`open_cylinder`, `spring`).
pub const EDGE_MATCH: f64 = 1e-6;
/// A pcurve is used for a face's trimming loop only if its image on the surface stays this
/// close (relative to the diagonal) to the edge's 3D curve at its ends and three interior
/// points; otherwise the edge use is mapped from 3D. Loose enough for CAD files whose edges
/// lie off their faces by the modelling tolerance, tight enough to catch a pcurve in the wrong
/// unit, on the wrong side of a seam's surface copy or of another edge.
pub const PCURVE_TOLERANCE: f64 = 1e-3;
/// A face is refused when an edge of its loops lies farther than this (relative to the model's
/// diagonal) from the face's surface, at a point of the edge's trimming polygon: its loop would
/// not bound a piece of that surface, so the model is not closed there whatever the file says.
/// Ten times [`PCURVE_TOLERANCE`], for CAD files whose edges lie off their faces by the
/// modelling tolerance. Such files are corrupt rather than sloppy (a cylinder's radius of
/// `1e308`, `1e9` or `1e-320` around edges of radius 1, found by the structure-aware fuzz
/// test), and they cost the ray-hit search its piece cap on every ray: up to a second per
/// query, every value flagged, instead of this one-line error at load time.
pub const EDGE_OFF_SURFACE_LIMIT: f64 = 1e-2;

/// One patch of a face with its parameter rectangle and control-point box.
#[derive(Clone, Debug)]
pub struct FacePatch {
    /// The patch (rows along `u`).
    pub patch: Patch,
    /// `[u0, u1]`.
    pub u: [f64; 2],
    /// `[v0, v1]`.
    pub v: [f64; 2],
    /// Box of the control points (contains the patch).
    pub lo: [f64; 3],
    /// Upper corner.
    pub hi: [f64; 3],
    /// How the patch parameters map to `u` and `v` (angles of elementary surfaces are not
    /// linear in the patch parameter).
    pub map: [ParamMap; 2],
}

impl FacePatch {
    /// The patch with its box, for the hit search (`crate::patch::ray_hits`).
    pub(in crate::patch) fn boxed(&self) -> BoxedPatch<'_> {
        BoxedPatch {
            patch: &self.patch,
            lo: self.lo,
            hi: self.hi,
        }
    }

    /// `(u, v)` of the patch parameters `(s, t)`, with `du/ds` and `dv/dt`.
    pub fn uv_at(&self, st: [f64; 2]) -> ([f64; 2], [f64; 2]) {
        let (u, du) = self.map[0].at(self.u, st[0]);
        let (v, dv) = self.map[1].at(self.v, st[1]);
        ([u, v], [du, dv])
    }
}

/// One trimmed face.
#[derive(Clone, Debug)]
pub struct Face {
    /// `#id` in the file.
    pub id: u64,
    /// Patches covering the face's parameter rectangle.
    pub patches: Vec<FacePatch>,
    /// The trimming loops.
    pub trim: Trim,
    /// `+1` if the face normal is `S_u × S_v`, `−1` otherwise (`same_sense`).
    pub sense: f64,
}

/// Counts for `gwn info`.
#[derive(Clone, Debug, Default)]
pub struct StepInfo {
    /// Faces.
    pub faces: usize,
    /// Bézier patches over all faces.
    pub patches: usize,
    /// Faces per surface kind.
    pub surfaces: BTreeMap<&'static str, usize>,
    /// Distinct `EDGE_CURVE`s used by the faces.
    pub edges: usize,
    /// Edge-use pairs cancelled exactly (one `EDGE_CURVE`, opposite directions).
    pub cancelled_exact: usize,
    /// Edge-use pairs cancelled by the geometric match ([`EDGE_MATCH`]).
    pub cancelled_matched: usize,
    /// Edge uses left as the surface boundary.
    pub boundary_edges: usize,
    /// Solids and shells, length unit.
    pub topology: Topology,
    /// Segments of all trimming polygons.
    pub trim_segments: usize,
    /// Edge uses whose trimming polygon comes from the file's pcurve.
    pub pcurve_uses: usize,
    /// Edge uses mapped from their 3D curve although the file gives a pcurve on the face's
    /// surface: the pcurve strays more than [`PCURVE_TOLERANCE`] from the 3D curve, or the
    /// surface's parameters are not the file's (revolution, extrusion).
    pub pcurves_rejected: usize,
    /// Pcurves of a kind the reader does not evaluate (2D curve other than line, conic or
    /// B-spline; 3D curve trimmed or a closed B-spline run across its start).
    pub pcurves_unreadable: usize,
}

/// A trimmed B-rep model read from a STEP file.
#[derive(Clone, Debug)]
pub struct StepModel {
    pub(crate) faces: Vec<Face>,
    /// Surface boundary: homogeneous Bézier curves in world coordinates, oriented as the
    /// boundary of their faces.
    pub(crate) boundary: Vec<Vec<Homogeneous>>,
    /// The face (index into `faces`) each boundary curve bounds.
    pub(crate) boundary_faces: Vec<usize>,
    pub(crate) lo: [f64; 3],
    pub(crate) hi: [f64; 3],
    pub(crate) info: StepInfo,
}

impl StepModel {
    /// Counts and units.
    pub fn info(&self) -> &StepInfo {
        &self.info
    }

    /// Bounding box of the faces' patch control points (contains the model).
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        (self.lo, self.hi)
    }

    /// Diagonal of the bounding box.
    pub fn diagonal(&self) -> f64 {
        norm(sub(self.hi, self.lo))
    }

    /// The faces.
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// Surface-boundary curves (homogeneous control points, world coordinates).
    pub fn boundary(&self) -> &[Vec<Homogeneous>] {
        &self.boundary
    }

    /// Builds the model from a parsed file.
    pub fn from_part21(file: &Part21) -> Result<StepModel, StepError> {
        let mut reader = Reader::new(file);
        let (raw, topology) = reader.faces()?;
        // Model size from the edge geometry (the faces' extent before their patches exist).
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for pieces in reader.edges.values() {
            for c in pieces {
                for h in c {
                    let p = euc(*h);
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
            }
        }
        let diag = norm(sub(hi, lo));
        if !(diag.is_finite() && diag > 0.0) {
            return Err(StepError::NoFaces);
        }
        let chord = TRIM_CHORD * diag;
        let mut info = StepInfo {
            topology,
            ..StepInfo::default()
        };
        let mut faces = Vec::with_capacity(raw.len());
        // Edge uses over the whole model, for the boundary.
        let mut uses: Vec<(u64, bool, usize)> = Vec::new();
        for f in &raw {
            *info.surfaces.entry(f.surface.kind()).or_default() += 1;
            let (period_u, period_v) = f.surface.periods();
            let sense = if f.same_sense { 1.0 } else { -1.0 };
            let mut count: HashMap<u64, usize> = HashMap::new();
            for l in &f.loops {
                for u in l {
                    *count.entry(u.edge).or_default() += 1;
                    uses.push((u.edge, u.forward, faces.len()));
                }
            }
            let mut segments = Vec::new();
            for l in &f.loops {
                let mut poly: Vec<[f64; 2]> = Vec::new();
                let mut real: Vec<bool> = Vec::new();
                let mut hint: Option<[f64; 2]> = None;
                for u in l {
                    let geom = reader.edges[&u.edge].clone();
                    let geom = if u.forward { geom } else { reverse(geom) };
                    let seam = count[&u.edge] > 1;
                    let on_face: Vec<&EdgePcurve> = reader
                        .pcurves
                        .get(&u.edge)
                        .map(|v| v.iter().filter(|p| p.surface == f.surface_id).collect())
                        .unwrap_or_default();
                    let from_pcurve = f.pcurve_units.and_then(|units| {
                        on_face.iter().find_map(|pc| {
                            pcurve_polygon(pc, u.forward, units, &f.surface, &geom, chord, diag)
                        })
                    });
                    if let Some(mut pts) = from_pcurve {
                        info.pcurve_uses += 1;
                        // Continue where the loop is (a pcurve may be written in another
                        // period copy; a seam's two pcurves differ by one period).
                        if let Some(prev) = poly.last().copied() {
                            let mut shift = [0.0; 2];
                            for (k, period) in [period_u, period_v].into_iter().enumerate() {
                                if let Some(p) = period {
                                    shift[k] = p * ((prev[k] - pts[0][k]) / p).round();
                                }
                            }
                            for q in &mut pts {
                                q[0] += shift[0];
                                q[1] += shift[1];
                            }
                        }
                        append_to_loop(&mut poly, &mut real, pts, seam);
                        hint = poly.last().copied();
                        continue;
                    }
                    if !on_face.is_empty() {
                        info.pcurves_rejected += 1;
                    }
                    for c in &geom {
                        let (pts, off) = sample(c, &f.surface, &mut hint, chord);
                        if off > EDGE_OFF_SURFACE_LIMIT * diag {
                            return Err(StepError::Geometry {
                                id: f.id,
                                entity: "ADVANCED_FACE".into(),
                                message: format!(
                                    "edge #{} lies {off:.3e} from the face's surface, more than \
                                     {} of the model's size {diag:.3e} (edge and surface geometry \
                                     disagree)",
                                    u.edge, EDGE_OFF_SURFACE_LIMIT
                                ),
                            });
                        }
                        append_to_loop(&mut poly, &mut real, pts, seam);
                    }
                }
                if poly.len() < 2 {
                    continue;
                }
                for k in 0..poly.len() - 1 {
                    segments.push(Segment {
                        a: poly[k],
                        b: poly[k + 1],
                        real: real[k],
                    });
                }
                // Close the loop in the period copy next to its end (a band's end is its start
                // moved by a whole period: nothing to add).
                let (first, last) = (poly[0], poly[poly.len() - 1]);
                let mut target = first;
                if let Some(p) = period_u {
                    target[0] += p * ((last[0] - first[0]) / p).round();
                }
                if let Some(p) = period_v {
                    target[1] += p * ((last[1] - first[1]) / p).round();
                }
                if target != last {
                    segments.push(Segment {
                        a: last,
                        b: target,
                        real: true,
                    });
                }
            }
            if segments.is_empty() {
                return Err(StepError::Geometry {
                    id: f.id,
                    entity: "ADVANCED_FACE".into(),
                    message: "no edge loop (faces bounded only by vertex loops are not supported)"
                        .into(),
                });
            }
            info.trim_segments += segments.len();
            let trim = Trim::with_periods(segments, period_u, period_v, sense);
            let [u0, mut u1, mut v0, mut v1] = trim.bbox;
            if let Some(p) = period_u {
                u1 = u1.min(u0 + p);
            }
            if let Some(p) = period_v {
                v1 = v1.min(v0 + p);
            }
            if let Some([b0, b1]) = f.surface.v_bounds() {
                // A cap: the face reaches the pole when the indicator is 1 next to it.
                let um = u0 + 0.371 * (u1 - u0);
                if trim.indicator([um, b1 - 1e-12]) == 1 {
                    v1 = b1;
                }
                if trim.indicator([um, b0 + 1e-12]) == 1 {
                    v0 = b0;
                }
            }
            if !(u1 > u0 && v1 > v0) {
                return Err(StepError::Geometry {
                    id: f.id,
                    entity: "ADVANCED_FACE".into(),
                    message: "its loops enclose no area in the surface's parameters".into(),
                });
            }
            let uvp = f
                .surface
                .patches([u0, u1], [v0, v1])
                .map_err(|m| StepError::Geometry {
                    id: f.id,
                    entity: "ADVANCED_FACE".into(),
                    message: m,
                })?;
            let patches: Vec<FacePatch> = uvp
                .into_iter()
                .map(|p| {
                    let mut plo = [f64::INFINITY; 3];
                    let mut phi = [f64::NEG_INFINITY; 3];
                    for x in p.patch.points() {
                        for k in 0..3 {
                            plo[k] = plo[k].min(x[k]);
                            phi[k] = phi[k].max(x[k]);
                        }
                    }
                    FacePatch {
                        patch: p.patch,
                        u: p.u,
                        v: p.v,
                        lo: plo,
                        hi: phi,
                        map: p.map,
                    }
                })
                .collect();
            info.patches += patches.len();
            faces.push(Face {
                id: f.id,
                patches,
                trim,
                sense,
            });
        }
        info.faces = faces.len();
        info.pcurves_unreadable = reader.pcurves_unreadable;
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for f in &faces {
            for p in &f.patches {
                for k in 0..3 {
                    lo[k] = lo[k].min(p.lo[k]);
                    hi[k] = hi[k].max(p.hi[k]);
                }
            }
        }
        let (boundary, boundary_faces) =
            surface_boundary(&reader, &uses, EDGE_MATCH * diag, &mut info);
        Ok(StepModel {
            faces,
            boundary,
            boundary_faces,
            lo,
            hi,
            info,
        })
    }
}

/// Samples a Bézier piece into `(u, v)` points (start and end included): bisection until the
/// curve's midpoint is within `chord` of the chord in 3D and the inverted midpoint within
/// `chord` (to first order, scaled by the chord's 3D/uv length ratio) of the uv chord. Also
/// returns the largest distance from a sampled edge point to the surface at its `(u, v)`
/// ([`EDGE_OFF_SURFACE_LIMIT`]).
fn sample(
    c: &[Homogeneous],
    surface: &Surface,
    hint: &mut Option<[f64; 2]>,
    chord: f64,
) -> (Vec<[f64; 2]>, f64) {
    // The largest distance between a polygon point's edge point and its image on the surface
    // (infinite where either is not finite).
    let off = |uv: [f64; 2], p: [f64; 3]| {
        let d = surface.point(uv).map_or(f64::INFINITY, |s| norm(sub(s, p)));
        if d.is_nan() { f64::INFINITY } else { d }
    };
    let p0 = point_at(c, 0.0);
    let uv0 = surface.invert(p0, *hint);
    let mut largest_off = off(uv0, p0);
    let mut out = vec![uv0];
    // Explicit stack of intervals (t0, t1, depth) in order; points carried with their uv.
    let p1 = point_at(c, 1.0);
    let uv1 = surface.invert(p1, Some(uv0));
    let mut stack = vec![(1.0, p1, uv1, 0u32)];
    let mut cur = (0.0, p0, uv0);
    while let Some((t1, q1, w1, depth)) = stack.pop() {
        let (t0, q0, w0) = cur;
        let tm = 0.5 * (t0 + t1);
        let qm = point_at(c, tm);
        let wm = surface.invert(qm, Some(w0));
        let mid3 = [
            0.5 * (q0[0] + q1[0]),
            0.5 * (q0[1] + q1[1]),
            0.5 * (q0[2] + q1[2]),
        ];
        let dev3 = norm(sub(qm, mid3));
        let duv = ((w1[0] - w0[0]).powi(2) + (w1[1] - w0[1]).powi(2)).sqrt();
        let ratio = if duv > 0.0 {
            norm(sub(q1, q0)) / duv
        } else {
            0.0
        };
        let devuv = ((wm[0] - 0.5 * (w0[0] + w1[0])).powi(2)
            + (wm[1] - 0.5 * (w0[1] + w1[1])).powi(2))
        .sqrt()
            * ratio;
        // A piece shorter than the chord tolerance is not refined for its uv deviation: at a
        // pole or a collapsed edge the uv image of one 3D point is a whole segment.
        let short = norm(sub(q1, q0)) <= chord && dev3 <= chord;
        if depth < 22 && (depth < 2 || dev3 > chord || (devuv > chord && !short)) {
            stack.push((t1, q1, w1, depth + 1));
            stack.push((tm, qm, wm, depth + 1));
        } else {
            largest_off = largest_off.max(off(w1, q1));
            out.push(w1);
            cur = (t1, q1, w1);
        }
    }
    *hint = out.last().copied();
    (out, largest_off)
}

/// Appends an edge piece's polygon `pts` to a loop's points, with the `real` flag of each new
/// segment (a seam's own segments are not real). The piece's first point is dropped if it is
/// the loop's last point; otherwise the segment between them closes a gap, and is real: at a
/// pole (a collapsed edge) the two ends are one 3D point at different `u`, and the segment
/// runs along the pole's line. Dropping it unconditionally (the 3D-mapped path did) let the
/// loop cut straight to the next sample: a sliver out of boxed_sphere's sphere faces (lunes
/// between meridians), 7.7·10⁻⁴ wide in `v` at the pole.
fn append_to_loop(poly: &mut Vec<[f64; 2]>, real: &mut Vec<bool>, pts: Vec<[f64; 2]>, seam: bool) {
    for (k, uv) in pts.into_iter().enumerate() {
        if let Some(&last) = poly.last() {
            if k == 0 && near_uv(last, uv) {
                continue;
            }
            real.push(k == 0 || !seam);
        }
        poly.push(uv);
    }
}

/// Whether two loop points are the same up to rounding.
fn near_uv(a: [f64; 2], b: [f64; 2]) -> bool {
    let scale = 1.0 + a[0].abs().max(a[1].abs());
    (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= 1e-12 * scale
}

/// The trimming polygon of one edge use from its pcurve (start and end included), in this
/// reader's `(u, v)` (file units times `units`), or `None` if the pcurve's image on the
/// surface strays more than [`PCURVE_TOLERANCE`] `× diag` from the use's 3D curve `geom` (at its
/// ends, and at three interior points, which must also come in the curve's order).
/// Bisection in the pcurve's parameter until the surface point of each uv chord's midpoint is
/// within `chord` of the surface point of the curve's midpoint (the polygon's 3D image then
/// follows the edge as closely as a polygon mapped from 3D).
fn pcurve_polygon(
    pc: &EdgePcurve,
    forward: bool,
    units: [f64; 2],
    surface: &Surface,
    geom: &[Vec<Homogeneous>],
    chord: f64,
    diag: f64,
) -> Option<Vec<[f64; 2]>> {
    let [t0, t1] = if forward {
        pc.range
    } else {
        [pc.range[1], pc.range[0]]
    };
    let uv_at = |t: f64| {
        let p = pc.curve.at(t);
        [p[0] * units[0], p[1] * units[1]]
    };
    let finite = |p: [f64; 3]| p.iter().all(|c| c.is_finite());
    let point = |uv: [f64; 2]| surface.point(uv).filter(|&p| finite(p));
    // The check against the 3D curve first (a pcurve in the wrong unit is refused before it
    // is sampled).
    let pieces: Vec<(f64, f64, Vec<Homogeneous>)> = geom
        .iter()
        .enumerate()
        .map(|(k, c)| (k as f64, k as f64 + 1.0, c.clone()))
        .collect();
    if pieces.is_empty() {
        return None;
    }
    // Its ends at the use's ends, three interior points on the use's curve and in its order
    // (a pcurve run backwards, or over another arc of a circle, is refused).
    let tolerance = PCURVE_TOLERANCE * diag;
    let ends = [
        point_at(&geom[0], 0.0),
        point_at(&geom[geom.len() - 1], 1.0),
    ];
    for (t, end) in [t0, t1].into_iter().zip(ends) {
        let off = norm(sub(point(uv_at(t))?, end));
        if off.is_nan() || off > tolerance {
            return None;
        }
    }
    let mut previous = f64::NEG_INFINITY;
    for f in [0.25, 0.5, 0.75] {
        let p = point(uv_at(t0 + f * (t1 - t0)))?;
        let s = invert_curve(&pieces, p);
        let q = super::surface::curve_point(&pieces, s);
        let off = norm(sub(p, q));
        if off.is_nan() || off > tolerance || s.partial_cmp(&previous) != Some(Ordering::Greater) {
            return None;
        }
        previous = s;
    }
    let (uv0, uv1) = (uv_at(t0), uv_at(t1));
    let mut out = vec![uv0];
    let mut cur = (t0, uv0);
    let mut stack = vec![(t1, uv1, 0u32)];
    while let Some((tb, wb, depth)) = stack.pop() {
        let (ta, wa) = cur;
        let tm = 0.5 * (ta + tb);
        let wm = uv_at(tm);
        let on_curve = point(wm)?;
        let on_chord = point([0.5 * (wa[0] + wb[0]), 0.5 * (wa[1] + wb[1])])?;
        if depth < 22 && (depth < 2 || norm(sub(on_curve, on_chord)) > chord) {
            stack.push((tb, wb, depth + 1));
            stack.push((tm, wm, depth + 1));
        } else {
            out.push(wb);
            cur = (tb, wb);
        }
    }
    Some(out)
}

/// The edge uses that no other use cancels, as Bézier pieces. Exact cancellation first (one
/// `EDGE_CURVE` used in both directions), then the geometric match of [`EDGE_MATCH`].
fn surface_boundary(
    reader: &Reader<'_>,
    uses: &[(u64, bool, usize)],
    tol: f64,
    info: &mut StepInfo,
) -> (Vec<Vec<Homogeneous>>, Vec<usize>) {
    // Per edge, the faces using it forwards and backwards.
    let mut per_edge: HashMap<u64, (Vec<usize>, Vec<usize>)> = HashMap::new();
    for &(e, fwd, face) in uses {
        let c = per_edge.entry(e).or_default();
        if fwd {
            c.0.push(face);
        } else {
            c.1.push(face);
        }
    }
    info.edges = per_edge.len();
    let mut left: Vec<Vec<Vec<Homogeneous>>> = Vec::new();
    let mut left_faces: Vec<usize> = Vec::new();
    let mut ids: Vec<u64> = per_edge.keys().copied().collect();
    ids.sort_unstable();
    for e in ids {
        let (f, r) = &per_edge[&e];
        let pairs = f.len().min(r.len());
        info.cancelled_exact += pairs;
        let geom = &reader.edges[&e];
        for &face in &f[pairs..] {
            left.push(geom.clone());
            left_faces.push(face);
        }
        for &face in &r[pairs..] {
            left.push(reverse(geom.clone()));
            left_faces.push(face);
        }
    }
    // Geometric match among the leftovers.
    let probes: Vec<Probe> = left.iter().map(|g| Probe::new(g)).collect();
    let mut used = vec![false; left.len()];
    for i in 0..left.len() {
        if used[i] {
            continue;
        }
        for j in i + 1..left.len() {
            if used[j] || !probes[i].cancels(&probes[j], &left[j], tol) {
                continue;
            }
            used[i] = true;
            used[j] = true;
            info.cancelled_matched += 1;
            break;
        }
    }
    let mut pieces = Vec::new();
    let mut faces = Vec::new();
    for ((g, face), used) in left.into_iter().zip(left_faces).zip(used) {
        if !used {
            info.boundary_edges += 1;
            faces.extend(std::iter::repeat_n(face, g.len()));
            pieces.extend(g);
        }
    }
    (pieces, faces)
}

/// End points, interior points and tangents of an edge use, for the geometric match.
struct Probe {
    start: [f64; 3],
    end: [f64; 3],
    inner: Vec<([f64; 3], [f64; 3])>,
}

impl Probe {
    fn new(g: &[Vec<Homogeneous>]) -> Probe {
        let start = point_at(&g[0], 0.0);
        let end = point_at(&g[g.len() - 1], 1.0);
        let mut inner = Vec::new();
        for f in [0.25, 0.5, 0.75] {
            let x = f * g.len() as f64;
            let k = (x.floor() as usize).min(g.len() - 1);
            let t = x - k as f64;
            let (n, dn) = eval_with_derivative(&g[k], t);
            let p = euc(n);
            let d = [
                dn[0] - p[0] * dn[3],
                dn[1] - p[1] * dn[3],
                dn[2] - p[2] * dn[3],
            ];
            inner.push((p, d));
        }
        Probe { start, end, inner }
    }

    /// Whether `other` (with geometry `g`) runs along this use in the opposite direction.
    fn cancels(&self, other: &Probe, g: &[Vec<Homogeneous>], tol: f64) -> bool {
        if norm(sub(self.start, other.end)) > tol || norm(sub(self.end, other.start)) > tol {
            return false;
        }
        let pieces: Vec<(f64, f64, Vec<Homogeneous>)> = g
            .iter()
            .enumerate()
            .map(|(k, c)| (k as f64, k as f64 + 1.0, c.clone()))
            .collect();
        self.inner.iter().all(|(p, d)| {
            let t = invert_curve(&pieces, *p);
            let k = (t.floor() as usize).min(g.len() - 1);
            let (n, dn) = eval_with_derivative(&g[k], t - k as f64);
            let q = euc(n);
            let dq = [
                dn[0] - q[0] * dn[3],
                dn[1] - q[1] * dn[3],
                dn[2] - q[2] * dn[3],
            ];
            norm(sub(q, *p)) <= tol && dot(*d, dq) < 0.0
        })
    }
}
