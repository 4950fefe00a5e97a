//! Reads and writes kerf's file formats: `kerf.curves/1` in, `kerf.toolpath/1` out.
//!
//! The formats are specified in `docs/formats.md`; this crate is their one implementation.
//!
//! - [`curves`] reads cut contours: JSON to raw serde structs mirroring the file
//!   ([`curves::RawCurvesFile`]), then to a validated model ([`CurvesFile`]) of
//!   [`kerf_nurbs::NurbsCurve`]s and their carrying surfaces (NURBS, inline meshes, STL files
//!   read by [`stl`]).
//! - [`toolpath`] writes (atomically) and reads back cutting points ([`ToolpathFile`]).
//! - [`Pose`], a cutting point with its tool axis: the one pose type of every stage.
//!
//! Every error names the JSON path of the defect, in the style
//! `curves[3].knots[5]: knots must be non-decreasing (0.5 after 0.7)`; errors of functions that
//! take a file path are prefixed with the path (see [`FormatError`]).
//!
//! ```no_run
//! let file = kerf_format::curves::load("fixtures/circle.json")?;
//! for c in &file.curves {
//!     println!("{}: degree {}, {:.3} mm", c.id, c.curve.degree(), c.curve.arc_length());
//! }
//! # Ok::<(), kerf_format::FormatError>(())
//! ```

use std::fmt;

use serde::{Deserialize, Serialize};

pub mod curves;
pub mod error;
mod json;
mod pose;
pub mod stl;
pub mod toolpath;

pub use curves::{
    CurveRecord, CurvesFile, ScrapSide, SurfaceGeometry, SurfaceRecord, SurfaceRef, SurfaceSource,
    UnknownKey, MAX_CURVE_ON_SURFACE_TOLERANCE_MM, MAX_SHEET_THICKNESS_MM,
};
pub use error::{FormatError, MeshDefect, Result, StlProblem};
pub use pose::Pose;
pub use toolpath::{KerfOffset, ToolpathFile, ToolpathPoints, ToolpathRecord};

/// The `format` string of curve files.
pub const CURVES_FORMAT: &str = "kerf.curves/1";

/// The `format` string of toolpath files.
pub const TOOLPATH_FORMAT: &str = "kerf.toolpath/1";

/// The length unit of a document. kerf works in millimetres only; the `units` key exists so
/// that a file in another unit is refused instead of being cut 25.4 times too small.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Units {
    /// Millimetres, written `"mm"`.
    #[default]
    #[serde(rename = "mm")]
    Millimetres,
}

impl Units {
    /// The name written in files: `mm`.
    pub fn name(self) -> &'static str {
        match self {
            Units::Millimetres => "mm",
        }
    }

    /// The unit written `name` in a file, if kerf supports it.
    pub fn from_name(name: &str) -> Option<Units> {
        (name == "mm").then_some(Units::Millimetres)
    }
}

impl fmt::Display for Units {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}
