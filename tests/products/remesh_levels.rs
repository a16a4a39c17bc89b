//! The remesher's decisive values (`products::remesh::levels`): a first pass of certified
//! approximate values, the field itself only where an approximation's interval holds a level
//! the remesher compares `w` with. Every decision must be the one the field's own values make:
//! the same corners classified, cells split and refined, planar levels and triangles — even when
//! the evaluator answers the first pass at the far end of its bound.

use std::sync::atomic::{AtomicUsize, Ordering};

use gwn::Mesh;
use gwn::eval::Evaluator;
use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::levels::SCREENING_TOLERANCE;
use gwn::products::remesh::{RemeshOptions, Remeshed, remesh_guided};

use crate::remesh::{sphere, with_flipped_faces};

/// The exact evaluator with a first pass that answers as the test asks, counting its points:
/// with `far_end` false, the field's own values (bound 0: nothing approximated); with it true,
/// as wrong as the bound (the screening tolerance) allows — each value moved by 0.99 of it, up
/// or down by a hash of the point.
struct FirstPass<'a> {
    field: &'a WindingNumber,
    far_end: bool,
    points: AtomicUsize,
}

impl<'a> FirstPass<'a> {
    fn new(field: &'a WindingNumber, far_end: bool) -> Self {
        FirstPass {
            field,
            far_end,
            points: AtomicUsize::new(0),
        }
    }
}

impl Evaluator for FirstPass<'_> {
    fn eval(&self, q: [f64; 3]) -> f64 {
        self.field.eval(q)
    }
    fn eval_batch(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.field.eval_batch(points)
    }
    fn eval_batch_within(&self, points: &[[f64; 3]], tolerance: f64) -> Vec<(f64, f64)> {
        self.points.fetch_add(points.len(), Ordering::Relaxed);
        let b = if self.far_end { tolerance } else { 0.0 };
        self.field
            .eval_batch(points)
            .into_iter()
            .zip(points)
            .map(|(w, p)| {
                let h = p.iter().fold(0u64, |h, c| {
                    (h ^ c.to_bits()).wrapping_mul(0x9E37_79B9_7F4A_7C15)
                });
                let s = if h >> 63 == 1 { 1.0 } else { -1.0 };
                (w + s * 0.99 * b, b)
            })
            .collect()
    }
}

/// A ball with a tenth of its faces flipped (`w` about 0.8 inside, fractional next to the flips),
/// a consistent box (integral `w`, flat sides for the planar levels) and a consistent small ball.
fn mixed_input() -> Mesh {
    let ball = with_flipped_faces(&sphere([0.0, 0.0, 0.0], 1.0, 20, false), |i| i % 10 == 3);
    let cube = crate::common::unit_cube();
    let shifted: Vec<[f64; 3]> = cube
        .positions()
        .iter()
        .map(|p| [p[0] * 1.5 + 1.4, p[1] * 1.2 - 0.6, p[2] * 0.9 - 0.4])
        .collect();
    let cube = Mesh::new(shifted, cube.triangles().to_vec()).unwrap();
    let small = sphere([-0.2, 1.6, 0.3], 0.45, 12, false);
    ball.concatenated(&cube)
        .unwrap()
        .concatenated(&small)
        .unwrap()
}

/// Without simplification; `probe_flatness: false` keeps every planar level (the corners'
/// integrality then decides which cells stay whole).
fn run<E: Evaluator>(evaluator: &E, mesh: &Mesh, res: usize, probe_flatness: bool) -> Remeshed {
    let options = RemeshOptions {
        simplify: None,
        probe_flatness,
        ..RemeshOptions::with_resolution(res)
    };
    remesh_guided(
        evaluator,
        Some(&SegmentBvh::of_field_mesh(mesh)),
        mesh.bounding_box().unwrap(),
        &options,
        &|_| {},
    )
    .unwrap()
}

/// Everything the classes decide (placement's interpolation may probe elsewhere, so vertex
/// positions and placement evaluations are not compared).
fn assert_same_decisions(a: &Remeshed, b: &Remeshed, what: &str) {
    let (s, t) = (&a.stats, &b.stats);
    assert_eq!(
        (
            s.classified_points,
            s.split_cells,
            s.band_cells,
            s.refined_cells,
            s.planar_levels
        ),
        (
            t.classified_points,
            t.split_cells,
            t.band_cells,
            t.refined_cells,
            t.planar_levels
        ),
        "{what}"
    );
    assert_eq!(a.positions.len(), b.positions.len(), "{what}");
    assert!(a.triangles == b.triangles, "{what}: the triangles differ");
}

#[test]
fn first_passes_at_the_far_end_of_their_bound_decide_like_the_field() {
    const { assert!(SCREENING_TOLERANCE > 0.0 && SCREENING_TOLERANCE <= 0.125) };
    let mesh = mixed_input();
    let wn = WindingNumber::new(&mesh).unwrap();
    assert!(wn.boundary_edge_count() > 100);
    for (res, probe) in [(24, true), (40, false), (128, true)] {
        let own_values = FirstPass::new(&wn, false);
        let own = run(&own_values, &mesh, res, probe);
        assert!(probe || own.stats.planar_levels > 0, "{:?}", own.stats);
        let far_end = FirstPass::new(&wn, true);
        let far = run(&far_end, &mesh, res, probe);
        assert_same_decisions(&own, &far, &format!("far end of the bound, res {res}"));
        // The same points evaluated outside placement (whose interpolation may probe
        // elsewhere): the same transition leaves lent, their corners' integrality settled by
        // the field rather than their splits evaluated (which would give the same classes).
        let outside_placement = |first_pass: &AtomicUsize, r: &Remeshed| {
            first_pass.load(Ordering::Relaxed) - r.stats.placement_evaluations
        };
        assert_eq!(
            outside_placement(&own_values.points, &own),
            outside_placement(&far_end.points, &far),
            "points evaluated outside placement, res {res}"
        );
        // The exact evaluator's own first pass (its hierarchy at the screening tolerance).
        let exact = run(&wn, &mesh, res, probe);
        assert_same_decisions(&own, &exact, &format!("exact evaluator, res {res}"));
    }
}
