//! Running the `gwn` binary from integration tests (only tests of the `cli` feature include this
//! file: `CARGO_BIN_EXE_gwn` exists only when the binary is built).

use std::process::Command;

/// Runs `gwn args…`: (success, stdout, stderr).
pub fn gwn(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gwn"))
        .args(args)
        .output()
        .expect("run gwn");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
