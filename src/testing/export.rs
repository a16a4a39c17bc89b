//! Writers for generated cases: OBJ, OFF, ASCII STL and the certified query CSV used by
//! `gwn gen`. Numbers are printed with Rust's shortest round-trip formatting, so the files
//! reload bit-exactly and the output is a deterministic function of the case.

use std::io::{self, Write};

use super::oracle::{Certified, Decision};
use crate::mesh::Mesh;

/// OFF: header, vertices, then `3 i j k` faces (0-based).
pub fn write_off(mut w: impl Write, mesh: &Mesh) -> io::Result<()> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.positions().len(), mesh.triangles().len())?;
    for p in mesh.positions() {
        writeln!(w, "{} {} {}", p[0], p[1], p[2])?;
    }
    for t in mesh.triangles() {
        writeln!(w, "3 {} {} {}", t[0], t[1], t[2])?;
    }
    Ok(())
}

/// ASCII STL (facet normals written as `0 0 0`; readers recompute them from the winding).
/// STL has no shared vertices: `gwn::io::load_mesh` welds bit-identical positions back.
pub fn write_stl(mut w: impl Write, mesh: &Mesh) -> io::Result<()> {
    writeln!(w, "solid gwn")?;
    for f in 0..mesh.triangles().len() {
        writeln!(w, "facet normal 0 0 0")?;
        writeln!(w, "outer loop")?;
        for p in mesh.triangle_positions(f) {
            writeln!(w, "vertex {} {} {}", p[0], p[1], p[2])?;
        }
        writeln!(w, "endloop")?;
        writeln!(w, "endfacet")?;
    }
    writeln!(w, "endsolid gwn")?;
    Ok(())
}

/// The query CSV of `gwn gen`: header `x,y,z,lo,hi,inside`, one row per query with the certified
/// enclosure `[lo, hi]` of `w(q_ε)` and `inside` = `1` (certainly `w > 1/2`), `0` (certainly
/// `w < 1/2`) or `?` (undecided).
pub fn write_queries_csv(
    mut w: impl Write,
    queries: &[[f64; 3]],
    values: &[Certified],
) -> io::Result<()> {
    writeln!(w, "x,y,z,lo,hi,inside")?;
    for (q, c) in queries.iter().zip(values) {
        let inside = match c.decide(0.5) {
            Decision::Inside => "1",
            Decision::Outside => "0",
            Decision::Undecided => "?",
        };
        writeln!(w, "{},{},{},{},{},{}", q[0], q[1], q[2], c.lo, c.hi, inside)?;
    }
    Ok(())
}
