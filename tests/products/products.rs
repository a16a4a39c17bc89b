//! Products: slice PNGs, signed distance, tet filtering, face classification, and the CLI.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use gwn::eval::antipodal::WindingNumber;
use gwn::io::tets::{parse_ele, parse_node, write_ele, write_node};
use gwn::mesh::TetMesh;
use gwn::products::classify::classify_faces;
use gwn::products::colormap;
use gwn::products::png::Slice;
use gwn::products::sdf::{PseudoNormalSign, SignedDistance};
use gwn::products::tets::filter_tets;
use gwn::{BoundingBox, Mesh};

// ---------------------------------------------------------------- helpers

/// A fresh empty directory under the system temp dir, removed when dropped (the tests left
/// five per run behind).
fn temp_dir(name: &str) -> TempDir {
    let d = std::env::temp_dir().join(format!("gwn-products-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    TempDir(d)
}

struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn write_cube_obj(path: &Path, mesh: &Mesh) {
    let mut s = String::new();
    for p in mesh.positions() {
        s += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in mesh.triangles() {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, s).unwrap();
}

/// An axis-aligned box `[lo, hi]` whose faces are split into `n × n` quads of two triangles,
/// outward oriented, closed.
fn subdivided_box(lo: [f64; 3], hi: [f64; 3], n: usize) -> Mesh {
    let mut pos = Vec::new();
    let mut tris = Vec::new();
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, 1] {
            let base = pos.len() as u32;
            for j in 0..=n {
                for i in 0..=n {
                    let mut p = [0.0; 3];
                    p[axis] = if side == 0 { lo[axis] } else { hi[axis] };
                    p[u] = lerp(lo[u], hi[u], i, n);
                    p[v] = lerp(lo[v], hi[v], j, n);
                    pos.push(p);
                }
            }
            let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                    // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
                    if side == 1 {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, c, b]);
                        tris.push([a, d, c]);
                    }
                }
            }
        }
    }
    // Faces were built separately: weld the seams so the box is closed (no boundary edges).
    Mesh::new(pos, tris).unwrap().welded().0
}

/// `lo + (hi − lo)·i/n` with both ends exact.
fn lerp(lo: f64, hi: f64, i: usize, n: usize) -> f64 {
    if i == n {
        hi
    } else {
        lo + (hi - lo) * i as f64 / n as f64
    }
}

/// Unit icosphere (subdivided twice), outward oriented.
fn icosphere() -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<[f64; 3]> = vec![
        [-1., t, 0.],
        [1., t, 0.],
        [-1., -t, 0.],
        [1., -t, 0.],
        [0., -1., t],
        [0., 1., t],
        [0., -1., -t],
        [0., 1., -t],
        [t, 0., -1.],
        [t, 0., 1.],
        [-t, 0., -1.],
        [-t, 0., 1.],
    ];
    let norm = |p: [f64; 3]| {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        p.map(|c| c / l)
    };
    for p in &mut pos {
        *p = norm(*p);
    }
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..2 {
        let mut mid = std::collections::HashMap::new();
        let mut next = Vec::new();
        let mut m = |a: u32, b: u32, pos: &mut Vec<[f64; 3]>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (pos[a as usize], pos[b as usize]);
                pos.push(norm([p[0] + q[0], p[1] + q[1], p[2] + q[2]]));
                (pos.len() - 1) as u32
            })
        };
        for [a, b, c] in tris {
            let (ab, bc, ca) = (m(a, b, &mut pos), m(b, c, &mut pos), m(c, a, &mut pos));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    Mesh::new(pos, tris).unwrap()
}

/// A box grid of `n³` cubes each split into 6 tets around the main diagonal.
fn box_tets(lo: f64, hi: f64, n: usize) -> TetMesh {
    let mut points = Vec::new();
    let h = (hi - lo) / n as f64;
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                points.push([lo + i as f64 * h, lo + j as f64 * h, lo + k as f64 * h]);
            }
        }
    }
    let id = |i: usize, j: usize, k: usize| ((k * (n + 1) + j) * (n + 1) + i) as u32;
    let mut tets = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                for perm in [
                    [0, 1, 2],
                    [0, 2, 1],
                    [1, 0, 2],
                    [1, 2, 0],
                    [2, 0, 1],
                    [2, 1, 0],
                ] {
                    let mut c = [i, j, k];
                    let mut t = [id(c[0], c[1], c[2]); 4];
                    for (s, &a) in perm.iter().enumerate() {
                        c[a] += 1;
                        t[s + 1] = id(c[0], c[1], c[2]);
                    }
                    tets.push(t);
                }
            }
        }
    }
    let refs = vec![0; tets.len()];
    TetMesh { points, tets, refs }
}

fn decode_png(bytes: &[u8]) -> (usize, usize, Vec<u8>) {
    let dec = png::Decoder::new(bytes);
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

fn pixel(img: &(usize, usize, Vec<u8>), x: usize, y: usize) -> [u8; 3] {
    let i = 3 * (y * img.0 + x);
    [img.2[i], img.2[i + 1], img.2[i + 2]]
}

// ---------------------------------------------------------------- slices

#[test]
fn slice_png_has_the_map_colours_at_known_points_of_the_cube() {
    let cube = common::unit_cube();
    let region = BoundingBox {
        min: [-0.5; 3],
        max: [1.5; 3],
    };
    for axis in 0..3 {
        let slice = Slice::new(&region, axis, 0.5, 64);
        let wn = WindingNumber::with_options(
            &cube,
            gwn::eval::antipodal::Options {
                ray: slice.ray(),
                ..Default::default()
            },
        )
        .unwrap();
        let values = slice.evaluate(&wn);
        let mut bytes = Vec::new();
        slice
            .render(&values, Some(&cube))
            .write_png(&mut bytes)
            .unwrap();
        let img = decode_png(&bytes);
        assert_eq!(img.0, 64);
        assert_eq!(img.1, 64 + slice.legend_height());
        let inside = colormap::color(1.0);
        let outside = colormap::color(0.0);
        let (px, py) = slice.pixel_of([0.5, 0.5, 0.5]).unwrap();
        assert_eq!(pixel(&img, px, py), inside, "axis {axis} centre");
        let (px, py) = slice.pixel_of([-0.4, -0.4, -0.4]).unwrap();
        assert_eq!(pixel(&img, px, py), outside, "axis {axis} corner");
        let (px, py) = slice.pixel_of([1.4, 1.4, 1.4]).unwrap();
        assert_eq!(pixel(&img, px, py), outside);
        // The outline crosses the middle row at the cube's faces (u = 0 → pixel 16).
        let row = img.1 - slice.legend_height() - 1 - 32;
        assert_eq!(pixel(&img, 16, row), gwn::products::png::OUTLINE_COLOR);
        // Legend strip: the bar is drawn below the slice with the 0.5 colour in its middle.
        let bar_row = 64 + slice.legend_height() / 10 + 2;
        let mid = pixel(&img, 31, bar_row);
        assert!(mid.iter().all(|&c| c > 200), "{mid:?}");
        // Pixels map back to their own centres.
        let p = slice.pixel_point(10, 20);
        assert_eq!(slice.pixel_of(p), Some((10, 20)));
    }
}

#[test]
fn colours_outside_the_unit_range_are_distinct_and_saturated() {
    let (two, minus, one, zero) = (
        colormap::color(2.0),
        colormap::color(-1.0),
        colormap::color(1.0),
        colormap::color(0.0),
    );
    let sat = |c: [u8; 3]| c.iter().max().unwrap() - c.iter().min().unwrap();
    assert!(sat(two) > 150 && sat(minus) > 100, "{two:?} {minus:?}");
    assert!(two != one && minus != zero && two != minus);
}

// ---------------------------------------------------------------- signed distance

#[test]
fn sdf_of_the_cube_is_exact() {
    let sdf = SignedDistance::new(&common::unit_cube()).unwrap();
    assert_eq!(sdf.eval([0.5, 0.5, 0.5]), -0.5);
    assert_eq!(sdf.eval([0.5, 0.5, 3.0]), 2.0);
    assert_eq!(sdf.eval([0.25, 0.5, 0.5]), -0.25);
    assert_eq!(sdf.eval([-1.0, 0.5, 0.5]), 1.0);
    // Edge and corner regions: Euclidean distance to the edge / corner.
    assert!((sdf.eval([2.0, 2.0, 0.5]) - 2f64.sqrt()).abs() < 1e-15);
    assert!((sdf.eval([2.0, 3.0, -1.0]) - 6f64.sqrt()).abs() < 1e-15);
    // Batch = single.
    let pts = [[0.1, 0.2, 0.3], [1.5, -0.5, 0.5], [0.9, 0.9, 0.05]];
    let b = sdf.eval_batch(&pts);
    for (p, v) in pts.iter().zip(b) {
        assert_eq!(sdf.eval(*p), v);
    }
    assert_eq!(b_round(sdf.eval([0.9, 0.9, 0.05])), b_round(-0.05));
}

fn b_round(x: f64) -> i64 {
    (x * 1e12).round() as i64
}

#[test]
fn sdf_sign_flips_exactly_at_the_half_level_set_of_an_open_cube() {
    // Along the vertical line through the open top, w falls smoothly from 1 (deep inside) to 0;
    // the sign must flip exactly where w crosses 0.5, which is above the missing face, not on it.
    let open = common::open_cube();
    let sdf = SignedDistance::new(&open).unwrap();
    let wn = WindingNumber::new(&open).unwrap();
    let mut flips = Vec::new();
    let mut prev: Option<bool> = None;
    for i in 0..=2000 {
        let z = -0.5 + 2.0 * i as f64 / 2000.0;
        let q = [0.5, 0.5, z];
        let d = sdf.eval(q);
        let w = wn.eval(q);
        assert_eq!(d.is_sign_negative(), w > 0.5, "z = {z}: d = {d}, w = {w}");
        assert_eq!(d.abs(), sdf.unsigned(q));
        let neg = d.is_sign_negative();
        if prev.is_some_and(|p| p != neg) {
            flips.push(z);
            if z > 0.5 {
                // The flip through the hole happens half a unit away from every triangle.
                assert!(d.abs() > 0.49, "z = {z}: d = {d}");
            }
        }
        prev = Some(neg);
    }
    // Entering through the bottom face, leaving through the w = 0.5 membrane spanning the hole:
    // from the centre of the hole, half the sphere sees the cube's walls at z = 1.
    assert_eq!(flips.len(), 2, "{flips:?}");
    assert!((flips[0] - 0.0).abs() < 2e-3);
    assert!(
        flips[1] >= 1.0 - 1e-3 && flips[1] <= 1.0 + 2e-3,
        "{flips:?}"
    );
}

#[test]
fn pseudo_normal_signs_disagree_near_holes_but_not_on_closed_meshes() {
    let grid = gwn::grid::GridSpec::new(
        BoundingBox {
            min: [-0.5; 3],
            max: [1.5; 3],
        },
        [20, 20, 20],
    )
    .unwrap();
    let count = |mesh: &Mesh| {
        let sdf = SignedDistance::new(mesh).unwrap();
        let pn = PseudoNormalSign::new(mesh);
        let w = sdf.eval_grid(&grid);
        grid.points()
            .iter()
            .zip(&w)
            .filter(|(q, d)| {
                let c = sdf.closest(**q).unwrap();
                (pn.sign(**q, &c) < 0.0) != (**d < 0.0)
            })
            .count()
    };
    assert_eq!(count(&common::unit_cube()), 0);
    let open = count(&common::open_cube());
    assert!(open > 0, "the open cube must show disagreements");
}

// ---------------------------------------------------------------- tets

#[test]
fn filter_tets_keeps_exactly_the_tets_inside_the_sphere_polytope() {
    let sphere = icosphere();
    let wn = WindingNumber::new(&sphere).unwrap();
    let tm = box_tets(-1.3, 1.3, 9);
    assert_eq!(tm.tets.len(), 9 * 9 * 9 * 6);
    let keep = filter_tets(&tm.points, &tm.tets, &wn, 0.5);
    // Independent oracle: the icosphere is convex; inside iff below every face plane.
    let planes: Vec<([f64; 3], [f64; 3])> = (0..sphere.triangles().len())
        .map(|f| {
            let [a, b, c] = sphere.triangle_positions(f);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            (a, n)
        })
        .collect();
    let mut kept = 0;
    for (t, tet) in tm.tets.iter().enumerate() {
        let c = gwn::products::tets::centroid(&tm.points, tet).unwrap();
        let margin = planes
            .iter()
            .map(|(a, n)| {
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                ((c[0] - a[0]) * n[0] + (c[1] - a[1]) * n[1] + (c[2] - a[2]) * n[2]) / l
            })
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(
            margin.abs() > 1e-9,
            "ill-posed: centroid {c:?} on the sphere"
        );
        assert_eq!(keep[t], margin < 0.0, "tet {t} centroid {c:?}");
        kept += usize::from(keep[t]);
    }
    assert!(kept > 1000 && kept < tm.tets.len() / 2, "{kept}");
    // Out-of-range corners are never kept (no panic).
    assert_eq!(
        filter_tets(&tm.points, &[[0, 1, 2, 99_999]], &wn, 0.5),
        [false]
    );
    // Selection compacts points.
    let sel = tm.select(&keep);
    assert_eq!(sel.tets.len(), kept);
    assert!(sel.points.len() < tm.points.len());
}

// ---------------------------------------------------------------- classification

#[test]
fn classify_two_overlapping_cubes() {
    let a = subdivided_box([0.0; 3], [1.0; 3], 4);
    // B overlaps the corner x > 0.5, y > 0.25, z < 0.75 of A; no face of A is coplanar with B.
    let b = subdivided_box([0.5, 0.25, -1.0], [2.0, 2.0, 0.75], 1);
    let wn = WindingNumber::new(&b).unwrap();
    let w = classify_faces(&a, &wn);
    for (f, &v) in w.iter().enumerate() {
        let c = gwn::products::classify::face_centroid(&a, f);
        let inside = c[0] > 0.5 && c[1] > 0.25 && c[2] < 0.75 && c[2] > -1.0;
        assert_eq!(v, if inside { 1.0 } else { 0.0 }, "face {f} centroid {c:?}");
    }
    let n_inside = w.iter().filter(|&&v| v > 0.5).count();
    // Faces: x = 1 (z < 0.75, y > 0.25): 3×3 quads → 18; y = 1 (x > .5, z < .75): 2×3 → 12;
    // z = 0 (x > .5, y > .25): 2×3 → 12 triangles. Other faces lie outside B.
    assert_eq!(n_inside, 18 + 12 + 12);
}

#[test]
fn classify_coplanar_faces_follow_the_documented_side() {
    // B = [0.5, 1.5] × [0, 1] × [0, 1] shares A's faces y = 0, y = 1, z = 0, z = 1 (for x > 0.5),
    // and contains A's face x = 1. Rule (default ray +z): w_B at the point perturbed towards +x,
    // then +y, then +z. On y = 0 (B's outward normal −y) the perturbed point is inside B → 1;
    // on y = 1 → outside → 0; likewise z = 0 → 1, z = 1 → 0; the face x = 1 is inside → 1.
    let a = subdivided_box([0.0; 3], [1.0; 3], 4);
    let b = subdivided_box([0.5, 0.0, 0.0], [1.5, 1.0, 1.0], 3);
    let wn = WindingNumber::new(&b).unwrap();
    let w = classify_faces(&a, &wn);
    for (f, &v) in w.iter().enumerate() {
        let c = gwn::products::classify::face_centroid(&a, f);
        let inside = c[0] > 0.5 && (c[0] == 1.0 || c[1] == 0.0 || c[2] == 0.0);
        let want = if inside { 1.0 } else { 0.0 };
        assert_eq!(v, want, "face {f} centroid {c:?}");
    }
}

// ---------------------------------------------------------------- CLI

fn gwn() -> Command {
    Command::new(env!("CARGO_BIN_EXE_gwn"))
}

fn run_ok(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn run_err(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(!out.status.success(), "{cmd:?} should fail");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one-line error expected: {err}"
    );
    err
}

fn npy_payload(bytes: &[u8]) -> (String, &[u8]) {
    let hlen = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8_lossy(&bytes[10..10 + hlen]).into_owned();
    (header, &bytes[10 + hlen..])
}

#[test]
fn cli_slice_and_default() {
    let d = temp_dir("slice");
    let cube = d.join("cube.obj");
    write_cube_obj(&cube, &common::unit_cube());
    let out = d.join("s.png");
    let so = run_ok(
        gwn()
            .args([
                "slice",
                cube.to_str().unwrap(),
                "--axis",
                "y",
                "--at",
                "0.5",
            ])
            .args(["--res", "50", "--outline", "--out", out.to_str().unwrap()]),
    );
    assert!(so.contains("wrote"), "{so}");
    let img = decode_png(&std::fs::read(&out).unwrap());
    assert_eq!(img.0, 50);
    // Absolute position (`--at-coord`) outside the mesh: everything outside.
    run_ok(
        gwn()
            .args([
                "slice",
                cube.to_str().unwrap(),
                "--at-coord",
                "-3",
                "--res",
                "20",
            ])
            .args(["--out", out.to_str().unwrap()]),
    );
    let img = decode_png(&std::fs::read(&out).unwrap());
    assert_eq!(pixel(&img, 10, 10), colormap::color(0.0));
    // No subcommand: the bundled lion head to ./slice.png.
    let so = run_ok(gwn().current_dir(&d));
    assert!(d.join("slice.png").exists());
    assert!(so.contains("slice.png"), "{so}");
    // Bad mesh file.
    let bad = d.join("bad.off");
    std::fs::write(&bad, "OFF\n3 1 0\n0 0 0\n1 0 0\n").unwrap();
    let e = run_err(
        gwn()
            .args(["slice", bad.to_str().unwrap(), "--out"])
            .arg(&out),
    );
    assert!(e.contains("bad.off"), "{e}");
    let e = run_err(gwn().args(["slice", "/nonexistent/m.obj"]));
    assert!(e.contains("m.obj"), "{e}");
}

#[test]
fn cli_voxelize_counts_the_aligned_cube() {
    let d = temp_dir("voxelize");
    let cube = d.join("cube.obj");
    write_cube_obj(&cube, &common::unit_cube());
    let out = d.join("w.npy");
    let vti = d.join("w.vti");
    let so = run_ok(
        gwn()
            .args(["voxelize", cube.to_str().unwrap(), "--dims", "5", "5", "5"])
            .args([
                "--bounds", "-0.125", "-0.125", "-0.125", "1.125", "1.125", "1.125",
            ])
            .args(["--dtype", "f64", "--occupancy", "0.5", "--out"])
            .arg(&out)
            .arg("--vti")
            .arg(&vti),
    );
    assert!(so.contains("64 of 125"), "{so}");
    let bytes = std::fs::read(&out).unwrap();
    let (h, data) = npy_payload(&bytes);
    assert!(h.contains("'<f8'") && h.contains("(5, 5, 5)"), "{h}");
    let vals: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(vals.iter().filter(|&&v| v == 1.0).count(), 64);
    // [z, y, x] order: sample (x=0, y=0, z=1) is index 4·25 and lies on the top face → 0.
    assert_eq!(vals[4 * 25], 0.0);
    assert_eq!(vals[4], 0.0); // x = 1
    assert_eq!(vals[0], 1.0); // the corner (0, 0, 0)
    let occ = std::fs::read(d.join("w-occupancy.npy")).unwrap();
    let (h, data) = npy_payload(&occ);
    assert!(h.contains("'|u1'"));
    assert_eq!(data.iter().map(|&b| usize::from(b)).sum::<usize>(), 64);
    let v = std::fs::read_to_string(&vti).unwrap();
    assert!(v.contains("WholeExtent=\"0 4 0 4 0 4\"") && v.contains("Origin=\"0.0 0.0 0.0\""));
    // f32 with --res.
    run_ok(
        gwn()
            .args(["voxelize", cube.to_str().unwrap(), "--res", "8", "--out"])
            .arg(&out),
    );
    let (h, data) = {
        let b = std::fs::read(&out).unwrap();
        let (h, data) = npy_payload(&b);
        (h, data.len())
    };
    assert!(h.contains("'<f4'") && h.contains("(8, 8, 8)"), "{h}");
    assert_eq!(data, 8 * 8 * 8 * 4);
    // Bad inputs.
    let e = run_err(gwn().args(["voxelize", cube.to_str().unwrap(), "--dims", "0", "4", "4"]));
    assert!(e.contains("grid"), "{e}");
    let e = run_err(gwn().args(["voxelize", "/nonexistent/x.stl"]));
    assert!(e.contains("x.stl"), "{e}");
}

#[test]
fn cli_sdf() {
    let d = temp_dir("sdf");
    let cube = d.join("cube.obj");
    write_cube_obj(&cube, &common::unit_cube());
    let out = d.join("sdf.npy");
    run_ok(
        gwn()
            .args(["sdf", cube.to_str().unwrap(), "--dims", "2", "1", "1"])
            .args([
                "--bounds", "-1", "0", "0", "1", "1", "1", "--dtype", "f64", "--out",
            ])
            .arg(&out),
    );
    let b = std::fs::read(&out).unwrap();
    let (h, data) = npy_payload(&b);
    assert!(h.contains("(1, 1, 2)"), "{h}");
    let v: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(v, [0.5, -0.5]);
    let e = run_err(gwn().args(["sdf", "/nonexistent/s.ply"]));
    assert!(e.contains("s.ply"), "{e}");
}

#[test]
fn cli_filter_tets() {
    let d = temp_dir("tets");
    let sphere = d.join("sphere.obj");
    write_cube_obj(&sphere, &icosphere());
    let tm = box_tets(-1.3, 1.3, 5);
    let node = d.join("box.node");
    write_node(std::fs::File::create(&node).unwrap(), &tm.points).unwrap();
    write_ele(std::fs::File::create(d.join("box.ele")).unwrap(), &tm.tets).unwrap();
    let wn = WindingNumber::new(&icosphere()).unwrap();
    let want = filter_tets(&tm.points, &tm.tets, &wn, 0.5)
        .iter()
        .filter(|&&k| k)
        .count();
    let out = d.join("kept.ele");
    let so = run_ok(
        gwn()
            .args(["filter-tets", sphere.to_str().unwrap()])
            .arg(&node)
            .arg("--out")
            .arg(&out),
    );
    assert!(
        so.contains(&format!("kept {want} of {}", tm.tets.len())),
        "{so}"
    );
    let (pts, base) = parse_node(&std::fs::read(d.join("kept.node")).unwrap()).unwrap();
    let tets = parse_ele(&std::fs::read(&out).unwrap(), pts.len(), base).unwrap();
    assert_eq!(tets.len(), want);
    // MEDIT output, higher threshold keeps nothing.
    let med = d.join("kept.mesh");
    let so = run_ok(
        gwn()
            .args(["filter-tets", sphere.to_str().unwrap()])
            .arg(&node)
            .arg("--out")
            .arg(&med)
            .args(["--threshold", "1.5"]),
    );
    assert!(so.contains("kept 0 of"), "{so}");
    assert!(
        std::fs::read_to_string(&med)
            .unwrap()
            .contains("Tetrahedra\n0\n")
    );
    // Malformed tet files: named, with the line.
    let bad = d.join("bad.node");
    std::fs::write(&bad, "2 3 0 0\n1 0 0 0\n2 0 zero 0\n").unwrap();
    std::fs::write(d.join("bad.ele"), "0 4 0\n").unwrap();
    let e = run_err(
        gwn()
            .args(["filter-tets", sphere.to_str().unwrap()])
            .arg(&bad)
            .arg("--out")
            .arg(&out),
    );
    assert!(e.contains("bad.node: line 3: "), "{e}");
    let bad = d.join("bad.mesh");
    std::fs::write(&bad, "MeshVersionFormatted 2\nDimension 3\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n1 2 3 4 0\nEnd\n").unwrap();
    let e = run_err(
        gwn()
            .args(["filter-tets", sphere.to_str().unwrap()])
            .arg(&bad)
            .arg("--out")
            .arg(&med),
    );
    assert!(e.contains("bad.mesh: line 8: "), "{e}");
    let e = run_err(
        gwn()
            .args([
                "filter-tets",
                sphere.to_str().unwrap(),
                "/nonexistent/t.mesh",
                "--out",
            ])
            .arg(&med),
    );
    assert!(e.contains("t.mesh"), "{e}");
}

#[test]
fn cli_classify() {
    let d = temp_dir("classify");
    let a = d.join("a.obj");
    let b = d.join("b.obj");
    write_cube_obj(&a, &subdivided_box([0.0; 3], [1.0; 3], 4));
    write_cube_obj(&b, &subdivided_box([0.5, 0.25, -1.0], [2.0, 2.0, 0.75], 1));
    let csv = d.join("faces.csv");
    let sel = d.join("sel.obj");
    let so = run_ok(
        gwn()
            .args([
                "classify",
                a.to_str().unwrap(),
                b.to_str().unwrap(),
                "--out",
            ])
            .arg(&csv)
            .args(["--select", "inside", "--mesh-out"])
            .arg(&sel),
    );
    assert!(so.contains("42 of 192 faces inside"), "{so}");
    let vals: Vec<f64> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    assert_eq!(vals.len(), 192);
    let obj = gwn::io::load_mesh(&sel).unwrap().mesh;
    assert_eq!(obj.triangles().len(), 42);
    let npy = d.join("faces.npy");
    run_ok(
        gwn()
            .args([
                "classify",
                a.to_str().unwrap(),
                b.to_str().unwrap(),
                "--out",
            ])
            .arg(&npy),
    );
    let bytes = std::fs::read(&npy).unwrap();
    assert!(npy_payload(&bytes).0.contains("(192,)"));
    let e = run_err(
        gwn()
            .args([
                "classify",
                a.to_str().unwrap(),
                "/nonexistent/b.off",
                "--out",
            ])
            .arg(&npy),
    );
    assert!(e.contains("b.off"), "{e}");
}
