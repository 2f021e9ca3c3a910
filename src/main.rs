use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    robosim::cli::main(std::env::args_os(), open_editor)
}

/// Whether descriptor 1 is closed, looked at before Rust's runtime starts: it opens
/// /dev/null on a closed descriptor, after which a closed standard output (`>&-`) cannot
/// be told from one the caller sent to /dev/null on purpose.
#[cfg(unix)]
#[ctor::ctor(unsafe)]
fn note_standard_output() {
    // SAFETY: a plain query of descriptor 1's flags.
    let closed = unsafe { libc::fcntl(1, libc::F_GETFD) } == -1;
    robosim::cli::note_standard_output(closed);
}

#[cfg(feature = "app")]
fn open_editor(db: Option<PathBuf>) -> Result<(), String> {
    robosim::app::run(db)
}

/// A headless build (`--no-default-features`) has no editor to open.
#[cfg(not(feature = "app"))]
fn open_editor(_db: Option<PathBuf>) -> Result<(), String> {
    Err(robosim::cli::NO_EDITOR.to_string())
}
