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

use nalgebra::{Point3, Vector4};

use crate::curve::project;
use crate::error::{NurbsError, Result};
use crate::knots;

mod closest;
mod eval;
mod net;
mod normal;
mod offset;
mod poly;

pub use offset::{
    OffsetSurface, SurfaceOffsetError, SurfaceOffsetOptions, MAX_OFFSET_DEGREE,
    MAX_OFFSET_DEGREE_RATIONAL,
};

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
    /// The cells' Bezier nets, for the closest-point search.
    cells: net::NetCache,
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
            cells: net::NetCache::default(),
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
