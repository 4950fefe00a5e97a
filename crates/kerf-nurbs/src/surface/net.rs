//! Helpers on control nets: the Bezier net of a knot-span cell by blossoming, turning and
//! flatness measures, box distances, subdivision and the sign tests of the closest-point
//! search.

use std::sync::{Arc, OnceLock};

use nalgebra::{Point3, Vector3, Vector4};

use super::{NurbsSurface, COEFFICIENT_NOISE, LEAF_NORMAL_CONE, LEAF_TURNING};
use crate::basis::binomial;
use crate::curve::project;
use crate::MAX_ORDER;

/// A knot span as `(span index, start, end)`.
pub(super) type Span = (usize, f64, f64);

/// An edge of a parameter rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Edge {
    /// `u = u0`.
    U0,
    /// `u = u1`.
    U1,
    /// `v = v0`.
    V0,
    /// `v = v1`.
    V1,
}

/// The rational Bezier nets of a surface's knot-span cells and the boxes of their projected
/// control points, computed once per surface: every cold closest-point query starts from all
/// of them (a lower bound per cell, then the cells in order of it), and extracting them by
/// blossoming cost more than the rest of a query on surfaces of many cells.
#[derive(Debug)]
pub(super) struct CellNets {
    /// The nets, cell `iu * spans_v + iv` at `[k * stride, (k + 1) * stride)`, each row-major
    /// over u with `stride = (degree_u + 1) (degree_v + 1)` entries.
    nets: Vec<Vector4<f64>>,
    /// The box `(min, max)` of each cell's projected control points.
    boxes: Vec<(Point3<f64>, Point3<f64>)>,
    stride: usize,
}

impl CellNets {
    /// The net of cell `k` (`iu * spans_v + iv`).
    pub(super) fn net(&self, k: usize) -> &[Vector4<f64>] {
        &self.nets[k * self.stride..(k + 1) * self.stride]
    }

    /// The box of cell `k`'s projected control points.
    pub(super) fn bounds(&self, k: usize) -> (Point3<f64>, Point3<f64>) {
        self.boxes[k]
    }
}

/// A surface's [`CellNets`], filled on first use. It is derived from the surface's own fields
/// (which never change after construction), so it takes no part in equality; a clone taken
/// after it is filled shares it, one taken before fills its own.
#[derive(Clone, Default)]
pub(super) struct NetCache(OnceLock<Arc<CellNets>>);

impl PartialEq for NetCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for NetCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.get().is_some() {
            "NetCache(filled)"
        } else {
            "NetCache(empty)"
        })
    }
}

impl NurbsSurface {
    /// The Bezier nets of every knot-span cell (the spans of [`NurbsSurface::spans_u`] by
    /// those of [`NurbsSurface::spans_v`]), computed on the first call.
    pub(super) fn cell_nets(&self) -> &CellNets {
        self.cells.0.get_or_init(|| {
            let (spans_u, spans_v) = (self.spans_u(), self.spans_v());
            let stride = (self.degree_u + 1) * (self.degree_v + 1);
            let cells = spans_u.len() * spans_v.len();
            let mut nets = Vec::with_capacity(cells * stride);
            let mut boxes = Vec::with_capacity(cells);
            let mut net = [[Vector4::zeros(); MAX_ORDER]; MAX_ORDER];
            for &su in &spans_u {
                for &sv in &spans_v {
                    self.bezier_net(su, sv, &mut net);
                    let start = nets.len();
                    for row in net.iter().take(self.degree_u + 1) {
                        nets.extend(row.iter().take(self.degree_v + 1));
                    }
                    boxes.push(crate::curve::hull_box(&nets[start..]));
                }
            }
            Arc::new(CellNets {
                nets,
                boxes,
                stride,
            })
        })
    }

    /// The homogeneous Bezier net of the knot-span cell `[u0, u1] x [v0, v1]` (spans `su`,
    /// `sv`), `net[a][b]` for `a <= degree_u`, `b <= degree_v`, by blossoming in each direction
    /// (see [`NurbsCurve::bezier_in_span`](crate::NurbsCurve::bezier_in_span)).
    pub(super) fn bezier_net(
        &self,
        (su, u0, u1): Span,
        (sv, v0, v1): Span,
        net: &mut [[Vector4<f64>; MAX_ORDER]; MAX_ORDER],
    ) {
        let (p, q) = (self.degree_u, self.degree_v);
        let mut rows = [[Vector4::zeros(); MAX_ORDER]; MAX_ORDER];
        let mut local = [Vector4::zeros(); MAX_ORDER];
        for a in 0..=p {
            let row = (su - p + a) * self.n_v + (sv - q);
            local[..=q].copy_from_slice(&self.cpw[row..=row + q]);
            blossom_extract(q, &self.knots_v, sv, v0, v1, &local, &mut rows[a]);
        }
        let mut out = [Vector4::zeros(); MAX_ORDER];
        for b in 0..=q {
            for a in 0..=p {
                local[a] = rows[a][b];
            }
            blossom_extract(p, &self.knots_u, su, u0, u1, &local, &mut out);
            for a in 0..=p {
                net[a][b] = out[a];
            }
        }
    }
}

/// Rational Bezier control points of the span `[t0, t1]` of a B-spline whose `degree + 1`
/// local homogeneous control points `local[..=degree]` are those of `span`, by blossoming (see
/// [`NurbsCurve::bezier_in_span`](crate::NurbsCurve::bezier_in_span)).
pub(super) fn blossom_extract(
    degree: usize,
    knots: &[f64],
    span: usize,
    t0: f64,
    t1: f64,
    local: &[Vector4<f64>; MAX_ORDER],
    out: &mut [Vector4<f64>; MAX_ORDER],
) {
    let p = degree;
    for j in 0..=p {
        let mut d = *local;
        for r in 1..=p {
            let x = if r <= p - j { t0 } else { t1 };
            for k in (r..=p).rev() {
                let lo = knots[span - p + k];
                let hi = knots[span + 1 + k - r];
                let alpha = (x - lo) / (hi - lo);
                d[k] = d[k - 1] * (1.0 - alpha) + d[k] * alpha;
            }
        }
        out[j] = d[p];
    }
}

/// The largest total turning angle of the control polygons of a flat net's rows along u and
/// along v: how much a patch bends.
pub(super) fn flat_net_turning(net: &[Vector4<f64>], p: usize, q: usize) -> (f64, f64) {
    let at = |a: usize, b: usize| project(&net[a * (q + 1) + b]);
    let mut turn_u: f64 = 0.0;
    let mut turn_v: f64 = 0.0;
    for b in 0..=q {
        turn_u = turn_u.max(polygon_turning((0..=p).map(|a| at(a, b))));
    }
    for a in 0..=p {
        turn_v = turn_v.max(polygon_turning((0..=q).map(|b| at(a, b))));
    }
    (turn_u, turn_v)
}

/// True if a sub-patch's net is simple enough to be a leaf of the closest-point search: its
/// rows and columns turn by at most [`LEAF_TURNING`], and its parametrisation is regular — all
/// cross products of a u-leg with a v-leg of the net (the terms of which `Su x Sv` is a
/// positive combination, for polynomial nets) lie within [`LEAF_NORMAL_CONE`] of their sum —
/// so that the distance has a single minimum on it unless the query point is far beyond its
/// centres of curvature.
pub(super) fn simple_net(net: &[Vector4<f64>], p: usize, q: usize) -> bool {
    let (turn_u, turn_v) = flat_net_turning(net, p, q);
    if !(turn_u <= LEAF_TURNING && turn_v <= LEAF_TURNING) {
        return false;
    }
    let at = |a: usize, b: usize| project(&net[a * (q + 1) + b]);
    let mut legs_u = Vec::with_capacity(p * (q + 1));
    let mut legs_v = Vec::with_capacity((p + 1) * q);
    for a in 0..=p {
        for b in 0..=q {
            if a < p {
                legs_u.push(at(a + 1, b) - at(a, b));
            }
            if b < q {
                legs_v.push(at(a, b + 1) - at(a, b));
            }
        }
    }
    let mut sum = Vector3::zeros();
    for lu in &legs_u {
        for lv in &legs_v {
            sum += lu.cross(lv);
        }
    }
    let cos_limit = LEAF_NORMAL_CONE.cos();
    let sn = sum.norm();
    if sn <= 0.0 || sn.is_nan() {
        return false;
    }
    legs_u.iter().all(|lu| {
        legs_v.iter().all(|lv| {
            let c = lu.cross(lv);
            let cn = c.norm();
            cn == 0.0 || c.dot(&sum) >= cos_limit * cn * sn
        })
    })
}

/// The sum of the angles between consecutive non-degenerate legs of a polygon.
pub(super) fn polygon_turning(points: impl Iterator<Item = Point3<f64>>) -> f64 {
    let mut prev_point: Option<Point3<f64>> = None;
    let mut prev_leg: Option<Vector3<f64>> = None;
    let mut total = 0.0;
    for pt in points {
        if let Some(pp) = prev_point {
            let leg = pt - pp;
            if leg.norm() > 0.0 {
                if let Some(pl) = prev_leg {
                    total += pl.angle(&leg);
                }
                prev_leg = Some(leg);
            }
        }
        prev_point = Some(pt);
    }
    total
}

/// Splits a flat `(p + 1) x (q + 1)` rational Bezier net at the middle of its u (`along_u`)
/// or v parameter range by de Casteljau's algorithm in homogeneous space.
pub(super) fn split_net(
    net: &[Vector4<f64>],
    p: usize,
    q: usize,
    along_u: bool,
) -> (Vec<Vector4<f64>>, Vec<Vector4<f64>>) {
    let mut left = net.to_vec();
    let mut right = net.to_vec();
    let (lines, len) = if along_u {
        (q + 1, p + 1)
    } else {
        (p + 1, q + 1)
    };
    let idx = |line: usize, k: usize| {
        if along_u {
            k * (q + 1) + line
        } else {
            line * (q + 1) + k
        }
    };
    let mut d = [Vector4::zeros(); MAX_ORDER];
    for line in 0..lines {
        for k in 0..len {
            d[k] = net[idx(line, k)];
        }
        let n = len - 1;
        left[idx(line, 0)] = d[0];
        right[idx(line, n)] = d[n];
        for r in 1..=n {
            for i in 0..=(n - r) {
                d[i] = (d[i] + d[i + 1]) * 0.5;
            }
            left[idx(line, r)] = d[0];
            right[idx(line, n - r)] = d[n - r];
        }
    }
    (left, right)
}

/// Rows of Pascal's triangle `C(n, 0..=n)` for `n = 0..=max`.
pub(super) fn pascal(max: usize) -> Vec<Vec<f64>> {
    (0..=max)
        .map(|n| (0..=n).map(|k| binomial(n, k)).collect())
        .collect()
}

/// The edge of a sub-patch holding its closest point to `x`, if the Bernstein coefficients
/// prove one: `(S - x) . Su` has the sign of `F = B . (B_u w - B w_u)` with
/// `B = A - x w` (`A`, `w` the homogeneous numerator and weight), a polynomial of degree
/// `(3p - 1, 3q)` whose Bernstein coefficients follow from the net by the product rule. If
/// they are all `>= 0` (within rounding) the distance does not decrease with u anywhere on the
/// sub-patch, so its minimum lies on the edge `u = u0`; all `<= 0` gives `u = u1`. Likewise
/// along v.
pub(super) fn stationarity_sign(
    net: &[Vector4<f64>],
    (p, q): (usize, usize),
    x: &Point3<f64>,
) -> Option<Edge> {
    for along_u in [true, false] {
        match stationarity_sign_along(net, (p, q), x, along_u) {
            Some(true) => return Some(if along_u { Edge::U0 } else { Edge::V0 }),
            Some(false) => return Some(if along_u { Edge::U1 } else { Edge::V1 }),
            None => {}
        }
    }
    None
}

/// `Some(true)` if `(S - x) . S_d >= 0` on the whole patch (d = u if `along_u`, else v),
/// `Some(false)` if `<= 0`, `None` if the Bernstein coefficients have both signs.
///
/// Only signs matter, so the computation works in the scaled basis
/// `u^i (1 - u)^(m - i) v^j (1 - v)^(n - j)` (Bernstein coefficients times `C(m, i) C(n, j)`),
/// in which products of polynomials are plain convolutions of coefficients: the resulting
/// coefficient `k, l` is the Bernstein one times `m C(3m - 1, k) C(3n, l) > 0`.
pub(super) fn stationarity_sign_along(
    net: &[Vector4<f64>],
    (p, q): (usize, usize),
    x: &Point3<f64>,
    along_u: bool,
) -> Option<bool> {
    // Work on an (m + 1) x (n + 1) grid whose first index runs along the derivative.
    let (m, n) = if along_u { (p, q) } else { (q, p) };
    let at = |i: usize, j: usize| {
        if along_u {
            net[i * (q + 1) + j]
        } else {
            net[j * (q + 1) + i]
        }
    };
    let bin = pascal(m.max(n));
    let xn = x.coords.norm();
    // Scaled B = A - x w, its bound beta, w; and the scaled differences along the first index.
    let g = |i: usize, j: usize| i * (n + 1) + j;
    let mut b = vec![Vector3::zeros(); (m + 1) * (n + 1)];
    let mut beta = vec![0.0; (m + 1) * (n + 1)];
    let mut w = vec![0.0; (m + 1) * (n + 1)];
    let mut db = vec![Vector3::zeros(); m * (n + 1)];
    let mut db_abs = vec![0.0; m * (n + 1)];
    let mut dw = vec![0.0; m * (n + 1)];
    let mut dw_abs = vec![0.0; m * (n + 1)];
    for j in 0..=n {
        for i in 0..=m {
            let c = at(i, j);
            let s = bin[m][i] * bin[n][j];
            b[g(i, j)] = (c.xyz() - x.coords * c.w) * s;
            beta[g(i, j)] = (c.xyz().norm() + xn * c.w) * s;
            w[g(i, j)] = c.w * s;
        }
        for i in 0..m {
            let (c0, c1) = (at(i, j), at(i + 1, j));
            let s = bin[m - 1][i] * bin[n][j];
            db[g(i, j)] = ((c1.xyz() - x.coords * c1.w) - (c0.xyz() - x.coords * c0.w)) * s;
            db_abs[g(i, j)] = (c0.xyz().norm() + c1.xyz().norm() + xn * (c0.w + c1.w)) * s;
            dw[g(i, j)] = (c1.w - c0.w) * s;
            dw_abs[g(i, j)] = (c0.w + c1.w) * s;
        }
    }
    // H = B_d w - B w_d, degree (2m - 1, 2n), scaled.
    let (hm, hn) = (2 * m - 1, 2 * n);
    let gh = |i: usize, j: usize| i * (hn + 1) + j;
    let mut h = vec![Vector3::zeros(); (hm + 1) * (hn + 1)];
    let mut h_abs = vec![0.0; (hm + 1) * (hn + 1)];
    for i1 in 0..m {
        for j1 in 0..=n {
            let (d, da, e, ea) = (
                db[g(i1, j1)],
                db_abs[g(i1, j1)],
                dw[g(i1, j1)],
                dw_abs[g(i1, j1)],
            );
            for i2 in 0..=m {
                for j2 in 0..=n {
                    let k = gh(i1 + i2, j1 + j2);
                    let (bb, ba, ww) = (b[g(i2, j2)], beta[g(i2, j2)], w[g(i2, j2)]);
                    h[k] += d * ww - bb * e;
                    h_abs[k] += da * ww + ba * ea;
                }
            }
        }
    }
    // F = B . H, degree (3m - 1, 3n), scaled.
    let (fm, fnn) = (3 * m - 1, 3 * n);
    let gf = |i: usize, j: usize| i * (fnn + 1) + j;
    let mut f = vec![0.0; (fm + 1) * (fnn + 1)];
    let mut f_abs = vec![0.0; (fm + 1) * (fnn + 1)];
    for i1 in 0..=m {
        for j1 in 0..=n {
            let (bij, beta_ij) = (b[g(i1, j1)], beta[g(i1, j1)]);
            for i2 in 0..=hm {
                for j2 in 0..=hn {
                    let k = gf(i1 + i2, j1 + j2);
                    f[k] += bij.dot(&h[gh(i2, j2)]);
                    f_abs[k] += beta_ij * h_abs[gh(i2, j2)];
                }
            }
        }
    }
    let (mut positive, mut negative) = (false, false);
    for (&v, &bound) in f.iter().zip(&f_abs) {
        let tol = COEFFICIENT_NOISE * bound;
        if v > tol {
            positive = true;
        } else if v < -tol {
            negative = true;
        } else if v.is_nan() {
            return None;
        }
    }
    match (positive, negative) {
        (_, false) => Some(true),
        (false, true) => Some(false),
        (true, true) => None,
    }
}
