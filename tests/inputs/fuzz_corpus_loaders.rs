//! Replays the fuzz corpus (`fuzz/corpus/load_mesh/`) through the fuzz target's own check on
//! stable Rust, so CI catches regressions without cargo-fuzz.

include!("../../fuzz/fuzz_targets/load_mesh_check.rs");

/// Every file of the fuzz corpus, as written and under every loader. The files go to the thread
/// pool, as in `every_prefix_and_byte_corruption_of_the_fixtures_is_handled` below (why).
#[test]
fn fuzz_corpus_never_panics() {
    use rayon::prelude::*;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load_mesh");
    let files: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.is_file())
        .collect();
    files.par_iter().for_each(|path| {
        let data = std::fs::read(path).unwrap();
        check_load_mesh(&data);
        // Every format on the same bytes, too.
        for sel in 0..7u8 {
            let mut d = data.clone();
            if let Some(first) = d.first_mut() {
                *first = sel;
            }
            check_load_mesh(&d);
        }
    });
    let n = files.len();
    assert!(n >= 10, "only {n} corpus files in {}", dir.display());
}

/// Inputs from the adversarial pass of issue 11 that used to load wrongly (or be rejected
/// wrongly), with what they must give now: `Err(substring of the one-line error)` or
/// `Ok(substring of the one warning)`. The files are in the corpus above (first byte: the
/// loader, as in `check_load_mesh`), so `fuzz_corpus_never_panics` and the fuzzer start from
/// them too.
const REPRODUCERS: &[(&str, Result<&str, &str>)] = &[
    (
        "repro_ply_face_count_short",
        Err("fuzz: line 14: 1 value(s) after the end of element `face` 0 of 2"),
    ),
    (
        "repro_ply_vertex_extra_value",
        Err("fuzz: line 10: 1 value(s) after the end of element `vertex` 0 of 4"),
    ),
    (
        "repro_ply_last_face_extra_value",
        Err("fuzz: line 15: 1 value(s) after the end of element `face` 1 of 2 (first `1`)"),
    ),
    (
        "repro_ply_vertex_missing_value",
        Err("fuzz: line 11: line ends too early in element `vertex` 1 of 4"),
    ),
    (
        "repro_ply_uchar_300",
        Err("fuzz: line 14: invalid uchar value `300` in element `face` 0 of 2"),
    ),
    (
        "repro_ply_char_fraction",
        Err("fuzz: line 14: invalid char value `2.5`"),
    ),
    (
        "repro_ply_blender247_header",
        Ok("line 3: unknown PLY header line `Created by Blender3D 247"),
    ),
    (
        "repro_obj_vertex_trailing_word",
        Err("fuzz: line 1: invalid value `abc` after the coordinates"),
    ),
    (
        "repro_stl_vertex_four_values",
        Err("fuzz: line 4: vertex has more than three coordinates (`7`)"),
    ),
    (
        "repro_off_vertex_trailing_word",
        Err("fuzz: line 3: invalid value `abc` after the data"),
    ),
    (
        "repro_stl_facet_normal_word",
        Err("fuzz: line 2: expected `facet normal NX NY NZ` with three numbers"),
    ),
    ("repro_points_header_only", Err("fuzz: contains no points")),
    ("repro_points_empty", Err("fuzz: contains no points")),
];

#[test]
fn reproducers_give_their_documented_result() {
    use gwn::io::{Format, load_mesh_from_bytes, load_points_from_bytes};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/load_mesh");
    for &(name, expected) in REPRODUCERS {
        let data = std::fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let (&selector, body) = data.split_first().unwrap();
        let format = [Format::Obj, Format::Stl, Format::Off, Format::Ply];
        let result: Result<Vec<String>, String> = match selector {
            0..=3 => load_mesh_from_bytes(body, "fuzz", Some(format[selector as usize]))
                .map(|l| l.warnings.iter().map(|w| w.to_string()).collect())
                .map_err(|e| e.to_string()),
            5 => load_points_from_bytes(body, "fuzz")
                .map(|_| Vec::new())
                .map_err(|e| e.to_string()),
            s => panic!("{name}: selector {s} not used by reproducers"),
        };
        match (expected, result) {
            (Err(want), Err(got)) => {
                assert!(got.contains(want), "{name}: got `{got}`, want `{want}`");
                assert!(!got.contains('\n'), "{name}: `{got}`");
            }
            (Ok(want), Ok(warnings)) => {
                assert_eq!(warnings.len(), 1, "{name}: {warnings:?}");
                assert!(warnings[0].contains(want), "{name}: {warnings:?}");
            }
            (want, got) => panic!("{name}: got {got:?}, want {want:?}"),
        }
    }
}

/// Every prefix of every good fixture, and every fixture with one byte replaced by a few
/// troublesome values, through every loader: a valid mesh or a one-line error, never a panic.
/// About 170,000 deterministic malformed inputs next to the corpus above. The (fixture,
/// selector) runs go to the thread pool: the checks' own parallel steps (the remesh keeps'
/// sorts, intersection tests and topology reports) then run on a pool thread, where rayon's
/// calls are a queue push; from the test's thread each was a cross-thread handoff, 14 s of
/// system time in the scheduler for 5 s of work.
#[test]
fn every_prefix_and_byte_corruption_of_the_fixtures_is_handled() {
    use rayon::prelude::*;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let names = [
        "cube.obj",
        "cube.off",
        "cube_ascii.ply",
        "cube_ascii.stl",
        "cube_binary.stl",
        "cube_binary_be.ply",
        "cube_binary_le.ply",
        "points.csv",
    ];
    let runs: Vec<(&str, u8)> = names
        .iter()
        .flat_map(|&name| (0..6u8).map(move |selector| (name, selector)))
        .collect();
    let cases: usize = runs
        .into_par_iter()
        .map(|(name, selector)| {
            let file = std::fs::read(dir.join(name)).unwrap();
            let mut cases = 0;
            let mut input = vec![selector];
            input.extend_from_slice(&file);
            for end in 1..input.len() {
                check_load_mesh(&input[..end]);
                cases += 1;
            }
            for at in 1..input.len() {
                let original = input[at];
                for b in [b'\n', b' ', b'-', b'9', 0, 0xff] {
                    input[at] = b;
                    check_load_mesh(&input);
                    cases += 1;
                }
                input[at] = original;
            }
            cases
        })
        .sum();
    assert!(cases > 150_000, "{cases}");
}
