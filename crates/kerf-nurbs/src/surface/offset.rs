//! The offset of a NURBS surface, `O = S + d n` (`n` the unit normal along `Su x Sv`), as a
//! NURBS surface with a proven bound on its distance from the exact offset and on the angle
//! between their normals (docs/step.md, "Offsets of free-form surfaces").
//!
//! The offset of a free-form surface is not rational, so it is approximated: on each cell of a
//! grid over the domain (the knot spans, bisected where needed) the approximation is
//! `A = (P + E) / W`, where `P / W` is the surface's own rational Bezier patch (degree raised to
//! at least 3) and `E` the polynomial of that degree that interpolates `W d n` at the cell's
//! uniform grid of `(p + 1) (q + 1)` points. Neighbouring cells interpolate the same values on
//! their shared edge, so `A` is continuous; written with every cell edge a knot of full
//! multiplicity it is one NURBS surface with `S`'s weights.
//!
//! **The certificate.** With `M = W (P_u x P_v) - W_v (P_u x P) - W_u (P x P_v)` (the normal's
//! polynomial direction: `S_u x S_v = M / W^3`), the error `A - O = E / W - d M / |M|` splits
//! into a part along `n`, `E . M / (W |M|) - d`, and a part across it, `|E x M| / (W |M|)`.
//! Both are ratios of polynomials: `(E . M)^2 / (W^2 |M|^2)` and `|E x M|^2 / (W^2 |M|^2)`,
//! of one degree, whose values lie between the least and the largest ratio of their Bernstein
//! coefficients wherever the denominator's coefficients are positive ([`Poly::ratio_range`]).
//! With `E . M` of `d`'s sign throughout (its coefficients), the cell's bound is
//! `sqrt(T + max((|d| - sqrt(R_lo))^2, (sqrt(R_hi) - |d|)^2))` (`T` the largest tangential
//! ratio, `[R_lo, R_hi]` the normal ones). The angle between `A`'s normal and `n` follows the
//! same way from `|M_A x M|^2 / (|M_A|^2 |M|^2)` with `M_A . M > 0`. A cell whose bound is
//! above the tolerance has its row and column of the grid bisected; the work is counted in
//! cells certified, each weighed by its degree, against a budget.

use std::collections::HashMap;

use nalgebra::{Point3, Vector4};

use super::poly::{add3, cross, dot, scale3, Poly, Poly3};
use super::NurbsSurface;
use crate::MAX_ORDER;

/// How closely to approximate an offset, and the work allowed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SurfaceOffsetOptions {
    /// The largest distance, mm, the approximation may keep from the exact offset.
    pub tolerance_mm: f64,
    /// The most work before giving up, in cells of a bicubic polynomial surface: a cell of
    /// higher degree counts as several ([`OffsetSurface::work`]).
    pub max_work: usize,
}

impl SurfaceOffsetOptions {
    /// A tolerance of `tolerance_mm` and a budget of 20,000 bicubic cells (seconds: 0.37 ms a
    /// cell when measured, docs/performance.md).
    pub fn new(tolerance_mm: f64) -> Self {
        Self {
            tolerance_mm,
            max_work: 20_000,
        }
    }

    /// Sets [`max_work`](Self::max_work): the most work, in bicubic polynomial cells, before
    /// the offset stops with [`SurfaceOffsetError::Budget`].
    pub fn with_max_work(mut self, max_work: usize) -> Self {
        self.max_work = max_work;
        self
    }
}

/// An offset surface: the approximation and what is proven about it.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct OffsetSurface {
    /// The approximation, over the basis surface's domain and parameters (a point at `(u, v)`
    /// approximates `S(u, v) + d n(u, v)`).
    pub surface: NurbsSurface,
    /// A proven bound, mm, of `|A(u, v) - S(u, v) - d n(u, v)|` over the domain (with an
    /// allowance for rounding); 0 for a plane patch or `d = 0`, up to that allowance.
    pub position_bound_mm: f64,
    /// A proven bound, rad, of the angle between `A`'s normal and `n` at every `(u, v)` (the
    /// exact offset's normal at `S + d n` is `n`).
    pub normal_bound_rad: f64,
    /// The cells of the result (`A`'s Bezier patches).
    pub cells: usize,
    /// The cells certified on the way.
    pub cells_certified: usize,
    /// The work spent, at most the budget: the cells certified times each one's cost in cells
    /// of a bicubic polynomial surface, `ceil(((t + 1) / 21)^4)` with `t` the certificate's
    /// highest degree (`8p - 4` for a polynomial surface, `12p - 4` for a rational one, `p` the
    /// degree raised to at least 3; a product of two polynomials of degree `t / 2` costs about
    /// `(t / 2 + 1)^4`).
    pub work: usize,
}

/// Why an offset was not built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceOffsetError {
    /// The certificate's polynomials grow with the degree: refused above a cap.
    #[error("the offset of a surface of degree ({degree_u}, {degree_v}) is not built (at most {MAX_OFFSET_DEGREE} for a polynomial surface, {MAX_OFFSET_DEGREE_RATIONAL} for a rational one)")]
    Degree {
        /// Degree along u.
        degree_u: usize,
        /// Degree along v.
        degree_v: usize,
    },
    /// The distance or the tolerance is not a finite number (the tolerance must be > 0).
    #[error("offset distance {distance_mm} mm and tolerance {tolerance_mm} mm must be finite (the tolerance > 0)")]
    Arguments {
        /// The distance.
        distance_mm: f64,
        /// The tolerance.
        tolerance_mm: f64,
    },
    /// The exact offset turns inside out: at a point of the grid its normal
    /// `(S_u + d n_u) x (S_v + d n_v)` points against the surface's (`1 - 2 H d + K d^2 < 0`).
    /// No approximation fixes it.
    #[error("the offset by {distance_mm} mm near (u, v) = ({u}, {v}): {}", FOLDS)]
    Folds {
        /// The distance.
        distance_mm: f64,
        /// The middle of the cell where it was seen.
        u: f64,
        /// The middle of the cell where it was seen.
        v: f64,
        /// The work spent ([`OffsetSurface::work`]).
        work: usize,
    },
    /// The surface's normal vanishes (a collapsed edge, a cusp): the offset has no direction
    /// there.
    #[error("the surface's normal vanishes in the cell about (u, v) = ({u}, {v}) (a collapsed edge or a cusp): no offset direction there")]
    NormalVanishes {
        /// The middle of the cell where it was seen.
        u: f64,
        /// The middle of the cell where it was seen.
        v: f64,
        /// The work spent ([`OffsetSurface::work`]).
        work: usize,
    },
    /// The surface has a crease (its normal jumps across a cell edge): the offsets of the two
    /// sides part there by `gap_mm`, and no continuous surface approximates them.
    #[error("the offset by {distance_mm} mm tears apart by {gap_mm:.3e} mm at a crease of the surface near (u, v) = ({u}, {v})")]
    Crease {
        /// The distance.
        distance_mm: f64,
        /// How far apart the two sides' offsets are on the edge.
        gap_mm: f64,
        /// The middle of a cell beside the crease.
        u: f64,
        /// The middle of a cell beside the crease.
        v: f64,
        /// The work spent ([`OffsetSurface::work`]).
        work: usize,
    },
    /// The offset was not certified: the work budget ran out, the failing cells are too narrow
    /// to halve, or the result is not a valid surface (`why` says which).
    #[error("the offset by {distance_mm} mm is not certified within {tolerance_mm} mm after {cells} cells ({work} bicubic cells of work): {why} near (u, v) = ({u}, {v})")]
    Budget {
        /// The distance.
        distance_mm: f64,
        /// The tolerance.
        tolerance_mm: f64,
        /// The cells certified.
        cells: usize,
        /// The work spent ([`OffsetSurface::work`]).
        work: usize,
        /// What the last cell that failed showed.
        why: String,
        /// The middle of that cell.
        u: f64,
        /// The middle of that cell.
        v: f64,
    },
}

impl SurfaceOffsetError {
    /// The work spent before the error ([`OffsetSurface::work`]; 0 where none was done), for a
    /// caller that charges it to a budget of its own.
    pub fn work(&self) -> usize {
        match self {
            Self::Degree { .. } | Self::Arguments { .. } => 0,
            Self::Folds { work, .. }
            | Self::NormalVanishes { work, .. }
            | Self::Crease { work, .. }
            | Self::Budget { work, .. } => *work,
        }
    }
}

/// The highest degree (in either direction) of a polynomial surface whose offset is built.
pub const MAX_OFFSET_DEGREE: usize = 7;
/// The highest degree of a rational surface whose offset is built.
pub const MAX_OFFSET_DEGREE_RATIONAL: usize = 5;

/// A cell's polynomials, translated to its first corner.
struct CellPolys {
    /// `P`, the homogeneous coordinates less `W` times the corner.
    p: Poly3,
    /// `W`; `None` for a polynomial surface (then `w0`).
    w: Option<Poly>,
    w0: f64,
    /// The normal direction `M`.
    m: Poly3,
    corner: Point3<f64>,
    /// The raised degrees.
    deg: (usize, usize),
    /// The exact offset turns inside out at one of the cell's grid points.
    folds: bool,
}

/// One certified (or refused) cell.
struct Cell {
    /// The position and normal bounds, or why there are none.
    bound: Result<(f64, f64), Unproven>,
    /// `A`'s homogeneous net, row-major over u, degree `deg`.
    net: Vec<Vector4<f64>>,
}

/// Why a cell has no bound.
enum Unproven {
    /// Smaller cells may prove it.
    Refine(String),
    /// No cell will: the exact offset turns inside out at one of the cell's grid points.
    Folds,
    /// No cell will: the surface's normal vanishes at one of the cell's grid points (to
    /// double precision: a collapsed edge, a cusp).
    Vanishes,
}

/// The reason given for an offset that turns inside out.
const FOLDS: &str = "the offset turns inside out (the distance is beyond a radius of curvature on its side: it folds over)";

impl NurbsSurface {
    /// The surface offset by `distance_mm` along its unit normal `Su x Sv / |Su x Sv|`,
    /// approximated within `options.tolerance_mm` with the bound proven.
    ///
    /// The domain is cut into cells (the knot spans, bisected by rows and columns until every
    /// cell is proven); on each, the surface's own rational Bezier patch `P / W` plus a
    /// polynomial `E` that interpolates `W d n` on a uniform grid, so the result is continuous
    /// with the surface's weights and every cell edge a knot of full multiplicity. The distance
    /// to the exact offset and the angle between the normals are proven from Bernstein
    /// coefficient ratios of polynomial quotients (docs/step.md, "Offsets of free-form
    /// surfaces", has the derivation).
    ///
    /// ```
    /// use kerf_nurbs::{NurbsSurface, SurfaceOffsetOptions};
    /// use nalgebra::{Point3, Vector3};
    ///
    /// // A cylinder of radius 20 (rational), offset outward by 2.
    /// let c = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), 20.0, 10.0)?;
    /// let o = c.offset(2.0, &SurfaceOffsetOptions::new(1e-4)).expect("certified");
    /// assert!(o.position_bound_mm <= 1e-4, "the bound reached");
    /// let p = o.surface.point(0.3, 0.5);
    /// assert!((p.x.hypot(p.y) - 22.0).abs() <= o.position_bound_mm, "on the radius-22 cylinder");
    /// # Ok::<(), kerf_nurbs::NurbsError>(())
    /// ```
    ///
    /// # Errors
    /// [`SurfaceOffsetError::Degree`] above the degree caps, [`SurfaceOffsetError::Arguments`]
    /// for a non-finite distance or tolerance, [`SurfaceOffsetError::NormalVanishes`] at a
    /// collapsed edge, [`SurfaceOffsetError::Folds`] where the offset turns inside out (the
    /// distance beyond a radius of curvature on its side, or exactly at one),
    /// [`SurfaceOffsetError::Crease`] where the surface's normal jumps across a cell edge (the
    /// offset tears), [`SurfaceOffsetError::Budget`] where the budget runs out (a tolerance too
    /// fine, a normal nearly vanishing) or no finer grid can be made.
    pub fn offset(
        &self,
        distance_mm: f64,
        options: &SurfaceOffsetOptions,
    ) -> Result<OffsetSurface, SurfaceOffsetError> {
        let (p, q) = (self.degree_u, self.degree_v);
        let cap = if self.rational {
            MAX_OFFSET_DEGREE_RATIONAL
        } else {
            MAX_OFFSET_DEGREE
        };
        if p.max(q) > cap {
            return Err(SurfaceOffsetError::Degree {
                degree_u: p,
                degree_v: q,
            });
        }
        let tol = options.tolerance_mm;
        if !(distance_mm.is_finite() && tol > 0.0 && tol.is_finite()) {
            return Err(SurfaceOffsetError::Arguments {
                distance_mm,
                tolerance_mm: tol,
            });
        }
        let breaks = |spans: &[(usize, f64, f64)]| {
            let mut b = vec![spans[0].1];
            b.extend(spans.iter().map(|s| s.2));
            b
        };
        let (spans_u, spans_v) = (self.spans_u(), self.spans_v());
        let (mut us, mut vs) = (breaks(&spans_u), breaks(&spans_v));
        let mut cells: HashMap<[u64; 4], Cell> = HashMap::new();
        let mut certified = 0usize;
        let cost = cell_cost(p.max(3).max(q.max(3)), self.rational);
        // The same for every cell: the interpolation's matrices and the surface's size.
        let fit = Fit {
            iu: collocation_inverse(p.max(3)),
            iv: collocation_inverse(q.max(3)),
            size: self.size(),
        };
        let key = |u0: f64, u1: f64, v0: f64, v1: f64| {
            [u0.to_bits(), u1.to_bits(), v0.to_bits(), v1.to_bits()]
        };
        loop {
            let mut bad_u = vec![false; us.len() - 1];
            let mut bad_v = vec![false; vs.len() - 1];
            let mut failed: Option<(String, f64, f64)> = None;
            for i in 0..us.len() - 1 {
                for j in 0..vs.len() - 1 {
                    let (u0, u1, v0, v1) = (us[i], us[i + 1], vs[j], vs[j + 1]);
                    let k = key(u0, u1, v0, v1);
                    if let std::collections::hash_map::Entry::Vacant(slot) = cells.entry(k) {
                        if (certified + 1).saturating_mul(cost) > options.max_work {
                            let (why, u, v) = failed.map_or_else(
                                || {
                                    (
                                        "the work budget ran out with cells left to certify".into(),
                                        0.5 * (u0 + u1),
                                        0.5 * (v0 + v1),
                                    )
                                },
                                |(why, u, v)| {
                                    (
                                        format!("the work budget ran out (last failure: {why})"),
                                        u,
                                        v,
                                    )
                                },
                            );
                            return Err(SurfaceOffsetError::Budget {
                                distance_mm,
                                tolerance_mm: tol,
                                cells: certified,
                                work: certified * cost,
                                why,
                                u,
                                v,
                            });
                        }
                        certified += 1;
                        let cp =
                            self.cell_polys((u0, u1), (v0, v1), &spans_u, &spans_v, distance_mm);
                        slot.insert(offset_cell(&cp, distance_mm, &fit));
                    }
                    let cell = &cells[&k];
                    let why = match &cell.bound {
                        Ok((b, _)) if *b <= tol => continue,
                        Ok((b, _)) => format!("the bound there is {b:.3e} mm"),
                        Err(Unproven::Refine(why)) => why.clone(),
                        Err(Unproven::Folds) => {
                            return Err(SurfaceOffsetError::Folds {
                                distance_mm,
                                u: 0.5 * (u0 + u1),
                                v: 0.5 * (v0 + v1),
                                work: certified * cost,
                            })
                        }
                        Err(Unproven::Vanishes) => {
                            return Err(SurfaceOffsetError::NormalVanishes {
                                u: 0.5 * (u0 + u1),
                                v: 0.5 * (v0 + v1),
                                work: certified * cost,
                            })
                        }
                    };
                    bad_u[i] = true;
                    bad_v[j] = true;
                    failed = Some((why, 0.5 * (u0 + u1), 0.5 * (v0 + v1)));
                }
            }
            let Some((why, u, v)) = failed else {
                break;
            };
            let (nu, nv) = (bisect(&us, &bad_u), bisect(&vs, &bad_v));
            if nu.len() == us.len() && nv.len() == vs.len() {
                // The failing cells are too narrow to halve in floating point: no finer grid
                // exists, and the cached cells would be tried again for ever.
                return Err(SurfaceOffsetError::Budget {
                    distance_mm,
                    tolerance_mm: tol,
                    cells: certified,
                    work: certified * cost,
                    why: format!("{why}, in cells too narrow to halve"),
                    u,
                    v,
                });
            }
            (us, vs) = (nu, nv);
        }
        // Assemble the cells as one Bezier-form B-spline surface.
        let (pe, qe) = (p.max(3), q.max(3));
        let (ncu, ncv) = (us.len() - 1, vs.len() - 1);
        let (nu, nv) = (ncu * pe + 1, ncv * qe + 1);
        let mut net: Vec<Vector4<f64>> = vec![Vector4::zeros(); nu * nv];
        let mut written = vec![false; nu * nv];
        // The largest difference between two cells' points on their shared edge, and where.
        let mut seam: (f64, f64, f64) = (0.0, us[0], vs[0]);
        let mut position: f64 = 0.0;
        let mut normal: f64 = 0.0;
        for i in 0..ncu {
            for j in 0..ncv {
                let (u0, u1, v0, v1) = (us[i], us[i + 1], vs[j], vs[j + 1]);
                let cell = &cells[&key(u0, u1, v0, v1)];
                // Every cell of the final grid was certified (the loop ends only then).
                let (b, theta) = cell
                    .bound
                    .as_ref()
                    .map_or((f64::INFINITY, f64::INFINITY), |b| *b);
                position = position.max(b);
                normal = normal.max(theta);
                for a in 0..=pe {
                    for b in 0..=qe {
                        let k = (i * pe + a) * nv + j * qe + b;
                        let h = cell.net[a * (qe + 1) + b];
                        if written[k] {
                            let gap = (net[k].xyz() / net[k].w - h.xyz() / h.w).norm();
                            if gap > seam.0 {
                                seam = (gap, 0.5 * (u0 + u1), 0.5 * (v0 + v1));
                            }
                        }
                        net[k] = h;
                        written[k] = true;
                    }
                }
            }
        }
        // Neighbours interpolate the same values on their shared edge where the normal is
        // continuous: their edge points then agree to rounding, and the later cell's replace
        // the earlier's. Where the surface has a crease the offset tears apart there, and no
        // continuous surface approximates it.
        let seam_allowance = 1e-9 * (distance_mm.abs() + 1.0) + 1e-12 * self.size();
        if seam.0 > seam_allowance {
            return Err(SurfaceOffsetError::Crease {
                distance_mm,
                gap_mm: seam.0,
                u: seam.1,
                v: seam.2,
                work: certified * cost,
            });
        }
        if seam.0 > 0.0 {
            // Some cells' edge rows were replaced (by rounding-level amounts): both bounds are
            // taken again from the nets as written, so that they hold for the surface itself.
            position = 0.0;
            normal = 0.0;
            for i in 0..ncu {
                for j in 0..ncv {
                    let cp = self.cell_polys(
                        (us[i], us[i + 1]),
                        (vs[j], vs[j + 1]),
                        &spans_u,
                        &spans_v,
                        distance_mm,
                    );
                    let cell_net: Vec<Vector4<f64>> = (0..=pe)
                        .flat_map(|a| (0..=qe).map(move |b| (a, b)))
                        .map(|(a, b)| net[(i * pe + a) * nv + j * qe + b])
                        .collect();
                    let (b, theta) = written_bounds(&cp, &cell_net, distance_mm, fit.size)
                        .map_err(|why| SurfaceOffsetError::Budget {
                            distance_mm,
                            tolerance_mm: tol,
                            cells: certified,
                            work: certified * cost,
                            why,
                            u: 0.5 * (us[i] + us[i + 1]),
                            v: 0.5 * (vs[j] + vs[j + 1]),
                        })?;
                    position = position.max(b);
                    normal = normal.max(theta);
                }
            }
        }
        let knots = |b: &[f64], deg: usize| {
            let mut k = vec![b[0]; deg + 1];
            for x in &b[1..b.len() - 1] {
                k.extend(std::iter::repeat_n(*x, deg));
            }
            k.extend(std::iter::repeat_n(b[b.len() - 1], deg + 1));
            k
        };
        let points: Vec<Vec<Point3<f64>>> = (0..nu)
            .map(|a| {
                (0..nv)
                    .map(|b| {
                        let h = net[a * nv + b];
                        Point3::from(h.xyz() / h.w)
                    })
                    .collect()
            })
            .collect();
        let weights = self.rational.then(|| {
            (0..nu)
                .map(|a| (0..nv).map(|b| net[a * nv + b].w).collect())
                .collect()
        });
        let surface =
            NurbsSurface::try_new(pe, qe, knots(&us, pe), knots(&vs, qe), points, weights)
                .map_err(|e| SurfaceOffsetError::Budget {
                    distance_mm,
                    tolerance_mm: tol,
                    cells: certified,
                    work: certified * cost,
                    why: format!("the approximation is not a valid surface: {e}"),
                    u: us[0],
                    v: vs[0],
                })?;
        Ok(OffsetSurface {
            surface,
            position_bound_mm: position,
            normal_bound_rad: normal,
            cells: ncu * ncv,
            cells_certified: certified,
            work: certified * cost,
        })
    }

    /// The polynomials of the cell `[u0, u1] x [v0, v1]` (inside one knot span each way), and
    /// whether the exact offset by `distance_mm` turns inside out at one of its grid points.
    fn cell_polys(
        &self,
        (u0, u1): (f64, f64),
        (v0, v1): (f64, f64),
        spans_u: &[(usize, f64, f64)],
        spans_v: &[(usize, f64, f64)],
        distance_mm: f64,
    ) -> CellPolys {
        let span = |spans: &[(usize, f64, f64)], a: f64, b: f64| {
            let mid = 0.5 * (a + b);
            let s = spans
                .iter()
                .find(|s| s.1 <= mid && mid <= s.2)
                .unwrap_or(&spans[0]);
            (s.0, a, b)
        };
        let (p, q) = (self.degree_u, self.degree_v);
        let mut raw = [[Vector4::zeros(); MAX_ORDER]; MAX_ORDER];
        self.bezier_net(span(spans_u, u0, u1), span(spans_v, v0, v1), &mut raw);
        let h0 = raw[0][0];
        let corner = Point3::from(h0.xyz() / h0.w);
        let (pe, qe) = (p.max(3), q.max(3));
        let comp = |f: &dyn Fn(&Vector4<f64>) -> f64| {
            let mut c = Vec::with_capacity((p + 1) * (q + 1));
            for row in raw.iter().take(p + 1) {
                c.extend(row.iter().take(q + 1).map(f));
            }
            Poly::new(p, q, c).elevate(pe, qe)
        };
        let pp: Poly3 = [
            comp(&|h| h.x - corner.x * h.w),
            comp(&|h| h.y - corner.y * h.w),
            comp(&|h| h.z - corner.z * h.w),
        ];
        let w = self.rational.then(|| comp(&|h| h.w));
        let m = normal_direction(&pp, w.as_ref());
        let folds = (0..=pe).any(|a| {
            (0..=qe).any(|b| {
                let u = u0 + (u1 - u0) * a as f64 / pe as f64;
                let v = v0 + (v1 - v0) * b as f64 / qe as f64;
                self.offset_turns(u, v, distance_mm)
            })
        });
        CellPolys {
            p: pp,
            w,
            w0: h0.w,
            m,
            corner,
            deg: (pe, qe),
            folds,
        }
    }

    /// Whether the exact offset by `d` turns inside out at `(u, v)`: its normal
    /// `(S_u + d n_u) x (S_v + d n_v)` points against `n` (`n_u = P(m_u) / |m|`, `m = S_u x S_v`,
    /// `P` the projection across `n`). False where the surface's normal nearly vanishes (there
    /// the test means nothing; the cell refuses on its own).
    fn offset_turns(&self, u: f64, v: f64, d: f64) -> bool {
        let s = self.derivatives(u, v);
        let (su, sv) = (s[1][0], s[0][1]);
        let m = su.cross(&sv);
        let len = m.norm();
        // Against the larger derivative (at a collapsed edge the other is rounding noise).
        if len.is_nan() || len <= 1e-9 * su.norm_squared().max(sv.norm_squared()) {
            return false;
        }
        let n = m / len;
        let across = |x: nalgebra::Vector3<f64>| (x - n * n.dot(&x)) / len;
        let nu = across(s[2][0].cross(&sv) + su.cross(&s[1][1]));
        let nv = across(s[1][1].cross(&sv) + su.cross(&s[0][2]));
        // At or below 0 (to rounding): inside out, or degenerate on a focal line where the
        // distance equals a radius of curvature (no cell would certify it).
        (su + nu * d).cross(&(sv + nv * d)).dot(&n) <= 1e-9 * len
    }
}

/// A cell's cost in cells of a bicubic polynomial surface ([`OffsetSurface::work`]), for the
/// raised degree `p` (the larger of the two).
fn cell_cost(p: usize, rational: bool) -> usize {
    let top = if rational { 12 * p - 4 } else { 8 * p - 4 };
    (((top + 1) as f64 / 21.0).powi(4)).ceil() as usize
}

/// The grid bisected at the intervals marked.
fn bisect(b: &[f64], bad: &[bool]) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * b.len());
    for (i, w) in b.windows(2).enumerate() {
        out.push(w[0]);
        let mid = 0.5 * (w[0] + w[1]);
        if bad[i] && w[0] < mid && mid < w[1] {
            out.push(mid);
        }
    }
    out.push(b[b.len() - 1]);
    out
}

/// `W` as a polynomial (the constant `w0` where the surface is polynomial).
fn weight(cp: &CellPolys) -> Poly {
    cp.w.clone().unwrap_or_else(|| Poly::new(0, 0, vec![cp.w0]))
}

/// `E` interpolating `W d n` on the cell's uniform grid, `A`'s net and the position bound.
/// What every cell's fit shares: the inverses of the collocation matrices along u and v, and
/// the surface's size (for the rounding allowance).
struct Fit {
    iu: Vec<f64>,
    iv: Vec<f64>,
    size: f64,
}

fn offset_cell(cp: &CellPolys, d: f64, fit: &Fit) -> Cell {
    let (pe, qe) = cp.deg;
    if cp.folds {
        return Cell {
            bound: Err(Unproven::Folds),
            net: Vec::new(),
        };
    }
    let w = weight(cp);
    // The values W d n at the grid points.
    let mut f = [
        vec![0.0; (pe + 1) * (qe + 1)],
        vec![0.0; (pe + 1) * (qe + 1)],
        vec![0.0; (pe + 1) * (qe + 1)],
    ];
    let scale = coefficient_scale(&cp.m);
    for a in 0..=pe {
        for b in 0..=qe {
            let (u, v) = (a as f64 / pe as f64, b as f64 / qe as f64);
            let m = value3(&cp.m, u, v);
            let len = m.norm();
            // NaN fails `is_finite`.
            if !len.is_finite() || len <= 1e-9 * scale {
                return Cell {
                    bound: Err(Unproven::Vanishes),
                    net: Vec::new(),
                };
            }
            let k = w.eval(u, v) * d / len;
            for c in 0..3 {
                f[c][a * (qe + 1) + b] = k * m[c];
            }
        }
    }
    let e: Poly3 =
        [0, 1, 2].map(|c| Poly::new(pe, qe, interpolate(&f[c], &fit.iu, &fit.iv, pe, qe)));
    // A's net: P + E over W, moved back from the corner.
    let wn = w.elevate(pe, qe);
    let net: Vec<Vector4<f64>> = (0..(pe + 1) * (qe + 1))
        .map(|k| {
            let wk = wn.coefficients()[k];
            Vector4::new(
                cp.p[0].coefficients()[k] + e[0].coefficients()[k] + cp.corner.x * wk,
                cp.p[1].coefficients()[k] + e[1].coefficients()[k] + cp.corner.y * wk,
                cp.p[2].coefficients()[k] + e[2].coefficients()[k] + cp.corner.z * wk,
                wk,
            )
        })
        .collect();
    let bound = match position_bound(cp, &e, &w, d, fit.size) {
        Err(why) => Err(Unproven::Refine(why)),
        Ok(b) => normal_angle(cp, &net).map(|theta| (b, theta)),
    };
    Cell { bound, net }
}

/// Both bounds of a cell from its net as written (`A`'s homogeneous points, row-major over
/// u): `E` is the net less the surface's own, translated alike.
fn written_bounds(
    cp: &CellPolys,
    net: &[Vector4<f64>],
    d: f64,
    size: f64,
) -> Result<(f64, f64), String> {
    let (pe, qe) = cp.deg;
    let w = weight(cp);
    let e: Poly3 = [0, 1, 2].map(|c| {
        Poly::new(
            pe,
            qe,
            net.iter()
                .zip(cp.p[c].coefficients())
                .map(|(h, p)| h[c] - cp.corner[c] * h.w - p)
                .collect(),
        )
    });
    let b = position_bound(cp, &e, &w, d, size)?;
    let theta = normal_angle(cp, net).map_err(|u| match u {
        Unproven::Refine(why) => why,
        Unproven::Folds | Unproven::Vanishes => "the offset turns inside out".to_string(),
    })?;
    Ok((b, theta))
}

/// The proven bound of `|E / W - d n|` on the cell (the module's derivation).
fn position_bound(cp: &CellPolys, e: &Poly3, w: &Poly, d: f64, size: f64) -> Result<f64, String> {
    let mm = dot(&cp.m, &cp.m);
    let den = w.mul(w).mul(&mm);
    let along = dot(e, &cp.m);
    if d != 0.0 {
        let signed = Poly::new(
            along.degree().0,
            along.degree().1,
            along
                .coefficients()
                .iter()
                .map(|x| x * d.signum())
                .collect(),
        );
        // A NaN coefficient makes the least one NaN, refused too.
        if !positive(signed.min_coefficient()) {
            return Err(
                "the approximation is not proven to stay on the offset's side of the surface"
                    .into(),
            );
        }
    }
    let (r_lo, r_hi) = along
        .mul(&along)
        .ratio_range(&den)
        .ok_or("the surface's normal vanishes")?;
    let across = cross(e, &cp.m);
    let (_, t_hi) = dot(&across, &across)
        .ratio_range(&den)
        .ok_or("the surface's normal vanishes")?;
    let ad = d.abs();
    let normal = (ad - r_lo.max(0.0).sqrt()).max(r_hi.max(0.0).sqrt() - ad);
    // Rounding: the coefficients are computed in floating point from coordinates translated
    // to the cell's corner.
    let allowance = 1e-9 * ad + 1e-12 * size;
    Ok((t_hi.max(0.0) + normal * normal).sqrt() + allowance)
}

/// The proven bound of the angle between the normals of `A` (its net) and of the surface.
fn normal_angle(cp: &CellPolys, net: &[Vector4<f64>]) -> Result<f64, Unproven> {
    let (pe, qe) = cp.deg;
    // A's P (translated to the same corner).
    let pa: Poly3 = [0, 1, 2].map(|c| {
        Poly::new(
            pe,
            qe,
            net.iter().map(|h| h[c] - cp.corner[c] * h.w).collect(),
        )
    });
    let ma = normal_direction(&pa, cp.w.as_ref());
    if !positive(dot(&ma, &cp.m).min_coefficient()) {
        // Not proven here; the exact offset does not turn at the grid points (checked before),
        // so a finer cell may prove it.
        return Err(Unproven::Refine(
            "the approximation's normal is not proven on the offset's side".into(),
        ));
    }
    let x = cross(&ma, &cp.m);
    let den = dot(&ma, &ma).mul(&dot(&cp.m, &cp.m));
    let (_, s2) = dot(&x, &x)
        .ratio_range(&den)
        .ok_or_else(|| Unproven::Refine("the surface's normal vanishes".into()))?;
    // Rounding of the cross product's coefficients, relative.
    Ok(s2.clamp(0.0, 1.0).sqrt().asin() + 1e-12)
}

/// `x > 0` (false for NaN).
fn positive(x: f64) -> bool {
    x > 0.0
}

/// The largest coefficient of the three polynomials, in absolute value: their scale.
fn coefficient_scale(m: &Poly3) -> f64 {
    m.iter()
        .flat_map(|p| p.coefficients().iter())
        .fold(0.0, |a: f64, x| a.max(x.abs()))
}

/// The value of three polynomials at `(u, v)`.
fn value3(m: &Poly3, u: f64, v: f64) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(m[0].eval(u, v), m[1].eval(u, v), m[2].eval(u, v))
}

/// The polynomial direction `M` of the normal of `P / W`: `W (P_u x P_v) - W_v (P_u x P) -
/// W_u (P x P_v)` (`(P / W)_u x (P / W)_v = M / W^3`); `P_u x P_v` where `W` is constant.
fn normal_direction(p: &Poly3, w: Option<&Poly>) -> Poly3 {
    let (pu, pv) = (
        [p[0].du(), p[1].du(), p[2].du()],
        [p[0].dv(), p[1].dv(), p[2].dv()],
    );
    let uv = cross(&pu, &pv);
    match w {
        Some(w) => add3(
            &add3(&scale3(w, &uv), &scale3(&w.dv(), &cross(&pu, p)), -1.0),
            &scale3(&w.du(), &cross(p, &pv)),
            -1.0,
        ),
        None => uv,
    }
}

/// The inverse of the collocation matrix `B_k^n(i / n)` (rows `i`, columns `k`), by
/// Gauss-Jordan elimination with partial pivoting (well conditioned for the degrees taken).
fn collocation_inverse(n: usize) -> Vec<f64> {
    let k = n + 1;
    let mut a = vec![0.0; k * k];
    for i in 0..k {
        let t = i as f64 / n as f64;
        for j in 0..k {
            a[i * k + j] =
                crate::basis::binomial(n, j) * t.powi(j as i32) * (1.0 - t).powi((n - j) as i32);
        }
    }
    let mut inv = vec![0.0; k * k];
    for i in 0..k {
        inv[i * k + i] = 1.0;
    }
    for col in 0..k {
        let piv = (col..k)
            .max_by(|&x, &y| a[x * k + col].abs().total_cmp(&a[y * k + col].abs()))
            .unwrap_or(col);
        for j in 0..k {
            a.swap(col * k + j, piv * k + j);
            inv.swap(col * k + j, piv * k + j);
        }
        let d = a[col * k + col];
        for j in 0..k {
            a[col * k + j] /= d;
            inv[col * k + j] /= d;
        }
        for r in 0..k {
            if r != col {
                let f = a[r * k + col];
                if f != 0.0 {
                    for j in 0..k {
                        a[r * k + j] -= f * a[col * k + j];
                        inv[r * k + j] -= f * inv[col * k + j];
                    }
                }
            }
        }
    }
    inv
}

/// Coefficients `X = Iu F Iv^T` of the tensor polynomial through the grid values `F`.
fn interpolate(f: &[f64], iu: &[f64], iv: &[f64], pe: usize, qe: usize) -> Vec<f64> {
    let (ku, kv) = (pe + 1, qe + 1);
    // Along v first: G[a][l] = sum_b F[a][b] Iv[l][b].
    let mut g = vec![0.0; ku * kv];
    for a in 0..ku {
        for l in 0..kv {
            g[a * kv + l] = (0..kv).map(|b| f[a * kv + b] * iv[l * kv + b]).sum();
        }
    }
    let mut x = vec![0.0; ku * kv];
    for k in 0..ku {
        for l in 0..kv {
            x[k * kv + l] = (0..ku).map(|a| iu[k * ku + a] * g[a * kv + l]).sum();
        }
    }
    x
}
