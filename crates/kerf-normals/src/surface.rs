//! "A surface kerf can take normals from": the trait and its NURBS implementation.

use kerf_nurbs::NurbsSurface;
use nalgebra::{Point3, Vector3};

/// Where a previous projection landed, to warm-start the next one.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Hint {
    /// No previous projection.
    #[default]
    None,
    /// Surface parameters of a NURBS surface.
    Uv(f64, f64),
    /// A triangle of a mesh.
    Triangle(u32),
}

/// The closest point of a surface to a query point, with the surface's unit normal there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// The closest surface point.
    pub point: Point3<f64>,
    /// Distance from the query point.
    pub distance: f64,
    /// The unit normal at the closest point (oriented as the surface says, after `flip`), or
    /// `None` where the surface has none.
    pub normal: Option<Vector3<f64>>,
    /// Where it landed (warm start for the next query).
    pub hint: Hint,
}

/// A surface kerf can take normals from.
pub trait NormalSource: Send + Sync {
    /// The closest point to `p`, its distance and the unit normal there; `hint` is where the
    /// previous (nearby) query landed.
    fn project(&self, p: &Point3<f64>, hint: Hint) -> Projection;
}

/// A NURBS surface as a normal source: normal `Su x Sv` normalised (reversed if `flip`), at
/// the global closest point, warm-started from the previous point's `(u, v)`.
#[derive(Debug, Clone)]
pub struct NurbsNormals {
    surface: NurbsSurface,
    flip: bool,
}

impl NurbsNormals {
    /// Wraps a surface; `flip` reverses its normal.
    pub fn new(surface: NurbsSurface, flip: bool) -> Self {
        Self { surface, flip }
    }

    /// The surface.
    pub fn surface(&self) -> &NurbsSurface {
        &self.surface
    }
}

impl NormalSource for NurbsNormals {
    fn project(&self, p: &Point3<f64>, hint: Hint) -> Projection {
        let warm = match hint {
            Hint::Uv(u, v) => Some((u, v)),
            _ => None,
        };
        let pr = self.surface.closest_point(p, warm);
        let normal = self
            .surface
            .normal(pr.u, pr.v)
            .map(|n| if self.flip { -n } else { n });
        Projection {
            point: pr.point,
            distance: pr.distance,
            normal,
            hint: Hint::Uv(pr.u, pr.v),
        }
    }
}
