//! A closed contour projected along its mean normal: the polygon, its signed area (positive
//! when it runs counter-clockwise seen from the normal), winding-number containment and
//! segment crossings.

use kerf_nurbs::Segment;
use nalgebra::{Point3, Vector2, Vector3};

use crate::Pose;

/// A closed contour in the plane through its first point perpendicular to its mean normal.
#[derive(Debug, Clone)]
pub(crate) struct Projected {
    origin: Point3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    /// The polygon (the closing point not repeated).
    poly: Vec<Vector2<f64>>,
    /// Signed area (mm^2): > 0 counter-clockwise seen from the mean normal.
    pub(crate) area: f64,
    /// True if the normals cancel (a loop whose tool axes turn all the way round, e.g. around
    /// a tube): the projection then folds the two sides onto the contour.
    pub(crate) wraps: bool,
}

impl Projected {
    /// The projection of a closed contour (first and last point within `tol`, at least three
    /// distinct points); `None` for an open one.
    pub(crate) fn of_closed(poses: &[Pose], tol: f64) -> Option<Self> {
        if poses.len() < 4 {
            return None;
        }
        let first = poses[0].position;
        let last = poses[poses.len() - 1].position;
        if (first - last).norm() > tol {
            return None;
        }
        // Whether the normals cancel over the distinct points (the closing point repeats the
        // first); the projection keeps the sum over all points.
        let distinct: Vector3<f64> = poses[..poses.len() - 1].iter().map(|p| p.axis).sum();
        let wraps = distinct.norm() < 1e-6 * poses.len() as f64;
        let mut n: Vector3<f64> = poses.iter().map(|p| p.axis).sum();
        if n.norm() < 1e-6 * poses.len() as f64 {
            // Normals cancel (a loop around a tube): use the polygon's own plane (Newell).
            n = Vector3::zeros();
            for w in poses.windows(2) {
                n += w[0].position.coords.cross(&w[1].position.coords);
            }
        }
        let n = n.try_normalize(1e-300)?;
        let helper = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = helper.cross(&n).normalize();
        let e2 = n.cross(&e1);
        let poly: Vec<Vector2<f64>> = poses[..poses.len() - 1]
            .iter()
            .map(|p| {
                let d = p.position - first;
                Vector2::new(d.dot(&e1), d.dot(&e2))
            })
            .collect();
        let mut area = 0.0;
        for i in 0..poly.len() {
            let a = poly[i];
            let b = poly[(i + 1) % poly.len()];
            area += a.x * b.y - a.y * b.x;
        }
        Some(Self {
            origin: first,
            e1,
            e2,
            poly,
            area: 0.5 * area,
            wraps,
        })
    }

    /// The unit normal of the plane the contour is projected onto.
    pub(crate) fn normal(&self) -> Vector3<f64> {
        self.e1.cross(&self.e2)
    }

    /// The point in the contour's plane.
    pub(crate) fn project(&self, p: &Point3<f64>) -> Vector2<f64> {
        let d = p - self.origin;
        Vector2::new(d.dot(&self.e1), d.dot(&self.e2))
    }

    /// The winding number of the polygon around `q`.
    fn winding(&self, q: Vector2<f64>) -> i32 {
        let mut w = 0;
        let n = self.poly.len();
        for i in 0..n {
            let a = self.poly[i];
            let b = self.poly[(i + 1) % n];
            let cross = (b - a).perp(&(q - a));
            if a.y <= q.y {
                if b.y > q.y && cross > 0.0 {
                    w += 1;
                }
            } else if b.y <= q.y && cross < 0.0 {
                w -= 1;
            }
        }
        w
    }

    /// True if `p` (projected) lies inside the polygon.
    pub(crate) fn contains(&self, p: &Point3<f64>) -> bool {
        self.winding(self.project(p)) != 0
    }

    /// True if the contour `poses` lies inside: three of its points spread along it are.
    pub(crate) fn contains_contour(&self, poses: &[Pose]) -> bool {
        let n = poses.len();
        [0, n / 3, (2 * n) / 3]
            .iter()
            .all(|&i| self.contains(&poses[i.min(n - 1)].position))
    }

    /// True if the segment `a b` (projected) crosses an edge of the polygon other than the
    /// edges touching vertex `skip` (the start point, where a lead-in meets the contour).
    pub(crate) fn crosses(&self, a: &Point3<f64>, b: &Point3<f64>, skip: usize) -> bool {
        let (p, q) = (self.project(a), self.project(b));
        let n = self.poly.len();
        (0..n).any(|i| {
            let j = (i + 1) % n;
            if i == skip % n || j == skip % n {
                return false;
            }
            segments_cross(p, q, self.poly[i], self.poly[j])
        })
    }

    /// The smallest distance from `p` (projected) to the polygon's edges.
    pub(crate) fn distance(&self, p: &Point3<f64>) -> f64 {
        let q = self.project(p);
        let n = self.poly.len();
        (0..n)
            .map(|i| Segment::new(self.poly[i], self.poly[(i + 1) % n]).distance(&q))
            .fold(f64::INFINITY, f64::min)
    }
}

/// True if the closed segments `p q` and `a b` intersect (proper crossings and touches).
fn segments_cross(p: Vector2<f64>, q: Vector2<f64>, a: Vector2<f64>, b: Vector2<f64>) -> bool {
    let d1 = (q - p).perp(&(a - p));
    let d2 = (q - p).perp(&(b - p));
    let d3 = (b - a).perp(&(p - a));
    let d4 = (b - a).perp(&(q - a));
    (d1 * d2 <= 0.0) && (d3 * d4 <= 0.0) && !(d1 == 0.0 && d2 == 0.0)
}
