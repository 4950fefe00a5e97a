//! Point-to-segment distance: the one implementation every kerf crate calls (the discretizer's
//! certified bound, the arc fitter, the linearization error of the kinematics, the checker's
//! dense sampling, the cut-order geometry of the process crate).
//!
//! The nearest point of the segment `a + s (b - a)`, `s` in `[0, 1]`, to `q` is at
//! `s = clamp((q - a).(b - a) / |b - a|^2, 0, 1)`; a segment of zero length (or one whose
//! squared length is not a positive number) is the point `a`, at `s = 0`. The difference
//! `q - a` is formed once and the distance taken as `|(q - a) - s (b - a)|`, so a point on the
//! segment gives exactly 0 at its ends.

use nalgebra::{Point3, SVector};

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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

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
