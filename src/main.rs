use std::process::ExitCode;

fn main() -> ExitCode {
    robosim::cli::main(std::env::args_os(), robosim::app::run)
}
