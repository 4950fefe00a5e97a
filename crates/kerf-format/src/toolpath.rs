//! `kerf.toolpath/1`: the cutting points of each curve, written by the discretizer and read
//! back by the commands that check or use them.
//!
//! The writer checks the same rules as the reader before writing anything, so kerf never writes
//! a file it would refuse to read: params strictly increasing and finite, one point per param,
//! at least two points, points all `[x, y, z]` or all `[x, y, z, i, j, k]` with finite
//! coordinates and unit normals, `0 <= max_chord_error <= tolerance`, unique non-empty ids.
//!
//! Files are written atomically ([`write()`]): to a temporary file in the destination's
//! directory, renamed over the destination only once complete, so a failure never leaves a
//! half-written toolpath behind.
//!
//! ```
//! use kerf_format::toolpath::{self, ToolpathRecord, ToolpathPoints, ToolpathFile};
//!
//! let file = ToolpathFile {
//!     units: kerf_format::Units::Millimetres,
//!     tolerance: 0.01,
//!     paths: vec![ToolpathRecord {
//!         id: "line".into(),
//!         params: vec![0.0, 1.0],
//!         points: ToolpathPoints::Positions(vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]),
//!         max_chord_error: 0.0,
//!     }],
//! };
//! let text = toolpath::to_string(&file)?;
//! assert!(text.starts_with("{\n  \"format\": \"kerf.toolpath/1\""), "{text}");
//! assert_eq!(toolpath::from_str(&text)?, file);
//! # Ok::<(), kerf_format::FormatError>(())
//! ```

use std::io::{self, BufWriter, Read, Write};
use std::path::Path;

use nalgebra::{Point3, Vector3};
use serde::Deserialize;
use serde_json::Value;

use crate::curves::IdSet;
use crate::error::{FormatError, Result};
use crate::{json, Units, TOOLPATH_FORMAT};

/// How far from 1 the length of a normal may be: enough for normals written with 6 decimals.
pub const UNIT_NORMAL_TOLERANCE: f64 = 1e-6;

/// A `kerf.toolpath/1` document.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolpathFile {
    /// The length unit (always millimetres).
    pub units: Units,
    /// The chord tolerance the points were computed for, in mm; > 0.
    pub tolerance: f64,
    /// One path per input curve, same ids, same order.
    pub paths: Vec<ToolpathRecord>,
}

/// The cutting points of one curve.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolpathRecord {
    /// The id of the curve.
    pub id: String,
    /// `params[n]` is the curve parameter of point `n`; strictly increasing, first and last
    /// the ends of the curve's domain.
    pub params: Vec<f64>,
    /// The points, with or without normals.
    pub points: ToolpathPoints,
    /// The largest distance, over every segment, from the curve to the chord; <= the file's
    /// tolerance.
    pub max_chord_error: f64,
}

/// The points of a toolpath: all positions, or all positions with unit normals.
#[derive(Debug, Clone, PartialEq)]
pub enum ToolpathPoints {
    /// `[x, y, z]`.
    Positions(Vec<[f64; 3]>),
    /// `[x, y, z, i, j, k]`, `(i, j, k)` the unit normal (tool axis).
    Poses(Vec<[f64; 6]>),
}

impl ToolpathPoints {
    /// The number of points.
    pub fn len(&self) -> usize {
        match self {
            ToolpathPoints::Positions(p) => p.len(),
            ToolpathPoints::Poses(p) => p.len(),
        }
    }

    /// True if there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True if the points carry normals.
    pub fn has_normals(&self) -> bool {
        matches!(self, ToolpathPoints::Poses(_))
    }

    /// The position of point `n`.
    ///
    /// # Panics
    /// If `n >= self.len()`.
    pub fn position(&self, n: usize) -> Point3<f64> {
        match self {
            ToolpathPoints::Positions(p) => Point3::from(p[n]),
            ToolpathPoints::Poses(p) => Point3::new(p[n][0], p[n][1], p[n][2]),
        }
    }

    /// The normal of point `n`, if the points carry normals.
    ///
    /// # Panics
    /// If `n >= self.len()`.
    pub fn normal(&self, n: usize) -> Option<Vector3<f64>> {
        match self {
            ToolpathPoints::Positions(_) => None,
            ToolpathPoints::Poses(p) => Some(Vector3::new(p[n][3], p[n][4], p[n][5])),
        }
    }

    /// Each point as a slice of 3 or 6 numbers, as written in the file.
    pub fn iter(&self) -> Box<dyn Iterator<Item = &[f64]> + '_> {
        match self {
            ToolpathPoints::Positions(p) => Box::new(p.iter().map(|q| q.as_slice())),
            ToolpathPoints::Poses(p) => Box::new(p.iter().map(|q| q.as_slice())),
        }
    }
}

impl ToolpathFile {
    /// Checks every rule of the format (see the module documentation).
    ///
    /// # Errors
    /// [`FormatError::BadNumber`], [`FormatError::EmptyId`], [`FormatError::UnsafeText`],
    /// [`FormatError::DuplicateId`],
    /// [`FormatError::PathCount`], [`FormatError::ParamsNotIncreasing`],
    /// [`FormatError::NotUnitNormal`] or [`FormatError::ChordErrorAboveTolerance`].
    pub fn validate(&self) -> Result<()> {
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return Err(FormatError::BadNumber {
                path: "tolerance".into(),
                requirement: "finite and > 0",
                value: self.tolerance,
            });
        }
        let mut ids = IdSet::default();
        for (index, path) in self.paths.iter().enumerate() {
            ids.insert("paths", index, &path.id)?;
            validate_path(index, path, self.tolerance)?;
        }
        Ok(())
    }
}

fn validate_path(index: usize, path: &ToolpathRecord, tolerance: f64) -> Result<()> {
    let (n, m) = (path.points.len(), path.params.len());
    if n != m {
        return Err(FormatError::PathCount {
            index,
            problem: format!("{n} points but {m} params (one param per point)"),
        });
    }
    if n < 2 {
        return Err(FormatError::PathCount {
            index,
            problem: format!("{n} points; a path has at least 2 (the ends of the domain)"),
        });
    }
    for (i, &t) in path.params.iter().enumerate() {
        if !t.is_finite() {
            return Err(FormatError::BadNumber {
                path: format!("paths[{index}].params[{i}]"),
                requirement: "finite",
                value: t,
            });
        }
        if i > 0 && t <= path.params[i - 1] {
            return Err(FormatError::ParamsNotIncreasing {
                path: format!("paths[{index}].params[{i}]"),
                value: t,
                previous: path.params[i - 1],
            });
        }
    }
    for (i, point) in path.points.iter().enumerate() {
        for (k, &x) in point.iter().enumerate() {
            if !x.is_finite() {
                return Err(FormatError::BadNumber {
                    path: format!("paths[{index}].points[{i}][{k}]"),
                    requirement: "finite",
                    value: x,
                });
            }
        }
        if let Some(normal) = path.points.normal(i) {
            let norm = normal.norm();
            if (norm - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
                return Err(FormatError::NotUnitNormal {
                    path: format!("paths[{index}].points[{i}]"),
                    norm,
                });
            }
        }
    }
    let e = path.max_chord_error;
    if !(e.is_finite() && e >= 0.0) {
        return Err(FormatError::BadNumber {
            path: format!("paths[{index}].max_chord_error"),
            requirement: "finite and >= 0",
            value: e,
        });
    }
    if e > tolerance {
        return Err(FormatError::ChordErrorAboveTolerance {
            index,
            value: e,
            tolerance,
        });
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Writing.
// ---------------------------------------------------------------------------------------------

/// Checks `file` and writes it to `dest`, atomically; `-` means standard output.
///
/// Written by [`kerf_io::write_file`]: the document goes to a temporary file in `dest`'s
/// directory, which is renamed to `dest` once completely written and flushed; on any failure
/// the temporary file is removed and `dest` is untouched. A device or FIFO is written through,
/// a symbolic link's target is written. A new file gets the permissions of a newly created
/// file (the umask applies); a replaced one keeps its mode.
///
/// # Errors
/// Any error of [`ToolpathFile::validate`], or [`FormatError::Write`]; wrapped in
/// [`FormatError::File`] naming `dest`.
pub fn write(file: &ToolpathFile, dest: impl AsRef<Path>) -> Result<()> {
    let dest = dest.as_ref();
    let result = file.validate().and_then(|()| {
        kerf_io::write_file(dest, |mut w| write_json(file, &mut w))
            .map_err(|error| FormatError::Write { error })
    });
    result.map_err(|e| e.in_file(dest))
}

/// Checks `file` and writes it to `writer`.
///
/// # Errors
/// Any error of [`ToolpathFile::validate`], or [`FormatError::Write`].
pub fn to_writer(file: &ToolpathFile, writer: impl Write) -> Result<()> {
    file.validate()?;
    let mut w = BufWriter::new(writer);
    write_json(file, &mut w)
        .and_then(|()| w.flush())
        .map_err(|error| FormatError::Write { error })
}

/// Checks `file` and returns it as JSON text.
///
/// # Errors
/// Any error of [`ToolpathFile::validate`].
pub fn to_string(file: &ToolpathFile) -> Result<String> {
    let mut bytes = Vec::new();
    to_writer(file, &mut bytes)?;
    // The writer emits valid UTF-8 (ids are Rust strings, everything else ASCII), so the
    // lossy conversion never replaces anything.
    Ok(String::from_utf8_lossy(&bytes).into_owned())
}

/// Writes the JSON text: keys in the order of the format description, one point per line.
fn write_json(file: &ToolpathFile, w: &mut impl Write) -> io::Result<()> {
    writeln!(w, "{{")?;
    writeln!(w, "  \"format\": \"{TOOLPATH_FORMAT}\",")?;
    writeln!(w, "  \"units\": \"{}\",", file.units)?;
    write!(w, "  \"tolerance\": ")?;
    number(w, file.tolerance)?;
    if file.paths.is_empty() {
        writeln!(w, ",\n  \"paths\": []")?;
    } else {
        writeln!(w, ",\n  \"paths\": [")?;
        for (i, path) in file.paths.iter().enumerate() {
            write_path(path, w)?;
            writeln!(w, "{}", if i + 1 < file.paths.len() { "," } else { "" })?;
        }
        writeln!(w, "  ]")?;
    }
    writeln!(w, "}}")
}

fn write_path(path: &ToolpathRecord, w: &mut impl Write) -> io::Result<()> {
    writeln!(w, "    {{")?;
    write!(w, "      \"id\": ")?;
    serde_json::to_writer(&mut *w, &path.id)?;
    writeln!(w, ",\n      \"point_count\": {},", path.points.len())?;
    write!(w, "      \"max_chord_error\": ")?;
    number(w, path.max_chord_error)?;
    writeln!(w, ",\n      \"params\": [")?;
    // The numbers go straight from the formatter into `w` (a buffered writer): no string per
    // number, no serializer per number.
    let mut fmt = zmij::Buffer::new();
    for (i, chunk) in path.params.chunks(8).enumerate() {
        w.write_all(b"        ")?;
        for (k, &t) in chunk.iter().enumerate() {
            if k > 0 {
                w.write_all(b", ")?;
            }
            w.write_all(fmt.format_finite(t).as_bytes())?;
        }
        let last = (i + 1) * 8 >= path.params.len();
        w.write_all(if last { b"\n" } else { b",\n" })?;
    }
    w.write_all(b"      ],\n      \"points\": [\n")?;
    let n = path.points.len();
    for (i, point) in path.points.iter().enumerate() {
        w.write_all(b"        [")?;
        for (k, &x) in point.iter().enumerate() {
            if k > 0 {
                w.write_all(b", ")?;
            }
            w.write_all(fmt.format_finite(x).as_bytes())?;
        }
        w.write_all(if i + 1 < n { b"],\n" } else { b"]\n" })?;
    }
    write!(w, "      ]\n    }}")
}

/// Writes a finite number in the shortest form that reads back to the same double (the
/// formatter serde_json uses, so the bytes are those serde_json would write).
fn number(w: &mut impl Write, x: f64) -> io::Result<()> {
    debug_assert!(x.is_finite(), "validated before writing");
    w.write_all(zmij::Buffer::new().format_finite(x).as_bytes())
}

// ---------------------------------------------------------------------------------------------
// Reading.
// ---------------------------------------------------------------------------------------------

#[derive(Deserialize)]
struct RawToolpathFile {
    tolerance: f64,
    paths: Vec<RawToolPath>,
}

#[derive(Deserialize)]
struct RawToolPath {
    id: String,
    params: Vec<f64>,
    points: Vec<Vec<f64>>,
    max_chord_error: f64,
    #[serde(default)]
    point_count: Option<usize>,
}

/// Reads and checks a `kerf.toolpath/1` file.
///
/// # Errors
/// Any [`FormatError`], wrapped in [`FormatError::File`] naming `path`.
pub fn load(path: impl AsRef<Path>) -> Result<ToolpathFile> {
    let path = path.as_ref();
    json::read_file(path)
        .and_then(|bytes| from_slice(&bytes))
        .map_err(|e| e.in_file(path))
}

/// Reads and checks a `kerf.toolpath/1` document held in memory.
///
/// # Errors
/// Any [`FormatError`] about the content.
pub fn from_str(text: &str) -> Result<ToolpathFile> {
    from_slice(text.as_bytes())
}

/// Reads and checks a `kerf.toolpath/1` document from a reader (read to the end).
///
/// # Errors
/// [`FormatError::Read`] if reading fails, else any [`FormatError`] about the content.
pub fn from_reader(reader: impl Read) -> Result<ToolpathFile> {
    from_slice(&json::read_all(reader)?)
}

fn from_slice(bytes: &[u8]) -> Result<ToolpathFile> {
    let map = json::parse_document(bytes, TOOLPATH_FORMAT)?;
    let raw: RawToolpathFile = json::deserialize(Value::Object(map), "")?;
    let mut paths = Vec::with_capacity(raw.paths.len());
    for (index, p) in raw.paths.into_iter().enumerate() {
        if let Some(count) = p.point_count {
            if count != p.points.len() {
                return Err(FormatError::PathCount {
                    index,
                    problem: format!(
                        "point_count is {count} but there are {} points",
                        p.points.len()
                    ),
                });
            }
        }
        paths.push(ToolpathRecord {
            points: points_from_rows(index, p.points)?,
            id: p.id,
            params: p.params,
            max_chord_error: p.max_chord_error,
        });
    }
    let file = ToolpathFile {
        units: Units::Millimetres,
        tolerance: raw.tolerance,
        paths,
    };
    file.validate()?;
    Ok(file)
}

/// Turns the rows of `points` into [`ToolpathPoints`], checking their lengths.
fn points_from_rows(index: usize, rows: Vec<Vec<f64>>) -> Result<ToolpathPoints> {
    let first = rows.first().map_or(3, Vec::len);
    let bad_length = |i: usize, got: usize| FormatError::PointLength {
        path: format!("paths[{index}].points[{i}]"),
        got,
        first: (i > 0 && (got == 3 || got == 6)).then_some(first),
    };
    match first {
        3 => rows
            .into_iter()
            .enumerate()
            .map(|(i, r)| <[f64; 3]>::try_from(r).map_err(|r| bad_length(i, r.len())))
            .collect::<Result<_>>()
            .map(ToolpathPoints::Positions),
        6 => rows
            .into_iter()
            .enumerate()
            .map(|(i, r)| <[f64; 6]>::try_from(r).map_err(|r| bad_length(i, r.len())))
            .collect::<Result<_>>()
            .map(ToolpathPoints::Poses),
        got => Err(bad_length(0, got)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The writer formats numbers itself (zmij, no serializer per number): the bytes must
        /// be serde_json's, and read back to the same double.
        #[test]
        fn numbers_are_serde_jsons_and_round_trip(bits in proptest::num::u64::ANY) {
            let x = f64::from_bits(bits);
            proptest::prop_assume!(x.is_finite());
            let mut ours = Vec::new();
            number(&mut ours, x).unwrap();
            let theirs = serde_json::to_string(&x).unwrap();
            proptest::prop_assert_eq!(std::str::from_utf8(&ours).unwrap(), theirs.as_str());
            let back: f64 = serde_json::from_slice(&ours).unwrap();
            proptest::prop_assert_eq!(back.to_bits(), x.to_bits());
        }
    }

    fn sample() -> ToolpathFile {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        ToolpathFile {
            units: Units::Millimetres,
            tolerance: 0.001,
            paths: vec![
                ToolpathRecord {
                    id: "arc \"1\"".into(),
                    params: (0..=9).map(|i| f64::from(i) / 9.0).collect(),
                    points: ToolpathPoints::Poses(
                        (0..=9)
                            .map(|i| {
                                let a = f64::from(i) * 0.1;
                                [50.0 * a.cos(), 50.0 * a.sin(), 1e-7, h, 0.0, h]
                            })
                            .collect(),
                    ),
                    max_chord_error: 0.00097,
                },
                ToolpathRecord {
                    id: "line".into(),
                    params: vec![-1.0, 2.5],
                    points: ToolpathPoints::Positions(vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]),
                    max_chord_error: 0.0,
                },
            ],
        }
    }

    fn document(paths: &str) -> String {
        format!(
            r#"{{"format": "kerf.toolpath/1", "units": "mm", "tolerance": 0.01, "paths": [{paths}]}}"#
        )
    }

    fn error(text: &str) -> String {
        match from_str(text) {
            Ok(_) => panic!("expected an error for {text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn round_trip_keeps_every_bit() {
        let file = sample();
        let text = to_string(&file).expect("valid");
        assert_eq!(from_str(&text).expect("reads back"), file, "round trip");
        let empty = ToolpathFile {
            paths: vec![],
            ..sample()
        };
        let text = to_string(&empty).expect("valid");
        assert_eq!(from_str(&text).expect("reads back"), empty, "no paths");
    }

    #[test]
    fn written_keys_are_those_of_the_format() {
        let text = to_string(&sample()).expect("valid");
        let v: Value = serde_json::from_str(&text).expect("valid JSON");
        let top: Vec<&str> = v
            .as_object()
            .expect("object")
            .keys()
            .map(String::as_str)
            .collect();
        assert_eq!(
            top,
            ["format", "paths", "tolerance", "units"],
            "top-level keys"
        );
        assert_eq!(v["format"], "kerf.toolpath/1", "format");
        assert_eq!(v["units"], "mm", "units");
        let path = v["paths"][0].as_object().expect("path object");
        let keys: Vec<&str> = path.keys().map(String::as_str).collect();
        assert_eq!(
            keys,
            ["id", "max_chord_error", "params", "point_count", "points"],
            "path keys: the format's plus point_count"
        );
        assert_eq!(
            v["paths"][0]["points"][3].as_array().map(Vec::len),
            Some(6),
            "pose"
        );
        assert_eq!(
            v["paths"][1]["points"][1],
            serde_json::json!([1.0, 2.0, 3.0]),
            "position"
        );
        assert_eq!(v["paths"][0]["point_count"], 10, "point_count");
    }

    #[test]
    fn the_writer_refuses_what_the_reader_would() {
        let mut f = sample();
        f.paths[1].points = ToolpathPoints::Positions(vec![[0.0, f64::NAN, 0.0], [1.0, 2.0, 3.0]]);
        assert_eq!(
            to_string(&f).expect_err("NaN").to_string(),
            "paths[1].points[0][1]: must be finite (got NaN)",
            "NaN point"
        );
        let mut f = sample();
        f.tolerance = 0.0;
        assert_eq!(
            to_string(&f).expect_err("zero tolerance").to_string(),
            "tolerance: must be finite and > 0 (got 0)",
            "tolerance"
        );
        let mut f = sample();
        f.paths[0].max_chord_error = 0.0011;
        assert_eq!(
            to_string(&f).expect_err("above tolerance").to_string(),
            "paths[0].max_chord_error: 0.0011 exceeds the tolerance 0.001",
            "chord error"
        );
        let mut f = sample();
        f.paths[1].max_chord_error = f64::INFINITY;
        assert_eq!(
            to_string(&f).expect_err("infinite").to_string(),
            "paths[1].max_chord_error: must be finite and >= 0 (got inf)",
            "infinite chord error"
        );
        let mut f = sample();
        f.paths[1].params[1] = f64::NAN;
        assert_eq!(
            to_string(&f).expect_err("NaN param").to_string(),
            "paths[1].params[1]: must be finite (got NaN)",
            "NaN param"
        );
        let mut f = sample();
        f.paths[1].id = "arc \"1\"".into();
        assert_eq!(
            to_string(&f).expect_err("duplicate").to_string(),
            "paths[1].id: duplicate id \"arc \"1\"\" (already used by paths[0])",
            "duplicate id"
        );
    }

    #[test]
    fn reader_checks_params_points_and_counts() {
        let cases = [
            (
                r#"{"id": "a", "params": [0, 0.5, 0.5, 1], "points": [[0,0,0],[1,0,0],[2,0,0],[3,0,0]], "max_chord_error": 0}"#,
                "paths[0].params[2]: params must be strictly increasing (0.5 after 0.5)",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0],[1,0,0,1]], "max_chord_error": 0}"#,
                "paths[0].points[1]: a point is [x, y, z] or [x, y, z, i, j, k], got 4 numbers",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0,0,0,1],[1,0,0]], "max_chord_error": 0}"#,
                "paths[0].points[1]: a point is [x, y, z] or [x, y, z, i, j, k], got 3 numbers (points[0] has 6: all points of a path have the same length)",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0],[1,0]], "max_chord_error": 0}"#,
                "paths[0].points[0]: a point is [x, y, z] or [x, y, z, i, j, k], got 2 numbers",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0,0,0,1],[1,0,0,0,0,2]], "max_chord_error": 0}"#,
                "paths[0].points[1]: the normal (i, j, k) must be a unit vector (its length is 2)",
            ),
            (
                r#"{"id": "a", "params": [0, 1, 2], "points": [[0,0,0],[1,0,0]], "max_chord_error": 0}"#,
                "paths[0]: 2 points but 3 params (one param per point)",
            ),
            (
                r#"{"id": "a", "params": [0], "points": [[0,0,0]], "max_chord_error": 0}"#,
                "paths[0]: 1 points; a path has at least 2 (the ends of the domain)",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0],[1,0,0]], "max_chord_error": 0, "point_count": 3}"#,
                "paths[0]: point_count is 3 but there are 2 points",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0],[1,0,0]], "max_chord_error": -1}"#,
                "paths[0].max_chord_error: must be finite and >= 0 (got -1)",
            ),
            (
                r#"{"id": "", "params": [0, 1], "points": [[0,0,0],[1,0,0]], "max_chord_error": 0}"#,
                "paths[0].id: id must not be empty",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0],[1,"x",0]], "max_chord_error": 0}"#,
                "paths[0].points[1][1]: invalid type: string \"x\", expected a number",
            ),
            (
                r#"{"id": "a", "params": [0, 1], "points": [[0,0,0],[1,0,0]]}"#,
                "paths[0].max_chord_error: required key is missing",
            ),
        ];
        for (path, expected) in cases {
            assert_eq!(error(&document(path)), expected, "for {path}");
        }
    }

    #[test]
    fn reader_checks_the_header() {
        assert_eq!(
            error(r#"{"format": "kerf.curves/1", "units": "mm", "tolerance": 1, "paths": []}"#),
            "format: unsupported format \"kerf.curves/1\" (this reader reads \"kerf.toolpath/1\")",
            "format"
        );
        assert_eq!(
            error(""),
            "the file is empty (expected a kerf.toolpath/1 JSON document)",
            "empty"
        );
        assert_eq!(
            error(r#"{"format": "kerf.toolpath/1", "units": "mm", "tolerance": -1, "paths": []}"#),
            "tolerance: must be finite and > 0 (got -1)",
            "tolerance"
        );
        assert!(
            error(
                r#"{"format": "kerf.toolpath/1", "units": "mm", "tolerance": 1e999, "paths": []}"#
            )
            .starts_with("tolerance: invalid JSON at line 1, column "),
            "huge tolerance"
        );
    }

    #[test]
    fn write_to_a_file_and_load() {
        let dir = tempfile::tempdir().expect("temp dir");
        let dest = dir.path().join("out.json");
        write(&sample(), &dest).expect("written");
        assert_eq!(
            load(&dest).expect("reads back"),
            sample(),
            "round trip on disk"
        );
        // Overwrite in place.
        let mut other = sample();
        other.paths.pop();
        write(&other, &dest).expect("overwritten");
        assert_eq!(load(&dest).expect("reads back"), other, "replaced");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["out.json"], "no temporary file left");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&dest).expect("stat").permissions().mode();
            assert_ne!(
                mode & 0o044,
                0,
                "readable by others as a normal file (mode {mode:o})"
            );
        }
    }

    #[test]
    fn a_failed_write_leaves_nothing_behind() {
        let dir = tempfile::tempdir().expect("temp dir");
        let dest = dir.path().join("out.json");
        // Failure in the middle of writing.
        let result = kerf_io::write_file(&dest, |w| {
            w.write_all(b"{\"format\": ")?;
            Err(io::Error::other("disk full"))
        });
        assert!(result.is_err(), "the failure is reported");
        assert_eq!(
            std::fs::read_dir(dir.path()).expect("list").count(),
            0,
            "neither the destination nor a temporary file exists"
        );
        // Failure of validation leaves an existing file as it was.
        std::fs::write(&dest, "old").expect("write");
        let mut bad = sample();
        bad.tolerance = f64::NAN;
        let e = write(&bad, &dest).expect_err("invalid");
        assert_eq!(e.file(), Some(dest.as_path()), "names the file");
        assert_eq!(
            std::fs::read_to_string(&dest).expect("read"),
            "old",
            "untouched"
        );
        // A directory that does not exist.
        let e = write(&sample(), dir.path().join("no/such/dir/out.json")).expect_err("no dir");
        assert!(e.to_string().contains("cannot write"), "{e}");
    }

    #[test]
    fn accessors() {
        let f = sample();
        let poses = &f.paths[0].points;
        assert!(poses.has_normals() && !poses.is_empty(), "poses");
        assert_eq!(poses.position(0), Point3::new(50.0, 0.0, 1e-7), "position");
        let n = poses.normal(0).expect("normal");
        assert!((n.norm() - 1.0).abs() < 1e-15, "unit normal");
        assert_eq!(f.paths[1].points.normal(0), None, "no normals");
        assert_eq!(
            from_reader(to_string(&f).expect("valid").as_bytes()).expect("reads"),
            f,
            "reader"
        );
    }
}
