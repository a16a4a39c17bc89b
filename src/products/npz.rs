//! NumPy `.npz` archives: a zip of `.npy` members, written *stored* (uncompressed), which
//! `numpy.load` reads like any `.npz`. Every header field that could vary (timestamps, attributes)
//! is fixed, so the same arrays always give the same bytes.

use std::io;

use super::npy::{self, NpyElement};

/// An archive being assembled in memory.
#[derive(Debug, Default)]
pub struct NpzWriter {
    data: Vec<u8>,
    central: Vec<u8>,
    entries: u16,
}

/// 1980-01-01 00:00, the earliest DOS date: a constant so the bytes never depend on the clock.
const DOS_DATE: u16 = 0x0021;
const DOS_TIME: u16 = 0;

impl NpzWriter {
    /// An empty archive.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the array `name` (stored as `name.npy`, read back as `archive[name]`).
    pub fn add<T: NpyElement>(
        &mut self,
        name: &str,
        shape: &[usize],
        data: &[T],
    ) -> io::Result<()> {
        let mut member = Vec::new();
        npy::write(&mut member, shape, data)?;
        self.add_file(&format!("{name}.npy"), &member)
    }

    fn add_file(&mut self, name: &str, content: &[u8]) -> io::Result<()> {
        let too_big = |what: &str| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{what} exceeds the 4 GiB zip limit (zip64 is not written)"),
            )
        };
        let size = u32::try_from(content.len()).map_err(|_| too_big(name))?;
        let offset = u32::try_from(self.data.len()).map_err(|_| too_big("the archive"))?;
        let name_len = u16::try_from(name.len())
            .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "member name too long"))?;
        self.entries = self
            .entries
            .checked_add(1)
            .ok_or_else(|| too_big("entry count"))?;
        let crc = crc32fast::hash(content);

        let common = |out: &mut Vec<u8>| {
            put16(out, 20); // version needed: 2.0
            put16(out, 0); // flags
            put16(out, 0); // method: stored
            put16(out, DOS_TIME);
            put16(out, DOS_DATE);
            put32(out, crc);
            put32(out, size); // compressed
            put32(out, size); // uncompressed
            put16(out, name_len);
            put16(out, 0); // extra field length
        };
        put32(&mut self.data, 0x0403_4b50);
        common(&mut self.data);
        self.data.extend_from_slice(name.as_bytes());
        self.data.extend_from_slice(content);

        put32(&mut self.central, 0x0201_4b50);
        put16(&mut self.central, 20); // made by: 2.0, MS-DOS attributes
        common(&mut self.central);
        put16(&mut self.central, 0); // comment length
        put16(&mut self.central, 0); // disk
        put16(&mut self.central, 0); // internal attributes
        put32(&mut self.central, 0); // external attributes
        put32(&mut self.central, offset);
        self.central.extend_from_slice(name.as_bytes());
        u32::try_from(self.data.len() + self.central.len() + 22)
            .map_err(|_| too_big("the archive"))?;
        Ok(())
    }

    /// The finished archive.
    pub fn finish(mut self) -> Vec<u8> {
        // Sizes were checked in `add_file` to fit 32 bits.
        let cd_offset = self.data.len() as u32;
        let cd_size = self.central.len() as u32;
        self.data.extend_from_slice(&self.central);
        put32(&mut self.data, 0x0605_4b50);
        put16(&mut self.data, 0); // this disk
        put16(&mut self.data, 0); // disk with the central directory
        put16(&mut self.data, self.entries);
        put16(&mut self.data, self.entries);
        put32(&mut self.data, cd_size);
        put32(&mut self.data, cd_offset);
        put16(&mut self.data, 0); // comment length
        self.data
    }
}

fn put16(out: &mut Vec<u8>, v: u16) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_crc() {
        let mut z = NpzWriter::new();
        z.add("a", &[2], &[1.0f64, 2.0]).unwrap();
        z.add("b", &[3], &[true, false, true]).unwrap();
        let bytes = z.finish();
        assert_eq!(&bytes[..4], b"PK\x03\x04");
        let eocd = &bytes[bytes.len() - 22..];
        assert_eq!(&eocd[..4], b"PK\x05\x06");
        assert_eq!(u16::from_le_bytes([eocd[10], eocd[11]]), 2);
        // The first member's CRC is that of its .npy bytes.
        let mut member = Vec::new();
        npy::write(&mut member, &[2], &[1.0f64, 2.0]).unwrap();
        let crc = u32::from_le_bytes([bytes[14], bytes[15], bytes[16], bytes[17]]);
        assert_eq!(crc, crc32fast::hash(&member));
        assert_eq!(&bytes[30..35], b"a.npy");
        assert_eq!(&bytes[35..35 + member.len()], &member[..]);
    }
}
