//! A lenient reader of `kerf.toolpath/1`.
//!
//! [`kerf_format::toolpath::load`] refuses a file at its first defect, which is right for the
//! pipeline but not for a checker: a file from another tool whose params run backwards should
//! come back with every defect listed. This reader only insists on the shape of the document
//! (an object with `format: "kerf.toolpath/1"`, a numeric `tolerance`, `paths` of objects with
//! a string `id`, numeric `params`, `points` as arrays of numbers); every rule about the
//! values is left to [`crate::check()`]. Unknown keys are ignored (the format may grow).

use std::path::Path;

use kerf_format::{ToolpathFile, ToolpathPoints, TOOLPATH_FORMAT};
use kerf_io::{JsonProblem, ShapeError};
use serde::Deserialize;
use serde_json::Value;

use crate::error::{CheckError, Result};

/// A toolpath document as written, before any rule about its values is checked.
#[derive(Debug, Clone, PartialEq)]
pub struct RawToolpath {
    /// The `units` value, if present (the format requires `"mm"`).
    pub units: Option<String>,
    /// The chord tolerance the file claims, in mm.
    pub tolerance: f64,
    /// The paths, in file order.
    pub paths: Vec<RawPathRecord>,
}

/// One path of a [`RawToolpath`], as written.
#[derive(Debug, Clone, PartialEq)]
pub struct RawPathRecord {
    /// The id of the curve the path claims to discretize.
    pub id: String,
    /// The curve parameter of each point.
    pub params: Vec<f64>,
    /// Each point as written: 3 numbers, or 6 with the normal.
    pub points: Vec<Vec<f64>>,
    /// The `max_chord_error` the file claims, if present.
    pub claimed_chord_error: Option<f64>,
    /// The optional `point_count` the file claims (kerf's writer adds it), if present.
    pub point_count: Option<usize>,
    /// The optional `kerf_offset`: the path offset by half the kerf (`kerf run` with a kerf
    /// width), measured against the exact offset by [`crate::check()`].
    pub kerf_offset: Option<kerf_format::KerfOffset>,
}

#[derive(Deserialize)]
struct RawFile {
    #[serde(default)]
    units: Option<String>,
    tolerance: f64,
    paths: Vec<RawPath>,
}

#[derive(Deserialize)]
struct RawPath {
    id: String,
    params: Vec<f64>,
    points: Vec<Vec<f64>>,
    #[serde(default)]
    max_chord_error: Option<f64>,
    #[serde(default)]
    point_count: Option<usize>,
    #[serde(default)]
    kerf_offset: Option<kerf_format::KerfOffset>,
}

impl RawToolpath {
    /// Reads a toolpath file leniently (see the module documentation).
    ///
    /// # Errors
    /// [`CheckError::Read`] if the file cannot be read, else any error of
    /// [`RawToolpath::from_slice`], wrapped in [`CheckError::File`].
    pub fn load(path: impl AsRef<Path>) -> Result<RawToolpath> {
        let path = path.as_ref();
        let bytes = kerf_io::read_file(path).map_err(|error| CheckError::Read {
            path: path.to_path_buf(),
            error,
        })?;
        RawToolpath::from_slice(&bytes).map_err(|e| e.in_file(path))
    }

    /// Reads a toolpath document held in memory leniently.
    ///
    /// # Errors
    /// [`CheckError::Syntax`] for text that is not JSON, [`CheckError::Format`] if `format` is
    /// not `kerf.toolpath/1`, [`CheckError::Shape`] naming the JSON path of a value of the
    /// wrong type or a missing key.
    pub fn from_slice(bytes: &[u8]) -> Result<RawToolpath> {
        // The shared front end: BOM skipped, a key given twice refused (a checker must not
        // read a different document than the pipeline did).
        let value: Value = kerf_io::parse_json(bytes).map_err(|e| match JsonProblem::from(e) {
            JsonProblem::Syntax {
                line,
                column,
                message,
            } => CheckError::Syntax {
                line,
                column,
                message,
            },
            JsonProblem::Shape(ShapeError { path, message }) => CheckError::Shape { path, message },
        })?;
        match value.get("format") {
            Some(Value::String(s)) if s == TOOLPATH_FORMAT => {}
            other => {
                return Err(CheckError::Format {
                    found: other.map(Value::to_string),
                })
            }
        }
        let raw: RawFile = kerf_io::deserialize_at(value, "")
            .map_err(|ShapeError { path, message }| CheckError::Shape { path, message })?;
        Ok(RawToolpath {
            units: raw.units,
            tolerance: raw.tolerance,
            paths: raw
                .paths
                .into_iter()
                .map(|p| RawPathRecord {
                    id: p.id,
                    params: p.params,
                    points: p.points,
                    claimed_chord_error: p.max_chord_error,
                    point_count: p.point_count,
                    kerf_offset: p.kerf_offset,
                })
                .collect(),
        })
    }
}

impl From<&ToolpathFile> for RawToolpath {
    fn from(file: &ToolpathFile) -> Self {
        RawToolpath {
            units: Some(file.units.name().to_owned()),
            tolerance: file.tolerance,
            paths: file
                .paths
                .iter()
                .map(|p| RawPathRecord {
                    id: p.id.clone(),
                    params: p.params.clone(),
                    points: match &p.points {
                        ToolpathPoints::Positions(v) => v.iter().map(|q| q.to_vec()).collect(),
                        ToolpathPoints::Poses(v) => v.iter().map(|q| q.to_vec()).collect(),
                    },
                    claimed_chord_error: Some(p.max_chord_error),
                    point_count: None,
                    kerf_offset: p.kerf_offset.clone(),
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_what_kerf_format_would_refuse() {
        let text = r#"{"format": "kerf.toolpath/1", "units": "mm", "tolerance": 0.1,
            "paths": [{"id": "a", "params": [1, 0], "points": [[0,0,0],[1,0,0,0]],
                       "max_chord_error": 5, "extra": true}]}"#;
        let tp = RawToolpath::from_slice(text.as_bytes()).unwrap();
        assert_eq!(tp.paths[0].params, vec![1.0, 0.0], "reversed params kept");
        assert_eq!(tp.paths[0].points[1].len(), 4, "odd point length kept");
        assert_eq!(tp.paths[0].claimed_chord_error, Some(5.0), "claim kept");
    }

    #[test]
    fn errors_name_the_json_path() {
        let bad = r#"{"format": "kerf.toolpath/1", "tolerance": 0.1,
            "paths": [{"id": "a", "params": [0, "x"], "points": []}]}"#;
        let e = RawToolpath::from_slice(bad.as_bytes())
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("paths[0].params[1]: invalid type: string"),
            "{e}"
        );
        let missing = r#"{"format": "kerf.toolpath/1", "paths": []}"#;
        let e = RawToolpath::from_slice(missing.as_bytes())
            .unwrap_err()
            .to_string();
        assert_eq!(e, "tolerance: required key is missing", "{e}");
        let curves = r#"{"format": "kerf.curves/1", "curves": []}"#;
        let e = RawToolpath::from_slice(curves.as_bytes())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("expected \"kerf.toolpath/1\", found \"kerf.curves/1\""),
            "{e}"
        );
        let e = RawToolpath::from_slice(b"{").unwrap_err().to_string();
        assert!(e.starts_with("invalid JSON at line 1"), "{e}");
        let e = RawToolpath::load("/nonexistent/x.json")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/x.json: cannot read"), "{e}");
    }
}
