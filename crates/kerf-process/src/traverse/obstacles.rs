//! The part's surfaces in the workpiece frame and their distance queries.

use nalgebra::{Point3, Vector3};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

use kerf_nurbs::NurbsSurface;

use super::boxes::BoxTree;
use super::tessellated::Tessellated;
use crate::{ProcessError, Result};
use kerf_nurbs::distance_to_box;

/// One surface of the part, placed in the workpiece frame.
#[derive(Debug)]
enum Obstacle {
    Nurbs(Box<Tessellated>),
    Mesh(Box<TriMesh>),
}

/// The most vertices of one mesh tested for joins ([`Obstacles::parts`]).
const MESH_JOIN_VERTICES: usize = 20_000;

/// Points on the boundary of a surface ([`Obstacles::parts`]): a NURBS surface's four
/// boundary curves, a mesh's vertices.
fn boundary_points(shape: &Obstacle) -> Vec<Point3<f64>> {
    match shape {
        Obstacle::Nurbs(t) => {
            let s = t.surface();
            let ((u0, u1), (v0, v1)) = (s.domain_u(), s.domain_v());
            let k = 32;
            (0..=k)
                .flat_map(|j| {
                    let f = j as f64 / k as f64;
                    let (u, v) = (u0 + (u1 - u0) * f, v0 + (v1 - v0) * f);
                    [
                        s.point(u, v0),
                        s.point(u, v1),
                        s.point(u0, v),
                        s.point(u1, v),
                    ]
                })
                .collect()
        }
        Obstacle::Mesh(m) => {
            let v = m.vertices();
            // Every vertex of a mesh of up to 20,000 (a shared edge's vertices lie on the
            // other surface); every k-th of a larger one.
            let step = v.len().div_ceil(MESH_JOIN_VERTICES).max(1);
            v.iter().step_by(step).copied().collect()
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
#[derive(Debug)]
pub struct Obstacles {
    items: Vec<Item>,
    /// How many exact distance queries have been made (the work the checks cost).
    queries: std::sync::atomic::AtomicUsize,
    /// This set of surfaces, as the recent queries' cache knows it: never the same for two
    /// sets (a new one for every set made and every surface added).
    generation: u64,
    /// The tree of the surfaces' boxes (built at the first query after a surface is added).
    tree: std::sync::OnceLock<BoxTree>,
}

impl Default for Obstacles {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            queries: Default::default(),
            generation: next_generation(),
            tree: Default::default(),
        }
    }
}

/// A number no set of surfaces had before.
fn next_generation() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// One entry of the recent queries' cache: the set of surfaces, the point and the limit (bit
/// for bit), and the answer.
#[derive(Debug, Clone, Copy, Default)]
struct Recent {
    generation: u64,
    key: [u64; 4],
    value: f64,
}

/// Entries of each thread's cache of recent queries (a power of two).
const RECENT: usize = 1 << 13;

thread_local! {
    /// The answers of this thread's recent [`Obstacles::distance_below`] queries, by a hash of
    /// the query (direct-mapped: a query replaces the one before it in its slot).
    static RECENT_QUERIES: std::cell::RefCell<Vec<Recent>> =
        std::cell::RefCell::new(vec![Recent::default(); RECENT]);
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
        self.generation = next_generation();
        self.tree = Default::default();
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
            generation: next_generation(),
            tree: Default::default(),
        }
    }

    /// The parts of the surfaces: for each surface (in the order added) the index of its part,
    /// surfaces being of one part where joined directly or through others. Two surfaces are
    /// joined where a point of one's boundary (for a NURBS surface, its four boundary curves
    /// at 33 points each; for a mesh, its vertices, at most 20,000 of them) lies within
    /// `tolerance_mm` of the other: the floor a cut lies on and the wall beside it, not
    /// another part that a file holds in the same place.
    pub fn parts(&self, tolerance_mm: f64) -> Vec<usize> {
        let n = self.items.len();
        let mut parent: Vec<usize> = (0..n).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        for (i, item) in self.items.iter().enumerate() {
            for b in boundary_points(&item.shape) {
                for (j, other) in self.items.iter().enumerate() {
                    if j == i || distance_to_box(&b, &other.lo, &other.hi) > tolerance_mm {
                        continue;
                    }
                    let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                    if ri != rj && shape_distance(&other.shape, &b) <= tolerance_mm {
                        parent[ri] = rj;
                    }
                }
            }
        }
        (0..n).map(|k| root(&mut parent, k)).collect()
    }

    /// The surfaces whose part (`parts`, from [`Obstacles::parts`]) holds one of the surfaces
    /// named in `seeds` (shared, not copied); every surface when `seeds` names none of them
    /// (a curve that names no surface is checked against the whole file).
    pub fn of_parts(&self, parts: &[usize], seeds: &[String]) -> Obstacles {
        if !self.items.iter().any(|i| seeds.contains(&i.id)) {
            return self.without(&[]);
        }
        let keep: Vec<usize> = self
            .items
            .iter()
            .zip(parts)
            .filter(|(i, _)| seeds.contains(&i.id))
            .map(|(_, &p)| p)
            .collect();
        let out: Vec<String> = self
            .items
            .iter()
            .zip(parts)
            .filter(|(_, p)| !keep.contains(p))
            .map(|(i, _)| i.id.clone())
            .collect();
        self.without(&out)
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
                    distance_to_box(&p, &i.lo, &i.hi) < distance_mm
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
            .filter(|i| distance_to_box(p, &i.lo, &i.hi) <= tolerance_mm)
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
        self.generation = next_generation();
        self.tree = Default::default();
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
                if let Some(s) = file.surface(id) {
                    obs.add_surface(s, &map)?;
                }
            }
        }
        Ok(obs)
    }

    /// Every surface of `file`, whether a curve names it or not (a wall beside a hole, a
    /// flange over a trim line), moved by `map`, named by their ids.
    ///
    /// # Errors
    /// As [`Obstacles::from_file`].
    pub fn from_all_surfaces(
        file: &kerf_format::CurvesFile,
        map: impl Fn(&Point3<f64>) -> Point3<f64>,
    ) -> Result<Self> {
        let mut obs = Self::new();
        for s in &file.surfaces {
            obs.add_surface(s, &map)?;
        }
        Ok(obs)
    }

    fn add_surface(
        &mut self,
        s: &kerf_format::SurfaceRecord,
        map: &impl Fn(&Point3<f64>) -> Point3<f64>,
    ) -> Result<()> {
        let id = &s.id;
        match &s.geometry {
            kerf_format::SurfaceGeometry::Nurbs(n) => self.add_nurbs_mapped_named(n, map, id),
            kerf_format::SurfaceGeometry::Mesh {
                vertices,
                triangles,
            } => self.add_mesh_named(
                vertices.iter().map(map).collect(),
                triangles.clone(),
                id.clone(),
            ),
        }
    }

    /// The largest coordinate along `up` of the boxes of the surfaces that come within
    /// `radius_mm` of the segment `a b` seen along `up` (their boxes' distance with the `up`
    /// component left out), or `None` if none does or `up` is not a coordinate axis.
    pub(super) fn local_top(
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

    /// How many exact distance queries (one surface, one point: a closest point on a NURBS
    /// surface, a projection onto a mesh) the checks have made so far; a surface passed over
    /// by its boxes, or a query answered from the cache of recent ones, costs none.
    pub fn queries(&self) -> usize {
        self.queries.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The distance from `p` to the nearest surface, mm (infinite without surfaces).
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.distance_below(p, f64::INFINITY)
    }

    /// The distance from `p` to the nearest surface if it is below `limit`; otherwise some
    /// value `>= limit` (surfaces whose box is at least `limit` away are not queried).
    ///
    /// The answer is a function of the surfaces, `p` and `limit` alone, so each thread keeps
    /// the answers of its recent queries and gives the same one again for the same query (bit
    /// for bit): the checks ask again for many points (the nozzle where one traced move ends is
    /// where the next starts, the head at a retract point starts every route from it).
    pub fn distance_below(&self, p: &Point3<f64>, limit: f64) -> f64 {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), limit.to_bits()];
        let slot = recent_slot(self.generation, &key);
        let known = RECENT_QUERIES.with(|r| {
            let e = r.borrow()[slot];
            (e.generation == self.generation && e.key == key).then_some(e.value)
        });
        if let Some(value) = known {
            return value;
        }
        let value = self.distance_below_uncached(p, limit);
        RECENT_QUERIES.with(|r| {
            r.borrow_mut()[slot] = Recent {
                generation: self.generation,
                key,
                value,
            }
        });
        value
    }

    /// [`Obstacles::distance_below`] without the cache: the surfaces nearest first (by the
    /// distance to their pieces' boxes), each surface's exact distance only while that bound
    /// is below the best so far, and the same answer, bit for bit, as the scan in the order
    /// the surfaces were added ([`Obstacles::distance_below_in_order`]), which it falls back
    /// to where it cannot show that (`docs/process.md`, "The nearest surface first").
    fn distance_below_uncached(&self, p: &Point3<f64>, limit: f64) -> f64 {
        // Each candidate: the lower bound `m` (pieces' boxes, or the box for a mesh), the
        // box's distance `g`, its index, and its exact distance once known.
        let mut cands = [(0.0_f64, 0.0_f64, 0usize, f64::NAN); NEAREST_CANDIDATES];
        let mut n = 0;
        // Above the limit: the least box distance, and the least pieces' bound.
        let mut above = f64::INFINITY;
        let mut overflow = false;
        let tree = self.tree();
        tree.within(p, limit, |i, g| {
            let m = match &*self.items[i].shape {
                Obstacle::Nurbs(t) => t.piece_bound(p, limit),
                Obstacle::Mesh(_) => g,
            };
            if m >= limit {
                above = above.min(m);
            } else if n == NEAREST_CANDIDATES {
                overflow = true;
            } else {
                cands[n] = (m, g, i, f64::NAN);
                n += 1;
            }
        });
        if overflow {
            return self.distance_below_in_order(p, limit);
        }
        let cands = &mut cands[..n];
        cands.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        // Rounding slack between a computed lower bound and a computed exact distance.
        let eps = 1e-6 + 1e-9 * p.coords.amax();
        let mut best = f64::INFINITY;
        let mut nearest = usize::MAX;
        for (k, cand) in cands.iter_mut().enumerate() {
            if cand.0 >= limit.min(best + 2.0 * eps) {
                break;
            }
            self.count_query();
            let c = match &*self.items[cand.2].shape {
                Obstacle::Nurbs(t) => t.exact(p),
                Obstacle::Mesh(mesh) => mesh.distance_to_local_point(p, false),
            };
            cand.3 = c;
            if c < best {
                best = c;
                nearest = k;
            }
        }
        if best >= limit || nearest == usize::MAX {
            // Nothing below the limit: every candidate's exact distance was taken (each at or
            // above it), as the scan in order does, and the surfaces at least the limit away
            // count with their boxes' distance.
            let near = best.min(above);
            return near.min(tree.nearest_beyond(p, limit, near));
        }
        // The scan in order takes the nearest surface's distance if every surface before it
        // stays above both of the bounds it is passed over by (its box's distance and its
        // pieces' bound): then its threshold there is above them.
        let (m, g, i, c) = cands[nearest];
        let t = m.max(g);
        let clear = t + eps < limit
            && cands
                .iter()
                .all(|&(mk, _, k, ck)| k >= i || if ck.is_nan() { mk > t + eps } else { ck > t });
        if clear {
            c
        } else {
            self.distance_below_in_order(p, limit)
        }
    }

    /// The tree of the surfaces' boxes.
    fn tree(&self) -> &BoxTree {
        self.tree
            .get_or_init(|| BoxTree::new(self.items.iter().map(|i| (i.lo, i.hi)).collect()))
    }

    fn count_query(&self) {
        self.queries
            .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }

    /// The scan of the surfaces in the order they were added, each passed over where its box
    /// (then its pieces' boxes) is at least the best so far or the limit away.
    fn distance_below_in_order(&self, p: &Point3<f64>, limit: f64) -> f64 {
        // Skipped surfaces are at least their box's distance away: the result is exact below
        // `limit` and a lower bound of the distance (itself >= limit) above it.
        let mut best = f64::INFINITY;
        let mut floor = f64::INFINITY;
        for item in &self.items {
            let gap = distance_to_box(p, &item.lo, &item.hi);
            let below = limit.min(best);
            if gap >= below {
                floor = floor.min(gap);
                continue;
            }
            // As `shape_distance_below`, counting the exact queries.
            let d = match &*item.shape {
                Obstacle::Nurbs(t) => {
                    let bound = t.piece_bound(p, below);
                    if bound >= below {
                        bound
                    } else {
                        self.count_query();
                        t.exact(p)
                    }
                }
                Obstacle::Mesh(m) => {
                    self.count_query();
                    m.distance_to_local_point(p, false)
                }
            };
            best = best.min(d);
        }
        best.min(floor)
    }
}

/// Most surfaces within the limit one query orders nearest first (beyond, the scan in order).
const NEAREST_CANDIDATES: usize = 32;

/// The slot of a query in the cache of recent queries.
fn recent_slot(generation: u64, key: &[u64; 4]) -> usize {
    let mut h = generation.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    for k in key {
        h = (h ^ k).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    }
    (h >> 32) as usize & (RECENT - 1)
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

/// The largest coordinate along `up` of the box `lo hi`, mm.
pub(super) fn top_along(lo: &Point3<f64>, hi: &Point3<f64>, up: &Vector3<f64>) -> f64 {
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

    /// A sheet-metal-like part: faces meeting at edges (a box of six planes, one face split in
    /// two coplanar halves), a cylinder, a sphere and a mesh, whose nearest surface is often
    /// one of two at exactly the same distance (points beyond an edge, over a split).
    fn part() -> Obstacles {
        let mut o = Obstacles::new();
        let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
        let at = Point3::new;
        for (origin, u, v, lu, lv) in [
            (at(0.0, 0.0, 0.0), x, y, 50.0, 80.0),
            (at(50.0, 0.0, 0.0), x, y, 50.0, 80.0),
            (at(0.0, 0.0, 30.0), x, y, 100.0, 80.0),
            (at(0.0, 0.0, 0.0), x, z, 100.0, 30.0),
            (at(0.0, 80.0, 0.0), x, z, 100.0, 30.0),
            (at(0.0, 0.0, 0.0), y, z, 80.0, 30.0),
            (at(100.0, 0.0, 0.0), y, z, 80.0, 30.0),
        ] {
            o.add_nurbs(NurbsSurface::plane(origin, u, v, lu, lv).unwrap());
        }
        o.add_nurbs(NurbsSurface::cylinder(at(100.0, 40.0, 45.0), y, 15.0, 40.0).unwrap());
        o.add_nurbs(NurbsSurface::sphere(at(30.0, 40.0, 50.0), 12.0).unwrap());
        o.add_mesh(
            vec![
                at(-20.0, 0.0, 0.0),
                at(-20.0, 80.0, 0.0),
                at(-20.0, 0.0, 30.0),
            ],
            vec![[0, 1, 2]],
        )
        .unwrap();
        o
    }

    /// The nearest-first query gives the scan in order's answer bit for bit, at points on a
    /// grid through the part's edges and faces (many at the same distance from two surfaces)
    /// and pseudo-random ones, for limits below, near and above the distances.
    #[test]
    fn nearest_first_answers_as_the_scan_in_order_bit_for_bit() {
        let o = part();
        let mut points = Vec::new();
        for i in -2..=14 {
            for j in -2..=11 {
                for k in -2i32..=7 {
                    points.push(Point3::new(
                        f64::from(i) * 10.0 - 10.0 * 0.5_f64.powi(k.abs()),
                        f64::from(j) * 10.0,
                        f64::from(k) * 7.5,
                    ));
                }
            }
        }
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..3000 {
            points.push(Point3::new(
                140.0 * next() - 20.0,
                120.0 * next() - 20.0,
                70.0 * next() - 20.0,
            ));
        }
        let mut below = 0;
        for p in &points {
            for limit in [0.5, 2.5, 5.0, 12.5, 40.0, f64::INFINITY] {
                let fast = o.distance_below_uncached(p, limit);
                let scan = o.distance_below_in_order(p, limit);
                assert_eq!(
                    fast.to_bits(),
                    scan.to_bits(),
                    "{p} below {limit}: {fast} {scan}"
                );
                below += usize::from(fast < limit);
            }
        }
        assert!(below > 10_000, "{below}");
    }
}
