use std::process::ExitCode;

fn main() -> ExitCode {
    match robosim::app::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("robosim: {e}");
            ExitCode::from(2)
        }
    }
}
