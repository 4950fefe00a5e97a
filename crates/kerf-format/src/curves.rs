//! The reader of `kerf.curves/1`: cut contours as NURBS curves, with the surfaces that carry
//! them.
//!
//! Reading has two layers:
//! - the *raw* structs ([`RawCurvesFile`], [`RawCurve`], [`RawSurface`], ...) mirror the JSON
//!   key for key and are what serde reads and writes; they hold unchecked data;
//! - [`from_raw`] checks every value and builds the *validated model* ([`CurvesFile`], whose
//!   curves are [`NurbsCurve`]s and whose surfaces are [`NurbsSurface`]s or triangle meshes,
//!   STL files loaded), which is what the rest of kerf uses.
//!
//! [`load`], [`from_str`] and [`from_reader`] do both. The first defect found is reported, with
//! its JSON path: `curves[3].knots[5]: knots must be non-decreasing (0.5 after 0.7)`. Unknown
//! keys are allowed (extensions), but one that looks like a misspelt known key is reported in
//! [`CurvesFile::warnings`] ([`UnknownKey`]): `curves[0].weigths: unknown key, did you mean
//! "weights"?`.
//!
//! ```
//! let json = r#"{
//!     "format": "kerf.curves/1",
//!     "units": "mm",
//!     "curves": [
//!         {"id": "line", "degree": 1, "knots": [0, 0, 1, 1],
//!          "control_points": [[0, 0, 0], [10, 0, 0]]}
//!     ]
//! }"#;
//! let file = kerf_format::curves::from_str(json, std::path::Path::new("."))?;
//! assert_eq!(file.curves[0].id, "line");
//! assert!((file.curves[0].curve.arc_length() - 10.0).abs() < 1e-12, "a 10 mm line");
//!
//! let bad = json.replace("[0, 0, 1, 1]", "[0, 0, 1, 0.5]");
//! let err = kerf_format::curves::from_str(&bad, std::path::Path::new(".")).unwrap_err();
//! assert_eq!(err.to_string(), "curves[0].knots[3]: knots must be non-decreasing (0.5 after 1)");
//! # Ok::<(), kerf_format::FormatError>(())
//! ```

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::Point3;
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::error::{FormatError, MeshDefect, Result};
use crate::{json, stl, Units, CURVES_FORMAT};
use kerf_io::json_type_name;

mod keys;

pub use keys::UnknownKey;

// ---------------------------------------------------------------------------------------------
// Raw layer: the JSON as written.
// ---------------------------------------------------------------------------------------------

/// A `kerf.curves/1` document exactly as written, before any check. Serialising it writes a
/// valid document if [`from_raw`] accepts it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawCurvesFile {
    /// Must be `"kerf.curves/1"`.
    pub format: String,
    /// Must be `"mm"`.
    pub units: String,
    /// The cut contours, in cutting order.
    pub curves: Vec<RawCurve>,
    /// The surfaces that carry curves (optional key, default empty).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub surfaces: Vec<RawSurface>,
}

/// One entry of `curves`. Build one with [`RawCurve::new`] and the `with_*` setters (the
/// optional keys grow with the format).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[non_exhaustive]
pub struct RawCurve {
    /// Unique, non-empty name; the toolpath keeps it.
    pub id: String,
    /// Polynomial degree, >= 1.
    pub degree: usize,
    /// The full knot vector: control points + degree + 1 non-decreasing values.
    pub knots: Vec<f64>,
    /// Control points `[x, y, z]` in mm.
    pub control_points: Vec<[f64; 3]>,
    /// One weight per control point, finite and > 0; absent means all 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<f64>>,
    /// The surface carrying the curve (which gives the tool axis), if any: one id, or a list
    /// of ids for a curve over several faces.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<SurfaceRef>,
    /// For a closed curve, the parameter where its cut begins (optional `start` key); checked
    /// by [`from_raw`] to lie inside the curve's domain.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<f64>,
    /// The side of the curve that is waste, `"left"` or `"right"` (optional `scrap` key);
    /// checked by [`from_raw`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scrap: Option<String>,
    /// How far the curve's points may lie from its surface, mm (optional
    /// `on_surface_tolerance_mm` key): the curve's own tolerance where it is looser than a
    /// run's (a CAD edge on its face within the tolerance its file states). Checked by
    /// [`from_raw`]: finite, > 0 and at most [`MAX_CURVE_ON_SURFACE_TOLERANCE_MM`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on_surface_tolerance_mm: Option<f64>,
    /// The thickness of the sheet whose face the curve lies on, mm (optional
    /// `sheet_thickness_mm` key): the beam enters at this face and leaves the thickness behind
    /// it, so the curve is cut from its surface's side only (turned to the other side, the
    /// nozzle would stand off from the far face, inside the sheet). Checked by [`from_raw`]:
    /// finite, > 0 and at most [`MAX_SHEET_THICKNESS_MM`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sheet_thickness_mm: Option<f64>,
}

impl RawCurve {
    /// A curve entry with no optional key: `id`, `degree`, the full knot vector and the
    /// control points in mm (polynomial: no weights).
    pub fn new(
        id: impl Into<String>,
        degree: usize,
        knots: Vec<f64>,
        control_points: Vec<[f64; 3]>,
    ) -> Self {
        Self {
            id: id.into(),
            degree,
            knots,
            control_points,
            weights: None,
            surface: None,
            start: None,
            scrap: None,
            on_surface_tolerance_mm: None,
            sheet_thickness_mm: None,
        }
    }

    /// Sets the weights (`None`: all 1).
    pub fn with_weights(mut self, weights: Option<Vec<f64>>) -> Self {
        self.weights = weights;
        self
    }

    /// Sets the surface (or surfaces) carrying the curve.
    pub fn with_surface(mut self, surface: Option<SurfaceRef>) -> Self {
        self.surface = surface;
        self
    }

    /// Sets the parameter where the cut of a closed curve begins.
    pub fn with_start(mut self, start: Option<f64>) -> Self {
        self.start = start;
        self
    }

    /// Sets the waste side, `"left"` or `"right"`.
    pub fn with_scrap(mut self, scrap: Option<String>) -> Self {
        self.scrap = scrap;
        self
    }

    /// Sets the curve's own on-surface tolerance, mm.
    pub fn with_on_surface_tolerance_mm(mut self, tolerance: Option<f64>) -> Self {
        self.on_surface_tolerance_mm = tolerance;
        self
    }

    /// Sets the thickness of the sheet the curve's face bounds, mm.
    pub fn with_sheet_thickness_mm(mut self, thickness: Option<f64>) -> Self {
        self.sheet_thickness_mm = thickness;
        self
    }
}

/// The first of a curve's optional lengths (`on_surface_tolerance_mm`, `sheet_thickness_mm`)
/// outside its range, as its key and what is wrong (`must be > 0 and at most 0.1 mm (got
/// 0.2)`): the one rule for files ([`from_raw`]) and for curves built in code.
pub fn length_key_error(
    on_surface_tolerance_mm: Option<f64>,
    sheet_thickness_mm: Option<f64>,
) -> Option<(&'static str, String)> {
    [
        (
            "on_surface_tolerance_mm",
            on_surface_tolerance_mm,
            MAX_CURVE_ON_SURFACE_TOLERANCE_MM,
        ),
        (
            "sheet_thickness_mm",
            sheet_thickness_mm,
            MAX_SHEET_THICKNESS_MM,
        ),
    ]
    .into_iter()
    .find_map(|(key, value, max)| {
        let t = value?;
        (!(t > 0.0 && t <= max))
            .then(|| (key, format!("must be > 0 and at most {max} mm (got {t})")))
    })
}

/// The largest `sheet_thickness_mm` a curve may state, mm (a plate far thicker than any a laser
/// cuts; the key exists to keep a thick sheet's contours on their side).
pub const MAX_SHEET_THICKNESS_MM: f64 = 1000.0;

/// The largest `on_surface_tolerance_mm` a curve may state, mm: farther from its surface a
/// curve is not on it (its normals would be another place's).
pub const MAX_CURVE_ON_SURFACE_TOLERANCE_MM: f64 = 0.1;

/// The `surface` key of a curve: one surface id, or a list of them for a curve that runs over
/// several faces (the normal at each point then comes from the nearest of them).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(untagged)]
pub enum SurfaceRef {
    /// `"surface": "panel"`.
    One(String),
    /// `"surface": ["panel", "flange"]`.
    Many(Vec<String>),
}

impl SurfaceRef {
    /// The ids, in the order written.
    pub fn ids(&self) -> Vec<String> {
        match self {
            SurfaceRef::One(s) => vec![s.clone()],
            SurfaceRef::Many(v) => v.clone(),
        }
    }
}

impl From<&str> for SurfaceRef {
    fn from(id: &str) -> Self {
        SurfaceRef::One(id.to_owned())
    }
}

impl From<String> for SurfaceRef {
    fn from(id: String) -> Self {
        SurfaceRef::One(id)
    }
}

impl<'de> Deserialize<'de> for SurfaceRef {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        use serde::de::Error;
        match Value::deserialize(d)? {
            Value::String(s) => Ok(SurfaceRef::One(s)),
            Value::Array(items) => items
                .into_iter()
                .enumerate()
                .map(|(k, v)| match v {
                    Value::String(s) => Ok(s),
                    other => Err(D::Error::custom(format!(
                        "item {k}: expected a surface id (a string), got {}",
                        json_type_name(&other)
                    ))),
                })
                .collect::<std::result::Result<Vec<_>, _>>()
                .map(SurfaceRef::Many),
            other => Err(D::Error::custom(format!(
                "expected a surface id or a list of ids, got {}",
                json_type_name(&other)
            ))),
        }
    }
}

/// One entry of `surfaces`, told apart by its `type` key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum RawSurface {
    /// `"type": "nurbs"`.
    Nurbs(RawNurbsSurface),
    /// `"type": "mesh"`.
    Mesh(RawMesh),
    /// `"type": "stl"`.
    Stl(RawStl),
}

/// A NURBS surface as written (`"type": "nurbs"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawNurbsSurface {
    /// Unique, non-empty name, referred to by the curves' `surface`.
    pub id: String,
    /// Degree along u (first index of `control_points`).
    pub degree_u: usize,
    /// Degree along v (second index).
    pub degree_v: usize,
    /// Full knot vector along u.
    pub knots_u: Vec<f64>,
    /// Full knot vector along v.
    pub knots_v: Vec<f64>,
    /// `control_points[a][b]`: `a` runs along u, `b` along v.
    pub control_points: Vec<Vec<[f64; 3]>>,
    /// Weights in the same layout as the control points; absent means all 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub weights: Option<Vec<Vec<f64>>>,
    /// Optional (kerf extension): reverse this surface's normal. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub flip: bool,
}

/// A triangle mesh written inline (`"type": "mesh"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawMesh {
    /// Unique, non-empty name.
    pub id: String,
    /// Vertex coordinates `[x, y, z]` in mm.
    pub vertices: Vec<[f64; 3]>,
    /// Vertex indices (from 0) of each triangle, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Optional (kerf extension): reverse this surface's normal. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub flip: bool,
}

/// A triangle mesh in an STL file (`"type": "stl"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RawStl {
    /// Unique, non-empty name.
    pub id: String,
    /// The STL file (binary or ASCII), relative to the directory of the JSON file.
    pub path: String,
    /// Optional (kerf extension): reverse this surface's normal. Default false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub flip: bool,
}

// ---------------------------------------------------------------------------------------------
// Validated model.
// ---------------------------------------------------------------------------------------------

/// A checked `kerf.curves/1` document: every curve is a valid NURBS curve, every surface valid,
/// ids unique, every `surface` reference resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvesFile {
    /// The length unit of all coordinates (always millimetres).
    pub units: Units,
    /// The cut contours, in file order.
    pub curves: Vec<CurveRecord>,
    /// The surfaces, in file order.
    pub surfaces: Vec<SurfaceRecord>,
    /// Unknown keys that look like misspellings of known ones (`"weigths"`, `"Surface"`), in
    /// document order: the document was read without them, which is rarely what its author
    /// meant. Empty for a document built from raw structs ([`from_raw`]), which have no unknown
    /// keys; callers show them as warnings.
    pub warnings: Vec<UnknownKey>,
}

/// One cut contour. Build one with [`CurveRecord::new`] and the `with_*` setters.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CurveRecord {
    /// Its id, unique among the curves.
    pub id: String,
    /// The curve.
    pub curve: NurbsCurve,
    /// The id of the surface carrying it (the first, if the file names several), guaranteed to
    /// exist in [`CurvesFile::surfaces`].
    pub surface: Option<String>,
    /// Every surface id the curve names, in file order (empty without `surface`; one entry for
    /// the string form). The normal at a point comes from the nearest of them.
    pub surfaces: Vec<String>,
    /// The parameter where the cut of this closed curve begins (the `start` key), inside the
    /// curve's domain; `None` lets kerf choose.
    pub start: Option<f64>,
    /// The side that is waste (the `scrap` key); `None` lets kerf decide.
    pub scrap: Option<ScrapSide>,
    /// The curve's own on-surface tolerance, mm (the `on_surface_tolerance_mm` key): the
    /// normals stage takes the looser of it and the run's.
    pub on_surface_tolerance_mm: Option<f64>,
    /// The thickness of the sheet whose face the curve lies on, mm (the `sheet_thickness_mm`
    /// key): the curve is cut from its surface's side only, never turned to the other side.
    pub sheet_thickness_mm: Option<f64>,
}

impl CurveRecord {
    /// A contour with no surface, start, scrap side or tolerance of its own.
    pub fn new(id: impl Into<String>, curve: NurbsCurve) -> Self {
        Self {
            id: id.into(),
            curve,
            surface: None,
            surfaces: Vec::new(),
            start: None,
            scrap: None,
            on_surface_tolerance_mm: None,
            sheet_thickness_mm: None,
        }
    }

    /// Sets the surfaces carrying it (the first is `surface`); the caller keeps them
    /// existing in the file's surfaces.
    pub fn with_surfaces(mut self, surfaces: Vec<String>) -> Self {
        self.surface = surfaces.first().cloned();
        self.surfaces = surfaces;
        self
    }

    /// Sets the parameter where the cut of this closed curve begins.
    pub fn with_start(mut self, start: Option<f64>) -> Self {
        self.start = start;
        self
    }

    /// Sets the waste side.
    pub fn with_scrap(mut self, scrap: Option<ScrapSide>) -> Self {
        self.scrap = scrap;
        self
    }

    /// Sets the curve's own on-surface tolerance, mm.
    pub fn with_on_surface_tolerance_mm(mut self, tolerance: Option<f64>) -> Self {
        self.on_surface_tolerance_mm = tolerance;
        self
    }

    /// Sets the thickness of the sheet whose face the curve lies on, mm.
    pub fn with_sheet_thickness_mm(mut self, thickness: Option<f64>) -> Self {
        self.sheet_thickness_mm = thickness;
        self
    }
}

/// The side of a curve that is waste, seen along the curve's direction with the normal toward
/// the viewer: `Left` is the side of `normal x tangent` (the `scrap` key of `kerf.curves/1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScrapSide {
    /// `"left"`: the side of `normal x tangent`.
    Left,
    /// `"right"`: the other side.
    Right,
}

impl ScrapSide {
    /// `"left"` or `"right"`, as the file writes it.
    pub fn name(self) -> &'static str {
        match self {
            ScrapSide::Left => "left",
            ScrapSide::Right => "right",
        }
    }
}

/// Ends of a curve closer than this are one point: the curve is closed and may carry `start`
/// (mm; the closure tolerance of the cut planning).
const CLOSED_TOLERANCE_MM: f64 = 1e-6;

/// Checks a curve's `start` and `scrap` keys against the built curve.
fn start_and_scrap(
    index: usize,
    curve: &NurbsCurve,
    start: Option<f64>,
    scrap: Option<&str>,
) -> Result<(Option<f64>, Option<ScrapSide>)> {
    if let Some(t) = start {
        let path = format!("curves[{index}].start");
        let (a, b) = curve.domain();
        if !t.is_finite() || t < a || t > b {
            return Err(FormatError::Shape {
                path,
                message: format!("{t} is outside the domain [{a}, {b}]"),
            });
        }
        let gap = (curve.point(a) - curve.point(b)).norm();
        if gap > CLOSED_TOLERANCE_MM {
            return Err(FormatError::Shape {
                path,
                message: format!(
                    "the curve is open (its ends are {gap:.6} mm apart); only a closed curve takes a start"
                ),
            });
        }
    }
    let side = match scrap {
        None => None,
        Some("left") => Some(ScrapSide::Left),
        Some("right") => Some(ScrapSide::Right),
        Some(other) => {
            return Err(FormatError::Shape {
                path: format!("curves[{index}].scrap"),
                message: format!(
                    "expected \"left\" or \"right\", got {}",
                    Value::String(other.to_owned())
                ),
            })
        }
    };
    Ok((start, side))
}

/// One surface.
#[derive(Debug, Clone, PartialEq)]
pub struct SurfaceRecord {
    /// Its id, unique among the surfaces.
    pub id: String,
    /// Its geometry.
    pub geometry: SurfaceGeometry,
    /// Where the geometry came from (for reports).
    pub source: SurfaceSource,
    /// Reverse the normal (the optional `flip` key).
    pub flip: bool,
}

/// The geometry of a surface.
#[derive(Debug, Clone, PartialEq)]
pub enum SurfaceGeometry {
    /// A NURBS surface; its normal is `Su x Sv` normalised.
    Nurbs(NurbsSurface),
    /// A triangle mesh (inline or from an STL file); its normal follows the triangles' winding
    /// (counter-clockwise seen from outside).
    ///
    /// Guarantees: vertices finite, indices in range, no triangle uses a vertex twice, at least
    /// one triangle of non-zero area. Other zero-area triangles (three distinct but collinear
    /// vertices) may remain; a consumer computing normals must skip them.
    Mesh {
        /// Vertex coordinates in mm.
        vertices: Vec<Point3<f64>>,
        /// Vertex indices of each triangle.
        triangles: Vec<[u32; 3]>,
    },
}

/// Where a surface's geometry came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SurfaceSource {
    /// Written in the JSON file (`"type": "nurbs"` or `"mesh"`).
    Inline,
    /// Read from an STL file (`"type": "stl"`).
    Stl {
        /// The file, resolved against the JSON file's directory.
        path: PathBuf,
        /// Facets dropped because two of their corners coincide (they have no normal).
        dropped_facets: usize,
    },
}

impl CurvesFile {
    /// The surface with this id.
    pub fn surface(&self, id: &str) -> Option<&SurfaceRecord> {
        self.surfaces.iter().find(|s| s.id == id)
    }

    /// The surface carrying `curve`, if it names one.
    pub fn surface_of(&self, curve: &CurveRecord) -> Option<&SurfaceRecord> {
        curve.surface.as_deref().and_then(|id| self.surface(id))
    }
}

impl SurfaceRecord {
    /// The `type` the surface has in the file: `nurbs`, `mesh` or `stl`.
    pub fn type_name(&self) -> &'static str {
        match (&self.geometry, &self.source) {
            (_, SurfaceSource::Stl { .. }) => "stl",
            (SurfaceGeometry::Nurbs(_), _) => "nurbs",
            (SurfaceGeometry::Mesh { .. }, _) => "mesh",
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Entry points.
// ---------------------------------------------------------------------------------------------

/// Reads and checks a `kerf.curves/1` file. STL paths are relative to the file's directory.
///
/// # Errors
/// Any [`FormatError`], wrapped in [`FormatError::File`] naming `path`.
pub fn load(path: impl AsRef<Path>) -> Result<CurvesFile> {
    let path = path.as_ref();
    let base_dir = path.parent().unwrap_or(Path::new(""));
    json::read_file(path)
        .and_then(|bytes| from_slice(&bytes, base_dir))
        .map_err(|e| e.in_file(path))
}

/// Reads and checks a `kerf.curves/1` document held in memory. STL paths are resolved against
/// `base_dir` (the directory the document would live in).
///
/// # Errors
/// Any [`FormatError`] about the document's content.
pub fn from_str(text: &str, base_dir: &Path) -> Result<CurvesFile> {
    from_slice(text.as_bytes(), base_dir)
}

/// Reads and checks a `kerf.curves/1` document from a reader (read to the end). STL paths are
/// resolved against `base_dir`.
///
/// # Errors
/// [`FormatError::Read`] if reading fails, else any [`FormatError`] about the content.
pub fn from_reader(reader: impl Read, base_dir: &Path) -> Result<CurvesFile> {
    from_slice(&json::read_all(reader)?, base_dir)
}

/// Reads a `kerf.curves/1` document into the raw structs, checking only its JSON shape,
/// `format` and `units`.
///
/// # Errors
/// [`FormatError::Empty`], [`FormatError::Syntax`], [`FormatError::NotAnObject`],
/// [`FormatError::UnsupportedFormat`], [`FormatError::UnsupportedUnits`],
/// [`FormatError::Shape`] or [`FormatError::UnknownSurfaceType`].
pub fn raw_from_slice(bytes: &[u8]) -> Result<RawCurvesFile> {
    raw_and_warnings(bytes).map(|(raw, _)| raw)
}

/// [`raw_from_slice`] with the near-miss keys of the document ([`CurvesFile::warnings`]).
fn raw_and_warnings(bytes: &[u8]) -> Result<(RawCurvesFile, Vec<UnknownKey>)> {
    if let Some(read) = raw_in_one_pass(bytes) {
        return Ok(read);
    }
    raw_and_warnings_careful(bytes)
}

/// The common document in one pass: straight into the typed structs, with every key of the
/// top level and of each curve one the format names. It gives up (`None`) on anything else (an
/// unknown or repeated key, a syntax or type error, the wrong `format` or `units`, a bad
/// surface), and the careful reader ([`raw_and_warnings_careful`]: a [`Value`] first, so that
/// errors name their JSON path and near-miss keys are found) reads the document again and
/// says what is wrong. So it accepts only documents the careful reader accepts, with the same
/// result (the same serde_json number parser builds the same doubles; the surfaces go through
/// the same [`raw_surface`]), and costs a failed attempt only on documents that are refused
/// or carry extension keys. On the 5,000-curve benchmark file it reads in about a third of
/// the careful reader's time (`docs/performance.md`).
fn raw_in_one_pass(bytes: &[u8]) -> Option<(RawCurvesFile, Vec<UnknownKey>)> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Body {
        format: String,
        units: String,
        curves: Vec<Curve>,
        #[serde(default)]
        surfaces: Vec<kerf_io::StrictValue>,
    }
    /// [`RawCurve`] with no key but its own.
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Curve {
        id: String,
        degree: usize,
        knots: Vec<f64>,
        control_points: Vec<[f64; 3]>,
        #[serde(default)]
        weights: Option<Vec<f64>>,
        #[serde(default)]
        surface: Option<SurfaceRef>,
        #[serde(default)]
        start: Option<f64>,
        #[serde(default)]
        scrap: Option<String>,
        #[serde(default)]
        on_surface_tolerance_mm: Option<f64>,
        #[serde(default)]
        sheet_thickness_mm: Option<f64>,
    }
    let body: Body = serde_json::from_slice(kerf_io::strip_bom(bytes)).ok()?;
    if body.format != CURVES_FORMAT || Units::from_name(&body.units).is_none() {
        return None;
    }
    // The surfaces' keys are not checked by the typed structs: their near misses as the
    // careful reader finds them.
    let mut doc = Map::new();
    doc.insert(
        "surfaces".into(),
        Value::Array(body.surfaces.into_iter().map(|v| v.0).collect()),
    );
    let warnings = keys::near_misses(&doc);
    let Some(Value::Array(values)) = doc.remove("surfaces") else {
        unreachable!("inserted above")
    };
    let surfaces = values
        .into_iter()
        .enumerate()
        .map(|(index, value)| raw_surface(index, value))
        .collect::<Result<_>>()
        .ok()?;
    let curves = body
        .curves
        .into_iter()
        .map(|c| RawCurve {
            id: c.id,
            degree: c.degree,
            knots: c.knots,
            control_points: c.control_points,
            weights: c.weights,
            surface: c.surface,
            start: c.start,
            scrap: c.scrap,
            on_surface_tolerance_mm: c.on_surface_tolerance_mm,
            sheet_thickness_mm: c.sheet_thickness_mm,
        })
        .collect();
    let raw = RawCurvesFile {
        format: body.format,
        units: body.units,
        curves,
        surfaces,
    };
    Some((raw, warnings))
}

/// [`raw_and_warnings`] through a [`Value`]: every error with its JSON path, near-miss keys
/// found.
fn raw_and_warnings_careful(bytes: &[u8]) -> Result<(RawCurvesFile, Vec<UnknownKey>)> {
    /// Everything but the surfaces, which are told apart by hand so that errors inside them
    /// keep their path (serde's internally tagged enums buffer their content and lose it).
    #[derive(Deserialize)]
    struct Body {
        format: String,
        units: String,
        curves: Vec<RawCurve>,
        #[serde(default)]
        surfaces: Vec<Value>,
    }
    let map = json::parse_document(bytes, CURVES_FORMAT)?;
    let warnings = keys::near_misses(&map);
    let named = |e| keys::name_the_misspelling(e, &warnings);
    let body: Body = json::deserialize(Value::Object(map), "").map_err(named)?;
    let surfaces = body
        .surfaces
        .into_iter()
        .enumerate()
        .map(|(index, value)| raw_surface(index, value))
        .collect::<Result<_>>()
        .map_err(named)?;
    let raw = RawCurvesFile {
        format: body.format,
        units: body.units,
        curves: body.curves,
        surfaces,
    };
    Ok((raw, warnings))
}

fn raw_surface(index: usize, value: Value) -> Result<RawSurface> {
    let prefix = format!("surfaces[{index}]");
    let Value::Object(map) = &value else {
        return Err(FormatError::Shape {
            message: format!(
                "expected an object {{\"id\": ..., \"type\": ...}}, got {}",
                json_type_name(&value)
            ),
            path: prefix,
        });
    };
    let kind = match map.get("type") {
        Some(Value::String(s)) => s.clone(),
        other => {
            return Err(FormatError::UnknownSurfaceType {
                index,
                found: other.map(Value::to_string),
            })
        }
    };
    match kind.as_str() {
        "nurbs" => json::deserialize(value, &prefix).map(RawSurface::Nurbs),
        "mesh" => json::deserialize(value, &prefix).map(RawSurface::Mesh),
        "stl" => json::deserialize(value, &prefix).map(RawSurface::Stl),
        _ => Err(FormatError::UnknownSurfaceType {
            index,
            found: Some(Value::String(kind).to_string()),
        }),
    }
}

fn from_slice(bytes: &[u8], base_dir: &Path) -> Result<CurvesFile> {
    let (raw, warnings) = raw_and_warnings(bytes)?;
    let file = from_raw(raw, base_dir)?;
    Ok(CurvesFile { warnings, ..file })
}

/// Checks raw data and builds the validated model. STL files are read, relative to
/// `base_dir`.
///
/// Checks, in this order, stopping at the first defect: `format` and `units`; each curve (id,
/// then the NURBS data, then that it is not a point: [`is_a_point`]); each surface (id, then
/// its geometry); each curve's `surface` reference.
///
/// # Errors
/// [`FormatError::UnsupportedFormat`], [`FormatError::UnsupportedUnits`],
/// [`FormatError::EmptyId`], [`FormatError::UnsafeText`], [`FormatError::DuplicateId`], [`FormatError::Curve`],
/// [`FormatError::PointCurve`], [`FormatError::Surface`], [`FormatError::Mesh`],
/// [`FormatError::Stl`] or [`FormatError::UnknownSurface`].
pub fn from_raw(raw: RawCurvesFile, base_dir: &Path) -> Result<CurvesFile> {
    let units = json::check_header(&raw.format, &raw.units, CURVES_FORMAT)?;

    let mut ids = IdSet::default();
    let mut curves = Vec::with_capacity(raw.curves.len());
    for (index, c) in raw.curves.into_iter().enumerate() {
        ids.insert("curves", index, &c.id)?;
        let points = c.control_points.iter().map(|&p| Point3::from(p)).collect();
        let curve = NurbsCurve::try_new(c.degree, c.knots, points, c.weights)
            .map_err(|error| FormatError::Curve { index, error })?;
        if is_a_point(&curve) {
            return Err(FormatError::PointCurve { index, id: c.id });
        }
        let named = c.surface.as_ref().map(SurfaceRef::ids).unwrap_or_default();
        if matches!(&c.surface, Some(SurfaceRef::Many(v)) if v.is_empty()) {
            return Err(FormatError::Shape {
                path: format!("curves[{index}].surface"),
                message: "an empty list of surface ids (omit the key for no surface)".into(),
            });
        }
        let (start, scrap) = start_and_scrap(index, &curve, c.start, c.scrap.as_deref())?;
        if let Some((key, message)) =
            length_key_error(c.on_surface_tolerance_mm, c.sheet_thickness_mm)
        {
            return Err(FormatError::Shape {
                path: format!("curves[{index}].{key}"),
                message,
            });
        }
        curves.push(CurveRecord {
            id: c.id,
            curve,
            surface: named.first().cloned(),
            surfaces: named,
            start,
            scrap,
            on_surface_tolerance_mm: c.on_surface_tolerance_mm,
            sheet_thickness_mm: c.sheet_thickness_mm,
        });
    }

    let mut ids = IdSet::default();
    let mut surfaces = Vec::with_capacity(raw.surfaces.len());
    for (index, s) in raw.surfaces.into_iter().enumerate() {
        let record = match s {
            RawSurface::Nurbs(n) => {
                ids.insert("surfaces", index, &n.id)?;
                let control_points = n
                    .control_points
                    .iter()
                    .map(|row| row.iter().map(|&p| Point3::from(p)).collect())
                    .collect();
                let surface = NurbsSurface::try_new(
                    n.degree_u,
                    n.degree_v,
                    n.knots_u,
                    n.knots_v,
                    control_points,
                    n.weights,
                )
                .map_err(|error| FormatError::Surface { index, error })?;
                SurfaceRecord {
                    flip: n.flip,
                    id: n.id,
                    geometry: SurfaceGeometry::Nurbs(surface),
                    source: SurfaceSource::Inline,
                }
            }
            RawSurface::Mesh(m) => {
                ids.insert("surfaces", index, &m.id)?;
                let vertices: Vec<Point3<f64>> =
                    m.vertices.iter().map(|&p| Point3::from(p)).collect();
                check_mesh(&vertices, &m.triangles)
                    .map_err(|defect| FormatError::Mesh { index, defect })?;
                SurfaceRecord {
                    flip: m.flip,
                    id: m.id,
                    geometry: SurfaceGeometry::Mesh {
                        vertices,
                        triangles: m.triangles,
                    },
                    source: SurfaceSource::Inline,
                }
            }
            RawSurface::Stl(s) => {
                ids.insert("surfaces", index, &s.id)?;
                let file = base_dir.join(&s.path);
                let mesh = stl::read(&file).map_err(|problem| FormatError::Stl {
                    index,
                    file: file.clone(),
                    problem,
                })?;
                SurfaceRecord {
                    flip: s.flip,
                    id: s.id,
                    geometry: SurfaceGeometry::Mesh {
                        vertices: mesh.vertices,
                        triangles: mesh.triangles,
                    },
                    source: SurfaceSource::Stl {
                        path: file,
                        dropped_facets: mesh.dropped_facets,
                    },
                }
            }
        };
        surfaces.push(record);
    }

    for (index, c) in curves.iter().enumerate() {
        for id in &c.surfaces {
            if !surfaces.iter().any(|s| &s.id == id) {
                return Err(FormatError::UnknownSurface {
                    index,
                    id: id.clone(),
                    available: surfaces.iter().map(|s| s.id.clone()).collect(),
                });
            }
        }
    }

    Ok(CurvesFile {
        units,
        curves,
        surfaces,
        warnings: Vec::new(),
    })
}

pub use crate::error::POINT_CURVE;

/// The smallest control-point spread, mm, that is a contour wherever the coordinates are
/// small; see [`is_a_point`].
pub const POINT_SPREAD_MM: f64 = 1e-12;

/// Whether `curve` is a point, not a contour: the diagonal of its control points' bounding
/// box ([`NurbsCurve::size`]; the curve lies in that box) is at most
/// `max(POINT_SPREAD_MM, 16 eps m)`, where `m` is the largest magnitude of any control point's
/// coordinate and `eps = 2^-52` ([`f64::EPSILON`]). The second term is the round-off of the
/// coordinates themselves (16 units in the last place of the largest): control points that
/// differ by less than that differ by how they were computed, not by geometry. A curve whose
/// control points are not all at one place has a length, however small: a circle of radius
/// 1e-8 mm is a contour (its box is 2.8e-8 mm across) anywhere within 1e6 mm (a kilometre) of
/// the origin. A non-finite box (impossible for a checked curve) is not called a point.
pub fn is_a_point(curve: &NurbsCurve) -> bool {
    let (lo, hi) = curve.bounding_box();
    let m = lo.coords.amax().max(hi.coords.amax());
    let spread = POINT_SPREAD_MM.max(16.0 * f64::EPSILON * m);
    spread.is_finite() && curve.size() <= spread
}

/// Checks an inline mesh: finite vertices, indices in range, no repeated corner, at least one
/// triangle of non-zero area.
pub(crate) fn check_mesh(
    vertices: &[Point3<f64>],
    triangles: &[[u32; 3]],
) -> std::result::Result<(), MeshDefect> {
    for (vertex, p) in vertices.iter().enumerate() {
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(MeshDefect::NonFiniteVertex {
                vertex,
                x: p.x,
                y: p.y,
                z: p.z,
            });
        }
    }
    if triangles.is_empty() {
        return Err(MeshDefect::NoTriangles);
    }
    let mut any_area = false;
    for (triangle, t) in triangles.iter().enumerate() {
        for (corner, &index) in t.iter().enumerate() {
            if index as usize >= vertices.len() {
                return Err(MeshDefect::IndexOutOfRange {
                    triangle,
                    corner,
                    index,
                    count: vertices.len(),
                });
            }
            if t[..corner].contains(&index) {
                return Err(MeshDefect::RepeatedVertex { triangle, index });
            }
        }
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        any_area |= (b - a).cross(&(c - a)).norm() > 0.0;
    }
    if !any_area {
        return Err(MeshDefect::AllDegenerate);
    }
    Ok(())
}

/// Tracks the ids of one list (`curves`, `surfaces` or `paths`) to report empty, unsafe and
/// duplicate ones.
#[derive(Default)]
pub(crate) struct IdSet {
    seen: HashMap<String, usize>,
}

impl IdSet {
    /// Records the id of `list[index]`.
    pub(crate) fn insert(&mut self, list: &str, index: usize, id: &str) -> Result<()> {
        if id.is_empty() {
            return Err(FormatError::EmptyId {
                path: format!("{list}[{index}].id"),
            });
        }
        if let Err(defect) = kerf_io::check_text(id) {
            return Err(FormatError::UnsafeText {
                path: format!("{list}[{index}].id"),
                defect,
            });
        }
        if let Some(&first) = self.seen.get(id) {
            return Err(FormatError::DuplicateId {
                path: format!("{list}[{index}].id"),
                id: id.to_owned(),
                first: format!("{list}[{first}]"),
            });
        }
        self.seen.insert(id.to_owned(), index);
        Ok(())
    }
}

/// Writes a raw `kerf.curves/1` document as JSON to `dest` through the one writer
/// ([`kerf_io::write_file`]: atomic for regular files, written through for devices, FIFOs and
/// `-`). It does not check
/// the content: pass it through [`from_raw`] first.
///
/// # Errors
/// [`FormatError::Write`], wrapped in [`FormatError::File`] naming `dest`.
pub fn write_raw(file: &RawCurvesFile, dest: impl AsRef<Path>) -> Result<()> {
    use std::io::Write;
    let dest = dest.as_ref();
    let json = |w: &mut dyn Write| -> std::io::Result<()> {
        serde_json::to_writer_pretty(&mut *w, file).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    };
    let result = kerf_io::write_file(dest, json);
    result
        .map_err(|error| FormatError::Write { error })
        .map_err(|e| e.in_file(dest))
}

#[cfg(test)]
mod tests;
