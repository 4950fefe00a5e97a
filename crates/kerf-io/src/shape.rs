//! The second half of the JSON front end: a parsed [`Value`] read into typed structs, with the
//! JSON path and a message in the words of the format (not of Rust) for every value of the
//! wrong shape; and the one wording of the parser's errors that are about a place in the
//! document (an empty file, a key given twice).

use std::fmt;

use serde::de::DeserializeOwned;
use serde_json::Value;

use crate::JsonError;

/// A value that does not have the shape its reader expects, or a place in the document that
/// is wrong as JSON (an empty file, a key given twice).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShapeError {
    /// The JSON path of the value (`curves[0].knots`), `top level` for the document itself.
    pub path: String,
    /// What is wrong, e.g. `invalid type: string "a", expected a number` or
    /// `required key is missing`.
    pub message: String,
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

impl std::error::Error for ShapeError {}

/// A [`JsonError`] sorted for a reader's error type: a syntax error keeps its line and column
/// (the JSON path, when known, appended to the message as `(in curves[0].knots[3])`); an empty
/// file and a key given twice become a [`ShapeError`] with kerf's one wording of them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JsonProblem {
    /// Not well-formed JSON.
    Syntax {
        /// Line, from 1.
        line: usize,
        /// Column (byte in the line), from 1.
        column: usize,
        /// What the parser found wrong, with the JSON path when known.
        message: String,
    },
    /// An empty document or a key given twice.
    Shape(ShapeError),
}

impl From<JsonError> for JsonProblem {
    fn from(e: JsonError) -> Self {
        match e {
            JsonError::Empty => JsonProblem::Shape(ShapeError {
                path: "top level".to_owned(),
                message: "the file is empty".to_owned(),
            }),
            JsonError::Syntax {
                line,
                column,
                path,
                message,
            } => JsonProblem::Syntax {
                line,
                column,
                message: if path.is_empty() {
                    message
                } else {
                    format!("{message} (in {path})")
                },
            },
            JsonError::DuplicateKey { path, line } => JsonProblem::Shape(ShapeError {
                path,
                message: duplicate_key_message(line),
            }),
        }
    }
}

/// The message for a key given twice in one object, second occurrence on `line`.
pub fn duplicate_key_message(line: usize) -> String {
    format!(
        "key given twice in one object (line {line}); readers disagree on which one counts, \
         so remove one of them"
    )
}

/// Reads `value` into `T`. Errors carry the JSON path, starting with `prefix` (the path of
/// `value` itself in the document, empty for the top level): a missing key is reported at
/// its own path (`curves[0].knots: required key is missing`), and serde's Rust words
/// (`f64`, `sequence`, `map`) are replaced by the format's (a number, an array, an object).
///
/// # Errors
/// A [`ShapeError`] for the first value of the wrong type or length, or a missing key.
pub fn deserialize_at<T: DeserializeOwned>(value: Value, prefix: &str) -> Result<T, ShapeError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let inner = e.path().to_string();
        let mut path = if inner == "." {
            prefix.to_owned()
        } else if prefix.is_empty() {
            inner
        } else if inner.starts_with('[') {
            format!("{prefix}{inner}")
        } else {
            format!("{prefix}.{inner}")
        };
        let mut message = tidy_message(&e.into_inner().to_string());
        // "curves[0]: missing field `knots`" reads better as "curves[0].knots: missing".
        if let Some(field) = message
            .strip_prefix("missing field `")
            .and_then(|rest| rest.strip_suffix('`'))
        {
            path = if path.is_empty() {
                field.to_owned()
            } else {
                format!("{path}.{field}")
            };
            message = "required key is missing".to_owned();
        }
        if path.is_empty() {
            path = "top level".to_owned();
        }
        ShapeError { path, message }
    })
}

/// Replaces Rust type names in serde's messages with words a user of the format knows.
fn tidy_message(message: &str) -> String {
    message
        .replace("expected usize", "expected a non-negative integer")
        .replace("expected u32", "expected a non-negative integer")
        .replace("expected f64", "expected a number")
        .replace("a sequence", "an array")
        .replace("invalid type: map", "invalid type: object")
        .replace("invalid type: sequence", "invalid type: array")
}
