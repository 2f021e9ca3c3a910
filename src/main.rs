use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    robosim::cli::main(std::env::args_os(), open_editor)
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
