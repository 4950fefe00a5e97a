//! The errors a command can end with; `main` prints them as `error: <message>`.
//!
//! Everything the pipeline can fail with is one [`kerf_pipeline::Error`] (which keeps the
//! stage's error as its source and names the file and the curve); the variants here add what
//! only a command line has: usage errors, standard output, the checker's verdict.

use std::fmt;
use std::io;

use kerf_format::FormatError;

/// Why a command failed.
#[derive(Debug)]
pub(crate) enum CliError {
    /// A stage of the pipeline failed (the message names the file and the curve).
    Pipeline(kerf_pipeline::Error),
    /// Writing to standard output failed.
    Output(io::Error),
    /// An input is unusable for this command (the message names file and place).
    Input(String),
    /// The command line asks for something that cannot be done (an output that is also an
    /// input); exit status 2 like clap's own usage errors.
    Usage(String),
    /// A toolpath could not be read by `kerf check` (not JSON, not kerf.toolpath/1, wrong
    /// shape); the message names the file and the JSON path.
    Check(kerf_check::CheckError),
    /// `kerf check` found violations (listed in its report).
    CheckFailed {
        /// The toolpath file.
        toolpath: std::path::PathBuf,
        /// How many.
        violations: usize,
    },
    /// `kerf plot` could not make its picture (the message names the file).
    Plot(String),
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Pipeline(e) => {
                write!(f, "{}", with_flags(e.to_string()))?;
                if let Some(hint) = hint(e) {
                    write!(f, " [{hint}]")?;
                }
                Ok(())
            }
            CliError::Output(e) => write!(f, "cannot write to standard output: {e}"),
            CliError::Input(m) | CliError::Usage(m) => write!(f, "{m}"),
            CliError::Check(e) => write!(f, "{e}"),
            CliError::CheckFailed {
                toolpath,
                violations,
            } => write!(
                f,
                "{}: {violations} violation{} (listed above)",
                toolpath.display(),
                if *violations == 1 { "" } else { "s" }
            ),
            CliError::Plot(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for CliError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CliError::Pipeline(e) => Some(e),
            CliError::Output(e) => Some(e),
            CliError::Check(e) => Some(e),
            _ => None,
        }
    }
}

/// The library's option names in its messages, and the command line's flag for each.
const OPTION_FLAGS: [(&str, &str); 6] = [
    ("ImportOptions::with_edges", "--edges"),
    ("accept_head_collisions", "--accept-head-collisions"),
    ("tilt_tolerance_deg", "--tilt-tolerance (degrees)"),
    ("cut_clearance_mm", "--cut-clearance"),
    ("the run's kerf_width_mm", "--kerf-width"),
    ("the run's feed_mm_per_min", "--feed"),
];

/// A library message (an error, a warning) with the command line's flags for the options it
/// names (the library names its options, `JobOptions::tilt_tolerance_deg`; a process engineer
/// types `--tilt-tolerance`).
pub(crate) fn with_flags(message: String) -> String {
    let flags: Vec<&str> = OPTION_FLAGS
        .iter()
        .filter(|(option, _)| message.contains(option))
        .map(|(_, flag)| *flag)
        .collect();
    match flags.as_slice() {
        [] => message,
        [one] => format!("{message} [option: {one}]"),
        more => format!("{message} [options: {}]", more.join(", ")),
    }
}

/// The command-line options that change the outcome of an error (the library's messages name
/// its options, the command line's flags are named here).
fn hint(e: &kerf_pipeline::Error) -> Option<&'static str> {
    use kerf_discretize::DiscretizeError as E;
    use kerf_pipeline::Error as P;
    let discretize = |source: &E| {
        match source {
        E::TooManyPoints { .. } => {
            Some("options: a larger --tolerance, or a larger point limit (--max-points of kerf discretize, --max-total-points of kerf run)")
        }
        E::ToleranceBelowPrecision { .. } => Some("option: a larger --tolerance"),
        E::TurnUnreachable { .. } => Some("option: a larger --max-turn (degrees)"),
        _ => None,
    }
    };
    match e {
        P::Discretize { source, .. } => discretize(source),
        P::Normals { source, .. } => match source {
            kerf_normals::NormalsError::TooManyInserted { .. } => {
                Some("option: a larger --max-normal-step (degrees)")
            }
            kerf_normals::NormalsError::Discretize(d) => discretize(d),
            _ => None,
        },
        P::TooManyPoints { .. } => Some(
            "options: a larger --tolerance, or a larger point limit (--max-total-points of kerf run)",
        ),
        P::NoNormals { .. } => {
            Some("run kerf discretize --normals on curves that name their surface")
        }
        _ => None,
    }
}

impl From<kerf_pipeline::Error> for CliError {
    fn from(e: kerf_pipeline::Error) -> Self {
        CliError::Pipeline(e)
    }
}

impl From<FormatError> for CliError {
    fn from(e: FormatError) -> Self {
        CliError::Pipeline(e.into())
    }
}

impl From<io::Error> for CliError {
    fn from(e: io::Error) -> Self {
        CliError::Output(e)
    }
}

impl From<kerf_kinematics::KinematicsError> for CliError {
    fn from(e: kerf_kinematics::KinematicsError) -> Self {
        CliError::Pipeline(e.into())
    }
}

impl From<kerf_check::CheckError> for CliError {
    fn from(e: kerf_check::CheckError) -> Self {
        CliError::Check(e)
    }
}
