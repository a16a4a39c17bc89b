//! The finest lattice: box-shaped cells of edge `h[a]` along axis `a`, integer corner
//! coordinates, the coarse level and the margin whose outermost corners are declared outside.
//!
//! Cells are cubes of edge `longest extent / res`, except along an axis whose extent is below
//! `longest / THIN_AXIS_DIVISOR`: there `res / THIN_AXIS_DIVISOR` cells span the extent. A plate
//! thinner than a cube cell (a printer bed: 235 × 235 × 3 mm at `res 64` has 3.7 mm cubes) would
//! otherwise fall between two lattice planes and hold no lattice point, and a part that holds no
//! lattice point is lost. Everything downstream works in lattice units (integer corners,
//! fixed-point vertices), and a positive scaling of each axis keeps incidences, orientations and
//! intersections, so the guarantees do not depend on the cells being cubes.

use crate::base::bounding_box::BoundingBox;

/// The coarse level has about this many cells along the longest axis (inside the margin): fine
/// enough that a thin part is rarely missed by every coarse corner, coarse enough that its
/// `(COARSE_TARGET + 3)³` corners cost little with ray reuse.
pub const COARSE_TARGET: usize = 64;

/// An axis whose extent is below `longest / THIN_AXIS_DIVISOR` gets `res / THIN_AXIS_DIVISOR`
/// cells across (finer cells than the cubes); the others keep cubic cells. 4: at `res 64` a
/// whole-model plate is 16 cells thick, enough for its top and bottom (placed within a tick
/// like every vertex) and its rim, while a model whose box is not flat (the bunny, 1 : 1 : 0.8)
/// keeps the lattice it had with cubes. The side walls of a plate cost about
/// `perimeter · res / THIN_AXIS_DIVISOR` band cells, a fraction of its top and bottom.
pub const THIN_AXIS_DIVISOR: f64 = 4.0;

/// Cells are at most this many times finer along a thin axis than along the longest one: below
/// it the cell edge would approach the rounding of the coordinates (a box flat to `1e-12`),
/// and a part that thin is a sheet, not a solid.
pub const MAX_ANISOTROPY: f64 = (1u64 << 20) as f64;

/// A lattice corner, in finest-cell units from the lattice origin.
pub type Corner = [u32; 3];

/// The finest lattice of a remeshing run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    /// Position of corner `[0, 0, 0]`.
    pub origin: [f64; 3],
    /// Cell edge along each axis (the longest axis's is `longest extent / res`, the largest).
    pub h: [f64; 3],
    /// Finest cells per axis; corners run over `0..=cells[a]`.
    pub cells: [usize; 3],
    /// Octree levels: a coarse cell is `2^levels` finest cells wide.
    pub levels: u32,
    /// Octree levels below the *regular* cell, the cell of the lattice's regular band
    /// ([`Lattice::with_sub_levels`], [`Lattice::with_planar_levels`]): a regular cell is
    /// `2^sub_levels` finest cells wide, and the octree refines below it only where
    /// [`super::octree`] finds a reason to.
    pub sub_levels: u32,
    /// How many of the [`Lattice::sub_levels`] lie above the resolution's cell
    /// ([`Lattice::with_planar_levels`]): the regular cell is `2^planar_levels` resolution cells
    /// wide, and is cut down to the resolution's cell wherever the input in it is not flat.
    /// The resolution's cell is `2^(sub_levels − planar_levels)` finest cells wide.
    pub planar_levels: u32,
}

impl Lattice {
    /// The lattice of cell edge `longest extent / res` around `bounds` (finer along thin axes,
    /// see the [module documentation](self)), with one coarse cell of margin on every side;
    /// `None` when `bounds` is not finite or inverted.
    pub fn new(bounds: BoundingBox, res: usize) -> Option<Lattice> {
        Lattice::refined(bounds, res, [1.0; 3])
    }

    /// [`Lattice::new`] with the cell edge along axis `a` divided by `refinement[a]` (at least 1;
    /// [`super::plates`] decides it), down to at most [`MAX_ANISOTROPY`] times below the cube.
    pub fn refined(bounds: BoundingBox, res: usize, refinement: [f64; 3]) -> Option<Lattice> {
        let ok = (0..3).all(|a| {
            bounds.min[a].is_finite() && bounds.max[a].is_finite() && bounds.min[a] <= bounds.max[a]
        });
        if !ok || res == 0 {
            return None;
        }
        let extent = [0, 1, 2].map(|a| bounds.max[a] - bounds.min[a]);
        let longest = extent[0].max(extent[1]).max(extent[2]);
        // A single point: any positive cell edge shows it (as nothing, w ≤ ½ everywhere).
        let cube = if longest > 0.0 {
            longest / res as f64
        } else {
            1.0
        };
        // A flat axis (extent 0: a planar sheet, no volume) keeps the cube edge.
        let h = [0, 1, 2].map(|a| {
            let e = extent[a];
            let finer = if refinement[a].is_finite() {
                refinement[a].max(1.0)
            } else {
                1.0
            };
            if e > 0.0 {
                ((THIN_AXIS_DIVISOR * e / res as f64).min(cube) / finer)
                    .clamp(cube / MAX_ANISOTROPY, cube)
            } else {
                cube
            }
        });
        let mut levels = 0;
        while res >> (levels + 1) >= COARSE_TARGET {
            levels += 1;
        }
        let coarse = 1usize << levels;
        let mut cells = [0; 3];
        let mut origin = [0.0; 3];
        for a in 0..3 {
            let coarse_edge = h[a] * coarse as f64;
            let inner = ((extent[a] / coarse_edge).ceil() as usize).max(1);
            let c = inner + 2;
            cells[a] = c * coarse;
            let centre = 0.5 * (bounds.min[a] + bounds.max[a]);
            origin[a] = centre - 0.5 * c as f64 * coarse_edge;
        }
        Some(Lattice {
            origin,
            h,
            cells,
            levels,
            sub_levels: 0,
            planar_levels: 0,
        })
    }

    /// The same lattice with every regular cell cut into `2^sub_levels` finest cells per axis
    /// (the corners and the box do not move; the octree gets `sub_levels` more levels). `None`
    /// if the corners would not fit [`pack`]'s 21 bits per axis.
    pub fn with_sub_levels(self, sub_levels: u32) -> Option<Lattice> {
        let scale = 1usize << sub_levels;
        let cells = self.cells.map(|c| c * scale);
        (cells.iter().all(|&c| c < 1 << 21) && self.sub_levels + sub_levels <= 8).then(|| Lattice {
            origin: self.origin,
            h: self.h.map(|h| h / scale as f64),
            cells,
            levels: self.levels + sub_levels,
            sub_levels: self.sub_levels + sub_levels,
            planar_levels: self.planar_levels,
        })
    }

    /// [`Lattice::with_sub_levels`] for a lattice built at `2^planar_levels` times coarser than
    /// the resolution: its regular cells are that many resolution cells wide, and the new levels
    /// lie above the resolution's cell ([`Lattice::planar_levels`]).
    pub fn with_planar_levels(self, planar_levels: u32) -> Option<Lattice> {
        self.with_sub_levels(planar_levels).map(|l| Lattice {
            planar_levels: l.planar_levels + planar_levels,
            ..l
        })
    }

    /// The octree level of the resolution's cell (0: the finest).
    pub fn resolution_level(&self) -> u32 {
        self.sub_levels - self.planar_levels
    }

    /// The lattice of resolution cells: the same box and corners at every
    /// `2^resolution_level`-th finest corner (the units of the simplification's tolerances and
    /// of the report).
    pub fn resolution(self) -> Lattice {
        let level = self.resolution_level();
        let scale = 1usize << level;
        Lattice {
            origin: self.origin,
            h: self.h.map(|h| h * scale as f64),
            cells: self.cells.map(|c| c / scale),
            levels: self.levels - level,
            sub_levels: self.planar_levels,
            planar_levels: self.planar_levels,
        }
    }

    /// Finest cells per regular cell along each axis.
    pub fn regular_cell(&self) -> u32 {
        1 << self.sub_levels
    }

    /// Finest cells per resolution cell along each axis.
    pub fn resolution_cell(&self) -> u32 {
        1 << self.resolution_level()
    }

    /// Coarse cells per axis.
    pub fn coarse_cells(&self) -> [usize; 3] {
        self.cells.map(|n| n >> self.levels)
    }

    /// Position of a point given in (possibly fractional) lattice units.
    pub fn position(&self, p: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.origin[a] + p[a] * self.h[a])
    }

    /// The world plane `n·x + d = 0` (`[n, d]`, `|n| = 1`) in lattice units (the same points,
    /// `x = position(u)`), with a unit normal again; `None` if `n` is 0 or not finite.
    pub fn plane_in_lattice_units(&self, [a, b, c, d]: [f64; 4]) -> Option<[f64; 4]> {
        // n·(origin + h∘u) + d = (n∘h)·u + (n·origin + d).
        let n = [a * self.h[0], b * self.h[1], c * self.h[2]];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let offset = a * self.origin[0] + b * self.origin[1] + c * self.origin[2] + d;
        (len > 0.0 && len.is_finite() && offset.is_finite())
            .then(|| [n[0] / len, n[1] / len, n[2] / len, offset / len])
    }

    /// The largest cell edge (along the longest axis of the box): the unit of the reports'
    /// distances in cells.
    pub fn largest_cell(&self) -> f64 {
        self.h[0].max(self.h[1]).max(self.h[2])
    }

    /// The smallest cell edge.
    pub fn smallest_cell(&self) -> f64 {
        self.h[0].min(self.h[1]).min(self.h[2])
    }

    /// Position of a corner.
    pub fn corner_position(&self, c: Corner) -> [f64; 3] {
        self.position(c.map(f64::from))
    }

    /// Whether `c` lies on the outer faces of the lattice (declared outside, never evaluated).
    pub fn is_border(&self, c: Corner) -> bool {
        (0..3).any(|a| c[a] == 0 || c[a] as usize == self.cells[a])
    }

    /// Whether `c` is a corner of the lattice.
    pub fn contains(&self, c: [i64; 3]) -> bool {
        (0..3).all(|a| c[a] >= 0 && c[a] as u64 <= self.cells[a] as u64)
    }
}

/// Packs a corner into one key (21 bits per axis; [`super::MAX_RESOLUTION`] keeps coordinates
/// below `2^21`).
pub fn pack(c: Corner) -> u64 {
    u64::from(c[0]) | (u64::from(c[1]) << 21) | (u64::from(c[2]) << 42)
}

/// A multiplicative hasher for the packed integer keys of the remesher's maps (the standard
/// SipHash costs more than the lookups it serves; the keys are not attacker-chosen hash-flooding
/// material, and a bad distribution only costs time).
#[derive(Clone, Copy, Debug, Default)]
pub struct KeyHasher(u64);

impl std::hash::Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        // Fold the high bits down: hashbrown takes its bucket index from the low bits.
        self.0 ^ (self.0 >> 29)
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(u64::from(v));
    }
}

/// Builds [`KeyHasher`]s.
pub type KeyHash = std::hash::BuildHasherDefault<KeyHasher>;
/// A map keyed by packed lattice keys.
pub type KeyMap<V> = std::collections::HashMap<u64, V, KeyHash>;
/// A set of packed lattice keys.
pub type KeySet<K> = std::collections::HashSet<K, KeyHash>;

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(extent: [f64; 3], res: usize) -> Lattice {
        let bounds = BoundingBox {
            min: [-1.0, 2.0, 3.0],
            max: [-1.0 + extent[0], 2.0 + extent[1], 3.0 + extent[2]],
        };
        Lattice::new(bounds, res).unwrap()
    }

    #[test]
    fn a_plane_in_lattice_units_holds_the_same_points() {
        // A thin box: cells of different edges per axis.
        let l = lattice([100.0, 60.0, 2.0], 64);
        assert!(l.h[2] < l.h[0]);
        let n = [0.3f64, -0.5, 0.8];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let n = n.map(|x| x / len);
        let through = [10.0, 25.0, 4.0];
        let d = -(n[0] * through[0] + n[1] * through[1] + n[2] * through[2]);
        let p = l.plane_in_lattice_units([n[0], n[1], n[2], d]).unwrap();
        assert!((p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - 1.0).abs() < 1e-12);
        for u in [[0.0, 0.0, 0.0], [3.5, 7.25, 1.0], [60.0, 2.0, 30.0]] {
            let x = l.position(u);
            let world = n[0] * x[0] + n[1] * x[1] + n[2] * x[2] + d;
            let lattice = p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + p[3];
            // Same sign, and the lattice distance is the world one in cells along the normal.
            assert_eq!(world > 0.0, lattice > 0.0, "{u:?}");
            let h_n = (0..3).map(|a| (n[a] * l.h[a]).powi(2)).sum::<f64>().sqrt();
            assert!((lattice - world / h_n).abs() < 1e-9, "{lattice} {world}");
        }
        assert_eq!(l.plane_in_lattice_units([0.0; 4]), None);
        assert_eq!(l.plane_in_lattice_units([f64::NAN, 0.0, 0.0, 0.0]), None);
    }

    #[test]
    fn thin_axes_get_res_over_four_cells_and_the_others_cubes() {
        let cube = 100.0 / 64.0;
        // Not thin (extent ≥ longest / 4): cubes, as before.
        assert_eq!(lattice([100.0, 60.0, 25.0], 64).h, [cube; 3]);
        // A plate: 16 cells across its thickness, plus the margin (one coarse cell each side).
        let plate = lattice([100.0, 100.0, 1.0], 64);
        assert_eq!(plate.h, [cube, cube, 4.0 / 64.0]);
        assert_eq!(plate.cells[2], 16 + 2);
        // Continuous at the threshold: just below it, the cell is just below the cube.
        let edge = lattice([100.0, 100.0, 24.999], 64).h[2];
        assert!(edge < cube && edge > 0.9999 * cube, "{edge}");
        // A flat box (no volume) keeps cubes; a nearly flat one stops at MAX_ANISOTROPY.
        assert_eq!(lattice([100.0, 100.0, 0.0], 64).h[2], cube);
        assert_eq!(
            lattice([100.0, 100.0, 1e-12], 64).h[2],
            cube / MAX_ANISOTROPY
        );
        // Positions follow each axis's cell edge.
        let p = plate.position([1.0, 2.0, 3.0]);
        for a in 0..3 {
            assert_eq!(p[a], plate.origin[a] + [1.0, 2.0, 3.0][a] * plate.h[a]);
        }
        assert_eq!(plate.largest_cell(), cube);
        assert_eq!(plate.smallest_cell(), 4.0 / 64.0);
    }
}
