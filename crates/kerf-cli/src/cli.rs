//! The command line, as clap definitions. Each subcommand's work lives in its own module.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

/// Turns NURBS cut contours into 5-axis laser cutting motion.
#[derive(Debug, Parser)]
#[command(
    name = "kerf",
    version,
    propagate_version = true,
    after_help = "Examples:\n  kerf validate fixtures/mixed.json\n  kerf validate --json part.json > summary.json\n\nExit status: 0 success, 1 invalid or unreadable input, 2 usage error.\nFile formats: shared/formats.md (kerf.curves/1 in, kerf.toolpath/1 out)."
)]
pub(crate) struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub(crate) command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Check a kerf.curves/1 file and summarise its curves and surfaces.
    ///
    /// Reads the file (and any STL files it names), checks every value, and prints one line
    /// per curve (id, degree, control points, rational or not, parameter domain, length in mm,
    /// number of C0 corners, closed or not, carrying surface) and per surface (type and size).
    /// On the first defect it prints `error: <file>: <JSON path>: <defect>` to standard error
    /// and exits with status 1.
    #[command(
        after_help = "Examples:\n  kerf validate fixtures/circle.json\n  kerf validate --json fixtures/mixed.json\n  cat part.json | kerf validate -    (STL paths are then relative to the current directory)"
    )]
    Validate(ValidateArgs),
}

/// Arguments of `kerf validate`.
#[derive(Debug, Args)]
pub(crate) struct ValidateArgs {
    /// The kerf.curves/1 file to check; `-` reads standard input.
    #[arg(value_name = "CURVES.json")]
    pub(crate) curves: PathBuf,

    /// Print the summary as JSON on standard output (also on failure, as
    /// {"valid": false, "error": ...}).
    #[arg(long)]
    pub(crate) json: bool,
}
