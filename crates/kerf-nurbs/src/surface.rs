//! Rational B-spline (NURBS) surfaces: validation, evaluation, partial derivatives, unit normals
//! (with well-defined limits on degenerate edges such as the poles of a sphere or the apex of a
//! cone), and closest points.
//!
//! The control net is indexed `[a][b]` with `a` running along `u` and `b` along `v`. It is stored
//! flat and row-major over `a` (entry `a * n_v + b`) in homogeneous form `(w x, w y, w z, w)`.
//!
//! ```
//! use kerf_nurbs::NurbsSurface;
//! use nalgebra::Point3;
//!
//! // A quarter cylinder of radius 2 and height 3: rational quadratic in u, linear in v.
//! let h = std::f64::consts::FRAC_1_SQRT_2;
//! let (r, z) = (2.0, 3.0);
//! let ring = [(r, 0.0), (r, r), (0.0, r)];
//! let s = NurbsSurface::try_new(
//!     2,
//!     1,
//!     vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
//!     vec![0.0, 0.0, 1.0, 1.0],
//!     ring.iter().map(|&(x, y)| vec![Point3::new(x, y, 0.0), Point3::new(x, y, z)]).collect(),
//!     Some(vec![vec![1.0, 1.0], vec![h, h], vec![1.0, 1.0]]),
//! )?;
//! let p = s.point(0.3, 0.5);
//! assert!((p.x.hypot(p.y) - r).abs() < 1e-14, "the point lies on the cylinder");
//! let n = s.normal(0.3, 0.5).expect("regular point");
//! assert!((n - nalgebra::Vector3::new(p.x, p.y, 0.0) / r).norm() < 1e-14, "radial normal");
//! let q = s.closest_point(&Point3::new(5.0, 5.0, 1.0), None);
//! assert!((q.distance - (50f64.sqrt() - r)).abs() < 1e-12, "closest point on the cylinder");
//! # Ok::<(), kerf_nurbs::NurbsError>(())
//! ```

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{Point3, Vector3, Vector4};

use crate::basis::{basis_funs, basis_funs_m, binomial, ders_basis_funs_m};
use crate::closest::float_before;
use crate::curve::{project, NurbsCurve};
use crate::error::{NurbsError, Result};
use crate::knots;
use crate::MAX_ORDER;

/// A non-uniform rational B-spline surface in 3D.
///
/// Stored as the two degrees, the two full knot vectors and the homogeneous control net. The
/// parameter domain is `domain_u() x domain_v()`; clamped and unclamped knot vectors are both
/// legal. Construction validates everything (see [`NurbsSurface::try_new`]), so evaluation
/// never fails: parameters outside the domain (and NaN) are clamped to it, as for curves.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsSurface {
    degree_u: usize,
    degree_v: usize,
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    n_u: usize,
    n_v: usize,
    /// Homogeneous control net, entry `a * n_v + b`.
    cpw: Vec<Vector4<f64>>,
    rational: bool,
    /// Domain edges along which the surface collapses to a point:
    /// `[u = u_min, u = u_max, v = v_min, v = v_max]`.
    collapsed: [bool; 4],
    /// Directions in which the surface is closed (its boundary curves at both ends of the
    /// domain coincide): `[u, v]`.
    closed: [bool; 2],
}

/// Result of projecting a point onto a surface ([`NurbsSurface::closest_point`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceProjection {
    /// u parameter of the closest point.
    pub u: f64,
    /// v parameter of the closest point.
    pub v: f64,
    /// Distance from the query point to the surface, `|S(u, v) - p|`.
    pub distance: f64,
    /// The closest point `S(u, v)`.
    pub point: Point3<f64>,
}

/// Binomial coefficients `C(n, k)` for `n < 8`, for the Leibniz rule of the rational
/// derivatives (orders up to [`TAYLOR_ORDER`] + 1 = 5).
const BINOMIAL: [[f64; 8]; 8] = {
    let mut t = [[0.0; 8]; 8];
    let mut n = 0;
    while n < 8 {
        t[n][0] = 1.0;
        let mut k = 1;
        while k <= n {
            t[n][k] = t[n - 1][k - 1] + t[n - 1][k];
            k += 1;
        }
        n += 1;
    }
    t
};

/// Relative size of rounding noise, against the running error bounds computed by
/// [`NurbsSurface::derivs`], below which a derivative expression is treated as zero.
const NOISE: f64 = 1024.0 * f64::EPSILON;

/// Within this fraction of the boundary knot span of a collapsed edge, [`NurbsSurface::normal`]
/// uses the mid-point formula instead of `Su x Sv` (see there).
const NEAR_EDGE: f64 = 1e-5;

/// Highest order of the Taylor expansion of `Su x Sv` tried at a degenerate point.
const TAYLOR_ORDER: usize = 4;

/// Iteration limit of the projection Newton method.
const NEWTON_ITERATIONS: usize = 60;

/// Newton stops when `|(S - p) . Su| <= ORTHOGONALITY |S - p| |Su|` (and likewise for `v`).
const ORTHOGONALITY: f64 = 1e-13;

/// A warm-started Newton result that moved more than this fraction of the domain (in either
/// direction) is not trusted; the global search runs instead.
const WARM_REACH: f64 = 0.25;

/// Relative size of rounding noise below which a Bernstein coefficient of the stationarity
/// conditions counts as zero in the closest-point search.
const COEFFICIENT_NOISE: f64 = 256.0 * f64::EPSILON;

/// Sub-patches at least this deep whose nets are simple (see [`simple_net`]) are leaves of
/// the closest-point search (Newton runs inside them).
const MIN_LEAF_DEPTH: u32 = 2;

/// See [`MIN_LEAF_DEPTH`].
const LEAF_TURNING: f64 = std::f64::consts::PI / 8.0;

/// See [`simple_net`].
const LEAF_NORMAL_CONE: f64 = std::f64::consts::PI / 3.0;

/// Sample intervals per direction on a leaf of the closest-point search.
const LEAF_SAMPLES: usize = 4;

/// Depth at which every sub-patch is a leaf.
const MAX_SUBDIVISION: u32 = 12;

/// Sub-patches split per closest-point query before all further ones become leaves.
const SUBPATCH_BUDGET: usize = 4096;

/// A candidate closest point.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    u: f64,
    v: f64,
    distance: f64,
}

/// A knot span as `(span index, start, end)`.
type Span = (usize, f64, f64);

/// A knot-span cell: one rational polynomial patch.
#[derive(Debug, Clone, Copy)]
struct Patch {
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

/// A sub-patch of a cell in the global closest-point search.
#[derive(Debug, Clone)]
struct SubPatch {
    /// Distance from the query point to the bounding box of the sub-patch's net.
    lower_bound: f64,
    /// Creation order, for deterministic ties.
    order: u64,
    /// Number of halvings from the cell.
    depth: u32,
    /// The cell: indices into the lists of non-empty spans.
    cell: (usize, usize),
    /// Parameter rectangle `(u0, u1, v0, v1)`.
    rect: (f64, f64, f64, f64),
    /// Rational Bezier net, `(degree_u + 1) x (degree_v + 1)`, row-major over u.
    net: Vec<Vector4<f64>>,
}

impl PartialEq for SubPatch {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for SubPatch {}

impl PartialOrd for SubPatch {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for SubPatch {
    /// Reversed, so that the max-heap pops the smallest lower bound (then the oldest entry).
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .lower_bound
            .total_cmp(&self.lower_bound)
            .then(other.order.cmp(&self.order))
    }
}

/// An edge of a parameter rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Edge {
    /// `u = u0`.
    U0,
    /// `u = u1`.
    U1,
    /// `v = v0`.
    V0,
    /// `v = v1`.
    V1,
}

impl NurbsSurface {
    /// Builds a surface from its degrees, full knot vectors, control net `control_points[a][b]`
    /// (`a` along u, `b` along v) and optional weights in the same layout (`None` = all 1),
    /// checking every value.
    ///
    /// # Errors
    /// - the degree and knot checks of curves, per direction (see
    ///   [`crate::knots::validate`]), naming `degree_u`/`knots_u` or `degree_v`/`knots_v`;
    ///   too few rows or columns give [`NurbsError::TooFewPoints`] for `control_points`;
    /// - [`NurbsError::RaggedGrid`] (`control_points`) if a row's length differs from row 0's;
    /// - [`NurbsError::PointNotFinite`] (`control_points[a][b]`) for a NaN or infinite
    ///   coordinate;
    /// - [`NurbsError::WeightCount`] if the weights hold a different total number of entries
    ///   than the control net, [`NurbsError::RaggedGrid`] (`weights`) if the totals agree but a
    ///   row of weights does not match the control net's row length;
    /// - [`NurbsError::BadWeight`] (`weights[a][b]`) for a weight that is not finite and > 0.
    pub fn try_new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        control_points: Vec<Vec<Point3<f64>>>,
        weights: Option<Vec<Vec<f64>>>,
    ) -> Result<Self> {
        let n_u = control_points.len();
        knots::validate(
            degree_u,
            &knots_u,
            n_u,
            "degree_u",
            "knots_u",
            "control_points",
        )?;
        // n_u >= degree_u + 1 >= 2 now.
        let n_v = control_points[0].len();
        for (row, r) in control_points.iter().enumerate() {
            if r.len() != n_v {
                return Err(NurbsError::RaggedGrid {
                    field: "control_points",
                    row,
                    got: r.len(),
                    expected: n_v,
                });
            }
        }
        knots::validate(
            degree_v,
            &knots_v,
            n_v,
            "degree_v",
            "knots_v",
            "control_points",
        )?;
        for (a, row) in control_points.iter().enumerate() {
            for (b, p) in row.iter().enumerate() {
                if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                    return Err(NurbsError::PointNotFinite {
                        field: "control_points",
                        index: format!("[{a}][{b}]"),
                        x: p.x,
                        y: p.y,
                        z: p.z,
                    });
                }
            }
        }
        if let Some(w) = &weights {
            let total: usize = w.iter().map(Vec::len).sum();
            if total != n_u * n_v {
                return Err(NurbsError::WeightCount {
                    field: "weights",
                    expected: n_u * n_v,
                    got: total,
                });
            }
            for (row, r) in w.iter().enumerate() {
                if r.len() != n_v {
                    return Err(NurbsError::RaggedGrid {
                        field: "weights",
                        row,
                        got: r.len(),
                        expected: n_v,
                    });
                }
            }
            for (a, row) in w.iter().enumerate() {
                for (b, &value) in row.iter().enumerate() {
                    if !(value.is_finite() && value > 0.0) {
                        return Err(NurbsError::BadWeight {
                            field: "weights",
                            index: format!("[{a}][{b}]"),
                            value,
                        });
                    }
                }
            }
        }
        // Exact power-of-two normalisation, as for curves: subnormal weights become normal.
        let weights = match weights {
            Some(w) => {
                let flat = crate::curve::normalized_weights(w.concat(), "weights").map_err(
                    |e| match e {
                        NurbsError::WeightRatio { field, ratio, .. } => NurbsError::WeightRatio {
                            field,
                            index: String::new(),
                            ratio,
                        },
                        other => other,
                    },
                )?;
                Some(flat.chunks(n_v).map(<[f64]>::to_vec).collect::<Vec<_>>())
            }
            None => None,
        };
        let mut cpw = Vec::with_capacity(n_u * n_v);
        for (a, row) in control_points.iter().enumerate() {
            for (b, p) in row.iter().enumerate() {
                let w = weights.as_ref().map_or(1.0, |w| w[a][b]);
                cpw.push(Vector4::new(p.x * w, p.y * w, p.z * w, w));
            }
        }
        let rational = cpw.iter().any(|c| c.w != cpw[0].w);
        let mut surface = Self {
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            n_u,
            n_v,
            cpw,
            rational,
            collapsed: [false; 4],
            closed: [false; 2],
        };
        (surface.collapsed, surface.closed) = surface.detect_edges();
        Ok(surface)
    }

    /// Like [`NurbsSurface::try_new`] for data known to be valid.
    ///
    /// # Panics
    /// If the data is invalid; the message is the [`NurbsError`].
    pub fn new(
        degree_u: usize,
        degree_v: usize,
        knots_u: Vec<f64>,
        knots_v: Vec<f64>,
        control_points: Vec<Vec<Point3<f64>>>,
        weights: Option<Vec<Vec<f64>>>,
    ) -> Self {
        match Self::try_new(
            degree_u,
            degree_v,
            knots_u,
            knots_v,
            control_points,
            weights,
        ) {
            Ok(s) => s,
            Err(e) => panic!("invalid NURBS surface: {e}"),
        }
    }

    /// The degree along u.
    pub fn degree_u(&self) -> usize {
        self.degree_u
    }

    /// The degree along v.
    pub fn degree_v(&self) -> usize {
        self.degree_v
    }

    /// The full knot vector along u.
    pub fn knots_u(&self) -> &[f64] {
        &self.knots_u
    }

    /// The full knot vector along v.
    pub fn knots_v(&self) -> &[f64] {
        &self.knots_v
    }

    /// The parameter domain along u, `[knots_u[p], knots_u[n_u]]`.
    pub fn domain_u(&self) -> (f64, f64) {
        (self.knots_u[self.degree_u], self.knots_u[self.n_u])
    }

    /// The parameter domain along v, `[knots_v[q], knots_v[n_v]]`.
    pub fn domain_v(&self) -> (f64, f64) {
        (self.knots_v[self.degree_v], self.knots_v[self.n_v])
    }

    /// The size `(n_u, n_v)` of the control net: rows along u, entries per row along v.
    pub fn net_size(&self) -> (usize, usize) {
        (self.n_u, self.n_v)
    }

    /// The homogeneous control net `(w x, w y, w z, w)`, flat: entry `[a][b]` is at
    /// `a * n_v + b`.
    pub fn homogeneous_points(&self) -> &[Vector4<f64>] {
        &self.cpw
    }

    /// The homogeneous control point `[a][b]`.
    ///
    /// # Panics
    /// If `a >= n_u` or `b >= n_v`.
    pub fn homogeneous_point(&self, a: usize, b: usize) -> Vector4<f64> {
        assert!(
            a < self.n_u && b < self.n_v,
            "control point [{a}][{b}] outside the {}x{} net",
            self.n_u,
            self.n_v
        );
        self.cpw[a * self.n_v + b]
    }

    /// The control points `[a][b]` (projected from homogeneous form).
    pub fn control_points(&self) -> Vec<Vec<Point3<f64>>> {
        self.cpw
            .chunks(self.n_v)
            .map(|row| row.iter().map(project).collect())
            .collect()
    }

    /// The weights `[a][b]`.
    pub fn weights(&self) -> Vec<Vec<f64>> {
        self.cpw
            .chunks(self.n_v)
            .map(|row| row.iter().map(|c| c.w).collect())
            .collect()
    }

    /// True if the weights are not all equal (a surface with equal weights is polynomial).
    pub fn is_rational(&self) -> bool {
        self.rational
    }

    /// Which domain edges are collapsed to a single point (a pole or an apex), in the order
    /// `[u = u_min, u = u_max, v = v_min, v = v_max]`. An edge counts as collapsed when its
    /// boundary curve stays within `1e-10` of the surface's size of one point.
    pub fn collapsed_edges(&self) -> [bool; 4] {
        self.collapsed
    }

    /// Whether the surface is closed along u and along v: its boundary curves at both ends of
    /// the domain coincide (a cylinder around its axis, a torus in both directions), within
    /// `1e-10` of the surface's size. A warm-started [`NurbsSurface::closest_point`] crosses
    /// such a seam.
    pub fn closed_directions(&self) -> (bool, bool) {
        (self.closed[0], self.closed[1])
    }

    /// The non-empty knot spans along u inside the domain, as `(span index, start, end)`.
    pub fn spans_u(&self) -> Vec<(usize, f64, f64)> {
        spans(self.degree_u, &self.knots_u, self.n_u)
    }

    /// The non-empty knot spans along v inside the domain, as `(span index, start, end)`.
    pub fn spans_v(&self) -> Vec<(usize, f64, f64)> {
        spans(self.degree_v, &self.knots_v, self.n_v)
    }

    /// The axis-aligned box `(min, max)` of the control points, which contains the surface
    /// (convex-hull property, all weights > 0).
    pub fn bounding_box(&self) -> (Point3<f64>, Point3<f64>) {
        crate::curve::hull_box(&self.cpw)
    }

    /// The diagonal of the control-point bounding box: the surface's size, for relative
    /// tolerances.
    pub fn size(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).norm()
    }

    #[inline]
    fn clamp_uv(&self, u: f64, v: f64) -> (f64, f64) {
        (clamp(u, self.domain_u()), clamp(v, self.domain_v()))
    }

    /// The point `S(u, v)`. Parameters outside the domain (and NaN) are clamped to it.
    #[inline]
    pub fn point(&self, u: f64, v: f64) -> Point3<f64> {
        let (u, v) = self.clamp_uv(u, v);
        let (su, sv) = self.spans_at(u, v);
        self.point_in(u, v, su, sv)
    }

    /// The knot spans `(su, sv)` that hold `(u, v)` (see [`knots::find_span`]).
    #[inline]
    fn spans_at(&self, u: f64, v: f64) -> (usize, usize) {
        (
            knots::find_span(self.degree_u, &self.knots_u, self.n_u, u),
            knots::find_span(self.degree_v, &self.knots_v, self.n_v, v),
        )
    }

    /// The point at `(u, v)` evaluated with the polynomials of the spans `su`, `sv` (so on a
    /// span's upper edge it is the limit from inside the span).
    #[inline]
    fn point_in(&self, u: f64, v: f64, su: usize, sv: usize) -> Point3<f64> {
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
    fn point_in_m<const M: usize>(&self, u: f64, v: f64, su: usize, sv: usize) -> Point3<f64> {
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
    fn derivs<const KU: usize, const KV: usize>(
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
    fn derivs_in<const KU: usize, const KV: usize>(
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
    fn derivs_in_m<const KU: usize, const KV: usize, const M: usize>(
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
    fn interior_sign(&self, along_u: bool, u: f64, v: f64) -> f64 {
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
    fn normal_near_collapsed_edge(&self, u: f64, v: f64) -> Option<Vector3<f64>> {
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
    fn taylor_normal(&self, u: f64, v: f64, along_u: bool, sign: f64) -> Option<Vector3<f64>> {
        const K: usize = TAYLOR_ORDER + 2;
        if along_u {
            let mut s = [[Vector3::zeros(); 2]; K];
            let mut b = [[0.0; 2]; K];
            self.derivs(u, v, &mut s, Some(&mut b));
            for k in 0..=TAYLOR_ORDER {
                let mut t = Vector3::zeros();
                let mut noise = 0.0;
                for i in 0..=k {
                    let c = binomial(k, i);
                    let (x, y) = (s[i + 1][0], s[k - i][1]);
                    t += x.cross(&y) * c;
                    noise += c * (b[i + 1][0] * y.norm() + x.norm() * b[k - i][1]);
                }
                if t.norm() > NOISE * noise && t.norm().is_finite() {
                    return Some(t.normalize() * sign.powi(k as i32));
                }
            }
        } else {
            let mut s = [[Vector3::zeros(); K]; 2];
            let mut b = [[0.0; K]; 2];
            self.derivs(u, v, &mut s, Some(&mut b));
            for k in 0..=TAYLOR_ORDER {
                let mut t = Vector3::zeros();
                let mut noise = 0.0;
                for i in 0..=k {
                    let c = binomial(k, i);
                    let (x, y) = (s[1][i], s[0][k - i + 1]);
                    t += x.cross(&y) * c;
                    noise += c * (b[1][i] * y.norm() + x.norm() * b[0][k - i + 1]);
                }
                if t.norm() > NOISE * noise && t.norm().is_finite() {
                    return Some(t.normalize() * sign.powi(k as i32));
                }
            }
        }
        None
    }

    /// The homogeneous control points `Q_j = sum_i N_i(t) P_ij` of the boundary curve at
    /// parameter `t` of the u (`along_u`) or v direction: a curve in the other direction.
    fn edge_points(&self, along_u: bool, t: f64) -> Vec<Vector4<f64>> {
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
    fn detect_edges(&self) -> ([bool; 4], [bool; 2]) {
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

    /// The homogeneous Bezier net of the knot-span cell `[u0, u1] x [v0, v1]` (spans `su`,
    /// `sv`), `net[a][b]` for `a <= degree_u`, `b <= degree_v`, by blossoming in each direction
    /// (see [`NurbsCurve::bezier_in_span`](crate::NurbsCurve::bezier_in_span)).
    fn bezier_net(
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
    /// (the corners of every sub-patch are candidates). A sub-patch is then
    /// - *reduced to an edge* if the Bernstein coefficients of `(S - p) . Su` (or `. Sv`) all
    ///   have one sign: the distance is then monotone in u (or v) on the whole sub-patch, so
    ///   its minimum lies on one edge, a rational Bezier curve, whose closest point
    ///   [`NurbsCurve::closest_point`] finds exactly. (These coefficients are those of
    ///   `B . (B_u w - B w_u)` with `B = A - p w`, which has the sign of `(S - p) . Su`; see
    ///   the [`closest`](crate::closest) module.) This also settles whole families of
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

    fn projection(&self, p: &Point3<f64>, c: Candidate) -> SurfaceProjection {
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
    fn polish(
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
    fn patch(&self, spans_u: &[Span], spans_v: &[Span], iu: usize, iv: usize) -> Patch {
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
    fn walking_newton(
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
    fn below_jumps(&self, cell: &Patch, mut c: Candidate) -> Candidate {
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
    fn global_search(
        &self,
        p: &Point3<f64>,
        spans_u: &[Span],
        spans_v: &[Span],
        mut best: Candidate,
    ) -> Candidate {
        let (deg_u, deg_v) = (self.degree_u, self.degree_v);
        let mut heap = BinaryHeap::new();
        let mut order = 0u64;
        let mut net = [[Vector4::zeros(); MAX_ORDER]; MAX_ORDER];
        for iu in 0..spans_u.len() {
            for iv in 0..spans_v.len() {
                self.bezier_net(spans_u[iu], spans_v[iv], &mut net);
                let flat: Vec<Vector4<f64>> = net
                    .iter()
                    .take(deg_u + 1)
                    .flat_map(|row| row.iter().take(deg_v + 1).copied())
                    .collect();
                let cell = self.patch(spans_u, spans_v, iu, iv);
                let sub = SubPatch {
                    lower_bound: net_box_distance(&flat, p),
                    order,
                    depth: 0,
                    cell: (iu, iv),
                    rect: (cell.u0, cell.u1, cell.v0, cell.v1),
                    net: flat,
                };
                self.offer_corners(p, &cell, &sub, &mut best);
                heap.push(sub);
                order += 1;
            }
        }
        // Distances closer than rounding cannot be told apart: a sub-patch whose lower bound is
        // within `slack` of the best distance cannot hold a meaningfully closer point.
        let (lo, hi) = self.bounding_box();
        let slack =
            16.0 * f64::EPSILON * lo.coords.amax().max(hi.coords.amax()).max(p.coords.amax());
        let mut budget = SUBPATCH_BUDGET;
        while let Some(sub) = heap.pop() {
            if sub.lower_bound >= best.distance - slack || sub.lower_bound.is_nan() {
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
                    let child = SubPatch {
                        lower_bound: net_box_distance(&quarter, p),
                        order,
                        depth: sub.depth + 1,
                        cell: sub.cell,
                        rect: (a, b, c, d),
                        net: quarter,
                    };
                    order += 1;
                    self.offer_corners(p, &cell, &child, &mut best);
                    if child.lower_bound < best.distance - slack {
                        heap.push(child);
                    }
                }
            }
        }
        best
    }

    /// The closest point on a leaf of the search: samples a small grid on the leaf's
    /// rectangle and runs Newton's method (confined to the rectangle) from the best sample and
    /// from the centre.
    fn leaf_minimum(&self, p: &Point3<f64>, leaf: &Patch) -> Option<Candidate> {
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
    fn offer_corners(&self, p: &Point3<f64>, cell: &Patch, sub: &SubPatch, best: &mut Candidate) {
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
    fn edge_minimum(
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
    fn newton(&self, p: &Point3<f64>, cell: &Patch, u: f64, v: f64) -> (Candidate, bool) {
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

/// `t` clamped to `[a, b]`, NaN mapped to `a`.
#[inline]
fn clamp(t: f64, (a, b): (f64, f64)) -> f64 {
    if t.is_nan() {
        a
    } else {
        t.clamp(a, b)
    }
}

/// The non-empty knot spans of the domain as `(span index, start, end)`.
fn spans(degree: usize, knots: &[f64], n: usize) -> Vec<(usize, f64, f64)> {
    (degree..n)
        .filter(|&i| knots[i] < knots[i + 1])
        .map(|i| (i, knots[i], knots[i + 1]))
        .collect()
}

/// Length of the first (or, with `last`, the last) non-empty knot span of the domain.
fn boundary_span_len(degree: usize, knots: &[f64], n: usize, last: bool) -> f64 {
    let mut it = (degree..n).filter(|&i| knots[i] < knots[i + 1]);
    let i = if last { it.next_back() } else { it.next() };
    i.map_or(1.0, |i| knots[i + 1] - knots[i])
}

/// Rational Bezier control points of the span `[t0, t1]` of a B-spline whose `degree + 1`
/// local homogeneous control points `local[..=degree]` are those of `span`, by blossoming (see
/// [`NurbsCurve::bezier_in_span`](crate::NurbsCurve::bezier_in_span)).
fn blossom_extract(
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
fn flat_net_turning(net: &[Vector4<f64>], p: usize, q: usize) -> (f64, f64) {
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
fn simple_net(net: &[Vector4<f64>], p: usize, q: usize) -> bool {
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
fn polygon_turning(points: impl Iterator<Item = Point3<f64>>) -> f64 {
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

/// Distance from `p` to the axis-aligned box of the projected control points of a net: a
/// lower bound on the distance to the patch (convex hull property).
fn net_box_distance(net: &[Vector4<f64>], p: &Point3<f64>) -> f64 {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for c in net {
        let x = project(c).coords;
        lo = lo.inf(&x);
        hi = hi.sup(&x);
    }
    (lo - p.coords)
        .sup(&(p.coords - hi))
        .sup(&Vector3::zeros())
        .norm()
}

/// Splits a flat `(p + 1) x (q + 1)` rational Bezier net at the middle of its u (`along_u`)
/// or v parameter range by de Casteljau's algorithm in homogeneous space.
fn split_net(
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
fn pascal(max: usize) -> Vec<Vec<f64>> {
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
fn stationarity_sign(
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
fn stationarity_sign_along(
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NurbsCurve;
    use std::f64::consts::{FRAC_1_SQRT_2, PI};

    const H: f64 = FRAC_1_SQRT_2;

    /// The 9-point rational quadratic unit circle in the xy plane, parameter in [0, 1].
    fn circle9() -> (Vec<f64>, Vec<(f64, f64)>, Vec<f64>) {
        let knots = vec![
            0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
        ];
        let pts = vec![
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (-1.0, 1.0),
            (-1.0, 0.0),
            (-1.0, -1.0),
            (0.0, -1.0),
            (1.0, -1.0),
            (1.0, 0.0),
        ];
        let w = vec![1.0, H, 1.0, H, 1.0, H, 1.0, H, 1.0];
        (knots, pts, w)
    }

    /// The half circle from (0, -1) through (1, 0) to (0, 1), as (rho, z), parameter [0, 1].
    fn half5() -> (Vec<f64>, Vec<(f64, f64)>, Vec<f64>) {
        let knots = vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
        let pts = vec![(0.0, -1.0), (1.0, -1.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        (knots, pts, vec![1.0, H, 1.0, H, 1.0])
    }

    const CENTRE: Vector3<f64> = Vector3::new(0.3, -0.2, 0.5);

    /// Sphere of radius `r` around CENTRE. With `meridian_u` the rows (u) run along the
    /// meridian (poles at u = 0, 1; normal inward); otherwise along the equator (poles at
    /// v = 0, 1; normal outward).
    fn sphere(r: f64, meridian_u: bool) -> NurbsSurface {
        let (kc, pc, wc) = circle9();
        let (km, pm, wm) = half5();
        let at = |m: usize, c: usize| {
            let (rho, z) = pm[m];
            let (x, y) = pc[c];
            (
                Point3::from(CENTRE + Vector3::new(rho * x, rho * y, z) * r),
                wm[m] * wc[c],
            )
        };
        let (ku, kv, nu, nv) = if meridian_u {
            (km, kc, pm.len(), pc.len())
        } else {
            (kc, km, pc.len(), pm.len())
        };
        let mut pts = vec![];
        let mut ws = vec![];
        for a in 0..nu {
            let (mut row, mut wrow) = (vec![], vec![]);
            for b in 0..nv {
                let (p, w) = if meridian_u { at(a, b) } else { at(b, a) };
                row.push(p);
                wrow.push(w);
            }
            pts.push(row);
            ws.push(wrow);
        }
        NurbsSurface::new(2, 2, ku, kv, pts, Some(ws))
    }

    /// Cylinder of radius `r` around the z axis, z in [0, height]: u around, v up.
    fn cylinder(r: f64, height: f64) -> NurbsSurface {
        let (kc, pc, wc) = circle9();
        let pts = pc
            .iter()
            .map(|&(x, y)| {
                vec![
                    Point3::new(r * x, r * y, 0.0),
                    Point3::new(r * x, r * y, height),
                ]
            })
            .collect();
        let ws = wc.iter().map(|&w| vec![w, w]).collect();
        NurbsSurface::new(2, 1, kc, vec![0.0, 0.0, 1.0, 1.0], pts, Some(ws))
    }

    /// Torus around the z axis: tube radius `r`, centre-circle radius `big`. u around the tube,
    /// v around the axis.
    fn torus(big: f64, r: f64) -> NurbsSurface {
        let (kc, pc, wc) = circle9();
        let mut pts = vec![];
        let mut ws = vec![];
        for a in 0..9 {
            let (cx, cz) = pc[a];
            let rho = big + r * cx;
            let z = r * cz;
            pts.push(
                (0..9)
                    .map(|b| Point3::new(rho * pc[b].0, rho * pc[b].1, z))
                    .collect(),
            );
            ws.push((0..9).map(|b| wc[a] * wc[b]).collect());
        }
        NurbsSurface::new(2, 2, kc.clone(), kc, pts, Some(ws))
    }

    /// Cone with apex (0, 0, height) at v = 0 and base circle of radius `r` at z = 0, v = 1.
    fn cone(r: f64, height: f64) -> NurbsSurface {
        let (kc, pc, wc) = circle9();
        let pts = pc
            .iter()
            .map(|&(x, y)| {
                vec![
                    Point3::new(0.0, 0.0, height),
                    Point3::new(r * x, r * y, 0.0),
                ]
            })
            .collect();
        let ws = wc.iter().map(|&w| vec![w, w]).collect();
        NurbsSurface::new(2, 1, kc, vec![0.0, 0.0, 1.0, 1.0], pts, Some(ws))
    }

    fn plane_grid(n_u: usize, n_v: usize) -> Vec<Vec<Point3<f64>>> {
        (0..n_u)
            .map(|a| {
                (0..n_v)
                    .map(|b| Point3::new(a as f64, b as f64, 0.0))
                    .collect()
            })
            .collect()
    }

    fn clamped(degree: usize, n: usize) -> Vec<f64> {
        let inner = n - degree;
        let mut k = vec![0.0; degree + 1];
        k.extend((1..inner).map(|i| i as f64 / inner as f64));
        k.extend(vec![1.0; degree + 1]);
        k
    }

    fn try_plane(
        grid: Vec<Vec<Point3<f64>>>,
        weights: Option<Vec<Vec<f64>>>,
    ) -> Result<NurbsSurface> {
        let (nu, nv) = (grid.len(), grid.first().map_or(0, Vec::len));
        NurbsSurface::try_new(2, 1, clamped(2, nu), clamped(1, nv.max(2)), grid, weights)
    }

    fn params(n: usize) -> impl Iterator<Item = f64> {
        (0..=n).map(move |i| i as f64 / n as f64)
    }

    #[test]
    fn validation_errors() {
        let ok = try_plane(plane_grid(4, 3), None);
        assert!(ok.is_ok(), "a valid plane: {ok:?}");
        let e = NurbsSurface::try_new(0, 1, vec![], clamped(1, 3), plane_grid(4, 3), None);
        assert_eq!(
            e,
            Err(NurbsError::DegreeZero { field: "degree_u" }),
            "degree_u 0"
        );
        let e = NurbsSurface::try_new(2, 30, clamped(2, 4), vec![], plane_grid(4, 3), None);
        assert!(
            matches!(
                e,
                Err(NurbsError::DegreeTooHigh {
                    field: "degree_v",
                    degree: 30,
                    ..
                })
            ),
            "degree_v too high: {e:?}"
        );
        let e = NurbsSurface::try_new(2, 3, clamped(2, 4), vec![0.0; 7], plane_grid(4, 3), None);
        assert_eq!(
            e,
            Err(NurbsError::TooFewPoints {
                field: "control_points",
                got: 3,
                degree: 3,
                needed: 4
            }),
            "too few points along v"
        );
        let e = NurbsSurface::try_new(2, 1, clamped(2, 4), vec![0.0, 1.0], plane_grid(4, 3), None);
        assert_eq!(
            e,
            Err(NurbsError::KnotCount {
                field: "knots_v",
                expected: 5,
                got: 2
            }),
            "knots_v count"
        );
        let e = NurbsSurface::try_new(
            2,
            1,
            vec![0.0, 0.0, 0.0, 0.7, 0.5, 1.0, 1.0],
            clamped(1, 3),
            plane_grid(4, 3),
            None,
        );
        assert!(
            matches!(
                e,
                Err(NurbsError::KnotsDecreasing {
                    field: "knots_u",
                    index: 4,
                    ..
                })
            ),
            "decreasing knots_u: {e:?}"
        );
        let mut grid = plane_grid(4, 3);
        grid[2].pop();
        assert_eq!(
            try_plane(grid, None),
            Err(NurbsError::RaggedGrid {
                field: "control_points",
                row: 2,
                got: 2,
                expected: 3
            }),
            "ragged control net"
        );
        let mut grid = plane_grid(4, 3);
        grid[1][2].y = f64::NAN;
        let e = try_plane(grid, None);
        assert!(
            matches!(&e, Err(NurbsError::PointNotFinite { field: "control_points", index, .. }) if index == "[1][2]"),
            "non-finite point: {e:?}"
        );
        let e = try_plane(plane_grid(4, 3), Some(vec![vec![1.0; 3]; 3]));
        assert_eq!(
            e,
            Err(NurbsError::WeightCount {
                field: "weights",
                expected: 12,
                got: 9
            }),
            "missing row of weights"
        );
        let e = try_plane(
            plane_grid(4, 3),
            Some(vec![vec![1.0; 3], vec![1.0; 4], vec![1.0; 2], vec![1.0; 3]]),
        );
        assert_eq!(
            e,
            Err(NurbsError::RaggedGrid {
                field: "weights",
                row: 1,
                got: 4,
                expected: 3
            }),
            "ragged weights"
        );
        for bad in [0.0, -1.0, f64::INFINITY] {
            let mut w = vec![vec![1.0; 3]; 4];
            w[3][1] = bad;
            let e = try_plane(plane_grid(4, 3), Some(w));
            assert!(
                matches!(&e, Err(NurbsError::BadWeight { field: "weights", index, value }) if index == "[3][1]" && (value == &bad)),
                "bad weight {bad}: {e:?}"
            );
        }
        let mut w = vec![vec![1.0; 3]; 4];
        w[0][0] = f64::NAN;
        let e = try_plane(plane_grid(4, 3), Some(w));
        assert!(
            matches!(&e, Err(NurbsError::BadWeight { index, .. }) if index == "[0][0]"),
            "NaN weight: {e:?}"
        );
        let e = NurbsSurface::try_new(1, 1, vec![0.0; 2], vec![0.0; 4], vec![], None);
        assert!(
            matches!(e, Err(NurbsError::TooFewPoints { got: 0, .. })),
            "empty control net: {e:?}"
        );
        let msg = std::panic::catch_unwind(|| {
            NurbsSurface::new(
                1,
                1,
                vec![0.0; 4],
                vec![0.0, 0.0, 1.0, 1.0],
                plane_grid(2, 2),
                None,
            )
        });
        assert!(msg.is_err(), "new panics on an empty domain");
    }

    #[test]
    fn accessors_round_trip() {
        let mut w = vec![vec![1.0; 3]; 4];
        w[2][1] = 3.0;
        let grid = plane_grid(4, 3);
        let s = try_plane(grid.clone(), Some(w.clone())).expect("valid");
        assert_eq!(s.net_size(), (4, 3), "net size");
        assert_eq!((s.degree_u(), s.degree_v()), (2, 1), "degrees");
        assert_eq!(s.knots_u(), &clamped(2, 4)[..], "knots_u");
        assert_eq!(s.knots_v(), &clamped(1, 3)[..], "knots_v");
        assert_eq!(s.weights(), w, "weights");
        assert_eq!(s.control_points(), grid, "control points");
        assert!(s.is_rational(), "one weight differs");
        assert_eq!(
            s.homogeneous_point(2, 1),
            Vector4::new(6.0, 3.0, 0.0, 3.0),
            "homogeneous"
        );
        assert_eq!(s.homogeneous_points().len(), 12, "flat net");
        assert_eq!(s.domain_u(), (0.0, 1.0), "domain u");
        assert_eq!(s.spans_u().len(), 2, "two spans along u");
        let (lo, hi) = s.bounding_box();
        assert_eq!(
            (lo, hi),
            (Point3::origin(), Point3::new(3.0, 2.0, 0.0)),
            "box"
        );
        assert_eq!(s.collapsed_edges(), [false; 4], "nothing collapsed");
    }

    #[test]
    fn closed_directions_and_collapsed_edges() {
        assert_eq!(
            cylinder(2.0, 1.0).closed_directions(),
            (true, false),
            "cylinder"
        );
        assert_eq!(torus(3.0, 1.0).closed_directions(), (true, true), "torus");
        assert_eq!(
            sphere(1.0, true).closed_directions(),
            (false, true),
            "sphere"
        );
        assert_eq!(cone(1.0, 2.0).closed_directions(), (true, false), "cone");
        let plane = try_plane(plane_grid(4, 3), None).expect("valid");
        assert_eq!(plane.closed_directions(), (false, false), "plane");
        assert_eq!(cylinder(2.0, 1.0).collapsed_edges(), [false; 4], "cylinder");
        assert_eq!(torus(3.0, 1.0).collapsed_edges(), [false; 4], "torus");
    }

    #[test]
    fn exact_surfaces_lie_on_their_quadrics() {
        let cyl = cylinder(2.5, 4.0);
        let sph = [sphere(1.7, true), sphere(1.7, false)];
        let tor = torus(3.0, 0.8);
        for u in params(97) {
            for v in params(89) {
                let p = cyl.point(u, v);
                assert!(
                    (p.x.hypot(p.y) / 2.5 - 1.0).abs() < 1e-12,
                    "cylinder at {u} {v}"
                );
                for s in &sph {
                    let d = (s.point(u, v).coords - CENTRE).norm();
                    assert!((d / 1.7 - 1.0).abs() < 1e-12, "sphere at {u} {v}: {d}");
                }
                let p = tor.point(u, v);
                let d = (p.x.hypot(p.y) - 3.0).hypot(p.z);
                assert!((d / 0.8 - 1.0).abs() < 1e-12, "torus at {u} {v}: {d}");
            }
        }
    }

    #[test]
    fn cylinder_and_torus_normals_are_analytic() {
        let cyl = cylinder(2.5, 4.0);
        let tor = torus(3.0, 0.8);
        for u in params(61) {
            for v in params(53) {
                let p = cyl.point(u, v);
                let n = cyl.normal(u, v).expect("regular");
                let radial = Vector3::new(p.x, p.y, 0.0) / 2.5;
                assert!(
                    (n - radial).norm() < 1e-12,
                    "cylinder normal at {u} {v}: {n}"
                );
                let p = tor.point(u, v);
                let rho = p.x.hypot(p.y);
                let c = Vector3::new(p.x / rho * 3.0, p.y / rho * 3.0, 0.0);
                let expected = (p.coords - c) / 0.8;
                let n = tor.normal(u, v).expect("regular");
                // u runs around the tube counter-clockwise in (rho, z), v around the axis:
                // Su x Sv points into the tube.
                assert!(
                    (n + expected).norm() < 1e-10,
                    "torus normal at {u} {v}: {n}"
                );
            }
        }
    }

    #[test]
    fn subnormal_weights_are_normalised_exactly() {
        let s = sphere(1.7, false);
        let tiny: Vec<Vec<f64>> = s
            .weights()
            .iter()
            .map(|r| r.iter().map(|w| w * 1e-318).collect())
            .collect();
        let t = NurbsSurface::try_new(
            2,
            2,
            s.knots_u().to_vec(),
            s.knots_v().to_vec(),
            s.control_points(),
            Some(tiny),
        )
        .expect("subnormal weights are normalised, not refused");
        assert!(
            t.weights().iter().flatten().all(|&w| w >= 2f64.powi(-970)),
            "normal weights"
        );
        for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.33)] {
            // The subnormal weights keep ~10 bits, so the surface is not exactly the sphere,
            // but it is the surface the data defines, evaluated at full precision: close.
            let d = (t.point(u, v) - s.point(u, v)).norm();
            assert!(d < 1e-2, "point at ({u}, {v}) off by {d}");
        }
    }

    #[test]
    fn sphere_normals_everywhere_including_poles() {
        for meridian_u in [true, false] {
            let s = sphere(1.7, meridian_u);
            // With the meridian along u, Su x Sv points inward; along v, outward.
            let sign = if meridian_u { -1.0 } else { 1.0 };
            let expect = |u: f64, v: f64| (s.point(u, v).coords - CENTRE) / 1.7 * sign;
            let collapsed = if meridian_u {
                [true, true, false, false]
            } else {
                [false, false, true, true]
            };
            assert_eq!(s.collapsed_edges(), collapsed, "poles detected");
            let mut ts: Vec<f64> = params(40).collect();
            for e in [
                1e-15, 1e-13, 1e-11, 1e-9, 1e-8, 1e-7, 3e-6, 1e-5, 2e-5, 1e-4, 1e-3,
            ] {
                ts.push(e);
                ts.push(1.0 - e);
            }
            for &a in &ts {
                for b in params(36) {
                    let (u, v) = if meridian_u { (a, b) } else { (b, a) };
                    let n = s.normal(u, v).expect("the sphere has a normal everywhere");
                    let e = expect(u, v);
                    assert!(
                        (n - e).norm() < 1e-9,
                        "sphere normal at {u} {v}: {n} vs {e}"
                    );
                    assert!((n.norm() - 1.0).abs() < 1e-14, "unit normal");
                }
            }
            // At the poles exactly the normal is the axis direction.
            for b in params(17) {
                let (south, north) = if meridian_u {
                    (s.normal(0.0, b), s.normal(1.0, b))
                } else {
                    (s.normal(b, 0.0), s.normal(b, 1.0))
                };
                let south = south.expect("pole");
                let north = north.expect("pole");
                assert!(
                    (south - Vector3::new(0.0, 0.0, -sign)).norm() < 1e-14,
                    "south pole normal {south}"
                );
                assert!(
                    (north - Vector3::new(0.0, 0.0, sign)).norm() < 1e-14,
                    "north pole normal {north}"
                );
            }
        }
    }

    #[test]
    fn cone_apex_normal_is_the_limit_along_the_ruling() {
        let (r, h) = (1.5, 2.0);
        let c = cone(r, h);
        assert_eq!(
            c.collapsed_edges(),
            [false, false, true, false],
            "apex at v = 0"
        );
        let len = r.hypot(h);
        for u in params(50) {
            let base = c.point(u, 1.0);
            let (ct, st) = (base.x / r, base.y / r);
            // Su x Sv points into the cone (see the derivation in the test's comment).
            let expected = -Vector3::new(h * ct, h * st, r) / len;
            for v in [0.0, 1e-14, 1e-9, 1e-6, 0.3, 1.0] {
                let n = c.normal(u, v).expect("cone normal");
                assert!(
                    (n - expected).norm() < 1e-10,
                    "cone normal at {u} {v}: {n} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn degenerate_without_collapsed_edge_uses_taylor_limit() {
        // A bilinear-like patch whose corner has Su = 0 (two coincident corner control points
        // along u) but no collapsed edge: the limit along u is still well defined.
        let pts = vec![
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
                Point3::new(0.0, 2.0, 0.0),
            ],
            vec![
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(1.0, 2.0, 0.0),
            ],
            vec![
                Point3::new(2.0, 0.0, 0.0),
                Point3::new(2.0, 1.0, 0.0),
                Point3::new(2.0, 2.0, 0.0),
            ],
        ];
        let s = NurbsSurface::new(2, 2, clamped(2, 3), clamped(2, 3), pts, None);
        assert_eq!(s.collapsed_edges(), [false; 4], "no collapsed edge");
        let (_, su, _) = s.eval_d1(0.0, 0.0);
        assert!(su.norm() < 1e-15, "Su vanishes at the corner");
        let n = s.normal(0.0, 0.0).expect("limit exists");
        assert!(
            (n - Vector3::z()).norm() < 1e-14,
            "planar patch: normal +z, got {n}"
        );
        // A surface collapsed to a single point has no normal.
        let dot = NurbsSurface::new(
            1,
            1,
            clamped(1, 2),
            clamped(1, 2),
            vec![vec![Point3::origin(); 2]; 2],
            None,
        );
        assert_eq!(dot.normal(0.5, 0.5), None, "a point has no normal");
    }

    #[test]
    fn pure_derivatives_match_isocurves() {
        // Independent truth: the isocurves as NURBS curves (whose derivatives are the curve
        // module's), built from the homogeneous net combined with the basis of the other
        // direction.
        let s = torus(3.0, 0.8);
        let (nu, nv) = s.net_size();
        for u in params(23) {
            for v in params(19) {
                let d = s.derivatives(u, v);
                // v-isocurve at fixed u: control points sum_a N_a(u) P_ab.
                let span = knots::find_span(2, s.knots_u(), nu, u);
                let mut n = [0.0; MAX_ORDER];
                basis_funs(span, u, 2, s.knots_u(), &mut n);
                let cpw: Vec<Vector4<f64>> = (0..nv)
                    .map(|b| {
                        (0..=2)
                            .map(|i| s.homogeneous_point(span - 2 + i, b) * n[i])
                            .sum()
                    })
                    .collect();
                let iso = NurbsCurve::from_homogeneous_unchecked(2, s.knots_v().to_vec(), cpw);
                let c = iso.derivatives(v, 2);
                for k in 0..3 {
                    let err = (c[k] - d[0][k]).norm();
                    assert!(
                        err < 1e-11 * (1.0 + c[k].norm()),
                        "d^{k}/dv^{k} at {u} {v}: {err}"
                    );
                }
                let span = knots::find_span(2, s.knots_v(), nv, v);
                basis_funs(span, v, 2, s.knots_v(), &mut n);
                let cpw: Vec<Vector4<f64>> = (0..nu)
                    .map(|a| {
                        (0..=2)
                            .map(|j| s.homogeneous_point(a, span - 2 + j) * n[j])
                            .sum()
                    })
                    .collect();
                let iso = NurbsCurve::from_homogeneous_unchecked(2, s.knots_u().to_vec(), cpw);
                let c = iso.derivatives(u, 2);
                for k in 0..3 {
                    let err = (c[k] - d[k][0]).norm();
                    assert!(
                        err < 1e-11 * (1.0 + c[k].norm()),
                        "d^{k}/du^{k} at {u} {v}: {err}"
                    );
                }
                let (p, su, sv) = s.eval_d1(u, v);
                assert_eq!((p.coords, su, sv), (d[0][0], d[1][0], d[0][1]), "eval_d1");
                assert!((s.point(u, v).coords - d[0][0]).norm() < 1e-14, "point");
            }
        }
    }

    #[test]
    fn sphere_closest_points_are_analytic() {
        let r = 1.7;
        for meridian_u in [true, false] {
            let s = sphere(r, meridian_u);
            let mut seed = 12345u64;
            let mut rnd = || {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (seed >> 11) as f64 / (1u64 << 53) as f64
            };
            for i in 0..200 {
                let dir = Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
                let t = [0.05, 0.9, 1.69, 1.71, 2.5, 40.0][i % 6] * r / 1.7;
                let p = Point3::from(CENTRE + dir * t);
                let q = s.closest_point(&p, None);
                assert!(
                    (q.distance - (t - r).abs()).abs() < 1e-12,
                    "distance from {p}: {q:?}"
                );
                let expected = CENTRE + dir * r;
                assert!(
                    (q.point.coords - expected).norm() < 1e-7,
                    "closest point from {p}: {q:?} off by {}",
                    (q.point.coords - expected).norm()
                );
                let warm = s.closest_point(&p, Some((q.u + 0.01, q.v - 0.01)));
                assert!(
                    (warm.distance - q.distance).abs() < 1e-12,
                    "warm = cold: {warm:?} {q:?}"
                );
            }
            // The poles and the centre.
            for z in [-1.0, 1.0] {
                let p = Point3::from(CENTRE + Vector3::new(0.0, 0.0, 3.0 * z));
                let q = s.closest_point(&p, None);
                assert!(
                    (q.distance - (3.0 - r)).abs() < 1e-12,
                    "above a pole: {q:?}"
                );
            }
            let q = s.closest_point(&Point3::from(CENTRE), None);
            assert!((q.distance - r).abs() < 1e-12, "from the centre: {q:?}");
        }
    }

    #[test]
    fn cylinder_closest_points_including_boundary_minima() {
        let (r, h) = (2.5, 4.0);
        let s = cylinder(r, h);
        for i in 0..72 {
            let a = i as f64 * PI / 36.0 + 0.01;
            for (rho, z) in [
                (0.3, 2.0),
                (2.4, 0.5),
                (3.0, 3.9),
                (7.0, 1.0),
                (3.0, 5.0),
                (1.0, -2.0),
                (0.0, 6.0),
            ] {
                let p = Point3::new(rho * a.cos(), rho * a.sin(), z);
                let q = s.closest_point(&p, None);
                let dz = if z > h {
                    z - h
                } else if z < 0.0 {
                    -z
                } else {
                    0.0
                };
                let expected = (rho - r).hypot(dz);
                assert!(
                    (q.distance - expected).abs() < 1e-12,
                    "from ({rho}, {a}, {z}): {q:?} vs {expected}"
                );
                let warm = s.closest_point(&p, Some((q.u, q.v)));
                assert!(
                    (warm.distance - q.distance).abs() < 1e-13,
                    "warm start at the answer"
                );
                assert!(
                    (warm.u - q.u).abs() < 1e-9 && (warm.v - q.v).abs() < 1e-9 || rho == 0.0,
                    "same parameters"
                );
            }
        }
    }

    #[test]
    fn plane_boundary_and_corner_minima() {
        // Degree (3, 2) plane z = 0 over [0, 3] x [0, 2], non-uniform knots.
        let grid: Vec<Vec<Point3<f64>>> = (0..5)
            .map(|a| {
                (0..4)
                    .map(|b| Point3::new(a as f64 * 0.75, b as f64 * 2.0 / 3.0, 0.0))
                    .collect()
            })
            .collect();
        let s = NurbsSurface::new(
            3,
            2,
            vec![0.0, 0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0, 1.0],
            vec![0.0, 0.0, 0.0, 0.6, 1.0, 1.0, 1.0],
            grid,
            None,
        );
        let cases = [
            (Point3::new(1.0, 1.0, 2.0), 2.0),
            (Point3::new(4.0, 1.0, 1.0), 2f64.sqrt()),
            (Point3::new(-1.0, 1.5, -1.0), 2f64.sqrt()),
            (Point3::new(1.2, -2.0, 0.0), 2.0),
            (Point3::new(4.0, 3.0, 1.0), 3f64.sqrt()),
            (Point3::new(-2.0, -2.0, 0.0), 8f64.sqrt()),
        ];
        for (p, expected) in cases {
            let q = s.closest_point(&p, None);
            assert!((q.distance - expected).abs() < 1e-12, "from {p}: {q:?}");
            let w = s.closest_point(&p, Some((0.5, 0.5)));
            assert!(
                (w.distance - expected).abs() < 1e-12,
                "warm from {p}: {w:?}"
            );
        }
    }

    #[test]
    fn warm_start_tracks_a_point_around_the_torus() {
        // A tool point circling the torus on a wobbly helix: every warm-started query (from the
        // previous answer) agrees with the cold one.
        let (big, r) = (3.0, 0.8);
        let s = torus(big, r);
        let mut prev = None;
        for i in 0..400 {
            let t = i as f64 / 400.0 * 2.0 * PI;
            let (rho, z) = (
                big + 1.2 * (7.0 * t).cos(),
                1.2 * (7.0 * t).sin() + 0.1 * t.cos(),
            );
            let p = Point3::new(rho * t.cos(), rho * t.sin(), z);
            let warm = s.closest_point(&p, prev);
            let cold = s.closest_point(&p, None);
            assert!(
                (warm.distance - cold.distance).abs() < 1e-12,
                "step {i}: warm {warm:?} cold {cold:?}"
            );
            let expected = ((rho - big).hypot(z) - r).abs();
            assert!(
                (warm.distance - expected).abs() < 1e-12,
                "step {i}: analytic"
            );
            prev = Some((warm.u, warm.v));
        }
    }

    #[test]
    fn torus_closest_points() {
        let (big, r) = (3.0, 0.8);
        let s = torus(big, r);
        for i in 0..50 {
            let a = i as f64 * 0.37;
            for (rho, z) in [
                (0.0, 0.0),
                (0.5, 0.3),
                (2.9, 0.1),
                (3.5, -0.5),
                (6.0, 2.0),
                (3.0, 0.0),
            ] {
                let p = Point3::new(rho * a.cos(), rho * a.sin(), z);
                let q = s.closest_point(&p, None);
                let expected = ((rho - big).hypot(z) - r).abs();
                assert!(
                    (q.distance - expected).abs() < 1e-12,
                    "torus from {p}: {q:?} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn jump_between_cells_uses_the_limit_from_inside() {
        // Degree 1 along u with a knot of multiplicity 2 at u = 1: two separate patches.
        let row = |x: f64, z: f64| vec![Point3::new(x, 0.0, z), Point3::new(x, 1.0, z)];
        let s = NurbsSurface::new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0],
            vec![0.0, 0.0, 1.0, 1.0],
            vec![row(0.0, 0.0), row(1.0, 0.0), row(3.0, 5.0), row(4.0, 5.0)],
            None,
        );
        let p = Point3::new(1.2, 0.5, 0.0);
        for warm in [None, Some((0.5, 0.5))] {
            let q = s.closest_point(&p, warm);
            assert!((q.distance - 0.2).abs() < 1e-12, "limit from inside: {q:?}");
            assert_eq!(q.u, float_before(1.0), "represented below the knot");
            assert_eq!(q.point, s.point(q.u, q.v), "point is S(u, v)");
        }
        // Beyond the jump the second patch wins.
        let q = s.closest_point(&Point3::new(2.5, 0.5, 5.0), None);
        assert!((q.distance - 0.5).abs() < 1e-12, "second patch: {q:?}");
        assert_eq!(q.u, 1.0, "its first edge is at the knot");
    }

    #[test]
    fn nan_query_does_not_panic() {
        let s = sphere(1.0, true);
        let q = s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0), None);
        assert!(q.distance.is_nan(), "NaN in, NaN out: {q:?}");
        let q = s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0), Some((0.5, 0.5)));
        assert!(q.distance.is_nan(), "NaN in, NaN out (warm): {q:?}");
        let p = s.point(f64::NAN, 2.0);
        assert_eq!(
            p,
            s.point(0.0, 1.0),
            "NaN and out-of-domain parameters are clamped"
        );
    }
}
