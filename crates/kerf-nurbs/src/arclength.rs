//! Arc length with error control, and its inverse.
//!
//! The length of each knot span is integrated by adaptive Gauss-Legendre quadrature: a span is
//! split in halves until the 10-point rule on the whole and on the halves agree to the
//! requested tolerance. Within a span the speed `|C'(t)|` is smooth (analytic for rational
//! pieces with positive weights), so the rule converges fast; the span boundaries are where the
//! speed may have kinks, which is why the integration never crosses them.

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

impl NurbsCurve {
    /// `|C'(t)|`, the speed of the parametrisation.
    #[inline]
    pub fn speed(&self, t: f64) -> f64 {
        self.eval_d1(t).1.norm()
    }

    fn gauss(&self, a: f64, b: f64) -> f64 {
        let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
        let mut s = 0.0;
        for i in 0..5 {
            s += GL10_WEIGHTS[i]
                * (self.speed(m - h * GL10_NODES[i]) + self.speed(m + h * GL10_NODES[i]));
        }
        s * h
    }

    fn adaptive(&self, a: f64, b: f64, whole: f64, tol: f64, depth: u32) -> f64 {
        let m = 0.5 * (a + b);
        let (l, r) = (self.gauss(a, m), self.gauss(m, b));
        if depth == 0 || (l + r - whole).abs() <= tol {
            return l + r;
        }
        self.adaptive(a, m, l, 0.5 * tol, depth - 1) + self.adaptive(m, b, r, 0.5 * tol, depth - 1)
    }

    /// Length of the curve between parameters `t0 <= t1` (clamped to the domain), to an
    /// absolute accuracy of about `1e-13` times the curve's size.
    pub fn arc_length_between(&self, t0: f64, t1: f64) -> f64 {
        let (a, b) = self.domain();
        let (t0, t1) = (t0.clamp(a, b), t1.clamp(a, b));
        if t1 <= t0 {
            return 0.0;
        }
        let tol = 1e-13 * self.size().max(f64::MIN_POSITIVE);
        let mut total = 0.0;
        for (_, s0, s1) in self.spans() {
            let (lo, hi) = (s0.max(t0), s1.min(t1));
            if hi > lo {
                let whole = self.gauss(lo, hi);
                total += self.adaptive(lo, hi, whole, tol, 40);
            }
        }
        total
    }

    /// Length of the whole curve.
    pub fn arc_length(&self) -> f64 {
        let (a, b) = self.domain();
        self.arc_length_between(a, b)
    }

    /// The parameter `t` at which the arc length from the domain start equals `s`, found by
    /// Newton's method on `L(t) - s` (derivative: the speed) safeguarded by bisection.
    ///
    /// # Errors
    /// [`NurbsError::ParameterOutsideDomain`] if `s` is not in `[0, length]` (the "domain" in
    /// the error is then the length range).
    pub fn param_at_length(&self, s: f64) -> Result<f64> {
        let (a, b) = self.domain();
        let total = self.arc_length();
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
        let tol = 1e-12 * total.max(f64::MIN_POSITIVE);
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
            if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1.0) {
                break;
            }
        }
        Ok(t)
    }
}
