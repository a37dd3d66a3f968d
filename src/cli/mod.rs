//! The `interact3d` command's work, one file per subcommand, so that `main.rs` only parses
//! the arguments and calls [`run`]. Errors go to stderr through the caller; machine-readable
//! results go to stdout or files.
//!
//! Entry points: [`Cli`] (the arguments), [`run`]; the subcommands [`export::export`],
//! [`validate::validate`], [`batch::batch`], [`compose::compose`], [`render::render`].

pub mod args;
pub mod batch;
pub mod compose;
pub mod export;
pub mod render;
pub mod validate;

use crate::Error;
pub use args::Cli;
use args::Command;
use std::process::ExitCode;

/// Runs one parsed command line. Exit codes: 0 pass, 1 findings or failed validation; an
/// `Err` is bad input or usage (the caller prints it and exits 2).
pub fn run(cli: Cli) -> Result<ExitCode, Error> {
    match cli.command {
        Command::Export(a) => export::export(a),
        Command::Validate(a) => validate::validate(a),
        Command::Batch(a) => batch::batch(a),
        Command::Compose(a) => compose::compose(a),
        Command::Render(a) => render::render(a),
    }
}

/// Every warning on stderr, one line each, under the table; then the summary line, which counts
/// them.
pub(crate) fn print_warnings_and_summary(warnings: &[String], summary: &str) {
    for w in warnings {
        eprintln!("warning: {w}");
    }
    let n = warnings.len();
    eprintln!("{summary}, {n} warning{}", if n == 1 { "" } else { "s" });
}
