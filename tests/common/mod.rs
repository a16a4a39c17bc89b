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

/// `../shared/meshes` if present, else prints why the caller skips and returns `None`.
pub fn shared_meshes() -> Option<std::path::PathBuf> {
    let p = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    if p.join("manifest.csv").exists() {
        Some(p)
    } else {
        eprintln!(
            "skipping: {} not found (shared mesh corpus absent)",
            p.display()
        );
        None
    }
}

/// Deterministic pseudo-random numbers (SplitMix64) so tests need no RNG dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.f64()
    }
}

pub use gwn::testing::direct_at_perturbed;
