//! The small vector vocabulary of `[f64; 3]` points shared by every module (the crate stores
//! plain arrays, not a vector type, so that meshes and queries are the caller's own layout).

/// `a − b`.
#[inline]
pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a·b`.
#[inline]
pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a × b`.
#[inline]
pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`.
#[inline]
pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// `|a|` for any finite `a`, without the overflow (components above ~1e154) or underflow (below
/// ~1e-154) of the squares: when `a·a` is not a normal `f64`, `a` is scaled by `2^∓600` (exact)
/// first. Equal to [`norm`] bit for bit whenever `a·a` is normal.
#[inline]
pub fn norm_safe(a: [f64; 3]) -> f64 {
    let s = dot(a, a);
    if (f64::MIN_POSITIVE..f64::INFINITY).contains(&s) {
        return s.sqrt();
    }
    let m = a[0].abs().max(a[1].abs()).max(a[2].abs());
    if m == 0.0 || !m.is_finite() {
        return if a.iter().any(|c| c.is_nan()) {
            f64::NAN
        } else {
            m
        };
    }
    // 2^600 and 2^-600: exact scalings that bring the largest component to ~[1e-143, 1e127].
    let (up, down) = (
        f64::from_bits((1023 + 600) << 52),
        f64::from_bits((1023 - 600) << 52),
    );
    if m < 1.0 {
        norm(a.map(|c| c * up)) * down
    } else {
        norm(a.map(|c| c * down)) * up
    }
}

/// `|a − b|²`.
#[inline]
pub fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}
