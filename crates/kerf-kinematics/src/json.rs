//! The reading front end of the machine and axes files: [`kerf_io`]'s bounded read and JSON
//! parser (byte-order mark skipped, duplicate keys refused) with kerf-kinematics' errors.

use std::path::Path;

use kerf_io::JsonError;
use serde_json::Value;

use crate::error::{KinematicsError, Result};

/// Parses JSON bytes into a value.
pub(crate) fn parse(bytes: &[u8]) -> Result<Value> {
    kerf_io::parse_json(bytes).map_err(|e| match e {
        JsonError::Empty => KinematicsError::doc("top level", "the file is empty"),
        JsonError::Syntax {
            line,
            column,
            path,
            message,
        } => KinematicsError::Syntax {
            line,
            column,
            message: if path.is_empty() {
                message
            } else {
                format!("{message} (in {path})")
            },
        },
        JsonError::DuplicateKey { path, line } => KinematicsError::doc(
            path,
            format!(
                "key given twice in one object (line {line}); readers disagree on which one \
                 counts, so remove one of them"
            ),
        ),
    })
}

/// Reads the file at `path` (at most [`kerf_io::MAX_INPUT_BYTES`]).
pub(crate) fn read(path: &Path) -> Result<Vec<u8>> {
    kerf_io::read_file(path).map_err(|e| KinematicsError::Io {
        file: path.display().to_string(),
        action: "read",
        message: e.to_string(),
    })
}

/// Checks that a text that may reach a program is one printable line.
pub(crate) fn check_text(path: &str, text: &str) -> Result<()> {
    kerf_io::check_text(text).map_err(|defect| KinematicsError::doc(path, defect.to_string()))
}
