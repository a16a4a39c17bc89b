//! Every mesh of the shared corpus (`../shared/meshes/manifest.csv`) loads, and its statistics
//! match the manifest's independently computed ones.

use crate::common;

use std::path::PathBuf;

use gwn::io::{Format, LoadOptions, load_mesh_with};
use gwn::mesh::stats::MeshStats;

/// Documented differences between our statistics and the manifest: `(file, column, reason)`.
/// Empty: every column of every file matches.
const ALLOWED: &[(&str, &str, &str)] = &[];

/// Minimal CSV: comma-separated, `"` quoting with `""` escapes, rows on single lines.
fn parse_csv_line(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(std::mem::take(&mut cur)),
            (c, _) => cur.push(c),
        }
    }
    out.push(cur);
    out
}

fn corpus_dir() -> Option<PathBuf> {
    common::shared_meshes()
}

#[test]
fn manifest_statistics_match() {
    let Some(dir) = corpus_dir() else {
        return;
    };
    let text = std::fs::read_to_string(dir.join("manifest.csv")).unwrap();
    let mut lines = text.lines();
    let header = parse_csv_line(lines.next().unwrap());
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let mut mismatches = Vec::new();
    let mut rows = 0;
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let row = parse_csv_line(line);
        let file = row[col("file")].clone();
        rows += 1;
        let path = dir.join(&file);
        // The manifest does not weld OBJ/OFF/PLY; STL counts are after welding (float32 corners).
        let loaded = match load_mesh_with(&path, &LoadOptions::default()) {
            Ok(l) => l,
            Err(e) => {
                mismatches.push(format!("{file}: failed to load: {e}"));
                continue;
            }
        };
        let s = MeshStats::compute(&loaded.mesh);
        let yes = |b: bool| if b { "yes" } else { "no" }.to_string();
        let ours: [(&str, String); 9] = [
            ("faces", s.faces.to_string()),
            ("vertices", s.vertices.to_string()),
            ("boundary_edges", s.boundary_edges.to_string()),
            ("nonmanifold_edges", s.nonmanifold_edges.to_string()),
            ("components", s.components.to_string()),
            ("degenerate_faces", s.degenerate_faces.to_string()),
            ("duplicate_faces", s.duplicate_faces.to_string()),
            ("closed", yes(s.closed)),
            // Not a column: from the notes' `oriented_closed=` entry.
            ("oriented_closed", yes(s.oriented_closed)),
        ];
        let notes = &row[col("notes")];
        for (name, value) in ours {
            let expected = if name == "oriented_closed" {
                match notes
                    .split_whitespace()
                    .find_map(|kv| kv.strip_prefix("oriented_closed="))
                {
                    Some(v) => v.to_string(),
                    None => continue,
                }
            } else {
                row[col(name)].clone()
            };
            if expected != value {
                if let Some((_, _, why)) = ALLOWED.iter().find(|(f, c, _)| *f == file && *c == name)
                {
                    println!("allowed difference {file} {name}: {value} vs {expected} ({why})");
                    continue;
                }
                mismatches.push(format!(
                    "{file}: {name} = {value}, manifest says {expected}"
                ));
            }
        }
        if let Some(u) = notes
            .split_whitespace()
            .find_map(|kv| kv.strip_prefix("unref_verts="))
        {
            if loaded.format != Format::Stl && u != s.unreferenced_vertices.to_string() {
                mismatches.push(format!(
                    "{file}: unreferenced = {}, manifest says {u}",
                    s.unreferenced_vertices
                ));
            }
        }
        if let Some(p) = notes
            .split_whitespace()
            .find_map(|kv| kv.strip_prefix("polys="))
        {
            if p != loaded.polygons_triangulated.to_string() {
                mismatches.push(format!(
                    "{file}: polygons = {}, manifest says {p}",
                    loaded.polygons_triangulated
                ));
            }
        }
    }
    assert!(rows >= 100, "only {rows} rows in the manifest");
    assert!(
        mismatches.is_empty(),
        "{} mismatches:\n{}",
        mismatches.len(),
        mismatches.join("\n")
    );
}

/// `gwn info`'s logic (load with each weld setting, compute statistics) on every corpus file,
/// fossil folder included, without panicking.
#[test]
fn every_corpus_file_loads_or_errors_cleanly() {
    let Some(dir) = corpus_dir() else {
        return;
    };
    let mut stack = vec![dir];
    let mut n = 0;
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
                continue;
            }
            if gwn::io::format_from_extension(&p).is_none() {
                continue;
            }
            for weld in [None, Some(true), Some(false)] {
                match load_mesh_with(&p, &LoadOptions { weld }) {
                    Ok(l) => {
                        let s = MeshStats::compute(&l.mesh);
                        assert_eq!(s.faces, l.mesh.triangles().len());
                    }
                    Err(e) => {
                        let msg = e.to_string();
                        assert!(!msg.contains('\n'));
                        assert!(msg.contains(&*p.file_name().unwrap().to_string_lossy()));
                        println!("{msg}");
                    }
                }
            }
            n += 1;
        }
    }
    assert!(n >= 100);
}
