//! Shared test helpers: small closed-form meshes and the shared-corpus locator.
#![allow(dead_code, unused_imports)]

use gwn::Mesh;

/// Unit cube [0,1]³, 12 outward-oriented triangles.
pub fn unit_cube() -> Mesh {
    gwn::testing::unit_cube(false)
}

/// Unit cube without its top face (z = 1): open, 10 triangles.
pub fn open_cube() -> Mesh {
    gwn::testing::unit_cube(true)
}

pub use gwn::testing::OCTAHEDRON_FACES;

/// The repository's root, the `gwn` package's directory (`tests/cli` and `tests/products` belong
/// to the `gwn-cli` package in `cli/`, whose manifest directory is one below).
pub fn repo() -> &'static std::path::Path {
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    if env!("CARGO_PKG_NAME") == "gwn-cli" {
        manifest.parent().expect("cli/ has a parent")
    } else {
        manifest
    }
}

/// A file of `tests/fixtures/`.
pub fn fixture(name: &str) -> std::path::PathBuf {
    repo().join("tests/fixtures").join(name)
}

/// Reports that the running test skips its body for want of `what` (e.g. `../shared/meshes`),
/// visibly: libtest captures the `print!`/`eprint!` output of passing tests, so a skipped test
/// used to show as `ok` in 0.00 s. A direct write to the process's stderr is not captured, and
/// `cargo test` shows `SKIPPED <test>: needs <what>` next to the test's `ok`.
pub fn report_skip(what: &str) {
    use std::io::Write;
    let thread = std::thread::current();
    let test = thread.name().unwrap_or("(unnamed test)");
    // Ignoring a failed write: the report is informative, the test result stands either way.
    let _ = writeln!(
        std::io::stderr().lock(),
        "SKIPPED {test}: needs {what} (absent)"
    );
}

/// The shared data folder: `$GWN_SHARED_DIR` when set (a checkout whose `../shared` is not the
/// data, e.g. a git worktree elsewhere), else `../shared` next to the repository.
pub fn shared_root() -> std::path::PathBuf {
    match std::env::var_os("GWN_SHARED_DIR") {
        Some(dir) => std::path::PathBuf::from(dir),
        None => repo().join("../shared"),
    }
}

/// `../shared/meshes` if present, else reports the skip ([`report_skip`]) and returns `None`.
pub fn shared_meshes() -> Option<std::path::PathBuf> {
    let p = shared_root().join("meshes");
    if p.join("manifest.csv").exists() {
        Some(p)
    } else {
        report_skip(&p.display().to_string());
        None
    }
}

/// A file (or folder) of the shared corpus (`relative` below [`shared_root`]), or `None` after
/// reporting the skip ([`report_skip`]).
pub fn shared_file(relative: &str) -> Option<std::path::PathBuf> {
    let p = shared_root().join(relative);
    if p.exists() {
        Some(p)
    } else {
        report_skip(&p.display().to_string());
        None
    }
}

/// The file names listed in the shared corpus's `manifest.csv` (first column), with the folder;
/// `None` (and a printed reason) when the corpus is absent.
pub fn shared_mesh_files() -> Option<(std::path::PathBuf, Vec<String>)> {
    let dir = shared_meshes()?;
    let manifest = std::fs::read_to_string(dir.join("manifest.csv")).unwrap();
    let files = manifest
        .lines()
        .skip(1)
        .filter_map(|l| l.split(',').next())
        .map(str::to_owned)
        .collect();
    Some((dir, files))
}

/// Deterministic pseudo-random numbers: the crate's SplitMix64 (`gwn::testing::SplitMix64`) with
/// the state in the open, so tests need no RNG dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        let mut g = gwn::testing::SplitMix64(self.0);
        let v = g.next_u64();
        self.0 = g.0;
        v
    }
    /// Uniform in [0, 1) (53 random bits; dividing by 2^53 and multiplying by 2^-53 are the
    /// same exact operation).
    pub fn f64(&mut self) -> f64 {
        let mut g = gwn::testing::SplitMix64(self.0);
        let v = g.unit();
        self.0 = g.0;
        v
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
}

pub use gwn::testing::direct_at_perturbed;

/// Centre of [`cap_beside_far_tetrahedron`]'s cap (full-precision coordinates).
pub const CAP_CENTRE: [f64; 3] = [0.3127, -0.1171, 2.7113];

/// A small open cap — a fan of `ring` triangles from [`CAP_CENTRE`] to a ragged rim of radius in
/// `radius`, below the centre by 0.5 … 3 — beside a closed unit tetrahedron at `(far, far, far)`,
/// which sets the extent when `far` is huge (at `1e15` the 60-bit cell is `2^-8` and the cap
/// is off the lattice). Returns the mesh and its positions (the centre, the rim, the tetrahedron).
pub fn cap_beside_far_tetrahedron(
    rng: &mut Rng,
    ring: usize,
    radius: (f64, f64),
    far: f64,
) -> (Mesh, Vec<[f64; 3]>) {
    let centre = CAP_CENTRE;
    let mut p = vec![centre];
    for i in 0..ring {
        let a = std::f64::consts::TAU * (i as f64 + rng.range(-0.2, 0.2)) / ring as f64;
        let r = rng.range(radius.0, radius.1);
        p.push([
            centre[0] + r * a.cos(),
            centre[1] + r * a.sin(),
            centre[2] - rng.range(0.5, 3.0),
        ]);
    }
    let first = p.len() as u32;
    let f = far;
    p.extend([[f, f, f], [f + 1.0, f, f], [f, f + 1.0, f], [f, f, f + 1.0]]);
    let mut t: Vec<[u32; 3]> = (0..ring as u32)
        .map(|i| [0, 1 + i, 1 + (i + 1) % ring as u32])
        .collect();
    t.extend([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]].map(|f| f.map(|i| first + i)));
    (Mesh::from_slices(&p, &t).unwrap(), p)
}

/// The unit sphere as 8 rational biquadratic patches (quarter circles × half meridians),
/// outward.
pub fn rational_sphere_patches() -> Vec<gwn::patch::Patch> {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let south = [(0.0, -1.0, 1.0), (1.0, -1.0, w), (1.0, 0.0, 1.0)];
    let north = [(1.0, 0.0, 1.0), (1.0, 1.0, w), (0.0, 1.0, 1.0)];
    let quarters = [
        [(1.0, 0.0), (1.0, 1.0), (0.0, 1.0)],
        [(0.0, 1.0), (-1.0, 1.0), (-1.0, 0.0)],
        [(-1.0, 0.0), (-1.0, -1.0), (0.0, -1.0)],
        [(0.0, -1.0), (1.0, -1.0), (1.0, 0.0)],
    ];
    let cw = [1.0, w, 1.0];
    let mut patches = Vec::new();
    for profile in [south, north] {
        for quarter in quarters {
            let mut pts = Vec::new();
            let mut ws = Vec::new();
            for &(r, z, wp) in &profile {
                for (j, &(x, y)) in quarter.iter().enumerate() {
                    pts.push([r * x, r * y, z]);
                    ws.push(wp * cw[j]);
                }
            }
            patches.push(gwn::patch::Patch::rational(2, 2, pts, ws).unwrap());
        }
    }
    patches
}

/// A sphere sampled by a Fibonacci spiral: oriented points carrying equal areas.
pub fn sphere_cloud(n: usize) -> gwn::mesh::PointCloud {
    let p: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let t = i as f64 * 2.399963229728653;
            [r * t.cos(), r * t.sin(), z]
        })
        .collect();
    let a = vec![4.0 * std::f64::consts::PI / n as f64; n];
    gwn::mesh::PointCloud::new(p.clone(), p, Some(a)).unwrap()
}
