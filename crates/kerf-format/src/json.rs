//! The JSON layer shared by the readers: bytes to a checked top-level object, and serde
//! deserialization that reports the JSON path of every error.
//!
//! Reading goes in three steps so that the most useful message wins:
//! 1. parse the text into a [`serde_json::Value`]; a syntax error gets its line, column and the
//!    JSON path of the value being read ([`path_at`]), so that even `1e400` (a number out of
//!    the range of a double, which serde_json rejects rather than turning into infinity) is
//!    reported as `curves[0].knots[3]: invalid JSON at line 5, column 31: number out of range`;
//! 2. check `format` and `units` before anything else, so that a toolpath handed to the curves
//!    reader says so instead of complaining about a missing `curves` key;
//! 3. deserialize the typed structs through [`kerf_io::deserialize_at`], so that a control point with
//!    two coordinates is reported as `curves[0].control_points[2]: invalid length 2, ...`.
//!
//! Step 1 is [`kerf_io::parse_json`], the front end every kerf reader shares: a byte-order mark
//! is skipped, a key given twice in one object is refused with its JSON path, and inputs are
//! read up to [`kerf_io::MAX_INPUT_BYTES`].

use std::io::Read;
use std::path::Path;

use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use kerf_io::JsonError;

use crate::error::{FormatError, Result};
use crate::Units;
use kerf_io::json_type_name;

/// Reads a whole file, at most [`kerf_io::MAX_INPUT_BYTES`].
pub(crate) fn read_file(path: &Path) -> Result<Vec<u8>> {
    kerf_io::read_file(path).map_err(|error| FormatError::Read { error })
}

/// Reads a whole reader, at most [`kerf_io::MAX_INPUT_BYTES`].
pub(crate) fn read_all(reader: impl Read) -> Result<Vec<u8>> {
    kerf_io::read_to_end(reader, kerf_io::MAX_INPUT_BYTES)
        .map_err(|error| FormatError::Read { error })
}

/// Parses `bytes` as a JSON object whose `format` is `expected` and whose `units` are `"mm"`.
pub(crate) fn parse_document(bytes: &[u8], expected: &'static str) -> Result<Map<String, Value>> {
    let value = kerf_io::parse_json(bytes).map_err(|e| match e {
        JsonError::Empty => FormatError::Empty { expected },
        JsonError::Syntax {
            line,
            column,
            path,
            message,
        } => FormatError::Syntax {
            line,
            column,
            path,
            message,
        },
        JsonError::DuplicateKey { path, line } => FormatError::Shape {
            path,
            message: kerf_io::duplicate_key_message(line),
        },
    })?;
    let Value::Object(map) = value else {
        return Err(FormatError::NotAnObject {
            expected,
            found: json_type_name(&value),
        });
    };
    check_format(map.get("format"), expected)?;
    check_units(map.get("units"))?;
    Ok(map)
}

/// Checks the `format` value.
fn check_format(value: Option<&Value>, expected: &'static str) -> Result<()> {
    match value {
        Some(Value::String(s)) if s == expected => Ok(()),
        other => Err(FormatError::UnsupportedFormat {
            found: other.map(Value::to_string),
            expected,
        }),
    }
}

/// Checks the `units` value.
fn check_units(value: Option<&Value>) -> Result<Units> {
    match value {
        Some(Value::String(s)) if Units::from_name(s).is_some() => Ok(Units::Millimetres),
        other => Err(FormatError::UnsupportedUnits {
            found: other.map(Value::to_string),
        }),
    }
}

/// Checks `format` and `units` given as strings (for documents built in memory).
pub(crate) fn check_header(format: &str, units: &str, expected: &'static str) -> Result<Units> {
    check_format(Some(&Value::String(format.to_owned())), expected)?;
    check_units(Some(&Value::String(units.to_owned())))
}

/// Deserializes `value` into `T`; errors carry the JSON path, starting with `prefix` (the path
/// of `value` itself in the document, empty for the top level): [`kerf_io::deserialize_at`].
pub(crate) fn deserialize<T: DeserializeOwned>(value: Value, prefix: &str) -> Result<T> {
    kerf_io::deserialize_at(value, prefix)
        .map_err(|kerf_io::ShapeError { path, message }| FormatError::Shape { path, message })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path_of_error(text: &str) -> String {
        match parse_document(text.as_bytes(), "kerf.curves/1") {
            Err(FormatError::Syntax { path, .. }) => path,
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    #[test]
    fn syntax_errors_name_the_value_being_read() {
        assert_eq!(
            path_of_error("{\"curves\": [{\"knots\": [0, 1e400]}]}"),
            "curves[0].knots[1]",
            "number out of range"
        );
        assert_eq!(
            path_of_error("{\"a\": {\"b\\\"c\": [1, 2 3]}}"),
            "a.b\"c[1]",
            "escaped key, missing comma"
        );
        assert_eq!(
            path_of_error("{\"curves\": [{}, {\"id\": \"x\",, }]}"),
            "curves[1]",
            "error at a key position names the object"
        );
        assert_eq!(
            path_of_error("{\"a\": 1,}"),
            "",
            "trailing comma at top level"
        );
        assert_eq!(
            path_of_error("{\"curves\": [[1, 2],\n [3, 4"),
            "curves[1][1]",
            "end of file inside an array"
        );
    }

    #[test]
    fn line_and_column_are_reported() {
        let err = parse_document(
            b"{\n  \"format\": \"kerf.curves/1\"\n  \"units\": \"mm\"\n}",
            "x",
        )
        .expect_err("missing comma");
        let FormatError::Syntax { line, column, .. } = err else {
            panic!("expected a syntax error, got {err:?}");
        };
        assert_eq!((line, column), (3, 3), "position of the unexpected key");
    }

    #[test]
    fn duplicate_keys_are_refused_with_their_path() {
        let e = parse_document(
            b"{\"format\": \"kerf.curves/1\", \"units\": \"mm\",\n \"curves\": [{\"id\": \"a\", \"id\": \"b\"}]}",
            "kerf.curves/1",
        )
        .expect_err("duplicate");
        assert_eq!(
            e.to_string(),
            "curves[0].id: key given twice in one object (line 2); readers disagree on which \
             one counts, so remove one of them",
            "path and line"
        );
    }

    #[test]
    fn byte_order_mark_is_skipped() {
        let map = parse_document(
            b"\xEF\xBB\xBF{\"format\": \"kerf.curves/1\", \"units\": \"mm\"}",
            "kerf.curves/1",
        )
        .expect("a BOM is tolerated");
        assert_eq!(map.len(), 2, "both keys read");
    }
}
