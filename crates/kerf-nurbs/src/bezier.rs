//! Rational Bezier pieces: extraction from a NURBS curve by blossoming, de Casteljau
//! subdivision, and the convex-hull bound the discretizer's proof rests on.

use nalgebra::{Point3, Vector4};

use crate::curve::{project, NurbsCurve};
use crate::error::{NurbsError, Result};
use crate::MAX_ORDER;

/// A rational Bezier curve of degree `degree <= MAX_DEGREE` in homogeneous form, carrying the
/// interval `[t0, t1]` of the NURBS parameter it represents (its own parameter runs over
/// `[0, 1]`).
///
/// All weights are positive when it comes from a valid [`NurbsCurve`], so the curve lies in the
/// convex hull of its projected control points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RationalBezier {
    /// Degree.
    pub degree: usize,
    /// First NURBS parameter covered.
    pub t0: f64,
    /// Last NURBS parameter covered.
    pub t1: f64,
    /// Homogeneous control points `(w x, w y, w z, w)`; entries beyond `degree` are unused.
    pub cpw: [Vector4<f64>; MAX_ORDER],
}

impl RationalBezier {
    /// The homogeneous control points in use.
    #[inline]
    pub fn homogeneous(&self) -> &[Vector4<f64>] {
        &self.cpw[..=self.degree]
    }

    /// The projected control points.
    pub fn control_points(&self) -> impl Iterator<Item = Point3<f64>> + '_ {
        self.homogeneous().iter().map(project)
    }

    /// The point at local parameter `u` in `[0, 1]` (de Casteljau in homogeneous space).
    pub fn point_local(&self, u: f64) -> Point3<f64> {
        let mut d = self.cpw;
        for r in 1..=self.degree {
            for i in 0..=(self.degree - r) {
                d[i] = d[i] * (1.0 - u) + d[i + 1] * u;
            }
        }
        project(&d[0])
    }

    /// Splits at local parameter `u` into the pieces on `[0, u]` and `[u, 1]`.
    #[inline]
    pub fn subdivide(&self, u: f64) -> (Self, Self) {
        crate::work::tick();
        let p = self.degree;
        let tm = self.t0 + (self.t1 - self.t0) * u;
        let mut left = *self;
        let mut right = *self;
        let mut d = self.cpw;
        left.cpw[0] = d[0];
        right.cpw[p] = d[p];
        for r in 1..=p {
            for i in 0..=(p - r) {
                d[i] = d[i] * (1.0 - u) + d[i + 1] * u;
            }
            left.cpw[r] = d[0];
            right.cpw[p - r] = d[p - r];
        }
        left.t1 = tm;
        right.t0 = tm;
        (left, right)
    }

    /// Splits at local parameter `u` in place: `self` becomes the piece on `[0, u]` and `right`,
    /// which must hold a copy of `self` on entry, the piece on `[u, 1]`. Touches only the
    /// `degree + 1` control points in use, so a hot loop copies one piece instead of three.
    #[inline]
    pub fn subdivide_in_place(&mut self, right: &mut Self, u: f64) {
        crate::work::tick();
        let p = self.degree;
        let tm = self.t0 + (self.t1 - self.t0) * u;
        // De Casteljau on `right`: after level r its entries 0..=p-r are the level-r points; the
        // entry j is last written at level p - j, which is the right half's point j.
        for r in 1..=p {
            for i in 0..=(p - r) {
                right.cpw[i] = right.cpw[i] * (1.0 - u) + right.cpw[i + 1] * u;
            }
            self.cpw[r] = right.cpw[0];
        }
        self.t1 = tm;
        right.t0 = tm;
    }

    /// The piece on local sub-interval `[a, b]` of `[0, 1]` (two de Casteljau splits).
    pub fn segment(&self, a: f64, b: f64) -> Self {
        let right = if a > 0.0 { self.subdivide(a).1 } else { *self };
        if b >= 1.0 {
            return right;
        }
        let u = if a > 0.0 { (b - a) / (1.0 - a) } else { b };
        right.subdivide(u).0
    }
}

impl NurbsCurve {
    /// The rational Bezier form of the curve on `[t0, t1]`, which must lie inside one knot
    /// span `span` (`knots[span] <= t0 < t1 <= knots[span + 1]`).
    ///
    /// Control point `j` is the blossom `b(t0, ..., t0, t1, ..., t1)` with `p - j` copies of
    /// `t0`, computed in homogeneous space by de Boor's algorithm with a different argument at
    /// each level. For arguments inside the span every de Boor step is a convex combination,
    /// so the Bezier weights stay positive.
    pub fn bezier_in_span(&self, span: usize, t0: f64, t1: f64) -> RationalBezier {
        let mut out = RationalBezier {
            degree: self.degree(),
            t0,
            t1,
            cpw: [Vector4::zeros(); MAX_ORDER],
        };
        self.bezier_in_span_into(span, t0, t1, &mut out.cpw);
        out
    }

    /// [`NurbsCurve::bezier_in_span`] written to `out[..=degree]` (homogeneous control points),
    /// without building a [`RationalBezier`]: hot loops keep their pieces in arrays sized for
    /// the degree instead of copying `MAX_ORDER` entries. `out` must hold at least
    /// `degree + 1` entries.
    #[inline]
    pub fn bezier_in_span_into(&self, span: usize, t0: f64, t1: f64, out: &mut [Vector4<f64>]) {
        // Scratch arrays sized for the degree: clearing 25-entry arrays costs more than the
        // arithmetic for the common degrees.
        match self.degree() {
            0..=3 => self.blossom_m::<4>(span, t0, t1, out),
            4..=7 => self.blossom_m::<8>(span, t0, t1, out),
            _ => self.blossom_m::<MAX_ORDER>(span, t0, t1, out),
        }
    }

    #[inline]
    fn blossom_m<const M: usize>(&self, span: usize, t0: f64, t1: f64, out: &mut [Vector4<f64>]) {
        crate::work::tick();
        let p = self.degree();
        let knots = self.knots();
        let cpw = self.homogeneous_points();
        // Control point j applies t0 at p - j de Boor levels and t1 at j levels. The t0 levels
        // are shared: `pre` holds the state after `p - j` levels of t0, for j = p down to 0.
        let level = |d: &mut [Vector4<f64>; M], r: usize, x: f64| {
            for k in (r..=p).rev() {
                let lo = knots[span - p + k];
                let hi = knots[span + 1 + k - r];
                let alpha = (x - lo) / (hi - lo);
                d[k] = d[k - 1] * (1.0 - alpha) + d[k] * alpha;
            }
        };
        let mut pre = [Vector4::zeros(); M];
        pre[..=p].copy_from_slice(&cpw[span - p..=span]);
        let mut d = [Vector4::zeros(); M];
        for j in (0..=p).rev() {
            if j < p {
                // One more level of t0: level p - j.
                level(&mut pre, p - j, t0);
            }
            d[..=p].copy_from_slice(&pre[..=p]);
            for r in (p - j + 1)..=p {
                level(&mut d, r, t1);
            }
            out[j] = d[p];
        }
    }

    /// The rational Bezier pieces of the curve on `[t0, t1]`: one per knot span the interval
    /// meets, in order, together covering exactly `[t0, t1]`.
    ///
    /// # Errors
    /// [`NurbsError::BadInterval`] unless `t0 < t1`, and
    /// [`NurbsError::ParameterOutsideDomain`] if either end is outside the domain.
    pub fn bezier_pieces(&self, t0: f64, t1: f64) -> Result<Vec<RationalBezier>> {
        let (a, b) = self.domain();
        for t in [t0, t1] {
            if !(t >= a && t <= b) {
                return Err(NurbsError::ParameterOutsideDomain {
                    value: t,
                    start: a,
                    end: b,
                });
            }
        }
        if t0 >= t1 {
            return Err(NurbsError::BadInterval { t0, t1 });
        }
        let mut out = Vec::new();
        self.for_each_bezier_piece(t0, t1, |b| out.push(*b));
        Ok(out)
    }

    /// Calls `f` with each rational Bezier piece of `[t0, t1]` (in order) without allocating.
    /// `t0 < t1` must lie in the domain (not checked).
    #[inline]
    pub fn for_each_bezier_piece(&self, t0: f64, t1: f64, mut f: impl FnMut(&RationalBezier)) {
        let knots = self.knots();
        let mut span = self.span(t0);
        let mut lo = t0;
        loop {
            let hi = knots[span + 1].min(t1);
            if hi > lo {
                f(&self.bezier_in_span(span, lo, hi));
            }
            if hi >= t1 || span + 1 >= self.len() {
                break;
            }
            lo = hi;
            span += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    #[test]
    fn in_place_split_equals_subdivide() {
        let c = NurbsCurve::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 2.0, 0.5),
                Point3::new(3.0, -1.0, 2.0),
                Point3::new(4.0, 0.0, 0.0),
            ],
            Some(vec![1.0, 0.3, 2.0, 1.0]),
        );
        let b = c.bezier_in_span(3, 0.1, 0.9);
        for u in [0.25, 0.5, 0.8] {
            let (l, r) = b.subdivide(u);
            let (mut l2, mut r2) = (b, b);
            l2.subdivide_in_place(&mut r2, u);
            assert_eq!(l, l2, "left halves agree");
            assert_eq!(r, r2, "right halves agree");
        }
    }
}
