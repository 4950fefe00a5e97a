//! Independent verification of `kerf.toolpath/1` files against the curves they discretize.
//!
//! The discretizer (crate `kerf-discretize`) proves a chord-error bound for every segment it
//! writes. This crate does not trust that proof, nor any other tool's: it reads a toolpath
//! leniently ([`RawToolpath`], so that a file kerf would refuse still gets every defect listed),
//! and [`check()`] measures every segment's chord error by brute force ([`segment_chord_error`]: dense
//! sampling between the two params including every knot inside, then golden-section
//! refinement of each local maximum), and checks every rule of the format
//! (`docs/formats.md`): same ids in the same order, params strictly increasing from one end
//! of the domain to the other, every point on the curve at its param (to `1e-9` of the curve
//! size, plus two ulps of the point's coordinates), every C0 corner a cutting point, unit
//! normals, every segment's chord error at most the tolerance and a `max_chord_error` claim that
//! does not understate the measurement; a path's optional `kerf_offset` (the path offset by
//! half the kerf) is measured against the exact offset of the curve and for the gouge
//! ([`OffsetReport`]). Distances are measured about the curve's local origin
//! ([`kerf_nurbs::LocalCurve`], an exact translation), so a curve 1e6 mm from the origin is
//! measured with the rounding of its own size.
//!
//! The measurement is an estimate from below of the true chord error (the maximum of a
//! distance is found by sampling and local search, not proved), good to about `1e-12` of the
//! curve size on smooth segments; it is a check of the discretizer's guarantee, not a second
//! guarantee.
//!
//! ```
//! use kerf_check::{check, CheckOptions, RawToolpath};
//!
//! let curves = kerf_format::curves::from_str(
//!     r#"{"format": "kerf.curves/1", "units": "mm", "curves": [{"id": "arc", "degree": 2,
//!         "knots": [0, 0, 0, 1, 1, 1], "control_points": [[0, 0, 0], [10, 10, 0], [20, 0, 0]]}]}"#,
//!     std::path::Path::new("."),
//! )?;
//! // Two points only: the chord misses the arc's apex (5 mm away) by far.
//! let toolpath = RawToolpath::from_slice(
//!     br#"{"format": "kerf.toolpath/1", "units": "mm", "tolerance": 0.01, "paths": [
//!         {"id": "arc", "params": [0, 1], "points": [[0, 0, 0], [20, 0, 0]], "max_chord_error": 0}]}"#,
//! )?;
//! let report = check(&curves.curves, &toolpath, &CheckOptions::default());
//! assert!(!report.passed(), "one segment cannot follow the arc");
//! assert!((report.paths[0].measured_chord_error - 5.0).abs() < 1e-12, "the apex is 5 mm off the chord");
//! for v in &report.violations {
//!     println!("{v}"); // paths[0] ("arc"): segment 0 (t 0 .. 1): chord error 5.000000e0 mm > ...
//! }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod check;
mod error;
mod input;
mod measure;

pub use check::{
    check, CheckOptions, Defect, OffsetReport, PathReport, Report, Violation, WorstSegment,
    MAX_SAMPLES, ROUNDING_ALLOWANCE,
};
pub use error::{CheckError, Result};
pub use input::{RawPathRecord, RawToolpath};
/// The point-to-segment distance of the checker's dense sampling (the one implementation, in `kerf-nurbs`).
pub use kerf_nurbs::distance_to_segment;
pub use measure::{segment_chord_error, SegmentError};
