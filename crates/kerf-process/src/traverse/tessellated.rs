//! A NURBS surface's tessellation and the proven boxes of its pieces: the fast lower bound
//! and the exact distance of one surface.

use nalgebra::Point3;
use parry3d_f64::query::{PointQuery, PointQueryWithLocation};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use kerf_nurbs::{distance_to_box, NurbsSurface};

/// A NURBS surface with a triangle mesh through points of it: the mesh finds, fast, which
/// surfaces are far (its distance less the estimated deviation `sag`) and where on the surface
/// the nearest point lies (the start of the exact closest-point search).
#[derive(Debug)]
pub(super) struct Tessellated {
    surface: NurbsSurface,
    mesh: Option<TriMesh>,
    /// `(u, v)` of each mesh vertex.
    uv: Vec<(f64, f64)>,
    /// Twice the largest distance found between the surface (cell centres and edge
    /// middles) and the mesh, plus a small floor: an estimate of the deviation, mm (it only
    /// chooses between the warm-started and the global closest point, never skips a query).
    sag: f64,
    /// The proven boxes of the surface's pieces, by strips of cells along u: each strip's
    /// box and its cells' boxes. A piece (the surface over one cell) lies in the convex hull
    /// of the control points of its rational Bezier form (positive weights), so in their box;
    /// the distance to the nearest box is a lower bound of the distance to the surface.
    strips: Vec<Strip>,
}

/// A strip of cells along v at one u interval, with its box and its cells' boxes.
#[derive(Debug)]
struct Strip {
    lo: Point3<f64>,
    hi: Point3<f64>,
    cells: Vec<(Point3<f64>, Point3<f64>)>,
}

/// The proven boxes of `surface` over the cells `cu` x `cv` (each `(span, start, end)`
/// inside one knot span): the rational Bezier form of the surface on a cell is taken row by
/// row along u (each row of the homogeneous net a curve in u), then column by column along v
/// (tensor-product blossoming commutes); its control points' box contains the piece.
fn cell_boxes(
    surface: &NurbsSurface,
    cu: &[(usize, f64, f64)],
    cv: &[(usize, f64, f64)],
) -> Vec<Strip> {
    let (n_u, n_v) = surface.net_size();
    let (p, q) = (surface.degree_u(), surface.degree_v());
    let cpw = surface.homogeneous_points();
    let rows: Vec<kerf_nurbs::NurbsCurve> = (0..n_v)
        .map(|b| {
            kerf_nurbs::NurbsCurve::from_homogeneous_unchecked(
                p,
                surface.knots_u().to_vec(),
                (0..n_u).map(|a| cpw[a * n_v + b]).collect(),
            )
        })
        .collect();
    let mut strips = Vec::with_capacity(cu.len());
    let mut out = vec![nalgebra::Vector4::zeros(); p.max(q) + 1];
    for &(su, u0, u1) in cu {
        // Q[a][b]: the u-Bezier points of row b on this u interval.
        let mut cols: Vec<Vec<nalgebra::Vector4<f64>>> = vec![Vec::with_capacity(n_v); p + 1];
        for row in &rows {
            row.bezier_in_span_into(su, u0, u1, &mut out);
            for (a, col) in cols.iter_mut().enumerate() {
                col.push(out[a]);
            }
        }
        let cols: Vec<kerf_nurbs::NurbsCurve> = cols
            .into_iter()
            .map(|c| {
                kerf_nurbs::NurbsCurve::from_homogeneous_unchecked(q, surface.knots_v().to_vec(), c)
            })
            .collect();
        let mut cells = Vec::with_capacity(cv.len());
        let mut slo = Point3::from([f64::INFINITY; 3]);
        let mut shi = Point3::from([f64::NEG_INFINITY; 3]);
        for &(sv, v0, v1) in cv {
            let mut lo = Point3::from([f64::INFINITY; 3]);
            let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
            for col in &cols {
                col.bezier_in_span_into(sv, v0, v1, &mut out);
                for h in &out[..=q] {
                    let x = Point3::new(h.x / h.w, h.y / h.w, h.z / h.w);
                    lo = lo.inf(&x);
                    hi = hi.sup(&x);
                }
            }
            slo = slo.inf(&lo);
            shi = shi.sup(&hi);
            cells.push((lo, hi));
        }
        strips.push(Strip {
            lo: slo,
            hi: shi,
            cells,
        });
    }
    strips
}

/// Most strips [`Tessellated::piece_bound`] orders nearest first (beyond, the strips in order).
const NEAREST_STRIPS: usize = 64;

/// Cells per knot span in each direction of a tessellation (at least 12 over the domain).
const CELLS_PER_SPAN: usize = 6;

impl Tessellated {
    /// The surface itself.
    pub(super) fn surface(&self) -> &NurbsSurface {
        &self.surface
    }

    pub(super) fn new(surface: NurbsSurface) -> Self {
        // The grid's values and its cells, each cell inside one knot span.
        let grid = |spans: Vec<(usize, f64, f64)>| {
            let per = CELLS_PER_SPAN.max(12usize.div_ceil(spans.len().max(1)));
            let mut g = Vec::new();
            let mut cells = Vec::new();
            for (k, &(span, a, b)) in spans.iter().enumerate() {
                for j in 0..per {
                    g.push(a + (b - a) * j as f64 / per as f64);
                    let end = if j + 1 == per {
                        b
                    } else {
                        a + (b - a) * (j + 1) as f64 / per as f64
                    };
                    cells.push((span, g[g.len() - 1], end));
                }
                if k + 1 == spans.len() {
                    g.push(b);
                }
            }
            (g, cells)
        };
        let (us, cu) = grid(surface.spans_u());
        let (vs, cv) = grid(surface.spans_v());
        let strips = cell_boxes(&surface, &cu, &cv);
        let (nu, nv) = (us.len(), vs.len());
        let mut vertices = Vec::with_capacity(nu * nv);
        let mut uv = Vec::with_capacity(nu * nv);
        for &u in &us {
            for &v in &vs {
                vertices.push(surface.point(u, v));
                uv.push((u, v));
            }
        }
        let mut triangles = Vec::new();
        for i in 0..nu.saturating_sub(1) {
            for j in 0..nv.saturating_sub(1) {
                let a = (i * nv + j) as u32;
                let b = a + 1;
                let c = a + nv as u32;
                let d = c + 1;
                triangles.push([a, c, b]);
                triangles.push([b, c, d]);
            }
        }
        let finite = vertices
            .iter()
            .all(|p| p.coords.iter().all(|x| x.is_finite()));
        let mesh = if finite && !triangles.is_empty() {
            TriMesh::with_flags(vertices, triangles, TriMeshFlags::empty()).ok()
        } else {
            None
        };
        let mut sag = 0.0_f64;
        if let Some(m) = &mesh {
            for i in 0..nu - 1 {
                for j in 0..nv - 1 {
                    let (u0, u1, v0, v1) = (us[i], us[i + 1], vs[j], vs[j + 1]);
                    for (u, v) in [
                        (0.5 * (u0 + u1), 0.5 * (v0 + v1)),
                        (0.5 * (u0 + u1), v0),
                        (u0, 0.5 * (v0 + v1)),
                        (0.25 * (3.0 * u0 + u1), 0.25 * (3.0 * v0 + v1)),
                        (0.25 * (u0 + 3.0 * u1), 0.25 * (v0 + 3.0 * v1)),
                    ] {
                        let q = surface.point(u, v);
                        sag = sag.max(m.distance_to_local_point(&q, false));
                    }
                }
            }
        }
        let sag = 2.0 * sag + 1e-6 * surface.size() + 1e-9;
        Self {
            surface,
            mesh,
            uv,
            sag,
            strips,
        }
    }

    /// A proven lower bound of the distance from `p` to the surface: the distance to the
    /// nearest of its pieces' boxes (a strip is passed over when its own box is farther than
    /// the best cell so far, or than `enough`, past which the exact value does not matter).
    fn lower_bound(&self, p: &Point3<f64>, enough: f64) -> f64 {
        let mut best = f64::INFINITY;
        for s in &self.strips {
            let d = distance_to_box(p, &s.lo, &s.hi);
            if d >= best || d >= enough {
                best = best.min(d);
                continue;
            }
            for (lo, hi) in &s.cells {
                best = best.min(distance_to_box(p, lo, hi));
            }
        }
        best
    }

    /// The exact distance from `p` where it may be below `limit`; else a value `>= limit`
    /// that is a proven lower bound of it (the distance to the nearest piece's box).
    pub(super) fn distance(&self, p: &Point3<f64>, limit: f64) -> f64 {
        let floor = self.piece_bound(p, limit);
        if floor >= limit {
            return floor;
        }
        self.exact(p)
    }

    /// [`Tessellated::lower_bound`], bit for bit: the distance to the nearest piece's box
    /// where that is below `enough`, else the value `>= enough` that `lower_bound` gives.
    ///
    /// The nearest strip first, then the others in order, each passed over where its box is
    /// at least the best cell so far or `enough` away: a cell is at least as far as its strip's
    /// box (which holds it, coordinate by coordinate, so also in floating point), so the least
    /// cell below `enough`, if there is one, is found, and that is what `lower_bound` returns
    /// then. Otherwise `lower_bound` itself gives its value (a bound whose exact value depends
    /// on its order).
    pub(super) fn piece_bound(&self, p: &Point3<f64>, enough: f64) -> f64 {
        let n = self.strips.len();
        if n > NEAREST_STRIPS {
            return self.lower_bound(p, enough);
        }
        let mut ds = [0.0_f64; NEAREST_STRIPS];
        let mut first = 0;
        for (k, s) in self.strips.iter().enumerate() {
            ds[k] = distance_to_box(p, &s.lo, &s.hi);
            if ds[k] < ds[first] {
                first = k;
            }
        }
        let cells = |k: usize, best: f64| {
            self.strips[k]
                .cells
                .iter()
                .fold(best, |b, (lo, hi)| b.min(distance_to_box(p, lo, hi)))
        };
        let mut best = f64::INFINITY;
        if n > 0 && ds[first] < enough {
            best = cells(first, best);
            for k in (0..n).filter(|&k| k != first) {
                if ds[k] < best.min(enough) {
                    best = cells(k, best);
                }
            }
        }
        if best < enough {
            best
        } else {
            self.lower_bound(p, enough)
        }
    }

    /// The exact distance from `p` (the closest point, warm-started from the tessellation).
    pub(super) fn exact(&self, p: &Point3<f64>) -> f64 {
        let Some(m) = &self.mesh else {
            return self.surface.closest_point(p, None).distance;
        };
        let (proj, (tri, _)) = m.project_local_point_and_get_location(p, false);
        let dm = (proj.point - p).norm();
        let corner = m.indices()[tri as usize][0] as usize;
        let warm = self
            .surface
            .closest_point(p, Some(self.uv[corner]))
            .distance;
        if warm <= dm + self.sag {
            warm
        } else {
            // The local search found a farther point than the mesh promises: the global one.
            self.surface.closest_point(p, None).distance
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// The proven lower bound never exceeds the exact distance (a sphere and a cylinder,
    /// distances known in closed form), and the far skip returns it only above the limit.
    #[test]
    fn the_piece_boxes_bound_the_exact_distance_from_below() {
        let c = Point3::new(10.0, -5.0, 3.0);
        let sphere = NurbsSurface::sphere(c, 40.0).unwrap();
        let cyl =
            NurbsSurface::cylinder(Point3::new(0.0, 0.0, 0.0), Vector3::z(), 25.0, 60.0).unwrap();
        let exact_sphere = |p: &Point3<f64>| ((p - c).norm() - 40.0).abs();
        let exact_cyl = |p: &Point3<f64>| {
            let r = (p.x * p.x + p.y * p.y).sqrt();
            let dz = if p.z < 0.0 {
                -p.z
            } else if p.z > 60.0 {
                p.z - 60.0
            } else {
                0.0
            };
            if dz == 0.0 {
                (r - 25.0).abs()
            } else {
                ((r - 25.0).powi(2) + dz * dz).sqrt()
            }
        };
        let ts = Tessellated::new(sphere);
        let tc = Tessellated::new(cyl);
        let mut worst_gap = 0.0_f64;
        let mut k = 0u32;
        for i in 0..12 {
            for j in 0..12 {
                for r in [0.0, 5.0, 20.0, 39.0, 41.0, 45.0, 60.0, 120.0] {
                    let (th, ph) = (0.52 * f64::from(i), 0.26 * f64::from(j) - 1.5);
                    let dir = Vector3::new(ph.cos() * th.cos(), ph.cos() * th.sin(), ph.sin());
                    let p = c + dir * r;
                    for enough in [1.0, 5.0, 12.5, 45.0, f64::INFINITY] {
                        for (t, x) in [
                            (&ts, &p),
                            (&tc, &Point3::new(p.x - 10.0, p.y + 5.0, p.z + 27.0)),
                        ] {
                            let (fast, scan) = (t.piece_bound(x, enough), t.lower_bound(x, enough));
                            assert_eq!(fast.to_bits(), scan.to_bits(), "{x} {enough}");
                        }
                    }
                    let lb = ts.lower_bound(&p, f64::INFINITY);
                    assert!(lb <= exact_sphere(&p) + 1e-9, "sphere at {p}: {lb}");
                    worst_gap = worst_gap.max(exact_sphere(&p) - lb);
                    let q = Point3::new(p.x - 10.0, p.y + 5.0, p.z + 27.0);
                    let lb = tc.lower_bound(&q, f64::INFINITY);
                    assert!(lb <= exact_cyl(&q) + 1e-9, "cylinder at {q}: {lb}");
                    // The skip: at or above the limit only if the exact distance is too.
                    for limit in [1.0, 5.0, 12.5] {
                        let d = tc.distance(&q, limit);
                        if d >= limit {
                            assert!(exact_cyl(&q) >= limit - 1e-9, "{q}: {d} {limit}");
                        } else {
                            assert!((d - exact_cyl(&q)).abs() < 1e-6, "{q}: {d}");
                        }
                    }
                    k += 1;
                }
            }
        }
        assert_eq!(k, 12 * 12 * 8);
        // Tight enough to skip: within a piece's size (the sphere's 1/12-domain cells).
        assert!(worst_gap < 20.0, "{worst_gap}");
    }
}
