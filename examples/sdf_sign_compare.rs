//! Winding-number sign vs angle-weighted pseudo-normal sign of the signed distance: on how many
//! grid points do they disagree?
//!
//! ```text
//! cargo run --release --features examples --example sdf_sign_compare [-- RES]
//! ```
//! Meshes: the unit cube, the cube without its top face (built in code), and from
//! `../shared/meshes` the lion head (open), the mech-holes shark (open) and the armadillo
//! (closed). Grid: the mesh's box grown by 5 %, longest side RES cells (default 64).

use gwn::Mesh;
use gwn::grid::GridSpec;
use gwn::products::sdf::{PseudoNormalSign, SignedDistance};
use rayon::prelude::*;

fn cube(open: bool) -> Mesh {
    gwn::testing::unit_cube(open)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let res: usize = std::env::args().nth(1).map_or(Ok(64), |a| a.parse())?;
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/meshes");
    let mut meshes = vec![
        ("unit cube (closed)".to_string(), cube(false)),
        ("cube without top face".to_string(), cube(true)),
    ];
    for name in [
        "cgal-lion-head.off",
        "cgal-mech-holes-shark.off",
        "cgal-armadillo.off",
    ] {
        match gwn::io::load_mesh(dir.join(name)) {
            Ok(l) => meshes.push((name.to_string(), l.mesh)),
            Err(e) => eprintln!("skipping {e}"),
        }
    }
    println!("| mesh | grid | points | inside by w > 0.5 | inside by pseudo-normal | disagree |");
    println!("|---|---|---:|---:|---:|---:|");
    for (name, mesh) in meshes {
        let bbox = mesh.bounding_box().ok_or("empty mesh")?;
        let spec = GridSpec::with_resolution(bbox.enlarged(0.05), res)?;
        let sdf = SignedDistance::new(&mesh)?;
        let pn = PseudoNormalSign::new(&mesh);
        let d = sdf.eval_grid(&spec);
        let pts = spec.points();
        let pn_inside: Vec<bool> = pts
            .par_iter()
            .map(|&q| sdf.closest(q).is_some_and(|c| pn.sign(q, &c) < 0.0))
            .collect();
        let w_in = d.iter().filter(|v| v.is_sign_negative()).count();
        let p_in = pn_inside.iter().filter(|&&b| b).count();
        let dis = d
            .iter()
            .zip(&pn_inside)
            .filter(|(v, p)| v.is_sign_negative() != **p)
            .count();
        let [w, h, dd] = spec.dims;
        println!(
            "| {name} | {w}×{h}×{dd} | {} | {w_in} | {p_in} | {dis} ({:.2} %) |",
            spec.len(),
            100.0 * dis as f64 / spec.len() as f64
        );
    }
    Ok(())
}
