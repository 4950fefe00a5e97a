//! Closest point on a curve: a global search by Bezier subdivision with convex-hull culling and
//! root isolation, and a local Newton variant.
//!
//! The closest point `C(t)` to `p` is either a domain end or a root of
//! `f(t) = (C(t) - p) . C'(t)` where `f` changes sign from `-` to `+`. On a rational Bezier
//! piece with homogeneous control points `(B_i + p w_i, w_i)` (so `B(s) = A(s) - p w(s)`),
//! `C - p = B / w` and `C' = (B' w - B w') / w^2`, hence
//! `f = B . (B' w - B w') / w^3`: the sign of `f` is that of the polynomial
//! `g = B . (B' w - B w')` of degree `3n - 1`, whose Bernstein coefficients follow from the
//! control points by the product rule for Bernstein polynomials. Their sign changes bound the
//! number of roots of `f` in the piece (Descartes' rule of signs for the Bernstein basis):
//! none means the piece's minimum is at an end, exactly one means at most one interior minimum,
//! found by bracketed Newton; more means the piece is split in half.
//!
//! ```
//! use kerf_nurbs::NurbsCurve;
//! use nalgebra::Point3;
//!
//! let h = std::f64::consts::FRAC_1_SQRT_2;
//! let arc = NurbsCurve::try_new(
//!     2,
//!     vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
//!     vec![Point3::new(1.0, 0.0, 0.0), Point3::new(1.0, 1.0, 0.0), Point3::new(0.0, 1.0, 0.0)],
//!     Some(vec![1.0, h, 1.0]),
//! )?;
//! let q = arc.closest_point(&Point3::new(3.0, 3.0, 0.0));
//! assert!((q.distance - (18f64.sqrt() - 1.0)).abs() < 1e-14, "distance to the unit circle");
//! assert!((q.point.x - h).abs() < 1e-14 && (q.point.y - h).abs() < 1e-14, "on the diagonal");
//! # Ok::<(), kerf_nurbs::NurbsError>(())
//! ```

use nalgebra::{Point3, Vector3, Vector4};

use crate::basis::binomial;
use crate::bezier::RationalBezier;
use crate::curve::NurbsCurve;
use crate::knots;
use crate::queue::BestFirst;
use crate::{MAX_DEGREE, MAX_ORDER};

/// Result of projecting a point onto a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurveProjection {
    /// Parameter of the closest point.
    pub t: f64,
    /// Distance from the query point to the curve, `|C(t) - p|`.
    pub distance: f64,
    /// The closest point `C(t)`.
    pub point: Point3<f64>,
}

/// Coefficients of `g` whose magnitude is below this multiple of their running error bound
/// are treated as zero.
const NOISE: f64 = 256.0 * f64::EPSILON;

/// Subdivision depth after which a piece with several candidate roots is resolved by sampling.
const MAX_DEPTH: u32 = 48;

/// Pieces the global closest-point search may examine per Bezier piece of the curve before it
/// returns its best candidate.
pub const CLOSEST_POPS_PER_PIECE: usize = 256;

/// Iteration limit of the one-dimensional Newton methods.
const ITERATIONS: usize = 100;

/// Number of Bernstein coefficients of `g` for the largest degree, `3 * MAX_DEGREE`.
const G_LEN: usize = 3 * MAX_DEGREE;

/// A Bezier piece waiting in the best-first queue.
struct Pending {
    depth: u32,
    piece: RationalBezier,
}

/// The best candidate so far.
#[derive(Debug, Clone, Copy)]
struct Best {
    t: f64,
    distance: f64,
}

impl Best {
    #[inline]
    fn offer(&mut self, t: f64, distance: f64) {
        if distance < self.distance {
            *self = Best { t, distance };
        }
    }
}

/// What the Bernstein coefficients of `g` say about a piece.
enum Roots {
    /// `g` vanishes identically (to rounding): every point of the piece is stationary.
    Flat,
    /// No sign change: the piece's minimum is at one of its ends.
    None,
    /// One sign change from `-` to `+`: exactly one interior minimum.
    OneMinimum,
    /// One sign change from `+` to `-`: one interior maximum, minima at the ends.
    OneMaximum,
    /// Two or more sign changes.
    Several,
}

impl NurbsCurve {
    /// The globally closest point of the curve to `p`.
    ///
    /// The curve is cut into its rational Bezier pieces, kept in a queue ordered by the
    /// distance from `p` to the bounding box of each piece's control points, a lower bound on
    /// the distance to the piece (convex hull property). The piece with the smallest bound is
    /// taken next; once that bound is not below the best distance found, the search ends. The
    /// Bernstein coefficients of `g = B . (B' w - B w')` (see the docs of `closest.rs`) classify
    /// the piece: no sign change leaves its ends as candidates; one change from `-` to `+`
    /// brackets the single interior minimum, found by Newton's method on
    /// `(C - p) . C'` safeguarded by bisection; more changes split the piece in half (its
    /// mid-point becomes a candidate). The domain ends are always candidates. Where the curve
    /// jumps (an interior knot of multiplicity `degree + 1`), the left-hand limit at the knot
    /// is represented by the largest parameter below it.
    ///
    /// The result is deterministic; `distance` is `|C(t) - p|` as evaluated by
    /// [`NurbsCurve::point`]. The search examines at most [`CLOSEST_POPS_PER_PIECE`] pieces per
    /// Bezier piece of the curve (plus 256); a pathological input that exhausts this gets the
    /// best candidate found.
    pub fn closest_point(&self, p: &Point3<f64>) -> CurveProjection {
        let (a, b) = self.domain();
        let mut best = Best {
            t: a,
            distance: f64::INFINITY,
        };
        best.offer(a, (self.point(a) - p).norm());
        best.offer(b, (self.point(b) - p).norm());
        // Where the curve jumps (an interior knot of multiplicity degree + 1), the end of the
        // piece before the knot is not C(knot), which belongs to the next span: use the
        // largest parameter below the knot instead, whose point is the left-hand limit.
        let jumps = self.jumps();
        let end_of = |t1: f64| {
            if jumps.contains(&t1) {
                float_before(t1)
            } else {
                t1
            }
        };
        let mut heap = BestFirst::new();
        self.for_each_bezier_piece(a, b, |piece| {
            let pending = Pending {
                depth: 0,
                piece: *piece,
            };
            heap.push(box_distance(piece, p), pending);
        });
        // Work budget: a fixed number of pieces examined per Bezier piece of the curve, so that
        // no input (however many near-equal candidates it has) makes the search exponential.
        let mut budget = CLOSEST_POPS_PER_PIECE * heap.len() + 256;
        while let Some((lower_bound, entry)) = heap.pop() {
            if lower_bound >= best.distance || lower_bound.is_nan() {
                break;
            }
            if budget == 0 {
                // The best candidate so far (never farther than the true minimum by more than
                // the spread of the remaining pieces' lower bounds).
                break;
            }
            budget -= 1;
            let piece = entry.piece;
            let (t0, t1) = (piece.t0, piece.t1);
            match classify(&piece, p) {
                Roots::None | Roots::OneMaximum => {
                    let t1 = end_of(t1);
                    best.offer(t0, (self.point(t0) - p).norm());
                    best.offer(t1, (self.point(t1) - p).norm());
                }
                Roots::Flat => {
                    let tm = 0.5 * (t0 + t1);
                    best.offer(tm, (self.point(tm) - p).norm());
                }
                Roots::OneMinimum => {
                    let t = self.bracketed_newton(p, t0, t1);
                    best.offer(t, (self.point(t) - p).norm());
                }
                Roots::Several => {
                    let tm = 0.5 * (t0 + t1);
                    if entry.depth >= MAX_DEPTH || !(tm > t0 && tm < t1) {
                        best.offer(t0, (self.point(t0) - p).norm());
                        let end = end_of(t1);
                        best.offer(end, (self.point(end) - p).norm());
                        self.resolve_by_sampling(p, t0, t1, &mut best);
                        continue;
                    }
                    best.offer(tm, (self.point(tm) - p).norm());
                    let (left, right) = piece.subdivide(0.5);
                    for half in [left, right] {
                        let lower_bound = box_distance(&half, p);
                        if lower_bound < best.distance {
                            let pending = Pending {
                                depth: entry.depth + 1,
                                piece: half,
                            };
                            heap.push(lower_bound, pending);
                        }
                    }
                }
            }
        }
        self.projection(p, best.t)
    }

    /// The closest point to `p` near the parameter `t_guess`: a local minimum of the distance
    /// reached by Newton's method on `(C(t) - p) . C'(t)` from `t_guess` (clamped to the
    /// domain), with the Gauss-Newton step `-f / |C'|^2` where the second-order model is not
    /// convex, steps halved until the distance does not grow (or, where the distance is flat
    /// to rounding, until `|f|` shrinks), and the domain ends as bounds. A start on a local
    /// maximum of the distance is nudged to the side that descends. Never farther than
    /// `C(t_guess)`; global only if `t_guess` lies in the basin of the global minimum (use
    /// [`NurbsCurve::closest_point`] otherwise).
    pub fn closest_point_near(&self, p: &Point3<f64>, t_guess: f64) -> CurveProjection {
        let (a, b) = self.domain();
        let mut t = if t_guess.is_nan() {
            a
        } else {
            t_guess.clamp(a, b)
        };
        let (mut c, mut d1, mut d2) = self.eval_d2(t);
        let mut r = c - p;
        let mut f = r.norm_squared();
        let mut escapes = 2;
        for _ in 0..ITERATIONS {
            let g = r.dot(&d1);
            if (t <= a && g >= 0.0) || (t >= b && g <= 0.0) {
                break;
            }
            let speed2 = d1.norm_squared();
            let h = speed2 + r.dot(&d2);
            if g.abs() <= 1e-14 * r.norm() * d1.norm() {
                // Stationary. A maximum of the distance (negative second derivative) is left
                // towards the side that descends; a minimum ends the search.
                if h >= 0.0 || escapes == 0 {
                    break;
                }
                escapes -= 1;
                let Some(tn) = self.escape_maximum(p, t, f) else {
                    break;
                };
                t = tn;
                (c, d1, d2) = self.eval_d2(t);
                r = c - p;
                f = r.norm_squared();
                continue;
            }
            let step = if h > 0.0 { -g / h } else { -g / speed2 };
            if !step.is_finite() {
                break;
            }
            let step = step.clamp(a - b, b - a);
            let mut scale = 1.0;
            let mut accepted = None;
            for _ in 0..60 {
                let tn = (t + scale * step).clamp(a, b);
                let (cn, dn) = self.eval_d1(tn);
                let fnew = (cn - p).norm_squared();
                // Where the distance is flat to rounding, a smaller gradient also counts.
                if fnew <= f
                    || (fnew - f <= 8.0 * f64::EPSILON * f && (cn - p).dot(&dn).abs() < g.abs())
                {
                    accepted = Some(tn);
                    break;
                }
                scale *= 0.5;
            }
            let Some(tn) = accepted else { break };
            let tiny = (tn - t).abs() <= 4.0 * f64::EPSILON * (t.abs() + (b - a));
            t = tn;
            (c, d1, d2) = self.eval_d2(t);
            r = c - p;
            f = r.norm_squared();
            if tiny {
                break;
            }
        }
        self.projection(p, t)
    }

    /// A parameter near the stationary point `t` (squared distance `f`) at which the squared
    /// distance is smaller, probing both sides at shrinking offsets; `None` if there is none.
    fn escape_maximum(&self, p: &Point3<f64>, t: f64, f: f64) -> Option<f64> {
        let (a, b) = self.domain();
        let mut delta = 1e-3 * (b - a);
        for _ in 0..40 {
            let left = (t - delta).max(a);
            let right = (t + delta).min(b);
            let fl = (self.point(left) - p).norm_squared();
            let fr = (self.point(right) - p).norm_squared();
            if fl.min(fr) < f {
                return Some(if fl <= fr { left } else { right });
            }
            delta *= 0.5;
        }
        None
    }

    fn projection(&self, p: &Point3<f64>, t: f64) -> CurveProjection {
        let point = self.point(t);
        CurveProjection {
            t,
            distance: (point - p).norm(),
            point,
        }
    }

    /// `(C(t) - p) . C'(t)` and its derivative `|C'|^2 + (C - p) . C''`.
    #[inline]
    fn stationarity(&self, p: &Point3<f64>, t: f64) -> (f64, f64) {
        let (c, d1, d2) = self.eval_d2(t);
        let r = c - p;
        (r.dot(&d1), d1.norm_squared() + r.dot(&d2))
    }

    /// The minimiser of the distance on `[lo, hi]` when `(C - p) . C'` has a single sign change
    /// from `-` to `+` there: Newton's method kept inside the bracket, bisection where a Newton
    /// step would leave it.
    ///
    /// The signs at the ends are taken as given (from the piece's Bernstein coefficients) and
    /// never evaluated: at a knot the curve's derivative is that of the next span, and an end
    /// may be a stationary point itself.
    fn bracketed_newton(&self, p: &Point3<f64>, mut lo: f64, mut hi: f64) -> f64 {
        let mut t = 0.5 * (lo + hi);
        for _ in 0..ITERATIONS {
            let (ft, dft) = self.stationarity(p, t);
            if ft == 0.0 || !ft.is_finite() || !(t > lo && t < hi) {
                return t;
            }
            if ft < 0.0 {
                lo = t;
            } else {
                hi = t;
            }
            let newton = t - ft / dft;
            let next = if dft > 0.0 && newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            let width = hi - lo;
            if width <= 4.0 * f64::EPSILON * lo.abs().max(hi.abs())
                || (next - t).abs() <= 2.0 * f64::EPSILON * t.abs().max(width)
            {
                return next;
            }
            t = next;
        }
        t
    }

    /// The interior knots where the curve may jump: multiplicity above the degree.
    fn jumps(&self) -> Vec<f64> {
        knots::interior_knots(self.degree(), self.knots(), self.len())
            .into_iter()
            .filter(|&(_, m)| m > self.degree())
            .map(|(u, _)| u)
            .collect()
    }

    /// Fallback for a piece that still has several candidate roots after [`MAX_DEPTH`]
    /// halvings (a multiple root, or `p` on an evolute): samples `(C - p) . C'` and refines
    /// every `-` to `+` sign change.
    fn resolve_by_sampling(&self, p: &Point3<f64>, t0: f64, t1: f64, best: &mut Best) {
        const N: usize = 16;
        // Interior samples only: at the ends the derivative would come from a neighbour span.
        let mut prev: Option<(f64, f64)> = None;
        for i in 1..N {
            let t = t0 + (t1 - t0) * (i as f64 / N as f64);
            let f = self.stationarity(p, t).0;
            best.offer(t, (self.point(t) - p).norm());
            if let Some((tp, fp)) = prev {
                if fp < 0.0 && f > 0.0 {
                    let r = self.bracketed_newton(p, tp, t);
                    best.offer(r, (self.point(r) - p).norm());
                }
            }
            prev = Some((t, f));
        }
    }
}

/// The largest `f64` below the finite `t`: the parameter that stands for the left-hand limit
/// at a knot where a curve or surface jumps.
pub(crate) fn float_before(t: f64) -> f64 {
    if t > 0.0 {
        f64::from_bits(t.to_bits() - 1)
    } else if t < 0.0 {
        f64::from_bits(t.to_bits() + 1)
    } else {
        -f64::from_bits(1)
    }
}

/// Distance from `p` to the axis-aligned box of the piece's projected control points.
fn box_distance(piece: &RationalBezier, p: &Point3<f64>) -> f64 {
    hull_box_distance(piece.homogeneous(), p)
}

/// Distance from `p` to the axis-aligned box of the projected homogeneous control points
/// `net` (of a curve piece or a surface patch): a lower bound on the distance to the piece
/// (convex hull property, positive weights).
pub(crate) fn hull_box_distance(net: &[Vector4<f64>], p: &Point3<f64>) -> f64 {
    let (lo, hi) = crate::curve::hull_box(net);
    crate::distance_to_box(p, &lo, &hi)
}

/// Row `n` of Pascal's triangle, `C(n, 0..=n)`.
fn binomial_row(n: usize) -> [f64; G_LEN] {
    let mut row = [0.0; G_LEN];
    for (k, x) in row.iter_mut().enumerate().take(n + 1) {
        *x = binomial(n, k);
    }
    row
}

/// Computes the Bernstein coefficients of `g = B . (B' w - B w')` on the piece (see the
/// [module](self) docs) with running error bounds, and counts their sign changes.
fn classify(piece: &RationalBezier, p: &Point3<f64>) -> Roots {
    let n = piece.degree;
    let cpw = piece.homogeneous();
    let pn = p.coords.norm();
    // B_i, |B_i| bound (magnitudes before cancellation), w_i.
    let mut bvec = [Vector3::zeros(); MAX_ORDER];
    let mut beta = [0.0; MAX_ORDER];
    let mut w = [0.0; MAX_ORDER];
    for i in 0..=n {
        bvec[i] = cpw[i].xyz() - p.coords * cpw[i].w;
        beta[i] = cpw[i].xyz().norm() + pn * cpw[i].w;
        w[i] = cpw[i].w;
    }
    // H = B' w - B w' / n, degree 2n - 1: product of the degree n-1 differences with degree n.
    let (c1, c0, c2) = (
        binomial_row(n - 1),
        binomial_row(n),
        binomial_row(2 * n - 1),
    );
    let mut h = [Vector3::zeros(); G_LEN];
    let mut h_abs = [0.0; G_LEN];
    for i in 0..n {
        let db = bvec[i + 1] - bvec[i];
        let dw = w[i + 1] - w[i];
        let db_abs = beta[i] + beta[i + 1];
        let dw_abs = w[i] + w[i + 1];
        for j in 0..=n {
            let coeff = c1[i] * c0[j] / c2[i + j];
            h[i + j] += (db * w[j] - bvec[j] * dw) * coeff;
            h_abs[i + j] += (db_abs * w[j] + beta[j] * dw_abs) * coeff;
        }
    }
    // g = B . H, degree 3n - 1.
    let c3 = binomial_row(3 * n - 1);
    let mut g = [0.0; G_LEN];
    let mut g_abs = [0.0; G_LEN];
    for j in 0..=n {
        for l in 0..2 * n {
            let coeff = c0[j] * c2[l] / c3[j + l];
            g[j + l] += bvec[j].dot(&h[l]) * coeff;
            g_abs[j + l] += beta[j] * h_abs[l] * coeff;
        }
    }
    let mut first_sign = 0.0;
    let mut last_sign = 0.0;
    let mut changes = 0;
    for m in 0..3 * n {
        if g[m].abs() <= NOISE * g_abs[m] || g[m].is_nan() {
            continue;
        }
        let sign = g[m].signum();
        if last_sign == 0.0 {
            first_sign = sign;
        } else if sign != last_sign {
            changes += 1;
        }
        last_sign = sign;
    }
    match changes {
        _ if last_sign == 0.0 => Roots::Flat,
        0 => Roots::None,
        1 if first_sign < 0.0 => Roots::OneMinimum,
        1 => Roots::OneMaximum,
        _ => Roots::Several,
    }
}

#[cfg(test)]
mod tests;
