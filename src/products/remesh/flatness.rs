//! How much of the input is flat at the scale of cells `2^l` resolution cells wide: the probe
//! that decides how many of [`super::RemeshOptions::planar_levels`] pay.
//!
//! A cell above the resolution's stays whole only where the input in it is flat and `w` is an
//! integer at its corners ([`super::octree`]); everywhere else it is cut down to the
//! resolution's cells, and the octree's levels, balance and transitions then cost more than
//! the uniform lattice they end up as (the armadillo at res 256, curved everywhere: 6.4 s with
//! no planar level, 12.5 s with 3, the same output within the sampling). So before the lattice
//! is built, [`SAMPLES`] points drawn on the input by area estimate, per level, the fraction
//! `f_l` of the input's area in cells that would stay whole: the cell of that level holding the
//! point is flat ([`SegmentBvh::flat_in_box`], the same test as the octree's) and `w` just off
//! the point is an integer on both sides, a different one (the triangle is where `w` changes).
//! The band of level `l` then holds about `r_l = (1 − f_l) + f_l / 4^l` of the uniform band's
//! cells; the level with the smallest `r_l` is taken if `r_l` is at most [`MAX_BAND_RATIO`],
//! none otherwise.
//!
//! Only the lattice depends on the probe (a rounding error or an unlucky sample gives other
//! cells, never a wrong label), so every guarantee holds whatever it finds.

use super::crossings::SegmentBvh;
use super::lattice::Lattice;
use super::levels::Comparisons;
use super::octree::{INTEGRAL_W_SLACK, MAX_PLANAR_LEVELS, PLANAR_MAX_TRIANGLES, PLANAR_TOLERANCE};
use crate::eval::Evaluator;

/// Points drawn on the input: the fractions are within about ±3 % (one standard deviation of
/// a proportion over 1,024 samples is at most 1.6 %).
pub const SAMPLES: usize = 1024;

/// Planar levels are used only where they take the band to at most this fraction of the
/// uniform lattice's. Measured on the corpus at res 256 (one level, side by side): with 76–90 %
/// of the area flat at 2x (`r_1` 0.33–0.43) the run was 1.07–3.3x faster, with 61–71 %
/// (`r_1` 0.47–0.54: cgal-cheese, -eight, -hand, -turbine) 1.07–1.33x slower; the octree's
/// levels, balance and transitions cost about what the band's last tenth saves.
pub const MAX_BAND_RATIO: f64 = 0.45;

/// How far off the input the probe evaluates `w`, in resolution cells (as the octree's probe).
const PROBE_OFFSET: f64 = 1e-3;

/// What the probe found.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlatnessProbe {
    /// `flat_fraction[l]`: the estimated fraction of the input's area in cells of level `l`
    /// (`2^l` resolution cells wide) that would stay whole (index 0: unused, 0).
    pub flat_fraction: [f64; MAX_PLANAR_LEVELS as usize + 1],
    /// The planar levels chosen (0: none pay).
    pub levels: u32,
}

/// Probes the input of `guide` with `w` from `evaluator` on the lattice of the resolution
/// (`lattice`), for at most `max_levels` planar levels.
pub fn probe<E: Evaluator + ?Sized>(
    evaluator: &E,
    guide: &SegmentBvh,
    lattice: &Lattice,
    max_levels: u32,
) -> FlatnessProbe {
    let mut out = FlatnessProbe::default();
    let max_levels = max_levels.min(MAX_PLANAR_LEVELS);
    if max_levels == 0 {
        return out;
    }
    let samples = guide.surface_samples(SAMPLES, 0x9e37_79b9_7f4a_7c15);
    if samples.is_empty() {
        return out;
    }
    let cell = lattice.smallest_cell();
    let offset = PROBE_OFFSET * cell;
    let probes: Vec<[f64; 3]> = samples
        .iter()
        .flat_map(|(p, n)| [1.0, -1.0].map(|s| [0, 1, 2].map(|a| p[a] + s * offset * n[a])))
        .collect();
    let w = super::levels::decisive_values(evaluator, &probes, Comparisons::Integrality);
    // `w` an integer on both sides and different: the triangle is where it changes (not an
    // inner face, a double wall, or a sheet that a thickened field surrounds).
    let integral: Vec<bool> = w
        .chunks(2)
        .map(|pair| {
            pair.iter()
                .all(|w| (w - w.round()).abs() <= INTEGRAL_W_SLACK)
                && pair[0].round() != pair[1].round()
        })
        .collect();
    let mut best = 1.0;
    for level in 1..=max_levels {
        let size = f64::from(1u32 << level);
        let flat = samples
            .iter()
            .zip(&integral)
            .filter(|&(_, &integral)| integral)
            .filter(|((p, _), _)| {
                // The cell of this level holding `p`, on the resolution's lattice.
                let lo: [f64; 3] = std::array::from_fn(|a| {
                    let edge = lattice.h[a] * size;
                    lattice.origin[a] + ((p[a] - lattice.origin[a]) / edge).floor() * edge
                });
                let hi: [f64; 3] = std::array::from_fn(|a| lo[a] + lattice.h[a] * size);
                guide
                    .flat_in_box(
                        lo,
                        hi,
                        1e-6 * cell,
                        PLANAR_TOLERANCE * cell,
                        PLANAR_MAX_TRIANGLES,
                    )
                    .is_some()
            })
            .count();
        let f = flat as f64 / samples.len() as f64;
        out.flat_fraction[level as usize] = f;
        let ratio = (1.0 - f) + f / size / size;
        if ratio <= MAX_BAND_RATIO && ratio < best {
            best = ratio;
            out.levels = level;
        }
    }
    out
}
