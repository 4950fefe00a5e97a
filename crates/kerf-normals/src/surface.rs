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

    /// True if the foot `foot` (a projection's hint) is a degenerate point of the surface,
    /// such as a collapsed edge or a cone's apex, where the normal depends on the direction
    /// from which the point is approached. The default (meshes): never.
    fn is_degenerate(&self, _foot: Hint) -> bool {
        false
    }

    /// At a degenerate `foot`, the normal as the limit approached from `toward` (a nearby point
    /// of the curve on the side of interest), with the hint there; `None` where the foot is
    /// not degenerate or the limit is undefined. The default: `None`.
    fn normal_from(&self, _foot: Hint, _toward: &Point3<f64>) -> Option<(Vector3<f64>, Hint)> {
        None
    }
}

/// A point where one partial derivative is below this fraction of the other is degenerate
/// (a collapsed edge: every `u` maps to the same point).
const DEGENERATE: f64 = 1e-9;

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

    fn is_degenerate(&self, foot: Hint) -> bool {
        self.collapsed_parameter(foot).is_some()
    }

    /// The collapsed parameter at the foot is replaced by the one of `toward`'s own foot
    /// (found globally: a warm start at the apex would stay there): at a cone's apex, the
    /// normal along the generator `toward` lies on.
    fn normal_from(&self, foot: Hint, toward: &Point3<f64>) -> Option<(Vector3<f64>, Hint)> {
        let along_u = self.collapsed_parameter(foot)?;
        let Hint::Uv(u, v) = foot else {
            return None;
        };
        let there = self.surface.closest_point(toward, None);
        let (uu, vv) = if along_u { (there.u, v) } else { (u, there.v) };
        let n = self.surface.normal(uu, vv)?;
        Some((if self.flip { -n } else { n }, Hint::Uv(uu, vv)))
    }
}

impl NurbsNormals {
    /// At a degenerate foot, whether it is `u` (true) or `v` (false) that does not move the
    /// point; `None` at a regular point.
    fn collapsed_parameter(&self, foot: Hint) -> Option<bool> {
        let Hint::Uv(u, v) = foot else {
            return None;
        };
        let (_, su, sv) = self.surface.eval_d1(u, v);
        let (a, b) = (su.norm(), sv.norm());
        if a <= DEGENERATE * b {
            Some(true)
        } else if b <= DEGENERATE * a {
            Some(false)
        } else {
            None
        }
    }
}
