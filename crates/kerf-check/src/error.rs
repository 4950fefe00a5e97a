//! Why a toolpath document could not be read at all.
//!
//! Everything the checker can still reason about (params out of order, points off the curve,
//! a chord error above the tolerance, ...) is a [`crate::Violation`], not an error: the point
//! of `kerf check` is to list every defect of a file, including files kerf itself would refuse
//! to read. A [`CheckError`] is left for documents with no usable structure.

use std::path::PathBuf;

/// A toolpath document that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum CheckError {
    /// The file could not be read. Fix: check the path and its permissions.
    #[error("{}: cannot read: {error}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        error: std::io::Error,
    },
    /// The text is not JSON. Fix the syntax at the given line and column.
    #[error("invalid JSON at line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// serde_json's description.
        message: String,
    },
    /// The document is not a `kerf.toolpath/1` document (missing or other `format`). Fix: pass
    /// a toolpath file, or convert the file to `kerf.toolpath/1`.
    #[error("format: expected \"kerf.toolpath/1\", found {}", found.as_deref().unwrap_or("(missing)"))]
    Format {
        /// The `format` value found, as JSON text, if any.
        found: Option<String>,
    },
    /// A value has the wrong JSON type or a required key is missing (`paths[0].params[3]:
    /// invalid type: string "x", expected a number`). Fix the value at that JSON path.
    #[error("{path}: {message}")]
    Shape {
        /// The JSON path of the value.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// An error of the other variants, in a named file.
    #[error("{}: {error}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// The error.
        #[source]
        error: Box<CheckError>,
    },
}

impl CheckError {
    /// The same error, prefixed with the file it came from.
    pub fn in_file(self, path: impl Into<PathBuf>) -> CheckError {
        match self {
            e @ (CheckError::Read { .. } | CheckError::File { .. }) => e,
            e => CheckError::File {
                path: path.into(),
                error: Box::new(e),
            },
        }
    }
}

/// `Result` with [`CheckError`].
pub type Result<T> = std::result::Result<T, CheckError>;
