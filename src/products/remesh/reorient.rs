//! Closed inputs with flipped faces, kept under the parity method with their faces turned.
//!
//! The parity method's solid ([`crate::eval::parity`]) of a closed mesh is where a ray crosses
//! it an odd number of times, whatever way its faces face. A closed, manifold, embedded input
//! whose faces were flipped here and there (an export that lost its orientation, a shuffled
//! soup) already is the surface of that solid, once every face is turned to face out of it;
//! [`keep_reoriented`] turns them and proves the result with [`super::keep_input`]'s own steps:
//!
//! 1. the input as [`keep_input::prepared`] takes it (welded, its size checked, the exact
//!    repairs made: the parity is unchanged off the surface) has every edge in two faces and
//!    every vertex's faces in one fan, which is step 1 but for the orientation;
//! 2. in each component, every face is turned to agree with its neighbours across each edge
//!    ([`consistently_oriented`], breadth first from the component's first face); where that
//!    contradicts itself the component is one-sided ([`NotKept::NotOrientable`]), which a closed
//!    surface is only while passing through itself;
//! 3. each component turned outward (the exact sign of the volume it encloses), the surface is
//!    embedded (step 2: no two vertices at one position, no two faces meeting outside what they
//!    share), so the components are disjoint closed surfaces and `w` of the turned faces counts
//!    the components around a point; `o`, `w` just outside a component (as step 3 measures it),
//!    counts the components around it;
//! 4. the components with `o` odd are cavities of the even–odd solid and are turned inward;
//!    step 3 on the result then proves `w = 0` in front of every face and `1` behind.
//!
//! Turning a face turns its crossings from `±1` to `∓1`, the same modulo 2, so the result's
//! crossing count has the input's parity everywhere off the surface; the result is closed and
//! oriented, so its `w` is its crossing count, and `w` is `0` or `1`: `{w > ½}` of the result is
//! the parity method's solid of the input, and the result its boundary, facing out.

use crate::Mesh;
use crate::base::bounding_box::BoundingBox;
use crate::eval::antipodal::{BoundaryBy, WindingNumber};
use crate::eval::parity::EdgeCensus;
use crate::kernel::predicates::closed_surface_orientation;

use super::keep_input::{
    self, InputCheck, NotKept, Prepared, check_winding, component_winding, components, embedded,
    referenced_exact, top_vertex, topology_problem, without_a_lattice,
};
use super::report::TopologyReport;
use super::{RemeshOptions, Remeshed};

/// The input with its faces turned to face out of the parity method's solid, as the remesh of
/// `mesh` under that method (with `bounds` and `options` as the remesh would take them), when
/// it provably is that solid's boundary (see the [module documentation](self)); else why not.
///
/// ```
/// use gwn::Mesh;
/// use gwn::products::remesh::{RemeshOptions, keep_input::InputCheck, reorient::keep_reoriented};
/// // A unit cube, outward but for two faces.
/// let p = [[0.,0.,0.],[1.,0.,0.],[1.,1.,0.],[0.,1.,0.],[0.,0.,1.],[1.,0.,1.],[1.,1.,1.],[0.,1.,1.]];
/// let t = [[0,2,1],[0,3,2],[0,1,5],[0,5,4],[1,2,6],[1,6,5],[2,3,7],[2,7,6],[3,0,4],[3,4,7],[4,5,6],[4,6,7]];
/// let mut flipped = t;
/// flipped[4] = [1, 6, 2];
/// flipped[11] = [4, 7, 6];
/// let cube = Mesh::from_slices(&p, &flipped)?;
/// let kept = keep_reoriented(&cube, cube.bounding_box().unwrap(), &RemeshOptions::with_resolution(64)).unwrap();
/// assert_eq!(kept.triangles, t);
/// assert!(matches!(kept.stats.input, Some(InputCheck::Reoriented { turned_faces: 2, .. })));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn keep_reoriented(
    mesh: &Mesh,
    bounds: BoundingBox,
    options: &RemeshOptions,
) -> Result<Remeshed, NotKept> {
    let Prepared {
        positions,
        fixed,
        repaired,
        lattice,
        ..
    } = keep_input::prepared(mesh, bounds, options)?;
    let repairs = repaired.counts;
    let (positions, fixed, triangles) = if repairs.is_empty() {
        (positions, fixed, repaired.triangles)
    } else {
        referenced_exact(&positions, &fixed, &repaired.triangles)
    };
    // Step 1 but the orientation, which is what this mends.
    match topology_problem(&TopologyReport::of(&positions, &triangles)) {
        None | Some(NotKept::Misoriented { .. }) => {}
        Some(problem) => return Err(problem),
    }
    let mut turned = consistently_oriented(&triangles).ok_or(NotKept::NotOrientable)?;
    let parts = components(&turned);
    for faces in &parts {
        let component = faces.iter().map(|&f| turned[f as usize]);
        let top = top_vertex(&positions, component.clone());
        match closed_surface_orientation(&fixed, component, fixed[top as usize]) {
            1 => {}
            -1 => turn(&mut turned, faces),
            // Encloses no volume: not embedded (step 2 would say so).
            _ => {
                return Err(NotKept::Winding {
                    outside: 0,
                    orientation: 0,
                });
            }
        }
    }
    embedded(&fixed, &turned)?;
    // Every component outward and none meeting another: `o` counts the components around one.
    let outward = Mesh::from_slices(&positions, &turned).map_err(|_| NotKept::CoordinateRange)?;
    let wn = WindingNumber::new(&outward).map_err(|_| NotKept::CoordinateRange)?;
    let cavities: Vec<&Vec<u32>> = parts
        .iter()
        .filter(|faces| component_winding(&wn, &outward, &fixed, faces).0 % 2 != 0)
        .collect();
    drop((wn, outward));
    for faces in cavities {
        turn(&mut turned, faces);
    }
    // The proof: `w` is 0 in front of every face and 1 behind.
    let surface = Mesh::from_slices(&positions, &turned).map_err(|_| NotKept::CoordinateRange)?;
    check_winding(&surface, &fixed)?;
    let turned_faces = triangles
        .iter()
        .zip(&turned)
        .filter(|(a, b)| a != b)
        .count();
    let input = InputCheck::Reoriented {
        repairs,
        turned_faces,
    };
    Ok(without_a_lattice(positions, turned, &lattice, input))
}

/// `triangles` (every edge in exactly two faces) with faces turned so that the two faces of
/// every edge use it in opposite directions, each component's first face as it was; `None`
/// where a component cannot be (one-sided).
pub fn consistently_oriented(triangles: &[[u32; 3]]) -> Option<Vec<[u32; 3]>> {
    // Each edge's two faces, from the edges sorted by their vertices: (low, high, face, whether
    // the face runs low -> high).
    let mut edges: Vec<(u32, u32, u32, bool)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(f, t)| {
            (0..3).map(move |k| {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                (a.min(b), a.max(b), f as u32, a < b)
            })
        })
        .collect();
    edges.sort_unstable();
    let mut across: Vec<[(u32, bool); 3]> = vec![[(u32::MAX, false); 3]; triangles.len()];
    let mut slot = vec![0u8; triangles.len()];
    for pair in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let [(_, _, f, df), (_, _, g, dg)] = pair else {
            return None;
        };
        // Two faces agree across the edge when they run it in opposite directions.
        let same = df != dg;
        for (a, b) in [(*f, *g), (*g, *f)] {
            across[a as usize][slot[a as usize] as usize] = (b, same);
            slot[a as usize] += 1;
        }
    }
    // `turn[f]`: whether face `f` is turned; `None` until reached.
    let mut turn: Vec<Option<bool>> = vec![None; triangles.len()];
    let mut queue = Vec::new();
    for start in 0..triangles.len() {
        if turn[start].is_some() {
            continue;
        }
        turn[start] = Some(false);
        queue.push(start as u32);
        while let Some(f) = queue.pop() {
            let tf = turn[f as usize].expect("queued faces are decided");
            for &(g, same) in &across[f as usize][..slot[f as usize] as usize] {
                let tg = tf ^ !same;
                match turn[g as usize] {
                    None => {
                        turn[g as usize] = Some(tg);
                        queue.push(g);
                    }
                    Some(t) if t != tg => return None,
                    Some(_) => {}
                }
            }
        }
    }
    Some(
        triangles
            .iter()
            .zip(&turn)
            .map(|(&[a, b, c], t)| {
                if *t == Some(true) {
                    [a, c, b]
                } else {
                    [a, b, c]
                }
            })
            .collect(),
    )
}

/// The faces `faces` of `triangles` turned.
fn turn(triangles: &mut [[u32; 3]], faces: &[u32]) {
    for &f in faces {
        let [a, b, c] = triangles[f as usize];
        triangles[f as usize] = [a, c, b];
    }
}

/// What a remesh under the exact method tells the user about a mesh that is closed but not
/// consistently oriented (`gwn remesh`'s line, `gwn.remesh`'s warning): `w` is fractional near
/// its flipped faces, and the parity method is the way to the solid it encloses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FlippedInput {
    /// Edges of its signed boundary ([`EdgeCensus::signed_boundary_edges`]).
    pub signed_boundary_edges: usize,
    /// Faces [`keep_reoriented`] turns to keep it, when it does.
    pub turned_faces: Option<usize>,
}

/// [`FlippedInput`] for `mesh` (its edges matched `by` position or index, as the exact
/// evaluator matched them), when it is closed but not consistently oriented
/// ([`EdgeCensus::closed_but_not_oriented`]); `bounds` and `options` as the remesh took them.
pub fn flipped_input(
    mesh: &Mesh,
    by: BoundaryBy,
    bounds: BoundingBox,
    options: &RemeshOptions,
) -> Option<FlippedInput> {
    let census = EdgeCensus::of(mesh, by);
    if !census.closed_but_not_oriented() {
        return None;
    }
    let turned_faces = match keep_reoriented(mesh, bounds, options).map(|k| k.stats.input) {
        Ok(Some(InputCheck::Reoriented { turned_faces, .. })) => Some(turned_faces),
        _ => None,
    };
    Some(FlippedInput {
        signed_boundary_edges: census.signed_boundary_edges,
        turned_faces,
    })
}

impl FlippedInput {
    /// The way out, naming the parity method as the caller spells it (`--method parity`,
    /// `method='parity'`).
    pub fn way_out(&self, parity: &str) -> String {
        match self.turned_faces {
            Some(n) => {
                format!("{parity} keeps it with {n} of its faces turned (proved, no lattice)")
            }
            None => format!("{parity} remeshes the solid it encloses"),
        }
    }
}

impl std::fmt::Display for FlippedInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the input is closed but not consistently oriented ({} signed boundary edges): w is \
             fractional near its flipped faces",
            self.signed_boundary_edges
        )
    }
}
