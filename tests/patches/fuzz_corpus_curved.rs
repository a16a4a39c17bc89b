//! Replays the curved-input fuzz corpus (`fuzz/corpus/load_curved/`) through the fuzz target's
//! own check on stable Rust, and corrupts the STEP and patch seeds deterministically: a model
//! that evaluates or a one-line error, never a panic.

include!("../../fuzz/fuzz_targets/load_curved_check.rs");

fn corpus() -> Vec<(String, Vec<u8>)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load_curved");
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    files.sort();
    files
}

#[test]
fn curved_fuzz_corpus_never_panics() {
    let files = corpus();
    assert!(files.len() >= 10, "only {} corpus files", files.len());
    for (_, data) in &files {
        check_load_curved(data);
        // Every reader on the same bytes, too.
        for selector in 0..3u8 {
            let mut d = data.clone();
            if let Some(first) = d.first_mut() {
                *first = selector;
            }
            check_load_curved(&d);
        }
    }
}

/// Prefixes of each seed (every 31st byte) and single-byte replacements (every 17th byte, by a
/// few troublesome values: a line break, a digit, a sign, a separator, a quote, a `#`).
#[test]
fn prefixes_and_byte_corruptions_of_the_curved_seeds_are_handled() {
    let mut cases = 0;
    for (name, input) in corpus() {
        if !(name.starts_with("step_") || name.contains("pt_")) {
            continue;
        }
        for end in (1..input.len()).step_by(31) {
            check_load_curved(&input[..end]);
            cases += 1;
        }
        let mut input = input;
        for at in (1..input.len()).step_by(17) {
            let original = input[at];
            for b in [b'\n', b'9', b'-', b',', b'\'', b'#'] {
                input[at] = b;
                check_load_curved(&input);
                cases += 1;
            }
            input[at] = original;
        }
    }
    assert!(cases > 3_000, "{cases}");
}
