//! Evaluation of a surface: points and partial derivatives (Piegl and Tiller A3.5, A3.6,
//! A4.4), in fixed-size scratch for the common degrees.

use nalgebra::{Point3, Vector3, Vector4};

use super::NurbsSurface;
use crate::basis::{basis_funs_m, binomial, ders_basis_funs_m};
use crate::curve::project;
use crate::knots;
use crate::MAX_ORDER;

/// Binomial coefficients `C(n, k)` for `n < 8`, for the Leibniz rule of the rational
/// derivatives (orders up to [`TAYLOR_ORDER`] + 1 = 5).
pub(super) const BINOMIAL: [[f64; 8]; 8] = {
    let mut t = [[0.0; 8]; 8];
    let mut n = 0;
    while n < 8 {
        let mut k = 0;
        while k <= n {
            t[n][k] = binomial(n, k);
            k += 1;
        }
        n += 1;
    }
    t
};

impl NurbsSurface {
    /// The point `S(u, v)`. Parameters outside the domain (and NaN) are clamped to it.
    #[inline]
    pub fn point(&self, u: f64, v: f64) -> Point3<f64> {
        let (u, v) = self.clamp_uv(u, v);
        let (su, sv) = self.spans_at(u, v);
        self.point_in(u, v, su, sv)
    }

    /// The knot spans `(su, sv)` that hold `(u, v)` (see [`knots::find_span`]).
    #[inline]
    pub(super) fn spans_at(&self, u: f64, v: f64) -> (usize, usize) {
        (
            knots::find_span(self.degree_u, &self.knots_u, self.n_u, u),
            knots::find_span(self.degree_v, &self.knots_v, self.n_v, v),
        )
    }

    /// The point at `(u, v)` evaluated with the polynomials of the spans `su`, `sv` (so on a
    /// span's upper edge it is the limit from inside the span).
    #[inline]
    pub(super) fn point_in(&self, u: f64, v: f64, su: usize, sv: usize) -> Point3<f64> {
        // Scratch arrays sized for the degree (clearing MAX_ORDER entries would cost more than
        // the arithmetic for the common low degrees).
        match self.degree_u.max(self.degree_v) {
            0..=3 => self.point_in_m::<4>(u, v, su, sv),
            4..=7 => self.point_in_m::<8>(u, v, su, sv),
            _ => self.point_in_m::<MAX_ORDER>(u, v, su, sv),
        }
    }

    /// [`NurbsSurface::point_in`] with scratch arrays of `M > max(degree_u, degree_v)`
    /// entries.
    #[inline]
    pub(super) fn point_in_m<const M: usize>(
        &self,
        u: f64,
        v: f64,
        su: usize,
        sv: usize,
    ) -> Point3<f64> {
        crate::work::tick();
        let (p, q) = (self.degree_u, self.degree_v);
        let mut nu = [0.0; M];
        let mut nv = [0.0; M];
        basis_funs_m(su, u, p, &self.knots_u, &mut nu);
        basis_funs_m(sv, v, q, &self.knots_v, &mut nv);
        let mut acc = Vector4::zeros();
        for i in 0..=p {
            let row = (su - p + i) * self.n_v + (sv - q);
            let mut tmp = Vector4::zeros();
            for j in 0..=q {
                tmp += self.cpw[row + j] * nv[j];
            }
            acc += tmp * nu[i];
        }
        project(&acc)
    }

    /// The point and the first partial derivatives `(S, Su, Sv)` at `(u, v)`, without
    /// allocating. Parameters are clamped to the domain.
    #[inline]
    pub fn eval_d1(&self, u: f64, v: f64) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        let mut s = [[Vector3::zeros(); 2]; 2];
        self.derivs(u, v, &mut s, None);
        (Point3::from(s[0][0]), s[1][0], s[0][1])
    }

    /// The partial derivatives up to order 2 in each parameter, without allocating:
    /// `d[k][l] = d^(k+l) S / du^k dv^l` for `k, l <= 2`, so `d[0][0]` is the point (as a
    /// vector), `d[1][0] = Su`, `d[0][1] = Sv`, `d[2][0] = Suu`, `d[1][1] = Suv`,
    /// `d[0][2] = Svv`, and the mixed third and fourth derivatives `Suuv`, `Suvv`, `Suuvv`
    /// come for free.
    ///
    /// Rational derivatives follow from the homogeneous ones `A(k,l)` (sums of basis-function
    /// derivatives times `(w x, w y, w z, w)`) by the Leibniz rule applied to `A = w S`
    /// (The NURBS Book A4.4):
    /// `S(k,l) = (A(k,l) - sum_{(i,j) != (0,0)} C(k,i) C(l,j) w(i,j) S(k-i,l-j)) / w`.
    /// Parameters are clamped to the domain; at a knot the derivatives are those of the span
    /// that starts there (the last span at the domain end).
    #[inline]
    pub fn derivatives(&self, u: f64, v: f64) -> [[Vector3<f64>; 3]; 3] {
        let mut s = [[Vector3::zeros(); 3]; 3];
        self.derivs(u, v, &mut s, None);
        s
    }

    /// All rational partial derivatives `S(k, l)` with `k < KU`, `l < KV` at `(u, v)` (clamped
    /// to the domain), and optionally running bounds `bound[k][l]` on the magnitude of the
    /// terms summed to obtain them: the rounding error of `S(k, l)` is a small multiple of
    /// `f64::EPSILON * bound[k][l]`.
    #[inline]
    pub(super) fn derivs<const KU: usize, const KV: usize>(
        &self,
        u: f64,
        v: f64,
        s: &mut [[Vector3<f64>; KV]; KU],
        bound: Option<&mut [[f64; KV]; KU]>,
    ) {
        let (u, v) = self.clamp_uv(u, v);
        let (su, sv) = self.spans_at(u, v);
        self.derivs_in(u, v, su, sv, s, bound);
    }

    /// [`NurbsSurface::derivs`] with the polynomials of the spans `su`, `sv`.
    #[inline]
    pub(super) fn derivs_in<const KU: usize, const KV: usize>(
        &self,
        u: f64,
        v: f64,
        su: usize,
        sv: usize,
        s: &mut [[Vector3<f64>; KV]; KU],
        bound: Option<&mut [[f64; KV]; KU]>,
    ) {
        crate::work::tick();
        match self.degree_u.max(self.degree_v) {
            0..=3 => self.derivs_in_m::<KU, KV, 4>(u, v, su, sv, s, bound),
            4..=7 => self.derivs_in_m::<KU, KV, 8>(u, v, su, sv, s, bound),
            _ => self.derivs_in_m::<KU, KV, MAX_ORDER>(u, v, su, sv, s, bound),
        }
    }

    /// [`NurbsSurface::derivs_in`] with basis-function scratch arrays of
    /// `M > max(degree_u, degree_v)` entries.
    #[inline]
    pub(super) fn derivs_in_m<const KU: usize, const KV: usize, const M: usize>(
        &self,
        u: f64,
        v: f64,
        su: usize,
        sv: usize,
        s: &mut [[Vector3<f64>; KV]; KU],
        bound: Option<&mut [[f64; KV]; KU]>,
    ) {
        let (p, q) = (self.degree_u, self.degree_v);
        let mut nu = [[0.0; M]; KU];
        let mut nv = [[0.0; M]; KV];
        ders_basis_funs_m(su, u, p, KU - 1, &self.knots_u, &mut nu[..]);
        ders_basis_funs_m(sv, v, q, KV - 1, &self.knots_v, &mut nv[..]);
        let mut a = [[Vector4::zeros(); KV]; KU];
        let want_bound = bound.is_some();
        // Bounds: sums of |N N'| |P w| (coordinates) and |N N'| w (weights).
        let mut m_abs = [[0.0; KV]; KU];
        let mut w_abs = [[0.0; KV]; KU];
        for i in 0..=p {
            let row = (su - p + i) * self.n_v + (sv - q);
            let mut tmp = [Vector4::zeros(); KV];
            let mut tm = [0.0; KV];
            let mut tw = [0.0; KV];
            for j in 0..=q {
                let c = self.cpw[row + j];
                for l in 0..KV {
                    tmp[l] += c * nv[l][j];
                }
                if want_bound {
                    let mag = c.xyz().norm();
                    for l in 0..KV {
                        let x = nv[l][j].abs();
                        tm[l] += x * mag;
                        tw[l] += x * c.w;
                    }
                }
            }
            for k in 0..KU {
                let x = nu[k][i];
                for l in 0..KV {
                    a[k][l] += tmp[l] * x;
                }
                if want_bound {
                    for l in 0..KV {
                        m_abs[k][l] += x.abs() * tm[l];
                        w_abs[k][l] += x.abs() * tw[l];
                    }
                }
            }
        }
        let w0 = a[0][0].w;
        for k in 0..KU {
            for l in 0..KV {
                let mut val = a[k][l].xyz();
                for j in 1..=l {
                    val -= s[k][l - j] * (BINOMIAL[l][j] * a[0][j].w);
                }
                for i in 1..=k {
                    let bi = BINOMIAL[k][i];
                    val -= s[k - i][l] * (bi * a[i][0].w);
                    for j in 1..=l {
                        val -= s[k - i][l - j] * (bi * BINOMIAL[l][j] * a[i][j].w);
                    }
                }
                s[k][l] = val / w0;
            }
        }
        if let Some(b) = bound {
            for k in 0..KU {
                for l in 0..KV {
                    let mut val = m_abs[k][l];
                    for j in 1..=l {
                        val += b[k][l - j] * BINOMIAL[l][j] * w_abs[0][j];
                    }
                    for i in 1..=k {
                        let bi = BINOMIAL[k][i];
                        val += b[k - i][l] * bi * w_abs[i][0];
                        for j in 1..=l {
                            val += b[k - i][l - j] * bi * BINOMIAL[l][j] * w_abs[i][j];
                        }
                    }
                    b[k][l] = val / w0;
                }
            }
        }
    }
}
