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
    /// A command-line option is out of range.
    Options(kerf_discretize::DiscretizeError),
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
            CliError::Kinematics(e, Some(file)) => write!(f, "{}: {e}", file.display()),
            CliError::Kinematics(e, None) => write!(f, "{e}"),
            CliError::Input(m) => write!(f, "{m}"),
            CliError::Discretize {
                file,
                index,
                id,
                error,
            } => write!(f, "{}: curves[{index}] ({id:?}): {error}", file.display()),
        }
    }
}

impl std::error::Error for CliError {}

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
