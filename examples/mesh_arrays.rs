//! Writes each mesh as gwn loads it (welding included) to `OUT_DIR/<i>.npz` with arrays `V`
//! (n, 3) float64 and `F` (m, 3) uint32, so peers in a benchmark label exactly the same triangles.
//! A mesh that does not load gets no file and a line on stderr.
//!
//! `cargo run --release --features examples --example mesh_arrays -- OUT_DIR MESH...`

use gwn::products::npz::NpzWriter;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some((out, meshes)) = args.split_first() else {
        eprintln!("usage: mesh_arrays OUT_DIR MESH...");
        std::process::exit(2);
    };
    for (i, path) in meshes.iter().enumerate() {
        let mesh = match gwn::io::load_mesh(path) {
            Ok(l) => l.mesh,
            Err(e) => {
                eprintln!("{e}");
                continue;
            }
        };
        let v: Vec<f64> = mesh.positions().iter().flatten().copied().collect();
        let f: Vec<u32> = mesh.triangles().iter().flatten().copied().collect();
        let mut z = NpzWriter::new();
        let written = z
            .add("V", &[mesh.positions().len(), 3], &v)
            .and_then(|_| z.add("F", &[mesh.triangles().len(), 3], &f))
            .and_then(|_| std::fs::write(format!("{out}/{i}.npz"), z.finish()));
        if let Err(e) = written {
            eprintln!("{path}: {e}");
            std::process::exit(1);
        }
    }
}
