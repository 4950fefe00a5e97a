//! The error type of the NURBS crate.

use thiserror::Error;

/// Everything that can be wrong with the data of a NURBS curve or surface, or with a request
/// made of one.
///
/// Each variant names the offending field (`knots`, `knots_u`, `weights`, ...) and index, so that
/// a file reader can prefix it with the JSON path of the curve and produce messages such as
/// `curves[3].knots[5]: knots must be non-decreasing (0.5 after 0.7)`.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum NurbsError {
    /// The degree is 0. Fix: a polyline is degree 1; use at least 1.
    #[error("{field}: degree must be at least 1 (got 0)")]
    DegreeZero {
        /// `degree`, `degree_u` or `degree_v`.
        field: &'static str,
    },
    /// The degree is above [`crate::MAX_DEGREE`]. Fix: reduce the degree (CAD systems stay
    /// far below this limit; such a degree is almost certainly a corrupt file).
    #[error("{field}: degree {degree} is above the maximum {max}")]
    DegreeTooHigh {
        /// `degree`, `degree_u` or `degree_v`.
        field: &'static str,
        /// The degree found.
        degree: usize,
        /// The largest degree supported.
        max: usize,
    },
    /// Fewer control points than `degree + 1`. Fix: lower the degree or add control points.
    #[error(
        "{field}: {got} control points are too few for degree {degree} (need at least {needed})"
    )]
    TooFewPoints {
        /// `control_points` (or the direction of a surface).
        field: &'static str,
        /// The number found.
        got: usize,
        /// The degree.
        degree: usize,
        /// `degree + 1`.
        needed: usize,
    },
    /// The knot vector does not have `points + degree + 1` entries. Fix: supply the full knot
    /// vector (including the end knots).
    #[error("{field}: expected {expected} knots (control points + degree + 1), got {got}")]
    KnotCount {
        /// `knots`, `knots_u` or `knots_v`.
        field: &'static str,
        /// Control points + degree + 1.
        expected: usize,
        /// The number found.
        got: usize,
    },
    /// A knot is NaN or infinite.
    #[error("{field}[{index}]: knot must be finite (got {})", Readable(*.value))]
    KnotNotFinite {
        /// `knots`, `knots_u` or `knots_v`.
        field: &'static str,
        /// Index of the knot.
        index: usize,
        /// The value found.
        value: f64,
    },
    /// A knot is smaller than the one before it. Fix: sort the knot vector.
    #[error("{field}[{index}]: knots must be non-decreasing ({} after {})", Readable(*.value), Readable(*.previous))]
    KnotsDecreasing {
        /// `knots`, `knots_u` or `knots_v`.
        field: &'static str,
        /// Index of the knot that is smaller than its predecessor.
        index: usize,
        /// Its value.
        value: f64,
        /// The predecessor's value.
        previous: f64,
    },
    /// A knot value is repeated more than `degree + 1` times. Fix: remove the extra copies.
    #[error("{field}[{index}]: knot {} is repeated {multiplicity} times, more than degree + 1 = {max}", Readable(*.value))]
    KnotMultiplicity {
        /// `knots`, `knots_u` or `knots_v`.
        field: &'static str,
        /// Index of the first copy beyond the allowed multiplicity.
        index: usize,
        /// The knot value.
        value: f64,
        /// How often it occurs.
        multiplicity: usize,
        /// `degree + 1`.
        max: usize,
    },
    /// The domain `[knots[p], knots[len - p - 1]]` has zero length. Fix: the knot vector must
    /// span a non-empty parameter interval.
    #[error("{field}: empty parameter domain [{}, {}]", Readable(*.start), Readable(*.end))]
    EmptyDomain {
        /// `knots`, `knots_u` or `knots_v`.
        field: &'static str,
        /// First parameter of the domain.
        start: f64,
        /// Last parameter of the domain.
        end: f64,
    },
    /// A control point coordinate is NaN or infinite.
    #[error("{field}{index}: control point must be finite (got [{}, {}, {}])", Readable(*.x), Readable(*.y), Readable(*.z))]
    PointNotFinite {
        /// `control_points`.
        field: &'static str,
        /// Index as written in a path: `[3]` for a curve, `[2][5]` for a surface.
        index: String,
        /// x coordinate.
        x: f64,
        /// y coordinate.
        y: f64,
        /// z coordinate.
        z: f64,
    },
    /// A weight times a coordinate of its control point overflows double precision (both are
    /// finite, but `w * x` is not), so the curve cannot be evaluated. Fix: scale the weights
    /// down (only their ratios matter) or the coordinates.
    #[error(
        "{field}{index}: weight {weight:e} times the control point overflows double precision"
    )]
    HomogeneousOverflow {
        /// `weights`.
        field: &'static str,
        /// Index as written in a path: `[3]`.
        index: String,
        /// The weight.
        weight: f64,
    },
    /// The largest weight is so many times the smallest (more than about `2^970`) that,
    /// scaled so the largest is 1, the smallest is near the subnormal range: the homogeneous coordinates
    /// `w x` would keep only a few significant bits, and evaluation would be wrong by far more
    /// than rounding. Fix: the curve is almost certainly corrupt; rebuild it with moderate
    /// weights (only their ratios matter).
    #[error("{field}{index}: weights differ by a ratio of {ratio:.3e}, beyond double precision")]
    WeightRatio {
        /// `weights`.
        field: &'static str,
        /// Index of the smallest weight, as written in a path: `[3]` or `[2][5]`.
        index: String,
        /// Largest weight divided by smallest.
        ratio: f64,
    },
    /// The number of weights differs from the number of control points.
    #[error("{field}: expected {expected} weights (one per control point), got {got}")]
    WeightCount {
        /// `weights`.
        field: &'static str,
        /// The number of control points.
        expected: usize,
        /// The number of weights.
        got: usize,
    },
    /// A weight is NaN, infinite, zero or negative. Fix: NURBS weights must be finite and > 0;
    /// a zero weight puts the curve at infinity.
    #[error("{field}{index}: weight must be finite and > 0 (got {})", Readable(*.value))]
    BadWeight {
        /// `weights`.
        field: &'static str,
        /// Index as written in a path: `[3]` or `[2][5]`.
        index: String,
        /// The value found.
        value: f64,
    },
    /// The rows of a surface's control net (or weights) differ in length.
    #[error("{field}[{row}]: row has {got} entries, expected {expected}")]
    RaggedGrid {
        /// `control_points` or `weights`.
        field: &'static str,
        /// Index of the offending row.
        row: usize,
        /// Its length.
        got: usize,
        /// The length of row 0.
        expected: usize,
    },
    /// A parameter passed to an operation is NaN or lies outside the domain.
    #[error("parameter {} is outside the domain [{}, {}]", Readable(*.value), Readable(*.start), Readable(*.end))]
    ParameterOutsideDomain {
        /// The parameter.
        value: f64,
        /// Start of the domain.
        start: f64,
        /// End of the domain.
        end: f64,
    },
    /// A knot insertion would raise a knot's multiplicity above the degree.
    #[error(
        "inserting {value} {times} times would raise its multiplicity above the degree {degree}"
    )]
    InsertionTooMany {
        /// The knot value.
        value: f64,
        /// Requested insertions.
        times: usize,
        /// The degree.
        degree: usize,
    },
    /// A shape constructor (`NurbsCurve::circle`, `NurbsSurface::cylinder`, ...) was given a
    /// non-finite value, a zero radius or length, a zero or parallel axis, or a sweep outside
    /// `0 < |sweep| <= 2 pi`. Fix: the message names the argument and what it must be.
    #[error("{field}: {reason}")]
    BadShape {
        /// The argument: `radius`, `axis_dir`, `points[3]`, ...
        field: &'static str,
        /// What is wrong with it, with the value found.
        reason: String,
    },
    /// A parameter interval `[t0, t1]` is empty or reversed.
    #[error("interval [{}, {}] is empty or reversed", Readable(*.t0), Readable(*.t1))]
    BadInterval {
        /// Start.
        t0: f64,
        /// End.
        t1: f64,
    },
}

/// A number formatted for a message: the shortest round-trip digits when its magnitude is
/// between `1e-4` and `1e9` (or zero), scientific notation otherwise, so that `1e-50` prints as
/// `1e-50` rather than as 52 characters of zeros.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readable(pub f64);

impl std::fmt::Display for Readable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-4..1e9).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// `Result` with [`NurbsError`].
pub type Result<T> = std::result::Result<T, NurbsError>;
