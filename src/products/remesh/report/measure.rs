//! The whole report of one remesh: the output's topology and exact self-intersections, its
//! sampled Hausdorff distance to what it stands for, and the occupancy agreement with the field,
//! with the run's counters — what `gwn remesh` prints and writes with `--report`, and what
//! `gwn.remesh(..., report=True)` returns, measured once here for both.

use super::super::exact_repair::RepairCounts;
use super::super::intersect::{
    IntersectError, SelfIntersections, self_intersections, self_intersections_of_positions,
};
use super::super::keep_input::InputCheck;
use super::super::separate_pinches::SeparatedCounts;
use super::super::{RemeshOptions, RemeshStats, Remeshed};
use super::{
    BoundaryHausdorff, NoSurface, TopologyReport, hausdorff_distance, hausdorff_to_solid_boundary,
    occupancy_agreement,
};
use crate::eval::Evaluator;
use crate::products::json::json_string;

/// Seed of the Hausdorff distance's surface samples (both sides derive theirs from it).
pub const HAUSDORFF_SEED: u64 = 0x4a5d;

/// Seed of the occupancy agreement's samples in the box.
pub const AGREEMENT_SEED: u64 = 0x9e57;

/// Offset of the side tests of [`hausdorff_to_solid_boundary`], in finest cells: far enough
/// off a face for `w` to be decided by it, close enough that no other sheet is nearer.
pub const SIDE_TEST_OFFSET_CELLS: f64 = 0.01;

/// Most samples [`RemeshReport::measure`] takes: about 100 bytes each at the peak (the input's
/// samples with their two side points, values and distances), so a typo cannot ask for
/// terabytes; 10⁷ is a gigabyte, and a thousand times the default.
pub const MAX_SAMPLES: usize = 10_000_000;

/// More samples than [`MAX_SAMPLES`] were asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooManySamples {
    /// The count asked for.
    pub samples: usize,
}

impl std::fmt::Display for TooManySamples {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} report samples is above the limit {MAX_SAMPLES}",
            self.samples
        )
    }
}

impl std::error::Error for TooManySamples {}

/// What a remeshed surface's Hausdorff distance is measured to.
#[derive(Clone, Copy, Debug)]
pub enum DistanceReference<'a> {
    /// The input triangles the field's `w` comes from: the distance to where they bound the
    /// solid (`w > ½` on one side only), with the plain distance on the same samples.
    BoundingMesh(&'a crate::Mesh),
    /// Triangles that all count (a thickened sheet's input bounds nothing of the slab's
    /// solid): the plain distance only.
    Mesh(&'a crate::Mesh),
    /// A tessellation standing for a curved input; its side tests use its own `w` by
    /// Barnes–Hut (β = 2, order 2): a trimmed model's tessellation is open along every trimming
    /// curve, where the exact evaluator's side tests would loop over all those edges, and the
    /// tests only ask whether `w` is above ½ a hundredth of a cell off a face.
    #[cfg(feature = "patch")]
    Curved(&'a super::CurvedSurface),
    /// Nothing to measure a distance to (an oriented point cloud).
    None,
}

/// The steps of [`RemeshReport::measure`], announced as each begins.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReportPhase {
    /// The exact self-intersection count.
    SelfIntersections,
    /// The sampled Hausdorff distance.
    Hausdorff,
    /// The occupancy agreement.
    Agreement,
}

impl ReportPhase {
    /// A short name for progress messages.
    pub fn name(self) -> &'static str {
        match self {
            ReportPhase::SelfIntersections => "counting self-intersections (exact)",
            ReportPhase::Hausdorff => "sampling the Hausdorff distance",
            ReportPhase::Agreement => "occupancy agreement",
        }
    }
}

/// Everything measured about one remesh.
#[derive(Clone, Debug, PartialEq)]
pub struct RemeshReport {
    /// The output's topology.
    pub topology: TopologyReport,
    /// Exact self-intersection count (or why it was not counted).
    pub self_intersections: Result<SelfIntersections, IntersectError>,
    /// Seconds the count took.
    pub self_intersection_seconds: f64,
    /// Sampled symmetric Hausdorff distance to the reference, all of it (world units).
    pub hausdorff: Option<f64>,
    /// The same to where the reference bounds the solid ([`DistanceReference::BoundingMesh`],
    /// [`DistanceReference::Curved`]).
    pub boundary_hausdorff: Option<BoundaryHausdorff>,
    /// A curved reference's longest grid segment (world units): distances near its trimming
    /// curves are known to within it.
    pub reference_segment: Option<f64>,
    /// Fraction of the box samples with the same `w > ½` class under the field and the output.
    pub occupancy_agreement: Option<f64>,
    /// Samples per surface (distance) and in the box (agreement); 0: neither measured.
    pub samples: usize,
    /// The resolution asked for.
    pub resolution: usize,
    /// The resolution's cell edge, the unit of the `_cells` values.
    pub cell_size: f64,
    /// The lattice spacing along each axis.
    pub cell_sizes: [f64; 3],
    /// Sub-cell levels asked for.
    pub sub_cell_levels: u32,
    /// Whether the surface was simplified.
    pub simplified: bool,
    /// The run's work counters.
    pub stats: RemeshStats,
    /// The field's evaluator ([`Evaluator::name`]).
    pub method: String,
    /// Seconds of the remesh itself (set by the caller that timed it; 0 otherwise).
    pub seconds: f64,
    /// The same by phase (set by a caller that timed them with a [`super::PhaseClock`]).
    pub phase_seconds: Option<super::PhaseSeconds>,
    /// Half-thickness of thickened sheets, if the field was a thickened one.
    pub thicken: Option<f64>,
}

impl RemeshReport {
    /// Whether [`RemeshReport::measure`] takes `samples`: callers check before a long remesh.
    pub fn check_samples(samples: usize) -> Result<(), TooManySamples> {
        if samples > MAX_SAMPLES {
            return Err(TooManySamples { samples });
        }
        Ok(())
    }

    /// Measures `out` (whose surface `surface` is, as a mesh) against the `field` it was
    /// extracted from, in `bounds` (the box the remesh was given), with `samples` samples per
    /// surface and in the box (0: no distance, no agreement). The distances and the agreement
    /// are seeded ([`HAUSDORFF_SEED`], [`AGREEMENT_SEED`]): the same inputs give the same
    /// report on every run and thread count. More than [`MAX_SAMPLES`] is refused.
    ///
    /// ```
    /// use gwn::eval::antipodal::WindingNumber;
    /// use gwn::products::remesh::report::{DistanceReference, RemeshReport};
    /// use gwn::products::remesh::{RemeshOptions, remesh};
    /// let tet = gwn::Mesh::from_slices(
    ///     &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
    ///     &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
    /// )?;
    /// let wn = WindingNumber::new(&tet)?;
    /// let bounds = tet.bounding_box().unwrap();
    /// let options = RemeshOptions::with_resolution(16);
    /// let mut out = remesh(&wn, bounds, &options)?;
    /// let surface = gwn::Mesh::new(
    ///     std::mem::take(&mut out.positions),
    ///     std::mem::take(&mut out.triangles),
    /// )?;
    /// let reference = DistanceReference::BoundingMesh(&tet);
    /// let report =
    ///     RemeshReport::measure(&out, &surface, &options, &wn, reference, bounds, 2000, &|_| {})?;
    /// assert!(report.topology.closed && report.self_intersections?.pairs == 0);
    /// assert!(report.boundary_hausdorff.unwrap().distance < out.cell_size);
    /// assert!(report.occupancy_agreement.unwrap() > 0.99);
    /// assert!(report.to_json().starts_with("{\"closed\": true"));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn measure<E: Evaluator + ?Sized>(
        out: &Remeshed,
        surface: &crate::Mesh,
        options: &RemeshOptions,
        field: &E,
        reference: DistanceReference<'_>,
        bounds: crate::BoundingBox,
        samples: usize,
        progress: &dyn Fn(ReportPhase),
    ) -> Result<RemeshReport, TooManySamples> {
        Self::measure_field(
            out, surface, options, &field, reference, bounds, samples, progress,
        )
    }

    /// [`RemeshReport::measure`] on a trait object: compiled once, in this crate, whatever the
    /// caller's evaluator type (as `remesh_guided`'s pipeline).
    #[allow(clippy::too_many_arguments)]
    fn measure_field(
        out: &Remeshed,
        surface: &crate::Mesh,
        options: &RemeshOptions,
        field: &dyn Evaluator,
        reference: DistanceReference<'_>,
        bounds: crate::BoundingBox,
        samples: usize,
        progress: &dyn Fn(ReportPhase),
    ) -> Result<RemeshReport, TooManySamples> {
        Self::check_samples(samples)?;
        let topology = TopologyReport::of(surface.positions(), surface.triangles());
        progress(ReportPhase::SelfIntersections);
        // The broad phase is linear on the remesher's output (faces of at most 6 cells, flat
        // ones up to `SimplifyOptions::max_flat_face_extent` in size classes of their own); the
        // budget only guards against a surprise.
        let budget = 1000 * surface.triangles().len() as u64 + 1_000_000;
        let start = std::time::Instant::now();
        // Kept inputs, whole or in part, have their `f64` positions proved, not fixed-point ones.
        let intersections = if out.fixed.is_empty() {
            self_intersections_of_positions(surface.positions(), surface.triangles(), budget)
        } else {
            self_intersections(&out.fixed, surface.triangles(), budget)
        };
        let self_intersection_seconds = start.elapsed().as_secs_f64();
        progress(ReportPhase::Hausdorff);
        let offset = SIDE_TEST_OFFSET_CELLS * out.cell_size;
        let seed = HAUSDORFF_SEED;
        let (boundary_hausdorff, reference_segment) = match reference {
            _ if samples == 0 => (None, None),
            DistanceReference::BoundingMesh(m) => (
                hausdorff_to_solid_boundary(m, field, surface, samples, seed, offset),
                None,
            ),
            #[cfg(feature = "patch")]
            DistanceReference::Curved(c) => {
                let tw = crate::eval::fast::FastWindingNumber::new(&c.mesh);
                (
                    hausdorff_to_solid_boundary(&c.mesh, &tw, surface, samples, seed, offset),
                    Some(c.segment),
                )
            }
            DistanceReference::Mesh(_) | DistanceReference::None => (None, None),
        };
        let hausdorff = match (reference, boundary_hausdorff) {
            (_, Some(b)) => Some(b.plain),
            (DistanceReference::Mesh(m), None) if samples > 0 => {
                hausdorff_distance(m, surface, samples, seed)
            }
            _ => None,
        };
        progress(ReportPhase::Agreement);
        // Against the output's own exact winding number; an empty output's is 0 everywhere,
        // and its agreement says whether empty was right (an open sheet: 100 %) or a solid was
        // lost.
        let occupancy = if samples == 0 {
            None
        } else if surface.is_empty() {
            occupancy_agreement(field, &NoSurface, bounds, samples, AGREEMENT_SEED)
        } else {
            match crate::eval::antipodal::WindingNumber::new(surface) {
                Ok(output) => occupancy_agreement(field, &output, bounds, samples, AGREEMENT_SEED),
                Err(_) => None,
            }
        };
        Ok(RemeshReport {
            topology,
            self_intersections: intersections,
            self_intersection_seconds,
            hausdorff,
            boundary_hausdorff,
            reference_segment: reference_segment.filter(|_| hausdorff.is_some()),
            occupancy_agreement: occupancy,
            samples,
            resolution: options.resolution,
            cell_size: out.cell_size,
            cell_sizes: out.cell_sizes,
            sub_cell_levels: options.sub_cell_levels,
            simplified: options.simplify.is_some(),
            stats: out.stats,
            method: field.name().to_string(),
            seconds: 0.0,
            phase_seconds: None,
            thicken: None,
        })
    }

    /// The report as one JSON object: the topology's members ([`TopologyReport::to_json`]),
    /// then the run's and the measurements'. Absent measurements are left out.
    pub fn to_json(&self) -> String {
        let s = &self.stats;
        let triple = |v: [f64; 3]| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
        let cell = self.cell_size;
        let mut members = vec![
            ("resolution", self.resolution.to_string()),
            ("cell_size", format!("{cell:?}")),
            ("cell_sizes", triple(self.cell_sizes)),
            ("plate_refinement", triple(s.plates.refinement)),
            (
                "plate_thickness",
                format!(
                    "[{}]",
                    s.plates
                        .thickness
                        .map(|t| t.map_or("null".to_string(), |t| format!("{t:?}")))
                        .join(", ")
                ),
            ),
            ("plate_thin_fraction", triple(s.plates.thin_fraction)),
            ("seconds", format!("{:.3}", self.seconds)),
        ];
        if let Some(check) = s.input {
            members.push(("input", json_string(check.name())));
        }
        match s.input {
            Some(InputCheck::Kept { repairs, separated }) => {
                members.extend(input_changes(repairs, separated));
            }
            Some(InputCheck::Reoriented {
                repairs,
                turned_faces,
            }) => {
                members.extend(input_changes(repairs, SeparatedCounts::default()));
                members.push(("input_turned_faces", turned_faces.to_string()));
            }
            Some(InputCheck::Cut {
                repairs,
                separated,
                cut,
                uncut_faces,
            }) => {
                members.extend(input_changes(repairs, separated));
                members.extend([
                    (
                        "input_intersecting_pairs",
                        cut.intersecting_pairs.to_string(),
                    ),
                    ("input_cut_faces", cut.cut_faces.to_string()),
                    ("input_new_vertices", cut.new_vertices.to_string()),
                    ("input_removed_faces", cut.removed_faces.to_string()),
                    ("input_kept_faces", uncut_faces.to_string()),
                ]);
            }
            Some(InputCheck::PartlyKept {
                kept_components,
                components,
                kept_faces,
                why,
            }) => members.extend([
                ("input_kept_components", kept_components.to_string()),
                ("input_components", components.to_string()),
                ("input_kept_faces", kept_faces.to_string()),
                ("input_not_kept", json_string(&why.to_string())),
            ]),
            Some(InputCheck::Remeshed(why)) => {
                members.push(("input_not_kept", json_string(&why.to_string())));
            }
            Some(InputCheck::Planar { repairs }) => {
                members.extend(input_changes(repairs, SeparatedCounts::default()));
            }
            Some(InputCheck::BoundsNothing { repairs, why }) => {
                members.extend(input_changes(repairs, SeparatedCounts::default()));
                members.push(("input_not_kept", json_string(&why.to_string())));
            }
            None => {}
        }
        if let Some(phases) = &self.phase_seconds {
            members.push(("phase_seconds", phases.to_json()));
        }
        members.extend([
            ("classified_points", s.classified_points.to_string()),
            ("band_cells", s.band_cells.to_string()),
            ("sub_cell_levels", self.sub_cell_levels.to_string()),
            ("refined_cells", s.refined_cells.to_string()),
            ("planar_levels", s.planar_levels.to_string()),
            (
                "flat_fraction",
                triple([
                    s.flatness.flat_fraction[1],
                    s.flatness.flat_fraction[2],
                    s.flatness.flat_fraction[3],
                ]),
            ),
            ("method", json_string(&self.method)),
            ("guided_vertices", s.guided_vertices.to_string()),
            ("placement_evaluations", s.placement_evaluations.to_string()),
            ("simplified", self.simplified.to_string()),
            ("marching_tetrahedra_faces", s.extracted_faces.to_string()),
            ("marching_cubes_faces", s.marching_cubes_faces.to_string()),
            ("collapses", s.simplify.collapses.to_string()),
            (
                "diagonal_collapses",
                s.simplify.diagonal_collapses.to_string(),
            ),
            ("diagonals_kept", s.simplify.diagonals_left.to_string()),
            ("relocated_vertices", s.simplify.relocated.to_string()),
        ]);
        match &self.self_intersections {
            Ok(r) => {
                members.push(("self_intersections", r.pairs.to_string()));
                members.push(("collinear_faces", r.degenerate_faces.to_string()));
            }
            Err(e) => members.push(("self_intersections_error", json_string(&e.to_string()))),
        }
        if let Some(d) = self.hausdorff {
            members.push(("hausdorff", format!("{d:?}")));
            members.push(("hausdorff_cells", format!("{:?}", d / cell)));
        }
        if let Some(b) = self.boundary_hausdorff {
            members.push(("hausdorff_boundary", format!("{:?}", b.distance)));
            members.push((
                "hausdorff_boundary_cells",
                format!("{:?}", b.distance / cell),
            ));
            members.push((
                "hausdorff_boundary_fraction",
                format!("{:?}", b.boundary_fraction),
            ));
        }
        if let Some(segment) = self.reference_segment {
            members.push((
                "hausdorff_reference_segment_cells",
                format!("{:?}", segment / cell),
            ));
        }
        if let Some(t) = self.thicken {
            members.push(("thicken", format!("{t:?}")));
        }
        if let Some(a) = self.occupancy_agreement {
            members.push(("occupancy_agreement", format!("{a:?}")));
            members.push(("occupancy_samples", self.samples.to_string()));
        }
        self.topology.to_json(&members)
    }
}

/// The report's members for what the input went through before it was kept or cut: the exact
/// repairs, and the coplanar faces replaced and the pinches pulled apart (only when there
/// were any, so a report of an input kept bit for bit is as before).
fn input_changes(repairs: RepairCounts, separated: SeparatedCounts) -> Vec<(&'static str, String)> {
    let mut members = vec![
        ("input_zero_area_faces", repairs.zero_area_faces.to_string()),
        ("input_cancelled_faces", repairs.cancelled_faces.to_string()),
        ("input_split_faces", repairs.split_faces.to_string()),
    ];
    if repairs.repeated_faces > 0 {
        members.push(("input_repeated_faces", repairs.repeated_faces.to_string()));
    }
    let coplanar = repairs.coplanar;
    if !coplanar.is_empty() {
        members.extend([
            ("input_coplanar_planes", coplanar.planes.to_string()),
            ("input_coplanar_faces", coplanar.faces.to_string()),
            ("input_coplanar_pieces", coplanar.pieces.to_string()),
            ("input_crossing_vertices", coplanar.crossings.to_string()),
            (
                "input_coplanar_split_neighbours",
                coplanar.split_neighbours.to_string(),
            ),
        ]);
    }
    if !separated.is_empty() {
        members.extend([
            ("input_separated_edges", separated.edges.to_string()),
            ("input_separated_vertices", separated.vertices.to_string()),
            ("input_added_vertices", separated.added_vertices.to_string()),
            ("input_separated_midpoints", separated.midpoints.to_string()),
            (
                "input_largest_move",
                format!("{:?}", separated.largest_move),
            ),
        ]);
    }
    members
}
