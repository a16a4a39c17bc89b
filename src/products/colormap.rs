//! The diverging colour map of the slice images.
//!
//! On `[0, 1]` the map is a blue–white–red diverging map centred at `w = 0.5`, built by linear
//! interpolation in CIELAB between three control points of equal chroma budget: blue
//! `L*a*b* = (40, 18, −62)` at 0, near-white `(97, 0, 0)` at 0.5, red `(40, 58, 42)` at 1.
//! Lightness rises linearly from both ends to the centre, so equal steps in `w` are equal
//! perceptual steps (CIELAB is approximately uniform), and both halves have the same lightness
//! profile (a fair diverging map).
//!
//! Values outside `[0, 1]` stay visible: from 1 to 2 the map runs from red to a saturated
//! yellow-orange `(80, 18, 88)` (overlapping shells, `w = 2`), and from 0 to −1 from blue to a
//! saturated teal-green `(62, −52, 12)` (inverted shells, `w = −1`); beyond 2 and −1 it is clamped.
//! NaN is drawn mid grey.

/// A CIELAB control point `(value, [L, a, b])`.
const STOPS: [(f64, [f64; 3]); 5] = [
    (-1.0, [62.0, -52.0, 12.0]),
    (0.0, [40.0, 18.0, -62.0]),
    (0.5, [97.0, 0.0, 0.0]),
    (1.0, [40.0, 58.0, 42.0]),
    (2.0, [80.0, 18.0, 88.0]),
];

/// The smallest and largest value the map distinguishes (clamped beyond).
pub const RANGE: (f64, f64) = (-1.0, 2.0);

/// Colour of NaN.
pub const NAN_COLOR: [u8; 3] = [128, 128, 128];

/// The map's colour for winding number `w` (8-bit sRGB).
pub fn color(w: f64) -> [u8; 3] {
    if w.is_nan() {
        return NAN_COLOR;
    }
    let w = w.clamp(RANGE.0, RANGE.1);
    let mut lab = STOPS[STOPS.len() - 1].1;
    for pair in STOPS.windows(2) {
        let ((v0, c0), (v1, c1)) = (pair[0], pair[1]);
        if w <= v1 {
            let t = (w - v0) / (v1 - v0);
            lab = std::array::from_fn(|k| c0[k] + t * (c1[k] - c0[k]));
            break;
        }
    }
    lab_to_srgb8(lab)
}

/// CIELAB (D65 white) → 8-bit sRGB, out-of-gamut channels clipped.
pub fn lab_to_srgb8(lab: [f64; 3]) -> [u8; 3] {
    // Reference white D65 (2° observer), Y normalized to 1.
    const WHITE: [f64; 3] = [0.950_47, 1.0, 1.088_83];
    let fy = (lab[0] + 16.0) / 116.0;
    let f = [fy + lab[1] / 500.0, fy, fy - lab[2] / 200.0];
    let delta = 6.0 / 29.0;
    let finv = |t: f64| {
        if t > delta {
            t * t * t
        } else {
            3.0 * delta * delta * (t - 4.0 / 29.0)
        }
    };
    let xyz: [f64; 3] = std::array::from_fn(|k| WHITE[k] * finv(f[k]));
    // XYZ → linear sRGB (IEC 61966-2-1 matrix).
    const M: [[f64; 3]; 3] = [
        [3.240_454_2, -1.537_138_5, -0.498_531_4],
        [-0.969_266_0, 1.876_010_8, 0.041_556_0],
        [0.055_643_4, -0.204_025_9, 1.057_225_2],
    ];
    std::array::from_fn(|r| {
        let lin = M[r][0] * xyz[0] + M[r][1] * xyz[1] + M[r][2] * xyz[2];
        let lin = lin.clamp(0.0, 1.0);
        let s = if lin <= 0.003_130_8 {
            12.92 * lin
        } else {
            1.055 * lin.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_is_light_and_ends_differ() {
        let c = color(0.5);
        assert!(c.iter().all(|&v| v > 235), "{c:?}");
        let (b, r, y, g) = (color(0.0), color(1.0), color(2.0), color(-1.0));
        assert!(b[2] > b[0], "blue {b:?}");
        assert!(r[0] > r[2], "red {r:?}");
        for (p, q) in [(b, r), (r, y), (b, g), (y, g)] {
            let d: i32 = (0..3)
                .map(|k| (i32::from(p[k]) - i32::from(q[k])).abs())
                .sum();
            assert!(d > 100, "{p:?} vs {q:?}");
        }
        assert_eq!(color(5.0), color(2.0));
        assert_eq!(color(f64::NAN), NAN_COLOR);
        // Lab white → sRGB white.
        assert_eq!(lab_to_srgb8([100.0, 0.0, 0.0]), [255, 255, 255]);
    }
}
