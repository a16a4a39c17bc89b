//! Curved surfaces: closed forms, oracles and ray independence for the patch evaluator
//! (`docs/patches.md`).

use crate::common;

use gwn::Mesh;
use gwn::RayAxis;
use gwn::eval::antipodal::WindingNumber;
use gwn::patch::tessellate::tessellate;
use gwn::patch::{Options, Patch, PatchSet, PatchWindingNumber};

/// xorshift64*: deterministic points without a dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn point(&mut self, lo: f64, hi: f64) -> [f64; 3] {
        [0, 1, 2].map(|_| lo + (hi - lo) * self.next())
    }
}

fn with(set: &PatchSet, ray: RayAxis, tolerance: f64) -> PatchWindingNumber {
    PatchWindingNumber::with_options(set, Options { ray, tolerance }).unwrap()
}

/// A planar parallelogram `o + t·a + s·b` as a patch of degrees `(m, n)` (affine control net).
fn planar(o: [f64; 3], a: [f64; 3], b: [f64; 3], m: usize, n: usize) -> Patch {
    let mut pts = Vec::new();
    for i in 0..=m {
        for j in 0..=n {
            let (s, t) = (i as f64 / m as f64, j as f64 / n as f64);
            pts.push([0, 1, 2].map(|c| o[c] + t * a[c] + s * b[c]));
        }
    }
    Patch::polynomial(m, n, pts).unwrap()
}

/// The unit cube without its top, as five planar patches of assorted degrees and as triangles.
fn open_box() -> (PatchSet, Mesh) {
    let faces = [
        ([0., 0., 0.], [0., 1., 0.], [1., 0., 0.], 3, 3), // bottom, normal −z
        ([0., 0., 0.], [0., 0., 1.], [0., 1., 0.], 1, 1), // x = 0
        ([1., 0., 0.], [0., 1., 0.], [0., 0., 1.], 2, 3), // x = 1
        ([0., 0., 0.], [1., 0., 0.], [0., 0., 1.], 3, 1), // y = 0
        ([0., 1., 0.], [0., 0., 1.], [1., 0., 0.], 3, 3), // y = 1
    ];
    let mut pos = Vec::new();
    let mut tri = Vec::new();
    let mut patches = Vec::new();
    for (o, a, b, m, n) in faces {
        patches.push(planar(o, a, b, m, n));
        let base = pos.len() as u32;
        let add = |u: [f64; 3], v: [f64; 3]| [0, 1, 2].map(|c| u[c] + v[c]);
        pos.extend([o, add(o, a), add(add(o, a), b), add(o, b)]);
        tri.push([base, base + 1, base + 2]);
        tri.push([base, base + 2, base + 3]);
    }
    (
        PatchSet::new(patches).unwrap(),
        Mesh::from_slices(&pos, &tri).unwrap(),
    )
}

#[test]
fn planar_patches_equal_the_triangle_evaluator() {
    let (set, mesh) = open_box();
    let exact = WindingNumber::new(&mesh).unwrap();
    let mut rng = Rng(7);
    let mut worst = 0.0f64;
    for k in 0..400 {
        let q = rng.point(-0.5, 1.5);
        let ray = RayAxis::ALL[k % 6];
        let w = with(&set, ray, 1e-15).eval(q);
        let r = exact.eval(q);
        worst = worst.max((w - r).abs());
    }
    assert!(worst < 1e-12, "worst difference {worst:e}");
    // Inside the open box, on the axis: 5/6 by symmetry.
    let w = PatchWindingNumber::new(&set).eval([0.5, 0.5, 0.5]);
    assert!((w - 5.0 / 6.0).abs() < 1e-12, "{w}");
}

/// The unit sphere as 8 rational biquadratic patches (quarter circles × half meridians), outward.
fn sphere() -> PatchSet {
    PatchSet::new(common::rational_sphere_patches()).unwrap()
}

#[test]
fn rational_sphere_is_one_inside_and_zero_outside() {
    let set = sphere();
    let wn = PatchWindingNumber::new(&set);
    // Only the collapsed pole edges are left out of the pairing: no boundary.
    assert_eq!(wn.edge_counts(), (0, 12, 8));
    let mut rng = Rng(11);
    let mut checked = 0;
    while checked < 600 {
        let q = rng.point(-1.6, 1.6);
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        if (r - 1.0).abs() < 1e-3 {
            continue;
        }
        let expected = if r < 1.0 { 1.0 } else { 0.0 };
        let w = with(&set, RayAxis::ALL[checked % 6], 1e-12).eval(q);
        assert!((w - expected).abs() < 1e-12, "q = {q:?}: {w}");
        checked += 1;
    }
    // Centre and poles' axis: every ray from the centre passes through a pole or an equator
    // point shared by patches.
    for ray in RayAxis::ALL {
        let w = with(&set, ray, 1e-12).eval([0.0; 3]);
        assert!((w - 1.0).abs() < 1e-12, "{ray:?}: {w}");
    }
}

/// The crossings of the segment `a → b` with the unit sphere (`t` and the point, which is the
/// outward normal),
/// or `None` where a closed form and a hit search may fairly disagree: a tangent segment, a
/// crossing within `margin` of an end, or one within `margin` of a pole (the patches'
/// collapsed edges, where the search proposes nothing).
fn unit_sphere_crossings(a: [f64; 3], b: [f64; 3], margin: f64) -> Option<Vec<(f64, [f64; 3])>> {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let (qa, qb, qc) = (dot(d, d), 2.0 * dot(a, d), dot(a, a) - 1.0);
    let disc = qb * qb - 4.0 * qa * qc;
    if disc < 0.0 {
        return Some(Vec::new());
    }
    let length = qa.sqrt();
    // Roots closer than 2·margin along the segment: nearly tangent.
    if disc.sqrt() / qa * length < 2.0 * margin {
        return None;
    }
    let mut out = Vec::new();
    for s in [-1.0, 1.0] {
        let t = (-qb + s * disc.sqrt()) / (2.0 * qa);
        if t * length < -margin || (1.0 - t) * length < -margin {
            continue;
        }
        let p = [0, 1, 2].map(|k| a[k] + t * d[k]);
        if t * length < margin || (1.0 - t) * length < margin || p[0].hypot(p[1]) < margin {
            return None;
        }
        out.push((t, p));
    }
    Some(out)
}

/// A Bézier set's segment crossings are the ray hit search of the STEP evaluator on its
/// patches: on the exact rational sphere, 5,000 short segments in seven directions (axes,
/// diagonals, oblique) give the closed-form crossings, `t` within 1e-9 and normals radial;
/// a crossing on a seam between two patches (the equator, here) is listed once.
#[test]
fn segment_crossings_of_a_patch_set_are_the_closed_form_ones() {
    let set = sphere();
    let wn = PatchWindingNumber::new(&set);
    let mut rng = Rng(29);
    let directions = crate::step_fixtures::SEGMENT_DIRECTIONS;
    let (mut checked, mut crossings) = (0, 0);
    for k in 0..5000 {
        let a = rng.point(-1.3, 1.3);
        let d = directions[k % directions.len()];
        let length = 0.05 + 0.6 * rng.point(0.0, 1.0)[0];
        let scale = length / d.iter().map(|x| x * x).sum::<f64>().sqrt();
        let b = [0, 1, 2].map(|i| a[i] + scale * d[i]);
        let Some(expected) = unit_sphere_crossings(a, b, 1e-3) else {
            continue;
        };
        // On the unit sphere the crossing point is its own unit normal.
        crate::step_fixtures::assert_crossings_are(a, b, &wn.segment_crossings(a, b), &expected);
        checked += 1;
        crossings += expected.len();
    }
    assert!(
        checked > 4500 && crossings > 500,
        "{checked} segments, {crossings} crossings"
    );
    // Through the equator, where the north and south patches meet: once.
    let seam = wn.segment_crossings([0.6, 0.0, 0.0], [1.4, 0.0, 0.0]);
    assert_eq!(seam.len(), 1, "{seam:?}");
    assert!((seam[0].t - 0.5).abs() < 1e-12, "{seam:?}");
    // Through the centre along a diagonal: in and out, both found.
    let through = wn.segment_crossings([-1.0, -0.5, 0.4], [1.0, 0.5, -0.4]);
    assert_eq!(through.len(), 2, "{through:?}");
    // Short of the sphere, degenerate and non-finite: none.
    assert!(
        wn.segment_crossings([0.0, 0.0, 0.1], [0.5, 0.0, 0.1])
            .is_empty()
    );
    assert!(wn.segment_crossings([0.5; 3], [0.5; 3]).is_empty());
    assert!(
        wn.segment_crossings([f64::NAN, 0.0, 0.0], [2.0, 0.0, 0.0])
            .is_empty()
    );
}

#[test]
fn hemisphere_cap_on_its_axis_is_the_closed_form() {
    let set = PatchSet::new(sphere().patches()[4..].to_vec()).unwrap();
    for h in [
        -3.0, -1.0, -0.5, -1e-3, 1e-9, 0.25, 0.5, 0.999, 1.001, 2.0, 10.0,
    ] {
        let disk = 0.5 * (1.0 - f64::abs(h) / (1.0 + h * h).sqrt());
        let expected = if h > 0.0 && h < 1.0 { 1.0 } else { 0.0 } - f64::signum(h) * disk;
        for ray in RayAxis::ALL {
            let w = with(&set, ray, 1e-13).eval([0.0, 0.0, h]);
            assert!(
                (w - expected).abs() < 1e-11,
                "h = {h}, {ray:?}: {w} vs {expected}"
            );
        }
    }
}

#[test]
fn tessellation_converges_to_the_patch_values() {
    // The open hemisphere: tessellations at k and 2k, Richardson-extrapolated, agree with the
    // patch evaluator within the extrapolation's own error estimate.
    let set = PatchSet::new(sphere().patches()[4..].to_vec()).unwrap();
    let wn = with(&set, RayAxis::PosZ, 1e-13);
    let coarse = WindingNumber::new(&tessellate(&set, 32).unwrap()).unwrap();
    let fine = WindingNumber::new(&tessellate(&set, 64).unwrap()).unwrap();
    let mut rng = Rng(5);
    let mut n = 0;
    while n < 200 {
        let q = rng.point(-1.5, 1.5);
        let r = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
        if (r - 1.0).abs() < 0.05 {
            continue;
        }
        let (a, b) = (coarse.eval(q), fine.eval(q));
        let reference = (4.0 * b - a) / 3.0;
        let est = (reference - b).abs();
        let w = wn.eval(q);
        assert!(
            (w - reference).abs() <= 0.5 * est + 1e-9,
            "q = {q:?}: {w} vs {reference} (estimate {est:e})"
        );
        n += 1;
    }
}

/// A tolerance that is not a finite positive number is refused (it used to become the default
/// silently).
#[test]
fn evaluator_refuses_a_bad_tolerance() {
    let (set, _) = open_box();
    for t in [f64::NAN, -1e-8, 0.0, f64::NEG_INFINITY, f64::INFINITY] {
        let options = Options {
            ray: RayAxis::PosZ,
            tolerance: t,
        };
        let e = PatchWindingNumber::with_options(&set, options).unwrap_err();
        assert_eq!(e.to_string(), gwn::patch::ToleranceError(t).to_string());
        assert!(e.to_string().contains("finite positive"), "{e}");
    }
    assert!(
        with(&set, RayAxis::PosZ, 1e-6)
            .eval([0.5, 0.5, 0.5])
            .is_finite()
    );
}

/// On an open boundary edge the patch evaluator's value is the principal value on every ray:
/// the mesh direct sum's value there (triangles in whose plane the query lies contribute 0),
/// 1/4 on the rim of the open box and 1/8 at its corners; flagged, with an estimate covering
/// the jump of `w` around the edge.
#[test]
fn open_box_rim_gets_the_principal_value_on_every_ray() {
    let (set, mesh) = open_box();
    for q in [
        [0.5, 0.0, 1.0],
        [1.0, 0.3, 1.0],
        [0.25, 1.0, 1.0],
        [1.0, 1.0, 1.0],
    ] {
        let direct = gwn::eval::direct::winding_number_direct(&mesh, q);
        for ray in RayAxis::ALL {
            let e = with(&set, ray, 1e-10).evaluate(q);
            assert!(
                (e.value - direct).abs() < 1e-12,
                "{q:?} {ray:?} {e:?} vs {direct}"
            );
            assert!(
                !e.certified && e.error_estimate >= 0.5,
                "{q:?} {ray:?} {e:?}"
            );
        }
    }
}
