//! NumPy `.npy` (format 1.0) writers for n-dimensional arrays in C order: `float64`, `float32`,
//! `uint32`, `uint8` and `bool`.

use std::io::{self, Write};
use std::path::Path;

/// A value that `float32` cannot hold ([`check_f32`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F32RangeError {
    /// Index of the first such value.
    pub index: usize,
    /// The value.
    pub value: f64,
}

impl std::fmt::Display for F32RangeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "value {:e} (index {}) does not fit float32 (it would become {})",
            self.value, self.index, self.value as f32
        )
    }
}

impl std::error::Error for F32RangeError {}

/// Checks that every finite value survives conversion to `f32`: none beyond `f32::MAX` (it would
/// become infinite) and none non-zero below the smallest `f32` (it would become 0). Products
/// whose magnitude matters (signed distances of a mesh at 1e60 or 1e-50) refuse a `float32`
/// output with this rather than write infinities or zeros.
pub fn check_f32(values: &[f64]) -> Result<(), F32RangeError> {
    match values.iter().position(|&v| {
        let f = v as f32;
        v.is_finite() && (f.is_infinite() || (f == 0.0 && v != 0.0))
    }) {
        Some(index) => Err(F32RangeError {
            index,
            value: values[index],
        }),
        None => Ok(()),
    }
}

/// An element type that `.npy` can hold.
pub trait NpyElement: Copy {
    /// The NumPy type descriptor, e.g. `'<f8'`.
    const DESCR: &'static str;
    /// Appends the little-endian bytes of `self`.
    fn put(self, out: &mut Vec<u8>);
}

impl NpyElement for f64 {
    const DESCR: &'static str = "<f8";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyElement for f32 {
    const DESCR: &'static str = "<f4";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyElement for u32 {
    const DESCR: &'static str = "<u4";
    fn put(self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.to_le_bytes());
    }
}

impl NpyElement for bool {
    const DESCR: &'static str = "|b1";
    fn put(self, out: &mut Vec<u8>) {
        out.push(u8::from(self));
    }
}

impl NpyElement for u8 {
    const DESCR: &'static str = "|u1";
    fn put(self, out: &mut Vec<u8>) {
        out.push(self);
    }
}

/// The `.npy` header (magic, version 1.0, dictionary padded to a multiple of 64 bytes).
pub fn header(descr: &str, shape: &[usize]) -> io::Result<Vec<u8>> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let shape = match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    };
    let dict = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let unpadded = 10 + dict.len() + 1;
    let pad = (64 - unpadded % 64) % 64;
    let hlen = u16::try_from(dict.len() + pad + 1)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "NPY header too long"))?;
    let mut head = Vec::with_capacity(unpadded + pad);
    head.extend_from_slice(b"\x93NUMPY\x01\x00");
    head.extend_from_slice(&hlen.to_le_bytes());
    head.extend_from_slice(dict.as_bytes());
    head.resize(head.len() + pad, b' ');
    head.push(b'\n');
    Ok(head)
}

/// Writes `data` (C order) as an array of `shape`. Fails when the lengths disagree.
pub fn write<T: NpyElement>(mut w: impl Write, shape: &[usize], data: &[T]) -> io::Result<()> {
    if shape.iter().product::<usize>() != data.len() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("shape {shape:?} does not hold {} values", data.len()),
        ));
    }
    w.write_all(&header(T::DESCR, shape)?)?;
    let mut buf = Vec::with_capacity(1 << 16);
    for &v in data {
        v.put(&mut buf);
        if buf.len() >= 1 << 16 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)?;
    w.flush()
}

/// [`write()`] to a new file at `path`.
pub fn save<T: NpyElement>(path: impl AsRef<Path>, shape: &[usize], data: &[T]) -> io::Result<()> {
    let f = io::BufWriter::new(std::fs::File::create(path)?);
    write(f, shape, data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_aligned_and_readable() {
        let mut out = Vec::new();
        write(&mut out, &[2, 3], &[1u8, 2, 3, 4, 5, 6]).unwrap();
        let hlen = u16::from_le_bytes([out[8], out[9]]) as usize;
        assert_eq!((10 + hlen) % 64, 0);
        let text = std::str::from_utf8(&out[10..10 + hlen]).unwrap();
        assert!(text.contains("'descr': '|u1'") && text.contains("'shape': (2, 3)"));
        assert_eq!(&out[10 + hlen..], &[1, 2, 3, 4, 5, 6]);
        assert!(write(&mut Vec::new(), &[4], &[1.0f32]).is_err());
    }
}
