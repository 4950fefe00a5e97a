//! The interpolation certificate: a bound of the chord error of a segment inside one knot
//! span from three curve points and the span's third-derivative bounds.

use super::{Bound, Certifier};
use kerf_nurbs::{Segment, MAX_ORDER};
use nalgebra::{Vector3, Vector4};

/// Per knot span, the bounds the interpolation certificate needs, from the span's Bezier form
/// (all derivatives with respect to the span's local parameter `u` in `[0, 1]`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct SpanBounds {
    /// The largest Bezier weight (a bound of `w` on the span: convex hull).
    pub(super) w_max: f64,
    /// Bounds of `|w'|`, `|w''|`, `|w'''|` (first, second, third hodograph of the weights),
    /// each raised by `slack`.
    pub(super) w1: f64,
    pub(super) w2: f64,
    pub(super) w3: f64,
    /// A bound of `|C'|` on the span (a rounding of the local parameter moves a point by
    /// `eps` times it).
    pub(super) d1: f64,
    /// `max_j |H_j|` and `max_j |H_j^w|` over the third hodograph's control points `(H_j,
    /// H_j^w)`: the third derivative of `P - w A` is at most `h3 + |A| h3w` on the span.
    pub(super) h3: f64,
    pub(super) h3w: f64,
    /// Added to the third-derivative bounds: the rounding of the Bezier points, amplified by
    /// the third differences (`64 p^4 eps w_max (L + |A|)`, the part in `L` stored here).
    pub(super) slack: f64,
}

/// The third hodographs and the derivative bounds of every span's Bezier form (see
/// [`SpanBounds`]); spans of zero length get zeros and are never asked for.
pub(super) fn span_derivative_bounds(
    p: usize,
    span_bezier: &[Vector4<f64>],
    spans: &[f64],
) -> (Vec<Vector4<f64>>, Vec<SpanBounds>) {
    // Work arrays sized for the degree: clearing two 25-entry arrays per span cost more than
    // the differences for the common degrees.
    match p {
        0..=3 => span_derivative_bounds_m::<4>(p, span_bezier, spans),
        4..=7 => span_derivative_bounds_m::<8>(p, span_bezier, spans),
        _ => span_derivative_bounds_m::<MAX_ORDER>(p, span_bezier, spans),
    }
}

/// [`span_derivative_bounds`] with work arrays of `M >= p + 1` entries.
fn span_derivative_bounds_m<const M: usize>(
    p: usize,
    span_bezier: &[Vector4<f64>],
    spans: &[f64],
) -> (Vec<Vector4<f64>>, Vec<SpanBounds>) {
    let n = spans.len();
    let mut h3 = vec![Vector4::zeros(); n * (p + 1)];
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
        let mut d1 = [Vector4::zeros(); M];
        let mut d2 = [Vector4::zeros(); M];
        for j in 0..p {
            d1[j] = b[j + 1] - b[j];
        }
        for j in 0..p.saturating_sub(1) {
            d2[j] = d1[j + 1] - d1[j];
        }
        let c3 = pf * (pf - 1.0) * (pf - 2.0);
        let (mut w3, mut h3n) = (0.0f64, 0.0f64);
        for j in 0..p.saturating_sub(2) {
            let v = (d2[j + 1] - d2[j]) * c3;
            h3[i * (p + 1) + j] = v;
            w3 = w3.max(v.w.abs());
            h3n = h3n.max(v.xyz().norm());
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
            h3: h3n,
            h3w: w3,
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
        if !all_finite(&h3[r], &out[i]) {
            out[i].d1 = f64::INFINITY;
        }
    }
    (h3, out)
}

/// Whether a span's hodograph bounds and derived numbers are all finite (no NaN that a
/// `f64::max` fold would drop).
fn all_finite(h3: &[Vector4<f64>], sb: &SpanBounds) -> bool {
    let finite = |v: &Vector4<f64>| v.iter().all(|c| c.is_finite());
    h3.iter().all(finite)
        && [
            sb.w_max, sb.h3, sb.h3w, sb.w1, sb.w2, sb.w3, sb.d1, sb.slack,
        ]
        .iter()
        .all(|x| x.is_finite())
}

/// A step's derivative bounds multiplied by the powers of the step that the certificate's
/// forms use, so that a step inside one span (in its local parameter) and a step across a knot
/// (each span's bounds in its own local units, the larger taken) share one implementation.
#[derive(Debug, Clone, Copy)]
struct Scaled {
    /// `h W1`: the step times the bound of `|w'|`.
    hw1: f64,
    /// `h^3` times the rounding slack of the third-derivative bounds.
    slack3: f64,
    /// `h^3 W3 + 3 h^2 W2`: the weights' part of `h^3 M3par` per unit of chord length.
    par_w3: f64,
    /// A bound of `|C'|` in local units (the ends' local parameters are rounded).
    d1: f64,
}

/// What the interpolation certificate knows of one step once its ends and middle point are
/// evaluated (`docs/discretization.md`, "The interpolation certificate").
struct Step {
    /// The chord's unit direction.
    dir: Vector3<f64>,
    /// The middle point's offset across the chord.
    offset: Vector3<f64>,
    /// The middle point's distance to the chord's line: a lower bound of the chord error.
    lower: f64,
    /// The middle point's weight and its reciprocal.
    wm: f64,
    inv_wm: f64,
    /// `a' = a / (1 - a/2)`, `a = h W1 / w(um)`.
    a2: f64,
    /// How far the given chord ends are from the curve's ends, and that times `w_hi`.
    e: f64,
    e_w: f64,
    /// `n = w(um) dm + w_hi e` and its reciprocal.
    n: f64,
    inv_n: f64,
    /// `4 (|N_par(um)| + w_hi e)`, and `l w_lo / 2`, which it must stay below with the third
    /// derivative's term for every foot to fall inside the chord.
    along0: f64,
    half_l_w_lo: f64,
    /// The chord's length.
    l: f64,
    margin: f64,
    scaled: Scaled,
}

impl Step {
    /// From the projected ends `c`, the middle point (projected, and its weight), the chord
    /// (its start `al` in local coordinates) and the margin; `None` for a degenerate chord, a
    /// non-positive middle weight or a weight that changes too much over the step (`a > 1/2`).
    #[inline(always)]
    fn new(
        c: [Vector3<f64>; 2],
        (cm, wm): (Vector3<f64>, f64),
        chord: &Segment<3>,
        al: &Vector3<f64>,
        margin: f64,
        scaled: Scaled,
    ) -> Option<Self> {
        let ab = chord.direction();
        let bl = al + ab;
        // How far the given chord ends are from the curve's ends.
        let e = (c[0] - al)
            .norm_squared()
            .max((c[1] - bl).norm_squared())
            .sqrt();
        let l = ab.norm();
        if !(l > 0.0 && wm > 0.0 && e.is_finite()) {
            return None;
        }
        let dir = ab * (1.0 / l);
        let xm = cm - al;
        let par = xm.dot(&dir);
        let offset = xm - dir * par;
        // w(u) >= w_m (1 - a |s - 1/2|) on the step.
        let inv_wm = 1.0 / wm;
        let a = scaled.hw1 * inv_wm;
        if a.is_nan() || a > 0.5 {
            return None;
        }
        let w_lo = wm * (1.0 - 0.5 * a);
        let w_hi = wm * (1.0 + 0.5 * a);
        let e_w = w_hi * e;
        let dm = offset.norm();
        let n = wm * dm + e_w;
        Some(Self {
            dir,
            offset,
            lower: dm,
            wm,
            inv_wm,
            a2: a / (1.0 - 0.5 * a),
            e,
            e_w,
            n,
            inv_n: 1.0 / n,
            along0: 4.0 * ((wm * (par - 0.5 * l)).abs() + e_w),
            half_l_w_lo: 0.5 * l * w_lo,
            l,
            margin,
            scaled,
        })
    }

    /// Whether the foot of every curve point on the chord's line lies in the chord (up to the
    /// ends' offset `e`), given `h^3` times a bound of the third derivative of N along the
    /// chord: then the distance to the chord is that to its line.
    #[inline(always)]
    fn feet_inside(&self, h3_m3_par: f64) -> bool {
        let s = &self.scaled;
        let along = self.along0 + (h3_m3_par + s.slack3 + self.l * s.par_w3) * (1.0 / 12.0);
        along <= self.half_l_w_lo
    }

    /// The scalar form's `cl` from `h^3` times a bound of `|N'''|` on the step:
    /// `c = h^3 m3 / 6`, `cl = c + 4 n a' + c a' / 2`.
    #[inline(always)]
    fn scalar(&self, h3_m3: f64) -> f64 {
        let c = (h3_m3 + self.scaled.slack3) * (1.0 / 6.0);
        c + 4.0 * self.n * self.a2 + 0.5 * c * self.a2
    }

    /// The bound from `cl`, the coefficient of the term linear in x = |s - 1/2|:
    /// |N_perp(u)| <= e_w + (1/4 - x^2) (4 n + cl x), divided by w(u) (whose variation is
    /// inside `cl`); the maximum over x in [0, 1/2] is in closed form, and where
    /// `cl <= 2 n` the bound `n + cl^2 / (256 n)` of it (dropping `-cl x^3`, the rest is a
    /// parabola in x) is used instead, within 0.05 % of it and without a root. With `x`,
    /// where the bound peaks.
    #[inline(always)]
    fn bound(&self, cl: f64, lower: f64) -> Option<(Bound, f64)> {
        let n = self.n;
        let (phi, x) = if n > 0.0 && cl <= 2.0 * n {
            let r = cl * self.inv_n;
            (n + cl * r * (1.0 / 256.0), r * (1.0 / 32.0))
        } else {
            let root = (64.0 * n * n + 3.0 * cl * cl).sqrt() + 8.0 * n;
            let x = if root > 0.0 { cl / (2.0 * root) } else { 0.0 };
            ((0.25 - x * x) * (4.0 * n + cl * x), x)
        };
        let upper = (phi * self.inv_wm
            + 2.0 * self.e * (1.0 + self.a2)
            + 4.0 * f64::EPSILON * self.scaled.d1)
            * (1.0 + 64.0 * f64::EPSILON)
            + self.margin;
        if !upper.is_finite() {
            return None;
        }
        Some((
            Bound {
                upper,
                lower: lower.min(upper),
            },
            x,
        ))
    }

    /// Level 2's `cl` (the smaller of the scalar and the vector form) and `t`, from the
    /// control points of the third hodograph's pieces on the step, `A` removed and multiplied
    /// by the step's cube in their span's local units (`h^3 (H_j - H_j^w A)`): projected across
    /// the chord they enclose `h^3 N'''` on the step. `t` is the middle of the first and last,
    /// `delta` the largest distance of one from it plus the rounding of the hodograph and of
    /// the splits (`2 slack`); along the chord, `max |d . G_j|`. `None` if the feet may fall
    /// outside the chord. Without control points (degree < 3) `N''' = 0` up to the slack.
    #[inline(always)]
    fn hodograph_cl(&self, pieces: &[&[Vector3<f64>]], margin: f64) -> Option<(f64, Vector3<f64>)> {
        let slack3 = self.scaled.slack3;
        let dir = self.dir;
        let across = |v: &Vector3<f64>| v - dir * v.dot(&dir);
        let first = pieces.iter().find_map(|g| g.first());
        let last = pieces.iter().rev().find_map(|g| g.last());
        let (t, delta, m3_par) = match (first, last) {
            (Some(f), Some(l)) => {
                let t = (across(f) + across(l)) * 0.5;
                let (mut spread, mut m3_par) = (0.0f64, 0.0f64);
                for v in pieces.iter().flat_map(|g| g.iter()) {
                    spread = spread.max((across(v) - t).norm_squared());
                    m3_par = m3_par.max(v.dot(&dir).abs());
                }
                (t, spread.sqrt() + 2.0 * slack3, m3_par + slack3)
            }
            _ => (Vector3::zeros(), slack3, 0.0),
        };
        if !self.feet_inside(m3_par) {
            return None;
        }
        let tn = t.norm();
        let mut cl = self.scalar(tn + delta);
        let n = self.n;
        if n > 0.0 {
            // The vector form (docs/discretization.md): with c = h^3 t / 6,
            // |4 D - x c| <= sqrt(16 n^2 + 8 x k + x^2 |c|^2) <= 4 n + x k / n + x^2 |c|^2 / (8 n)
            // for k >= |D . c| (from the middle point's own offset), then x^2 <= x / 2.
            let sixth = 1.0 / 6.0;
            let c = tn * sixth;
            let nm_t = self.offset.dot(&t) * self.wm * sixth;
            let k = (nm_t.abs() + (self.e_w + self.wm * margin) * c).min(n * c);
            let beta = k * self.inv_n + delta * sixth;
            let gamma = 0.125 * c * c * self.inv_n;
            let beta2 = beta + 4.0 * n * self.a2;
            let gamma2 = gamma + beta * self.a2 + 0.5 * gamma * self.a2;
            cl = cl.min(beta2 + 0.5 * gamma2);
        }
        Some((cl, t))
    }

    /// The scalar form with `h^3` times a bound of `|N'''|` on the step, also taken as the
    /// bound along the chord (`None` if the feet may fall outside the chord).
    #[inline(always)]
    fn scalar_bound(&self, h3_m3: f64) -> Option<Bound> {
        if !self.feet_inside(h3_m3) {
            return None;
        }
        self.bound(self.scalar(h3_m3), self.lower).map(|(bd, _)| bd)
    }
}

/// What a certificate is asked: the decision rules of the hull certificate
/// (`docs/discretization.md`, Step 4), so that it refines only while the question is open.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Question {
    /// The tolerance the segment is certified against.
    pub limit: f64,
    /// The lower bound wanted (the band's lower edge), or 0.
    pub want_lower: f64,
    /// The walk's question: once the cheapest bound is refined, only "certified or not"
    /// matters (the walk steers and accepts on the upper bound, so a lower bound in the band
    /// is not worth more work).
    pub settle: bool,
}

impl Question {
    /// Whether `bd` answers the question: certainly too long, or certified and either in the
    /// band, below it, or as tight as refining could make it.
    #[inline(always)]
    pub(super) fn decided(&self, bd: &Bound) -> bool {
        let tight = bd.upper - bd.lower <= 0.002 * self.limit;
        bd.lower > self.limit
            || (bd.upper <= self.limit
                && (bd.lower >= self.want_lower || bd.upper < self.want_lower || tight))
    }

    /// Whether a refined bound `bd` answers the question: [`Question::decided`], or for the
    /// walk, certified, or not certified by a bound within 5 % of the tolerance of a curve
    /// point's distance (the hull's subdivisions could move the answer only within that: the
    /// walk takes a slightly shorter step instead, for far less work).
    #[inline(always)]
    pub(super) fn settled(&self, bd: &Bound) -> bool {
        self.decided(bd)
            || (self.settle && (bd.upper <= self.limit || bd.upper - bd.lower <= 0.05 * self.limit))
    }
}

impl Certifier<'_> {
    /// The interpolation certificate of a segment `[t0, t1]` inside knot span `span`
    /// (`docs/discretization.md`, "The interpolation certificate"): from the curve points at
    /// both ends (`h0`, `h1`: the span's homogeneous values at its local parameters `u0` and
    /// `u1`, those of `t0` and `t1` by [`Certifier::local_u`]) and at the
    /// middle and the span's third-derivative bounds, an upper bound of the chord error
    /// (margin included) and the middle point's distance (a lower bound). The bound of the
    /// third derivative is refined in three levels, each only while `question` is not
    /// decided: the span's own bound (no work per segment), the hull of the third hodograph
    /// projected across and along the chord, then (degree >= 4) the third derivative at the
    /// middle plus half the step times the fourth's bound. `None` where its conditions fail
    /// (the weight changes too much over the step, or a curve point's foot might fall outside
    /// the chord): then only the hull certificate applies. Costs one evaluation.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn interpolation_bound<const P: usize, const M: usize>(
        &self,
        span: usize,
        (u0, h0): (f64, Vector4<f64>),
        (u1, h1): (f64, Vector4<f64>),
        chord: &Segment<3>,
        al: &Vector3<f64>,
        margin: f64,
        question: Question,
    ) -> Option<Bound> {
        let p = self.deg::<P>();
        let sb = &self.span_bounds[span];
        let h = u1 - u0;
        if h.is_nan() || h <= 0.0 {
            return None;
        }
        let hm = self.span_point::<P, M>(span, 0.5 * (u0 + u1));
        let h3 = h * h * h;
        let slack = sb.slack + 64.0 * (p as f64).powi(4) * f64::EPSILON * sb.w_max * al.amax();
        let scaled = Scaled {
            hw1: h * sb.w1,
            slack3: h3 * slack,
            par_w3: h3 * (sb.w3 + 3.0 * sb.w2 * (1.0 / h)),
            d1: sb.d1,
        };
        let ends = [self.project(&h0), self.project(&h1)];
        let st = Step::new(ends, (self.project(&hm), hm.w), chord, al, margin, scaled)?;
        let lower = st.lower;
        // Level 1, from the span's norms: |N'''| <= |H_j - H_j^w A| <= |H_j| + |A| |H_j^w| over
        // the third hodograph's control points (rounded up by `1 + 8 eps`).
        let m3_span = h3 * (sb.h3 + al.norm() * sb.h3w) * (1.0 + 8.0 * f64::EPSILON);
        if let Some(bd) = st.scalar_bound(m3_span).filter(|bd| question.decided(bd)) {
            return Some(bd);
        }
        // Level 2: the third hodograph's piece on the step (two de Casteljau splits, as the
        // hull certificate's pieces): its control points enclose N''' on the step.
        let mut g = [Vector3::zeros(); M];
        let q = p.saturating_sub(3);
        if p >= 3 {
            let mut d = [Vector4::zeros(); M];
            d[..=q].copy_from_slice(&self.span_h3[span * (p + 1)..][..=q]);
            split_to(&mut d[..=q], u0, u1);
            for j in 0..=q {
                g[j] = (d[j].xyz() - al * d[j].w) * h3;
            }
        }
        let g: &[Vector3<f64>] = if p >= 3 { &g[..=q] } else { &[] };
        let (cl, t) = st.hodograph_cl(&[g], margin)?;
        let (bd, at) = st.bound(cl, lower)?;
        if question.settled(&bd) {
            return Some(bd);
        }
        // Still undecided: the middle point may be far from the maximum (an asymmetric error,
        // the cubic term dominating); the curve point where the bound peaks, on the side
        // where `|4 D - sigma x c|` is the larger (`sigma D . c < 0`), is a far better lower
        // bound, for one evaluation.
        let side = if st.offset.dot(&t) > 0.0 { -1.0 } else { 1.0 };
        match self.probe::<P, M>(span, (u0, u1), side * at, chord) {
            Some(probe) => st.bound(cl, lower.max(probe)).map(|(bd, _)| bd),
            None => Some(bd),
        }
    }

    /// The interpolation certificate's first level for a segment `[t0, t1]` that crosses one
    /// knot, from span `left` into span `right`, where the curve is at least `C^2`
    /// (`docs/discretization.md`, "Across a knot"): the same identity on the nodes `t0`, `t1`
    /// and the middle, with `N'''` (piecewise polynomial, `N''` continuous) bounded by the
    /// larger of the two spans' norms, each in its own local units (`(t1 - t0) / (k_{i+1} -
    /// k_i)` the step there), refined, while `question` is open, by the third hodograph's
    /// pieces on both sides. `None` where its conditions fail (then only the hull certificate
    /// applies). Costs one evaluation.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn interpolation_bound_across<const P: usize, const M: usize>(
        &self,
        (left, right): (usize, usize),
        (t0, u0, h0): (f64, f64, Vector4<f64>),
        (t1, u1, h1): (f64, f64, Vector4<f64>),
        chord: &Segment<3>,
        al: &Vector3<f64>,
        margin: f64,
        question: Question,
    ) -> Option<Bound> {
        let p = self.deg::<P>();
        let knots = self.local.knots();
        let h = t1 - t0;
        if h.is_nan() || h <= 0.0 {
            return None;
        }
        let tm = 0.5 * (t0 + t1);
        let mid = if tm < knots[left + 1] { left } else { right };
        let hm = self.span_point::<P, M>(mid, self.local_u(mid, tm).0);
        let (a_norm, a_inf) = (al.norm(), al.amax());
        let t_max = t0.abs().max(t1.abs());
        let mut scaled = Scaled {
            hw1: 0.0,
            slack3: 0.0,
            par_w3: 0.0,
            d1: 0.0,
        };
        let mut m3 = 0.0f64;
        let mut hu3s = [0.0f64; 2];
        for (side, span) in [left, right].into_iter().enumerate() {
            let sb = &self.span_bounds[span];
            // The step in the span's local parameter (rounded up), and its powers.
            let rho = self.local_u(span, t0).1;
            let hu = h * rho * (1.0 + 4.0 * f64::EPSILON);
            let (hu2, hu3) = (hu * hu, hu * hu * hu);
            hu3s[side] = hu3;
            let slack = sb.slack + 64.0 * (p as f64).powi(4) * f64::EPSILON * sb.w_max * a_inf;
            scaled.hw1 = scaled.hw1.max(hu * sb.w1);
            scaled.slack3 = scaled.slack3.max(hu3 * slack);
            scaled.par_w3 = scaled.par_w3.max(hu3 * sb.w3 + 3.0 * hu2 * sb.w2);
            // The ends' and the middle's local parameters are rounded by about `eps` times
            // `|t| / (k_{i+1} - k_i)` (the middle is rounded in `t`): `4 eps D1` covers it
            // with `D1` scaled by that ratio where it exceeds 1.
            scaled.d1 = scaled.d1.max(sb.d1 * (t_max * rho).max(1.0));
            m3 = m3.max(hu3 * (sb.h3 + a_norm * sb.h3w) * (1.0 + 8.0 * f64::EPSILON));
        }
        if !(m3.is_finite() && scaled.par_w3.is_finite() && scaled.d1.is_finite()) {
            return None;
        }
        let ends = [self.project(&h0), self.project(&h1)];
        let st = Step::new(ends, (self.project(&hm), hm.w), chord, al, margin, scaled)?;
        if let Some(bd) = st.scalar_bound(m3).filter(|bd| question.decided(bd)) {
            return Some(bd);
        }
        // Level 2: the third hodograph's pieces on both sides of the knot, each multiplied by
        // the cube of the step in its span's local units.
        let q = p - 3;
        let mut g = [[Vector3::zeros(); M]; 2];
        for (side, (span, u0, u1)) in [(left, u0, 1.0), (right, 0.0, u1)].into_iter().enumerate() {
            let mut d = [Vector4::zeros(); M];
            d[..=q].copy_from_slice(&self.span_h3[span * (p + 1)..][..=q]);
            if u1 > u0 {
                split_to(&mut d[..=q], u0, u1);
            }
            for j in 0..=q {
                g[side][j] = (d[j].xyz() - al * d[j].w) * hu3s[side];
            }
        }
        let (cl, _) = st.hodograph_cl(&[&g[0][..=q], &g[1][..=q]], margin)?;
        st.bound(cl, st.lower).map(|(bd, _)| bd)
    }

    /// The distance to the chord of the curve point at `x = s - 1/2` (`|x| <= 1/2`) of the
    /// step `[u0, u1]` of span `span`, if the point is worth an evaluation (not within a
    /// twentieth of the step from the middle, where the middle point's distance is as good).
    #[inline(always)]
    fn probe<const P: usize, const M: usize>(
        &self,
        span: usize,
        (u0, u1): (f64, f64),
        x: f64,
        chord: &Segment<3>,
    ) -> Option<f64> {
        if x.is_nan() || x.abs() < 0.05 {
            return None;
        }
        let u = (u0 + (0.5 + x) * (u1 - u0)).clamp(u0, u1);
        let v = self.span_point::<P, M>(span, u);
        Some(chord.distance_upper(&self.project(&v)))
    }
}

/// Replaces the Bezier control points `d` on `[0, 1]` by those of the piece on `[u0, u1]`
/// (`0 <= u0 < u1 <= 1`): the left part at `u1`, then the right part of that at `u0 / u1`, as
/// the hull certificate cuts its pieces (every level a convex combination).
#[inline(always)]
pub(super) fn split_to(d: &mut [Vector4<f64>], u0: f64, u1: f64) {
    let q = d.len() - 1;
    if u1 < 1.0 {
        for r in 1..=q {
            for i in (r..=q).rev() {
                d[i] = d[i - 1] * (1.0 - u1) + d[i] * u1;
            }
        }
    }
    if u0 > 0.0 {
        let v = (u0 / u1).clamp(0.0, 1.0);
        for r in 1..=q {
            for i in 0..=(q - r) {
                d[i] = d[i] * (1.0 - v) + d[i + 1] * v;
            }
        }
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
        let (h3, out) = span_derivative_bounds(4, &b, &[16.0]);
        assert!(out[0].d1.is_finite(), "{:?}", out[0]);
        assert!(all_finite(&h3, &out[0]), "a tame span is usable");
        let mut bad = h3.clone();
        bad[0].y = f64::NAN;
        assert!(
            bad.iter().map(|v| v.amax()).fold(0.0, f64::max).is_finite(),
            "a max fold drops the NaN: why the check exists"
        );
        assert!(!all_finite(&bad, &out[0]), "NaN in the third hodograph");
        let mut sb = out[0];
        sb.w3 = f64::NAN;
        assert!(!all_finite(&h3, &sb), "NaN in a weight bound");
    }
}
