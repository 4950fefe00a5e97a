//! Closest point on a curve (to be completed).

/// Result of projecting a point onto a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveProjection {
    /// Parameter of the closest point.
    pub t: f64,
    /// Distance from the query point to the curve.
    pub distance: f64,
}
