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

mod hull;
mod interpolation;
mod span;
mod turn;

use hull::Piece;
use interpolation::{span_derivative_bounds, SpanBounds};

pub(crate) use interpolation::Question;

pub(crate) use span::Eval;

/// Runs `$go!(P, M)` with the const degree `P` of the curve's degree `$p` (and `M >= P + 1`,
/// the size of the work arrays) for degrees 1 to 7, else with `P = 0` (the degree read at run
/// time) and `M = MAX_ORDER`: the kernels of the walk and the interpolation certificate are
/// unrolled for the degrees of real curves.
macro_rules! by_degree {
    ($p:expr, $go:ident) => {
        match $p {
            1 => $go!(1, 4),
            2 => $go!(2, 4),
            3 => $go!(3, 4),
            4 => $go!(4, 8),
            5 => $go!(5, 8),
            6 => $go!(6, 8),
            7 => $go!(7, 8),
            _ => $go!(0, { kerf_nurbs::MAX_ORDER }),
        }
    };
}
pub(crate) use by_degree;

/// A curve value the caller already knows: the knot span, the local parameter in it and the
/// homogeneous local point at a parameter (from [`Certifier::eval`]), so that the certificate
/// neither evaluates it nor divides by the span's width again.
pub(crate) type Known = Option<(usize, f64, Vector4<f64>)>;
use kerf_nurbs::{LocalCurve, NurbsCurve, Segment, MAX_ORDER};
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

/// Two remembered homogeneous points of the local frame, by parameter and span (with the
/// local parameter).
type Ends = [Option<(f64, usize, f64, Vector4<f64>)>; 2];

/// Subdivisions of one Bezier piece beyond which it is not refined further: the rounding
/// margin covers the de Casteljau levels of this many halvings (see [`MARGIN_FACTOR`]).
pub const MAX_SUBDIVISION_DEPTH: u32 = 48;

/// The margin constant: `MARGIN_FACTOR (p + 1) eps * 2 L` (`L` the span's largest local
/// coordinate). It covers
/// the `p` de Boor levels of the Bezier extraction, `p` de Casteljau levels for each of up to
/// [`MAX_SUBDIVISION_DEPTH`] halvings, the projection and the distance, each one rounding of a
/// convex combination (`docs/discretization.md`, Step 5).
pub const MARGIN_FACTOR: f64 = 128.0;

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
    /// Per knot span index: the bounds of the interpolation certificate.
    span_bounds: Vec<SpanBounds>,
    /// Whether every weight is 1 (a polynomial curve): then every homogeneous weight the
    /// certificate computes is exactly 1 and the projections are skipped
    /// ([`Certifier::project`]).
    unit_weights: bool,
    /// [`Certifier::max_margin`] and [`Certifier::output_resolution`], known on construction.
    max_margin: f64,
    output_resolution: f64,
    /// `4 eps max |P_i|` for curves whose weights are not powers of two (the control points are
    /// recovered from `w P` by one division, within two ulps), else 0.
    representation: f64,
}

/// The rounding magnitudes of a curve, known from its control points alone (before any
/// Bezier form or walk): what [`Certifier::max_margin`] and [`Certifier::output_resolution`]
/// report, and what [`crate::check_tolerance`] compares with the tolerance.
pub(crate) struct Margins {
    /// Per knot span index: `L = max_i |P_i - O|_inf` over the span's `p + 1` control points
    /// (0 for empty spans).
    pub spans: Vec<f64>,
    pub max_margin: f64,
    pub output_resolution: f64,
}

impl Margins {
    /// From the curve's translation to its local origin.
    pub(crate) fn of(curve: &NurbsCurve, lc: &LocalCurve) -> Self {
        let p = curve.degree();
        let knots = curve.knots();
        let mags = lc.magnitudes();
        let mut spans = vec![0.0; curve.len()];
        for i in (p..curve.len()).filter(|&i| knots[i] < knots[i + 1]) {
            spans[i] = mags[i - p..=i].iter().copied().fold(0.0, f64::max);
        }
        let worst = spans.iter().copied().fold(0.0, f64::max);
        let f = MARGIN_FACTOR * (p + 1) as f64 * f64::EPSILON;
        Self {
            spans,
            max_margin: (2.0 * f + 8.0 * f64::EPSILON) * worst + lc.representation_mm(),
            output_resolution: 2.0 * f64::EPSILON * lc.max_coordinate(),
        }
    }
}

impl<'a> Certifier<'a> {
    /// Prepares `curve` for certification.
    pub fn new(curve: &'a NurbsCurve) -> Self {
        // The exact translation to the local origin, the per-point magnitudes and the weights'
        // kinds: one pass over the control points (kerf_nurbs::LocalCurve, shared with the
        // checker).
        let lc = LocalCurve::new(curve);
        let (origin, unit_weights) = (lc.origin(), lc.unit_weights());
        let representation = lc.representation_mm();
        let Margins {
            spans,
            max_margin,
            output_resolution,
        } = Margins::of(curve, &lc);
        let p = curve.degree();
        let knots = curve.knots();
        let local = lc.into_curve();
        let mut span_bezier = vec![Vector4::zeros(); curve.len() * (p + 1)];
        for i in (p..curve.len()).filter(|&i| knots[i] < knots[i + 1]) {
            let out = &mut span_bezier[i * (p + 1)..(i + 1) * (p + 1)];
            local.bezier_in_span_into(i, knots[i], knots[i + 1], out);
        }
        let (span_h3, span_bounds) = span_derivative_bounds(p, &span_bezier, &spans);
        Self {
            curve,
            local,
            origin,
            spans,
            span_bezier,
            span_h3,
            span_bounds,
            unit_weights,
            representation,
            max_margin,
            output_resolution,
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
        self.max_margin
    }

    /// The resolution of the output: one ulp of the largest coordinate of the curve's control
    /// points. A cutting point is a rounded `f64`, so it is off the curve by up to about half
    /// of this per coordinate, and no chord error below it can be certified reliably.
    pub fn output_resolution(&self) -> f64 {
        self.output_resolution
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
        macro_rules! go {
            ($p:literal, $m:expr) => {
                self.chord_error_known::<$p, $m>(
                    scratch,
                    (t0, None),
                    (t1, None),
                    a,
                    b,
                    Question {
                        limit,
                        want_lower,
                        settle: false,
                    },
                )
            };
        }
        by_degree!(self.curve.degree(), go)
    }

    /// [`Certifier::chord_error`] for a curve of degree `P` (0: any degree; `M >= P + 1` the
    /// size of the work arrays), with, optionally, the span and homogeneous local point that
    /// each end was evaluated from (by [`Certifier::eval`]), which saves evaluating them
    /// again, and the question asked.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn chord_error_known<const P: usize, const M: usize>(
        &self,
        scratch: &mut Scratch,
        (t0, start): (f64, Known),
        (t1, end): (f64, Known),
        a: &Point3<f64>,
        b: &Point3<f64>,
        question: Question,
    ) -> Bound {
        let Question {
            limit, want_lower, ..
        } = question;
        let (al, bl) = (a - self.origin, b - self.origin);
        let chord = Segment::between(&al, &bl);
        let margin = 8.0 * f64::EPSILON * al.coords.amax().max(bl.coords.amax());
        let mut lower = 0.0f64;
        let span = match start {
            Some((s, _, _)) => s,
            None => self.local.span(t0),
        };
        // Most segments lie in one span, or cross one knot where the curve is C^2, and are
        // decided by the interpolation certificate without any subdivision.
        let span_margin = |l: f64| {
            margin.max((2.0 * self.factor() + 8.0 * f64::EPSILON) * l) + self.representation
        };
        let interpolated = if t1 <= self.local.knots()[span + 1] {
            let known_end = end.filter(|e| e.0 == span);
            let ((u0, h0), (u1, h1)) = match (start, known_end) {
                // The walk knows both ends: nothing to remember.
                (Some((_, u0, v0)), Some((_, u1, v1))) => ((u0, v0), (u1, v1)),
                _ => {
                    let ends = &mut scratch.ends;
                    let (u0, h0, keep) = match start.or_else(|| find(ends, t0, span)) {
                        Some((_, u, v)) => {
                            (u, v, ends.iter().position(|e| e.is_some_and(|e| e.0 == t0)))
                        }
                        None => {
                            let (u, v) = self.span_value::<P, M>(span, t0);
                            ends[0] = Some((t0, span, u, v));
                            (u, v, Some(0))
                        }
                    };
                    let (u1, h1) = match known_end {
                        Some((_, u, v)) => (u, v),
                        None => self.span_value::<P, M>(span, t1),
                    };
                    ends[if keep == Some(0) { 1 } else { 0 }] = Some((t1, span, u1, h1));
                    ((u0, h0), (u1, h1))
                }
            };
            self.interpolation_bound::<P, M>(
                span,
                (u0, h0),
                (u1, h1),
                &chord,
                &al.coords,
                span_margin(self.spans[span]),
                question,
            )
        } else if let Some(right) = self.across_one_knot(span, t1) {
            let (u0, h0) = match start.or_else(|| find(&scratch.ends, t0, span)) {
                Some((_, u, v)) => (u, v),
                None => self.span_value::<P, M>(span, t0),
            };
            let (u1, h1) = match end.filter(|e| e.0 == right) {
                Some((_, u, v)) => (u, v),
                None => self.span_value::<P, M>(right, t1),
            };
            self.interpolation_bound_across::<P, M>(
                (span, right),
                (t0, u0, h0),
                (t1, u1, h1),
                &chord,
                &al.coords,
                span_margin(self.spans[span].max(self.spans[right])),
                question,
            )
        } else {
            None
        };
        if let Some(bd) = interpolated {
            if question.settled(&bd) {
                return bd;
            }
            lower = bd.lower;
        }
        // The walk only needs to know whether the segment is certified.
        let want_lower = if question.settle { 0.0 } else { want_lower };
        match self.curve.degree() {
            0..=3 => self.hull_bound(
                &mut scratch.small,
                t0,
                t1,
                &chord,
                margin,
                lower,
                limit,
                want_lower,
            ),
            4..=7 => self.hull_bound(
                &mut scratch.medium,
                t0,
                t1,
                &chord,
                margin,
                lower,
                limit,
                want_lower,
            ),
            _ => self.hull_bound(
                &mut scratch.large,
                t0,
                t1,
                &chord,
                margin,
                lower,
                limit,
                want_lower,
            ),
        }
    }
}

/// The remembered homogeneous point at `t` in `span`, if any.
impl Certifier<'_> {
    /// The knot span after the knot that ends `span`, if `t1` lies in it (up to its end) and
    /// the curve is `C^2` at that knot (multiplicity `m <= p - 2`): a segment from `span` to
    /// `t1` then crosses exactly one knot, where the interpolation certificate still applies.
    #[inline(always)]
    fn across_one_knot(&self, span: usize, t1: f64) -> Option<usize> {
        let knots = self.local.knots();
        let k = *knots.get(span + 1)?;
        let mut right = span + 1;
        while knots.get(right + 1) == Some(&k) {
            right += 1;
        }
        let m = right - span;
        (m + 2 <= self.curve.degree() && right < self.spans.len() && t1 <= *knots.get(right + 1)?)
            .then_some(right)
    }
}

fn find(ends: &Ends, t: f64, span: usize) -> Known {
    ends.iter()
        .flatten()
        .find(|e| e.0 == t && e.1 == span)
        .map(|e| (e.1, e.2, e.3))
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
