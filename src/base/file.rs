//! Opening input files without blocking: a FIFO that no program writes to must not hang a
//! reader (std has no `poll` and no `O_NONBLOCK` constant, and libc is not a dependency). Shared
//! by the mesh loaders (`io`), the 2D module and the patch files, which do not import each other.
//! Each reader is used by some of the features; a build with fewer of them leaves some unused.
#![cfg_attr(
    not(all(feature = "io", feature = "curve2d", feature = "patch")),
    allow(dead_code)
)]

use std::path::Path;

/// Reads a non-blocking stream until its end or `limit` bytes. "No data yet" (`WouldBlock`) is
/// waited out with short sleeps: std offers no `poll`, and the descriptor stays non-blocking
/// because clearing the flag needs `fcntl`.
pub(crate) fn read_stream(
    mut file: &std::fs::File,
    out: &mut Vec<u8>,
    limit: u64,
) -> std::io::Result<()> {
    use std::io::{ErrorKind, Read};
    let mut buf = vec![0u8; 1 << 16];
    let mut pause = std::time::Duration::from_millis(1);
    while (out.len() as u64) < limit {
        let room = usize::try_from(limit - out.len() as u64).unwrap_or(usize::MAX);
        let want = buf.len().min(room);
        match file.read(&mut buf[..want]) {
            Ok(0) => break,
            Ok(n) => {
                out.extend_from_slice(&buf[..n]);
                pause = std::time::Duration::from_millis(1);
            }
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                std::thread::sleep(pause);
                pause = (pause * 2).min(std::time::Duration::from_millis(100));
            }
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// The `O_NONBLOCK` flag of `open(2)` on this platform, if known. std has no constant for it and
/// libc is not a dependency; the values are the kernels' ABI (Linux: `0o4000`, `0x80` on MIPS,
/// `0x4000` on SPARC; Apple and the BSDs: `0x4`). Elsewhere files are opened normally and only the
/// metadata checks of `io::open_regular` protect against FIFOs.
#[cfg(unix)]
const fn o_nonblock() -> Option<i32> {
    if cfg!(any(target_os = "linux", target_os = "android")) {
        if cfg!(any(
            target_arch = "mips",
            target_arch = "mips64",
            target_arch = "mips32r6",
            target_arch = "mips64r6"
        )) {
            Some(0x80)
        } else if cfg!(any(target_arch = "sparc", target_arch = "sparc64")) {
            Some(0x4000)
        } else {
            Some(0o4000)
        }
    } else if cfg!(any(
        target_vendor = "apple",
        target_os = "freebsd",
        target_os = "netbsd",
        target_os = "openbsd",
        target_os = "dragonfly"
    )) {
        Some(0x4)
    } else {
        None
    }
}

/// Opens `path` for reading without waiting for a FIFO's writer (see [`o_nonblock`]).
pub(crate) fn open_nonblocking(path: &Path) -> std::io::Result<std::fs::File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    if let Some(flag) = o_nonblock() {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(flag);
    }
    options.open(path)
}

/// Reads a whole file opened without blocking: a regular file completely, anything else (a pipe,
/// a device) up to `stream_limit` bytes, beyond which it is an `InvalidData` error rather than a
/// read until memory runs out.
pub(crate) fn read_nonblocking(path: &Path, stream_limit: u64) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let file = open_nonblocking(path)?;
    let mut bytes = Vec::new();
    if file.metadata()?.is_file() {
        (&file).read_to_end(&mut bytes)?;
    } else {
        read_stream(&file, &mut bytes, stream_limit + 1)?;
        if bytes.len() as u64 > stream_limit {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("not a regular file and longer than {stream_limit} bytes"),
            ));
        }
    }
    Ok(bytes)
}

/// [`read_nonblocking`] as UTF-8 text.
pub(crate) fn read_text_nonblocking(path: &Path, stream_limit: u64) -> std::io::Result<String> {
    String::from_utf8(read_nonblocking(path, stream_limit)?).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "stream did not contain valid UTF-8",
        )
    })
}
