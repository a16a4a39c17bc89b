//! Replays the fuzz corpus (`fuzz/corpus/load_mesh/`) through the fuzz target's own check on
//! stable Rust, so CI catches regressions without cargo-fuzz.

include!("../fuzz/fuzz_targets/load_mesh_check.rs");

#[test]
fn fuzz_corpus_never_panics() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load_mesh");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            let data = std::fs::read(&path).unwrap();
            check_load_mesh(&data);
            // Every format on the same bytes, too.
            for sel in 0..7u8 {
                let mut d = data.clone();
                if let Some(first) = d.first_mut() {
                    *first = sel;
                }
                check_load_mesh(&d);
            }
            n += 1;
        }
    }
    assert!(n >= 10, "only {n} corpus files in {}", dir.display());
}
