//! The edge collapses of `gwn remesh` alone, on the marching-tetrahedra surface of one mesh at
//! one resolution: time, counters, and a fingerprint of the output (equal fingerprints: the same
//! surface), so that changes to `simplify/` can be timed and compared side by side.
//!
//! ```text
//! cargo run --release --features examples --example simplify_bench -- MESH RES [--repeat N] [--check] [--no-relocate] [--no-input-planes] [--flat TOL] [--no-diagonals] [--slab-cells N]
//! ```
//! The surface before simplification (exact evaluator, guided placement) is computed once and
//! cached in `$TMPDIR` (`gwn-simplify2-<mesh>-<res>-<lattice cells>.bin`, with the input's planes at
//! the vertices; `--no-input-planes` leaves them out of the quadrics). `--flat TOL`: the
//! flat tolerance in cells (`SimplifyOptions::flat_tolerance`; 0: stop at the target). `--no-diagonals`: no cube-by-cube pass over the diagonal vertices
//! (`SimplifyOptions::lattice_diagonals`). `--slab-cells N`: slab thickness of the parallel
//! collapses (`SimplifyOptions::slab_cells`; 0: none). `--check` also counts exact
//! self-intersections and checks the topology of the output. The thread count is rayon's
//! (`RAYON_NUM_THREADS`).

use std::io::{Read, Write};
use std::path::PathBuf;
use std::time::Instant;

use gwn::eval::antipodal::WindingNumber;
use gwn::products::remesh::lattice::Lattice;
use gwn::products::remesh::report::TopologyReport;
use gwn::products::remesh::{
    DEFAULT_BISECTION_STEPS, crossings, extract, intersect, octree, place, simplify,
};

struct Surface {
    fixed: Vec<[i64; 3]>,
    /// The input's plane at each vertex placed on it (lattice units; NaN: none).
    planes: Vec<[f64; 4]>,
    triangles: Vec<[u32; 3]>,
    ticks: i64,
    marching_cubes: usize,
}

fn build(mesh_path: &PathBuf, res: usize) -> Result<Surface, Box<dyn std::error::Error>> {
    let mesh = gwn::io::load_mesh(mesh_path)?.mesh;
    let wn = WindingNumber::new(&mesh)?;
    let bounds = mesh.bounding_box().ok_or("empty mesh")?;
    let lattice = Lattice::new(bounds, res).ok_or("bad bounds")?;
    let guide = crossings::SegmentBvh::of_mesh(&mesh);
    let classified =
        octree::classify(&wn, &lattice, Some(&guide), usize::MAX, None).map_err(|_| "too large")?;
    let band = extract::extract(&lattice, &classified, None).ok_or("no deadline")?;
    let placed = place::place_vertices(
        &wn,
        &lattice,
        &band.edges,
        &classified.edge_values(&band.edges),
        DEFAULT_BISECTION_STEPS,
        place::CrossingSource::Triangles(&guide),
        None,
    )
    .ok_or("no deadline")?;
    let planes = placed
        .planes_in_lattice_units(&lattice)
        .into_iter()
        .map(|p| p.unwrap_or([f64::NAN; 4]))
        .collect();
    Ok(Surface {
        fixed: placed.fixed,
        planes,
        triangles: band.triangles,
        ticks: placed.ticks_per_cell,
        marching_cubes: band.marching_cubes_triangles,
    })
}

fn save(s: &Surface, path: &PathBuf) -> std::io::Result<()> {
    let mut out = Vec::new();
    for x in [
        s.fixed.len() as u64,
        s.triangles.len() as u64,
        s.ticks as u64,
        s.marching_cubes as u64,
    ] {
        out.extend_from_slice(&x.to_le_bytes());
    }
    for p in &s.fixed {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &s.planes {
        for c in p {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &s.triangles {
        for v in t {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::File::create(path)?.write_all(&out)
}

fn load(path: &PathBuf) -> std::io::Result<Surface> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?.read_to_end(&mut bytes)?;
    let mut at = 0;
    let mut take = |n: usize| {
        let s = &bytes[at..at + n];
        at += n;
        s.to_vec()
    };
    let mut u64_ = || u64::from_le_bytes(take(8).try_into().unwrap_or([0; 8]));
    let (nv, nt, ticks, mc) = (u64_(), u64_(), u64_(), u64_());
    let fixed = (0..nv)
        .map(|_| [0; 3].map(|_: i64| u64_() as i64))
        .collect();
    let planes = (0..nv)
        .map(|_| [0; 4].map(|_: i32| f64::from_bits(u64_())))
        .collect();
    let triangles = (0..nt)
        .map(|_| [0; 3].map(|_: u32| u32::from_le_bytes(take(4).try_into().unwrap_or([0; 4]))))
        .collect();
    Ok(Surface {
        fixed,
        planes,
        triangles,
        ticks: ticks as i64,
        marching_cubes: mc as usize,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mesh_path = PathBuf::from(args.next().ok_or("usage: simplify_bench MESH RES")?);
    let res: usize = args
        .next()
        .ok_or("usage: simplify_bench MESH RES")?
        .parse()?;
    let mut repeat = 1;
    let mut check = false;
    let mut relocate = true;
    let mut input_planes = true;
    let mut diagonals = true;
    let mut flat = simplify::DEFAULT_FLAT_TOLERANCE;
    let mut slab_cells = simplify::DEFAULT_SLAB_CELLS;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--repeat" => repeat = args.next().ok_or("--repeat N")?.parse()?,
            "--check" => check = true,
            "--no-relocate" => relocate = false,
            "--no-input-planes" => input_planes = false,
            "--no-diagonals" => diagonals = false,
            "--flat" => flat = args.next().ok_or("--flat TOL")?.parse()?,
            "--slab-cells" => slab_cells = args.next().ok_or("--slab-cells N")?.parse()?,
            _ => return Err(format!("unknown argument {a}").into()),
        }
    }
    let name = mesh_path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("mesh");
    // The lattice's cell counts in the name: a cache from another lattice rule is not reused.
    let bounds = gwn::io::load_mesh(&mesh_path)?
        .mesh
        .bounding_box()
        .ok_or("empty mesh")?;
    let cells = Lattice::new(bounds, res).ok_or("bad bounds")?.cells;
    let cache = std::env::temp_dir().join(format!(
        "gwn-simplify2-{name}-{res}-{}x{}x{}.bin",
        cells[0], cells[1], cells[2]
    ));
    let surface = match load(&cache) {
        Ok(s) => s,
        Err(_) => {
            let s = build(&mesh_path, res)?;
            save(&s, &cache)?;
            s
        }
    };
    let options = simplify::SimplifyOptions {
        relocate,
        input_planes,
        flat_tolerance: flat,
        lattice_diagonals: diagonals,
        slab_cells,
        ..simplify::SimplifyOptions::default()
    };
    let target =
        (options.target_fraction_of_marching_cubes * surface.marching_cubes as f64) as usize;
    for _ in 0..repeat {
        let planes: Vec<Option<[f64; 4]>> = surface
            .planes
            .iter()
            .map(|p| (!p[0].is_nan()).then_some(*p))
            .collect();
        // The simplifier takes its input by value; the copies are not timed.
        let (points, triangles) = (surface.fixed.clone(), surface.triangles.clone());
        let t0 = Instant::now();
        let s = simplify::simplify_with_planes(
            points,
            triangles,
            surface.ticks,
            &options,
            target,
            options.input_planes.then_some(planes),
        );
        let dt = t0.elapsed().as_secs_f64();
        // FNV-1a over the output: equal surfaces, equal fingerprints.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for t in &s.triangles {
            for &v in t {
                h = (h ^ u64::from(s.vertices[v as usize])).wrapping_mul(0x100_0000_01b3);
                for c in s.points[v as usize] {
                    h = (h ^ c as u64).wrapping_mul(0x100_0000_01b3);
                }
            }
        }
        println!(
            "{name} res {res}: {} -> {} faces (MC {}), {} collapses ({} of diagonal vertices, {} kept; {} of flat stars) in {} rounds, refused {:?}, {} relocated ({} refused), {dt:.2} s, {:.2} us/collapse, fingerprint {h:016x}",
            s.stats.faces_before,
            s.stats.faces_after,
            surface.marching_cubes,
            s.stats.collapses,
            s.stats.diagonal_collapses,
            s.stats.diagonals_left,
            s.stats.flat_star_collapses,
            s.stats.rounds,
            s.stats.refused,
            s.stats.relocated,
            s.stats.relocations_refused,
            dt * 1e6 / s.stats.collapses.max(1) as f64
        );
        if check {
            // The output's own points: relocated vertices are not where the input had them.
            let fixed = s.points.clone();
            let at: Vec<[f64; 3]> = fixed.iter().map(|p| p.map(|c| c as f64)).collect();
            let rep = TopologyReport::of(&at, &s.triangles);
            let si = intersect::self_intersections(&fixed, &s.triangles, u64::MAX)
                .map_err(|e| e.to_string())?;
            println!(
                "  closed {} edge-manifold {} vertex-manifold {} oriented {} euler {} components {} self-intersections {}",
                rep.closed,
                rep.edge_manifold,
                rep.vertex_manifold,
                rep.oriented,
                rep.euler_characteristic,
                rep.components,
                si.pairs
            );
        }
    }
    Ok(())
}
