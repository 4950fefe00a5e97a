//! The interpolation certificate: a bound of the chord error of a segment inside one knot
//! span from three curve points and the span's third-derivative bounds.

use super::{Bound, Certifier, Ends};
use kerf_nurbs::{Segment, MAX_ORDER};
use nalgebra::{Vector3, Vector4};

/// Per knot span, the bounds the interpolation certificate needs, from the span's Bezier form
/// (all derivatives with respect to the span's local parameter `u` in `[0, 1]`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SpanBounds {
    /// The largest Bezier weight (a bound of `w` on the span: convex hull).
    w_max: f64,
    /// Bounds of `|w'|`, `|w''|`, `|w'''|` (first, second, third hodograph of the weights),
    /// each raised by `slack`.
    w1: f64,
    w2: f64,
    w3: f64,
    /// A bound of `|C'|` on the span (a rounding of the local parameter moves a point by
    /// `eps` times it).
    d1: f64,
    /// Added to the third-derivative bounds: the rounding of the Bezier points, amplified by
    /// the third differences (`64 p^4 eps w_max (L + |A|)`, the part in `L` stored here).
    slack: f64,
}

/// The third hodographs and the derivative bounds of every span's Bezier form (see
/// [`SpanBounds`]); spans of zero length get zeros and are never asked for.
pub(super) fn span_derivative_bounds(
    p: usize,
    span_bezier: &[Vector4<f64>],
    spans: &[f64],
) -> (Vec<Vector4<f64>>, Vec<Vector4<f64>>, Vec<SpanBounds>) {
    let n = spans.len();
    let mut h3 = vec![Vector4::zeros(); n * (p + 1)];
    let mut h4 = vec![Vector4::zeros(); n * (p + 1)];
    let mut out = vec![SpanBounds::default(); n];
    let eps = f64::EPSILON;
    let pf = p as f64;
    for i in 0..n {
        let b = &span_bezier[i * (p + 1)..(i + 1) * (p + 1)];
        if b[0].w == 0.0 {
            continue; // an empty span: never certified by this route
        }
        let w_min = b.iter().map(|v| v.w).fold(f64::INFINITY, f64::min);
        let w_max = b.iter().map(|v| v.w).fold(0.0, f64::max);
        let slack = 64.0 * pf.powi(4) * eps * w_max * spans[i].max(f64::MIN_POSITIVE);
        let wslack = 64.0 * pf.powi(4) * eps * w_max;
        let mut d1 = [Vector4::zeros(); MAX_ORDER];
        let mut d2 = [Vector4::zeros(); MAX_ORDER];
        for j in 0..p {
            d1[j] = b[j + 1] - b[j];
        }
        for j in 0..p.saturating_sub(1) {
            d2[j] = d1[j + 1] - d1[j];
        }
        let c3 = pf * (pf - 1.0) * (pf - 2.0);
        let mut w3 = 0.0f64;
        for j in 0..p.saturating_sub(2) {
            let v = (d2[j + 1] - d2[j]) * c3;
            h3[i * (p + 1) + j] = v;
            w3 = w3.max(v.w.abs());
        }
        let c4 = c3 * (pf - 3.0);
        for j in 0..p.saturating_sub(3) {
            h4[i * (p + 1) + j] = ((d2[j + 2] - d2[j + 1]) - (d2[j + 1] - d2[j])) * c4;
        }
        let w1 = pf * d1[..p].iter().map(|v| v.w.abs()).fold(0.0, f64::max);
        let w2 = pf
            * (pf - 1.0)
            * d2[..p.saturating_sub(1)]
                .iter()
                .map(|v| v.w.abs())
                .fold(0.0, f64::max);
        // |C'| = |P' - C w'| / w <= (|P'| + |C| |w'|) / w_min, |C| <= the largest projected
        // control point (convex hull).
        let pmax = pf * d1[..p].iter().map(|v| v.xyz().norm()).fold(0.0, f64::max);
        let cmax = b.iter().map(|v| v.xyz().norm() / v.w).fold(0.0, f64::max);
        out[i] = SpanBounds {
            w_max,
            w1: w1 + wslack,
            w2: w2 + wslack,
            w3: w3 + wslack,
            d1: 2.0 * (pmax + cmax * (w1 + wslack)) / w_min,
            slack,
        };
        // A NaN anywhere (inf - inf after an overflow) would vanish in the `f64::max` folds
        // and shrink a bound: then this span is never certified by this route (an infinite
        // `d1` makes every upper bound infinite, which `interpolation_bound` refuses).
        let r = i * (p + 1)..(i + 1) * (p + 1);
        if !all_finite(&h3[r.clone()], &h4[r], &out[i]) {
            out[i].d1 = f64::INFINITY;
        }
    }
    (h3, h4, out)
}

/// Whether a span's hodograph bounds and derived numbers are all finite (no NaN that a
/// `f64::max` fold would drop).
fn all_finite(h3: &[Vector4<f64>], h4: &[Vector4<f64>], sb: &SpanBounds) -> bool {
    let finite = |v: &Vector4<f64>| v.iter().all(|c| c.is_finite());
    h3.iter().all(finite)
        && h4.iter().all(finite)
        && [sb.w_max, sb.w1, sb.w2, sb.w3, sb.d1, sb.slack]
            .iter()
            .all(|x| x.is_finite())
}

impl Certifier<'_> {
    /// The interpolation certificate of a segment `[t0, t1]` inside one knot span
    /// (`docs/discretization.md`, "The interpolation certificate"): from the curve points at
    /// both ends and at the middle and the span's third-derivative bounds, an upper bound of
    /// the chord error (margin included) and the middle point's distance (a lower bound).
    /// `None` where its conditions fail (the weight changes too much over the step, or a
    /// curve point's foot might fall outside the chord): then only the hull certificate
    /// applies. Costs two evaluations (three for a new start).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub(super) fn interpolation_bound<const M: usize>(
        &self,
        ends: &mut Ends,
        end_hint: Option<(usize, Vector4<f64>)>,
        span: usize,
        t0: f64,
        t1: f64,
        chord: &Segment<3>,
        al: &Vector3<f64>,
        bl: &Vector3<f64>,
        margin: f64,
    ) -> Option<Bound> {
        let p = self.curve.degree();
        let sb = &self.span_bounds[span];
        let knots = self.local.knots();
        let (klo, khi) = (knots[span], knots[span + 1]);
        let dk = khi - klo;
        let u0 = ((t0 - klo) / dk).clamp(0.0, 1.0);
        let u1 = ((t1 - klo) / dk).clamp(0.0, 1.0);
        let h = u1 - u0;
        if h.is_nan() || h <= 0.0 {
            return None;
        }
        let um = 0.5 * (u0 + u1);
        let find = |ends: &Ends, t: f64| {
            ends.iter()
                .flatten()
                .find(|e| e.0 == t && e.1 == span)
                .map(|e| e.2)
        };
        let (h0, keep) = match find(ends, t0) {
            Some(v) => (v, ends.iter().position(|e| e.is_some_and(|e| e.0 == t0))),
            None => {
                let v = self.span_point::<M>(span, u0);
                ends[0] = Some((t0, span, v));
                (v, Some(0))
            }
        };
        let h1 = match end_hint.filter(|e| e.0 == span) {
            Some((_, v)) => v,
            None => self.span_point::<M>(span, u1),
        };
        ends[if keep == Some(0) { 1 } else { 0 }] = Some((t1, span, h1));
        let hm = self.span_point::<M>(span, um);
        let proj = |v: &Vector4<f64>| v.xyz() / v.w;
        let (c0, c1, cm) = (proj(&h0), proj(&h1), proj(&hm));
        // How far the given chord ends are from the curve's ends.
        let e = (c0 - al).norm().max((c1 - bl).norm());
        let ab = chord.direction();
        let l = ab.norm();
        let wm = hm.w;
        if !(l > 0.0 && wm > 0.0 && e.is_finite()) {
            return None;
        }
        let dir = ab / l;
        let xm = cm - al;
        let par = xm.dot(&dir);
        // The middle point's distance to the chord's line, and to the chord itself.
        let dm = (xm - dir * par).norm();
        let lower = chord.distance_upper(&cm);
        // w(u) >= w_m (1 - a |s - 1/2|) on the step.
        let a = h * sb.w1 / wm;
        if a.is_nan() || a > 0.5 {
            return None;
        }
        let w_lo = wm * (1.0 - 0.5 * a);
        let w_hi = wm * (1.0 + 0.5 * a);
        // Bounds of the third derivatives of the numerator N = P - w L across and along the
        // chord: the hodograph's control points of P''' - w''' A (a convex hull).
        let slack = sb.slack + 64.0 * (p as f64).powi(4) * f64::EPSILON * sb.w_max * al.amax();
        let (mut m3_perp, mut m3_par) = (0.0f64, 0.0f64);
        let h3s = &self.span_h3[span * (p + 1)..span * (p + 1) + p.saturating_sub(2)];
        for v in h3s {
            let g = v.xyz() - al * v.w;
            let gp = g.dot(&dir);
            m3_par = m3_par.max(gp.abs());
            m3_perp = m3_perp.max((g - dir * gp).norm());
        }
        if p >= 4 {
            // Across the chord, the third derivative at the middle (de Casteljau on the third
            // hodograph) plus half the step times the fourth derivative's bound, if smaller.
            let mut d = [Vector4::zeros(); M];
            let q = p - 3;
            d[..=q].copy_from_slice(h3s);
            for r in 1..=q {
                for i in 0..=(q - r) {
                    d[i] = d[i] * (1.0 - um) + d[i + 1] * um;
                }
            }
            let g = d[0].xyz() - al * d[0].w;
            let mid = (g - dir * g.dot(&dir)).norm();
            let mut m4 = 0.0f64;
            for v in &self.span_h4[span * (p + 1)..span * (p + 1) + p - 3] {
                let g = v.xyz() - al * v.w;
                m4 = m4.max((g - dir * g.dot(&dir)).norm());
            }
            // The de Casteljau value is off by the rounding of q levels (within `slack`); the
            // fourth differences amplify the Bezier points' rounding by `16 p^4` (`p slack`).
            m3_perp = m3_perp.min(mid + slack + 0.5 * h * (m4 + p as f64 * slack));
        }
        m3_perp += slack;
        m3_par += slack + l * (sb.w3 + 3.0 * sb.w2 / h);
        let h3 = h * h * h;
        // Every curve point's foot on the chord's line lies in the chord (up to the ends'
        // offset `e`): then the distance to the chord is that to its line.
        let along = 4.0 * ((wm * (par - 0.5 * l)).abs() + w_hi * e) + h3 * m3_par / 12.0;
        if along.is_nan() || along > 0.5 * l * w_lo {
            return None;
        }
        // |N_perp(u)| <= e_w + (1/4 - x^2) (4 n + c x) at x = |s - 1/2|, and w(u) >= w_m (1 - a x),
        // 1 / (1 - a x) <= 1 + a' x: the maximum over x of (1/4 - x^2) (4 n + c' x) with
        // c' = c + 4 n a' + c a' / 2 bounds it (x <= 1/2), in closed form.
        let e_w = w_hi * e;
        let n = wm * dm + e_w;
        let c = h3 * m3_perp / 6.0;
        let a2 = a / (1.0 - 0.5 * a);
        let c2 = c + 4.0 * n * a2 + 0.5 * c * a2;
        let root = (64.0 * n * n + 3.0 * c2 * c2).sqrt() + 8.0 * n;
        let x = if root > 0.0 { c2 / (2.0 * root) } else { 0.0 };
        let phi = (0.25 - x * x) * (4.0 * n + c2 * x);
        let upper = (phi / wm + 2.0 * e_w / w_lo + 4.0 * f64::EPSILON * sb.d1)
            * (1.0 + 64.0 * f64::EPSILON)
            + margin;
        if !upper.is_finite() {
            return None;
        }
        Some(Bound {
            upper,
            lower: lower.min(upper),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::{all_finite, span_derivative_bounds};
    use nalgebra::Vector4;

    #[test]
    fn a_nan_in_a_span_bound_is_seen() {
        let b: Vec<Vector4<f64>> = (0..5)
            .map(|j| Vector4::new(j as f64, (j * j) as f64, 0.0, 1.0))
            .collect();
        let (h3, h4, out) = span_derivative_bounds(4, &b, &[16.0]);
        assert!(out[0].d1.is_finite(), "{:?}", out[0]);
        assert!(all_finite(&h3, &h4, &out[0]), "a tame span is usable");
        let mut bad = h3.clone();
        bad[0].y = f64::NAN;
        assert!(
            bad.iter().map(|v| v.amax()).fold(0.0, f64::max).is_finite(),
            "a max fold drops the NaN: why the check exists"
        );
        assert!(
            !all_finite(&bad, &h4, &out[0]),
            "NaN in the third hodograph"
        );
        let mut sb = out[0];
        sb.w3 = f64::NAN;
        assert!(!all_finite(&h3, &h4, &sb), "NaN in a weight bound");
    }
}
