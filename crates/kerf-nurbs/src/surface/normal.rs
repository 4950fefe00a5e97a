//! Unit normals, with their limits on collapsed edges (the poles of a sphere, the apex of a
//! cone) and at degenerate points without one (Taylor expansion of the cross product).

use nalgebra::{Vector3, Vector4};

use super::{boundary_span_len, NurbsSurface, NEAR_EDGE, NOISE, TAYLOR_ORDER};
use crate::basis::{basis_funs, binomial};
use crate::curve::project;
use crate::knots;
use crate::MAX_ORDER;

impl NurbsSurface {
    /// The unit normal `Su x Sv / |Su x Sv|` at `(u, v)` (clamped to the domain), with a
    /// well-defined limit where `Su x Sv` vanishes; `None` only where no limit exists along
    /// the parameter lines (e.g. a surface collapsed to a curve or a point).
    ///
    /// **Orientation** is always that of `Su x Sv` at nearby interior points.
    ///
    /// **Degenerate points.** Let the surface collapse along the edge `u = u0` (all of the edge
    /// is one point: the pole of a sphere, the apex of a cone), so `Sv(u0, v) = 0` for every
    /// `v`. Moving off the edge into the interior, `u = u0 + s*h` with `h > 0` and `s = +1` at
    /// the start of the domain, `s = -1` at its end, Taylor expansion gives
    /// `Sv(u, v) = s h Suv(u0, v) + O(h^2)` and
    /// `Su x Sv = s h (Su x Suv) + O(h^2)`, so the limit normal is
    /// `s (Su x Suv) / |Su x Suv|` at `(u0, v)`. In general the limit is the first
    /// non-vanishing Taylor coefficient of `f(h) = Su x Sv` along the parameter line:
    /// `f^(k)(0) = s^k sum_{i=0..k} C(k,i) S(i+1,0) x S(k-i,1)` (Leibniz rule); orders up to
    /// 4 are tried, so edges whose first derivatives also vanish are handled too. A collapsed
    /// edge `v = v0` is the mirror case with `f^(k)(0) = s^k sum_i C(k,i) S(1,i) x S(0,k-i+1)`.
    /// For a surface that is smooth at the pole (a sphere) this limit does not depend on `v`;
    /// at a cone's apex it is the normal along the ruling through `v`, the limit a tool moving
    /// along that ruling sees.
    ///
    /// Near a collapsed edge the direct `Su x Sv` loses precision (`Sv` is computed as a
    /// difference of nearly equal terms, with relative error about `eps / h`). Within
    /// `1e-5` of the boundary knot span from such an edge the normal is therefore computed as
    /// `s Su(u, v) x Suv(um, v)` with `um = (u + u0) / 2`: since `Sv(u0, v) = 0`,
    /// `Sv(u, v) = (u - u0) Suv(um, v) + O(h^3)` by the mid-point rule, which has relative error
    /// `O(h^2)` and no cancellation. Elsewhere, a point where `|Su x Sv|` is below its rounding
    /// noise (estimated from running error bounds) is treated like an edge point, moving in the
    /// direction of the parameter whose derivative vanishes (towards the interior).
    pub fn normal(&self, u: f64, v: f64) -> Option<Vector3<f64>> {
        let (u, v) = self.clamp_uv(u, v);
        if let Some(n) = self.normal_near_collapsed_edge(u, v) {
            return Some(n);
        }
        let mut s = [[Vector3::zeros(); 2]; 2];
        let mut b = [[0.0; 2]; 2];
        self.derivs(u, v, &mut s, Some(&mut b));
        let (su, sv) = (s[1][0], s[0][1]);
        let n = su.cross(&sv);
        let noise = NOISE * (b[1][0] * sv.norm() + su.norm() * b[0][1]);
        if n.norm() > noise && n.norm().is_finite() {
            return Some(n.normalize());
        }
        // Degenerate: move along the parameter whose derivative (relatively) vanishes.
        let ru = su.norm() / b[1][0].max(f64::MIN_POSITIVE);
        let rv = sv.norm() / b[0][1].max(f64::MIN_POSITIVE);
        let along_u = rv <= ru;
        self.taylor_normal(u, v, along_u, self.interior_sign(along_u, u, v))
            .or_else(|| self.taylor_normal(u, v, !along_u, self.interior_sign(!along_u, u, v)))
    }

    /// The direction (+1 or -1) into the domain along the u (or v) parameter line at
    /// `(u, v)`: backwards at the end of the domain, forwards elsewhere.
    pub(super) fn interior_sign(&self, along_u: bool, u: f64, v: f64) -> f64 {
        let at_end = if along_u {
            u >= self.domain_u().1
        } else {
            v >= self.domain_v().1
        };
        if at_end {
            -1.0
        } else {
            1.0
        }
    }

    /// The mid-point formula of [`NurbsSurface::normal`] near a collapsed domain edge, or
    /// `None` if `(u, v)` is not near one.
    pub(super) fn normal_near_collapsed_edge(&self, u: f64, v: f64) -> Option<Vector3<f64>> {
        let (ua, ub) = self.domain_u();
        let (va, vb) = self.domain_v();
        if self.collapsed == [false; 4] {
            return None;
        }
        let (p, q) = (self.degree_u, self.degree_v);
        // (along u, edge parameter, direction into the interior, distance, edge slot)
        let edges = [
            (true, ua, 1.0, u - ua, 0),
            (true, ub, -1.0, ub - u, 1),
            (false, va, 1.0, v - va, 2),
            (false, vb, -1.0, vb - v, 3),
        ];
        let mut chosen: Option<(bool, f64, f64)> = None;
        let mut closest = f64::INFINITY;
        for (along_u, edge, sign, dist, slot) in edges {
            if !self.collapsed[slot] {
                continue;
            }
            let last = slot % 2 == 1;
            let span = if along_u {
                boundary_span_len(p, &self.knots_u, self.n_u, last)
            } else {
                boundary_span_len(q, &self.knots_v, self.n_v, last)
            };
            let rel = dist / span;
            if rel <= NEAR_EDGE && rel < closest {
                closest = rel;
                chosen = Some((along_u, edge, sign));
            }
        }
        let (along_u, edge, sign) = chosen?;
        let mut s = [[Vector3::zeros(); 2]; 2];
        let mut b = [[0.0; 2]; 2];
        let mut m = [[Vector3::zeros(); 2]; 2];
        let mut bm = [[0.0; 2]; 2];
        self.derivs(u, v, &mut s, Some(&mut b));
        let (n, noise) = if along_u {
            self.derivs(0.5 * (u + edge), v, &mut m, Some(&mut bm));
            // Sv(u) ~ (u - u0) Suv(um): Su x Sv ~ sign * h * (Su x Suv(um)).
            let n = s[1][0].cross(&m[1][1]) * sign;
            (
                n,
                NOISE * (b[1][0] * m[1][1].norm() + s[1][0].norm() * bm[1][1]),
            )
        } else {
            self.derivs(u, 0.5 * (v + edge), &mut m, Some(&mut bm));
            // Su(v) ~ (v - v0) Suv(vm): Su x Sv ~ sign * h * (Suv(vm) x Sv).
            let n = m[1][1].cross(&s[0][1]) * sign;
            (
                n,
                NOISE * (bm[1][1] * s[0][1].norm() + m[1][1].norm() * b[0][1]),
            )
        };
        if n.norm() > noise && n.norm().is_finite() {
            return Some(n.normalize());
        }
        self.taylor_normal(u, v, along_u, sign)
    }

    /// The limit normal at `(u, v)` from the first non-vanishing Taylor coefficient of
    /// `Su x Sv` along the u (or v) parameter line, moving in direction `sign`.
    pub(super) fn taylor_normal(
        &self,
        u: f64,
        v: f64,
        along_u: bool,
        sign: f64,
    ) -> Option<Vector3<f64>> {
        const K: usize = TAYLOR_ORDER + 2;
        // The k-th coefficient is sum_i C(k, i) X_i x Y_(k-i), X_i and Y_j the derivatives of
        // Su and Sv along the line (with their rounding bounds).
        if along_u {
            let mut s = [[Vector3::zeros(); 2]; K];
            let mut b = [[0.0; 2]; K];
            self.derivs(u, v, &mut s, Some(&mut b));
            first_taylor_term(|i| (s[i + 1][0], b[i + 1][0]), |j| (s[j][1], b[j][1]), sign)
        } else {
            let mut s = [[Vector3::zeros(); K]; 2];
            let mut b = [[0.0; K]; 2];
            self.derivs(u, v, &mut s, Some(&mut b));
            first_taylor_term(|i| (s[1][i], b[1][i]), |j| (s[0][j + 1], b[0][j + 1]), sign)
        }
    }

    /// The homogeneous control points `Q_j = sum_i N_i(t) P_ij` of the boundary curve at
    /// parameter `t` of the u (`along_u`) or v direction: a curve in the other direction.
    pub(super) fn edge_points(&self, along_u: bool, t: f64) -> Vec<Vector4<f64>> {
        let (deg, kn, n, m) = if along_u {
            (self.degree_u, &self.knots_u, self.n_u, self.n_v)
        } else {
            (self.degree_v, &self.knots_v, self.n_v, self.n_u)
        };
        let span = knots::find_span(deg, kn, n, t);
        let mut basis = [0.0; MAX_ORDER];
        basis_funs(span, t, deg, kn, &mut basis);
        (0..m)
            .map(|j| {
                let mut q = Vector4::zeros();
                for i in 0..=deg {
                    let idx = span - deg + i;
                    let c = if along_u {
                        self.cpw[idx * self.n_v + j]
                    } else {
                        self.cpw[j * self.n_v + idx]
                    };
                    q += c * basis[i];
                }
                q
            })
            .collect()
    }

    /// Finds which domain edges are collapsed (the boundary curve's control points, see
    /// [`NurbsSurface::edge_points`], all project to one point) and in which directions the
    /// surface is closed (the boundary curves at both ends of the domain are the same rational
    /// curve: equal projected control points and proportional weights), within `1e-10` of the
    /// surface's size (plus rounding of the coordinates).
    pub(super) fn detect_edges(&self) -> ([bool; 4], [bool; 2]) {
        let (lo, hi) = self.bounding_box();
        let scale = lo.coords.amax().max(hi.coords.amax());
        let tol = 1e-10 * (hi - lo).norm() + 64.0 * f64::EPSILON * scale;
        let (ua, ub) = self.domain_u();
        let (va, vb) = self.domain_v();
        let edges = [
            self.edge_points(true, ua),
            self.edge_points(true, ub),
            self.edge_points(false, va),
            self.edge_points(false, vb),
        ];
        let collapsed = edges.each_ref().map(|e| {
            let first = project(&e[0]);
            e.iter().all(|q| (project(q) - first).norm() <= tol)
        });
        let same = |a: &[Vector4<f64>], b: &[Vector4<f64>]| {
            let ratio = b[0].w / a[0].w;
            a.iter().zip(b).all(|(qa, qb)| {
                (project(qa) - project(qb)).norm() <= tol
                    && (qb.w - ratio * qa.w).abs() <= 1e-10 * qb.w
            })
        };
        let closed = [same(&edges[0], &edges[1]), same(&edges[2], &edges[3])];
        (collapsed, closed)
    }
}

/// The unit direction of the first Taylor coefficient of `Su x Sv` along a parameter line that
/// stands above its rounding noise, turned by `sign^k`: the k-th coefficient is
/// `sum_i C(k, i) X_i x Y_(k-i)` with `(X_i, bound)` = `x(i)` and `(Y_j, bound)` = `y(j)`, and its
/// noise `sum_i C(k, i) (|Y| b_X + |X| b_Y)`. `None` when every coefficient up to
/// `TAYLOR_ORDER` vanishes within its noise.
fn first_taylor_term(
    x: impl Fn(usize) -> (Vector3<f64>, f64),
    y: impl Fn(usize) -> (Vector3<f64>, f64),
    sign: f64,
) -> Option<Vector3<f64>> {
    for k in 0..=TAYLOR_ORDER {
        let mut t = Vector3::zeros();
        let mut noise = 0.0;
        for i in 0..=k {
            let c = binomial(k, i);
            let ((x, bx), (y, by)) = (x(i), y(k - i));
            t += x.cross(&y) * c;
            noise += c * (bx * y.norm() + x.norm() * by);
        }
        if t.norm() > NOISE * noise && t.norm().is_finite() {
            return Some(t.normalize() * sign.powi(k as i32));
        }
    }
    None
}
