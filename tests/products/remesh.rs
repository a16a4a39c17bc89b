//! `products::remesh`: closed forms (sphere, torus, nested and disjoint solids), double walls and
//! inner faces, an open mesh, and occupancy agreement of output against input.

use crate::common;

use gwn::Mesh;
use gwn::eval::Evaluator;
use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::crossings::SegmentBvh;
use gwn::products::remesh::intersect::self_intersections;
use gwn::products::remesh::report::{
    TopologyReport, hausdorff_distance, hausdorff_to_solid_boundary,
};
use gwn::products::remesh::{RemeshError, RemeshOptions, Remeshed, remesh, remesh_guided};
use gwn::products::sdf::SignedDistance;

/// A field that is noise at a scale near the cells' (integers 0 and 1), so that cells of every
/// level and every transition split see every labelling (the sub-cell and planar proptests).
pub(crate) struct Noise(pub(crate) f64);

impl Evaluator for Noise {
    fn eval(&self, q: [f64; 3]) -> f64 {
        let cell = q.map(|x| (x * self.0).floor() as i64);
        let k = (cell[0] * 73_856_093) ^ (cell[1] * 19_349_663) ^ (cell[2] * 83_492_791);
        if k.rem_euclid(3) == 0 { 1.0 } else { 0.0 }
    }
}

/// `mesh` with the faces whose index `flip` selects turned around (an inconsistently oriented
/// input: its signed boundary runs around every flipped patch).
pub(crate) fn with_flipped_faces(mesh: &Mesh, flip: impl Fn(usize) -> bool) -> Mesh {
    let triangles: Vec<[u32; 3]> = mesh
        .triangles()
        .iter()
        .enumerate()
        .map(|(i, &t)| if flip(i) { [t[0], t[2], t[1]] } else { t })
        .collect();
    Mesh::new(mesh.positions().to_vec(), triangles).unwrap()
}

/// UV sphere of radius `r` centred at `c`, outward (`flip`: inward), `n` segments.
pub(crate) fn sphere(c: [f64; 3], r: f64, n: usize, flip: bool) -> Mesh {
    let (rings, segs) = (n, 2 * n);
    let mut v = vec![[c[0], c[1], c[2] - r], [c[0], c[1], c[2] + r]];
    for i in 1..rings {
        let th = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segs {
            let ph = 2.0 * std::f64::consts::PI * j as f64 / segs as f64;
            v.push([
                c[0] + r * th.sin() * ph.cos(),
                c[1] + r * th.sin() * ph.sin(),
                c[2] - r * th.cos(),
            ]);
        }
    }
    let at = |i: usize, j: usize| (2 + (i - 1) * segs + j % segs) as u32;
    let mut f = Vec::new();
    for j in 0..segs {
        f.push([0, at(1, j + 1), at(1, j)]);
        f.push([1, at(rings - 1, j), at(rings - 1, j + 1)]);
        for i in 1..rings - 1 {
            f.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
            f.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
        }
    }
    let m = Mesh::new(v, f).unwrap();
    if flip { m.flipped() } else { m }
}

/// Torus around z, radii `big` and `small`, outward.
pub(crate) fn torus(big: f64, small: f64, n: usize) -> Mesh {
    let (nu, nv) = (2 * n, n);
    let mut v = Vec::new();
    for i in 0..nu {
        let u = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
        for j in 0..nv {
            let w = 2.0 * std::f64::consts::PI * j as f64 / nv as f64;
            let rr = big + small * w.cos();
            v.push([rr * u.cos(), rr * u.sin(), small * w.sin()]);
        }
    }
    let at = |i: usize, j: usize| ((i % nu) * nv + j % nv) as u32;
    let mut f = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            f.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            f.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Mesh::new(v, f).unwrap()
}

/// Remeshes `mesh` (simplified, the default) with its own triangles as the placement guide,
/// and checks with exact predicates that the output has no self-intersection.
pub(crate) fn run(mesh: &Mesh, res: usize) -> (Remeshed, TopologyReport) {
    run_with(mesh, &RemeshOptions::with_resolution(res))
}

/// [`run`] without simplification: the marching-tetrahedra surface.
pub(crate) fn run_raw(mesh: &Mesh, res: usize) -> (Remeshed, TopologyReport) {
    run_with(mesh, &raw(res))
}

pub(crate) fn raw(res: usize) -> RemeshOptions {
    RemeshOptions {
        simplify: None,
        ..RemeshOptions::with_resolution(res)
    }
}

pub(crate) fn run_with(mesh: &Mesh, options: &RemeshOptions) -> (Remeshed, TopologyReport) {
    let wn = WindingNumber::new(mesh).unwrap();
    let guide = SegmentBvh::of_mesh(mesh);
    let out = remesh_guided(
        &wn,
        Some(&guide),
        mesh.bounding_box().unwrap(),
        options,
        &|_| {},
    )
    .unwrap();
    // The exact check costs ~1 µs per face pair in the test profile: only on small outputs.
    if out.triangles.len() <= 50_000 {
        assert_no_self_intersections(&out);
    }
    let report = TopologyReport::of(&out.positions, &out.triangles);
    (out, report)
}

pub(crate) fn assert_no_self_intersections(out: &Remeshed) {
    let si = self_intersections(&out.fixed, &out.triangles, u64::MAX).unwrap();
    assert_eq!((si.pairs, si.degenerate_faces), (0, 0), "{si:?}");
    // Neighbouring faces were really compared.
    assert!(si.tested_pairs >= out.triangles.len(), "{si:?}");
}

/// Remeshes `mesh` with `options`, guided by its own triangles, with its winding number or
/// (`noise`: the scale) [`Noise`] as the field, and asserts every guarantee on a non-empty
/// output: closed, manifold, oriented, no self-intersection (exact). With its own winding
/// number the guide is declared the field's surface, as in the CLI: the testing kit's soups and
/// inconsistent meshes then have their thin-part probes screened by the approximation.
pub(crate) fn assert_guarantees_on(mesh: &Mesh, options: &RemeshOptions, noise: Option<f64>) {
    let Some(bounds) = mesh.bounding_box() else {
        return;
    };
    let guide = match noise {
        Some(_) => SegmentBvh::of_mesh(mesh),
        None => SegmentBvh::of_field_mesh(mesh),
    };
    let wn;
    let noisy;
    let field: &dyn Evaluator = match noise {
        Some(scale) => {
            noisy = Noise(scale);
            &noisy
        }
        None => {
            wn = WindingNumber::new(mesh).unwrap();
            &wn
        }
    };
    let out = remesh_guided(field, Some(&guide), bounds, options, &|_| {}).unwrap();
    let report = TopologyReport::of(&out.positions, &out.triangles);
    if report.faces > 0 {
        assert_closed_manifold(&report);
        assert_no_self_intersections(&out);
    }
}

pub(crate) fn assert_closed_manifold(r: &TopologyReport) {
    assert!(r.faces > 0, "{r}");
    assert!(
        r.closed && r.edge_manifold && r.vertex_manifold && r.oriented,
        "{r}"
    );
    assert_eq!(r.degenerate_faces, 0, "{r}");
}

/// Every vertex of `out` within a cell of the unit sphere centred at `c`, and the enclosed volume
/// within `volume_tolerance` (relative) of the ball's.
fn assert_unit_sphere_like(out: &Remeshed, c: [f64; 3], volume_tolerance: f64, res: usize) {
    for p in &out.positions {
        let d = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
        assert!(
            (d - 1.0).abs() < out.cell_size,
            "res {res}: vertex at radius {d}"
        );
    }
    let vol = signed_volume(out, |_| true);
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    assert!(
        (vol / ball - 1.0).abs() < volume_tolerance,
        "res {res}: volume {vol}"
    );
}

/// Signed volume of the triangles selected by `keep` (outward orientation: positive).
pub(crate) fn signed_volume(out: &Remeshed, keep: impl Fn([f64; 3]) -> bool) -> f64 {
    let mut vol = 0.0;
    for t in &out.triangles {
        let [a, b, c] = t.map(|i| out.positions[i as usize]);
        if !keep(a) {
            continue;
        }
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
            + a[2] * (b[0] * c[1] - b[1] * c[0]))
            / 6.0;
    }
    vol
}

/// Volume enclosed by a closed, outward-oriented mesh.
pub(crate) fn mesh_volume(mesh: &Mesh) -> f64 {
    let v = mesh.positions();
    mesh.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// Fraction of `n` random points in the input's box (grown by 10 %) farther than `cells` cells
/// from the output surface where input and output agree on `w > ½`; also the number compared.
pub(crate) fn occupancy_agreement(
    mesh: &Mesh,
    out: &Remeshed,
    n: usize,
    cells: f64,
) -> (f64, usize) {
    let input = WindingNumber::new(mesh).unwrap();
    let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let output = SignedDistance::new(&out_mesh).unwrap();
    let bb = mesh.bounding_box().unwrap();
    let mut rng = common::Rng(0x5eed_1234);
    let (mut agree, mut total) = (0usize, 0usize);
    for _ in 0..n {
        let q: [f64; 3] = std::array::from_fn(|a| {
            let pad = 0.1 * (bb.max[a] - bb.min[a]);
            rng.range(bb.min[a] - pad, bb.max[a] + pad)
        });
        let (sd, w_out) = output.eval_with_winding(q);
        if sd.abs() <= cells * out.cell_size {
            continue;
        }
        total += 1;
        if (input.eval(q) > 0.5) == (w_out > 0.5) {
            agree += 1;
        }
    }
    (agree as f64 / total as f64, total)
}

#[test]
fn sphere_is_a_closed_genus_zero_manifold_near_the_input() {
    let mesh = sphere([0.1, -0.2, 0.3], 1.0, 24, false);
    for res in [8, 32, 100] {
        let (out, r) = run_raw(&mesh, res);
        assert_closed_manifold(&r);
        assert_eq!(
            (r.euler_characteristic, r.components),
            (2, 1),
            "res {res}: {r}"
        );
        // Every vertex is within a cell of the polyhedral sphere (bisection on the true field).
        assert_unit_sphere_like(&out, [0.1, -0.2, 0.3], 0.05, res);
    }
}

#[test]
fn resolution_256_refines_only_the_band() {
    let mesh = sphere([0.0; 3], 1.0, 24, false);
    let wn = WindingNumber::new(&mesh).unwrap();
    // Topology and memory do not depend on placement: no bisection keeps the test short.
    let options = RemeshOptions {
        bisection_steps: 0,
        ..raw(256)
    };
    let out = remesh(&wn, mesh.bounding_box().unwrap(), &options).unwrap();
    let r = TopologyReport::of(&out.positions, &out.triangles);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    let lattice_points: usize = out.stats.lattice_cells.iter().map(|n| n + 1).product();
    // The classified points are a thin shell: far fewer than the lattice's (~17 M).
    assert!(
        out.stats.classified_points * 10 < lattice_points,
        "{:?}",
        out.stats
    );
}

#[test]
fn torus_has_euler_characteristic_zero() {
    let mesh = torus(1.0, 0.4, 24);
    for res in [16, 48] {
        let (_, r) = run(&mesh, res);
        assert_closed_manifold(&r);
        assert_eq!(
            (r.euler_characteristic, r.components),
            (0, 1),
            "res {res}: {r}"
        );
    }
}

#[test]
fn hollow_shell_gives_two_nested_components_oriented_apart() {
    let outer = sphere([0.0; 3], 1.0, 24, false);
    let inner = sphere([0.0; 3], 0.5, 16, true);
    let shell = outer.concatenated(&inner).unwrap();
    let (out, r) = run(&shell, 48);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (4, 2), "{r}");
    let radius = |p: [f64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    let v_outer = signed_volume(&out, |p| radius(p) > 0.75);
    let v_inner = signed_volume(&out, |p| radius(p) < 0.75);
    assert!(v_outer > 0.0 && v_inner < 0.0, "{v_outer} {v_inner}");
    // Both spheres outward: w = 2 inside the small one is still inside; one ball.
    let doubled = outer
        .concatenated(&sphere([0.0; 3], 0.5, 16, false))
        .unwrap();
    let (_, r) = run(&doubled, 48);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
}

#[test]
fn disjoint_cubes_stay_two_solids() {
    let a = common::unit_cube();
    let b = a.translated([1.5, 0.2, 0.0]);
    let (_, r) = run(&a.concatenated(&b).unwrap(), 40);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (4, 2), "{r}");
}

/// A plate 2.5 finest cells thick between two coarse lattice planes (res 256: a coarse cell is 4
/// finest cells), so no coarse corner is inside it: corner differences alone never find it; the
/// cells its triangles meet are refined and it is kept, closed and with its volume.
#[test]
fn plate_thinner_than_a_coarse_cell_is_kept() {
    use gwn::products::remesh::lattice::Lattice;
    let bounds = gwn::BoundingBox {
        min: [0.0; 3],
        max: [1.0; 3],
    };
    let res = 256;
    let lattice = Lattice::new(bounds, res).unwrap();
    assert_eq!(lattice.levels, 2);
    let h = lattice.h[0];
    assert_eq!(lattice.h, [h; 3], "a cube box has cubic cells");
    let coarse = 4.0 * h;
    // Coarse planes sit at origin + k·coarse on every axis; the plate spans (0.75 h, 3.25 h)
    // past one of them in z, and starts and ends off the lattice in x and y.
    let o = lattice.origin;
    let lo = [
        o[0] + 30.0 * coarse + 0.3 * h,
        o[1] + 31.0 * coarse + 0.6 * h,
        o[2] + 33.0 * coarse + 0.75 * h,
    ];
    let size = [0.12, 0.1, 2.5 * h];
    let cube = common::unit_cube();
    let positions: Vec<[f64; 3]> = cube
        .positions()
        .iter()
        .map(|p| std::array::from_fn(|a| lo[a] + p[a] * size[a]))
        .collect();
    let plate = Mesh::new(positions, cube.triangles().to_vec()).unwrap();
    let wn = WindingNumber::new(&plate).unwrap();
    let options = RemeshOptions::with_resolution(res);
    // Without the triangles, only corner differences refine: nothing is found.
    let blind = remesh(&wn, bounds, &options).unwrap();
    assert!(blind.triangles.is_empty(), "{:?}", blind.stats);
    let guide = SegmentBvh::of_mesh(&plate);
    let out = remesh_guided(&wn, Some(&guide), bounds, &options, &|_| {}).unwrap();
    let r = TopologyReport::of(&out.positions, &out.triangles);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    assert_no_self_intersections(&out);
    let vol = signed_volume(&out, |_| true);
    let want = size[0] * size[1] * size[2];
    assert!((vol / want - 1.0).abs() < 0.1, "volume {vol}, plate {want}");
    // Refinement follows the plate, not the whole box.
    let lattice_points: usize = out.stats.lattice_cells.iter().map(|n| n + 1).product();
    assert!(
        out.stats.classified_points * 10 < lattice_points,
        "{:?}",
        out.stats
    );
}

/// A closed plate of 100 × 100 × 1 at res 64: cubes of `100 / 64` would put no lattice plane
/// inside it (the lattice is centred on the box, so its planes nearest the middle are ±0.78 off
/// it) and the output would be empty; the thin axis gets `64 / 4` cells across instead.
#[test]
fn plate_thinner_than_a_cube_cell_is_kept() {
    use gwn::products::remesh::lattice::{Lattice, THIN_AXIS_DIVISOR};
    use gwn::products::remesh::report::occupancy_agreement;
    let size = [100.0, 100.0, 1.0];
    let cube = common::unit_cube();
    let positions: Vec<[f64; 3]> = cube
        .positions()
        .iter()
        .map(|p| std::array::from_fn(|a| 3.0 + (p[a] - 0.5) * size[a]))
        .collect();
    let plate = Mesh::new(positions, cube.triangles().to_vec()).unwrap();
    let bounds = plate.bounding_box().unwrap();
    let res = 64;
    let lattice = Lattice::new(bounds, res).unwrap();
    assert_eq!(lattice.h[0], 100.0 / 64.0);
    assert_eq!(lattice.h[1], 100.0 / 64.0);
    assert_eq!(lattice.h[2], THIN_AXIS_DIVISOR / 64.0);
    for simplify in [false, true] {
        let options = if simplify {
            RemeshOptions::with_resolution(res)
        } else {
            raw(res)
        };
        let (out, r) = run_with(&plate, &options);
        assert_closed_manifold(&r);
        assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
        assert_eq!(out.cell_size, 100.0 / 64.0);
        let vol = signed_volume(&out, |_| true);
        assert!((vol / 1e4 - 1.0).abs() < 0.02, "volume {vol}");
        let wn = WindingNumber::new(&plate).unwrap();
        let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
        let output = WindingNumber::new(&out_mesh).unwrap();
        let agreement = occupancy_agreement(&wn, &output, bounds, 20_000, 7).unwrap();
        assert!(
            agreement >= 0.99,
            "simplify {simplify}: agreement {agreement}"
        );
    }
}

/// A 1.5-thick plate of 100 × 100 on a 40-high pedestal at res 32: the box is not thin (the
/// pedestal), so cells are cubes of 3.125 and the plate, placed between two lattice planes, holds
/// no lattice point off the pedestal. The plate probe finds it (a plate run along z over most of
/// the lines) and makes the cells 4 times finer along z, which puts lattice planes inside it.
#[test]
fn plate_thinner_than_a_cell_on_a_pedestal_gets_finer_cells_across_it() {
    use gwn::products::remesh::lattice::Lattice;
    let cube = common::unit_cube();
    let block = |lo: [f64; 3], hi: [f64; 3]| -> Vec<[f64; 3]> {
        cube.positions()
            .iter()
            .map(|p| std::array::from_fn(|a| lo[a] + p[a] * (hi[a] - lo[a])))
            .collect()
    };
    let (pedestal_lo, pedestal_hi) = ([40.0, 40.0, 0.0], [60.0, 60.0, 40.0]);
    let bounds = gwn::BoundingBox {
        min: [0.0, 0.0, 0.0],
        max: [100.0, 100.0, 40.0],
    };
    let res = 32;
    let h = 100.0 / res as f64;
    let lattice = Lattice::new(bounds, res).unwrap();
    assert_eq!(lattice.h, [h; 3]);
    // Between the lattice planes k and k + 1 near z = 25 (0.8 above one, 0.825 below the next).
    let k = ((25.0 - lattice.origin[2]) / h).ceil();
    let z0 = lattice.origin[2] + k * h + 0.8;
    let thickness = 1.5;
    let mut positions = block(pedestal_lo, pedestal_hi);
    positions.extend(block([0.0, 0.0, z0], [100.0, 100.0, z0 + thickness]));
    let mut triangles = cube.triangles().to_vec();
    triangles.extend(cube.triangles().iter().map(|t| t.map(|v| v + 8)));
    let mesh = Mesh::new(positions, triangles).unwrap();
    assert_eq!(mesh.bounding_box().unwrap(), bounds);
    let wn = WindingNumber::new(&mesh).unwrap();
    // Points in the plate, over a cell and a half away from its rim and the pedestal (where
    // chamfers cut corners off): all inside the input.
    let mut rng = common::Rng(0x51ab);
    let in_plate: Vec<[f64; 3]> = std::iter::repeat_with(|| {
        [
            rng.range(5.0, 95.0),
            rng.range(5.0, 95.0),
            rng.range(z0 + 0.1, z0 + thickness - 0.1),
        ]
    })
    .filter(|p| !(35.0..65.0).contains(&p[0]) || !(35.0..65.0).contains(&p[1]))
    .take(2000)
    .collect();
    assert!(in_plate.iter().all(|&p| wn.eval(p) > 0.5));
    let kept = |out: &Remeshed| {
        let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
        let output = WindingNumber::new(&out_mesh).unwrap();
        let inside = output
            .eval_batch(&in_plate)
            .iter()
            .filter(|&&w| w > 0.5)
            .count();
        inside as f64 / in_plate.len() as f64
    };
    // Without the probe (and without sub-cell levels, which find much of the plate too: 97 %
    // kept at one level): the plate is lost wherever the pedestal does not hold it up.
    let (coarse, r) = run_with(
        &mesh,
        &RemeshOptions {
            refine_plates: false,
            sub_cell_levels: 0,
            ..RemeshOptions::with_resolution(res)
        },
    );
    assert_closed_manifold(&r);
    assert_eq!(coarse.cell_sizes, [h; 3]);
    assert!(kept(&coarse) < 0.1, "kept {}", kept(&coarse));
    for options in [RemeshOptions::with_resolution(res), raw(res)] {
        let (out, r) = run_with(&mesh, &options);
        assert_closed_manifold(&r);
        assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
        let plates = out.stats.plates;
        // Wanted: 2 cells across 1.5 (4.17 times finer), capped at 4.
        assert_eq!(plates.refinement, [1.0, 1.0, 4.0], "{plates:?}");
        assert!((plates.thickness[2].unwrap() - thickness).abs() < 1e-9);
        assert!(plates.thin_fraction[2] > 0.02, "{plates:?}");
        assert_eq!(out.cell_sizes, [h, h, h / 4.0]);
        // Distances in cells keep the resolution's cell.
        assert_eq!(out.cell_size, h);
        assert_eq!(kept(&out), 1.0);
        let want = 20.0 * 20.0 * 40.0 + 100.0 * 100.0 * thickness - 20.0 * 20.0 * thickness;
        let vol = signed_volume(&out, |_| true);
        assert!((vol / want - 1.0).abs() < 0.02, "volume {vol}, want {want}");
    }
}

#[test]
fn double_walls_and_inner_faces_vanish() {
    // Two cubes sharing the face x = 1: the double wall is inside the union (w = 1 on both sides).
    let a = common::unit_cube();
    let b = a.translated([1.0, 0.0, 0.0]);
    let (out, r) = run(&a.concatenated(&b).unwrap(), 40);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    let vol = signed_volume(&out, |_| true);
    assert!((vol - 2.0).abs() < 0.1, "volume {vol}");
    // Inner faces listed twice, once each way (as dirty exports have them): w is 1 on both
    // sides, so they leave no trace. (A single one-sided inner sheet would not do: w tends to ½
    // on one side of it, and the surface may rightly follow it there.)
    let sheet = Mesh::from_slices(
        &[
            [0.2, 0.2, 0.5],
            [0.8, 0.2, 0.5],
            [0.8, 0.8, 0.5],
            [0.2, 0.8, 0.5],
        ],
        &[[0, 1, 2], [0, 2, 3]],
    )
    .unwrap();
    let doubled = sheet.concatenated(&sheet.flipped()).unwrap();
    let (_, r) = run(&a.concatenated(&doubled).unwrap(), 40);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
}

#[test]
fn open_cube_is_closed_where_w_decides() {
    let mesh = common::open_cube();
    let (out, r) = run(&mesh, 40);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    let (agreement, compared) = occupancy_agreement(&mesh, &out, 3000, 1.0);
    assert!(
        compared > 2000 && agreement >= 0.99,
        "{agreement} of {compared}"
    );
}

/// A lone sheet, whose field tends to exactly ½ on its front: the lattice points on it evaluate
/// to ½ up to the boundary sum's rounding, which a test at `w > ½` turned into point-sized
/// solids that changed with the rounding (gwn::products::remesh::INSIDE_MARGIN). A lone triangle
/// on a plane through lattice points (`x + y + z = 6`, the corpus's assimp-multiple_spaces.obj)
/// has `w < ½` everywhere: nothing, for every ray. A tetrahedron with faces of both orientations
/// (cgal-tet-shuffled.off), whose faces hold lattice points too, is closed and manifold for every
/// ray (its surface is not the same for every ray: docs/remesh.md, "Lattice points on the input").
#[test]
fn fields_that_tend_to_one_half_on_the_faces_are_not_decided_by_rounding() {
    use gwn::RayAxis;
    use gwn::eval::antipodal::Options;
    let lone = Mesh::from_slices(
        &[[1.0, 2.0, 3.0], [2.0, 3.0, 1.0], [3.0, 1.0, 2.0]],
        &[[0, 1, 2]],
    )
    .unwrap();
    let tet = Mesh::from_slices(
        &[
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        &[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
    )
    .unwrap();
    for (name, mesh, res) in [("lone triangle", &lone, 64), ("tetrahedron", &tet, 32)] {
        let guide = SegmentBvh::of_mesh(mesh);
        for ray in RayAxis::ALL {
            let options = Options {
                ray,
                ..Options::default()
            };
            let wn = WindingNumber::with_options(mesh, options).unwrap();
            let bounds = mesh.bounding_box().unwrap();
            let resolution = RemeshOptions::with_resolution(res);
            let out = remesh_guided(&wn, Some(&guide), bounds, &resolution, &|_| {}).unwrap();
            let r = TopologyReport::of(&out.positions, &out.triangles);
            if name == "lone triangle" {
                assert!(out.triangles.is_empty(), "{name}, {ray:?}: {r}");
            } else {
                assert_closed_manifold(&r);
            }
        }
    }
}

#[test]
fn occupancy_agrees_away_from_the_surface() {
    for mesh in [
        sphere([0.0; 3], 1.0, 24, false),
        torus(1.0, 0.4, 24),
        sphere([0.0; 3], 1.0, 24, false)
            .concatenated(&sphere([0.0; 3], 0.5, 16, true))
            .unwrap(),
    ] {
        let (out, _) = run(&mesh, 48);
        let (agreement, compared) = occupancy_agreement(&mesh, &out, 3000, 1.0);
        assert!(
            compared > 2000 && agreement >= 0.99,
            "{agreement} of {compared}"
        );
    }
}

#[test]
fn labelling_of_every_kind_gives_a_closed_manifold() {
    // A field that is noise at lattice scale: any labelling must still give a closed 2-manifold
    // (the extraction's guarantee does not depend on the field being smooth).
    struct Noise;
    impl Evaluator for Noise {
        fn eval(&self, q: [f64; 3]) -> f64 {
            let cell = q.map(|x| (x * 7.3).floor() as i64);
            let k = (cell[0] * 73_856_093) ^ (cell[1] * 19_349_663) ^ (cell[2] * 83_492_791);
            if k.rem_euclid(3) == 0 { 1.0 } else { 0.0 }
        }
    }
    let bounds = gwn::BoundingBox {
        min: [0.0; 3],
        max: [2.0, 1.5, 1.0],
    };
    for res in [7, 20, 130] {
        // Simplified too where the exact check runs (the largest case would only cost time).
        let options = if res <= 20 {
            RemeshOptions::with_resolution(res)
        } else {
            raw(res)
        };
        let out = remesh(&Noise, bounds, &options).unwrap();
        let r = TopologyReport::of(&out.positions, &out.triangles);
        assert_closed_manifold(&r);
        // No self-intersection either, whatever the labelling (docs/remesh.md's argument; the
        // largest case is left out for time).
        if res <= 20 {
            assert_no_self_intersections(&out);
        }
    }
}

#[test]
fn bad_options_are_errors() {
    let mesh = common::unit_cube();
    let wn = WindingNumber::new(&mesh).unwrap();
    let bb = mesh.bounding_box().unwrap();
    assert_eq!(
        remesh(&wn, bb, &RemeshOptions::with_resolution(0)),
        Err(RemeshError::BadResolution { resolution: 0 })
    );
    let budget = RemeshOptions {
        max_classified_points: Some(5000),
        ..RemeshOptions::with_resolution(200)
    };
    assert_eq!(
        remesh(&wn, bb, &budget),
        Err(RemeshError::OutOfMemory { max_points: 5000 })
    );
    // Above the coarse grid (67³ points at res 256), below the band: stops while refining.
    let budget = RemeshOptions {
        max_classified_points: Some(400_000),
        ..RemeshOptions::with_resolution(256)
    };
    assert_eq!(
        remesh(&wn, bb, &budget),
        Err(RemeshError::OutOfMemory {
            max_points: 400_000
        })
    );
    let bad = gwn::BoundingBox {
        min: [0.0, f64::NAN, 0.0],
        max: [1.0; 3],
    };
    assert_eq!(
        remesh(&wn, bad, &RemeshOptions::with_resolution(8)),
        Err(RemeshError::BadBounds)
    );
}

/// The unit ball's indicator, counting its evaluations.
struct CountingBall(std::sync::atomic::AtomicUsize);

impl Evaluator for CountingBall {
    fn eval(&self, q: [f64; 3]) -> f64 {
        self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if q[0] * q[0] + q[1] * q[1] + q[2] * q[2] < 1.0 {
            1.0
        } else {
            0.0
        }
    }
}

/// A resolution whose surface cannot fit the budget is refused levels before the budget is
/// spent: every cell split above the resolution's level leaves one to split on each level
/// below it, so those are counted as soon as the cell is split. Before, the refusal came only
/// when the classified points themselves reached the budget.
#[test]
fn an_absurd_resolution_is_refused_early() {
    let ball = CountingBall(std::sync::atomic::AtomicUsize::new(0));
    let bb = gwn::BoundingBox {
        min: [-1.2; 3],
        max: [1.2; 3],
    };
    let max_points = 4_000_000;
    let options = RemeshOptions {
        max_classified_points: Some(max_points),
        ..RemeshOptions::with_resolution(1 << 16)
    };
    assert_eq!(
        remesh(&ball, bb, &options),
        Err(RemeshError::OutOfMemory { max_points })
    );
    // 971,519 evaluations with the bound; 3,115,537 without it.
    let evaluations = ball.0.load(std::sync::atomic::Ordering::Relaxed);
    assert!(evaluations < max_points / 3, "{evaluations}");
}

/// The early refusal's bound never refuses a run that fits: a budget of exactly the points a
/// run classifies is enough, on a sphere, a noise field (every labelling, sub-levels) and a
/// guided run with plates refined.
#[test]
fn a_budget_of_the_points_a_run_classifies_is_enough() {
    let mesh = sphere([0.1, -0.2, 0.3], 1.0, 24, false);
    let wn = WindingNumber::new(&mesh).unwrap();
    let bb = mesh.bounding_box().unwrap();
    let noise_box = gwn::BoundingBox {
        min: [0.0; 3],
        max: [1.0; 3],
    };
    let guide = SegmentBvh::of_mesh(&mesh);
    for res in [16, 64, 160] {
        let runs: [(
            &dyn Evaluator,
            gwn::BoundingBox,
            Option<&SegmentBvh>,
            RemeshOptions,
        ); 3] = [
            (&wn, bb, None, raw(res)),
            (
                &Noise(f64::from(res as u32) / 3.0),
                noise_box,
                None,
                raw(res.min(64)),
            ),
            (
                &wn,
                bb,
                Some(&guide),
                RemeshOptions {
                    sub_cell_levels: 1,
                    ..raw(res)
                },
            ),
        ];
        for (k, (evaluator, bounds, guide, options)) in runs.into_iter().enumerate() {
            let run =
                |options: &RemeshOptions| remesh_guided(evaluator, guide, bounds, options, &|_| {});
            let used = run(&options).unwrap().stats.classified_points;
            let exact_budget = RemeshOptions {
                max_classified_points: Some(used),
                ..options
            };
            assert!(
                run(&exact_budget).is_ok(),
                "res {res}, run {k}: {used} points"
            );
            let short = RemeshOptions {
                max_classified_points: Some(used - 1),
                ..options
            };
            assert!(run(&short).is_err(), "res {res}, run {k}: {used} points");
        }
    }
}

#[test]
fn oriented_point_cloud_remeshes_with_the_fast_evaluator() {
    use gwn::eval::fast::PointCloudWindingNumber;
    use gwn::mesh::PointCloud;
    // Fibonacci sphere of radius 1, outward normals, equal areas.
    let n = 4000;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let positions: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = golden * i as f64;
            [r * t.cos(), r * t.sin(), z]
        })
        .collect();
    let area = 4.0 * std::f64::consts::PI / n as f64;
    let cloud = PointCloud::new(positions.clone(), positions, Some(vec![area; n])).unwrap();
    let wn = PointCloudWindingNumber::new(&cloud);
    let bounds = gwn::BoundingBox {
        min: [-1.0; 3],
        max: [1.0; 3],
    };
    let out = remesh(&wn, bounds, &RemeshOptions::with_resolution(32)).unwrap();
    let r = TopologyReport::of(&out.positions, &out.triangles);
    assert_closed_manifold(&r);
    assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
    let vol = signed_volume(&out, |_| true);
    assert!(
        (vol / (4.0 / 3.0 * std::f64::consts::PI) - 1.0).abs() < 0.05,
        "volume {vol}"
    );
}

#[test]
fn guided_placement_matches_bisection_with_far_fewer_evaluations() {
    let mesh = sphere([0.1, -0.2, 0.3], 1.0, 24, false);
    let wn = WindingNumber::new(&mesh).unwrap();
    let bounds = mesh.bounding_box().unwrap();
    // One lattice for both: sub-cell levels need the guide, so only the guided run would have
    // them.
    let options = RemeshOptions {
        sub_cell_levels: 0,
        ..raw(40)
    };
    let bisected = remesh(&wn, bounds, &options).unwrap();
    let (guided, _) = run_with(&mesh, &options);
    // Extraction does not depend on placement: the same triangles over the same lattice edges.
    assert_eq!(guided.triangles, bisected.triangles);
    let vertices = guided.positions.len();
    assert!(
        guided.stats.guided_vertices * 10 >= vertices * 9,
        "{:?}",
        guided.stats
    );
    assert!(
        guided.stats.placement_evaluations * 3 < bisected.stats.placement_evaluations,
        "{:?} {:?}",
        guided.stats,
        bisected.stats
    );
    // Both are within one tick of the class change; on a closed mesh crossed once there is one
    // change, so they are within two ticks of each other (fixed point: exact).
    for (g, b) in guided.fixed.iter().zip(&bisected.fixed) {
        for k in 0..3 {
            assert!((g[k] - b[k]).abs() <= 2, "{g:?} {b:?}");
        }
    }
    // The fixed point and the world positions describe the same vertices.
    let t = guided.ticks_per_cell as f64;
    for (f, p) in guided.fixed.iter().zip(&guided.positions) {
        for k in 0..3 {
            let x = f[k] as f64 / t;
            let back = (p[k] - lattice_origin(&guided, k)) / guided.cell_size;
            assert!((x - back).abs() < 1e-6, "{x} {back}");
        }
    }
}

/// The lattice origin along axis `k`, recovered from any vertex (fixed point and position).
fn lattice_origin(out: &Remeshed, k: usize) -> f64 {
    out.positions[0][k] - out.fixed[0][k] as f64 / out.ticks_per_cell as f64 * out.cell_size
}

#[test]
fn a_misleading_guide_costs_evaluations_not_correctness() {
    // The guide is a sphere shifted by 3 cells: its crossings are wrong nearly everywhere, the
    // verification rejects them, and every vertex still ends within one tick of the true class
    // change, as bisection's does.
    let mesh = sphere([0.0; 3], 1.0, 24, false);
    let wn = WindingNumber::new(&mesh).unwrap();
    let bounds = mesh.bounding_box().unwrap();
    let options = RemeshOptions {
        sub_cell_levels: 0,
        ..raw(32)
    };
    let bisected = remesh(&wn, bounds, &options).unwrap();
    let wrong = SegmentBvh::of_mesh(&mesh.translated([3.0 * 2.0 / 32.0, 0.0, 0.0]));
    let out = remesh_guided(&wn, Some(&wrong), bounds, &options, &|_| {}).unwrap();
    assert_eq!(out.triangles, bisected.triangles);
    assert_no_self_intersections(&out);
    for (g, b) in out.fixed.iter().zip(&bisected.fixed) {
        for k in 0..3 {
            assert!((g[k] - b[k]).abs() <= 2, "{g:?} {b:?}");
        }
    }
}

/// An octahedron turned off the lattice's axes: its 12 sharp edges and 6 corners cross cells
/// every which way, and the marching-tetrahedra surface cuts them off (its vertices are on the
/// faces, its triangles chords across the edges). The relocation's quadrics, made of the
/// input's planes at the vertices (`SimplifyOptions::input_planes`), move vertices onto the
/// edges: the corners and edge points end closer to the output than with the quadrics of the
/// marching-tetrahedra faces, and the output stays closed, manifold and free of
/// self-intersections either way.
#[test]
fn sharp_edges_off_the_lattice_come_back_with_the_inputs_planes() {
    let (a, b) = (0.37f64, 0.61f64);
    let turn = |p: [f64; 3]| {
        let (x, y, z) = (
            p[0],
            p[1] * a.cos() - p[2] * a.sin(),
            p[1] * a.sin() + p[2] * a.cos(),
        );
        [x * b.cos() - y * b.sin(), x * b.sin() + y * b.cos(), z]
    };
    let corners: Vec<[f64; 3]> = [
        [1.0, 0.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.0, -1.0],
    ]
    .map(turn)
    .to_vec();
    let faces = common::OCTAHEDRON_FACES.to_vec();
    let mesh = Mesh::new(corners.clone(), faces.clone()).unwrap();
    // Points along every edge (a corner's own cell is the hardest; edges show the rule).
    let mut sharp = corners.clone();
    for f in &faces {
        for k in 0..3 {
            let (p, q) = (corners[f[k] as usize], corners[f[(k + 1) % 3] as usize]);
            for t in [0.2, 0.35, 0.5, 0.65, 0.8] {
                sharp.push([0, 1, 2].map(|c| p[c] + t * (q[c] - p[c])));
            }
        }
    }
    let worst = |input_planes: bool| {
        let options = RemeshOptions {
            simplify: Some(gwn::products::remesh::simplify::SimplifyOptions {
                input_planes,
                ..Default::default()
            }),
            ..RemeshOptions::with_resolution(24)
        };
        let (out, r) = run_with(&mesh, &options);
        assert_closed_manifold(&r);
        assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
        let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
        let distance = SignedDistance::new(&out_mesh).unwrap();
        let edge = sharp[6..]
            .iter()
            .map(|&p| distance.eval(p).abs())
            .fold(0.0, f64::max);
        let corner = sharp[..6]
            .iter()
            .map(|&p| distance.eval(p).abs())
            .fold(0.0, f64::max);
        (edge / out.cell_size, corner / out.cell_size)
    };
    let (faces_edge, faces_corner) = worst(false);
    let (planes_edge, planes_corner) = worst(true);
    // Measured: edges 0.35 -> 0.28 cells, corners 0.79 -> 0.42 cells.
    assert!(
        planes_edge < 0.9 * faces_edge && planes_corner < 0.6 * faces_corner,
        "edges {faces_edge} -> {planes_edge}, corners {faces_corner} -> {planes_corner} cells"
    );
    assert!(planes_corner < 0.5, "{planes_corner} cells");
}

#[test]
fn hausdorff_distance_of_a_sphere_is_below_one_cell() {
    let mesh = sphere([0.0; 3], 1.0, 32, false);
    let (out, _) = run(&mesh, 32);
    let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let d = hausdorff_distance(&mesh, &out_mesh, 4000, 1).unwrap();
    assert!(
        d > 0.0 && d < out.cell_size,
        "{d} vs cell {}",
        out.cell_size
    );
    // Against a sphere of radius 1.2 the distance is at least the 0.2 gap.
    let bigger = sphere([0.0; 3], 1.2, 32, false);
    let far = hausdorff_distance(&bigger, &out_mesh, 4000, 1).unwrap();
    assert!(far > 0.2 - out.cell_size, "{far}");
    assert_eq!(hausdorff_distance(&Mesh::default(), &out_mesh, 10, 1), None);
}

/// Two overlapping unit cubes, one self-intersecting closed input: the output is the union's
/// surface, and the parts of each cube inside the other (22 % of the area) are up to ~0.35 from
/// it, which the plain sampled distance counts as misses; measured from where the input bounds
/// the solid, the distance is below a cell. A part the output lacks still counts: against the
/// same input with a third, disjoint cube, the distance is at least the gap.
#[test]
fn hausdorff_to_the_solid_boundary_leaves_out_inner_faces() {
    let pair = common::unit_cube()
        .concatenated(&common::unit_cube().translated([0.5, 0.3, 0.2]))
        .unwrap();
    let (out, _) = run(&pair, 32);
    let out_mesh = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let h = out.cell_size;
    let plain = hausdorff_distance(&pair, &out_mesh, 4000, 1).unwrap();
    assert!(plain > 5.0 * h, "{plain} vs cell {h}");
    let wn = WindingNumber::new(&pair).unwrap();
    let b = hausdorff_to_solid_boundary(&pair, &wn, &out_mesh, 4000, 1, 0.01 * h).unwrap();
    assert!(b.distance < h, "{b:?} vs cell {h}");
    assert_eq!(
        b.plain, plain,
        "the same samples give the plain distance too"
    );
    // Inner parts: 2 × (0.7·0.8 + 0.5·0.8 + 0.5·0.7) = 2.62 of the area 12.
    assert!(
        (b.boundary_fraction - (1.0 - 2.62 / 12.0)).abs() < 0.02,
        "{b:?}"
    );
    let three = pair
        .concatenated(&common::unit_cube().translated([4.0, 0.0, 0.0]))
        .unwrap();
    let wn3 = WindingNumber::new(&three).unwrap();
    let lost = hausdorff_to_solid_boundary(&three, &wn3, &out_mesh, 4000, 1, 0.01 * h).unwrap();
    assert!(lost.distance > 2.5, "{lost:?}");
}

/// `--thicken`: an open square (w = ±½ beside it, no volume) becomes a closed slab of thickness
/// about `2·eps`; a closed sphere next to it is not thickened at all.
#[test]
fn thicken_turns_open_sheets_into_slabs_and_leaves_solids_alone() {
    use gwn::products::remesh::thicken::ThickenedSheets;
    let square = |z: f64| {
        Mesh::new(
            vec![[0., 0., z], [1., 0., z], [1., 1., z], [0., 1., z]],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap()
    };
    let ball = sphere([0.5, 0.5, 1.0], 0.3, 24, false);
    let mut positions = square(0.0).positions().to_vec();
    let mut triangles = square(0.0).triangles().to_vec();
    let n = positions.len() as u32;
    positions.extend_from_slice(ball.positions());
    triangles.extend(ball.triangles().iter().map(|t| t.map(|i| i + n)));
    let both = Mesh::new(positions, triangles).unwrap();
    let bounds = both.bounding_box().unwrap();
    // Raw surfaces: the simplification's stopping point depends on the whole face count.
    let options = RemeshOptions {
        simplify: None,
        ..RemeshOptions::with_resolution(48)
    };
    let guide = SegmentBvh::of_mesh(&both);
    let wn = WindingNumber::new(&both).unwrap();
    let eps = 0.05;
    let thick = ThickenedSheets::new(&both, &wn, eps).unwrap();
    let plain = remesh_guided(&wn, Some(&guide), bounds, &options, &|_| {}).unwrap();
    let out = remesh_guided(&thick, Some(&guide), bounds, &options, &|_| {}).unwrap();
    assert_no_self_intersections(&out);
    let report = TopologyReport::of(&out.positions, &out.triangles);
    assert_closed_manifold(&report);
    assert_eq!(report.components, 2, "{report}");
    // The sphere's part is the same surface with or without thickening.
    let upper = |p: [f64; 3]| p[2] > 0.5;
    let (v_plain, v_thick) = (signed_volume(&plain, upper), signed_volume(&out, upper));
    assert!((v_plain - v_thick).abs() < 1e-12, "{v_plain} vs {v_thick}");
    // Without thickening the square leaves (next to) nothing; with it, a slab of volume
    // ≈ 1 × 2·eps (the lattice rounds its faces to cells of 1/48).
    let lower = |p: [f64; 3]| p[2] <= 0.5;
    let before = signed_volume(&plain, lower);
    assert!(before.abs() < 1e-5, "{before}");
    let slab = signed_volume(&out, lower);
    assert!((0.07..0.13).contains(&slab), "slab volume {slab}");
    assert!(ThickenedSheets::new(&both, &wn, 0.0).is_err());
    assert!(ThickenedSheets::new(&both, &wn, f64::NAN).is_err());
}

/// A patch set's Hausdorff distance is measured to a tessellation that stands for it:
/// on the exact rational sphere every vertex and triangle centre of that tessellation is
/// within 1/32 of a res-16 cell of the unit sphere; the remeshed sphere is within a cell of it
/// (all of the tessellation bounds the solid); a cell so small that half-cell segments would
/// exceed the triangle budget gets longer segments within it; a nonsensical cell size, none.
#[test]
fn patch_sets_get_a_hausdorff_distance_to_a_fine_tessellation() {
    use gwn::patch::{PatchSet, PatchWindingNumber};
    use gwn::products::remesh::report::{
        MAX_CURVED_DISTANCE_TRIANGLES, patch_surface_for_distance,
    };
    let set = PatchSet::new(common::rational_sphere_patches()).unwrap();
    let wn = PatchWindingNumber::new(&set);
    let (lo, hi) = set.bounding_box();
    let out = remesh(&wn, gwn::BoundingBox { min: lo, max: hi }, &raw(16)).unwrap();
    let cell = out.cell_size;
    let curved = patch_surface_for_distance(&set, cell).expect("a tessellation");
    assert!(
        curved.segment <= 0.5 * cell,
        "{} cells",
        curved.segment / cell
    );
    let t = curved.mesh;
    let off_sphere = |p: [f64; 3]| ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 1.0).abs();
    for f in 0..t.triangles().len() {
        let c = t.triangle_positions(f);
        let centre = std::array::from_fn(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        assert!(off_sphere(c[0]) < 1e-12, "{:?}", c[0]);
        assert!(off_sphere(centre) < cell / 32.0, "{centre:?}");
    }
    let tw = WindingNumber::new(&t).unwrap();
    let output = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let d = hausdorff_to_solid_boundary(&t, &tw, &output, 20_000, 3, 0.01 * cell).unwrap();
    assert!(d.distance <= cell, "{} cells", d.distance / cell);
    assert!(d.boundary_fraction > 0.999, "{}", d.boundary_fraction);
    // A cell so small that half-cell segments would pass the budget: longer segments, within it.
    let coarse = patch_surface_for_distance(&set, 1e-5).unwrap();
    assert!(coarse.mesh.triangles().len() <= MAX_CURVED_DISTANCE_TRIANGLES);
    assert!(coarse.segment > 0.5e-5);
    assert!(patch_surface_for_distance(&set, 0.0).is_none());
    assert!(patch_surface_for_distance(&set, f64::NAN).is_none());
}

/// A curved input's own segment crossings placed at least 99 % of the `vertices` (`guided`),
/// with `evaluations` under a third of the field search's (`searched`, which guided none).
fn assert_guided_for_a_third(
    guided: usize,
    vertices: usize,
    evaluations: usize,
    (unguided, searched): (usize, usize),
) {
    assert_eq!(unguided, 0);
    assert!(
        100 * guided >= 99 * vertices,
        "{guided} of {vertices} verified"
    );
    assert!(
        3 * evaluations <= searched,
        "{evaluations} evaluations against {searched}"
    );
}

/// The capped cylinder of `tests/fixtures/step` (radius 1, height 2) and a box off the model's
/// own (the grown lattice would otherwise have corners on the caps and the wall's extreme
/// lines: a change at a corner is placed next to it, unverified).
fn capped_cylinder_step() -> (gwn::patch::step::StepModel, gwn::BoundingBox) {
    let model = gwn::patch::step::load_step(&common::fixture("step/capped_cylinder.step")).unwrap();
    let bounds = gwn::BoundingBox {
        min: [-1.013, -1.007, -0.011],
        max: [1.0, 1.0, 2.0],
    };
    (model, bounds)
}

/// A trimmed B-rep model's Hausdorff distance is measured to its trimmed tessellation: on the
/// capped cylinder (radius 1, height 2; `tests/fixtures/step`) every vertex of a kept triangle
/// lies on the wall or a cap's plane within a segment and a half of the disk (the staircase
/// along the trimming circle), every triangle centre within 1/32 of a cell of them, the
/// tessellation's own `w` is the cylinder's away from the surface, and the remesh at res 16 is
/// within a cell of it, nearly all of it bounding the solid.
#[test]
fn step_models_get_a_hausdorff_distance_to_their_trimmed_tessellation() {
    use gwn::patch::step::StepWindingNumber;
    use gwn::products::remesh::report::step_surface_for_distance;
    let (model, bounds) = capped_cylinder_step();
    let wn = StepWindingNumber::new(&model);
    let out = remesh(&wn, bounds, &raw(16)).unwrap();
    let cell = out.cell_size;
    let curved = step_surface_for_distance(&model, cell).expect("a tessellation");
    assert!(curved.segment <= 0.5 * cell);
    let t = &curved.mesh;
    // Distance to the wall or the caps' planes, within the staircase of the caps.
    let staircase = 1.0 + 1.5 * curved.segment;
    let off = |p: [f64; 3]| {
        let r = p[0].hypot(p[1]);
        let wall = if (0.0..=2.0).contains(&p[2]) {
            (r - 1.0).abs()
        } else {
            f64::INFINITY
        };
        let cap = |z: f64| {
            if r <= staircase {
                (p[2] - z).abs()
            } else {
                f64::INFINITY
            }
        };
        wall.min(cap(0.0)).min(cap(2.0))
    };
    assert!(t.triangles().len() > 100);
    for f in 0..t.triangles().len() {
        let c = t.triangle_positions(f);
        let centre: [f64; 3] = std::array::from_fn(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0);
        assert!(off(centre) < cell / 32.0, "{centre:?}");
        for p in c {
            assert!(off(p) < 1e-9, "{p:?}");
            // A cap's staircase ends within a segment outside the trimming circle.
            assert!(p[0].hypot(p[1]) < staircase, "{p:?}");
        }
    }
    let tw = WindingNumber::new(t).unwrap();
    for (q, w) in [
        ([0.1, 0.2, 1.0], 1.0),
        ([0.0, 0.0, 2.5], 0.0),
        ([1.5, 0.0, 1.0], 0.0),
    ] {
        assert!((tw.eval(q) - w).abs() < 0.01, "{q:?}: {}", tw.eval(q));
    }
    let output = Mesh::new(out.positions.clone(), out.triangles.clone()).unwrap();
    let d = hausdorff_to_solid_boundary(t, &tw, &output, 20_000, 3, 0.01 * cell).unwrap();
    assert!(d.distance <= cell, "{} cells", d.distance / cell);
    assert!(d.boundary_fraction > 0.99, "{}", d.boundary_fraction);
    assert!(step_surface_for_distance(&model, f64::NAN).is_none());
}

/// A STEP model's own segment crossings guide the placement as the input triangles do a
/// mesh's: the capped cylinder (radius 1, height 2; `tests/fixtures/step`) at res 16 has at
/// least 99 % of its vertices placed at a verified crossing (all 4,618 when written), for under
/// a third of the field search's evaluations (2.0 against 8.0 per vertex), and both surfaces
/// are closed genus-0 manifolds without a self-intersection, within a cell of the cylinder.
#[test]
fn step_models_place_vertices_at_their_own_surface_crossings() {
    use gwn::patch::step::StepWindingNumber;
    let (model, bounds) = capped_cylinder_step();
    let wn = StepWindingNumber::new(&model);
    let mut runs = Vec::new();
    for evaluator_crossings in [true, false] {
        let options = RemeshOptions {
            evaluator_crossings,
            ..RemeshOptions::with_resolution(16)
        };
        let out = remesh(&wn, bounds, &options).unwrap();
        assert_no_self_intersections(&out);
        let r = TopologyReport::of(&out.positions, &out.triangles);
        assert_closed_manifold(&r);
        assert_eq!((r.euler_characteristic, r.components), (2, 1), "{r}");
        let cell = out.cell_size;
        for p in &out.positions {
            let wall = (p[0].hypot(p[1]) - 1.0).abs();
            let caps = p[2].abs().min((p[2] - 2.0).abs());
            assert!(
                wall.min(caps) <= cell,
                "{p:?} is {} cells off",
                wall.min(caps) / cell
            );
        }
        runs.push((
            out.stats.guided_vertices,
            out.stats.placement_evaluations,
            out.stats.extracted_vertices,
        ));
    }
    let [(guided, evaluations, vertices), (unguided, searched, _)] = runs[..] else {
        unreachable!()
    };
    assert_guided_for_a_third(guided, vertices, evaluations, (unguided, searched));
}

/// Patch sets go through the same pipeline as meshes: the exact rational sphere comes out a
/// closed genus-0 manifold whose vertices lie within a cell of the unit sphere, with the ball's
/// volume and no self-intersection. Its vertices are placed at the patches' own segment
/// crossings (`PatchWindingNumber::segment_crossings`, verified like a mesh's triangle
/// crossings): at res 16 at least 99 % of them (3,512 of 3,518 when written; the poles, where
/// the patches' collapsed edges propose nothing, are left to the field search), for under a
/// third of the field search's evaluations (7,024 against 28,024), with the same topology
/// without them.
#[test]
fn rational_sphere_patches_remesh_to_a_closed_sphere() {
    use gwn::patch::{PatchSet, PatchWindingNumber};
    let set = PatchSet::new(common::rational_sphere_patches()).unwrap();
    let wn = PatchWindingNumber::new(&set);
    let (lo, hi) = set.bounding_box();
    let bounds = gwn::BoundingBox { min: lo, max: hi };
    let mut runs = Vec::new();
    for (res, evaluator_crossings) in [(8, true), (16, true), (16, false)] {
        let options = RemeshOptions {
            evaluator_crossings,
            ..raw(res)
        };
        let out = remesh(&wn, bounds, &options).unwrap();
        assert_no_self_intersections(&out);
        let r = TopologyReport::of(&out.positions, &out.triangles);
        assert_closed_manifold(&r);
        assert_eq!(
            (r.euler_characteristic, r.components),
            (2, 1),
            "res {res}: {r}"
        );
        assert_unit_sphere_like(&out, [0.0; 3], 0.06, res);
        runs.push((
            out.stats.guided_vertices,
            out.stats.placement_evaluations,
            out.stats.extracted_vertices,
        ));
    }
    let [_, (guided, evaluations, vertices), (unguided, searched, _)] = runs[..] else {
        unreachable!()
    };
    assert_guided_for_a_third(guided, vertices, evaluations, (unguided, searched));
}
