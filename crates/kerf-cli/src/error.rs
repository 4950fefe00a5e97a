//! The errors a command can end with; `main` prints them as `error: <message>`.

use std::fmt;
use std::io;

use kerf_format::FormatError;

/// Why a command failed.
#[derive(Debug)]
pub(crate) enum CliError {
    /// An input file is unreadable or invalid; the message starts with the file's path.
    Format(FormatError),
    /// Writing to standard output failed.
    Output(io::Error),
    /// The machine file is invalid, or a path cannot be solved on the machine. The optional
    /// path names the toolpath file the path came from.
    Kinematics(
        Box<kerf_kinematics::KinematicsError>,
        Option<std::path::PathBuf>,
    ),
    /// An input is unusable for this command (the message names file and place).
    Input(String),
    /// The command line asks for something that cannot be done (an output that is also an
    /// input); exit status 2 like clap's own usage errors.
    Usage(String),
    /// A command-line option is out of range.
    Options(kerf_discretize::DiscretizeError),
    /// A curve's normals could not be found (off its surface, reversed orientation, ...), or
    /// a surface cannot give normals.
    Normals {
        /// The input file.
        file: std::path::PathBuf,
        /// Where: `curves[3] ("id")` or `surfaces[1] ("id")`.
        place: String,
        /// What went wrong.
        error: kerf_normals::NormalsError,
    },
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
    /// A curve could not be discretized.
    Discretize {
        /// The input file.
        file: std::path::PathBuf,
        /// Index of the curve in `curves`.
        index: usize,
        /// Its id.
        id: String,
        /// What went wrong.
        error: kerf_discretize::DiscretizeError,
    },
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Format(e) => write!(f, "{e}"),
            CliError::Output(e) => write!(f, "cannot write to standard output: {e}"),
            CliError::Options(e) => write!(f, "{e}"),
            CliError::Normals { file, place, error } => {
                write!(f, "{}: {place}: {error}", file.display())
            }
            CliError::Kinematics(e, Some(file)) => write!(f, "{}: {e}", file.display()),
            CliError::Kinematics(e, None) => write!(f, "{e}"),
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
            CliError::Discretize {
                file,
                index,
                id,
                error,
            } => {
                write!(f, "{}: curves[{index}] ({id:?}): {error}", file.display())?;
                if let Some(hint) = discretize_hint(error) {
                    write!(f, " [{hint}]")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for CliError {}

/// The command-line options that change the outcome of a discretizer error.
fn discretize_hint(e: &kerf_discretize::DiscretizeError) -> Option<&'static str> {
    use kerf_discretize::DiscretizeError as E;
    match e {
        E::TooManyPoints { .. } => Some("options: a larger --tolerance, or --max-points"),
        E::ToleranceBelowPrecision { .. } => Some("option: a larger --tolerance"),
        _ => None,
    }
}

impl From<FormatError> for CliError {
    fn from(e: FormatError) -> Self {
        CliError::Format(e)
    }
}

impl From<io::Error> for CliError {
    fn from(e: io::Error) -> Self {
        CliError::Output(e)
    }
}

impl From<kerf_kinematics::KinematicsError> for CliError {
    fn from(e: kerf_kinematics::KinematicsError) -> Self {
        CliError::Kinematics(Box::new(e), None)
    }
}

impl From<kerf_check::CheckError> for CliError {
    fn from(e: kerf_check::CheckError) -> Self {
        CliError::Check(e)
    }
}
