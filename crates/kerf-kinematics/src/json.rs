//! The reading front end of the machine and axes files: [`kerf_io`]'s bounded read and JSON
//! parser (byte-order mark skipped, duplicate keys refused) with kerf-kinematics' errors.

use std::path::Path;

use kerf_io::{JsonProblem, ShapeError};
use serde_json::Value;

use crate::error::{KinematicsError, Result};

/// Parses JSON bytes into a value (kerf-io's front end, its problems as kerf-kinematics'
/// errors).
pub(crate) fn parse(bytes: &[u8]) -> Result<Value> {
    kerf_io::parse_json(bytes).map_err(|e| match JsonProblem::from(e) {
        JsonProblem::Syntax {
            line,
            column,
            message,
        } => KinematicsError::Syntax {
            line,
            column,
            message,
        },
        JsonProblem::Shape(ShapeError { path, message }) => KinematicsError::doc(path, message),
    })
}

/// Reads the document at `path` (at most [`kerf_io::MAX_INPUT_BYTES`]) with `parse`: an
/// unreadable file is [`KinematicsError::Io`], a parse error comes back wrapped in
/// [`KinematicsError::File`] so that its message names the file.
pub(crate) fn read_with<T>(path: &Path, parse: impl FnOnce(&[u8]) -> Result<T>) -> Result<T> {
    let bytes = kerf_io::read_file(path).map_err(|e| KinematicsError::Io {
        file: path.display().to_string(),
        action: "read",
        source: e.into(),
    })?;
    parse(&bytes).map_err(|error| KinematicsError::File {
        file: path.display().to_string(),
        error: Box::new(error),
    })
}

/// The number at `map[key]`, `None` when the key is absent.
///
/// # Errors
/// [`KinematicsError::Document`] at `{path}.{key}` for a value that is not a number.
pub(crate) fn optional_number(
    map: &serde_json::Map<String, Value>,
    path: &str,
    key: &str,
) -> Result<Option<f64>> {
    match map.get(key) {
        None => Ok(None),
        Some(v) => v.as_f64().map(Some).ok_or_else(|| {
            KinematicsError::doc(
                format!("{path}.{key}"),
                format!("expected a number, found {}", kerf_io::json_type_name(v)),
            )
        }),
    }
}

/// Checks that a text that may reach a program is one printable line.
pub(crate) fn check_text(path: &str, text: &str) -> Result<()> {
    kerf_io::check_text(text).map_err(|defect| KinematicsError::doc(path, defect.to_string()))
}

/// The top-level object of a document that must be of `format` (`{"format": FORMAT, ...}`).
///
/// # Errors
/// [`KinematicsError::Document`] at `top level` for another JSON value, at `format` for
/// another or a missing format.
pub(crate) fn top_object<'a>(
    value: &'a Value,
    format: &str,
) -> Result<&'a serde_json::Map<String, Value>> {
    let Value::Object(top) = value else {
        return Err(KinematicsError::doc(
            "top level",
            format!(
                "expected an object {{\"format\": \"{format}\", ...}}, found {}",
                kerf_io::json_type_name(value)
            ),
        ));
    };
    match top.get("format") {
        Some(Value::String(s)) if s == format => Ok(top),
        Some(other) => Err(KinematicsError::doc(
            "format",
            format!("unknown format {other} (this reader reads \"{format}\")"),
        )),
        None => Err(KinematicsError::doc(
            "format",
            format!("missing (expected \"{format}\")"),
        )),
    }
}
