//! The span-local evaluator: curve points and derivatives from each knot span's cached
//! Bezier form, by de Casteljau in the local frame.
//!
//! The kernels take the degree as a const parameter `P` (with `M = P + 1` the array size), so
//! that for the degrees of real curves every de Casteljau level is unrolled and the control
//! points are copied into arrays of exactly their size; `P = 0` is the generic kernel for any
//! degree, the degree then read from the curve.

use super::Certifier;
use kerf_nurbs::MAX_ORDER;
use nalgebra::{Point3, Vector3, Vector4};

/// A curve point with what the walk and the certificate need of it: its span and homogeneous
/// local value (the certificate's input), the point in the global frame and the first three
/// derivatives with respect to `t` (the step model's input).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Eval {
    /// The parameter.
    pub t: f64,
    /// The knot span it was evaluated in (right-sided at a knot).
    pub span: usize,
    /// The local parameter in that span ([`Certifier::local_u`]).
    pub u: f64,
    /// The homogeneous point of the span's Bezier form, local frame.
    pub h: Vector4<f64>,
    /// The point, global frame.
    pub p: Point3<f64>,
    /// `C'`, `C''`, `C'''` with respect to `t` (zero where not asked for).
    pub d: [Vector3<f64>; 3],
}

impl Certifier<'_> {
    /// The degree the kernels of const degree `P` work with (`P = 0`: the curve's).
    #[inline(always)]
    pub(super) fn deg<const P: usize>(&self) -> usize {
        if P > 0 {
            P
        } else {
            self.curve.degree()
        }
    }

    /// The span's homogeneous Bezier control points, copied into an array of `M >= p + 1`.
    #[inline(always)]
    fn span_cp<const P: usize, const M: usize>(&self, span: usize) -> [Vector4<f64>; M] {
        let p = self.deg::<P>();
        let mut d = [Vector4::zeros(); M];
        d[..=p].copy_from_slice(&self.span_bezier[span * (p + 1)..][..=p]);
        d
    }

    /// The local Cartesian point of a homogeneous one: `h.xyz / h.w`, or `h.xyz` itself for a
    /// curve whose weights are all 1 (every de Casteljau level of weights 1 is exactly 1, since
    /// `fl(fl(1 - u) + u) = 1` for `u` in `[0, 1]`, so this is the same number without the
    /// division).
    #[inline(always)]
    pub(super) fn project(&self, h: &Vector4<f64>) -> Vector3<f64> {
        if self.unit_weights {
            h.xyz()
        } else {
            h.xyz() / h.w
        }
    }

    /// The knot span of `t`: `hint` if `t` lies in it (the walk mostly stays in one span),
    /// else by binary search (right-sided at a knot, the last span at the domain's end).
    #[inline(always)]
    pub(crate) fn span_at(&self, t: f64, hint: usize) -> usize {
        let knots = self.local.knots();
        if hint + 1 < knots.len() && knots[hint] <= t && t < knots[hint + 1] {
            hint
        } else {
            self.local.span(t)
        }
    }

    /// The local parameter `u = (t - k_i) / (k_{i+1} - k_i)` of `t` in span `span`, clamped
    /// to `[0, 1]`, and `1 / (k_{i+1} - k_i)`.
    #[inline(always)]
    pub(super) fn local_u(&self, span: usize, t: f64) -> (f64, f64) {
        let knots = self.local.knots();
        let (klo, khi) = (knots[span], knots[span + 1]);
        let dk = khi - klo;
        if dk > 0.0 {
            (((t - klo) / dk).clamp(0.0, 1.0), 1.0 / dk)
        } else {
            (0.0, f64::INFINITY)
        }
    }

    /// The homogeneous point of span `span`'s Bezier form at the local parameter `u` in
    /// `[0, 1]`, by de Casteljau (`p` levels of convex combinations, like the splits of Step
    /// 1). Counts as one evaluation.
    #[inline(always)]
    pub(super) fn span_point<const P: usize, const M: usize>(
        &self,
        span: usize,
        u: f64,
    ) -> Vector4<f64> {
        kerf_nurbs::tick();
        let p = self.deg::<P>();
        let mut d = self.span_cp::<P, M>(span);
        let v = 1.0 - u;
        for r in 1..=p {
            for i in 0..=(p - r) {
                d[i] = d[i] * v + d[i + 1] * u;
            }
        }
        d[0]
    }

    /// The local parameter of `t` in span `span` ([`Certifier::local_u`]) and the span's
    /// homogeneous value there ([`Certifier::span_point`]): what the certificate needs of an
    /// end its caller did not evaluate. Counts as one evaluation.
    #[inline(always)]
    pub(super) fn span_value<const P: usize, const M: usize>(
        &self,
        span: usize,
        t: f64,
    ) -> (f64, Vector4<f64>) {
        let u = self.local_u(span, t).0;
        (u, self.span_point::<P, M>(span, u))
    }

    /// The curve point at `t`, evaluated on the span's cached Bezier form by de Casteljau (`p`
    /// levels of convex combinations in the local frame, then translated back): the walk's
    /// cutting points. Within a few `eps` of the local magnitude of the curve's value (the
    /// rounding is measured by the interpolation certificate, which evaluates the same way),
    /// and far cheaper than a basis-function evaluation. Counts as one evaluation.
    pub(crate) fn point(&self, t: f64) -> Point3<f64> {
        let span = self.local.span(t);
        match self.curve.degree() {
            0..=3 => self.eval::<0, 4, 0>(span, t).p,
            4..=7 => self.eval::<0, 8, 0>(span, t).p,
            _ => self.eval::<0, MAX_ORDER, 0>(span, t).p,
        }
    }

    /// The point (global frame) and the first derivative at `t`, as [`Certifier::point`].
    pub(crate) fn eval_d1(&self, t: f64) -> (Point3<f64>, Vector3<f64>) {
        let span = self.local.span(t);
        let e = match self.curve.degree() {
            0..=3 => self.eval::<0, 4, 1>(span, t),
            4..=7 => self.eval::<0, 8, 1>(span, t),
            _ => self.eval::<0, MAX_ORDER, 1>(span, t),
        };
        (e.p, e.d[0])
    }

    /// The point and the derivatives up to order `N` (`N <= 3`; higher entries zero) with
    /// respect to `t` in knot span `span`, from the span's Bezier form: de Casteljau down to
    /// level `p - N`, whose forward differences give the homogeneous derivatives
    /// (`p! / (p - k)! Delta^k`), then the quotient rule. Counts as one evaluation.
    #[inline(always)]
    pub(crate) fn eval<const P: usize, const M: usize, const N: usize>(
        &self,
        span: usize,
        t: f64,
    ) -> Eval {
        kerf_nurbs::tick();
        let p = self.deg::<P>();
        let (u, inv) = self.local_u(span, t);
        let mut d = self.span_cp::<P, M>(span);
        let v = 1.0 - u;
        let m = N.min(p);
        for r in 1..=(p - m) {
            for i in 0..=(p - r) {
                d[i] = d[i] * v + d[i + 1] * u;
            }
        }
        // Homogeneous derivatives from the level p - m points d[0..=m].
        let mut hd = [Vector4::zeros(); 4];
        let pf = p as f64;
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
            }
            hd[1] = (d[1] - d[0]) * (pf * inv);
            d[0] = d[0] * v + d[1] * u;
        }
        let h = d[0];
        let c0 = self.project(&h);
        let mut out = [Vector3::zeros(); 3];
        if self.unit_weights {
            // The weight's derivatives are exactly 0 (differences of ones): the quotient rule
            // below would give these same numbers.
            out[0] = hd[1].xyz();
            out[1] = hd[2].xyz();
            out[2] = hd[3].xyz();
        } else if N >= 1 {
            let w = h.w;
            let c1 = (hd[1].xyz() - c0 * hd[1].w) / w;
            out[0] = c1;
            if N >= 2 {
                let c2 = (hd[2].xyz() - c1 * (2.0 * hd[1].w) - c0 * hd[2].w) / w;
                out[1] = c2;
                if N >= 3 {
                    out[2] =
                        (hd[3].xyz() - c2 * (3.0 * hd[1].w) - c1 * (3.0 * hd[2].w) - c0 * hd[3].w)
                            / w;
                }
            }
        }
        Eval {
            t,
            span,
            u,
            h,
            p: (c0 + self.origin).into(),
            d: out,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::Certifier;

    /// The fast path of [`Certifier::project`] rests on this: with unit weights, the span's
    /// Bezier weights (from the blossom) and every de Casteljau level on them are exactly 1,
    /// whatever the parameter, so skipping the division changes no bit.
    #[test]
    fn unit_weights_stay_exactly_one() {
        for degree in 1..=9 {
            for c in kerf_nurbs::smooth_random_curves(degree, 3, 90 + degree as u64) {
                let cert = Certifier::new(&c);
                assert!(cert.unit_weights, "degree {degree}: unit weights seen");
                assert!(
                    cert.span_bezier.iter().all(|v| v.w == 1.0 || v.w == 0.0),
                    "degree {degree}: span weights exactly 1 (0 for empty spans)"
                );
                for (span, _, _) in c.spans() {
                    for k in 0..=1000 {
                        // Parameters with long mantissas, and the ends.
                        let u = (k as f64 * 0.618_033_988_749_894_9).fract();
                        let u = if k == 0 {
                            0.0
                        } else if k == 1 {
                            1.0
                        } else {
                            u
                        };
                        let w = cert.span_point::<0, { kerf_nurbs::MAX_ORDER }>(span, u).w;
                        assert_eq!(w, 1.0, "degree {degree} span {span} u {u}");
                    }
                }
            }
        }
    }
}
