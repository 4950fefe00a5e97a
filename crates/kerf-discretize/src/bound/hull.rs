//! The hull certificate: the rational Bezier pieces of a segment, the largest distance of
//! their projected control points to the chord, refined by subdivision (de Casteljau).

use super::{Bound, Certifier, MAX_SUBDIVISION_DEPTH};
use kerf_nurbs::Segment;
use nalgebra::{Vector3, Vector4};

#[derive(Debug, Clone, Copy)]
pub(super) struct Piece<const M: usize> {
    /// Homogeneous control points; entries beyond the degree are unused.
    cpw: [Vector4<f64>; M],
    upper: f64,
    depth: u32,
}

impl<const M: usize> Piece<M> {
    /// Splits at the middle in place: `self` becomes the left half and `right`, which must hold
    /// a copy of `self` on entry, the right half (de Casteljau: `p` levels of convex
    /// combinations with weights `1/2`, as `RationalBezier::subdivide_in_place`).
    #[inline]
    fn split(&mut self, right: &mut Self, p: usize) {
        kerf_nurbs::tick();
        for r in 1..=p {
            for i in 0..=(p - r) {
                right.cpw[i] = right.cpw[i] * 0.5 + right.cpw[i + 1] * 0.5;
            }
            self.cpw[r] = right.cpw[0];
        }
    }
}

/// Upper bound over a piece's hull (the largest distance of a projected control point to the
/// chord), and the distance of its last control point (a curve point). The projection
/// multiplies by `1 / w` (one more rounding of size `eps |Q|` than a division, within the
/// margin's allowance for the projection); the distance is [`Segment::distance_upper`], the
/// distance to *a* point of the segment, so never below the true distance (up to the rounding
/// of the norm).
#[inline]
fn hull_distance(chord: &Segment<3>, h: &[Vector4<f64>]) -> (f64, f64) {
    let mut upper = 0.0f64;
    let mut end = 0.0;
    for c in h {
        let inv = 1.0 / c.w;
        let q = Vector3::new(c.x * inv, c.y * inv, c.z * inv);
        end = chord.distance_upper(&q);
        upper = upper.max(end);
    }
    (upper, end)
}

impl Certifier<'_> {
    /// The Bezier piece of the curve on `[lo, hi]` inside knot span `span`, cut from the span's
    /// Bezier form by de Casteljau: first the left part at `u1 = (hi - k_lo) / (k_hi - k_lo)`,
    /// then the right part of that at `v = (lo - k_lo) / (hi - k_lo)`. Both local parameters
    /// lie in `[0, 1]` (clamped), so each level is a convex combination, like the blossom's de
    /// Boor levels; their rounding (and that of `u1`, `v`) is covered by the margin (3 `p`
    /// levels of extraction instead of `p`, Step 5). Counts as one evaluation.
    #[inline]
    fn piece_in_span(&self, span: usize, lo: f64, hi: f64, out: &mut [Vector4<f64>]) {
        kerf_nurbs::tick();
        let p = self.curve.degree();
        let knots = self.local.knots();
        let (klo, khi) = (knots[span], knots[span + 1]);
        out.copy_from_slice(&self.span_bezier[span * (p + 1)..(span + 1) * (p + 1)]);
        if hi < khi {
            let u = ((hi - klo) / (khi - klo)).clamp(0.0, 1.0);
            // Left part at u, in place: after level r, out[r] is the left piece's point r.
            for r in 1..=p {
                for i in (r..=p).rev() {
                    out[i] = out[i - 1] * (1.0 - u) + out[i] * u;
                }
            }
        }
        if lo > klo {
            let v = ((lo - klo) / (hi - klo)).clamp(0.0, 1.0);
            // Right part at v, in place: after level r, out[p - r] is the right piece's point.
            for r in 1..=p {
                for i in 0..=(p - r) {
                    out[i] = out[i] * (1.0 - v) + out[i + 1] * v;
                }
            }
        }
    }

    /// The hull certificate of `[t0, t1]` (Steps 1-4) against `chord` (local frame), starting
    /// from the lower bound `lower` already known (the interpolation certificate's middle
    /// point, or 0); `margin` is the chord ends' part of the rounding margin
    /// (`8 eps max(|A|, |B|)`), to which each piece's span adds its own.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn hull_bound<const M: usize>(
        &self,
        pieces: &mut Vec<Piece<M>>,
        t0: f64,
        t1: f64,
        chord: &Segment<3>,
        mut margin: f64,
        mut lower: f64,
        limit: f64,
        want_lower: f64,
    ) -> Bound {
        let f = self.factor();
        let p = self.curve.degree();
        pieces.clear();
        let local = &self.local;
        let knots = local.knots();
        let mut span = local.span(t0);
        // The Bezier pieces of [t0, t1], one per knot span it meets (as
        // `NurbsCurve::for_each_bezier_piece`), extracted straight into the work space.
        let mut lo = t0;
        loop {
            let hi = knots[span + 1].min(t1);
            if hi > lo {
                let mut pc = Piece {
                    cpw: [Vector4::zeros(); M],
                    upper: 0.0,
                    depth: 0,
                };
                self.piece_in_span(span, lo, hi, &mut pc.cpw[..=p]);
                let (upper, end) = hull_distance(chord, &pc.cpw[..=p]);
                pc.upper = upper;
                margin = margin.max((2.0 * f + 8.0 * f64::EPSILON) * self.spans[span]);
                lower = lower.max(end);
                pieces.push(pc);
            }
            if hi >= t1 || span + 1 >= local.len() {
                break;
            }
            lo = hi;
            span += 1;
        }
        margin += self.representation;
        let budget = 48 + 4 * pieces.len();
        let mut steps = 0;
        loop {
            // The piece with the largest bound decides the global bound.
            let mut worst = 0;
            let mut upper = 0.0f64;
            let mut nan = false;
            for (i, pc) in pieces.iter().enumerate() {
                nan |= pc.upper.is_nan();
                if pc.upper > upper {
                    upper = pc.upper;
                    worst = i;
                }
            }
            // A NaN distance (overflowing homogeneous coordinates) must never look like 0.
            if nan || lower.is_nan() || margin.is_nan() {
                return Bound {
                    upper: f64::INFINITY,
                    lower: if lower.is_nan() { f64::INFINITY } else { lower },
                };
            }
            let upper_m = upper + margin;
            if lower > limit {
                return Bound {
                    upper: upper_m.max(lower),
                    lower,
                };
            }
            // Refining further cannot move the estimate by more than the gap.
            let tight = upper - lower <= 0.002 * limit;
            let decided =
                upper_m <= limit && (lower >= want_lower || upper_m < want_lower || tight);
            let exhausted = steps >= budget
                || pieces
                    .get(worst)
                    .is_none_or(|pc| pc.depth >= MAX_SUBDIVISION_DEPTH);
            if decided || exhausted {
                return Bound {
                    upper: upper_m,
                    lower,
                };
            }
            steps += 1;
            // Split the worst piece in place: its copy at the end becomes the right half.
            pieces[worst].depth += 1;
            pieces.push(pieces[worst]);
            let last = pieces.len() - 1;
            let (head, tail) = pieces.split_at_mut(last);
            let (l, r) = (&mut head[worst], &mut tail[0]);
            l.split(r, p);
            let (ul, el) = hull_distance(chord, &l.cpw[..=p]);
            let (ur, _) = hull_distance(chord, &r.cpw[..=p]);
            lower = lower.max(el);
            l.upper = ul;
            r.upper = ur;
        }
    }
}
