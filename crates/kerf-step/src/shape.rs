//! Faces as kerf builds them from any CAD format: a surface cut to its boundary loops
//! ([`face`]), the faces a contour lies on ([`associate`]), and edge ids for faces that share
//! no topology ([`sew`]). Public through [`crate::cad`].

use std::collections::HashMap;

use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

use crate::curves::ON_GEOMETRY_TOLERANCE_MM;
use crate::surfaces::{angle_range, Approximation, Geometry};

/// A surface's parameter box `((u0, u1), (v0, v1))`.
pub type ParamBox = ((f64, f64), (f64, f64));

/// Where the reader is working (the entity being converted): it names errors and pays for
/// projections from the reader's budget.
pub trait Place {
    /// The reader's error.
    type Error;
    /// An error naming this place, with `message` as the defect.
    fn defect(&self, message: String) -> Self::Error;
    /// Charges `n` point projections to the reader's budget before they are made.
    ///
    /// # Errors
    /// The reader's budget error once its budget is crossed.
    fn charge(&self, n: usize) -> Result<(), Self::Error>;
}

/// Builds a face: the surface `g` cut to the parameter range its boundary covers (every
/// boundary sample, 181 per edge, mapped to natural parameters; an angle range
/// that leaves less than 3 degrees out is the full turn), each edge checked to lie on the cut
/// surface within [`ON_GEOMETRY_TOLERANCE_MM`], `Su x Sv` reversed when `reversed`.
///
/// `sigil` and `id` name the face (`face #12` for STEP, `face D45` for IGES); `edge_ids[l][k]`
/// names edge `k` of loop `l` (the same id in two faces is the edge they share; give distinct
/// ids where the format has no shared edges). `vertices` are boundary points of vertex loops.
/// `params` are boundary points already in the surface's natural parameters, where the format
/// gives them (an IGES boundary's parameter-space curve on a B-spline surface, which the file
/// may prefer to its model-space curve): the range covers them too.
/// `natural` is the surface's own parameter box where the format gives one (an IGES surface
/// of revolution's start and end angles): a direction in which the boundary samples span
/// nothing (a whole sphere bounded by its seam, run down and back) takes its range from it.
///
/// # Errors
/// `place`'s defect for a face without a boundary edge, an empty range, an edge off the
/// surface; `place`'s budget error.
#[allow(clippy::too_many_arguments)]
pub fn face<P: Place>(
    place: &P,
    sigil: &'static str,
    id: u64,
    name: String,
    g: &Geometry,
    loops: Vec<Vec<NurbsCurve>>,
    edge_ids: Vec<Vec<u64>>,
    vertices: &[Point3<f64>],
    params: &[(f64, f64)],
    natural: Option<ParamBox>,
    reversed: bool,
) -> Result<Face, P::Error> {
    use std::f64::consts::{FRAC_PI_2, TAU};
    // The parameter range: every boundary sample mapped to natural parameters.
    let mut us = Vec::new();
    let mut vs = Vec::new();
    let mut add = |q: &Point3<f64>, warm: &mut Option<(f64, f64)>| {
        let (u, v) = g.params_near(q, warm);
        us.push(u);
        vs.push(v);
    };
    let uses: usize = loops.iter().map(Vec::len).sum();
    place.charge(uses * EDGE_SAMPLES)?;
    for l in &loops {
        // Each sample's projection starts from its neighbour's parameters (an edge's first
        // from the previous edge's last: a loop's edges join end to start).
        let mut warm = None;
        for e in l {
            let (a, b) = e.domain();
            for k in 0..EDGE_SAMPLES {
                add(
                    &e.point(a + (b - a) * k as f64 / (EDGE_SAMPLES - 1) as f64),
                    &mut warm,
                );
            }
        }
    }
    for q in vertices {
        add(q, &mut None);
    }
    for &(u, v) in params {
        us.push(u);
        vs.push(v);
    }
    let (pu, pv) = g.periodic();
    let whole = loops.is_empty();
    if whole && !matches!(g, Geometry::Sphere(..) | Geometry::Torus(..)) {
        return Err(place.defect("a face without a boundary edge".into()));
    }
    let range = |x: &[f64], periodic: bool| {
        if periodic {
            angle_range(x, FULL_TURN_GAP)
        } else {
            let lo = x.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (lo, hi)
        }
    };
    // A sphere or torus bounded by vertex loops only (as Open CASCADE writes a whole sphere)
    // is the whole closed surface.
    let mut u = if whole { (0.0, TAU) } else { range(&us, pu) };
    let mut v = match (g, whole) {
        (Geometry::Sphere(..), true) => (-FRAC_PI_2, FRAC_PI_2),
        (_, true) => (0.0, TAU),
        _ => range(&vs, pv),
    };
    if let Some((nu, nv)) = natural {
        if !(u.1 - u.0 > 1e-12) {
            u = nu;
        }
        if !(v.1 - v.0 > 1e-12) {
            v = nv;
        }
    }
    if let Some(s) = g.nurbs_domain() {
        // Parameters come from projection: keep them inside the domain.
        let (a, b) = s.domain_u();
        let (c, d) = s.domain_v();
        u = (u.0.max(a), u.1.min(b));
        v = (v.0.max(c), v.1.min(d));
        // Within rounding of the whole domain: the whole domain (no knot insertion).
        let near = |x: f64, y: f64, span: f64| (x - y).abs() <= 1e-9 * span.max(1.0);
        if near(u.0, a, b - a) {
            u.0 = a;
        }
        if near(u.1, b, b - a) {
            u.1 = b;
        }
        if near(v.0, c, d - c) {
            v.0 = c;
        }
        if near(v.1, d, d - c) {
            v.1 = d;
        }
    }
    if let Geometry::Sphere(..) = g {
        // A cap bounded by one circle has its pole inside: the boundary alone shows no v
        // extent. Not resolved here.
        if v.1 - v.0 < 1e-9 {
            return Err(place.defect(
                "a spherical face whose boundary does not reach its pole is not supported".into(),
            ));
        }
    }
    // An approximation's work is charged after it is done (it has a budget of its own), and
    // also where it failed: the reader's budget then bounds a file of many offset faces.
    let charge = |work: usize| place.charge(work.saturating_mul(PROJECTIONS_PER_OFFSET_CELL));
    let (mut surface, approximation) = match g.to_nurbs_bounded(u, v) {
        Ok(x) => x,
        Err(e) => {
            if let crate::surfaces::SurfaceRangeError::Offset(o) = &e {
                charge(o.work())?;
            }
            return Err(place.defect(e.to_string()));
        }
    };
    if let Some(a) = approximation {
        charge(a.work)?;
    }
    edges_on_surface(place, sigil, &surface, g.kind(), &loops, &edge_ids)?;
    if reversed {
        surface = reverse_u(&surface);
    }
    Ok(Face {
        sigil,
        id,
        name,
        kind: g.kind(),
        surface,
        loops,
        edge_ids,
        instance: None,
        approximation,
    })
}

/// Every edge of a face lies on the face's surface, within [`ON_GEOMETRY_TOLERANCE_MM`]:
/// [`EDGE_CHECK_SAMPLES`] points inside each edge use (the ends are vertices the neighbouring
/// edges share) projected onto the surface.
///
/// A file whose edge runs off its face (an inconsistent wall, a face given the wrong plane)
/// would otherwise get the face's parameter range from points that are not on it and its
/// normal, which decides the scrap side of a cut, from the wrong place. The face is refused
/// naming the edge and the distance (the caller skips it and says why).
fn edges_on_surface<P: Place>(
    place: &P,
    sigil: &str,
    surface: &NurbsSurface,
    kind: &str,
    loops: &[Vec<NurbsCurve>],
    edge_ids: &[Vec<u64>],
) -> Result<(), P::Error> {
    let uses: usize = loops.iter().map(Vec::len).sum();
    place.charge(uses * EDGE_CHECK_SAMPLES)?;
    for (l, ids) in loops.iter().zip(edge_ids) {
        for (e, id) in l.iter().zip(ids) {
            let (a, b) = e.domain();
            let mut warm = None;
            for k in 0..EDGE_CHECK_SAMPLES {
                let t = a + (b - a) * (k as f64 + 0.5) / EDGE_CHECK_SAMPLES as f64;
                let q = e.point(t);
                let pr = surface.closest_point(&q, warm);
                warm = Some((pr.u, pr.v));
                // NaN fails the comparison and is refused too.
                if !(pr.distance <= ON_GEOMETRY_TOLERANCE_MM) {
                    return Err(place.defect(format!(
                        "edge {sigil}{id} lies {:.6} mm off the face's {kind} at ({:.6}, {:.6}, {:.6}) (at most {ON_GEOMETRY_TOLERANCE_MM} mm): the edge does not bound this face",
                        pr.distance, q.x, q.y, q.z
                    )));
                }
            }
        }
    }
    Ok(())
}

/// Edge ids for faces that share no topology (an IGES file's trimmed surfaces each carry their
/// own copy of every edge): two edges of `loops` (per face, its loops, each its edges) are one
/// edge where their ends meet within `tolerance` mm (either way round) and three interior
/// points of the one (at a quarter, half and three quarters of its parameter range) lie within
/// `tolerance` of the other. A seam is an edge its own face uses twice.
///
/// `ids` proposes an id per edge (the curve's entity number); each group of coincident edges
/// takes its first member's, or a number above every proposed id where that is taken by
/// another group, so that ids are equal exactly for coincident edges. Candidates come from a
/// grid of the ends (cells of `2 tolerance`); each interior test, and every 16 candidates, is
/// charged to `charge` (face index, tests) before it is made.
///
/// # Errors
/// What `charge` returns.
pub fn sew<E>(
    loops: &[&[Vec<NurbsCurve>]],
    ids: &[Vec<Vec<u64>>],
    tolerance: f64,
    mut charge: impl FnMut(usize, usize) -> Result<(), E>,
) -> Result<Vec<Vec<Vec<u64>>>, E> {
    // Every edge: (face, loop, position), its ends.
    let mut edges: Vec<(usize, usize, usize)> = Vec::new();
    let mut ends: Vec<(Point3<f64>, Point3<f64>)> = Vec::new();
    for (f, face) in loops.iter().enumerate() {
        for (l, lp) in face.iter().enumerate() {
            for (k, e) in lp.iter().enumerate() {
                let (a, b) = e.domain();
                edges.push((f, l, k));
                ends.push((e.point(a), e.point(b)));
            }
        }
    }
    let tol = tolerance.max(1e-12);
    let cell = 2.0 * tol;
    let key = |p: &Point3<f64>| {
        let c = |x: f64| (x / cell).floor().clamp(-1e15, 1e15) as i64;
        (c(p.x), c(p.y), c(p.z))
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (i, (s, _)) in ends.iter().enumerate() {
        grid.entry(key(s)).or_default().push(i);
    }
    let mut parent: Vec<usize> = (0..edges.len()).collect();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    let curve = |i: usize| {
        let (f, l, k) = edges[i];
        &loops[f][l][k]
    };
    for i in 0..edges.len() {
        let (s, e) = ends[i];
        // Edges whose start is near this one's start or end.
        let mut near: Vec<usize> = Vec::new();
        for q in [s, e] {
            let (x, y, z) = key(&q);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(v) = grid.get(&(x + dx, y + dy, z + dz)) {
                            near.extend(v.iter().copied().filter(|&j| j > i));
                        }
                    }
                }
            }
        }
        near.sort_unstable();
        near.dedup();
        // Every candidate is paid for (an end test costs little, but a file of a thousand edges
        // from one point would otherwise ask for a million of them unpaid).
        charge(edges[i].0, near.len().div_ceil(16))?;
        for j in near {
            if root(&mut parent, i) == root(&mut parent, j) {
                continue;
            }
            let (s2, e2) = ends[j];
            let same = (s - s2).norm() <= tol && (e - e2).norm() <= tol;
            let reverse = (s - e2).norm() <= tol && (e - s2).norm() <= tol;
            if !(same || reverse) {
                continue;
            }
            charge(edges[i].0, 3)?;
            let (a, b) = curve(i).domain();
            let other = curve(j);
            let on = [0.25, 0.5, 0.75].iter().all(|&w| {
                let p = curve(i).point(a + (b - a) * w);
                (other.point(other.closest_point(&p).t) - p).norm() <= tol
            });
            if on {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[rj.max(ri)] = ri.min(rj);
            }
        }
    }
    // Ids: a group's first member's proposal, unless another group has it.
    let proposed = |i: usize| {
        let (f, l, k) = edges[i];
        ids.get(f)
            .and_then(|x| x.get(l))
            .and_then(|x| x.get(k))
            .copied()
            .unwrap_or(0)
    };
    let mut fresh = (0..edges.len()).map(proposed).max().unwrap_or(0);
    let mut taken: HashMap<u64, usize> = HashMap::new();
    let mut group_id: HashMap<usize, u64> = HashMap::new();
    let mut out: Vec<Vec<Vec<u64>>> = loops
        .iter()
        .map(|face| face.iter().map(|lp| vec![0; lp.len()]).collect())
        .collect();
    for i in 0..edges.len() {
        let r = root(&mut parent, i);
        let id = *group_id.entry(r).or_insert_with(|| {
            let want = proposed(r);
            match taken.get(&want) {
                Some(&g) if g != r => {
                    fresh += 1;
                    taken.insert(fresh, r);
                    fresh
                }
                _ => {
                    taken.insert(want, r);
                    want
                }
            }
        });
        let (f, l, k) = edges[i];
        out[f][l][k] = id;
    }
    Ok(out)
}

/// Samples per edge for the parameter range (2 degrees apart on a full circle).
pub(crate) const EDGE_SAMPLES: usize = 181;

/// A gap between boundary angles below this (3 degrees) means the face turns all the way
/// round (a full cylinder, a torus tube).
pub(crate) const FULL_TURN_GAP: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// One face, converted ([`crate::cad::face`]): its surface cut to its boundary, `Su x Sv`
/// outward, and its boundary loops.
#[derive(Debug, Clone)]
pub struct Face {
    /// How the format writes an entity number (`#` in STEP, `D` in IGES).
    pub(crate) sigil: &'static str,
    /// The entity number of the face (STEP: the `ADVANCED_FACE` or `FACE_SURFACE`).
    pub(crate) id: u64,
    /// Its name attribute.
    pub(crate) name: String,
    /// The kind of its surface (`plane`, `cylinder`, ...).
    pub(crate) kind: &'static str,
    /// The surface over the face's parameter range, `Su x Sv` outward.
    pub(crate) surface: NurbsSurface,
    /// The boundary loops (outer first where marked), each as its edges in loop order.
    pub(crate) loops: Vec<Vec<NurbsCurve>>,
    /// The `EDGE_CURVE` `#id` of each edge of `loops` (the same edge in two faces' loops is
    /// the edge they share).
    pub(crate) edge_ids: Vec<Vec<u64>>,
    /// Which instance of its part this is, where the part is placed more than once (1, 2, ...).
    pub(crate) instance: Option<usize>,
    /// Where the surface approximates the file's (the offset of a B-spline surface): what is
    /// proven about it.
    pub(crate) approximation: Option<Approximation>,
}

/// How many point projections one bicubic cell of an offset's approximation is charged as
/// (about the time of 6-8 cold projections onto the same surface: docs/performance.md, the
/// `offset_cost` example of kerf-nurbs).
pub const PROJECTIONS_PER_OFFSET_CELL: usize = 6;

impl Face {
    /// The face's entity number in its file.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The face's entity as the file writes it, with its instance where its part is placed
    /// more than once: `#12`, `#12@2`, `D45`.
    pub fn tag(&self) -> String {
        match self.instance {
            None => format!("{}{}", self.sigil, self.id),
            Some(k) => format!("{}{}@{k}", self.sigil, self.id),
        }
    }

    /// The face's id in `kerf.curves/1` (`face #12`, `face #12@2`, `face D45`).
    pub fn label(&self) -> String {
        format!("face {}", self.tag())
    }

    /// The face moved by the rigid map `x -> r x + t` (exact: the control points of a NURBS
    /// surface or curve move, its weights stay), as instance `instance` of its part, each edge
    /// id or-ed with `edge_tag` (the instance in the top bits: two instances share no edge).
    pub(crate) fn moved(
        &self,
        r: &nalgebra::Matrix3<f64>,
        t: &Vector3<f64>,
        instance: Option<usize>,
        edge_tag: u64,
    ) -> Face {
        let map = |p: &Point3<f64>| Point3::from(r * p.coords + t);
        let s = &self.surface;
        let surface = NurbsSurface::try_new(
            s.degree_u(),
            s.degree_v(),
            s.knots_u().to_vec(),
            s.knots_v().to_vec(),
            s.control_points()
                .iter()
                .map(|row| row.iter().map(map).collect())
                .collect(),
            s.is_rational().then(|| s.weights()),
        )
        .unwrap_or_else(|_| s.clone());
        let loops = self
            .loops
            .iter()
            .map(|l| l.iter().map(|c| moved_curve(c, &map)).collect())
            .collect();
        Face {
            sigil: self.sigil,
            id: self.id,
            name: self.name.clone(),
            kind: self.kind,
            surface,
            loops,
            edge_ids: self
                .edge_ids
                .iter()
                .map(|l| l.iter().map(|e| e | edge_tag).collect())
                .collect(),
            instance,
            approximation: self.approximation,
        }
    }

    /// The surface, cut to the face's parameter range, `Su x Sv` outward, mm.
    pub fn surface(&self) -> &NurbsSurface {
        &self.surface
    }

    /// The boundary loops, each as its edges in loop order.
    pub fn loops(&self) -> &[Vec<NurbsCurve>] {
        &self.loops
    }
}

/// Where an edge id keeps the instance of its part (assemblies): bits 48 and up.
pub(crate) const INSTANCE_SHIFT: u32 = 48;

/// An edge id as the file writes it: `#47`, or `#47@2` for the second instance of its part.
pub(crate) fn edge_tag(sigil: &str, e: u64) -> String {
    let k = e >> INSTANCE_SHIFT;
    let id = e & ((1u64 << INSTANCE_SHIFT) - 1);
    if k == 0 {
        format!("{sigil}{id}")
    } else {
        format!("{sigil}{id}@{k}")
    }
}

/// A curve with its control points mapped by `map` (an affine map: exact), weights kept.
pub(crate) fn moved_curve(
    c: &NurbsCurve,
    map: &impl Fn(&Point3<f64>) -> Point3<f64>,
) -> NurbsCurve {
    NurbsCurve::try_new(
        c.degree(),
        c.knots().to_vec(),
        c.control_points().iter().map(map).collect(),
        c.is_rational().then(|| c.weights()),
    )
    .unwrap_or_else(|_| c.clone())
}

/// Samples of each edge use checked against its face's surface.
pub(crate) const EDGE_CHECK_SAMPLES: usize = 5;

/// The same surface with u reversed: `Su x Sv` flips.
pub(crate) fn reverse_u(s: &NurbsSurface) -> NurbsSurface {
    let (nu, nv) = s.net_size();
    let (a, b) = s.domain_u();
    let ku: Vec<f64> = s.knots_u().iter().rev().map(|k| a + b - k).collect();
    let pts: Vec<Vec<Point3<f64>>> = s.control_points().into_iter().rev().collect();
    let w: Vec<Vec<f64>> = s.weights().into_iter().rev().collect();
    let _ = (nu, nv);
    NurbsSurface::try_new(
        s.degree_u(),
        s.degree_v(),
        ku,
        s.knots_v().to_vec(),
        pts,
        Some(w),
    )
    .unwrap_or_else(|_| s.clone())
}

/// Which faces a contour lies on: sample it densely, keep the faces within `tolerance` mm of
/// some sample, and choose greedily the fewest faces that together are within tolerance of
/// every sample. `Ok(Err(worst))` if some sample is farther than `tolerance` from every face
/// (the contour is not on the part), with the worst distance.
///
/// Only the faces whose box, widened by `tolerance`, meets the samples' box are looked at,
/// each surface once (`same_as`: [`first_with_same_surface`]), and only the samples inside a
/// face's widened box are projected onto it; `charge` is told how many projections the contour
/// will cost before any is made (the reader's budget: a file of a thousand faces over one plane
/// and a thousand contours asked for 2e8 projections and took minutes).
///
/// # Errors
/// What `charge` returns (a budget crossed).
pub(crate) fn associate<E>(
    curve: &NurbsCurve,
    faces: &[Face],
    same_as: &[usize],
    tolerance: f64,
    mut charge: impl FnMut(usize) -> std::result::Result<(), E>,
) -> std::result::Result<std::result::Result<Vec<usize>, f64>, E> {
    let samples = sample(curve);
    let (mut clo, mut chi) = (samples[0], samples[0]);
    for p in &samples {
        for i in 0..3 {
            clo[i] = clo[i].min(p[i]);
            chi[i] = chi[i].max(p[i]);
        }
    }
    // The faces to look at (their widened box meets the samples' box, and no earlier face has
    // the same surface), and the projections they cost, charged before any is made.
    let widened = |f: &Face| {
        let (lo, hi) = f.surface.bounding_box();
        (
            lo - Vector3::repeat(tolerance),
            hi + Vector3::repeat(tolerance),
        )
    };
    let inside = |p: &Point3<f64>, (lo, hi): &(Point3<f64>, Point3<f64>)| {
        (0..3).all(|i| p[i] >= lo[i] && p[i] <= hi[i])
    };
    let boxes: Vec<Option<(Point3<f64>, Point3<f64>)>> = faces
        .iter()
        .enumerate()
        .map(|(fi, f)| {
            let b = widened(f);
            let apart = (0..3).any(|i| clo[i] > b.1[i] || chi[i] < b.0[i]);
            (same_as[fi] == fi && !apart).then_some(b)
        })
        .collect();
    let cost: usize = boxes
        .iter()
        .flatten()
        .map(|b| samples.iter().filter(|p| inside(p, b)).count())
        .sum();
    charge(cost)?;
    // near[f][k]: face f is within tolerance of sample k.
    let mut near: Vec<Vec<bool>> = Vec::with_capacity(faces.len());
    let mut best = vec![f64::INFINITY; samples.len()];
    for (fi, f) in faces.iter().enumerate() {
        if same_as[fi] != fi {
            // The same surface as an earlier face: the same distances (a file that repeats one
            // face a thousand times costs one face's projections).
            near.push(near[same_as[fi]].clone());
            continue;
        }
        let mut row = vec![false; samples.len()];
        let Some(b) = &boxes[fi] else {
            near.push(row);
            continue;
        };
        let mut warm = None;
        for (k, p) in samples.iter().enumerate() {
            if !inside(p, b) {
                warm = None;
                continue;
            }
            let pr = f.surface.closest_point(p, warm);
            warm = Some((pr.u, pr.v));
            best[k] = best[k].min(pr.distance);
            row[k] = pr.distance <= tolerance;
        }
        near.push(row);
    }
    let worst = best.iter().copied().fold(0.0, f64::max);
    if worst > tolerance {
        return Ok(Err(worst));
    }
    let mut covered = vec![false; samples.len()];
    let mut chosen = Vec::new();
    while covered.iter().any(|c| !c) {
        let (f, gain) = near
            .iter()
            .enumerate()
            .map(|(f, row)| {
                (
                    f,
                    row.iter()
                        .zip(&covered)
                        .filter(|(n, c)| **n && !**c)
                        .count(),
                )
            })
            .max_by_key(|&(f, g)| (g, std::cmp::Reverse(f)))
            .unwrap_or((0, 0));
        if gain == 0 {
            break;
        }
        chosen.push(f);
        for (c, n) in covered.iter_mut().zip(&near[f]) {
            *c |= *n;
        }
    }
    chosen.sort_unstable();
    Ok(Ok(chosen))
}

/// For each face, the first face with the same surface (itself if none): the association
/// projects onto each surface once.
pub fn first_with_same_surface(faces: &[Face]) -> Vec<usize> {
    let mut first: std::collections::HashMap<Vec<u64>, usize> = std::collections::HashMap::new();
    faces
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let s = &f.surface;
            let mut key: Vec<u64> = vec![s.degree_u() as u64, s.degree_v() as u64];
            key.extend(s.knots_u().iter().chain(s.knots_v()).map(|v| v.to_bits()));
            for (row, w) in s.control_points().iter().zip(s.weights()) {
                for (p, w) in row.iter().zip(w) {
                    key.extend([p.x.to_bits(), p.y.to_bits(), p.z.to_bits(), w.to_bits()]);
                }
            }
            *first.entry(key).or_insert(i)
        })
        .collect()
}

/// Dense samples of a curve: 16 per knot span and at least 200.
pub(crate) fn sample(curve: &NurbsCurve) -> Vec<Point3<f64>> {
    let spans = curve.spans();
    let per = (200 / spans.len().max(1)).max(16);
    let mut out = Vec::with_capacity(spans.len() * per + 1);
    for (_, a, b) in &spans {
        for k in 0..per {
            out.push(curve.point(a + (b - a) * k as f64 / per as f64));
        }
    }
    out.push(curve.point(curve.domain().1));
    out
}
