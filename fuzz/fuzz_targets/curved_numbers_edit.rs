// Shared by the `curved_numbers` fuzz target and `tests/patches/fuzz_corpus_curved.rs` (via
// `include!`).

/// The curved fuzz seeds: selector byte, then the file (as `load_curved` reads them).
const CURVED_SEEDS: [&[u8]; 10] = [
    include_bytes!("../corpus/load_curved/bpt_bicubic"),
    include_bytes!("../corpus/load_curved/bpt_cube"),
    include_bytes!("../corpus/load_curved/rbpt_sphere"),
    include_bytes!("../corpus/load_curved/step_capped_cylinder"),
    include_bytes!("../corpus/load_curved/step_capped_cylinder_pcurves"),
    include_bytes!("../corpus/load_curved/step_plate_with_hole"),
    include_bytes!("../corpus/load_curved/step_sliced_tube"),
    include_bytes!("../corpus/load_curved/step_torus_band"),
    include_bytes!("../corpus/load_curved/step_torus_full"),
    include_bytes!("../corpus/load_curved/step_torus_patch"),
];

/// The byte spans of the numbers in `text`: maximal runs of digits, signs, dots and exponents
/// that start with a digit not preceded by a letter, a digit or `#` (so `#12` references and
/// names stay).
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < text.len() {
        let starts = text[i].is_ascii_digit()
            && (i == 0 || !(text[i - 1].is_ascii_alphanumeric() || text[i - 1] == b'#'));
        if starts {
            let mut j = i;
            while j < text.len() && (text[j].is_ascii_digit() || b".Ee+-".contains(&text[j])) {
                j += 1;
            }
            spans.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    spans
}

/// `data`: a seed (first byte), then up to 8 edits of 11 bytes each: which number (2 bytes, modulo the
/// count), then a spelling (1 byte: an integer, a float in `{:e}`, in STEP's `1.E5` style, or a
/// special spelling) of a value (8 bytes, an `f64`'s bits or an `i64`). Returns the seed with
/// those numbers replaced, ready for `check_load_curved`.
pub fn edit_curved_seed(data: &[u8]) -> Option<Vec<u8>> {
    let (&which, edits) = data.split_first()?;
    let seed = CURVED_SEEDS[which as usize % CURVED_SEEDS.len()];
    let (&selector, body) = seed.split_first()?;
    let spans = number_spans(body);
    if spans.is_empty() {
        return None;
    }
    let mut replacements: Vec<(usize, String)> = Vec::new();
    for edit in edits.chunks_exact(11).take(8) {
        let index = u16::from_le_bytes([edit[0], edit[1]]) as usize % spans.len();
        let bits = u64::from_le_bytes(edit[3..11].try_into().ok()?);
        let x = f64::from_bits(bits);
        let spelling = match edit[2] % 6 {
            0 => format!("{}", bits as i64),
            1 => format!("{}", (bits as i64) % 100),
            2 if x.is_finite() => format!("{x:e}"),
            3 if x.is_finite() => format!("{x:?}"),
            4 if x.is_finite() => format!("{:.1}E{}", x.abs().min(9.0), (bits >> 56) as i8),
            _ => ["1.E999", "-0.", "1.E-320", "NaN", "", "."][(bits % 6) as usize].to_string(),
        };
        replacements.retain(|(i, _)| *i != index);
        replacements.push((index, spelling));
    }
    replacements.sort();
    let mut out = vec![selector];
    let mut at = 0;
    for (index, spelling) in replacements {
        let (a, b) = spans[index];
        out.extend_from_slice(&body[at..a]);
        out.extend_from_slice(spelling.as_bytes());
        at = b;
    }
    out.extend_from_slice(&body[at..]);
    Some(out)
}
