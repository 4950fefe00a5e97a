//! Closest point on a surface: a global branch-and-bound over Bezier sub-patches (net boxes
//! as lower bounds), a warm-started walking Newton, and the edge and corner minima.

use std::borrow::Cow;

use nalgebra::{Point3, Vector3, Vector4};

use super::net::{simple_net, split_net, stationarity_sign, Edge, Span};
use super::{
    clamp, NurbsSurface, SurfaceProjection, LEAF_SAMPLES, MAX_SUBDIVISION, MIN_LEAF_DEPTH,
    NEWTON_ITERATIONS, ORTHOGONALITY, SUBPATCH_BUDGET, WARM_REACH,
};
use crate::closest::{float_before, hull_box_distance};
use crate::curve::{project, NurbsCurve};
use crate::knots;
use crate::queue::BestFirst;

/// A candidate closest point.
#[derive(Debug, Clone, Copy)]
pub(super) struct Candidate {
    u: f64,
    v: f64,
    distance: f64,
}

/// A knot-span cell: one rational polynomial patch.
#[derive(Debug, Clone, Copy)]
pub(super) struct Patch {
    /// Indices into the lists of non-empty spans.
    iu: usize,
    iv: usize,
    /// Knot span indices.
    su: usize,
    sv: usize,
    /// Parameter rectangle.
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
}

/// A sub-patch of a cell in the global closest-point search (a whole cell borrows its net from
/// the surface's [`CellNets`](super::net::CellNets)).
#[derive(Debug, Clone)]
pub(super) struct SubPatch<'a> {
    /// Number of halvings from the cell.
    depth: u32,
    /// The cell: indices into the lists of non-empty spans.
    cell: (usize, usize),
    /// Parameter rectangle `(u0, u1, v0, v1)`.
    rect: (f64, f64, f64, f64),
    /// Rational Bezier net, `(degree_u + 1) x (degree_v + 1)`, row-major over u.
    net: Cow<'a, [Vector4<f64>]>,
}

impl NurbsSurface {
    /// The closest point of the surface to `p`.
    ///
    /// The surface is handled one knot-span cell at a time: inside a cell it is one rational
    /// polynomial patch, smooth up to its edges, while across cell edges it may have creases
    /// (or even jump, at a knot of multiplicity `degree + 1`). The minimum over the surface is
    /// the least of the cells' minima.
    ///
    /// **Cold** (`warm_start = None`): a global branch-and-bound search over rational Bezier
    /// sub-patches, best first by a lower bound on their distance: the distance from `p` to
    /// the box of their projected control points (convex hull property). It starts from the
    /// cells' Bezier nets and stops when no remaining bound is below the best distance found
    /// (the corners of every sub-patch are candidates). The cells' nets and their boxes are
    /// extracted on the first cold query and kept with the surface (and its later clones), as
    /// extracting them on every query was most of its cost on surfaces of many cells. A
    /// sub-patch is then
    /// - *reduced to an edge* if the Bernstein coefficients of `(S - p) . Su` (or `. Sv`) all
    ///   have one sign: the distance is then monotone in u (or v) on the whole sub-patch, so
    ///   its minimum lies on one edge, a rational Bezier curve, whose closest point
    ///   [`NurbsCurve::closest_point`] finds exactly. (These coefficients are those of
    ///   `B . (B_u w - B w_u)` with `B = A - p w`, which has the sign of `(S - p) . Su`; see
    ///   the curves' `closest.rs`.) This also settles whole families of
    ///   equidistant points, such as `p` on the axis of a surface of revolution;
    /// - a *leaf* once it is at least two halvings deep and simple — rows and columns of its
    ///   net turning by at most 22.5 degrees and a regular parametrisation (the cross products
    ///   of its u- and v-legs within 60 degrees of their sum); a leaf is sampled on a 5 x 5
    ///   grid and Newton's method (below) runs inside it from the best sample and from its
    ///   centre;
    /// - otherwise split into four by de Casteljau's algorithm (to at most 12 halvings).
    ///
    /// The four edges of every cell the search reaches are also projected onto exactly, so
    /// minima on the boundary of the domain and on creases between cells are found as curve
    /// minima. Finally Newton's method polishes the best point (distances near a minimum vary
    /// only quadratically, so comparing them fixes the parameters to about the square root of
    /// the rounding error; Newton drives the gradient to zero instead).
    ///
    /// **Warm** (`Some((u, v))`): Newton's method from `(u, v)` (clamped) in its cell; when it
    /// stops on an edge shared with a neighbouring cell and the distance decreases across that
    /// edge, it continues in the neighbour, as long as the distance keeps decreasing (across
    /// the seam, too, in a direction where the surface is closed, see
    /// [`NurbsSurface::closed_directions`]). The result is returned if Newton converged within
    /// a quarter of the domain (in each parameter, measured across a seam) of the start;
    /// otherwise the global search runs, seeded with it. Warm starts are meant for tracking a
    /// moving point: the result is the local minimum reached from the start, which is the
    /// global one when the start lies in its basin.
    ///
    /// **Newton** minimises `|S - p|^2 / 2` on the cell's rectangle: the gradient is
    /// `(f, g) = ((S - p) . Su, (S - p) . Sv)`, the Hessian
    /// `[[Su.Su + (S-p).Suu, Su.Sv + (S-p).Suv], [.., Sv.Sv + (S-p).Svv]]` (the Gauss-Newton
    /// matrix, slightly damped, where that is not positive definite). A parameter at a bound of
    /// the rectangle whose gradient component pushes outward is held fixed, so minima on the
    /// boundary (on an edge curve, at a corner, or on a crease between cells) are found by the
    /// same iteration; steps are clamped to the rectangle and halved until the distance does
    /// not grow.
    ///
    /// The result is deterministic. Where the surface jumps at a knot, the limit from below is
    /// represented by the largest parameter below the knot, so that `point` is always
    /// [`NurbsSurface::point`]`(u, v)` and `distance` is `|point - p|`.
    pub fn closest_point(
        &self,
        p: &Point3<f64>,
        warm_start: Option<(f64, f64)>,
    ) -> SurfaceProjection {
        let spans_u = self.spans_u();
        let spans_v = self.spans_v();
        let (ua, ub) = self.domain_u();
        let (va, vb) = self.domain_v();
        let mut best = Candidate {
            u: ua,
            v: va,
            distance: f64::INFINITY,
        };
        if let Some((u0, v0)) = warm_start {
            let (u0, v0) = self.clamp_uv(u0, v0);
            let (c, converged) = self.walking_newton(p, &spans_u, &spans_v, u0, v0);
            // Parameter distance, across the seam of a closed direction.
            let apart = |a: f64, b: f64, len: f64, closed: bool| {
                let d = (a - b).abs();
                if closed {
                    d.min(len - d)
                } else {
                    d
                }
            };
            let near = apart(c.u, u0, ub - ua, self.closed[0]) <= WARM_REACH * (ub - ua)
                && apart(c.v, v0, vb - va, self.closed[1]) <= WARM_REACH * (vb - va);
            if converged && near {
                return self.projection(p, c);
            }
            best = c;
        }
        let best = self.global_search(p, &spans_u, &spans_v, best);
        let best = self.polish(p, &spans_u, &spans_v, best);
        self.projection(p, best)
    }

    pub(super) fn projection(&self, p: &Point3<f64>, c: Candidate) -> SurfaceProjection {
        let point = self.point(c.u, c.v);
        SurfaceProjection {
            u: c.u,
            v: c.v,
            distance: (point - p).norm(),
            point,
        }
    }

    /// Newton's method in the cell of `c`, from `c`: the global search compares distances,
    /// which near a minimum vary only quadratically, so its parameters are accurate to about
    /// the square root of the rounding error; Newton drives the gradient to zero instead.
    pub(super) fn polish(
        &self,
        p: &Point3<f64>,
        spans_u: &[Span],
        spans_v: &[Span],
        c: Candidate,
    ) -> Candidate {
        if !c.distance.is_finite() {
            return c;
        }
        let (su, sv) = self.spans_at(c.u, c.v);
        let iu = spans_u.iter().position(|s| s.0 == su).unwrap_or(0);
        let iv = spans_v.iter().position(|s| s.0 == sv).unwrap_or(0);
        let cell = self.patch(spans_u, spans_v, iu, iv);
        let (polished, _) = self.newton(p, &cell, c.u, c.v);
        if polished.distance <= c.distance {
            self.below_jumps(&cell, polished)
        } else {
            c
        }
    }

    /// The cell made of the spans `spans_u[iu]` and `spans_v[iv]`.
    pub(super) fn patch(&self, spans_u: &[Span], spans_v: &[Span], iu: usize, iv: usize) -> Patch {
        let (su, u0, u1) = spans_u[iu];
        let (sv, v0, v1) = spans_v[iv];
        Patch {
            iu,
            iv,
            su,
            sv,
            u0,
            u1,
            v0,
            v1,
        }
    }

    /// Newton's method in the cell holding `(u, v)`, continued into neighbouring cells while
    /// it stops on a shared edge across which the distance decreases (see
    /// [`NurbsSurface::closest_point`]).
    pub(super) fn walking_newton(
        &self,
        p: &Point3<f64>,
        spans_u: &[Span],
        spans_v: &[Span],
        u: f64,
        v: f64,
    ) -> (Candidate, bool) {
        let (su, sv) = self.spans_at(u, v);
        let iu = spans_u.iter().position(|s| s.0 == su).unwrap_or(0);
        let iv = spans_v.iter().position(|s| s.0 == sv).unwrap_or(0);
        let mut cell = self.patch(spans_u, spans_v, iu, iv);
        let (mut c, mut converged) = self.newton(p, &cell, u, v);
        for _ in 0..spans_u.len() + spans_v.len() {
            let mut s = [[Vector3::zeros(); 2]; 2];
            self.derivs_in(c.u, c.v, cell.su, cell.sv, &mut s, None);
            let r = s[0][0] - p.coords;
            let (gu, gv) = (r.dot(&s[1][0]), r.dot(&s[0][1]));
            // The neighbour across an edge the gradient pushes out of, wrapping around the
            // seam of a closed surface.
            let step = |i: usize, t: f64, lo: f64, hi: f64, g: f64, n: usize, closed: bool| {
                let last = n - 1;
                if t >= hi && g < 0.0 {
                    if i < last {
                        Some((i + 1, t))
                    } else {
                        closed.then_some((0, f64::NEG_INFINITY))
                    }
                } else if t <= lo && g > 0.0 {
                    if i > 0 {
                        Some((i - 1, t))
                    } else {
                        closed.then_some((last, f64::INFINITY))
                    }
                } else {
                    None
                }
            };
            let mu = step(
                cell.iu,
                c.u,
                cell.u0,
                cell.u1,
                gu,
                spans_u.len(),
                self.closed[0],
            );
            let mv = step(
                cell.iv,
                c.v,
                cell.v0,
                cell.v1,
                gv,
                spans_v.len(),
                self.closed[1],
            );
            let ((iu, u), (iv, v)) = (mu.unwrap_or((cell.iu, c.u)), mv.unwrap_or((cell.iv, c.v)));
            if (iu, iv) == (cell.iu, cell.iv) {
                break;
            }
            let next = self.patch(spans_u, spans_v, iu, iv);
            let (u, v) = (clamp(u, (next.u0, next.u1)), clamp(v, (next.v0, next.v1)));
            let (c2, ok) = self.newton(p, &next, u, v);
            if c2.distance >= c.distance || c2.distance.is_nan() {
                break;
            }
            (c, converged, cell) = (c2, ok, next);
        }
        (self.below_jumps(&cell, c), converged)
    }

    /// The candidate with parameters on a cell's upper edge moved just below it where the
    /// surface jumps there, so that [`NurbsSurface::point`] gives the limit from inside the
    /// cell.
    pub(super) fn below_jumps(&self, cell: &Patch, mut c: Candidate) -> Candidate {
        let jump = |t: f64, end: f64, degree: usize, kn: &[f64]| {
            t >= end && end < kn[kn.len() - degree - 1] && knots::multiplicity(kn, end) > degree
        };
        if jump(c.u, cell.u1, self.degree_u, &self.knots_u) {
            c.u = float_before(cell.u1);
        }
        if jump(c.v, cell.v1, self.degree_v, &self.knots_v) {
            c.v = float_before(cell.v1);
        }
        c
    }

    /// The branch-and-bound search over knot-span cells and their sub-patches described in
    /// [`NurbsSurface::closest_point`], starting from `best`.
    pub(super) fn global_search(
        &self,
        p: &Point3<f64>,
        spans_u: &[Span],
        spans_v: &[Span],
        mut best: Candidate,
    ) -> Candidate {
        let (deg_u, deg_v) = (self.degree_u, self.degree_v);
        let mut heap = BestFirst::new();
        let cells = self.cell_nets();
        for iu in 0..spans_u.len() {
            for iv in 0..spans_v.len() {
                let k = iu * spans_v.len() + iv;
                let cell = self.patch(spans_u, spans_v, iu, iv);
                // The distance from the query point to the bounding box of the cell's net.
                let (lo, hi) = cells.bounds(k);
                let lower_bound = crate::distance_to_box(p, &lo, &hi);
                let sub = SubPatch {
                    depth: 0,
                    cell: (iu, iv),
                    rect: (cell.u0, cell.u1, cell.v0, cell.v1),
                    net: Cow::Borrowed(cells.net(k)),
                };
                self.offer_corners(p, &cell, &sub, &mut best);
                heap.push(lower_bound, sub);
            }
        }
        // Distances closer than rounding cannot be told apart: a sub-patch whose lower bound is
        // within `slack` of the best distance cannot hold a meaningfully closer point.
        let (lo, hi) = self.bounding_box();
        let slack =
            16.0 * f64::EPSILON * lo.coords.amax().max(hi.coords.amax()).max(p.coords.amax());
        let mut budget = SUBPATCH_BUDGET;
        while let Some((lower_bound, sub)) = heap.pop() {
            if lower_bound >= best.distance - slack || lower_bound.is_nan() {
                break;
            }
            let cell = self.patch(spans_u, spans_v, sub.cell.0, sub.cell.1);
            // A sub-patch on which (S - p) . Su (or . Sv) has one sign has its minimum on one
            // edge.
            if let Some(edge) = stationarity_sign(&sub.net, (deg_u, deg_v), p) {
                self.edge_minimum(p, &cell, &sub, edge, &mut best);
                continue;
            }
            if sub.depth == 0 {
                // The cell's own edges, exactly: minima on the boundary of the domain or on a
                // crease between cells.
                for edge in [Edge::U0, Edge::U1, Edge::V0, Edge::V1] {
                    self.edge_minimum(p, &cell, &sub, edge, &mut best);
                }
            }
            budget = budget.saturating_sub(1);
            let (u0, u1, v0, v1) = sub.rect;
            let leaf = sub.depth >= MAX_SUBDIVISION
                || budget == 0
                || (sub.depth >= MIN_LEAF_DEPTH && simple_net(&sub.net, deg_u, deg_v));
            if leaf {
                let leaf = Patch {
                    u0,
                    u1,
                    v0,
                    v1,
                    ..cell
                };
                if let Some(c) = self.leaf_minimum(p, &leaf) {
                    if c.distance < best.distance {
                        best = self.below_jumps(&cell, c);
                    }
                }
                continue;
            }
            let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
            let (left, right) = split_net(&sub.net, deg_u, deg_v, true);
            for (half, (a, b)) in [(left, (u0, um)), (right, (um, u1))] {
                let (low, high) = split_net(&half, deg_u, deg_v, false);
                for (quarter, (c, d)) in [(low, (v0, vm)), (high, (vm, v1))] {
                    let lower_bound = hull_box_distance(&quarter, p);
                    let child = SubPatch {
                        depth: sub.depth + 1,
                        cell: sub.cell,
                        rect: (a, b, c, d),
                        net: Cow::Owned(quarter),
                    };
                    self.offer_corners(p, &cell, &child, &mut best);
                    if lower_bound < best.distance - slack {
                        heap.push(lower_bound, child);
                    }
                }
            }
        }
        best
    }

    /// The closest point on a leaf of the search: samples a small grid on the leaf's
    /// rectangle and runs Newton's method (confined to the rectangle) from the best sample and
    /// from the centre.
    pub(super) fn leaf_minimum(&self, p: &Point3<f64>, leaf: &Patch) -> Option<Candidate> {
        const N: usize = LEAF_SAMPLES;
        let at = |i: usize, n: usize, a: f64, b: f64| {
            if i == n {
                b
            } else {
                a + (b - a) * (i as f64 / n as f64)
            }
        };
        let mut start = (
            f64::INFINITY,
            0.5 * (leaf.u0 + leaf.u1),
            0.5 * (leaf.v0 + leaf.v1),
        );
        for i in 0..=N {
            for j in 0..=N {
                let (u, v) = (at(i, N, leaf.u0, leaf.u1), at(j, N, leaf.v0, leaf.v1));
                let d = (self.point_in(u, v, leaf.su, leaf.sv) - p).norm();
                if d < start.0 {
                    start = (d, u, v);
                }
            }
        }
        let (from_sample, _) = self.newton(p, leaf, start.1, start.2);
        let (from_centre, _) = self.newton(
            p,
            leaf,
            0.5 * (leaf.u0 + leaf.u1),
            0.5 * (leaf.v0 + leaf.v1),
        );
        [from_sample, from_centre]
            .into_iter()
            .filter(|c| c.distance.is_finite())
            .min_by(|a, b| a.distance.total_cmp(&b.distance))
    }

    /// Offers the four corners of a sub-patch (points of the surface: the corners of its
    /// Bezier net) to `best`.
    pub(super) fn offer_corners(
        &self,
        p: &Point3<f64>,
        cell: &Patch,
        sub: &SubPatch,
        best: &mut Candidate,
    ) {
        let (p_deg, q_deg) = (self.degree_u, self.degree_v);
        let (u0, u1, v0, v1) = sub.rect;
        for (a, b, u, v) in [
            (0, 0, u0, v0),
            (p_deg, 0, u1, v0),
            (0, q_deg, u0, v1),
            (p_deg, q_deg, u1, v1),
        ] {
            let d = (project(&sub.net[a * (q_deg + 1) + b]) - p).norm();
            if d < best.distance {
                *best = self.below_jumps(cell, Candidate { u, v, distance: d });
            }
        }
    }

    /// Offers to `best` the closest point of one edge of a sub-patch, computed exactly by
    /// [`NurbsCurve::closest_point`] on the edge's rational Bezier curve (a row or column of
    /// the sub-patch's net).
    pub(super) fn edge_minimum(
        &self,
        p: &Point3<f64>,
        cell: &Patch,
        sub: &SubPatch,
        edge: Edge,
        best: &mut Candidate,
    ) {
        let (deg_u, deg_v) = (self.degree_u, self.degree_v);
        let (u0, u1, v0, v1) = sub.rect;
        let clamped = |degree: usize, t0: f64, t1: f64| {
            let mut k = vec![t0; degree + 1];
            k.extend(std::iter::repeat_n(t1, degree + 1));
            k
        };
        let at = |a: usize, b: usize| sub.net[a * (deg_v + 1) + b];
        let (curve, fixed) = match edge {
            Edge::U0 | Edge::U1 => {
                let (a, u) = if edge == Edge::U0 {
                    (0, u0)
                } else {
                    (deg_u, u1)
                };
                let cpw = (0..=deg_v).map(|b| at(a, b)).collect();
                (
                    NurbsCurve::from_homogeneous_unchecked(deg_v, clamped(deg_v, v0, v1), cpw),
                    u,
                )
            }
            Edge::V0 | Edge::V1 => {
                let (b, v) = if edge == Edge::V0 {
                    (0, v0)
                } else {
                    (deg_v, v1)
                };
                let cpw = (0..=deg_u).map(|a| at(a, b)).collect();
                (
                    NurbsCurve::from_homogeneous_unchecked(deg_u, clamped(deg_u, u0, u1), cpw),
                    v,
                )
            }
        };
        let q = curve.closest_point(p);
        if q.distance < best.distance {
            let (u, v) = match edge {
                Edge::U0 | Edge::U1 => (fixed, q.t),
                Edge::V0 | Edge::V1 => (q.t, fixed),
            };
            *best = self.below_jumps(
                cell,
                Candidate {
                    u,
                    v,
                    distance: q.distance,
                },
            );
        }
    }

    /// Projected Newton iteration for the closest point on the patch of one cell, from
    /// `(u, v)` (see [`NurbsSurface::closest_point`]). Returns the final candidate (parameters
    /// inside the cell's closed rectangle, distance from the cell's own polynomials) and
    /// whether it converged (gradient orthogonality met, or no further descent possible in
    /// floating point).
    pub(super) fn newton(
        &self,
        p: &Point3<f64>,
        cell: &Patch,
        u: f64,
        v: f64,
    ) -> (Candidate, bool) {
        let (ua, ub) = (cell.u0, cell.u1);
        let (va, vb) = (cell.v0, cell.v1);
        let (su_span, sv_span) = (cell.su, cell.sv);
        let (mut u, mut v) = (clamp(u, (ua, ub)), clamp(v, (va, vb)));
        let mut s = [[Vector3::zeros(); 3]; 3];
        self.derivs_in(u, v, su_span, sv_span, &mut s, None);
        let mut r = s[0][0] - p.coords;
        let mut f = r.norm_squared();
        let done = |u: f64, v: f64, f: f64, ok: bool| {
            (
                Candidate {
                    u,
                    v,
                    distance: f.sqrt(),
                },
                ok,
            )
        };
        for _ in 0..NEWTON_ITERATIONS {
            let (su, sv) = (s[1][0], s[0][1]);
            let g = [r.dot(&su), r.dot(&sv)];
            let rn = r.norm();
            let free_u = !((u <= ua && g[0] >= 0.0) || (u >= ub && g[0] <= 0.0));
            let free_v = !((v <= va && g[1] >= 0.0) || (v >= vb && g[1] <= 0.0));
            let small_u = !free_u || g[0].abs() <= ORTHOGONALITY * rn * su.norm();
            let small_v = !free_v || g[1].abs() <= ORTHOGONALITY * rn * sv.norm();
            if small_u && small_v {
                return done(u, v, f, true);
            }
            let (j00, j01, j11) = (su.dot(&su), su.dot(&sv), sv.dot(&sv));
            let h00 = j00 + r.dot(&s[2][0]);
            let h01 = j01 + r.dot(&s[1][1]);
            let h11 = j11 + r.dot(&s[0][2]);
            let (mut du, mut dv) = match (free_u, free_v) {
                (true, true) => {
                    let det = h00 * h11 - h01 * h01;
                    if h00 > 0.0 && det > 1e-12 * h00 * h11 {
                        (
                            -(h11 * g[0] - h01 * g[1]) / det,
                            -(h00 * g[1] - h01 * g[0]) / det,
                        )
                    } else {
                        // Damped Gauss-Newton: always a descent direction.
                        let mu = 1e-9 * (j00 + j11);
                        let (a, c) = (j00 + mu, j11 + mu);
                        let det = a * c - j01 * j01;
                        (
                            -(c * g[0] - j01 * g[1]) / det,
                            -(a * g[1] - j01 * g[0]) / det,
                        )
                    }
                }
                (true, false) => (-g[0] / if h00 > 0.0 { h00 } else { j00 }, 0.0),
                (false, true) => (0.0, -g[1] / if h11 > 0.0 { h11 } else { j11 }),
                (false, false) => (0.0, 0.0),
            };
            if !(du.is_finite() && dv.is_finite()) || du * g[0] + dv * g[1] >= 0.0 {
                // Steepest descent, scaled by the metric.
                let t = j00 + j11;
                if !(t > 0.0 && t.is_finite()) {
                    return done(u, v, f, false);
                }
                du = if free_u { -g[0] / t } else { 0.0 };
                dv = if free_v { -g[1] / t } else { 0.0 };
            }
            // At most the rectangle's size, keeping the direction (a descent direction).
            let shrink = ((ub - ua) / du.abs()).min((vb - va) / dv.abs()).min(1.0);
            du *= shrink;
            dv *= shrink;
            let (tol_u, tol_v) = (
                4.0 * f64::EPSILON * (u.abs() + (ub - ua)),
                4.0 * f64::EPSILON * (v.abs() + (vb - va)),
            );
            let mut step = 1.0;
            let mut accepted = None;
            for _ in 0..60 {
                if (step * du).abs() <= tol_u && (step * dv).abs() <= tol_v {
                    break;
                }
                let un = clamp(u + step * du, (ua, ub));
                let vn = clamp(v + step * dv, (va, vb));
                let fnew = (self.point_in(un, vn, su_span, sv_span) - p).norm_squared();
                if fnew <= f {
                    accepted = Some((un, vn));
                    break;
                }
                if fnew - f <= 8.0 * f64::EPSILON * f {
                    // The distance is flat to rounding here: accept the step if it reduces
                    // the gradient instead.
                    let mut t = [[Vector3::zeros(); 2]; 2];
                    self.derivs_in(un, vn, su_span, sv_span, &mut t, None);
                    let rt = t[0][0] - p.coords;
                    let gt = [rt.dot(&t[1][0]), rt.dot(&t[0][1])];
                    let mask = |g: [f64; 2]| {
                        (if free_u { g[0] * g[0] } else { 0.0 })
                            + (if free_v { g[1] * g[1] } else { 0.0 })
                    };
                    if mask(gt) < mask(g) {
                        accepted = Some((un, vn));
                        break;
                    }
                }
                step *= 0.5;
            }
            let Some((un, vn)) = accepted else {
                // No descent in floating point: a minimum to working precision.
                return done(u, v, f, true);
            };
            let tiny_u = (un - u).abs() <= tol_u;
            let tiny_v = (vn - v).abs() <= tol_v;
            u = un;
            v = vn;
            self.derivs_in(u, v, su_span, sv_span, &mut s, None);
            r = s[0][0] - p.coords;
            f = r.norm_squared();
            if tiny_u && tiny_v {
                return done(u, v, f, true);
            }
        }
        done(u, v, f, false)
    }
}
