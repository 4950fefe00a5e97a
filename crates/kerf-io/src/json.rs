//! JSON text to a [`serde_json::Value`], refusing duplicate keys, with the JSON path of every
//! error.

use std::cell::RefCell;
use std::fmt;

use serde::de::{self, DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::{Map, Number, Value};

use crate::read::strip_bom;

/// What a JSON value is, as an error message names it: `null`, `a boolean`, `a number`, `a
/// string`, `an array`, `an object` ("expected an object, found an array").
pub fn json_type_name(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// What can be wrong with JSON text, before any format-specific check.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum JsonError {
    /// The text is empty or only white space (after a byte-order mark).
    Empty,
    /// Not well-formed JSON (or a number beyond the range of a double, such as `1e400`).
    Syntax {
        /// Line, from 1.
        line: usize,
        /// Column (byte in the line), from 1.
        column: usize,
        /// JSON path of the value being read (`curves[0].knots[3]`), empty at the top level.
        path: String,
        /// What the parser found wrong.
        message: String,
    },
    /// A key appears twice in one object. JSON leaves the meaning open and readers differ
    /// (most keep the last, some the first), so a file that means two things is refused.
    DuplicateKey {
        /// JSON path of the second occurrence, e.g. `curves[0].id`.
        path: String,
        /// Line of the second occurrence, from 1.
        line: usize,
    },
}

impl fmt::Display for JsonError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            JsonError::Empty => write!(f, "the file is empty"),
            JsonError::Syntax {
                line,
                column,
                path,
                message,
            } => {
                if !path.is_empty() {
                    write!(f, "{path}: ")?;
                }
                write!(f, "invalid JSON at line {line}, column {column}: {message}")
            }
            JsonError::DuplicateKey { path, line } => write!(
                f,
                "{path}: key given twice in one object (line {line}); remove one of them"
            ),
        }
    }
}

impl std::error::Error for JsonError {}

/// Parses JSON `bytes` (a leading byte-order mark skipped) into a [`Value`].
///
/// Unlike `serde_json::from_slice::<Value>`, which silently keeps the last of two equal keys,
/// a key given twice in one object is an error naming its JSON path. The nesting depth is
/// limited by serde_json (128 levels), so hostile input cannot overflow the stack.
///
/// # Errors
/// [`JsonError::Empty`], [`JsonError::Syntax`] (with the JSON path from [`path_at`]) or
/// [`JsonError::DuplicateKey`].
pub fn parse_json(bytes: &[u8]) -> Result<Value, JsonError> {
    let bytes = strip_bom(bytes);
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(JsonError::Empty);
    }
    let duplicate = RefCell::new(None);
    let mut de = serde_json::Deserializer::from_slice(bytes);
    let result = Seed {
        at: Seg::Root,
        duplicate: &duplicate,
    }
    .deserialize(&mut de)
    .and_then(|v| de.end().map(|()| v));
    match result {
        Ok(v) => Ok(v),
        Err(e) => {
            if let Some(path) = duplicate.into_inner() {
                return Err(JsonError::DuplicateKey {
                    path,
                    line: e.line(),
                });
            }
            let (line, column) = (e.line(), e.column());
            let full = e.to_string();
            let suffix = format!(" at line {line} column {column}");
            let message = full.strip_suffix(&suffix).unwrap_or(&full);
            let message = if message == "number out of range" {
                "number out of range (a number must fit in a double: |x| < 1.8e308)".to_owned()
            } else {
                message.to_owned()
            };
            Err(JsonError::Syntax {
                line,
                column,
                path: path_at(bytes, offset_of(bytes, line, column)),
                message,
            })
        }
    }
}

/// A [`Value`] read like [`parse_json`] reads one: a key given twice in one object is an error
/// (here a plain deserialization error, without the path: a reader that wants the path reads
/// the document again with [`parse_json`]). For typed readers that keep part of a document as
/// JSON values in one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct StrictValue(pub Value);

impl<'de> Deserialize<'de> for StrictValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let duplicate = RefCell::new(None);
        Seed {
            at: Seg::Root,
            duplicate: &duplicate,
        }
        .deserialize(d)
        .map(StrictValue)
    }
}

/// One step of the JSON path of the value being built; rendered only for an error.
#[derive(Clone, Copy)]
enum Seg<'a> {
    Root,
    Key(&'a Seg<'a>, &'a str),
    Index(&'a Seg<'a>, usize),
}

impl Seg<'_> {
    fn render(&self) -> String {
        match self {
            Seg::Root => String::new(),
            Seg::Key(parent, key) => {
                let p = parent.render();
                if p.is_empty() {
                    (*key).to_owned()
                } else {
                    format!("{p}.{key}")
                }
            }
            Seg::Index(parent, i) => format!("{}[{i}]", parent.render()),
        }
    }
}

/// Builds a [`Value`] like serde_json's own visitor, but refuses a repeated key.
struct Seed<'a> {
    at: Seg<'a>,
    duplicate: &'a RefCell<Option<String>>,
}

impl<'de> DeserializeSeed<'de> for Seed<'_> {
    type Value = Value;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for Seed<'_> {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::Number(v.into()))
    }

    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        // JSON text cannot spell NaN or infinity, so this is always Some.
        Ok(Number::from_f64(v).map_or(Value::Null, Value::Number))
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_owned()))
    }

    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(4096));
        loop {
            let at = Seg::Index(&self.at, out.len());
            match seq.next_element_seed(Seed {
                at,
                duplicate: self.duplicate,
            })? {
                Some(v) => out.push(v),
                None => return Ok(Value::Array(out)),
            }
        }
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                *self.duplicate.borrow_mut() = Some(Seg::Key(&self.at, &key).render());
                return Err(de::Error::custom("duplicate key"));
            }
            let value = map.next_value_seed(Seed {
                at: Seg::Key(&self.at, &key),
                duplicate: self.duplicate,
            })?;
            out.insert(key, value);
        }
        Ok(Value::Object(out))
    }
}

/// The byte offset of serde_json's 1-based `line` and `column` (the column counts bytes; the
/// offending byte itself is excluded).
fn offset_of(bytes: &[u8], line: usize, column: usize) -> usize {
    let mut start = 0;
    for _ in 1..line {
        match bytes[start..].iter().position(|&b| b == b'\n') {
            Some(n) => start += n + 1,
            None => return bytes.len(),
        }
    }
    (start + column.saturating_sub(1)).min(bytes.len())
}

/// The JSON path of the value being read at byte `offset` of `bytes`, e.g.
/// `curves[0].knots[3]`, or an empty string at the top level.
///
/// Scans the (well-formed, since the parser got that far) text before `offset`, keeping a stack
/// of the open arrays with their current index and the open objects with their current key.
pub fn path_at(bytes: &[u8], offset: usize) -> String {
    enum Frame {
        Array(usize),
        Object(Option<String>),
    }
    let end = offset.min(bytes.len());
    let mut stack: Vec<Frame> = Vec::new();
    let mut i = 0;
    while i < end {
        match bytes[i] {
            b'{' => stack.push(Frame::Object(None)),
            b'[' => stack.push(Frame::Array(0)),
            b'}' | b']' => {
                stack.pop();
            }
            b',' => match stack.last_mut() {
                Some(Frame::Array(n)) => *n += 1,
                Some(Frame::Object(key)) => *key = None,
                None => {}
            },
            b'"' => {
                let start = i;
                i += 1;
                while i < end && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                if i >= end {
                    break;
                }
                if let Some(Frame::Object(key @ None)) = stack.last_mut() {
                    let raw = &bytes[start..=i];
                    *key = Some(
                        serde_json::from_slice::<String>(raw)
                            .unwrap_or_else(|_| String::from_utf8_lossy(raw).into_owned()),
                    );
                }
            }
            _ => {}
        }
        i += 1;
    }
    let mut path = String::new();
    for frame in &stack {
        match frame {
            Frame::Array(n) => path.push_str(&format!("[{n}]")),
            Frame::Object(Some(key)) => {
                if !path.is_empty() {
                    path.push('.');
                }
                path.push_str(key);
            }
            Frame::Object(None) => break,
        }
    }
    path
}

#[cfg(test)]
mod tests {
    use super::*;

    fn syntax_path(text: &str) -> String {
        match parse_json(text.as_bytes()) {
            Err(JsonError::Syntax { path, .. }) => path,
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    #[test]
    fn same_value_as_serde_json() {
        let text = r#"{"a": [1, -2, 3.5, 1e300, 18446744073709551615, true, null, "x\n"],
                       "b": {"c": {}}, "d": []}"#;
        let ours = parse_json(text.as_bytes()).expect("valid");
        let theirs: Value = serde_json::from_str(text).expect("valid");
        assert_eq!(ours, theirs, "identical values");
    }

    #[test]
    fn duplicate_keys_are_refused_with_their_path() {
        let e = parse_json(b"{\"curves\": [{\"id\": \"a\"}, {\"id\": \"b\",\n \"id\": \"c\"}]}")
            .expect_err("duplicate");
        assert_eq!(
            e,
            JsonError::DuplicateKey {
                path: "curves[1].id".to_owned(),
                line: 2
            },
            "second occurrence"
        );
        assert!(e.to_string().contains("given twice"), "{e}");
        let e = parse_json(b"{\"format\": 1, \"format\": 1}").expect_err("top level");
        assert!(
            matches!(&e, JsonError::DuplicateKey { path, .. } if path == "format"),
            "{e:?}"
        );
        // Equal keys in different objects are fine.
        parse_json(b"{\"a\": {\"id\": 1}, \"b\": {\"id\": 1}}").expect("distinct objects");
        // Escapes are decoded before comparing: "\u0061" is "a".
        assert!(
            parse_json(b"{\"a\": 1, \"\\u0061\": 2}").is_err(),
            "escaped duplicate"
        );
    }

    #[test]
    fn syntax_errors_name_the_value_being_read() {
        assert_eq!(
            syntax_path("{\"curves\": [{\"knots\": [0, 1e400]}]}"),
            "curves[0].knots[1]",
            "number out of range"
        );
        assert_eq!(
            syntax_path("{\"a\": {\"b\\\"c\": [1, 2 3]}}"),
            "a.b\"c[1]",
            "escaped key, missing comma"
        );
        assert_eq!(
            syntax_path("{\"a\": 1,}"),
            "",
            "trailing comma at top level"
        );
        assert_eq!(
            syntax_path("{\"curves\": [[1, 2],\n [3, 4"),
            "curves[1][1]",
            "end of file inside an array"
        );
        assert!(
            matches!(parse_json(b"{} {}"), Err(JsonError::Syntax { .. })),
            "trailing characters"
        );
    }

    #[test]
    fn bom_and_empty() {
        assert_eq!(
            parse_json(b"\xEF\xBB\xBF{\"a\": 1}").expect("BOM skipped"),
            serde_json::json!({"a": 1}),
            "BOM"
        );
        assert_eq!(parse_json(b" \n\t"), Err(JsonError::Empty), "white space");
        assert_eq!(
            parse_json(b"\xEF\xBB\xBF"),
            Err(JsonError::Empty),
            "only a BOM"
        );
    }

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let text = "[".repeat(100_000);
        assert!(
            matches!(parse_json(text.as_bytes()), Err(JsonError::Syntax { .. })),
            "recursion limit"
        );
    }
}
