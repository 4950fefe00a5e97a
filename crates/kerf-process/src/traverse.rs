//! Traverses between cuts that clear the part: retract along the tool axis, travel at a
//! clearance the part's surfaces cannot reach, approach along the next tool axis, checked
//! against the surfaces (NURBS through the global closest point, meshes through parry3d).
//!
//! The check rests on one fact: the distance `d(x)` from a point to a set of surfaces is
//! 1-Lipschitz, `|d(x) - d(y)| <= |x - y|`. So if samples spaced at most `h` apart along a
//! segment all have `d >= c + h / 2`, every point of the segment has `d >= c`. The distances
//! come from exact queries (the NURBS closest point's global search, parry's triangle
//! projection), so the claim is as good as those queries; surfaces whose bounding box (of
//! the control points for a NURBS surface, which contains it) is farther than the threshold
//! are not queried. The derivation and the routes are in `docs/process.md`.

use nalgebra::{Point3, Vector3};
use parry3d_f64::query::{PointQuery, PointQueryWithLocation};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use kerf_nurbs::NurbsSurface;

use crate::geometry::{normal, position};
use crate::{PoseArray, ProcessError, Result};

/// One surface of the part, placed in the workpiece frame.
#[derive(Debug)]
enum Obstacle {
    Nurbs(Box<Tessellated>),
    Mesh(Box<TriMesh>),
}

/// A NURBS surface with a triangle mesh through points of it: the mesh finds, fast, which
/// surfaces are far (its distance less the estimated deviation `sag`) and where on the surface
/// the nearest point lies (the start of the exact closest-point search).
#[derive(Debug)]
struct Tessellated {
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

/// Cells per knot span in each direction of a tessellation (at least 12 over the domain).
const CELLS_PER_SPAN: usize = 6;

impl Tessellated {
    fn new(surface: NurbsSurface) -> Self {
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
            let d = box_distance(p, &s.lo, &s.hi);
            if d >= best || d >= enough {
                best = best.min(d);
                continue;
            }
            for (lo, hi) in &s.cells {
                best = best.min(box_distance(p, lo, hi));
            }
        }
        best
    }

    /// The exact distance from `p` where it may be below `limit`; else a value `>= limit`
    /// that is a proven lower bound of it (the distance to the nearest piece's box).
    fn distance(&self, p: &Point3<f64>, limit: f64) -> f64 {
        let floor = self.lower_bound(p, limit);
        if floor >= limit {
            return floor;
        }
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

/// One surface with its bounding box and its name.
#[derive(Debug)]
struct Item {
    shape: std::sync::Arc<Obstacle>,
    lo: Point3<f64>,
    hi: Point3<f64>,
    id: String,
}

/// The part's surfaces in the workpiece frame, for distance queries.
#[derive(Debug, Default)]
pub struct Obstacles {
    items: Vec<Item>,
    /// How many exact distance queries have been made (the work the checks cost).
    queries: std::sync::atomic::AtomicUsize,
}

impl Obstacles {
    /// No surfaces (every traverse is clear).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a NURBS surface (already placed in the workpiece frame).
    pub fn add_nurbs(&mut self, surface: NurbsSurface) {
        let id = format!("#{}", self.items.len());
        self.add_nurbs_named(surface, id);
    }

    fn add_nurbs_named(&mut self, surface: NurbsSurface, id: String) {
        let (lo, hi) = surface.bounding_box();
        self.items.push(Item {
            shape: std::sync::Arc::new(Obstacle::Nurbs(Box::new(Tessellated::new(surface)))),
            lo,
            hi,
            id,
        });
    }

    /// The same surfaces without those named in `ids` (shared, not copied).
    pub fn without(&self, ids: &[String]) -> Obstacles {
        Obstacles {
            items: self
                .items
                .iter()
                .filter(|i| !ids.contains(&i.id))
                .map(|i| Item {
                    shape: i.shape.clone(),
                    lo: i.lo,
                    hi: i.hi,
                    id: i.id.clone(),
                })
                .collect(),
            queries: Default::default(),
        }
    }

    /// The names of the surfaces that come within `distance_mm` of the segment `a b` (sampled
    /// at most `distance_mm / 2` apart, so a surface within half of it anywhere on the
    /// segment is found).
    pub fn near_segment(&self, a: &Point3<f64>, b: &Point3<f64>, distance_mm: f64) -> Vec<String> {
        let k = (((b - a).norm() / (0.5 * distance_mm)).ceil() as usize).clamp(1, 100_000);
        self.items
            .iter()
            .filter(|i| {
                (0..=k).any(|j| {
                    let p = a + (b - a) * (j as f64 / k as f64);
                    box_distance(&p, &i.lo, &i.hi) < distance_mm
                        && shape_distance(&i.shape, &p) < distance_mm
                })
            })
            .map(|i| i.id.clone())
            .collect()
    }

    /// The names of the surfaces within `tolerance_mm` of `p` (from [`Obstacles::from_file`]:
    /// the surface ids; otherwise `#0`, `#1`, ... in the order added).
    pub fn touching(&self, p: &Point3<f64>, tolerance_mm: f64) -> Vec<String> {
        self.items
            .iter()
            .filter(|i| box_distance(p, &i.lo, &i.hi) <= tolerance_mm)
            .filter(|i| shape_distance(&i.shape, p) <= tolerance_mm)
            .map(|i| i.id.clone())
            .collect()
    }

    /// Adds a triangle mesh (vertices in the workpiece frame, mm).
    ///
    /// # Errors
    /// [`ProcessError::BadSurface`] if a vertex is not finite, an index is out of range or no
    /// triangle remains.
    pub fn add_mesh(&mut self, vertices: Vec<Point3<f64>>, triangles: Vec<[u32; 3]>) -> Result<()> {
        let id = format!("#{}", self.items.len());
        self.add_mesh_named(vertices, triangles, id)
    }

    fn add_mesh_named(
        &mut self,
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[u32; 3]>,
        id: String,
    ) -> Result<()> {
        let bad = |reason: String| ProcessError::BadSurface { reason };
        if let Some(i) = vertices
            .iter()
            .position(|v| !v.coords.iter().all(|x| x.is_finite()))
        {
            return Err(bad(format!("mesh vertex {i} is not finite")));
        }
        let n = vertices.len() as u32;
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
            return Err(bad(format!("mesh triangle {t} has a vertex index >= {n}")));
        }
        let mut lo = Point3::from([f64::INFINITY; 3]);
        let mut hi = Point3::from([f64::NEG_INFINITY; 3]);
        for v in &vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        let mesh = TriMesh::with_flags(
            vertices,
            triangles,
            TriMeshFlags::DELETE_DEGENERATE_TRIANGLES,
        )
        .map_err(|e| bad(format!("mesh: {e:?}")))?;
        if mesh.indices().is_empty() {
            return Err(bad("mesh: no triangle with a non-zero area".into()));
        }
        self.items.push(Item {
            shape: std::sync::Arc::new(Obstacle::Mesh(Box::new(mesh))),
            lo,
            hi,
            id,
        });
        Ok(())
    }

    /// Adds a NURBS surface moved by the rigid motion `map` (the placement of the part): the
    /// control points are mapped, the knots and weights kept, which moves the surface exactly.
    ///
    /// # Errors
    /// [`ProcessError::BadSurface`] if the mapped control net is not valid (a non-finite
    /// point).
    pub fn add_nurbs_mapped(
        &mut self,
        surface: &NurbsSurface,
        map: impl Fn(&Point3<f64>) -> Point3<f64>,
    ) -> Result<()> {
        let cps = surface
            .control_points()
            .iter()
            .map(|row| row.iter().map(&map).collect())
            .collect();
        let moved = NurbsSurface::try_new(
            surface.degree_u(),
            surface.degree_v(),
            surface.knots_u().to_vec(),
            surface.knots_v().to_vec(),
            cps,
            surface.is_rational().then(|| surface.weights()),
        )
        .map_err(|e| ProcessError::BadSurface {
            reason: e.to_string(),
        })?;
        self.add_nurbs(moved);
        Ok(())
    }

    fn add_nurbs_mapped_named(
        &mut self,
        surface: &NurbsSurface,
        map: impl Fn(&Point3<f64>) -> Point3<f64>,
        id: &str,
    ) -> Result<()> {
        self.add_nurbs_mapped(surface, map)?;
        if let Some(last) = self.items.last_mut() {
            last.id = id.to_string();
        }
        Ok(())
    }

    /// The surfaces that carry the curves `curves` (indices into `file.curves`), each once,
    /// moved by the rigid motion `map` (the part's placement on the machine), named by their
    /// ids.
    ///
    /// # Errors
    /// [`ProcessError::BadSurface`] as [`Obstacles::add_mesh`] and
    /// [`Obstacles::add_nurbs_mapped`].
    pub fn from_file(
        file: &kerf_format::CurvesFile,
        curves: &[usize],
        map: impl Fn(&Point3<f64>) -> Point3<f64>,
    ) -> Result<Self> {
        let mut obs = Self::new();
        let mut seen: Vec<&str> = Vec::new();
        for &i in curves {
            for id in &file.curves[i].surfaces {
                if seen.contains(&id.as_str()) {
                    continue;
                }
                seen.push(id);
                let Some(s) = file.surface(id) else { continue };
                match &s.geometry {
                    kerf_format::SurfaceGeometry::Nurbs(n) => {
                        obs.add_nurbs_mapped_named(n, &map, id)?
                    }
                    kerf_format::SurfaceGeometry::Mesh {
                        vertices,
                        triangles,
                    } => obs.add_mesh_named(
                        vertices.iter().map(&map).collect(),
                        triangles.clone(),
                        id.clone(),
                    )?,
                }
            }
        }
        Ok(obs)
    }

    /// The largest coordinate along `up` of the boxes of the surfaces that come within
    /// `radius_mm` of the segment `a b` seen along `up` (their boxes' distance with the `up`
    /// component left out), or `None` if none does or `up` is not a coordinate axis.
    fn local_top(
        &self,
        a: &Point3<f64>,
        b: &Point3<f64>,
        up: &Vector3<f64>,
        radius_mm: f64,
    ) -> Option<f64> {
        let k = (0..3).find(|&k| (up[k].abs() - 1.0).abs() < 1e-12)?;
        let n = (((b - a).norm() / (0.5 * radius_mm)).ceil() as usize).clamp(1, 100_000);
        self.items
            .iter()
            .filter(|i| {
                (0..=n).any(|j| {
                    let p = a + (b - a) * (j as f64 / n as f64);
                    let d = Vector3::from_fn(|m, _| {
                        if m == k {
                            0.0
                        } else {
                            (i.lo[m] - p[m]).max(p[m] - i.hi[m]).max(0.0)
                        }
                    });
                    // Samples half the radius apart: a box within it of the segment is within
                    // 1.25 times it of a sample.
                    d.norm() <= 1.25 * radius_mm
                })
            })
            .map(|i| top_along(&i.lo, &i.hi, up))
            .reduce(f64::max)
    }

    /// The id of the nearest surface to `p` and its distance, mm (`None` without surfaces).
    pub fn nearest(&self, p: &Point3<f64>) -> Option<(String, f64)> {
        self.items
            .iter()
            .map(|i| (i.id.clone(), shape_distance(&i.shape, p)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// True if there are no surfaces.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The axis-aligned box `(min, max)` that contains every surface, or `None` without any.
    pub fn bounding_box(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let mut it = self.items.iter();
        let first = it.next()?;
        Some(it.fold((first.lo, first.hi), |(a, b), i| {
            (a.inf(&i.lo), b.sup(&i.hi))
        }))
    }

    /// How many exact distance queries (one surface, one point) the checks have made so far.
    pub fn queries(&self) -> usize {
        self.queries.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The distance from `p` to the nearest surface, mm (infinite without surfaces).
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.distance_below(p, f64::INFINITY)
    }

    /// The distance from `p` to the nearest surface if it is below `limit`; otherwise some
    /// value `>= limit` (surfaces whose box is at least `limit` away are not queried).
    pub fn distance_below(&self, p: &Point3<f64>, limit: f64) -> f64 {
        // Skipped surfaces are at least their box's distance away: the result is exact below
        // `limit` and a lower bound of the distance (itself >= limit) above it.
        let mut best = f64::INFINITY;
        let mut floor = f64::INFINITY;
        for item in &self.items {
            let gap = box_distance(p, &item.lo, &item.hi);
            if gap >= limit.min(best) {
                floor = floor.min(gap);
                continue;
            }
            self.queries
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let d = shape_distance_below(&item.shape, p, limit.min(best));
            best = best.min(d);
        }
        best.min(floor)
    }
}

fn shape_distance(o: &Obstacle, p: &Point3<f64>) -> f64 {
    shape_distance_below(o, p, f64::INFINITY)
}

fn shape_distance_below(o: &Obstacle, p: &Point3<f64>, limit: f64) -> f64 {
    match o {
        Obstacle::Nurbs(s) => s.distance(p, limit),
        Obstacle::Mesh(m) => m.distance_to_local_point(p, false),
    }
}

fn box_distance(p: &Point3<f64>, lo: &Point3<f64>, hi: &Point3<f64>) -> f64 {
    let d = Vector3::from_fn(|k, _| (lo[k] - p[k]).max(p[k] - hi[k]).max(0.0));
    d.norm()
}

/// Options of the traverses.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TraverseOptions {
    /// No point of the travel (tip or nozzle) comes closer to the part than this, mm
    /// (default 5).
    pub clearance_mm: f64,
    /// How far the head first backs off along the tool axis, mm; at least 1.25 times the
    /// clearance, raised where the retract point is not clear (default 7.5).
    pub retract_mm: f64,
    /// Length of the nozzle, a segment from the tip along the tool axis toward the head that
    /// must keep the clearance too, mm (default 20).
    pub nozzle_mm: f64,
    /// The direction in the workpiece frame that is "up" (away from the fixture, toward the
    /// free space): a lifted travel runs in the plane perpendicular to it above every
    /// surface (default +z).
    pub up: Vector3<f64>,
}

impl Default for TraverseOptions {
    fn default() -> Self {
        Self {
            clearance_mm: 5.0,
            retract_mm: 7.5,
            nozzle_mm: 20.0,
            up: Vector3::z(),
        }
    }
}

impl TraverseOptions {
    /// Sets [`clearance_mm`](Self::clearance_mm): no point of the travel (tip or nozzle)
    /// comes closer to the part than this, mm (default 5).
    pub fn with_clearance_mm(mut self, clearance_mm: f64) -> Self {
        self.clearance_mm = clearance_mm;
        self
    }

    /// Sets [`retract_mm`](Self::retract_mm): how far the head first backs off along the
    /// tool axis, mm.
    pub fn with_retract_mm(mut self, retract_mm: f64) -> Self {
        self.retract_mm = retract_mm;
        self
    }

    /// Sets [`nozzle_mm`](Self::nozzle_mm): length of the nozzle, a segment from the tip
    /// along the tool axis toward the head that must keep the clearance too, mm (default
    /// 20).
    pub fn with_nozzle_mm(mut self, nozzle_mm: f64) -> Self {
        self.nozzle_mm = nozzle_mm;
        self
    }

    /// Sets [`up`](Self::up): the direction in the workpiece frame that is "up" (away from
    /// the fixture, toward the free space).
    pub fn with_up(mut self, up: Vector3<f64>) -> Self {
        self.up = up;
        self
    }

    /// With this clearance, mm; the retract becomes 1.5 times it.
    pub fn with_clearance(mut self, clearance_mm: f64) -> Self {
        self.clearance_mm = clearance_mm;
        self.retract_mm = 1.5 * clearance_mm;
        self
    }

    fn validate(&self) -> Result<()> {
        let check = |name: &'static str, v: f64, ok: bool| {
            if ok {
                Ok(())
            } else {
                Err(ProcessError::BadOption {
                    name,
                    value: v,
                    reason: "must be finite, > 0 and <= 1e4 (retract_mm >= 1.25 clearance_mm)",
                })
            }
        };
        let fine = |v: f64| v.is_finite() && v > 0.0 && v <= 1e4;
        check("clearance_mm", self.clearance_mm, fine(self.clearance_mm))?;
        check(
            "retract_mm",
            self.retract_mm,
            fine(self.retract_mm) && self.retract_mm >= 1.25 * self.clearance_mm,
        )?;
        check(
            "nozzle_mm",
            self.nozzle_mm,
            self.nozzle_mm.is_finite() && (0.0..=1e4).contains(&self.nozzle_mm),
        )?;
        let up_ok = self.up.iter().all(|v| v.is_finite()) && self.up.norm() > 1e-9;
        check("up", self.up.norm(), up_ok)
    }

    /// The height step of the lifted routes above the surfaces' boxes (two of them), mm.
    fn step(&self) -> f64 {
        self.clearance_mm / 8.0
    }

    /// The margin of the checks, mm: a sample closer than the clearance plus this is taken
    /// as blocked (so the sphere tracing advances by at least half of it, which bounds its
    /// work). A sixty-fourth of the clearance: a route that keeps 1.02 times the clearance is
    /// found, and the claim (the clearance) does not depend on it.
    fn margin(&self) -> f64 {
        self.clearance_mm / 64.0
    }
}

/// How a traverse runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Retract, one straight travel, approach.
    Straight,
    /// Retract, rise along the up direction to the safe plane above every surface, travel in
    /// it, descend, approach.
    SafePlane,
    /// Retract, rise along the up direction to a clearance above the surfaces whose boxes
    /// come near the travel (seen along the up direction), travel, descend, approach: lower
    /// than the safe plane, so often within the axis limits where that is not.
    Lifted,
}

impl Route {
    /// `"straight"` or `"safe_plane"`.
    pub fn name(self) -> &'static str {
        match self {
            Route::Straight => "straight",
            Route::SafePlane => "safe_plane",
            Route::Lifted => "lifted",
        }
    }
}

/// A planned traverse from the end of one cut to the pierce of the next.
#[derive(Debug, Clone, PartialEq)]
pub struct Traverse {
    /// The waypoints with tool axes, workpiece frame, from the retract point above the exit
    /// to the point above the pierce; the head reaches the first along the exit's tool axis
    /// and leaves the last along the pierce's tool axis. Between waypoints it moves straight,
    /// the tool axis turning from one waypoint's to the next's.
    pub waypoints: Vec<PoseArray>,
    /// The route taken.
    pub route: Route,
    /// The smallest surface distance found over the travel's samples (tip and nozzle), mm;
    /// the travel is certified to stay at least the clearance away.
    pub min_distance_mm: f64,
    /// The length of the tip's path from the exit to the pierce: retract, travel, approach,
    /// mm.
    pub length_mm: f64,
}

/// Why a stretch of a traverse is not clear: the first offending sample.
#[derive(Debug, Clone, Copy)]
struct Blocked {
    at: Point3<f64>,
    distance: f64,
}

/// Certifies the straight move `a -> b` (the tool axis turning as the normalised linear
/// interpolation of `a`'s and `b`'s): every point of the tip's segment and of the nozzle (from
/// the tip `nozzle` mm along the axis) keeps at least `need` from the surfaces. Returns the
/// smallest distance measured, or the first point closer than `need + floor`.
///
/// Sphere tracing with the 1-Lipschitz distance: along the nozzle at offset `s` with distance
/// `e`, the next sample is `(e - need) / 2` further, so over each stretch the distance is at
/// least `(e + need) / 2`, and the whole nozzle at this tip position at least `m`, the smallest
/// of those. A point of the swept surface at interpolation parameter `f + df` lies within
/// `df (|b - a| + nozzle |n_b - n_a| / cos(theta / 2))` of the one at `f` (the normalised
/// interpolation turns at most that fast, `theta` the angle between the axes), so the tip
/// advances by `df` with that distance equal to `m - need`.
fn certify(
    obs: &Obstacles,
    a: &PoseArray,
    b: &PoseArray,
    need: f64,
    nozzle: f64,
    floor: f64,
) -> std::result::Result<f64, Blocked> {
    let (pa, pb) = (position(a), position(b));
    let (na, nb) = (normal(a).normalize(), normal(b).normalize());
    let half_cos = (0.5 * (1.0 + na.dot(&nb))).max(0.0).sqrt().max(0.05);
    let speed = (pb - pa).norm() + nozzle * (nb - na).norm() / half_cos;
    let limit = need + 2.0 * floor.max(need / 4.0) + 0.25 * nozzle;
    let mut least = f64::INFINITY;
    let mut f = 0.0_f64;
    loop {
        let p = pa + (pb - pa) * f;
        let n = (na * (1.0 - f) + nb * f)
            .try_normalize(1e-12)
            .unwrap_or(if f < 0.5 { na } else { nb });
        // The nozzle at this tip position.
        let mut m = f64::INFINITY;
        let mut s = 0.0_f64;
        loop {
            let q = p + n * s;
            let e = obs.distance_below(&q, limit);
            least = least.min(e);
            if e < need + floor {
                return Err(Blocked { at: q, distance: e });
            }
            let ds = 0.5 * (e - need);
            m = m.min(e - ds);
            if s >= nozzle {
                break;
            }
            s = (s + ds).min(nozzle);
        }
        if f >= 1.0 || speed == 0.0 {
            return Ok(least);
        }
        f = (f + (m - need) / speed).min(1.0);
    }
}

/// Certifies a machine's move given as the poses of its tip and tool axis sampled along it
/// (e.g. the tip and axis of the machine axes interpolated between two solved waypoints,
/// closely spaced, workpiece frame): the tip and the nozzle (`nozzle_mm` along the axis) on
/// the straight moves between consecutive samples keep `need_mm` from the surfaces. Returns
/// the smallest distance measured.
///
/// The bound covers the polyline through the samples; the machine's own path between two
/// samples departs from it by the second order of their spacing, which the caller keeps small
/// (or adds to `need_mm`).
///
/// # Errors
/// `Err((point, distance))` for the first point closer than `need_mm` plus a hundredth of it.
pub fn check_move(
    obs: &Obstacles,
    samples: &[PoseArray],
    need_mm: f64,
    nozzle_mm: f64,
) -> std::result::Result<f64, (Point3<f64>, f64)> {
    let floor = need_mm.abs() / 100.0 + 1e-6;
    let mut least = f64::INFINITY;
    for w in samples.windows(2) {
        least = least.min(
            certify(obs, &w[0], &w[1], need_mm, nozzle_mm, floor)
                .map_err(|b| (b.at, b.distance))?,
        );
    }
    Ok(least)
}

fn with_axis(p: Point3<f64>, n: Vector3<f64>) -> PoseArray {
    [p.x, p.y, p.z, n.x, n.y, n.z]
}

fn path_length(points: &[Point3<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Plans the traverse from `from` (where the last cut ended: tip and tool axis, workpiece
/// frame) to `to` (the next pierce point and its tool axis).
///
/// The head backs off along `from`'s axis by the retract (doubled, up to 16 times the larger of
/// clearance and retract, where a route from there is not clear), and the straight travel to
/// the point as far above `to` is checked; where it is blocked, the travel rises along
/// [`TraverseOptions::up`] to the safe plane a clearance and a sample step above every
/// surface's bounding box, crosses in it and comes down. Along the retract and the approach,
/// from 3/4 of the clearance up the tip keeps half the clearance (their lower ends touch the
/// part by design); along the travel the tip and the nozzle keep the full clearance.
///
/// # Errors
/// [`ProcessError::BadOption`] for bad options, [`ProcessError::BadContour`] for non-finite
/// poses, [`ProcessError::TraverseBlocked`] if no route is clear (e.g. a tool axis pointing
/// into a pocket the head cannot back out of).
pub fn plan_traverse(
    obs: &Obstacles,
    from: &PoseArray,
    to: &PoseArray,
    opts: &TraverseOptions,
) -> Result<Traverse> {
    plan_traverse_within(obs, from, to, opts, &|_| true)
}

/// [`plan_traverse`] among the routes whose waypoints `reachable` accepts (e.g. within the
/// machine's axis limits); the others are not tried.
///
/// # Errors
/// As [`plan_traverse`].
pub fn plan_traverse_within(
    obs: &Obstacles,
    from: &PoseArray,
    to: &PoseArray,
    opts: &TraverseOptions,
    reachable: &dyn Fn(&[PoseArray]) -> bool,
) -> Result<Traverse> {
    plan_traverse_accepting(obs, from, to, opts, reachable, &mut |_| Ok(())).map(|(t, ())| t)
}

/// Why a route was refused by the caller's own check (e.g. the machine's rapid swing): the
/// first offending point and its distance, mm.
pub(crate) type Refusal = (Point3<f64>, f64);

/// [`plan_traverse_within`], where a route that is clear is also handed to `accept` (e.g.
/// the check of the machine's own rapid moves); the first route both accept is returned with
/// `accept`'s result, the next shortest tried otherwise.
pub(crate) fn plan_traverse_accepting<T>(
    obs: &Obstacles,
    from: &PoseArray,
    to: &PoseArray,
    opts: &TraverseOptions,
    reachable: &dyn Fn(&[PoseArray]) -> bool,
    accept: &mut dyn FnMut(&Traverse) -> std::result::Result<T, Refusal>,
) -> Result<(Traverse, T)> {
    opts.validate()?;
    for (name, p) in [("from", from), ("to", to)] {
        let axis_ok = normal(p).norm() > 1e-9;
        if !p.iter().all(|v| v.is_finite()) || !axis_ok {
            return Err(ProcessError::BadContour {
                id: format!("traverse {name}"),
                reason: "a non-finite pose or a zero tool axis".into(),
            });
        }
    }
    let c = opts.clearance_mm;
    let h = opts.step();
    let floor = opts.margin();
    let up = opts.up.normalize();
    let unit = |p: &PoseArray| {
        let n = normal(p).normalize();
        with_axis(position(p), n)
    };
    let (from, to) = (unit(from), unit(to));
    // The retract (and the approach) along the tool axis: from 3/4 of the clearance to the
    // retract height, the tip keeps half the clearance; raised where it does not.
    let axial = |p: &PoseArray, height: f64| -> std::result::Result<PoseArray, Blocked> {
        let (q, n) = (position(p), normal(p));
        let low = with_axis(q + n * (0.75 * c), n);
        let high = with_axis(q + n * height, n);
        certify(obs, &low, &high, 0.5 * c, 0.0, floor)?;
        Ok(high)
    };
    let length_of = |way: &[PoseArray]| {
        let mut pts = vec![position(&from)];
        pts.extend(way.iter().map(position));
        pts.push(position(&to));
        path_length(&pts)
    };
    let tip_ends = |w: &[PoseArray]| -> std::result::Result<f64, Blocked> {
        let mut least = f64::INFINITY;
        for s in w.windows(2) {
            least = least.min(certify(obs, &s[0], &s[1], c, opts.nozzle_mm, floor)?);
        }
        Ok(least)
    };
    let blocked_err = |b: Blocked, why: String| {
        ProcessError::TraverseBlocked(Box::new(crate::Blockage {
            from: [from[0], from[1], from[2]],
            to: [to[0], to[1], to[2]],
            at: [b.at.x, b.at.y, b.at.z],
            distance_mm: b.distance,
            clearance_mm: c,
            why,
        }))
    };
    // The retract heights tried at each end (doubling), those whose axial move is clear.
    let heights: Vec<f64> = (0..5)
        .map(|k| opts.retract_mm * f64::from(1 << k))
        .collect();
    let ends = |p: &PoseArray| -> std::result::Result<Vec<PoseArray>, Blocked> {
        let mut last = None;
        let ok: Vec<PoseArray> = heights
            .iter()
            .filter_map(|&hh| match axial(p, hh) {
                Ok(q) => Some(q),
                Err(e) => {
                    last = Some(e);
                    None
                }
            })
            .collect();
        match (ok.is_empty(), last) {
            (true, Some(e)) => Err(e),
            _ => Ok(ok),
        }
    };
    let top = heights[heights.len() - 1];
    let ends_a = ends(&from).map_err(|b| {
        blocked_err(
            b,
            format!(
                "the retract along the tool axis from the exit is blocked at every height from {:.1} to {top:.1} mm",
                heights[0]
            ),
        )
    })?;
    let ends_b = ends(&to).map_err(|b| {
        blocked_err(
            b,
            format!(
                "the approach along the tool axis to the pierce is blocked at every height from {:.1} to {top:.1} mm",
                heights[0]
            ),
        )
    })?;
    // Every route: straight between any two retract points, lifted along `up` over the
    // surfaces near the travel, or over the safe plane above every surface; checked shortest
    // first.
    let mut routes: Vec<(f64, Route, Vec<PoseArray>)> = Vec::new();
    let lift_to = |level: f64| {
        move |p: &PoseArray| {
            let q = position(p);
            let rise = (level - q.coords.dot(&up)).max(0.0);
            with_axis(q + up * rise, normal(p))
        }
    };
    let global_top = obs
        .bounding_box()
        .map(|(lo, hi)| top_along(&lo, &hi, &up) + c + 2.0 * h);
    for a in &ends_a {
        for b in &ends_b {
            let straight = vec![*a, *b];
            routes.push((length_of(&straight), Route::Straight, straight));
            let (pa, pb) = (position(a), position(b));
            // Each lift at a clearance and two steps above the boxes' top, and a clearance
            // higher (where a tilted nozzle reaches down past the first).
            let local = obs.local_top(&pa, &pb, &up, 2.0 * c + opts.nozzle_mm + 4.0 * h);
            for extra in [0.0, c + 2.0 * h] {
                if let Some(level) = local {
                    let lift = lift_to(level + c + 2.0 * h + extra);
                    let way = vec![*a, lift(a), lift(b), *b];
                    routes.push((length_of(&way), Route::Lifted, way));
                }
                if let Some(level) = global_top {
                    let lift = lift_to(level + extra);
                    let plane = vec![*a, lift(a), lift(b), *b];
                    routes.push((length_of(&plane), Route::SafePlane, plane));
                }
            }
        }
    }
    routes.sort_by(|x, y| x.0.total_cmp(&y.0));
    let (mut unreachable, mut refused) = (0usize, 0usize);
    let mut blocked: Option<Blocked> = None;
    for (length_mm, route, waypoints) in &routes {
        if !reachable(waypoints) {
            unreachable += 1;
            continue;
        }
        match tip_ends(waypoints) {
            Ok(least) => {
                let t = Traverse {
                    length_mm: *length_mm,
                    waypoints: waypoints.clone(),
                    route: *route,
                    min_distance_mm: least,
                };
                match accept(&t) {
                    Ok(v) => return Ok((t, v)),
                    Err((at, distance)) => {
                        refused += 1;
                        blocked = Some(Blocked { at, distance });
                    }
                }
            }
            Err(e) => blocked = Some(e),
        }
    }
    let n = routes.len();
    let why = if unreachable == n {
        format!("none of the {n} routes lies within the machine's axis limits")
    } else {
        format!(
            "{} of {n} routes come too close, {refused} of them only in the machine's rapid swing, {unreachable} leave the axis limits",
            n - unreachable
        )
    };
    let b = blocked.unwrap_or(Blocked {
        at: position(&from),
        distance: 0.0,
    });
    Err(blocked_err(b, why))
}

/// The largest coordinate along `up` of the box `lo hi`, mm.
fn top_along(lo: &Point3<f64>, hi: &Point3<f64>, up: &Vector3<f64>) -> f64 {
    (0..8)
        .map(|k| {
            let corner = Point3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            );
            corner.coords.dot(up)
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

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
