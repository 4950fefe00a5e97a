//! The error type of the format crate.
//!
//! Every message names where the defect is, as a JSON path into the document
//! (`curves[3].knots[5]`, `surfaces[0].triangles[4][1]`, `paths[2].params[7]`), followed by what
//! is wrong and, where it helps, what was found. Errors from [`crate::curves::load`] and
//! [`crate::toolpath::load`] are wrapped in [`FormatError::File`], so that the message also
//! names the file: `fixtures/bad/negative_weight.json: curves[0].weights[2]: weight must be
//! finite and > 0 (got -1)`.
//!
//! The underlying cause (an [`std::io::Error`], a [`NurbsError`]) is part of each message rather
//! than exposed through [`std::error::Error::source`], so that a reporter walking the source
//! chain does not print it twice.

use std::io;
use std::path::{Path, PathBuf};

use kerf_nurbs::NurbsError;
use thiserror::Error;

/// `Result` with [`FormatError`].
pub type Result<T> = std::result::Result<T, FormatError>;

/// Everything that can be wrong with a `kerf.curves/1` or `kerf.toolpath/1` document, or with
/// reading or writing one.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FormatError {
    /// An error inside the file `file` (added by the functions that take a path).
    /// Fix: see `error`; use [`FormatError::without_file`] to match on it.
    #[error("{}: {error}", file.display())]
    File {
        /// The file, as given by the caller.
        file: PathBuf,
        /// What is wrong in it.
        #[source]
        error: Box<FormatError>,
    },
    /// The file could not be read (missing, a directory, no permission, ...).
    /// Fix: check the path and its permissions.
    #[error("cannot read: {error}")]
    Read {
        /// The operating system's error.
        #[source]
        error: io::Error,
    },
    /// The output could not be written, or the temporary file could not be created or renamed.
    /// Nothing was written to the destination. Fix: check that the directory exists, is
    /// writable and has space.
    #[error("cannot write: {error}")]
    Write {
        /// The operating system's error.
        #[source]
        error: io::Error,
    },
    /// The document is empty (or only white space). Fix: the file was probably truncated or
    /// never written; regenerate it.
    #[error("the file is empty (expected a {expected} JSON document)")]
    Empty {
        /// The format that was expected, e.g. `kerf.curves/1`.
        expected: &'static str,
    },
    /// The document is not well-formed JSON (or holds a number too large for a double, such as
    /// `1e400`). Fix: correct the text at the given line and column.
    #[error(
        "{}invalid JSON at line {line}, column {column}: {message}",
        prefix(path)
    )]
    Syntax {
        /// Line, from 1.
        line: usize,
        /// Column (byte in the line), from 1.
        column: usize,
        /// The JSON path of the value being read when the error occurred, empty if it was at
        /// the top level.
        path: String,
        /// What the parser found wrong.
        message: String,
    },
    /// The top level of the document is not a JSON object. Fix: a kerf document is an object
    /// `{"format": ..., ...}`.
    #[error(
        "the top level must be a JSON object {{\"format\": \"{expected}\", ...}}, got {found}"
    )]
    NotAnObject {
        /// The format that was expected.
        expected: &'static str,
        /// The JSON type found (`an array`, `a string`, ...).
        found: &'static str,
    },
    /// The `format` key is missing or names a format this reader does not read (for instance a
    /// toolpath given where curves are expected, or a newer version). Fix: give a file of the
    /// expected format, or convert it.
    #[error("format: {}", describe_format(found.as_deref(), expected))]
    UnsupportedFormat {
        /// The value found, as JSON text (`"kerf.curves/2"`), or `None` if the key is missing.
        found: Option<String>,
        /// The format this reader supports.
        expected: &'static str,
    },
    /// The `units` key is missing or is not `"mm"`. kerf works in millimetres only and does
    /// not convert. Fix: scale the coordinates to millimetres and write `"units": "mm"`.
    #[error("units: {} (kerf works in millimetres only: convert the coordinates and write \"units\": \"mm\")", describe_found(found.as_deref()))]
    UnsupportedUnits {
        /// The value found, as JSON text, or `None` if the key is missing.
        found: Option<String>,
    },
    /// A value has the wrong JSON type or shape (a string where a number is expected, a
    /// control point with 2 coordinates, a missing required key, ...). Fix: write the value as
    /// the format specifies.
    #[error("{path}: {message}")]
    Shape {
        /// JSON path of the value.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// A surface's `type` is missing or is not one of `nurbs`, `mesh`, `stl`. Fix: correct the
    /// spelling of `type`.
    #[error("surfaces[{index}]: {} (expected one of nurbs, mesh, stl)", match found { Some(t) => format!("unknown type {t}"), None => "missing \"type\"".to_owned() })]
    UnknownSurfaceType {
        /// Index of the surface.
        index: usize,
        /// The type found, as JSON text (`"nurb"`), or `None` if the key is missing.
        found: Option<String>,
    },
    /// An `id` is the empty string. Fix: give every curve, surface and path a non-empty id.
    #[error("{path}: id must not be empty")]
    EmptyId {
        /// JSON path of the id, e.g. `curves[2].id`.
        path: String,
    },
    /// An id holds a control character or a line break (`\n`, `\r`, NUL, U+2028, ...). Ids are
    /// written into G-code comments, where a line break would start a block of its own (a
    /// rapid move, `M30`) that is no part of any path. Fix: use one line of printable text.
    #[error("{path}: {defect}")]
    UnsafeText {
        /// JSON path of the text, e.g. `curves[2].id`.
        path: String,
        /// The offending character and its position.
        defect: kerf_io::TextDefect,
    },
    /// Two curves, two surfaces or two toolpaths share an id. Fix: make the ids unique (curves
    /// and surfaces have separate name spaces).
    #[error("{path}: duplicate id \"{id}\" (already used by {first})")]
    DuplicateId {
        /// JSON path of the second occurrence, e.g. `curves[4].id`.
        path: String,
        /// The id.
        id: String,
        /// JSON path of the element that uses it first, e.g. `curves[1]`.
        first: String,
    },
    /// The data of curve `index` does not make a valid NURBS curve (degree, knots, control
    /// points, weights). Fix: see the [`NurbsError`] in the message.
    #[error("curves[{index}].{error}")]
    Curve {
        /// Index of the curve.
        index: usize,
        /// What is wrong with it; its message starts with the field (`knots[5]: ...`).
        error: NurbsError,
    },
    /// Every control point of curve `index` lies at one place (`curves::is_a_point`):
    /// the curve is a point, with no length and no side, and a cut of it would be only its
    /// lead-in and lead-out (or nothing at all). Fix: remove the curve, or give it the control
    /// points of the contour it was meant to be (a unit mistake can shrink a real contour to
    /// this).
    #[error("curves[{index}] ({id:?}): {}", POINT_CURVE)]
    PointCurve {
        /// Index of the curve.
        index: usize,
        /// Its id.
        id: String,
    },
    /// The data of surface `index` (of type `nurbs`) does not make a valid NURBS surface.
    /// Fix: see the [`NurbsError`] in the message.
    #[error("surfaces[{index}].{error}")]
    Surface {
        /// Index of the surface.
        index: usize,
        /// What is wrong with it; its message starts with the field (`knots_u[3]: ...`).
        error: NurbsError,
    },
    /// A curve's `surface` names no surface of the file. Fix: correct the id, add the surface
    /// to `surfaces`, or remove the `surface` key.
    #[error(
        "curves[{index}].surface: no surface with id \"{id}\" ({})",
        describe_ids(available)
    )]
    UnknownSurface {
        /// Index of the curve.
        index: usize,
        /// The id it names.
        id: String,
        /// The ids of the file's surfaces.
        available: Vec<String>,
    },
    /// The inline mesh of surface `index` is invalid. Fix: see [`MeshDefect`].
    #[error("surfaces[{index}].{defect}")]
    Mesh {
        /// Index of the surface.
        index: usize,
        /// What is wrong.
        defect: MeshDefect,
    },
    /// The STL file of surface `index` cannot be read or holds no usable mesh.
    /// Fix: see [`StlProblem`]; `path` is relative to the directory of the JSON file.
    #[error("surfaces[{index}].path: {}: {problem}", file.display())]
    Stl {
        /// Index of the surface.
        index: usize,
        /// The STL file, resolved against the JSON file's directory.
        file: PathBuf,
        /// What is wrong.
        problem: StlProblem,
    },
    /// A number breaks its rule: not finite, or a tolerance that is not > 0. (JSON text cannot
    /// hold NaN or infinity, but data built in memory can.) Fix: as the message says.
    #[error("{path}: must be {requirement} (got {value})")]
    BadNumber {
        /// JSON path of the number.
        path: String,
        /// The rule, e.g. `finite and > 0`.
        requirement: &'static str,
        /// The value found.
        value: f64,
    },
    /// The parameters of a toolpath are not strictly increasing. Fix: the writer must emit
    /// the cutting points in curve order without repeats.
    #[error("{path}: params must be strictly increasing ({value} after {previous})")]
    ParamsNotIncreasing {
        /// JSON path of the offending parameter.
        path: String,
        /// Its value.
        value: f64,
        /// The parameter before it.
        previous: f64,
    },
    /// A toolpath point does not have 3 (`[x, y, z]`) or 6 (`[x, y, z, i, j, k]`) numbers, or
    /// differs in length from the first point of its path. Fix: write every point of a path
    /// with the same layout.
    #[error("{path}: a point is [x, y, z] or [x, y, z, i, j, k], got {got} numbers{}", match first { Some(n) => format!(" (points[0] has {n}: all points of a path have the same length)"), None => String::new() })]
    PointLength {
        /// JSON path of the point.
        path: String,
        /// Its length.
        got: usize,
        /// The length of the path's first point, if the point is valid on its own but differs
        /// from it.
        first: Option<usize>,
    },
    /// The normal `(i, j, k)` of a toolpath point is not a unit vector (within 1e-6).
    /// Fix: normalise the normals before writing.
    #[error("{path}: the normal (i, j, k) must be a unit vector (its length is {norm})")]
    NotUnitNormal {
        /// JSON path of the point.
        path: String,
        /// The length found.
        norm: f64,
    },
    /// A toolpath has a different number of points and params, or fewer than 2 points, or a
    /// `point_count` that disagrees. Fix: one parameter per point, at least the two domain
    /// ends.
    #[error("paths[{index}]: {problem}")]
    PathCount {
        /// Index of the path.
        index: usize,
        /// What does not add up.
        problem: String,
    },
    /// A toolpath's `max_chord_error` is above the file's `tolerance`, which the format forbids.
    /// Fix: discretize again; this indicates a bug in the writer.
    #[error("paths[{index}].max_chord_error: {value} exceeds the tolerance {tolerance}")]
    ChordErrorAboveTolerance {
        /// Index of the path.
        index: usize,
        /// The path's `max_chord_error`.
        value: f64,
        /// The file's `tolerance`.
        tolerance: f64,
    },
}

impl FormatError {
    /// The file this error was found in, if the error came through a function that reads or
    /// writes a file.
    pub fn file(&self) -> Option<&Path> {
        match self {
            FormatError::File { file, .. } => Some(file),
            _ => None,
        }
    }

    /// The error without the file context added by [`FormatError::File`]: the variant to match
    /// on.
    pub fn without_file(&self) -> &FormatError {
        match self {
            FormatError::File { error, .. } => error.without_file(),
            other => other,
        }
    }

    /// Wraps the error in [`FormatError::File`] naming `file`.
    pub fn in_file(self, file: impl Into<PathBuf>) -> FormatError {
        FormatError::File {
            file: file.into(),
            error: Box::new(self),
        }
    }
}

/// What can be wrong with an inline triangle mesh (`"type": "mesh"`). Each message starts with
/// the field inside the surface (`triangles[4][1]: ...`).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MeshDefect {
    /// A vertex coordinate is NaN or infinite. Fix: export the mesh again; a non-finite vertex
    /// is corrupt data.
    #[error("vertices[{vertex}]: vertex must be finite (got [{x}, {y}, {z}])")]
    NonFiniteVertex {
        /// Index of the vertex.
        vertex: usize,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },
    /// A triangle refers to a vertex that does not exist. Fix: indices count from 0 and must
    /// be below the number of vertices.
    #[error(
        "triangles[{triangle}][{corner}]: vertex index {index} out of range ({count} vertices)"
    )]
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// Corner within the triangle (0, 1 or 2).
        corner: usize,
        /// The vertex index found.
        index: u32,
        /// The number of vertices.
        count: usize,
    },
    /// A triangle uses one vertex twice, so it has no area and no normal. Fix: remove it.
    #[error("triangles[{triangle}]: the triangle uses vertex {index} more than once")]
    RepeatedVertex {
        /// Index of the triangle.
        triangle: usize,
        /// The repeated vertex index.
        index: u32,
    },
    /// The mesh has no triangles, so it gives no normal anywhere. Fix: add the triangles.
    #[error("triangles: the mesh has no triangles")]
    NoTriangles,
    /// Every triangle has zero area, so the mesh gives no normal anywhere. Fix: check the
    /// vertex coordinates and indices.
    #[error("triangles: every triangle has zero area")]
    AllDegenerate,
}

/// What can be wrong with the STL file of a `"type": "stl"` surface.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum StlProblem {
    /// The file cannot be opened or read, or is not a regular file (a FIFO or a device is
    /// refused without being read). Fix: the `path` is relative to the directory of the JSON
    /// file; check that the STL file is there and is a plain file.
    #[error("cannot read: {error}")]
    Read {
        /// The operating system's error.
        #[source]
        error: io::Error,
    },
    /// The file is neither a complete binary STL nor a parsable ASCII STL. Fix: export it
    /// again.
    #[error("not a valid STL file: {reason}")]
    Malformed {
        /// What does not fit.
        reason: String,
    },
    /// A facet has a NaN or infinite vertex. Fix: export the mesh again.
    #[error("facet {facet} has a non-finite vertex [{x}, {y}, {z}]")]
    NonFiniteVertex {
        /// Index of the facet, from 0, in file order.
        facet: usize,
        /// x coordinate.
        x: f32,
        /// y coordinate.
        y: f32,
        /// z coordinate.
        z: f32,
    },
    /// The file holds no facets. Fix: export the surface again.
    #[error("the STL file has no facets")]
    NoFacets,
    /// Every facet has zero area. Fix: export the surface again.
    #[error("every facet of the STL file has zero area")]
    AllDegenerate,
    /// The mesh has more vertices than kerf's `u32` indices can address.
    /// Fix: split the mesh.
    #[error("{count} distinct vertices, more than the {} kerf supports", u32::MAX)]
    TooManyVertices {
        /// The number of distinct vertices.
        count: usize,
    },
}

fn prefix(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!("{path}: ")
    }
}

fn describe_format(found: Option<&str>, expected: &str) -> String {
    match found {
        None => format!("missing (this reader reads \"format\": \"{expected}\")"),
        Some(f) => format!("unsupported format {f} (this reader reads \"{expected}\")"),
    }
}

fn describe_found(found: Option<&str>) -> String {
    match found {
        None => "missing".to_owned(),
        Some(f) => format!("unsupported units {f}"),
    }
}

fn describe_ids(ids: &[String]) -> String {
    if ids.is_empty() {
        return "the file has no surfaces".to_owned();
    }
    let mut s = String::from("surfaces: ");
    for (i, id) in ids.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push_str(&format!("\"{id}\""));
    }
    s
}

/// What [`FormatError::PointCurve`] says of a curve that `curves::is_a_point` finds: the same words for a
/// file and for a curve built in code (`kerf_pipeline::Job::validate`).
pub const POINT_CURVE: &str = "all control points coincide: a point, not a contour";
