//! NURBS surfaces (to be completed).

/// A NURBS surface.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {}

/// Result of projecting a point onto a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceProjection {
    /// u parameter.
    pub u: f64,
    /// v parameter.
    pub v: f64,
    /// Distance.
    pub distance: f64,
}
