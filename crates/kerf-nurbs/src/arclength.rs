//! Arc length with error control and a work budget, and its inverse.
//!
//! The length of each knot span is integrated by globally adaptive Gauss-Legendre quadrature
//! ([`integrate`]): every panel carries the 10-point rule on itself and on its two halves, whose
//! difference estimates its error; the panel with the largest estimate is split next, until the
//! summed estimate is below the requested accuracy or the work budget (a fixed number of splits
//! per knot span, so linear in the size of the curve) is spent. Within a span the speed
//! `|C'(t)|` is smooth (analytic for rational pieces with positive weights), so the rule
//! converges fast; the span boundaries are where the speed may have kinks, which is why the
//! integration never crosses them.
//!
//! The accuracy asked is never below the rounding noise of the curve's coordinates: the speed is
//! computed from control points of magnitude `X`, so each span's length carries an error of
//! order `(p + 1) eps X` whatever the rule does; asking `1e-13` of a 0.1 mm hole 1.4 m from the
//! origin would otherwise split panels forever. Nor below the rounding of the parameter: a Gauss
//! node `t` is off by up to half an ulp of `t`, which moves the rule's value by up to
//! `eps |t| (max f - min f)` on a panel; on a curve of 100,000 short spans this noise exceeded
//! `1e-13 L` and the quadrature split noise until its budget ran out. `docs/nurbs.md` has the
//! details.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use crate::curve::NurbsCurve;
use crate::error::{NurbsError, Result};

/// Nodes of the 10-point Gauss-Legendre rule on `[-1, 1]` (positive half; the rule is
/// symmetric).
pub const GL10_NODES: [f64; 5] = [
    0.148_874_338_981_631_2,
    0.433_395_394_129_247_2,
    0.679_409_568_299_024_4,
    0.865_063_366_688_984_5,
    0.973_906_528_517_171_7,
];
/// Weights of the 10-point Gauss-Legendre rule, matching [`GL10_NODES`].
pub const GL10_WEIGHTS: [f64; 5] = [
    0.295_524_224_714_752_9,
    0.269_266_719_309_996_4,
    0.219_086_362_515_982_04,
    0.149_451_349_150_580_6,
    0.066_671_344_308_688_14,
];

/// Relative accuracy asked of arc lengths (the absolute floor of [`NurbsCurve::length_floor`]
/// takes over where rounding makes this unreachable).
pub const LENGTH_RELATIVE_ACCURACY: f64 = 1e-13;

/// Panel splits allowed per knot span (each costs 40 evaluations of the integrand and two
/// Bezier extractions) before the quadrature stops and reports itself unconverged. Enough to
/// chase a speed peak 40 halvings deep at both ends of a span (a weight of 1e12).
pub const SPLITS_PER_SPAN: usize = 128;

/// The result of an adaptive quadrature with a work budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quadrature {
    /// The integral's value (the sum of the finest rules computed).
    pub value: f64,
    /// The estimated absolute error of `value` (sum over panels of the difference between the
    /// rule on a panel and on its halves, an over-estimate for smooth integrands).
    pub error: f64,
    /// True if the estimated error met the requested accuracy; false if the work budget ran
    /// out first (`value` is then the best estimate reached, `error` its estimated error) or the
    /// integrand was not finite somewhere.
    pub converged: bool,
    /// Integrand evaluations spent.
    pub evaluations: usize,
}

/// The 10-point Gauss-Legendre rule on `[a, b]`.
#[inline]
pub fn gauss10(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    gauss10_range(f, a, b).0
}

/// [`gauss10`] with the smallest and largest integrand value at its nodes (NaN-free: a NaN
/// value shows in the rule's value instead).
#[inline]
fn gauss10_range(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> (f64, f64, f64) {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let (mut s, mut lo, mut hi) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
    for i in 0..5 {
        let (u, v) = (f(m - h * GL10_NODES[i]), f(m + h * GL10_NODES[i]));
        s += GL10_WEIGHTS[i] * (u + v);
        lo = lo.min(u).min(v);
        hi = hi.max(u).max(v);
    }
    (s * h, lo, hi)
}

#[derive(Debug, Clone, Copy)]
struct Panel {
    a: f64,
    b: f64,
    left: f64,
    right: f64,
    error: f64,
    /// What rounding the nodes' parameters can move the two rules' difference by (see
    /// [`Panel::new`]): error estimates below it are noise, not quadrature error.
    noise: f64,
}

/// Guaranteed bounds `(lower, upper)` of the integral over a panel, if the caller knows any.
pub type Bracket<'a> = &'a dyn Fn(f64, f64) -> (f64, f64);

impl Panel {
    fn new(
        f: &impl Fn(f64) -> f64,
        bracket: Option<Bracket<'_>>,
        a: f64,
        b: f64,
        whole: f64,
    ) -> Self {
        let m = 0.5 * (a + b);
        let ((left, lo_l, hi_l), (right, lo_r, hi_r)) =
            (gauss10_range(f, a, m), gauss10_range(f, m, b));
        // Each node `t` is rounded by up to eps |t| / 2, moving f by |f'| times that; summed
        // with the weights over the panel that is at most (eps |t| / 2) (max f - min f) per
        // rule (f varying by max f - min f across the panel), and the error estimate compares
        // two rules.
        let noise = f64::EPSILON * a.abs().max(b.abs()) * (hi_l.max(hi_r) - lo_l.min(lo_r));
        let mut e = (left + right - whole).abs();
        if let Some(br) = bracket {
            // The rule can miss a peak that none of its nodes sees (the speed of a heavy
            // weight lives in 1e-12 of the parameter); a guaranteed bracket cannot.
            let (lo, hi) = br(a, b);
            let v = left + right;
            e = e.max(lo - v).max(v - hi);
        }
        Panel {
            a,
            b,
            left,
            right,
            // A NaN difference must be split first and never look converged.
            error: if e.is_nan() { f64::INFINITY } else { e },
            noise: if noise.is_finite() { noise } else { 0.0 },
        }
    }
}

impl PartialEq for Panel {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Panel {}
impl PartialOrd for Panel {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Panel {
    /// By error (the heap pops the largest), then by position for determinism.
    fn cmp(&self, other: &Self) -> Ordering {
        self.error
            .total_cmp(&other.error)
            .then(other.a.total_cmp(&self.a))
    }
}

/// Integrates `f` over the union of the intervals `pieces` (each integrated separately, so `f`
/// may have kinks at their ends) to the accuracy `max(relative * |value|, absolute + noise)`,
/// with at most `SPLITS_PER_SPAN`-like `max_splits` panel splits in all (each costs 40
/// evaluations; the start costs 30 per piece). `noise` is what rounding the nodes' parameters
/// alone can change the estimate by, summed over the panels: `eps |t| (max f - min f)` each.
///
/// Globally adaptive: the panel with the largest error estimate is split next, so the budget
/// goes where the integrand is hard (a peak of the speed at a heavy weight, a corner) instead
/// of being spread over a recursion tree. Never loops beyond the budget, whatever `f` returns.
/// With a `bracket` (guaranteed lower and upper bounds of the integral over any panel), a
/// panel's error estimate is at least the distance of its value outside the bracket.
///
/// Besides the evaluations, the work is `O(log n)` per split for the priority queue and, in
/// all, `O(splits + n)` for the exact sums that confirm convergence (`n` the panels): a
/// confirmation that fails waits for `n / 8` further splits before the next one, so estimates
/// hovering at the threshold cannot make it walk all panels on every split.
pub fn integrate(
    f: impl Fn(f64) -> f64,
    bracket: Option<Bracket<'_>>,
    pieces: &[(f64, f64)],
    relative: f64,
    absolute: f64,
    max_splits: usize,
) -> Quadrature {
    let mut heap = BinaryHeap::with_capacity(pieces.len() + 2 * max_splits.min(1 << 16));
    let mut evaluations = 0usize;
    for &(a, b) in pieces {
        if b > a {
            let whole = gauss10(&f, a, b);
            heap.push(Panel::new(&f, bracket, a, b, whole));
            evaluations += 30;
        }
    }
    let sums = |heap: &BinaryHeap<Panel>| {
        heap.iter().fold((0.0, 0.0, 0.0), |(v, e, n), p: &Panel| {
            (v + p.left + p.right, e + p.error, n + p.noise)
        })
    };
    let met = |value: f64, error: f64, noise: f64| {
        error <= relative * value.abs() || error <= absolute + noise
    };
    let (mut value, mut error, mut noise) = sums(&heap);
    let mut splits = 0;
    let mut next_confirmation = 0;
    loop {
        // Running sums drift (and an infinite estimate leaves NaN behind); confirm with exact
        // sums before stopping, at most once per heap.len() / 8 splits.
        let maybe = met(value, error, noise) || !(error.is_finite() && value.is_finite());
        if maybe && splits >= next_confirmation {
            (value, error, noise) = sums(&heap);
            next_confirmation = splits + (heap.len() / 8).max(1);
            if met(value, error, noise) {
                return Quadrature {
                    value,
                    error,
                    converged: value.is_finite(),
                    evaluations,
                };
            }
        }
        let splittable = heap
            .peek()
            .is_some_and(|p| 0.5 * (p.a + p.b) > p.a && 0.5 * (p.a + p.b) < p.b);
        if splits >= max_splits || !splittable {
            (value, error, _) = sums(&heap);
            return Quadrature {
                value,
                error,
                converged: false,
                evaluations,
            };
        }
        let p = heap.pop().expect("a panel exists when not converged");
        let m = 0.5 * (p.a + p.b);
        let l = Panel::new(&f, bracket, p.a, m, p.left);
        let r = Panel::new(&f, bracket, m, p.b, p.right);
        evaluations += 40;
        splits += 1;
        value += l.left + l.right + r.left + r.right - p.left - p.right;
        error += l.error + r.error - p.error;
        noise += l.noise + r.noise - p.noise;
        heap.push(l);
        heap.push(r);
    }
}

impl NurbsCurve {
    /// `|C'(t)|`, the speed of the parametrisation.
    #[inline]
    pub fn speed(&self, t: f64) -> f64 {
        self.eval_d1(t).1.norm()
    }

    /// The rounding noise of a length measured on `spans` knot spans of this curve: each
    /// span's speed is computed from `degree + 1` control points of magnitude up to
    /// `max |P_i|`, so its length carries an error of order `(p + 1) eps max |P_i|` that no
    /// quadrature can remove. Asking for less only burns the budget.
    pub fn length_floor(&self, spans: usize) -> f64 {
        self.floor_of(self.homogeneous_points(), spans)
    }

    /// [`NurbsCurve::length_floor`] with the scale taken from `points` only.
    fn floor_of(&self, points: &[nalgebra::Vector4<f64>], spans: usize) -> f64 {
        let scale = points
            .iter()
            .map(|c| (c.xyz() / c.w).amax())
            .fold(0.0, f64::max);
        16.0 * (self.degree() + 1) as f64 * f64::EPSILON * scale * spans.max(1) as f64
    }

    /// The knot-span pieces of `[t0, t1]` (clamped to the domain) and the rounding floor of
    /// their lengths, found from the spans of `t0` and `t1` (two binary searches), so one
    /// span's length costs the same on a curve of 10 spans or of 100,000: walking every span
    /// and every control point per call made [`NurbsCurve::param_at_length`] quadratic.
    fn pieces(&self, t0: f64, t1: f64) -> (Vec<(f64, f64)>, f64) {
        let (a, b) = self.domain();
        let (t0, t1) = (t0.clamp(a, b), t1.clamp(a, b));
        let (first, last) = (self.span(t0), self.span(t1));
        let knots = self.knots();
        let pieces: Vec<_> = (first..=last)
            .map(|i| (knots[i].max(t0), knots[i + 1].min(t1)))
            .filter(|(lo, hi)| hi > lo)
            .collect();
        let p = self.degree();
        let floor = self.floor_of(&self.homogeneous_points()[first - p..=last], pieces.len());
        (pieces, floor)
    }

    /// The length of the curve between `t0 <= t1` (clamped to the domain) with its error
    /// estimate: relative accuracy [`LENGTH_RELATIVE_ACCURACY`], absolute floor
    /// [`NurbsCurve::length_floor`], at most [`SPLITS_PER_SPAN`] panel splits per span. Every
    /// panel's value is also checked against its guaranteed bracket `[chord, control polygon]`,
    /// so a speed peak that the Gauss nodes miss is split down to instead of being reported as
    /// converged.
    pub fn arc_length_quadrature(&self, t0: f64, t1: f64) -> Quadrature {
        let (pieces, floor) = self.pieces(t0, t1);
        // The length of a rational Bezier piece lies between its chord and its control
        // polygon (subdivision in homogeneous space projects to corner cutting).
        let bracket = |a: f64, b: f64| {
            let bez = self.bezier_in_span(self.span(a), a, b);
            let q: Vec<_> = bez.control_points().collect();
            let chord = (q[q.len() - 1] - q[0]).norm();
            let polygon: f64 = q.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
            let slack = 1e-12 * polygon;
            (chord - slack, polygon + slack)
        };
        integrate(
            |t| self.speed(t),
            Some(&bracket),
            &pieces,
            LENGTH_RELATIVE_ACCURACY,
            floor,
            SPLITS_PER_SPAN * pieces.len(),
        )
    }

    /// Length of the curve between parameters `t0 <= t1` (clamped to the domain), to a relative
    /// accuracy of about `1e-13` or the rounding noise of the coordinates, whichever is larger
    /// (see [`NurbsCurve::arc_length_quadrature`] for the error estimate and the budget).
    pub fn arc_length_between(&self, t0: f64, t1: f64) -> f64 {
        self.arc_length_quadrature(t0, t1).value
    }

    /// Length of the whole curve.
    pub fn arc_length(&self) -> f64 {
        let (a, b) = self.domain();
        self.arc_length_between(a, b)
    }

    /// The parameter `t` at which the arc length from the domain start equals `s`, found by
    /// Newton's method on `L(t) - s` (derivative: the speed) safeguarded by bisection, to the
    /// accuracy of the length itself (at most 100 steps, each one span's quadrature).
    ///
    /// # Errors
    /// [`NurbsError::ParameterOutsideDomain`] if `s` is not in `[0, length]` (the "domain" in
    /// the error is then the length range).
    pub fn param_at_length(&self, s: f64) -> Result<f64> {
        let (a, b) = self.domain();
        let whole = self.arc_length_quadrature(a, b);
        let total = whole.value;
        if !(s >= 0.0 && s <= total) {
            return Err(NurbsError::ParameterOutsideDomain {
                value: s,
                start: 0.0,
                end: total,
            });
        }
        // Locate the span by accumulated lengths.
        let mut acc = 0.0;
        let (mut lo, mut hi) = (a, b);
        for (_, s0, s1) in self.spans() {
            let l = self.arc_length_between(s0, s1);
            if acc + l >= s {
                lo = s0;
                hi = s1;
                break;
            }
            acc += l;
        }
        let target = s - acc;
        let base = lo;
        let tol = (1e-12 * total)
            .max(2.0 * whole.error)
            .max(self.length_floor(self.spans().len()))
            .max(f64::MIN_POSITIVE);
        let mut t =
            lo + (hi - lo) * (target / self.arc_length_between(lo, hi).max(f64::MIN_POSITIVE));
        for _ in 0..100 {
            let f = self.arc_length_between(base, t) - target;
            if f.abs() <= tol {
                return Ok(t);
            }
            if f > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            let v = self.speed(t);
            let newton = t - f / v;
            t = if v > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
                break;
            }
        }
        Ok(t)
    }
}
