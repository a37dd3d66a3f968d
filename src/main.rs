//! The `interact3d` command: argument parsing only; the work is in the library.
//!
//! Exit codes: 0 pass, 1 a scene failed validation (or an asset has findings at or above
//! `--fail-on`), 2 bad input or usage (or not one asset could be read).

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = interact3d::cli::Cli::parse();
    match interact3d::cli::run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
