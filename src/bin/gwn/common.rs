//! Helpers shared by the subcommands: the error type printed as one line, and progress bars.

use std::fmt;

/// An error printed by `main` as a single line `gwn: <message>` with exit code 1.
#[derive(Debug)]
pub struct CliError(pub String);

impl CliError {
    /// An error from a message.
    pub fn msg(m: impl Into<String>) -> Self {
        CliError(m.into())
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // One line, whatever the source said.
        write!(f, "{}", self.0.replace('\n', " "))
    }
}

impl<E: std::error::Error> From<E> for CliError {
    fn from(e: E) -> Self {
        CliError(e.to_string())
    }
}

/// A progress bar on stderr for `len` steps; hidden when stderr is not a terminal, so logs and
/// pipes stay clean.
pub fn progress(len: u64, what: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new(len);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb
}

/// Loads a mesh for a subcommand: STL files are welded unless `no_weld`; errors name the file.
pub fn load_mesh_for_cli(path: &std::path::Path, no_weld: bool) -> Result<gwn::Mesh, CliError> {
    let opts = gwn::io::LoadOptions {
        weld: if no_weld { Some(false) } else { None },
    };
    let loaded = gwn::io::load_mesh_with(path, &opts)?;
    Ok(loaded.mesh)
}
