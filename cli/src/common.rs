//! Helpers shared by the subcommands: the error type printed as one line, checked writes to
//! stdout, argument checks, and progress bars.

use std::fmt;
use std::io::Write;

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

/// `--weld` / `--no-weld`, shared by every subcommand that reads a mesh.
#[derive(clap::Args, Debug, Clone, Copy, Default)]
pub struct WeldArgs {
    /// Merge bit-identical vertices of every format when loading (default: STL only).
    #[arg(long, conflicts_with = "no_weld")]
    pub weld: bool,
    /// Keep the file's vertices as they are (no STL welding), and match the exact method's
    /// boundary edges by vertex index instead of by position (same values; slower on meshes split
    /// at seams or stored as indexed soups, whose index boundary is large).
    #[arg(long)]
    pub no_weld: bool,
}

impl WeldArgs {
    /// What the loader merges.
    pub fn load_options(&self) -> gwn::io::LoadOptions {
        gwn::io::LoadOptions {
            weld: match (self.weld, self.no_weld) {
                (true, _) => Some(true),
                (_, true) => Some(false),
                _ => None,
            },
        }
    }

    /// How the exact method matches boundary edges.
    pub fn boundary(&self) -> gwn::eval::antipodal::BoundaryBy {
        if self.no_weld {
            gwn::eval::antipodal::BoundaryBy::Index
        } else {
            gwn::eval::antipodal::BoundaryBy::Position
        }
    }
}

/// Loads a mesh for a subcommand, welded as `weld` says; errors name the file.
pub fn load_mesh_for_cli(path: &std::path::Path, weld: WeldArgs) -> Result<gwn::Mesh, CliError> {
    let opts = weld.load_options();
    let loaded = gwn::io::load_mesh_with(path, &opts)?;
    print_load_warnings(path, &loaded.warnings);
    Ok(loaded.mesh)
}

/// The error for a failed write to stdout (full disk, closed pipe): one line naming "stdout".
pub fn stdout_error(e: std::io::Error) -> CliError {
    CliError(format!("stdout: cannot write: {e}"))
}

/// Writes formatted text to stdout, turning a failed write into a [`CliError`] instead of the
/// panic of `println!`. Use through [`outln!`].
pub fn write_stdout(args: fmt::Arguments<'_>) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .map_err(stdout_error)
}

/// Flushes stdout; `main` calls it last, because the standard library ignores a failed flush at
/// exit and the last lines would be lost without an error.
pub fn flush_stdout() -> Result<(), CliError> {
    std::io::stdout().flush().map_err(stdout_error)
}

/// `println!` that returns `Result<(), CliError>` instead of panicking when stdout fails.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::common::write_stdout(format_args!($($arg)*))
    };
}
pub(crate) use outln;

/// Prints a warning line on stderr. A failed write to stderr is ignored: there is nowhere left
/// to report it.
pub fn warn(message: impl fmt::Display) {
    let _ = writeln!(std::io::stderr(), "gwn: warning: {message}");
}

/// Worker threads allowed per core: more only adds start-up and scheduling cost (5000 threads
/// took over 20 s for a single query).
pub const THREADS_PER_CORE: usize = 4;

/// A requested thread count, checked: 0 is an error, counts above [`THREADS_PER_CORE`] × the
/// available cores are capped with a warning.
pub fn checked_threads(requested: usize, option: &str) -> Result<usize, CliError> {
    if requested == 0 {
        return Err(CliError(format!("{option} 0: expected at least 1 thread")));
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cap = THREADS_PER_CORE * cores;
    if requested > cap {
        warn(format_args!(
            "{option} {requested} capped at {cap} ({THREADS_PER_CORE} per core, {cores} cores)"
        ));
        return Ok(cap);
    }
    Ok(requested)
}

/// Checks a threshold on w (`--threshold`, `--occupancy`): any finite number.
pub fn check_threshold(value: f64, option: &str) -> Result<(), CliError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(CliError(format!(
            "{option} {value}: expected a finite number"
        )))
    }
}

/// Prints the loader's warnings (e.g. ignored PLY header lines), one line each, naming the file.
pub fn print_load_warnings(path: &std::path::Path, warnings: &[gwn::error::LoadWarning]) {
    for w in warnings {
        warn(format_args!("{}: {w}", path.display()));
    }
}
