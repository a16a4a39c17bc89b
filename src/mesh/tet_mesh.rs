//! Tetrahedral meshes, as tet meshers write them (files: `products::tets`).

/// A tetrahedral mesh: points, tets as four point indices (0-based), and one integer reference
/// per tet (MEDIT's reference; 0 for TetGen files).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Point coordinates.
    pub points: Vec<[f64; 3]>,
    /// Corner indices into `points`.
    pub tets: Vec<[u32; 4]>,
    /// One reference (region label) per tet.
    pub refs: Vec<i64>,
}

impl TetMesh {
    /// The tets with `keep[t]`, with unreferenced points removed (indices renumbered, order kept).
    pub fn select(&self, keep: &[bool]) -> TetMesh {
        let mut map = vec![u32::MAX; self.points.len()];
        let mut out = TetMesh::default();
        for (t, tet) in self.tets.iter().enumerate() {
            if !keep.get(t).copied().unwrap_or(false)
                || tet.iter().any(|&i| i as usize >= self.points.len())
            {
                continue;
            }
            let mapped = tet.map(|i| {
                let m = &mut map[i as usize];
                if *m == u32::MAX {
                    *m = out.points.len() as u32;
                    out.points.push(self.points[i as usize]);
                }
                *m
            });
            out.tets.push(mapped);
            out.refs.push(self.refs.get(t).copied().unwrap_or(0));
        }
        out
    }
}
