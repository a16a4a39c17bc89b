// Shared by the fuzz target and by `tests/patches/fuzz_corpus_curved.rs` (via `include!`), so the
// stable test replays the corpus through exactly the code the fuzzer runs.

/// Feeds `data` to the curved-input readers: the first byte selects STEP (`% 3 == 0`), `.bpt`
/// (1) or `.rbpt` (2) text, the rest is the file. Must never panic: an error is one non-empty
/// line; a model that reads must evaluate (bounded work) at points around and inside its box
/// with a value that is finite, or NaN only for a non-finite query.
pub fn check_load_curved(data: &[u8]) {
    use gwn::patch::io::{PatchFormat, parse_patches};
    use gwn::patch::step::{StepWindingNumber, parse_step};
    use gwn::patch::PatchWindingNumber;
    let Some((&selector, body)) = data.split_first() else {
        return;
    };
    // The file readers take text: invalid UTF-8 is their `Io` error before any parsing.
    let Ok(text) = std::str::from_utf8(body) else {
        return;
    };
    let one_line = |message: String| {
        assert!(!message.is_empty() && !message.contains('\n'), "{message:?}");
    };
    let probes = |(lo, hi): ([f64; 3], [f64; 3])| -> Vec<[f64; 3]> {
        let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * lo[k] + 0.5 * hi[k]);
        let out: [f64; 3] = std::array::from_fn(|k| hi[k] + (hi[k] - lo[k]).abs() + 1.0);
        let skew: [f64; 3] = std::array::from_fn(|k| lo[k] + [0.31, 0.57, 0.73][k] * (hi[k] - lo[k]));
        vec![mid, out, skew, lo]
    };
    let check_value = |q: [f64; 3], value: f64| {
        assert!(
            value.is_finite() || q.iter().any(|c| !c.is_finite()),
            "w({q:?}) = {value}"
        );
    };
    match selector % 3 {
        0 => match parse_step(text) {
            Ok(model) => {
                let wn = StepWindingNumber::new(&model);
                for q in probes(model.bounding_box()) {
                    check_value(q, wn.evaluate(q).value);
                }
            }
            Err(e) => one_line(e.to_string()),
        },
        k => {
            let format = if k == 1 { PatchFormat::Bpt } else { PatchFormat::Rbpt };
            match parse_patches(text, format) {
                Ok(set) => {
                    let wn = PatchWindingNumber::new(&set);
                    for q in probes(set.bounding_box()) {
                        check_value(q, wn.evaluate(q).value);
                    }
                }
                Err(e) => one_line(e.to_string()),
            }
        }
    }
}
