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
//!         kerf_offset: None,
//!     }],
//! };
//! let text = toolpath::to_string(&file)?;
//! assert!(text.starts_with("{\n  \"format\": \"kerf.toolpath/1\""), "{text}");
//! assert_eq!(toolpath::from_str(&text)?, file);
//! # Ok::<(), kerf_format::FormatError>(())
//! ```

use std::io::{self, Read, Write};
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
    /// The path offset by half the kerf toward the scrap (`kerf run` with a kerf width, in the
    /// computer): the optional key `kerf_offset`, which `kerf check` measures against the exact
    /// offset of the curve. `None`: the path is the contour itself.
    pub kerf_offset: Option<KerfOffset>,
}

/// The optional `kerf_offset` of a path: the beam's path offset by `offset_mm` toward `side`,
/// at right angles to the path and the tool axis (`docs/process.md`, "Kerf compensation").
#[derive(Debug, Clone, PartialEq, serde::Serialize, Deserialize)]
pub struct KerfOffset {
    /// Half the kerf, mm (> 0).
    pub offset_mm: f64,
    /// The side the path moved to, seen along the curve with the tool axis toward the viewer.
    pub side: crate::ScrapSide,
    /// The curve parameter each point comes from: non-decreasing (the points of an arc about
    /// a corner share the corner's).
    pub params: Vec<f64>,
    /// The offset points with their unit tool axes, `[x, y, z, i, j, k]`, in the curve's
    /// coordinates.
    pub points: Vec<[f64; 6]>,
    /// The largest distance from a chord to the exact offset the writer found, mm: proven
    /// where `proven`, else measured.
    pub max_chord_error: f64,
    /// True if every chord's distance is proven.
    pub proven: bool,
}

impl KerfOffset {
    /// The shape rules: as many params as points, at least two, every number finite, the
    /// params non-decreasing, the offset > 0. `index` names the path in the messages.
    ///
    /// # Errors
    /// [`FormatError::PathCount`], [`FormatError::BadNumber`], [`FormatError::ParamsNotIncreasing`].
    pub fn validate(&self, index: usize) -> Result<()> {
        let (n, m) = (self.points.len(), self.params.len());
        if n != m || n < 2 {
            return Err(FormatError::PathCount {
                index,
                problem: format!(
                    "kerf_offset: {n} points and {m} params (one param per point, at least 2)"
                ),
            });
        }
        if !(self.offset_mm > 0.0 && self.offset_mm.is_finite()) {
            return Err(FormatError::BadNumber {
                path: format!("paths[{index}].kerf_offset.offset_mm"),
                requirement: "finite and > 0",
                value: self.offset_mm,
            });
        }
        for (i, p) in self.points.iter().enumerate() {
            if let Some(&v) = p.iter().find(|v| !v.is_finite()) {
                return Err(FormatError::BadNumber {
                    path: format!("paths[{index}].kerf_offset.points[{i}]"),
                    requirement: "finite",
                    value: v,
                });
            }
            let norm = (p[3] * p[3] + p[4] * p[4] + p[5] * p[5]).sqrt();
            if (norm - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
                return Err(FormatError::BadNumber {
                    path: format!("paths[{index}].kerf_offset.points[{i}]"),
                    requirement: "a unit tool axis (i, j, k)",
                    value: norm,
                });
            }
        }
        for (i, &t) in self.params.iter().enumerate() {
            if !t.is_finite() {
                return Err(FormatError::BadNumber {
                    path: format!("paths[{index}].kerf_offset.params[{i}]"),
                    requirement: "finite",
                    value: t,
                });
            }
            if i > 0 && t < self.params[i - 1] {
                return Err(FormatError::ParamsNotIncreasing {
                    path: format!("paths[{index}].kerf_offset.params[{i}]"),
                    value: t,
                    previous: self.params[i - 1],
                });
            }
        }
        Ok(())
    }
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
    let (params, e) = (&path.params, path.max_chord_error);
    if let Some(o) = &path.kerf_offset {
        o.validate(index)?;
    }
    match &path.points {
        ToolpathPoints::Positions(p) => validate_rows(index, params, p, e, tolerance),
        ToolpathPoints::Poses(p) => validate_rows(index, params, p, e, tolerance),
    }
}

/// The rules of one path (see the module documentation), on its parts.
fn validate_rows<R: PointRow>(
    index: usize,
    params: &[f64],
    points: &[R],
    max_chord_error: f64,
    tolerance: f64,
) -> Result<()> {
    let (n, m) = (points.len(), params.len());
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
    for (i, &t) in params.iter().enumerate() {
        if !t.is_finite() {
            return Err(FormatError::BadNumber {
                path: format!("paths[{index}].params[{i}]"),
                requirement: "finite",
                value: t,
            });
        }
        if i > 0 && t <= params[i - 1] {
            return Err(FormatError::ParamsNotIncreasing {
                path: format!("paths[{index}].params[{i}]"),
                value: t,
                previous: params[i - 1],
            });
        }
    }
    for (i, point) in points.iter().enumerate() {
        let row = point.row();
        for (k, &x) in row.iter().enumerate() {
            if !x.is_finite() {
                return Err(FormatError::BadNumber {
                    path: format!("paths[{index}].points[{i}][{k}]"),
                    requirement: "finite",
                    value: x,
                });
            }
        }
        if row.len() == 6 {
            let norm = Vector3::new(row[3], row[4], row[5]).norm();
            if (norm - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
                return Err(FormatError::NotUnitNormal {
                    path: format!("paths[{index}].points[{i}]"),
                    norm,
                });
            }
        }
    }
    let e = max_chord_error;
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
    file.validate().map_err(|e| e.in_file(dest))?;
    write_with(dest, file.units, file.tolerance, |w| write_paths(file, w))
}

/// Writes a document of the given units and tolerance to `dest` atomically, as [`write()`], with
/// the paths `paths` hands to the [`ToolpathWriter`] one by one: a caller that produces paths
/// one after the other (the discretizer) writes them as they come and never holds the whole
/// document. If `paths` fails, or a path breaks a rule of the format, `dest` is untouched and
/// the error is returned.
///
/// # Errors
/// The error of `paths`, or a [`FormatError`] (wrapped in [`FormatError::File`] naming `dest`,
/// then converted to `E`).
pub fn write_with<E: From<FormatError>>(
    dest: &Path,
    units: Units,
    tolerance: f64,
    paths: impl FnOnce(&mut ToolpathWriter<&mut dyn Write>) -> std::result::Result<(), E>,
) -> std::result::Result<(), E> {
    // The callback of `kerf_io::write_file` returns io errors: any other error is kept here.
    let mut kept: Option<E> = None;
    let mut keep = |e: E| {
        kept = Some(e);
        io::Error::other("stopped")
    };
    let result = kerf_io::write_file(dest, |w| {
        let mut tw =
            ToolpathWriter::new(w, units, tolerance).map_err(|e| keep(E::from(e.in_file(dest))))?;
        paths(&mut tw).map_err(&mut keep)?;
        tw.finish()
            .map(drop)
            .map_err(|e| keep(E::from(e.in_file(dest))))
    });
    match (result, kept) {
        (_, Some(e)) => Err(e),
        (Ok(()), None) => Ok(()),
        (Err(error), None) => Err(E::from(FormatError::Write { error }.in_file(dest))),
    }
}

/// Checks `file` and writes it to `writer`.
///
/// # Errors
/// Any error of [`ToolpathFile::validate`], or [`FormatError::Write`].
pub fn to_writer(file: &ToolpathFile, writer: impl Write) -> Result<()> {
    file.validate()?;
    write_document(file, writer)
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

/// Streams `file` through a [`ToolpathWriter`].
fn write_document(file: &ToolpathFile, writer: impl Write) -> Result<()> {
    let mut w = ToolpathWriter::new(writer, file.units, file.tolerance)?;
    write_paths(file, &mut w)?;
    w.finish().map(drop)
}

/// Every path of `file`, in order.
fn write_paths<W: Write>(file: &ToolpathFile, w: &mut ToolpathWriter<W>) -> Result<()> {
    for path in &file.paths {
        let o = path.kerf_offset.as_ref();
        match &path.points {
            ToolpathPoints::Positions(p) => {
                w.path_with_offset(&path.id, &path.params, p, path.max_chord_error, o)?
            }
            ToolpathPoints::Poses(p) => {
                w.path_with_offset(&path.id, &path.params, p, path.max_chord_error, o)?
            }
        }
    }
    Ok(())
}

/// One point of a path as written: `[x, y, z]` or `[x, y, z, i, j, k]` (a normal).
pub trait PointRow {
    /// The numbers of the row, 3 or 6.
    fn row(&self) -> &[f64];
}

impl PointRow for [f64; 3] {
    fn row(&self) -> &[f64] {
        self
    }
}

impl PointRow for [f64; 6] {
    fn row(&self) -> &[f64] {
        self
    }
}

impl PointRow for Point3<f64> {
    fn row(&self) -> &[f64] {
        self.coords.as_slice()
    }
}

/// Bytes gathered before they go to the underlying writer.
const CHUNK: usize = 1 << 16;

/// Room kept free beyond [`CHUNK`]: more than any line of points or parameters (at most
/// `8 + 8 * 24 + 7 * 2 + 2` bytes), so that a line is assembled without checking for space.
const LINE_ROOM: usize = 1024;

/// The document's bytes on their way to the writer: lines are assembled in place with copies
/// of fixed sizes (a number costs no call to `memcpy`), and go to the writer in pieces of
/// [`CHUNK`] bytes.
struct Sink<W: Write> {
    out: W,
    buf: Box<[u8]>,
    len: usize,
}

impl<W: Write> Sink<W> {
    /// Appends a constant piece of text (of a line, which [`Sink::line`] made room for).
    #[inline]
    fn push<const N: usize>(&mut self, s: &[u8; N]) {
        self.buf[self.len..self.len + N].copy_from_slice(s);
        self.len += N;
    }

    /// Appends a finite number in the shortest form that reads back to the same double (the
    /// formatter serde_json uses, so the bytes are those serde_json would write; at most 24),
    /// by two overlapping copies of a fixed size (the first and the last 16, 8 or 4 bytes), as
    /// `memcpy` does for short lengths, without the call.
    #[inline]
    fn number(&mut self, fmt: &mut zmij::Buffer, x: f64) {
        debug_assert!(x.is_finite(), "validated before writing");
        let s = fmt.format_finite(x).as_bytes();
        let n = s.len();
        let out = &mut self.buf[self.len..self.len + n];
        if n >= 16 {
            out[..16].copy_from_slice(&s[..16]);
            out[n - 16..].copy_from_slice(&s[n - 16..]);
        } else if n >= 8 {
            out[..8].copy_from_slice(&s[..8]);
            out[n - 8..].copy_from_slice(&s[n - 8..]);
        } else if n >= 4 {
            out[..4].copy_from_slice(&s[..4]);
            out[n - 4..].copy_from_slice(&s[n - 4..]);
        } else {
            for (o, &c) in out.iter_mut().zip(s) {
                *o = c;
            }
        }
        self.len += n;
    }

    /// Makes room for one line: hands a full piece to the writer.
    #[inline]
    fn line(&mut self) -> io::Result<()> {
        if self.len >= CHUNK {
            self.out.write_all(&self.buf[..self.len])?;
            self.len = 0;
        }
        Ok(())
    }

    /// Appends text of any length (an id, a count).
    fn bytes(&mut self, s: &[u8]) -> io::Result<()> {
        if self.len + s.len() > self.buf.len() {
            self.out.write_all(&self.buf[..self.len])?;
            self.len = 0;
            if s.len() > self.buf.len() {
                return self.out.write_all(s);
            }
        }
        self.buf[self.len..self.len + s.len()].copy_from_slice(s);
        self.len += s.len();
        Ok(())
    }

    /// Writes what is left and flushes.
    fn finish(&mut self) -> io::Result<()> {
        self.out.write_all(&self.buf[..self.len])?;
        self.len = 0;
        self.out.flush()
    }
}

/// A `kerf.toolpath/1` document written path by path, so that a caller with many paths (the
/// discretizer's output, millions of points) never holds the whole document: the header on
/// [`ToolpathWriter::new`], each path on [`ToolpathWriter::path`] (checked by the reader's
/// rules first: [`ToolpathFile::validate`] path by path, ids unique across the document), the
/// end on [`ToolpathWriter::finish`]. The text is that of [`to_string`]: keys in the order of
/// the format description, one point per line, every number in the shortest form that reads
/// back to the same double.
///
/// Lines are assembled in one buffer that goes to `out` in 64 KiB pieces, so `out` sees a few
/// large writes instead of one per number. A document left unfinished by an error is not a
/// valid file: write through [`write_with`] (or [`kerf_io::write_file`]), which removes it.
pub struct ToolpathWriter<W: Write> {
    sink: Sink<W>,
    fmt: zmij::Buffer,
    tolerance: f64,
    ids: IdSet,
    paths: usize,
}

impl<W: Write> ToolpathWriter<W> {
    /// Starts a document of the given units and chord tolerance (mm, finite and `> 0`).
    ///
    /// # Errors
    /// [`FormatError::BadNumber`] for the tolerance, or [`FormatError::Write`].
    pub fn new(out: W, units: Units, tolerance: f64) -> Result<Self> {
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(FormatError::BadNumber {
                path: "tolerance".into(),
                requirement: "finite and > 0",
                value: tolerance,
            });
        }
        let mut w = Self {
            sink: Sink {
                out,
                buf: vec![0; CHUNK + LINE_ROOM].into_boxed_slice(),
                len: 0,
            },
            fmt: zmij::Buffer::new(),
            tolerance,
            ids: IdSet::default(),
            paths: 0,
        };
        let header = format!(
            "{{\n  \"format\": \"{TOOLPATH_FORMAT}\",\n  \"units\": \"{units}\",\n  \"tolerance\": "
        );
        w.sink.bytes(header.as_bytes()).map_err(write_error)?;
        w.sink.number(&mut w.fmt, tolerance);
        w.sink.push(b",\n  \"paths\": [");
        Ok(w)
    }

    /// Writes the next path: its id, parameters, points and certified chord error.
    ///
    /// # Errors
    /// The path's defects as [`ToolpathFile::validate`] names them (with this path's index),
    /// or [`FormatError::Write`].
    pub fn path<R: PointRow>(
        &mut self,
        id: &str,
        params: &[f64],
        points: &[R],
        max_chord_error: f64,
    ) -> Result<()> {
        self.path_with_offset(id, params, points, max_chord_error, None)
    }

    /// [`ToolpathWriter::path`] with the path's optional `kerf_offset` ([`KerfOffset`]).
    ///
    /// # Errors
    /// As [`ToolpathWriter::path`], and the offset's defects ([`KerfOffset::validate`]).
    pub fn path_with_offset<R: PointRow>(
        &mut self,
        id: &str,
        params: &[f64],
        points: &[R],
        max_chord_error: f64,
        offset: Option<&KerfOffset>,
    ) -> Result<()> {
        let index = self.paths;
        self.ids.insert("paths", index, id)?;
        validate_rows(index, params, points, max_chord_error, self.tolerance)?;
        if let Some(o) = offset {
            o.validate(index)?;
        }
        self.paths += 1;
        self.write_path(id, params, points, max_chord_error, offset)
            .map_err(write_error)
    }

    fn write_path<R: PointRow>(
        &mut self,
        id: &str,
        params: &[f64],
        points: &[R],
        max_chord_error: f64,
        offset: Option<&KerfOffset>,
    ) -> io::Result<()> {
        let (s, fmt) = (&mut self.sink, &mut self.fmt);
        let head = format!(
            "{}    {{\n      \"id\": {},\n      \"point_count\": {},\n      \"max_chord_error\": ",
            if self.paths == 1 { "\n" } else { ",\n" },
            serde_json::to_string(id).map_err(io::Error::from)?,
            points.len()
        );
        s.bytes(head.as_bytes())?;
        s.line()?;
        s.number(fmt, max_chord_error);
        s.push(b",\n      \"params\": [\n");
        for (i, chunk) in params.chunks(8).enumerate() {
            s.line()?;
            s.push(b"        ");
            for (k, &t) in chunk.iter().enumerate() {
                if k > 0 {
                    s.push(b", ");
                }
                s.number(fmt, t);
            }
            if (i + 1) * 8 >= params.len() {
                s.push(b"\n");
            } else {
                s.push(b",\n");
            }
        }
        s.line()?;
        s.push(b"      ],\n      \"points\": [\n");
        let n = points.len();
        for (i, point) in points.iter().enumerate() {
            s.line()?;
            s.push(b"        [");
            for (k, &x) in point.row().iter().enumerate() {
                if k > 0 {
                    s.push(b", ");
                }
                s.number(fmt, x);
            }
            if i + 1 < n {
                s.push(b"],\n");
            } else {
                s.push(b"]\n");
            }
        }
        s.line()?;
        match offset {
            None => s.push(b"      ]\n    }"),
            Some(o) => {
                s.push(b"      ],\n      \"kerf_offset\": ");
                let text = serde_json::to_string(o).map_err(io::Error::from)?;
                s.bytes(text.as_bytes())?;
                s.line()?;
                s.push(b"\n    }");
            }
        }
        Ok(())
    }

    /// Ends the document, writes what is left and flushes; returns the writer.
    ///
    /// # Errors
    /// [`FormatError::Write`].
    pub fn finish(mut self) -> Result<W> {
        self.sink.line().map_err(write_error)?;
        if self.paths == 0 {
            self.sink.push(b"]\n}\n");
        } else {
            self.sink.push(b"\n  ]\n}\n");
        }
        self.sink.finish().map_err(write_error)?;
        Ok(self.sink.out)
    }
}

/// An output error as the format's error.
fn write_error(error: io::Error) -> FormatError {
    FormatError::Write { error }
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
    #[serde(default)]
    kerf_offset: Option<KerfOffset>,
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
            kerf_offset: p.kerf_offset,
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
            let mut sink = Sink { out: Vec::new(), buf: vec![0; 64].into_boxed_slice(), len: 0 };
            sink.number(&mut zmij::Buffer::new(), x);
            sink.finish().unwrap();
            let ours = sink.out;
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
                    kerf_offset: None,
                },
                ToolpathRecord {
                    id: "line".into(),
                    params: vec![-1.0, 2.5],
                    points: ToolpathPoints::Positions(vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]]),
                    max_chord_error: 0.0,
                    kerf_offset: None,
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

    /// A document written path by path through `write_with` is the one `write` gives, also
    /// when it is far larger than the writer's 64 KiB pieces; a failure of the caller midway,
    /// or a path the reader would refuse, leaves no file and returns that error.
    #[test]
    fn paths_written_one_by_one_are_the_document() {
        let dir = tempfile::tempdir().expect("temp dir");
        let mut big = sample();
        let n = 20_000;
        big.paths.push(ToolpathRecord {
            id: "long".into(),
            params: (0..n).map(|i| f64::from(i) / 7.0).collect(),
            points: ToolpathPoints::Positions(
                (0..n)
                    .map(|i| {
                        let a = f64::from(i) * 1e-3;
                        [a.sin() * 123.456789, a.cos(), -a / 3.0]
                    })
                    .collect(),
            ),
            max_chord_error: 0.000_999_999_999_999_9,
            kerf_offset: None,
        });
        let dest = dir.path().join("one-by-one.json");
        write_with(&dest, big.units, big.tolerance, |w| {
            for p in &big.paths {
                match &p.points {
                    ToolpathPoints::Positions(q) => {
                        w.path(&p.id, &p.params, q, p.max_chord_error)?
                    }
                    ToolpathPoints::Poses(q) => w.path(&p.id, &p.params, q, p.max_chord_error)?,
                }
            }
            Ok::<(), FormatError>(())
        })
        .expect("written");
        let text = std::fs::read_to_string(&dest).expect("read");
        assert!(text.len() > 4 << 16, "several pieces: {} bytes", text.len());
        assert_eq!(text, to_string(&big).expect("valid"), "the same bytes");
        assert_eq!(from_str(&text).expect("reads back"), big, "round trip");

        // The caller fails after one path: nothing is left, the caller's error comes back.
        let failed = dir.path().join("failed.json");
        let e = write_with(&failed, Units::Millimetres, 0.001, |w| {
            w.path("a", &[0.0, 1.0], &[[0.0; 3], [1.0, 0.0, 0.0]], 0.0)?;
            Err(FormatError::EmptyId {
                path: "the caller's own error".into(),
            })
        })
        .expect_err("fails");
        assert_eq!(
            e.to_string(),
            "the caller's own error: id must not be empty",
            "{e}"
        );
        // A path the reader would refuse: a duplicate id, named with the file.
        let e = write_with(&failed, Units::Millimetres, 0.001, |w| {
            w.path("a", &[0.0, 1.0], &[[0.0; 3], [1.0, 0.0, 0.0]], 0.0)?;
            w.path("a", &[0.0, 1.0], &[[0.0; 3], [1.0, 0.0, 0.0]], 0.0)
        })
        .expect_err("duplicate");
        assert!(e.to_string().contains("paths[1].id: duplicate id"), "{e}");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["one-by-one.json"], "no file from the failures");
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
