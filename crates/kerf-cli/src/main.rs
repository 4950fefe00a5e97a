//! The `kerf` command-line tool.
//!
//! Layout: [`cli`] holds the clap definitions of every subcommand, one module per subcommand
//! reads the inputs, calls the library and prints (`validate`, `discretize_cmd`, `run_cmd`,
//! ...; the stages themselves are `kerf-pipeline`), and `main` dispatches and turns errors into messages and exit
//! codes: 0 success, 1 a failure (invalid or unreadable input, unwritable output), 2 a usage
//! error (reported by clap). To add a subcommand, add its arguments and a variant to
//! [`cli::Command`], a module with a `run` function, and a line to the `match` below.

mod check;
mod cli;
mod discretize_cmd;
mod error;
mod guard;
mod import;
mod input;
mod motion_cmd;
mod plot;
mod post;
mod run_cmd;
mod validate;
mod view;

use std::process::ExitCode;

use clap::Parser;

use crate::cli::{Cli, Command};
use crate::error::CliError;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Validate(args) => validate::run(args),
        Command::Discretize(args) => discretize_cmd::run(args),
        Command::Post(args) => post::run(args),
        Command::Run(args) => run_cmd::run(args),
        Command::View(args) => view::run(args),
        Command::Interpolate(args) => motion_cmd::run_interpolate(args),
        Command::Gcode(args) => motion_cmd::run_gcode(args),
        Command::Check(args) => check::run(args),
        Command::Plot(args) => plot::run(args),
        Command::Import(args) => import::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of our output went away (`kerf validate x | head -1`): nothing to report.
        Err(CliError::Output(e)) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e @ CliError::Usage(_)) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
