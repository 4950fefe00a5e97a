//! Point-to-segment distance: the one implementation every kerf crate calls (the discretizer's
//! certified bound, the arc fitter, the linearization error of the kinematics, the checker's
//! dense sampling, the cut-order geometry of the process crate); and the point-to-box
//! distance ([`distance_to_box`]), the lower bound of every bounding-box search.
//!
//! The nearest point of the segment `a + s (b - a)`, `s` in `[0, 1]`, to `q` is at
//! `s = clamp((q - a).(b - a) / |b - a|^2, 0, 1)`; a segment of zero length (or one whose
//! squared length is not a positive number) is the point `a`, at `s = 0`. The difference
//! `q - a` is formed once and the distance taken as `|(q - a) - s (b - a)|`, so a point on the
//! segment gives exactly 0 at its ends.

use nalgebra::{Point3, SVector, Vector3};

/// A segment from `start` to `start + direction` in `D` dimensions, prepared for many distance
/// queries (its squared length is computed once).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment<const D: usize> {
    start: SVector<f64, D>,
    direction: SVector<f64, D>,
    length_squared: f64,
    /// `1 / length_squared` where that is a finite positive number, else 0 (then
    /// [`Segment::distance_upper`] falls back to the exact division).
    inv_length_squared: f64,
}

impl<const D: usize> Segment<D> {
    /// The segment from `a` to `b`.
    #[inline]
    pub fn new(a: SVector<f64, D>, b: SVector<f64, D>) -> Self {
        let direction = b - a;
        let length_squared = direction.norm_squared();
        let inv = 1.0 / length_squared;
        Self {
            start: a,
            direction,
            length_squared,
            inv_length_squared: if inv.is_finite() && inv > 0.0 {
                inv
            } else {
                0.0
            },
        }
    }

    /// The distance from `q` to the segment for hot loops that need an upper bound rather than
    /// the nearest point: the foot parameter is `(q - a).(b - a)` times the cached
    /// `1 / |b - a|^2` (a multiplication instead of a division), clamped to `[0, 1]`. The
    /// reciprocal puts the foot off by a rounding, but the clamped foot is still a point of
    /// the segment, so the value is the distance to *a* point of the segment: never below the
    /// true distance, up to the rounding of the norm (the certified chord-error bound of
    /// `kerf-discretize` relies on this). Unlike [`Segment::distance`], a point at the far end
    /// may give a tiny positive value instead of exactly 0.
    #[inline]
    pub fn distance_upper(&self, q: &SVector<f64, D>) -> f64 {
        if self.inv_length_squared == 0.0 {
            return self.distance(q);
        }
        let aq = q - self.start;
        let s = (aq.dot(&self.direction) * self.inv_length_squared).clamp(0.0, 1.0);
        (aq - self.direction * s).norm()
    }

    /// The start point `a`.
    #[inline]
    pub fn start(&self) -> &SVector<f64, D> {
        &self.start
    }

    /// The vector `b - a`.
    #[inline]
    pub fn direction(&self) -> &SVector<f64, D> {
        &self.direction
    }

    /// The nearest point of the segment to `q`: its distance (in the units of the coordinates,
    /// mm in kerf) and its parameter `s` in `[0, 1]` (0 at the start, 1 at the end; 0 when the
    /// segment has no length).
    #[inline]
    pub fn nearest(&self, q: &SVector<f64, D>) -> (f64, f64) {
        let aq = q - self.start;
        let s = if self.length_squared > 0.0 {
            (aq.dot(&self.direction) / self.length_squared).clamp(0.0, 1.0)
        } else {
            0.0
        };
        ((aq - self.direction * s).norm(), s)
    }

    /// The distance from `q` to the nearest point of the segment.
    #[inline]
    pub fn distance(&self, q: &SVector<f64, D>) -> f64 {
        self.nearest(q).0
    }
}

impl Segment<3> {
    /// The segment between two points of space.
    #[inline]
    pub fn between(a: &Point3<f64>, b: &Point3<f64>) -> Self {
        Self::new(a.coords, b.coords)
    }

    /// The distance from the point `q` to the segment.
    #[inline]
    pub fn distance_to(&self, q: &Point3<f64>) -> f64 {
        self.distance(&q.coords)
    }
}

/// The distance from `q` to the segment `a b` (to `a` when the segment has zero length).
#[inline]
pub fn distance_to_segment(q: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    Segment::between(a, b).distance_to(q)
}

/// The nearest point of the segment `a b` to `q`: its distance and its parameter `s` in
/// `[0, 1]` along `a -> b`.
#[inline]
pub fn nearest_on_segment(q: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> (f64, f64) {
    Segment::between(a, b).nearest(&q.coords)
}

/// The distance from `p` to the axis-aligned box with corners `lo <= hi` (0 inside or on it):
/// the length of `max(lo - p, p - hi, 0)` taken per coordinate. A lower bound on the distance
/// from `p` to anything inside the box (the convex hull of a NURBS piece's control points, a
/// bounding-volume node, a face's vertices).
#[inline]
pub fn distance_to_box(p: &Point3<f64>, lo: &Point3<f64>, hi: &Point3<f64>) -> f64 {
    Vector3::from_fn(|k, _| (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The box distance against the distances it must be: 0 inside and on the faces, the
    /// distance to a face, an edge (a hypotenuse) and a corner (a 3D diagonal) outside.
    #[test]
    fn distance_to_box_is_zero_inside_and_the_nearest_face_edge_or_corner_outside() {
        let (lo, hi) = (Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 3.0, 4.0));
        let d = |x: f64, y: f64, z: f64| distance_to_box(&Point3::new(x, y, z), &lo, &hi);
        assert_eq!(d(1.0, 1.0, 1.0), 0.0, "inside");
        assert_eq!(d(2.0, 3.0, 0.0), 0.0, "on a corner");
        assert_eq!(d(1.0, 1.0, 7.0), 3.0, "above a face");
        assert_eq!(d(-3.0, 7.0, 2.0), 5.0, "beside an edge: 3-4-5");
        assert_eq!(d(4.0, 6.0, 10.0), 7.0, "off a corner: 2-3-6-7");
    }

    /// `distance_upper` (reciprocal) against the analytic distance: on a segment along x, the
    /// distance of `(x, y, z)` is `hypot(y, z)` beside it and the distance to the nearer end
    /// beyond it. Never below (beyond a rounding), never above by more than a rounding.
    #[test]
    fn distance_upper_is_the_analytic_distance_up_to_rounding() {
        let len = 3.0f64;
        let s = Segment::<3>::new(
            Vector3::new(1.0, 2.0, 3.0),
            Vector3::new(1.0 + len, 2.0, 3.0),
        );
        for i in -20..=50 {
            for j in -5..=5 {
                let (x, y, z) = (0.1 * i as f64, 0.37 * j as f64, 0.11 * j as f64);
                let q = Vector3::new(1.0 + x, 2.0 + y, 3.0 + z);
                let dx = if x < 0.0 { -x } else { (x - len).max(0.0) };
                let exact = (dx * dx + y * y + z * z).sqrt();
                let d = s.distance_upper(&q);
                assert!(d >= exact * (1.0 - 1e-15) - 1e-15, "{d} below {exact}");
                assert!(d <= exact * (1.0 + 1e-14) + 1e-14, "{d} above {exact}");
            }
        }
        // A zero-length segment is its start point.
        let p = Segment::<3>::new(Vector3::new(1.0, 1.0, 1.0), Vector3::new(1.0, 1.0, 1.0));
        assert_eq!(p.distance_upper(&Vector3::new(4.0, 5.0, 1.0)), 5.0, "3-4-5");
    }
}
