//! Space lines and space arcs through three points (paper 000, eq 1-12).

use nalgebra::{Point3, Vector3};

use crate::error::{InterpError, Result};

/// A space arc through three points `P1, P2, P3` (paper 000 eq 5-8).
///
/// The centre `O'` is the point of the plane `P1 P2 P3` equidistant from the three points (the
/// intersection of the bisector planes of `P1P2` and `P2P3` with the arc's plane); the local
/// frame is `e1 = O'P1 / R`, `e3 = N / |N|` with `N = (P2 - P1) x (P3 - P2)`, `e2 = e3 x e1`.
/// In that frame the arc runs counter-clockwise from angle 0 (at `P1`) through `angle_mid`
/// (at `P2`) to `angle_end` (at `P3`), all in `(0, 2 pi)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpaceArc {
    /// Start point `P1`.
    pub start: Point3<f64>,
    /// Intermediate point `P2`.
    pub mid: Point3<f64>,
    /// End point `P3`.
    pub end: Point3<f64>,
    /// Centre `O'`.
    pub centre: Point3<f64>,
    /// Radius `R`, mm.
    pub radius: f64,
    /// `e1`: from the centre toward `P1`.
    pub e1: Vector3<f64>,
    /// `e2 = e3 x e1`.
    pub e2: Vector3<f64>,
    /// `e3`: the arc's normal, right-handed with the direction of travel.
    pub e3: Vector3<f64>,
    /// Swept angle from `P1` to `P2`, radians (`alpha_12` in the paper).
    pub angle_mid: f64,
    /// Swept angle from `P1` to `P3`, radians (`alpha_12 + alpha_23`).
    pub angle_end: f64,
}

impl SpaceArc {
    /// The arc through `p1`, `p2`, `p3`, in that order.
    ///
    /// # Errors
    /// [`InterpError::CollinearArc`] when the points are collinear or two coincide (relative
    /// test: `|P1P2 x P2P3| <= 1e-12 |P1P2| |P2P3|`), [`InterpError::NonFinite`] for NaN input.
    pub fn through(p1: Point3<f64>, p2: Point3<f64>, p3: Point3<f64>) -> Result<Self> {
        for (i, p) in [p1, p2, p3].iter().enumerate() {
            if !p.coords.iter().all(|v| v.is_finite()) {
                return Err(InterpError::NonFinite { index: i });
            }
        }
        let a = p2 - p1;
        let b = p3 - p2;
        let n = a.cross(&b);
        let nn = n.norm();
        if nn.is_nan() || nn <= 1e-12 * a.norm() * b.norm() || nn == 0.0 {
            return Err(InterpError::CollinearArc { cross: nn });
        }
        // Circumcentre of the triangle, with P1 as origin: u = P2 - P1, v = P3 - P1, w = u x v:
        // O = P1 + (|u|^2 (v x w) + |v|^2 (w x u)) / (2 |w|^2). It lies in the plane and is
        // equidistant from the three points, i.e. on both bisector planes (paper's Fig. 1).
        let u = a;
        let v = p3 - p1;
        let w = u.cross(&v);
        let w2 = w.norm_squared();
        let centre =
            p1 + (v.cross(&w) * u.norm_squared() + w.cross(&u) * v.norm_squared()) / (2.0 * w2);
        let r1 = p1 - centre;
        let radius = r1.norm();
        let e1 = r1 / radius;
        let e3 = n / nn;
        let e2 = e3.cross(&e1);
        let angle = |p: &Point3<f64>| {
            let d = p - centre;
            let t = d.dot(&e2).atan2(d.dot(&e1));
            if t < 0.0 {
                t + std::f64::consts::TAU
            } else {
                t
            }
        };
        let angle_mid = angle(&p2);
        let angle_end = angle(&p3);
        if !(angle_mid > 0.0 && angle_end > angle_mid) {
            // Only rounding can order them otherwise (nearly collinear points).
            return Err(InterpError::CollinearArc { cross: nn });
        }
        Ok(Self {
            start: p1,
            mid: p2,
            end: p3,
            centre,
            radius,
            e1,
            e2,
            e3,
            angle_mid,
            angle_end,
        })
    }

    /// Length of the arc, mm.
    pub fn length(&self) -> f64 {
        self.radius * self.angle_end
    }

    /// Arc length from `P1` to `P2`, mm.
    pub fn length_to_mid(&self) -> f64 {
        self.radius * self.angle_mid
    }

    /// The point at swept angle `theta` (radians from `P1`): `O' + R (cos theta e1 + sin theta
    /// e2)`, paper 000 eq 6-8. Returns `P3` itself at `theta >= angle_end` and `P1` at
    /// `theta <= 0`, so that a block ends exactly on its end point.
    #[inline]
    pub fn point_at_angle(&self, theta: f64) -> Point3<f64> {
        if theta >= self.angle_end {
            return self.end;
        }
        if theta <= 0.0 {
            return self.start;
        }
        let (s, c) = theta.sin_cos();
        self.centre + (self.e1 * c + self.e2 * s) * self.radius
    }

    /// Unit tangent (direction of travel) at swept angle `theta`.
    pub fn tangent_at_angle(&self, theta: f64) -> Vector3<f64> {
        let (s, c) = theta.sin_cos();
        self.e2 * c - self.e1 * s
    }

    /// Distance from `p` to the arc (not the full circle): to the circle if `p` projects inside
    /// the swept angle, else to the nearer end. Also returns the swept angle of `p`'s
    /// projection in `[0, 2 pi)`.
    pub fn distance(&self, p: &Point3<f64>) -> (f64, f64) {
        let d = p - self.centre;
        let x = d.dot(&self.e1);
        let y = d.dot(&self.e2);
        let z = d.dot(&self.e3);
        let mut t = y.atan2(x);
        if t < 0.0 {
            t += std::f64::consts::TAU;
        }
        if t <= self.angle_end {
            let rho = (x * x + y * y).sqrt();
            (((rho - self.radius).powi(2) + z * z).sqrt(), t)
        } else {
            let to_start = (p - self.start).norm();
            let to_end = (p - self.end).norm();
            (to_start.min(to_end), t)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn arc_in_a_tilted_plane() {
        // Circle of radius 5 about (1, 2, 3) in the plane spanned by a, b (orthonormal).
        let c = Point3::new(1.0, 2.0, 3.0);
        let a = Vector3::new(1.0, 1.0, 0.0).normalize();
        let b = Vector3::new(-1.0, 1.0, 1.0).normalize();
        let at = |t: f64| c + (a * t.cos() + b * t.sin()) * 5.0;
        let arc = SpaceArc::through(at(0.2), at(1.0), at(2.5)).expect("arc");
        assert_relative_eq!(arc.radius, 5.0, epsilon = 1e-12);
        assert_relative_eq!((arc.centre - c).norm(), 0.0, epsilon = 1e-12);
        assert_relative_eq!(arc.angle_mid, 0.8, epsilon = 1e-12);
        assert_relative_eq!(arc.angle_end, 2.3, epsilon = 1e-12);
        assert_relative_eq!(
            (arc.point_at_angle(1.3) - at(1.5)).norm(),
            0.0,
            epsilon = 1e-12
        );
        assert_eq!(arc.point_at_angle(arc.angle_end), at(2.5), "end exact");
        // Reverse direction: e3 flips, angles are the same.
        let rev = SpaceArc::through(at(2.5), at(1.0), at(0.2)).expect("arc");
        assert_relative_eq!(rev.angle_end, 2.3, epsilon = 1e-12);
        assert_relative_eq!(rev.e3.dot(&arc.e3), -1.0, epsilon = 1e-12);
    }

    #[test]
    fn arc_over_half_a_turn() {
        let at = |t: f64| Point3::new(t.cos(), t.sin(), 0.0);
        let arc = SpaceArc::through(at(0.0), at(2.0), at(5.0)).expect("arc");
        assert_relative_eq!(arc.angle_end, 5.0, epsilon = 1e-12);
        assert_relative_eq!(arc.e3.z, 1.0, epsilon = 1e-12);
        let (d, t) = arc.distance(&Point3::new(2.0 * 4f64.cos(), 2.0 * 4f64.sin(), 0.5));
        assert_relative_eq!(d, (1.0f64 + 0.25).sqrt(), epsilon = 1e-12);
        assert_relative_eq!(t, 4.0, epsilon = 1e-12);
    }

    #[test]
    fn collinear_and_coincident_points_are_errors() {
        let p = |x: f64| Point3::new(x, 2.0 * x, 0.0);
        assert!(matches!(
            SpaceArc::through(p(0.0), p(1.0), p(3.0)),
            Err(InterpError::CollinearArc { .. })
        ));
        assert!(matches!(
            SpaceArc::through(p(0.0), p(0.0), p(3.0)),
            Err(InterpError::CollinearArc { .. })
        ));
        let nan = Point3::new(f64::NAN, 0.0, 0.0);
        assert!(matches!(
            SpaceArc::through(p(0.0), nan, p(3.0)),
            Err(InterpError::NonFinite { index: 1 })
        ));
    }
}
