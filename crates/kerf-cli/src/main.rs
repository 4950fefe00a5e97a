//! The `kerf` command-line tool.
//!
//! Layout: [`cli`] holds the clap definitions of every subcommand, one module per subcommand
//! does its work (`validate`), and `main` dispatches and turns errors into messages and exit
//! codes: 0 success, 1 a failure (invalid or unreadable input, unwritable output), 2 a usage
//! error (reported by clap). To add a subcommand, add its arguments and a variant to
//! [`cli::Command`], a module with a `run` function, and a line to the `match` below.

mod check;
mod cli;
mod cuts;
mod discretize;
mod error;
mod guard;
mod import;
mod motion;
mod place;
mod plot;
mod post;
mod run;
mod validate;

use std::process::ExitCode;

use clap::Parser;

use crate::cli::{Cli, Command};
use crate::error::CliError;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Validate(args) => validate::run(args),
        Command::Discretize(args) => discretize::run(args),
        Command::Post(args) => post::run(args),
        Command::Run(args) => run::run(args),
        Command::Interpolate(args) => motion::run_interpolate(args),
        Command::Gcode(args) => motion::run_gcode(args),
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
