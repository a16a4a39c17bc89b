//! Replays the curved-input fuzz corpus (`fuzz/corpus/load_curved/`) through the fuzz target's
//! own check on stable Rust, and corrupts the STEP and patch seeds deterministically: a model
//! that evaluates or a one-line error, never a panic.

include!("../../fuzz/fuzz_targets/load_curved_check.rs");
include!("../../fuzz/fuzz_targets/curved_numbers_edit.rs");

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

/// Each number of each seed (every `stride`-th; all of them took 83 s in release and found the
/// hang below) replaced by extreme values one at a time: a model that evaluates or a one-line
/// error, never a panic or a hang (degrees, counts and multiplicities of 10⁹, knots, radii and
/// weights of ±1e308 or 1e-320, out-of-range spellings).
#[test]
fn numbers_replaced_by_extreme_values_are_handled() {
    let stride = 37;
    let extremes = [
        "0",
        "-1",
        "1000000000",
        "1.E308",
        "-1.E308",
        "1.E-320",
        "1.E999",
        "2.5",
    ];
    let mut cases = 0;
    for (name, input) in corpus() {
        let Ok(text) = std::str::from_utf8(&input[1..]) else {
            continue;
        };
        let spans = number_spans(text.as_bytes());
        for &(a, b) in spans.iter().step_by(stride) {
            for value in extremes {
                let mut data = vec![input[0]];
                data.extend_from_slice(&text.as_bytes()[..a]);
                data.extend_from_slice(value.as_bytes());
                data.extend_from_slice(&text.as_bytes()[b..]);
                check_load_curved(&data);
                cases += 1;
            }
        }
        assert!(!spans.is_empty(), "{name}: no numbers");
    }
    assert!(cases > 200, "{cases}");
}

/// The hang the extreme numbers found: the capped cylinder with a radius of 1e308 around its
/// edges of radius 1 (1e9 and 1e-320 were slow too). Its rational patches overflow in the ray
/// frame, the hull tests cull nothing, and the ray-hit search split every patch to its depth
/// limit, `4^12` pieces per patch and ray: minutes per query (the search's piece cap bounds
/// that now: `ray_hits`' own test). Such a file is refused when it is read: its edges do not
/// lie on their face's surface.
#[test]
fn a_cylinder_whose_radius_disagrees_with_its_edges_is_refused() {
    use gwn::patch::step::parse_step;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/step");
    let text = std::fs::read_to_string(dir.join("capped_cylinder.step")).unwrap();
    for radius in ["1.E308", "1.E9", "1.E-320", "1.1"] {
        let hostile = text.replace(
            "CYLINDRICAL_SURFACE('',#10,1.)",
            &format!("CYLINDRICAL_SURFACE('',#10,{radius})"),
        );
        assert_ne!(hostile, text);
        let message = parse_step(&hostile).unwrap_err().to_string();
        assert!(
            message.contains("from the face's surface") && !message.contains('\n'),
            "{radius}: {message}"
        );
    }
    // Within the limit (edges of radius 1 on a cylinder of radius 1.001: 0.1 % of the model's
    // size off) the model reads.
    let close = text.replace(
        "CYLINDRICAL_SURFACE('',#10,1.)",
        "CYLINDRICAL_SURFACE('',#10,1.001)",
    );
    assert!(parse_step(&close).is_ok());
}

/// The `curved_numbers` fuzz target's inputs, drawn at random on stable: each seed with one to
/// eight of its numbers replaced by arbitrary integers, floats and odd spellings, through the
/// same check (every input handled: a model that evaluates, or a one-line error).
#[test]
fn seeds_with_random_numbers_are_handled() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        // splitmix64
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let mut edited = 0;
    for case in 0..120 {
        let mut data = vec![(case % CURVED_SEEDS.len()) as u8];
        for _ in 0..1 + next() % 8 {
            data.extend_from_slice(&next().to_le_bytes()[..3]);
            // Half the values near the seeds' scale, half anywhere in `f64`.
            let value = if next() % 2 == 0 {
                ((next() % 2001) as f64 / 100.0 - 10.0).to_bits()
            } else {
                next()
            };
            data.extend_from_slice(&value.to_le_bytes());
        }
        if let Some(input) = edit_curved_seed(&data) {
            check_load_curved(&input);
            edited += 1;
        }
    }
    assert_eq!(edited, 120);
}

/// The `curved_numbers` fuzzer's corpus (`fuzz/corpus/curved_numbers/`), replayed on stable.
/// `nan_at_a_corner` is its first find: the cube patch set with one control point moved to
/// `1.2·10^155`, whose exact evaluation at the corner `(0, 0, 0)` was NaN (now finite,
/// uncertified, with an infinite error estimate).
#[test]
fn curved_numbers_corpus_is_handled() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/curved_numbers");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let data = std::fs::read(entry.unwrap().path()).unwrap();
        if let Some(input) = edit_curved_seed(&data) {
            check_load_curved(&input);
            replayed += 1;
        }
    }
    assert!(replayed >= 1, "{replayed}");
    let corner = edit_curved_seed(&std::fs::read(dir.join("nan_at_a_corner")).unwrap()).unwrap();
    let text = std::str::from_utf8(&corner[1..]).unwrap();
    assert!(text.contains("1.1937922535104073e155 0.0 1.0"), "{text}");
    let set = gwn::patch::io::parse_patches(text, gwn::patch::io::PatchFormat::Bpt).unwrap();
    let e = gwn::patch::PatchWindingNumber::new(&set).evaluate([0.0, 0.0, 0.0]);
    assert!(
        e.value.is_finite() && !e.certified && e.error_estimate == f64::INFINITY,
        "{e:?}"
    );
}
