//! Where a ray (or a segment: the ray up to a reach) meets a rational Bézier patch: subdivision
//! of the control net in the ray's frame, hull tests against the ray's line, and Newton's method
//! on pieces that hold at most one crossing. Shared by the trimmed B-rep evaluator
//! ([`super::step`], which classifies each hit against its face's loops) and the segment
//! crossings of Bézier patch sets ([`super::eval::PatchWindingNumber`]): one hit search, so a
//! fix to it reaches both.

use super::curve::Homogeneous;
use super::model::Patch;
use crate::base::vec3::{cross, dot, norm, sub};

/// A patch with the box of its control points (which contains it: positive weights).
#[derive(Clone, Copy)]
pub(in crate::patch) struct BoxedPatch<'a> {
    pub(in crate::patch) patch: &'a Patch,
    pub(in crate::patch) lo: [f64; 3],
    pub(in crate::patch) hi: [f64; 3],
}

/// A crossing of the ray with a patch: the point, the patch parameters `(s, t)` in `[0, 1]²`,
/// the partial derivatives there, and the distance `τ` along the ray.
pub(in crate::patch) struct PatchHit {
    pub(in crate::patch) point: [f64; 3],
    // Read by the STEP evaluator (feature `io`), which maps it to its face's `(u, v)`.
    #[cfg_attr(not(feature = "io"), allow(dead_code))]
    pub(in crate::patch) st: [f64; 2],
    pub(in crate::patch) ds: [f64; 3],
    pub(in crate::patch) dt: [f64; 3],
    pub(in crate::patch) tau: f64,
}

/// Subdivision depth of a patch before Newton's method starts from the piece's centre.
const HIT_DEPTH: u32 = 12;

/// Most pieces [`patch_hits`] examines on one patch. Four children per split and
/// [`HIT_DEPTH`] levels allow `4^12` pieces where the hull tests cannot cull (a surface whose
/// control points overflow in the ray frame, radius 1e308 in a fuzzed STEP file: minutes per
/// query); real queries examine a few per level near each hit. Past it the whole line is
/// reported unresolved, so no ray counts through the patch and the caller tries another ray or
/// flags the value (a bounded, certified refusal instead of a hang).
const MAX_HIT_PIECES: usize = 1 << 14;

/// A ray frame: `e1`, `e2`, `d` right-handed.
#[derive(Clone, Copy)]
pub(in crate::patch) struct RayFrame {
    pub(in crate::patch) e1: [f64; 3],
    pub(in crate::patch) e2: [f64; 3],
    pub(in crate::patch) d: [f64; 3],
}

impl RayFrame {
    pub(in crate::patch) fn new(d: [f64; 3]) -> RayFrame {
        let a = if d[0].abs() < 0.6 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let e1 = cross(d, a);
        let n = norm(e1);
        let e1 = [e1[0] / n, e1[1] / n, e1[2] / n];
        let e2 = cross(d, e1);
        RayFrame { e1, e2, d }
    }
    pub(in crate::patch) fn map(&self, r: [f64; 3]) -> [f64; 3] {
        [dot(self.e1, r), dot(self.e2, r), dot(self.d, r)]
    }
}

/// Where [`patch_hits`] looks for gaps: the patch's sides on an edge of the untrimmed surface
/// (a STEP face's: its `surface_edges`), the distance in model units (its `EDGE_GAP`), and
/// whether to look only there (a patch whose box the ray misses but passes within `gap` of).
#[derive(Clone, Copy)]
pub(in crate::patch) struct SurfaceEdges {
    pub(in crate::patch) sides: [bool; 4],
    pub(in crate::patch) gap: f64,
    pub(in crate::patch) only: bool,
}

impl SurfaceEdges {
    /// No side on an edge: an untrimmed patch set's patches, whose crossings all count.
    pub(in crate::patch) const NONE: SurfaceEdges = SurfaceEdges {
        sides: [false; 4],
        gap: 0.0,
        only: false,
    };
}

/// A piece of a patch in the ray frame: homogeneous net and its parameter rectangle.
struct Piece {
    h: Vec<Homogeneous>,
    s: [f64; 2],
    t: [f64; 2],
}

/// Ray hits on one patch: subdivision culls pieces whose control hull misses the ray's line
/// (xy box not containing the origin) or lies behind `q` or beyond `reach`; at depth
/// [`HIT_DEPTH`] or once a piece is small, Newton's method from its centre; a root counts for
/// the piece containing it.
pub(in crate::patch) fn patch_hits(
    fp: BoxedPatch,
    edges: SurfaceEdges,
    q: [f64; 3],
    frame: &RayFrame,
    reach: f64,
    out: &mut Vec<PatchHit>,
    unresolved: &mut Vec<[f64; 2]>,
) {
    let patch = fp.patch;
    let (m, n) = patch.degree();
    let h: Vec<Homogeneous> = patch
        .points()
        .iter()
        .zip(patch.weights())
        .map(|(p, &w)| {
            let f = frame.map(sub(*p, q));
            [w * f[0], w * f[1], w * f[2], w]
        })
        .collect();
    let size = norm(sub(fp.hi, fp.lo));
    let mut stack = vec![(
        Piece {
            h,
            s: [0.0, 1.0],
            t: [0.0, 1.0],
        },
        0u32,
    )];
    let mut examined = 0;
    while let Some((piece, depth)) = stack.pop() {
        examined += 1;
        if examined > MAX_HIT_PIECES {
            unresolved.push([f64::NEG_INFINITY, f64::INFINITY]);
            return;
        }
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &piece.h {
            for k in 0..3 {
                let x = p[k] / p[3];
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
        }
        let pad = 1e-12 * size;
        // A piece on an edge of the untrimmed surface is kept while the ray passes within
        // `gap` of it: a crossing just beyond the edge (Newton's root outside the piece, or
        // none) leaves the piece unresolved at the depth limit, so no ray counts through a
        // gap between two faces.
        let sides = edges.sides;
        let on_edge = (sides[0] && piece.s[0] == 0.0)
            || (sides[1] && piece.s[1] == 1.0)
            || (sides[2] && piece.t[0] == 0.0)
            || (sides[3] && piece.t[1] == 1.0);
        if edges.only && !on_edge {
            continue;
        }
        let pad_xy = if on_edge { pad.max(edges.gap) } else { pad };
        if lo[0] > pad_xy
            || hi[0] < -pad_xy
            || lo[1] > pad_xy
            || hi[1] < -pad_xy
            || hi[2] < -pad
            || lo[2] > reach + pad
        {
            continue;
        }
        // The box in the ray's plane is loose for a piece beside the ray and slanted to it;
        // with the box alone the pieces next to each hit were halved down to where their box
        // misses (1.3× per query on boxed_sphere).
        if hull_misses_origin(&piece.h, pad_xy) {
            continue;
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(hi[2] - lo[2]);
        let graph = depth >= 2 && extent <= 0.05 * size && single_root(fp, frame, &piece);
        if graph || depth >= HIT_DEPTH {
            // A piece that is a graph over the ray's plane holds at most one crossing; a root
            // Newton's method finds in it is that one. If the iterate leaves the piece
            // (converging to another crossing of the line, or to none) or fails, the piece may
            // still hold one and is halved again, like any piece its hull does not rule out.
            // At the depth limit (a tangency, a collapsed patch edge) a piece without that
            // proof may hide crossings: its span along the ray is reported, and no ray may
            // count through it. Dropping such pieces gave certified integer errors on
            // boxed_sphere.step (corner blends' missed crossings: `w = −1` and `w = 1` at
            // points outside; docs/patches.md).
            match newton(fp, q, frame, &piece) {
                Ok(Some(hit)) if graph => {
                    out.push(hit);
                    continue;
                }
                Ok(hit) if depth >= HIT_DEPTH => {
                    out.extend(hit);
                    unresolved.push(span_along_ray(lo[2], hi[2]));
                    continue;
                }
                Err(()) if depth >= HIT_DEPTH => {
                    unresolved.push(span_along_ray(lo[2], hi[2]));
                    continue;
                }
                _ => {}
            }
        }
        for (a, b) in split4(&piece, m, n) {
            stack.push((a, depth + 1));
            stack.push((b, depth + 1));
        }
    }
}

/// The unresolved span `[lo, hi]` along the ray, or the whole line when rounding made it NaN
/// (an overflowing net): the callers' tests (`hi ≥ −margin`) must reject the ray then, which
/// a NaN bound would not.
fn span_along_ray(lo: f64, hi: f64) -> [f64; 2] {
    if lo <= hi {
        [lo, hi]
    } else {
        [f64::NEG_INFINITY, f64::INFINITY]
    }
}

/// Whether the convex hull of the control points projected to the ray's plane (`x/w`, `y/w`;
/// positive weights, so it holds the piece's projection) stays farther than `pad` from the
/// origin, the ray's line. A few steps of Gilbert's distance algorithm in 2D from the
/// centroid: each step's direction `v` is a candidate separating line through the origin
/// (every point beyond `pad` along `v` proves the miss); it moves to the nearest point of the
/// segment from `v` to the support point. `false` is only "not proved".
fn hull_misses_origin(h: &[Homogeneous], pad: f64) -> bool {
    let point = |p: &Homogeneous| [p[0] / p[3], p[1] / p[3]];
    let n = h.len() as f64;
    let mut v = h
        .iter()
        .map(point)
        .fold([0.0, 0.0], |c, p| [c[0] + p[0] / n, c[1] + p[1] / n]);
    for _ in 0..4 {
        let length = v[0].hypot(v[1]);
        if !length.is_finite() || length <= 0.0 {
            return false;
        }
        let (w, along) = h
            .iter()
            .map(point)
            .map(|p| (p, p[0] * v[0] + p[1] * v[1]))
            .fold(
                ([0.0, 0.0], f64::INFINITY),
                |a, b| if b.1 < a.1 { b } else { a },
            );
        if along > pad * length {
            return true;
        }
        // Nearest point to the origin on the segment from v to w.
        let d = [w[0] - v[0], w[1] - v[1]];
        let dd = d[0] * d[0] + d[1] * d[1];
        if !dd.is_finite() || dd <= 0.0 {
            return false;
        }
        let t = (-(v[0] * d[0] + v[1] * d[1]) / dd).clamp(0.0, 1.0);
        v = [v[0] + t * d[0], v[1] + t * d[1]];
    }
    false
}

/// Whether a small piece can hold only one crossing of the ray: its normals at the corners and
/// the centre lie within 30° of each other and all make an angle of at least ~6° with the
/// ray's plane (`|n̂·d| ≥ 0.1`), so the piece is a graph over the plane normal to the ray. A
/// ray that enters and leaves one piece (near tangency) is subdivided further.
fn single_root(fp: BoxedPatch, frame: &RayFrame, piece: &Piece) -> bool {
    let at = |s: f64, t: f64| {
        let (_, ds, dt) = fp.patch.eval_with_partials(s, t);
        let n = cross(ds, dt);
        let l = norm(n);
        if l > 0.0 {
            Some([n[0] / l, n[1] / l, n[2] / l])
        } else {
            None
        }
    };
    let (s0, s1, t0, t1) = (piece.s[0], piece.s[1], piece.t[0], piece.t[1]);
    let Some(c) = at(0.5 * (s0 + s1), 0.5 * (t0 + t1)) else {
        return false;
    };
    let side = dot(c, frame.d);
    if side.abs() < 0.1 {
        return false;
    }
    [(s0, t0), (s0, t1), (s1, t0), (s1, t1)]
        .iter()
        .all(|&(s, t)| match at(s, t) {
            Some(n) => dot(n, c) >= 0.866 && dot(n, frame.d) * side.signum() >= 0.1,
            None => false,
        })
}

/// Halves a piece in `s` and in `t` (four pieces, returned in pairs).
fn split4(piece: &Piece, m: usize, n: usize) -> [(Piece, Piece); 2] {
    let (sa, sb) = split_dir(&piece.h, m, n, true);
    let sm = 0.5 * (piece.s[0] + piece.s[1]);
    let tm = 0.5 * (piece.t[0] + piece.t[1]);
    [(sa, [piece.s[0], sm]), (sb, [sm, piece.s[1]])].map(|(hs, s)| {
        let (ta, tb) = split_dir(&hs, m, n, false);
        (
            Piece {
                h: ta,
                s,
                t: [piece.t[0], tm],
            },
            Piece {
                h: tb,
                s,
                t: [tm, piece.t[1]],
            },
        )
    })
}

/// Halves a row-major `(m+1) × (n+1)` net along `s` (rows) or `t` (columns): each line of the
/// net by de Casteljau, in place in the right half, with the operations of
/// [`split_half`](super::curve::split_half) in its order, so the halves are bit for bit its halves. No allocation but the
/// two nets: with a `Vec` per line and per half, the allocator took a third of a STEP model's
/// remeshing time (docs/benchmarks.md, "STEP models place their vertices at their own surface
/// hits").
fn split_dir(
    h: &[Homogeneous],
    m: usize,
    n: usize,
    along_s: bool,
) -> (Vec<Homogeneous>, Vec<Homogeneous>) {
    let mut left = vec![[0.0; 4]; h.len()];
    let mut right = h.to_vec();
    // Line `k`'s `i`-th point is at `k · stride + i · step`.
    let (lines, degree, stride, step) = if along_s {
        (n + 1, m, 1, n + 1)
    } else {
        (m + 1, n, n + 1, 1)
    };
    for k in 0..lines {
        let at = |i: usize| k * stride + i * step;
        left[at(0)] = right[at(0)];
        // After level `l`, point `degree − l` is final: the right half's, as in `split_half`.
        for level in 1..=degree {
            for i in 0..=(degree - level) {
                let next = right[at(i + 1)];
                for (c, x) in right[at(i)].iter_mut().enumerate() {
                    *x = 0.5 * (*x + next[c]);
                }
            }
            left[at(level)] = right[at(0)];
        }
    }
    (left, right)
}

/// Newton's method for `x(s, t) = y(s, t) = 0` in the ray frame, from the piece's centre.
/// `Ok(None)`: the root is outside the piece; `Err`: the method failed (singular or
/// not converging), so the piece's crossings are unknown.
fn newton(
    fp: BoxedPatch,
    q: [f64; 3],
    frame: &RayFrame,
    piece: &Piece,
) -> Result<Option<PatchHit>, ()> {
    let mut st = [
        0.5 * (piece.s[0] + piece.s[1]),
        0.5 * (piece.t[0] + piece.t[1]),
    ];
    let centre = [
        0.5 * (fp.lo[0] + fp.hi[0]),
        0.5 * (fp.lo[1] + fp.hi[1]),
        0.5 * (fp.lo[2] + fp.hi[2]),
    ];
    let scale = norm(sub(fp.hi, fp.lo)) + norm(sub(centre, q));
    let mut converged = false;
    for _ in 0..40 {
        let (p, ds, dt) = fp.patch.eval_with_partials(st[0], st[1]);
        let r = frame.map(sub(p, q));
        let a = [dot(frame.e1, ds), dot(frame.e1, dt)];
        let b = [dot(frame.e2, ds), dot(frame.e2, dt)];
        let det = a[0] * b[1] - a[1] * b[0];
        if det == 0.0 || !det.is_finite() {
            return Err(());
        }
        let d0 = (r[0] * b[1] - a[1] * r[1]) / det;
        let d1 = (a[0] * r[1] - r[0] * b[0]) / det;
        st = [(st[0] - d0).clamp(-0.5, 1.5), (st[1] - d1).clamp(-0.5, 1.5)];
        if d0.abs() + d1.abs() < 1e-14 || (r[0].abs() + r[1].abs()) < 1e-15 * scale {
            converged = true;
            break;
        }
    }
    if !converged {
        return Err(());
    }
    let tol = 1e-10;
    if st[0] < piece.s[0] - tol
        || st[0] > piece.s[1] + tol
        || st[1] < piece.t[0] - tol
        || st[1] > piece.t[1] + tol
    {
        return Ok(None);
    }
    // Roots on a piece's border are found by both neighbours; `tol` keeps the one at the
    // patch border inside [0, 1]².
    let st = [st[0].clamp(0.0, 1.0), st[1].clamp(0.0, 1.0)];
    let (p, ds, dt) = fp.patch.eval_with_partials(st[0], st[1]);
    let r = frame.map(sub(p, q));
    if (r[0] * r[0] + r[1] * r[1]).sqrt() > 1e-9 * scale {
        return Ok(None);
    }
    Ok(Some(PatchHit {
        point: p,
        st,
        ds,
        dt,
        tau: r[2],
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A net whose homogeneous points overflow in the ray frame (coordinates `±1e308` with
    /// weight 4) turns NaN when halved, so no hull test culls a piece: without
    /// [`MAX_HIT_PIECES`] the search would split all `4^12` pieces of [`HIT_DEPTH`] levels
    /// (minutes). With it, the whole line is reported unresolved after the cap.
    #[test]
    fn a_net_that_overflows_in_the_ray_frame_is_refused_after_the_piece_cap() {
        let big = 1e308;
        let points = vec![
            [-big, -big, 0.0],
            [-big, big, 0.0],
            [big, -big, 0.0],
            [big, big, 0.0],
        ];
        let patch = Patch::rational(1, 1, points, vec![4.0; 4]).unwrap();
        let fp = BoxedPatch {
            patch: &patch,
            lo: [-big, -big, 0.0],
            hi: [big, big, 0.0],
        };
        let frame = RayFrame::new([0.0, 0.6, 0.8]);
        let (mut hits, mut unresolved) = (Vec::new(), Vec::new());
        patch_hits(
            fp,
            SurfaceEdges::NONE,
            [0.1, 0.2, -1.0],
            &frame,
            f64::INFINITY,
            &mut hits,
            &mut unresolved,
        );
        // Work counted, not timed: each examined piece reports at most one span.
        assert!(
            unresolved.len() <= MAX_HIT_PIECES + 1,
            "{}",
            unresolved.len()
        );
        assert_eq!(unresolved.last(), Some(&[f64::NEG_INFINITY, f64::INFINITY]));
    }
}
