//! The README's first command: `cargo run --release` runs `gwn` without a subcommand, which
//! renders the bundled open mesh into `slice.png` in the working directory.

use std::process::Command;

#[test]
fn gwn_without_a_subcommand_writes_the_bundled_slice() {
    let dir = std::env::temp_dir().join(format!("gwn-readme-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .current_dir(&dir)
        .output()
        .expect("run gwn");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let png = std::fs::read(dir.join("slice.png")).expect("slice.png written");
    // A PNG signature, then the IHDR chunk: the slice's longer side is `res` = 1024 pixels (the
    // colour bar adds rows below it).
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(&png[12..16], b"IHDR");
    let width = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let height = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert!(
        width > 0 && height > 0 && width.max(height) >= 1024,
        "{width}×{height}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
