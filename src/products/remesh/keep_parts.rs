//! Inputs whose clean parts are kept as they are, and only the rest remeshed.
//!
//! An assembly is often clean but for a few parts: a printer bed whose clips cross it, a CAD
//! export with one open or flipped part. [`super::keep_input`] remeshes all of it then, and the
//! clean parts lose their exact geometry (and the run costs their area in cells). Here the
//! input's connected components are split into `K`, kept, and `R`, remeshed alone in the same
//! box at the same resolution into `S` (the plate probe sees `R` alone), and the output is
//! `K ∪ S`. With `w = w_K + w_R`:
//!
//! 1. every component of `K` is closed, manifold and oriented, and none of its faces meets a
//!    face of the input outside what they share (exact, on the input's own coordinates, after
//!    [`super::exact_repair`]);
//! 2. `K` alone bounds `{w_K > ½}` (step 3 of [`super::keep_input`] on `K` alone: per
//!    component, `w_K` 0 just outside a solid's wall and 1 just outside a cavity's), so `w_K` is
//!    1 in `K`'s solids and 0 elsewhere;
//! 3. `|w_R| < ½` at every vertex of `K` (the exact evaluator of `R`, with a margin of
//!    [`REST_FIELD_MARGIN`] over its error): `w` crosses ½ across `K`'s faces there. Between the
//!    vertices `w_R` is continuous but not bounded: as a remesh's lattice, this samples;
//! 4. `S` is proved, with `K`, a closed, manifold, oriented surface without self-intersections
//!    whose every component has `w = 0` in front and `1` behind (steps 1–3 of
//!    [`super::keep_input`] on `K ∪ S`, exact on the `f64` coordinates written): so `S` meets no
//!    face of `K`, lies in none of `K`'s solids and holds none (either would put a component in
//!    `w = 2`, or `1` on both sides).
//!
//! A component that fails 2 or 3 moves to `R` (which changes `w_K` and `w_R`, so the steps run
//! again until none moves, at most [`MAX_ROUNDS`] times). When 4 fails, the whole input is
//! remeshed.

use crate::Mesh;
use crate::base::bounding_box::BoundingBox;
use crate::eval::antipodal::WindingNumber;
use crate::kernel::quantize::common_fixed_point;

use super::exact_repair;
use super::intersect::{self, intersecting_faces_wide};
use super::keep_input::{
    ALWAYS_KEPT_FACES, bounds_its_solid, component_winding, components, intersection_budget,
    marching_cubes_faces, referenced, topology_problem, winds_right,
};
use super::lattice::Lattice;
use super::report::TopologyReport;
use super::{RemeshOptions, Remeshed};

/// `|w_R|` at `K`'s vertices must be below `½ −` this: over the exact evaluator's documented
/// error on the boundary sum (`1e-10`), so the test is certain.
pub const REST_FIELD_MARGIN: f64 = 1e-9;

/// Rounds of steps 2 and 3 before giving up: each moves at least one component, and a round
/// builds two evaluators, so nested failures (a component failing only once its container
/// moved) are followed this deep.
pub const MAX_ROUNDS: usize = 8;

/// The split of an input into the components kept and the rest ([`kept_parts`]).
pub struct KeptParts {
    /// `K`'s vertices (the input's, welded), in the input's order.
    pub kept_positions: Vec<[f64; 3]>,
    /// `K`'s faces (repaired), in the input's order.
    pub kept_triangles: Vec<[u32; 3]>,
    /// How many components `K` has.
    pub kept_components: usize,
    /// How many components the input has.
    pub components: usize,
    /// `R`, to remesh.
    pub rest: Mesh,
    /// `R`'s exact evaluator (default options), which step 3 used.
    pub rest_field: WindingNumber,
}

/// `K` and `R` of the [module documentation](self) (steps 1–3), when neither is empty; `None`
/// also when the input's coordinates need more than the exact tests' range, its faces are too
/// uneven for the intersection test, or `K` has more faces than the remesh would aim for (as in
/// [`super::keep_input`]).
pub fn kept_parts(mesh: &Mesh, bounds: BoundingBox, options: &RemeshOptions) -> Option<KeptParts> {
    let cell = Lattice::new(bounds, options.resolution)?.h;
    let (welded, _) = mesh.welded();
    let (positions, triangles) = referenced(welded.positions(), welded.triangles());
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let fixed = common_fixed_point(&positions, bits)?;
    let closed = TopologyReport::of(&positions, &triangles).closed;
    let budget = intersection_budget(triangles.len());
    let triangles = exact_repair::repair(&fixed, &triangles, closed, budget).triangles;
    let parts = components(&triangles);
    // Step 1, per component: the topology first (cheap, and most inputs stop there), then the
    // intersections of the whole input.
    let faces_of =
        |c: &[u32]| -> Vec<[u32; 3]> { c.iter().map(|&f| triangles[f as usize]).collect() };
    let mut kept: Vec<bool> = parts
        .iter()
        .map(|c| {
            let (p, t) = referenced(&positions, &faces_of(c));
            topology_problem(&TopologyReport::of(&p, &t)).is_none()
        })
        .collect();
    if !kept.contains(&true) {
        return None;
    }
    let meets_another = intersecting_faces_wide(&fixed, &triangles, budget).ok()?;
    for (k, c) in kept.iter_mut().zip(&parts) {
        *k &= c.iter().all(|&f| !meets_another[f as usize]);
    }
    for _ in 0..MAX_ROUNDS {
        let select = |keep: bool| -> Vec<[u32; 3]> {
            (parts.iter().zip(&kept))
                .filter(|&(_, &k)| k == keep)
                .flat_map(|(c, _)| faces_of(c))
                .collect()
        };
        let (k_faces, r_faces) = (select(true), select(false));
        if k_faces.is_empty() || r_faces.is_empty() {
            return None;
        }
        // Step 2 on K alone: its components in the order of `kept`'s `true`s.
        let (k_positions, k_triangles) = referenced(&positions, &k_faces);
        let (k_fixed, _) = referenced(&fixed, &k_faces);
        let k_mesh = Mesh::from_slices(&k_positions, &k_triangles).ok()?;
        let k_field = WindingNumber::new(&k_mesh).ok()?;
        let ids: Vec<usize> = (0..parts.len()).filter(|&i| kept[i]).collect();
        let mut first = 0;
        let mut moved = false;
        let mut k_parts = Vec::with_capacity(ids.len());
        for &i in &ids {
            let faces: Vec<u32> = (first..first + parts[i].len() as u32).collect();
            first += parts[i].len() as u32;
            let (o, s) = component_winding(&k_field, &k_mesh, &k_fixed, &faces);
            if !winds_right(o, s) {
                kept[i] = false;
                moved = true;
            }
            k_parts.push(faces);
        }
        if moved {
            continue;
        }
        // Step 3: R's field at K's vertices.
        let rest = Mesh::from_slices(&positions, &r_faces).ok()?;
        let rest_field = WindingNumber::new(&rest).ok()?;
        for (&i, faces) in ids.iter().zip(&k_parts) {
            let near_half = faces
                .iter()
                .flat_map(|&f| k_triangles[f as usize])
                .any(|v| rest_field.eval(k_positions[v as usize]).abs() >= 0.5 - REST_FIELD_MARGIN);
            if near_half {
                kept[i] = false;
                moved = true;
            }
        }
        if moved {
            continue;
        }
        // The size rule of `keep_input`, on K.
        let target = options.simplify.map_or(0.0, |s| {
            s.target_fraction_of_marching_cubes * marching_cubes_faces(&k_mesh, cell)
        });
        if k_triangles.len() > ALWAYS_KEPT_FACES && k_triangles.len() as f64 > target {
            return None;
        }
        return Some(KeptParts {
            kept_positions: k_positions,
            kept_triangles: k_triangles,
            kept_components: ids.len(),
            components: parts.len(),
            rest,
            rest_field,
        });
    }
    None
}

/// `K ∪ S` (`rest` is `S`, the remesh of `parts.rest` on the lattice of a remesh of the whole
/// input), when step 4 of the [module documentation](self) proves it; `None` otherwise. The
/// result has `rest`'s statistics and cell sizes and no fixed-point vertices (its `f64`
/// positions are what was proved).
pub fn merge(parts: &KeptParts, rest: Remeshed) -> Option<Remeshed> {
    let offset = parts.kept_positions.len() as u32;
    let positions: Vec<[f64; 3]> = (parts.kept_positions.iter())
        .chain(&rest.positions)
        .copied()
        .collect();
    let triangles: Vec<[u32; 3]> = (parts.kept_triangles.iter().copied())
        .chain(rest.triangles.iter().map(|t| t.map(|v| v + offset)))
        .collect();
    if topology_problem(&TopologyReport::of(&positions, &triangles)).is_some() {
        return None;
    }
    let bits = intersect::MAX_WIDE_COORDINATE.trailing_zeros();
    let fixed = common_fixed_point(&positions, bits)?;
    bounds_its_solid(&positions, &fixed, &triangles).ok()?;
    Some(Remeshed {
        positions,
        triangles,
        fixed: Vec::new(),
        ticks_per_cell: 0,
        ..rest
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(lo: f64, hi: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let unit = crate::testing::unit_cube(false);
        let p = unit
            .positions()
            .iter()
            .map(|p| p.map(|c| lo + c * (hi - lo)))
            .collect();
        (p, unit.triangles().to_vec())
    }

    /// Step 4 alone: `S` (here a cube, as a remesh would return it) apart from `K` is merged;
    /// crossing it, holding it or inside it, it is not.
    #[test]
    fn the_union_is_proved_or_refused() {
        let (kp, kt) = cube(0.0, 1.0);
        let rest = Mesh::from_slices(&kp, &kt).unwrap();
        let parts = KeptParts {
            kept_positions: kp,
            kept_triangles: kt,
            kept_components: 1,
            components: 2,
            rest_field: WindingNumber::new(&rest).unwrap(),
            rest,
        };
        let s = |lo: f64, hi: f64| {
            let (positions, triangles) = cube(lo, hi);
            Remeshed {
                positions,
                triangles,
                ..Remeshed::default()
            }
        };
        let merged = merge(&parts, s(2.0, 3.0)).expect("apart");
        assert_eq!(merged.triangles.len(), 24);
        assert_eq!(&merged.triangles[12..14], &[[8, 10, 9], [8, 11, 10]]);
        assert!(merge(&parts, s(0.5, 1.5)).is_none(), "crossing");
        assert!(
            merge(&parts, s(-1.0, 2.0)).is_none(),
            "holding K: w = 2 in it"
        );
        assert!(merge(&parts, s(0.25, 0.75)).is_none(), "inside K");
        assert!(merge(&parts, s(1.0, 2.0)).is_none(), "touching K");
    }
}
