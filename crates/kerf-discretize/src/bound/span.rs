//! The span-local evaluator: curve points and derivatives from each knot span's cached
//! Bezier form, by de Casteljau in the local frame.

use super::Certifier;
use kerf_nurbs::MAX_ORDER;
use nalgebra::{Point3, Vector3, Vector4};

impl Certifier<'_> {
    /// The homogeneous point of span `span`'s Bezier form at the local parameter `u` in
    /// `[0, 1]`, by de Casteljau (`p` levels of convex combinations, like the splits of Step
    /// 1). Counts as one evaluation.
    #[inline]
    pub(super) fn span_point<const M: usize>(&self, span: usize, u: f64) -> Vector4<f64> {
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
}
