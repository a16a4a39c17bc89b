//! `products::remesh::reorient`: a closed input with flipped faces is kept under the parity
//! method with its faces turned to face out of the parity's solid, and its `w` then is that
//! parity at every point off the surface; inputs that are not such a surface are told apart.

use proptest::prelude::*;

use crate::remesh::{sphere, torus, with_flipped_faces};
use crate::remesh_cut::join;
use crate::remesh_keep::cuboid;

use gwn::Mesh;
use gwn::eval::antipodal::WindingNumber;
use gwn::eval::parity::CrossingParity;
use gwn::products::remesh::keep_input::{InputCheck, NotKept};
use gwn::products::remesh::reorient::{consistently_oriented, keep_reoriented};
use gwn::products::remesh::report::TopologyReport;
use gwn::products::remesh::{Keep, RemeshOptions, Remeshed, remesh_mesh};

fn reoriented(mesh: &Mesh) -> Result<Remeshed, NotKept> {
    keep_reoriented(
        mesh,
        mesh.bounding_box().unwrap(),
        &RemeshOptions::with_resolution(32),
    )
}

/// Pseudo-random face flips: face `f` flipped where bit `f mod 64` of `mask` is set, mixed.
fn flips(mask: u64) -> impl Fn(usize) -> bool {
    move |f| (mask.rotate_left((f * 7 % 64) as u32) ^ (f as u64 / 64)) & 1 == 1
}

/// `w` of the output at `q` equals the parity of the input there, at every point of `points`
/// (off both surfaces: none of them on a face of the input), and is 0 or 1.
fn assert_w_is_the_parity(input: &Mesh, out: &Remeshed, points: &[[f64; 3]]) {
    let parity = CrossingParity::new(input).unwrap();
    let w = (!out.triangles.is_empty()).then(|| {
        let mesh = Mesh::from_slices(&out.positions, &out.triangles).unwrap();
        WindingNumber::new(&mesh).unwrap()
    });
    for &q in points {
        let got = w.as_ref().map_or(0.0, |w| w.eval(q));
        assert_eq!(got, parity.eval(q), "at {q:?}");
    }
}

/// Points on the segment from `a` to `b` at a non-dyadic spacing.
fn along(a: [f64; 3], b: [f64; 3], n: usize) -> Vec<[f64; 3]> {
    (0..=n)
        .map(|i| {
            let t = (i as f64 + 0.3071) / (n as f64 + 1.0);
            std::array::from_fn(|k| a[k] + t * (b[k] - a[k]))
        })
        .collect()
}

/// Spheres, a torus and three nested spheres, each with faces flipped at random: kept, every
/// face the input's with its vertices, turned or not; the result oriented, with the outer
/// shells outward and a cavity's wall inward, and `w` the parity.
#[test]
fn flipped_closed_shells_are_turned_to_face_out_of_the_parity_solid() {
    let nested = join(&[
        sphere([0.0; 3], 1.0, 12, false),
        sphere([0.0; 3], 0.6, 10, false),
        sphere([0.0; 3], 0.3, 8, true),
    ]);
    for (name, mesh, volumes) in [
        ("sphere", sphere([0.1, 0.2, 0.3], 1.0, 12, false), vec![1]),
        ("inward sphere", sphere([0.0; 3], 1.0, 12, true), vec![1]),
        ("torus", torus(1.0, 0.3, 12), vec![1]),
        // Outward, a cavity's wall inward, a solid inside the cavity outward.
        ("nested spheres", nested, vec![1, -1, 1]),
    ] {
        for mask in [0u64, u64::MAX, 0x9e37_79b9_7f4a_7c15, 0x0123_4567_89ab_cdef] {
            let input = with_flipped_faces(&mesh, flips(mask));
            let out = reoriented(&input).unwrap_or_else(|e| panic!("{name} {mask:x}: {e}"));
            let Some(InputCheck::Reoriented {
                repairs,
                turned_faces,
            }) = out.stats.input
            else {
                panic!("{name}: {:?}", out.stats.input);
            };
            assert!(repairs.is_empty(), "{name}");
            assert_eq!(out.positions.as_slice(), input.positions(), "{name}");
            // Each face the input's, as it was or turned (the same first vertex).
            let mut turned = 0;
            for (&[a, b, c], &t) in input.triangles().iter().zip(&out.triangles) {
                match t {
                    t if t == [a, b, c] => {}
                    t if t == [a, c, b] => turned += 1,
                    t => panic!("{name}: {t:?} is not [{a}, {b}, {c}]"),
                }
            }
            assert_eq!(turned, turned_faces, "{name}");
            let r = TopologyReport::of(&out.positions, &out.triangles);
            assert!(r.closed && r.oriented && r.edge_manifold, "{name}: {r}");
            // Each component's signed volume, in the order of their first faces.
            let volumes_out: Vec<i32> = split_by_component(&out)
                .iter()
                .map(|faces| signed_volume(&out.positions, faces).signum() as i32)
                .collect();
            assert_eq!(volumes_out, volumes, "{name} {mask:x}");
            let points = along([-1.7, -0.05, 0.013], [1.9, 0.07, -0.021], 97);
            assert_w_is_the_parity(&input, &out, &points);
        }
    }
}

fn split_by_component(out: &Remeshed) -> Vec<Vec<[u32; 3]>> {
    let mut by_root: Vec<Vec<[u32; 3]>> = Vec::new();
    let mut parent: Vec<usize> = (0..out.positions.len()).collect();
    fn find(p: &mut [usize], x: usize) -> usize {
        let mut x = x;
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for t in &out.triangles {
        for k in 0..3 {
            let (a, b) = (
                find(&mut parent, t[k] as usize),
                find(&mut parent, t[(k + 1) % 3] as usize),
            );
            parent[a] = b;
        }
    }
    let mut slot = vec![usize::MAX; out.positions.len()];
    for t in &out.triangles {
        let root = find(&mut parent, t[0] as usize);
        if slot[root] == usize::MAX {
            slot[root] = by_root.len();
            by_root.push(Vec::new());
        }
        by_root[slot[root]].push(*t);
    }
    by_root
}

fn signed_volume(p: &[[f64; 3]], faces: &[[u32; 3]]) -> f64 {
    faces
        .iter()
        .map(|&[a, b, c]| {
            let [a, b, c] = [a, b, c].map(|v| p[v as usize]);
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        })
        .sum()
}

/// The six-vertex real projective plane: every edge in two faces, one-sided.
#[test]
fn a_one_sided_closed_surface_is_not_reoriented() {
    let faces: Vec<[u32; 3]> = [
        [1, 2, 4],
        [1, 2, 6],
        [1, 3, 5],
        [1, 3, 6],
        [1, 4, 5],
        [2, 3, 4],
        [2, 3, 5],
        [2, 5, 6],
        [3, 4, 6],
        [4, 5, 6],
    ]
    .iter()
    .map(|t| t.map(|v| v - 1))
    .collect();
    assert_eq!(consistently_oriented(&faces), None);
    // A sphere's faces, flipped at random, orient (every face agreeing with its neighbours).
    let flipped = with_flipped_faces(&sphere([0.0; 3], 1.0, 6, false), flips(99));
    let turned = consistently_oriented(flipped.triangles()).unwrap();
    assert!(TopologyReport::of(flipped.positions(), &turned).oriented);
    let positions = [
        [0.0, 0.0, 1.0],
        [0.9, 0.1, 0.2],
        [0.3, 0.8, -0.1],
        [-0.7, 0.5, 0.3],
        [-0.5, -0.6, -0.2],
        [0.4, -0.7, 0.4],
    ];
    let rp2 = Mesh::from_slices(&positions, &faces).unwrap();
    assert!(matches!(reoriented(&rp2), Err(NotKept::NotOrientable)));
}

/// What is not a closed, manifold, embedded surface is not kept, and the parity remesh goes on
/// to the lattice, saying why; the exact method remeshes a flipped input (`w` fractional).
#[test]
fn inputs_that_are_not_such_a_surface_are_remeshed() {
    let open = gwn::testing::unit_cube(true);
    assert!(matches!(
        reoriented(&open),
        Err(NotKept::Open { boundary_edges: 4 })
    ));
    let overlapping = with_flipped_faces(
        &join(&[
            cuboid([0.0; 3], [2.0; 3], false),
            cuboid([1.0, 0.5, 0.5], [3.0, 1.5, 1.5], false),
        ]),
        flips(0x5555_aaaa_1234_4321),
    );
    assert!(matches!(
        reoriented(&overlapping),
        Err(NotKept::SelfIntersecting { .. })
    ));
    let run = |mesh: &Mesh, keep: Keep| {
        let parity = CrossingParity::new(mesh).unwrap();
        remesh_mesh(
            mesh,
            keep,
            &parity,
            None,
            mesh.bounding_box().unwrap(),
            &RemeshOptions::with_resolution(16),
            &|_| {},
        )
        .unwrap()
    };
    let out = run(&overlapping, Keep::Parity);
    assert!(matches!(
        out.stats.input,
        Some(InputCheck::Remeshed(NotKept::SelfIntersecting { .. }))
    ));
    let r = TopologyReport::of(&out.positions, &out.triangles);
    assert!(r.closed && r.oriented && r.faces > 0, "{r}");
    // Kept through `remesh_mesh` too; not tried under the exact method's keep.
    let flipped = with_flipped_faces(&sphere([0.0; 3], 1.0, 8, false), flips(7));
    let out = run(&flipped, Keep::Parity);
    assert!(matches!(
        out.stats.input,
        Some(InputCheck::Reoriented { .. })
    ));
    assert_eq!(out.triangles.len(), flipped.triangles().len());
    let wn = WindingNumber::new(&flipped).unwrap();
    let out = remesh_mesh(
        &flipped,
        Keep::Winding,
        &wn,
        None,
        flipped.bounding_box().unwrap(),
        &RemeshOptions::with_resolution(16),
        &|_| {},
    )
    .unwrap();
    assert!(matches!(
        out.stats.input,
        Some(InputCheck::Remeshed(NotKept::Misoriented { .. }))
    ));
}

/// Up to three boxes at integer corners (apart, nested, touching or overlapping), each face
/// flipped at random: wherever the input is kept, `w` of the output is the input's parity at
/// every point of a grid off the integer planes; and every input whose boxes are pairwise
/// apart or strictly nested is kept.
fn boxes() -> impl Strategy<Value = Vec<([f64; 3], [f64; 3], u64)>> {
    // A box, and boxes shrunk into it by a margin of 0 to 2 on each side (nested, touching its
    // wall from inside, or, from 0, sharing a wall), or anywhere in the box of 0..9.
    let corner = (0u8..6, 1u8..4);
    let inset = (0u8..3, 0u8..3);
    let free = (corner.clone(), corner.clone(), corner, any::<u64>());
    let nested = (
        prop::collection::vec((inset.clone(), inset.clone(), inset, any::<u64>()), 0..3),
        any::<bool>(),
    );
    (free, nested, prop::collection::vec(free_box(), 0..2)).prop_map(
        |(((x, dx), (y, dy), (z, dz), mask), (insets, chain), more)| {
            // The first box large enough to hold a few inside it.
            let lo = [x, y, z].map(f64::from);
            let hi = [x + dx + 4, y + dy + 4, z + dz + 4].map(f64::from);
            let mut v = vec![(lo, hi, mask)];
            for ((a, b), (c, d), (e, f), mask) in insets {
                // Inside the last box (a chain of nested boxes) or the first.
                let (plo, phi, _) = if chain { *v.last().unwrap() } else { v[0] };
                let lo = [
                    plo[0] + f64::from(a),
                    plo[1] + f64::from(c),
                    plo[2] + f64::from(e),
                ];
                let hi = [
                    phi[0] - f64::from(b),
                    phi[1] - f64::from(d),
                    phi[2] - f64::from(f),
                ];
                if (0..3).all(|k| lo[k] < hi[k]) {
                    v.push((lo, hi, mask));
                }
            }
            v.extend(more);
            v
        },
    )
}

fn free_box() -> impl Strategy<Value = ([f64; 3], [f64; 3], u64)> {
    let corner = (0u8..9, 1u8..4);
    (corner.clone(), corner.clone(), corner, any::<u64>()).prop_map(
        |((x, dx), (y, dy), (z, dz), mask)| {
            let lo = [x, y, z].map(f64::from);
            (lo, [x + dx, y + dy, z + dz].map(f64::from), mask)
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn boxes_with_flipped_faces_keep_their_parity(boxes in boxes()) {
        let parts: Vec<Mesh> = boxes
            .iter()
            .map(|&(lo, hi, mask)| with_flipped_faces(&cuboid(lo, hi, false), flips(mask)))
            .collect();
        let input = join(&parts);
        let apart = |a: &([f64; 3], [f64; 3], u64), b: &([f64; 3], [f64; 3], u64)| {
            (0..3).any(|k| a.1[k] < b.0[k] || b.1[k] < a.0[k])
        };
        let inside = |a: &([f64; 3], [f64; 3], u64), b: &([f64; 3], [f64; 3], u64)| {
            (0..3).all(|k| b.0[k] < a.0[k] && a.1[k] < b.1[k])
        };
        let separate = (0..boxes.len()).all(|i| {
            (0..i).all(|j| {
                let (a, b) = (&boxes[i], &boxes[j]);
                apart(a, b) || inside(a, b) || inside(b, a)
            })
        });
        let points: Vec<[f64; 3]> = (0..14)
            .flat_map(|x| (0..14).flat_map(move |y| (0..14).map(move |z| [x, y, z])))
            .map(|[x, y, z]: [i32; 3]| [x as f64 - 0.37, y as f64 - 0.61, z as f64 - 0.29])
            .collect();
        match reoriented(&input) {
            Ok(out) => {
                let reoriented = matches!(out.stats.input, Some(InputCheck::Reoriented { .. }));
                prop_assert!(reoriented, "{:?}", out.stats.input);
                assert_w_is_the_parity(&input, &out, &points);
            }
            Err(e) => prop_assert!(!separate, "separate boxes not kept: {e}"),
        }
    }
}
