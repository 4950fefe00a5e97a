//! The certified chord-error bound.
//!
//! For a segment `[t0, t1]` with chord `A = C(t0)`, `B = C(t1)`, the curve between the two is
//! split into rational Bezier pieces (one per knot span). With positive weights, each piece is a
//! convex combination of its projected control points, so it lies in their convex hull; the
//! distance to the segment `AB` is a convex function, so its maximum over the hull is attained
//! at a control point. Hence `max_j dist(Q_j, AB)` bounds the chord error of that piece from
//! above. Subdividing a piece (de Casteljau) makes the bound converge to the true maximum; the
//! curve points found on the way (the pieces' end points) give a lower bound. The search stops
//! as soon as the bounds decide the question asked. See `docs/discretization.md`.

use kerf_nurbs::{NurbsCurve, RationalBezier, Segment, MAX_ORDER};
use nalgebra::{Point3, Vector3, Vector4};

/// The verdict on one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// A certified upper bound of the chord error (includes the floating-point margin), or
    /// `f64::INFINITY` when the search stopped before it could certify anything below `limit`.
    pub upper: f64,
    /// The largest distance from a curve point found during the search to the chord: a lower
    /// bound of the chord error (up to rounding), and an estimate of it.
    pub lower: f64,
}

impl Bound {
    /// True if the segment is certified to meet `tolerance`.
    #[inline]
    pub fn certified(&self, tolerance: f64) -> bool {
        self.upper <= tolerance
    }
}

/// Reusable work space of [`Certifier::chord_error`], so that a walk along a curve allocates once.
/// Pieces are kept in arrays sized for the degree (4, 8 or `MAX_ORDER` control points), so a
/// cubic's piece is 128 bytes to copy, not 800.
#[derive(Debug, Default, Clone)]
pub struct Scratch {
    small: Vec<Piece<4>>,
    medium: Vec<Piece<8>>,
    large: Vec<Piece<MAX_ORDER>>,
    /// Homogeneous curve points the interpolation certificate evaluated last (`t`, its span,
    /// the point): the walk tries several ends from one start, and the end it accepts is the
    /// next start.
    ends: Ends,
}

/// Two remembered homogeneous points of the local frame, by parameter and span.
type Ends = [Option<(f64, usize, Vector4<f64>)>; 2];

#[derive(Debug, Clone, Copy)]
struct Piece<const M: usize> {
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

/// Subdivisions of one Bezier piece beyond which it is not refined further: the rounding
/// margin covers the de Casteljau levels of this many halvings (see [`MARGIN_FACTOR`]).
pub const MAX_SUBDIVISION_DEPTH: u32 = 48;

/// The margin constant: `MARGIN_FACTOR (p + 1) eps * 2 L` (`L` the span's largest local
/// coordinate). It covers
/// the `p` de Boor levels of the Bezier extraction, `p` de Casteljau levels for each of up to
/// [`MAX_SUBDIVISION_DEPTH`] halvings, the projection and the distance, each one rounding of a
/// convex combination (`docs/discretization.md`, Step 5).
pub const MARGIN_FACTOR: f64 = 128.0;

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

/// Per knot span, the bounds the interpolation certificate needs, from the span's Bezier form
/// (all derivatives with respect to the span's local parameter `u` in `[0, 1]`).
#[derive(Debug, Clone, Copy, Default)]
struct SpanBounds {
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
fn span_derivative_bounds(
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
    }
    (h3, h4, out)
}

/// The curve prepared for certification: a copy translated to a local origin (so that rounding
/// is relative to the curve's size, not its distance from the origin) and, per knot span, the
/// magnitudes that bound the rounding of its Bezier pieces.
///
/// The origin `O` is the centre of the control points' box rounded to a multiple of a power of
/// two `g >= ` the box's extent; then `P_i - O` is exact in floating point (checked for every
/// coordinate; if any were inexact `O = 0` would be used). Build one per curve and reuse it:
/// construction costs one pass over the control points.
#[derive(Debug, Clone)]
pub struct Certifier<'a> {
    curve: &'a NurbsCurve,
    local: NurbsCurve,
    origin: Vector3<f64>,
    /// Per knot span index: `L = max_i |P_i - O|_inf` over the span's `p + 1` control points.
    spans: Vec<f64>,
    /// Per knot span index `i`: the homogeneous control points of the whole span's Bezier form
    /// at `span_bezier[i * (p + 1)..(i + 1) * (p + 1)]` (zeros for empty spans). A segment's
    /// piece in the span is cut from it by two de Casteljau splits (`docs/discretization.md`,
    /// Step 1), instead of a blossom per trial.
    span_bezier: Vec<Vector4<f64>>,
    /// Per knot span index `i`: the third hodograph of the span's homogeneous Bezier form,
    /// `p (p - 1) (p - 2) Delta^3 Q^w_j` for `j <= p - 3`, at `span_h3[i * (p + 1)..]` (the
    /// control points of the third derivatives of `(P, w)` in the local parameter).
    span_h3: Vec<Vector4<f64>>,
    /// The fourth hodographs likewise (`j <= p - 4`): a bound of how fast the third
    /// derivative changes, so that the third derivative near a step is bounded from its value
    /// at the step's middle rather than over the whole span.
    span_h4: Vec<Vector4<f64>>,
    /// Per knot span index: the bounds of the interpolation certificate.
    span_bounds: Vec<SpanBounds>,
    /// `4 eps max |P_i|` for curves whose weights are not powers of two (the control points are
    /// recovered from `w P` by one division, within two ulps), else 0.
    representation: f64,
}

/// `a - b` and whether it is exact (Knuth's TwoSum error term is zero).
fn exact_diff(a: f64, b: f64) -> (f64, bool) {
    let s = a - b;
    let bb = s - a;
    let err = (a - (s - bb)) + (-b - bb);
    (s, err == 0.0)
}

impl<'a> Certifier<'a> {
    /// Prepares `curve` for certification.
    pub fn new(curve: &'a NurbsCurve) -> Self {
        let (lo, hi) = curve.bounding_box();
        let extent = (hi - lo).amax();
        let centre = (lo.coords + hi.coords) * 0.5;
        let g = if extent > 0.0 && extent.is_finite() {
            2f64.powi(extent.log2().ceil() as i32)
        } else {
            1.0
        };
        let mut origin = centre.map(|c| (c / g).round() * g);
        if !origin.iter().all(|c| c.is_finite()) {
            origin = Vector3::zeros();
        }
        let points = curve.control_points();
        let weights = curve.weights();
        let mut shifted = Vec::with_capacity(points.len());
        let mut exact = true;
        for p in &points {
            let mut d = Vector3::zeros();
            for k in 0..3 {
                let (v, ok) = exact_diff(p[k], origin[k]);
                d[k] = v;
                exact &= ok;
            }
            shifted.push(d);
        }
        if !exact {
            origin = Vector3::zeros();
            shifted = points.iter().map(|p| p.coords).collect();
        }
        let cpw: Vec<Vector4<f64>> = shifted
            .iter()
            .zip(&weights)
            .map(|(d, &w)| Vector4::new(d.x * w, d.y * w, d.z * w, w))
            .collect();
        let p = curve.degree();
        let mut spans = vec![0.0; curve.len()];
        for (i, _, _) in curve.spans() {
            spans[i] = shifted[i - p..=i]
                .iter()
                .map(|d| d.amax())
                .fold(0.0, f64::max);
        }
        let pow2 = |w: f64| w.log2().fract() == 0.0;
        let representation = if weights.iter().all(|&w| pow2(w)) {
            0.0
        } else {
            let scale = points.iter().map(|p| p.coords.amax()).fold(0.0, f64::max);
            4.0 * f64::EPSILON * scale
        };
        let local = NurbsCurve::from_homogeneous_unchecked(p, curve.knots().to_vec(), cpw);
        let mut span_bezier = vec![Vector4::zeros(); curve.len() * (p + 1)];
        for (i, a, b) in curve.spans() {
            local.bezier_in_span_into(i, a, b, &mut span_bezier[i * (p + 1)..(i + 1) * (p + 1)]);
        }
        let (span_h3, span_h4, span_bounds) = span_derivative_bounds(p, &span_bezier, &spans);
        Self {
            curve,
            local,
            origin,
            spans,
            span_bezier,
            span_h3,
            span_h4,
            span_bounds,
            representation,
        }
    }

    /// The curve being certified.
    pub fn curve(&self) -> &NurbsCurve {
        self.curve
    }

    /// The local origin `O` the certificate computes in.
    pub fn origin(&self) -> Vector3<f64> {
        self.origin
    }

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

    /// The homogeneous point of span `span`'s Bezier form at the local parameter `u` in
    /// `[0, 1]`, by de Casteljau (`p` levels of convex combinations, like the splits of Step
    /// 1). Counts as one evaluation.
    #[inline]
    fn span_point<const M: usize>(&self, span: usize, u: f64) -> Vector4<f64> {
        kerf_nurbs::tick();
        let p = self.curve.degree();
        let mut d = [Vector4::zeros(); M];
        d[..=p].copy_from_slice(&self.span_bezier[span * (p + 1)..(span + 1) * (p + 1)]);
        let v = 1.0 - u;
        for r in 1..=p {
            for i in 0..=(p - r) {
                d[i] = d[i] * v + d[i + 1] * u;
            }
        }
        d[0]
    }

    /// The interpolation certificate of a segment `[t0, t1]` inside one knot span
    /// (`docs/discretization.md`, "The interpolation certificate"): from the curve points at
    /// both ends and at the middle and the span's third-derivative bounds, an upper bound of
    /// the chord error (margin included) and the middle point's distance (a lower bound).
    /// `None` where its conditions fail (the weight changes too much over the step, or a
    /// curve point's foot might fall outside the chord): then only the hull certificate
    /// applies. Costs two evaluations (three for a new start).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn interpolation_bound<const M: usize>(
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

    /// The curve point at `t`, evaluated on the span's cached Bezier form by de Casteljau (`p`
    /// levels of convex combinations in the local frame, then translated back): the walk's
    /// cutting points. Within a few `eps` of the local magnitude of the curve's value (the
    /// rounding is measured by the interpolation certificate, which evaluates the same way),
    /// and far cheaper than a basis-function evaluation. Counts as one evaluation.
    pub(crate) fn point(&self, t: f64) -> Point3<f64> {
        match self.curve.degree() {
            0..=3 => self.local_derivs::<4>(t, 0).0[0],
            4..=7 => self.local_derivs::<8>(t, 0).0[0],
            _ => self.local_derivs::<MAX_ORDER>(t, 0).0[0],
        }
        .into()
    }

    /// The point (global frame) and first derivative at `t`, as [`Certifier::point`], and
    /// the knot span and homogeneous local point they come from (for the certificate).
    pub(crate) fn eval_d1_h(&self, t: f64) -> (Point3<f64>, Vector3<f64>, (usize, Vector4<f64>)) {
        let (d, span, h) = match self.curve.degree() {
            0..=3 => self.local_derivs::<4>(t, 1),
            4..=7 => self.local_derivs::<8>(t, 1),
            _ => self.local_derivs::<MAX_ORDER>(t, 1),
        };
        (d[0].into(), d[1], (span, h))
    }

    /// The point (global frame) and its span and homogeneous local point, as
    /// [`Certifier::eval_d1_h`].
    pub(crate) fn point_h(&self, t: f64) -> (Point3<f64>, (usize, Vector4<f64>)) {
        let (d, span, h) = match self.curve.degree() {
            0..=3 => self.local_derivs::<4>(t, 0),
            4..=7 => self.local_derivs::<8>(t, 0),
            _ => self.local_derivs::<MAX_ORDER>(t, 0),
        };
        (d[0].into(), (span, h))
    }

    /// The point (global frame) and the first three derivatives at `t`, as
    /// [`Certifier::point`].
    pub(crate) fn eval_d3(&self, t: f64) -> [Vector3<f64>; 4] {
        match self.curve.degree() {
            0..=3 => self.local_derivs::<4>(t, 3).0,
            4..=7 => self.local_derivs::<8>(t, 3).0,
            _ => self.local_derivs::<MAX_ORDER>(t, 3).0,
        }
    }

    /// The point (translated back to the global frame) and the derivatives up to order `n`
    /// (`n <= 3`; higher entries zero) with respect to `t`, from the span's Bezier form: de
    /// Casteljau down to level `p - n`, whose forward differences give the homogeneous
    /// derivatives (`p! / (p - k)! Delta^k`), then the quotient rule.
    #[inline]
    fn local_derivs<const M: usize>(
        &self,
        t: f64,
        n: usize,
    ) -> ([Vector3<f64>; 4], usize, Vector4<f64>) {
        kerf_nurbs::tick();
        let p = self.curve.degree();
        let span = self.local.span(t);
        let knots = self.local.knots();
        let (klo, khi) = (knots[span], knots[span + 1]);
        let dk = khi - klo;
        let u = if dk > 0.0 {
            ((t - klo) / dk).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let mut d = [Vector4::zeros(); M];
        d[..=p].copy_from_slice(&self.span_bezier[span * (p + 1)..(span + 1) * (p + 1)]);
        let v = 1.0 - u;
        let m = n.min(p);
        for r in 1..=(p - m) {
            for i in 0..=(p - r) {
                d[i] = d[i] * v + d[i + 1] * u;
            }
        }
        // Homogeneous derivatives from the level p - m points d[0..=m].
        let mut hd = [Vector4::zeros(); 4];
        let pf = p as f64;
        let inv = 1.0 / dk;
        if m >= 3 {
            let c = pf * (pf - 1.0) * (pf - 2.0) * inv * inv * inv;
            hd[3] = (d[3] - d[2] * 3.0 + d[1] * 3.0 - d[0]) * c;
        }
        if m >= 2 {
            // Level p - 2 points from level p - m.
            for r in 0..(m - 2) {
                for i in 0..(m - r) {
                    d[i] = d[i] * v + d[i + 1] * u;
                }
            }
            hd[2] = (d[2] - d[1] * 2.0 + d[0]) * (pf * (pf - 1.0) * inv * inv);
        }
        if m >= 1 {
            if m >= 2 {
                d[0] = d[0] * v + d[1] * u;
                d[1] = d[1] * v + d[2] * u;
            } else {
                // m == 1: d[0..=1] are the level p - 1 points already.
            }
            hd[1] = (d[1] - d[0]) * (pf * inv);
            d[0] = d[0] * v + d[1] * u;
        }
        let h0 = d[0];
        let w = h0.w;
        let c0 = h0.xyz() / w;
        let mut out = [Vector3::zeros(); 4];
        out[0] = c0 + self.origin;
        if n >= 1 {
            let c1 = (hd[1].xyz() - c0 * hd[1].w) / w;
            out[1] = c1;
            if n >= 2 {
                let c2 = (hd[2].xyz() - c1 * (2.0 * hd[1].w) - c0 * hd[2].w) / w;
                out[2] = c2;
                if n >= 3 {
                    out[3] =
                        (hd[3].xyz() - c2 * (3.0 * hd[1].w) - c1 * (3.0 * hd[2].w) - c0 * hd[3].w)
                            / w;
                }
            }
        }
        (out, span, h0)
    }

    fn factor(&self) -> f64 {
        MARGIN_FACTOR * (self.curve.degree() + 1) as f64 * f64::EPSILON
    }

    /// The largest rounding margin any segment of the curve can get, known before any walk:
    /// `128 (p + 1) eps * 2 L + 8 eps L` with `L` the largest `|P_i - O|_inf` of a knot span's
    /// control points, plus the representation term. The weights do not enter: every
    /// homogeneous value the certificate computes is a convex combination
    /// `sum_i lambda_i w_i (P_i - O, 1)`, whose rounding is at most a few `eps` times
    /// `sum_i lambda_i w_i |P_i - O| <= w L` per level, so after dividing by its weight `w` the
    /// projected point is off by a few `eps L` per level, whatever the weights' ratio
    /// (`docs/discretization.md`, Step 5). A tolerance not well above the margin cannot be
    /// certified.
    pub fn max_margin(&self) -> f64 {
        let f = self.factor();
        let worst = self
            .curve
            .spans()
            .iter()
            .map(|&(i, _, _)| self.spans[i])
            .fold(0.0, f64::max);
        (2.0 * f + 8.0 * f64::EPSILON) * worst + self.representation
    }

    /// The resolution of the output: one ulp of the largest coordinate of the curve's control
    /// points. A cutting point is a rounded `f64`, so it is off the curve by up to about half
    /// of this per coordinate, and no chord error below it can be certified reliably.
    pub fn output_resolution(&self) -> f64 {
        let scale = self
            .curve
            .control_points()
            .iter()
            .map(|p| p.coords.amax())
            .fold(0.0, f64::max);
        2.0 * f64::EPSILON * scale
    }

    /// Certifies the chord error of the curve on `[t0, t1]` against the chord `a b`; see
    /// [`chord_error`].
    #[allow(clippy::too_many_arguments)]
    pub fn chord_error(
        &self,
        scratch: &mut Scratch,
        t0: f64,
        t1: f64,
        a: &Point3<f64>,
        b: &Point3<f64>,
        limit: f64,
        want_lower: f64,
    ) -> Bound {
        self.chord_error_hinted(scratch, t0, t1, a, b, None, limit, want_lower)
    }

    /// [`Certifier::chord_error`] with, optionally, the span and homogeneous local point that
    /// `b` was evaluated from (by [`Certifier::eval_d1_h`]), which saves evaluating it again.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn chord_error_hinted(
        &self,
        scratch: &mut Scratch,
        t0: f64,
        t1: f64,
        a: &Point3<f64>,
        b: &Point3<f64>,
        end_hint: Option<(usize, Vector4<f64>)>,
        limit: f64,
        want_lower: f64,
    ) -> Bound {
        match self.curve.degree() {
            0..=3 => self.chord_error_m(
                &mut scratch.small,
                &mut scratch.ends,
                end_hint,
                t0,
                t1,
                a,
                b,
                limit,
                want_lower,
            ),
            4..=7 => self.chord_error_m(
                &mut scratch.medium,
                &mut scratch.ends,
                end_hint,
                t0,
                t1,
                a,
                b,
                limit,
                want_lower,
            ),
            _ => self.chord_error_m(
                &mut scratch.large,
                &mut scratch.ends,
                end_hint,
                t0,
                t1,
                a,
                b,
                limit,
                want_lower,
            ),
        }
    }

    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn chord_error_m<const M: usize>(
        &self,
        pieces: &mut Vec<Piece<M>>,
        ends: &mut Ends,
        end_hint: Option<(usize, Vector4<f64>)>,
        t0: f64,
        t1: f64,
        a: &Point3<f64>,
        b: &Point3<f64>,
        limit: f64,
        want_lower: f64,
    ) -> Bound {
        let (al, bl) = (a - self.origin, b - self.origin);
        let chord = Segment::between(&al, &bl);
        let f = self.factor();
        let p = self.curve.degree();
        let mut margin = 8.0 * f64::EPSILON * al.coords.amax().max(bl.coords.amax());
        pieces.clear();
        let mut lower = 0.0f64;
        let local = &self.local;
        let knots = local.knots();
        let mut span = local.span(t0);
        // Most segments lie in one span and are decided by the interpolation certificate
        // without any subdivision.
        if t1 <= knots[span + 1] {
            let m =
                margin.max((2.0 * f + 8.0 * f64::EPSILON) * self.spans[span]) + self.representation;
            if let Some(bd) = self.interpolation_bound::<M>(
                ends, end_hint, span, t0, t1, &chord, &al.coords, &bl.coords, m,
            ) {
                let tight = bd.upper - bd.lower <= 0.002 * limit;
                if bd.lower > limit
                    || (bd.upper <= limit
                        && (bd.lower >= want_lower || bd.upper < want_lower || tight))
                {
                    return bd;
                }
                lower = bd.lower;
            }
        }
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
                let (upper, end) = hull_distance(&chord, &pc.cpw[..=p]);
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
            let (ul, el) = hull_distance(&chord, &l.cpw[..=p]);
            let (ur, _) = hull_distance(&chord, &r.cpw[..=p]);
            lower = lower.max(el);
            l.upper = ul;
            r.upper = ur;
        }
    }
}

impl Certifier<'_> {
    /// A certified upper bound (radians) of the largest angle between the tangents at any two
    /// points of `[t0, t1]`, refined until it is `<= limit` or cannot be brought below it; `PI`
    /// where the tangent may reverse (a cusp).
    ///
    /// The derivative of a rational Bezier piece is `C' = sum_{i<k} w_i w_k (B_i B_k' - B_k B_i')
    /// (Q_k - Q_i) / w^2`, and `B_i B_k' - B_k B_i' >= 0` for `i < k` (the ratio `B_k / B_i`
    /// increases), so every tangent lies in the cone spanned by the control polygon's edges
    /// `Q_{j+1} - Q_j`. If every edge is within `theta < 90` degrees of one direction `d`, so is
    /// every tangent, and two tangents differ by at most `2 theta`. Halving a piece (de
    /// Casteljau) shrinks its cone to the tangents actually taken; at most `32 + 2 * pieces`
    /// halvings.
    pub fn turn_bound(&self, t0: f64, t1: f64, limit: f64) -> f64 {
        let mut pieces: Vec<(RationalBezier, f64)> = Vec::new();
        let mut d = self.local.point(t1) - self.local.point(t0);
        if d.norm() == 0.0 {
            self.local.for_each_bezier_piece(t0, t1, |bez| {
                if d.norm() == 0.0 {
                    if let Some(e) = edges(bez).find(|e| e.norm() > 0.0) {
                        d = e;
                    }
                }
            });
        }
        if d.norm() == 0.0 || !d.norm().is_finite() {
            return 0.0;
        }
        let spread = |bez: &RationalBezier| {
            edges(bez)
                .filter(|e| e.norm() > 0.0)
                .map(|e| e.angle(&d))
                .fold(0.0f64, f64::max)
        };
        self.local.for_each_bezier_piece(t0, t1, |bez| {
            pieces.push((*bez, spread(bez)));
        });
        let budget = 32 + 2 * pieces.len();
        for _ in 0..=budget {
            let (worst, theta) = pieces
                .iter()
                .enumerate()
                .map(|(i, p)| (i, p.1))
                .fold((0, 0.0f64), |acc, x| if x.1 > acc.1 { x } else { acc });
            let bound = if theta >= std::f64::consts::FRAC_PI_2 || theta.is_nan() {
                std::f64::consts::PI
            } else {
                2.0 * theta
            };
            if bound <= limit {
                return bound;
            }
            let mut right = pieces[worst].0;
            let mut left = right;
            left.subdivide_in_place(&mut right, 0.5);
            pieces[worst] = (left, spread(&left));
            pieces.push((right, spread(&right)));
            if pieces.len() > budget + 2 {
                break;
            }
        }
        let theta = pieces.iter().map(|p| p.1).fold(0.0f64, f64::max);
        if theta >= std::f64::consts::FRAC_PI_2 || theta.is_nan() {
            std::f64::consts::PI
        } else {
            2.0 * theta
        }
    }
}

/// The edges `Q_{j+1} - Q_j` of a piece's projected control polygon.
fn edges(bez: &RationalBezier) -> impl Iterator<Item = Vector3<f64>> + '_ {
    let h = bez.homogeneous();
    h.windows(2)
        .map(|w| w[1].xyz() / w[1].w - w[0].xyz() / w[0].w)
}

/// Certifies the chord error of the curve on `[t0, t1]` against the chord `a b`, where `a` and
/// `b` are the points the caller will output for `t0` and `t1` (normally `curve.point(t0)` and
/// `curve.point(t1)`; any points are allowed, the bound is about the segment between them).
/// The search refines until one of:
/// - the upper bound is `<= limit` and the lower bound is `>= want_lower` (or cannot rise any
///   more): returns the bounds;
/// - the lower bound exceeds `limit`: the segment certainly fails; `upper` is then the
///   current (larger) bound;
/// - the refinement budget (`48 + 4 * pieces` subdivisions, none deeper than
///   [`MAX_SUBDIVISION_DEPTH`]) is spent: `upper` is the bound reached (possibly `> limit`).
///
/// The rounding margin of [`Certifier`] (from the magnitudes of each span's control points
/// relative to a local origin, and its weights) is included in `upper`. This builds a
/// [`Certifier`] per call; a walk along a curve should build one and call
/// [`Certifier::chord_error`].
pub fn chord_error(
    curve: &NurbsCurve,
    t0: f64,
    t1: f64,
    a: &Point3<f64>,
    b: &Point3<f64>,
    limit: f64,
    want_lower: f64,
) -> Bound {
    Certifier::new(curve).chord_error(&mut Scratch::default(), t0, t1, a, b, limit, want_lower)
}
