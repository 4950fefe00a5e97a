//! Rational B-spline curves and surfaces for kerf.
//!
//! Everything downstream of the file reader evaluates geometry through this crate: points,
//! derivatives of any order, curvature, arc length, knot insertion, the rational Bezier pieces of
//! any sub-interval (on which the discretizer's chord-error proof rests) and closest points.
//! The algorithms follow Piegl and Tiller, *The NURBS Book* (2nd ed.); `docs/nurbs.md` derives
//! the formulas.
//!
//! ```
//! use kerf_nurbs::NurbsCurve;
//! use nalgebra::Point3;
//!
//! // A quarter of the unit circle as a rational quadratic.
//! let h = std::f64::consts::FRAC_1_SQRT_2;
//! let arc = NurbsCurve::try_new(
//!     2,
//!     vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
//!     vec![Point3::new(1.0, 0.0, 0.0), Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)],
//!     Some(vec![1.0, h, 1.0]),
//! )?;
//! let p = arc.point(0.3);
//! assert!((p.coords.norm() - 1.0).abs() < 1e-15, "every point lies on the circle");
//! assert!((arc.curvature(0.7) - 1.0).abs() < 1e-12, "curvature of the unit circle is 1");
//! # Ok::<(), kerf_nurbs::NurbsError>(())
//! ```

mod arclength;
mod basis;
mod bezier;
mod closest;
mod curve;
mod error;
mod geom;
mod knots;
mod local;
mod param;
mod queue;
#[cfg(feature = "samples")]
mod samples;
mod shapes;
mod surface;
mod work;

pub use arclength::{
    gauss10, integrate, Bracket, Quadrature, GL10_NODES, GL10_WEIGHTS, LENGTH_RELATIVE_ACCURACY,
    SPLITS_PER_SPAN,
};
pub use basis::{basis_funs, basis_funs_m, binomial, ders_basis_funs, ders_basis_funs_m};
pub use bezier::RationalBezier;
pub use closest::{CurveProjection, CLOSEST_POPS_PER_PIECE};
pub use curve::{
    curvature_of, hull_box, normalized_weights, project, rational_from_homogeneous, scale_pow2,
    FrenetFrame, NurbsCurve, MIN_NORMALISED_WEIGHT,
};
pub use error::{NurbsError, Readable, Result};
pub use geom::{distance_to_box, distance_to_segment, nearest_on_segment, Segment};
pub use knots::{find_span, interior_knots, multiplicity, validate as validate_knots};
pub use local::{is_power_of_two, LocalCurve};
pub use param::CurvePoint;
#[cfg(feature = "samples")]
pub use samples::{smooth_random_curves, Lcg};
pub use surface::{
    NurbsSurface, OffsetSurface, SurfaceOffsetError, SurfaceOffsetOptions, SurfaceProjection,
    MAX_OFFSET_DEGREE, MAX_OFFSET_DEGREE_RATIONAL,
};
pub use work::{counted, evaluations, knot_reads, tick, tick_knots};

/// The largest degree kerf accepts. CAD systems use degree <= 11 in practice; the fixed-size
/// scratch arrays of the evaluator are sized by this constant.
pub const MAX_DEGREE: usize = 24;

/// `MAX_DEGREE + 1`: the most basis functions that are non-zero at one parameter.
pub const MAX_ORDER: usize = MAX_DEGREE + 1;
