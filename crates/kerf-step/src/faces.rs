//! B-rep faces: their boundary loops as NURBS curves, their surface as a NURBS surface cut to
//! the face's parameter range and oriented so that `Su x Sv` is the face's outward normal,
//! and the association of contours to faces by projection.

use std::f64::consts::TAU;

use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

use crate::curves::{basis, oriented_piece, Basis};
use crate::error::{Result, StepError};
use crate::model::{boolean, err, name_of, refs, Model};
use crate::parser::{Instance, Value};
use crate::surfaces::geometry;

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
}

impl Face {
    /// The face's entity number in its file.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The face's id in `kerf.curves/1` (`face #12`, `face D45`).
    pub fn label(&self) -> String {
        format!("face {}{}", self.sigil, self.id)
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

/// The faces of the file, in file order; a face that cannot be converted is returned as an
/// error message in the second list (it is skipped, not fatal).
///
/// With `only`, just the faces with those ids are read (the others cost nothing). A
/// [`StepError::Budget`] is fatal: it stops the import instead of skipping one face.
pub(crate) fn read_faces(m: &Model<'_>, only: Option<&[u64]>) -> Result<(Vec<Face>, Vec<String>)> {
    let flipped = oriented_face_flips(m)?;
    let mut faces = Vec::new();
    let mut skipped = Vec::new();
    let mut ids = m.ex.ids_of("ADVANCED_FACE");
    ids.extend(m.ex.ids_of("FACE_SURFACE"));
    if let Some(only) = only {
        ids.retain(|id| only.contains(id));
    }
    for id in ids {
        let Some(inst) = m.ex.get(id)? else { continue };
        let flip = flipped.contains(&inst.id);
        match face(m, &inst, flip) {
            Ok(f) => faces.push(f),
            Err(e @ StepError::Budget { .. }) => return Err(e),
            Err(e) => skipped.push(e.to_string()),
        }
    }
    Ok((faces, skipped))
}

/// The faces a shell uses through an `ORIENTED_FACE` with orientation `.F.` (reversed).
///
/// Only the `ORIENTED_FACE`s a shell lists count: one that nothing uses must not turn its face
/// (a file with such dangling entities on its walls had every scrap side reversed).
fn oriented_face_flips(m: &Model<'_>) -> Result<Vec<u64>> {
    let mut in_shells: std::collections::HashSet<u64> = std::collections::HashSet::new();
    for name in ["CLOSED_SHELL", "OPEN_SHELL"] {
        for s in m.all(name)? {
            if let Some(Value::List(items)) = s.record(name).and_then(|p| p.get(1)) {
                in_shells.extend(items.iter().filter_map(|v| match v {
                    Value::Ref(r) => Some(*r),
                    _ => None,
                }));
            }
        }
    }
    Ok(m.all("ORIENTED_FACE")?
        .into_iter()
        .filter(|i| in_shells.contains(&i.id))
        .filter_map(|i| {
            let p = i.record("ORIENTED_FACE")?;
            match (p.get(2), p.get(3)) {
                (Some(Value::Ref(f)), Some(Value::Enum(o))) if o == "F" => Some(*f),
                _ => None,
            }
        })
        .collect())
}

fn face(m: &Model<'_>, inst: &Instance, flip: bool) -> Result<Face> {
    let p = inst
        .record("ADVANCED_FACE")
        .or_else(|| inst.record("FACE_SURFACE"))
        .ok_or_else(|| err(inst, "expected a face"))?;
    let surf_inst = &m.param_ref(inst, p, 2)?;
    let same_sense = boolean(inst, p.get(3), "same_sense")?;
    let g = geometry(m, surf_inst).map_err(|e| err(inst, format!("face_geometry: {e}")))?;
    let mut loops = Vec::new();
    let mut edge_ids = Vec::new();
    let mut vertices: Vec<Point3<f64>> = Vec::new();
    for bid in refs(inst, p.get(1), "bounds")? {
        let b = &m.get(inst, bid)?;
        let bp = b
            .record("FACE_OUTER_BOUND")
            .or_else(|| b.record("FACE_BOUND"))
            .ok_or_else(|| err(b, "expected a FACE_BOUND"))?;
        let lp_inst = &m.param_ref(b, bp, 1)?;
        let orientation = boolean(b, bp.get(2), "orientation")?;
        if let Some(vl) = lp_inst.record("VERTEX_LOOP") {
            let v = &m.param_ref(lp_inst, vl, 1)?;
            vertices.push(vertex(m, v)?);
            continue;
        }
        let mut edges = edge_loop(m, lp_inst)?;
        if !orientation {
            edges = edges
                .into_iter()
                .rev()
                .map(|(id, c)| (id, c.reversed()))
                .collect();
        }
        edge_ids.push(edges.iter().map(|e| e.0).collect());
        loops.push(edges.into_iter().map(|e| e.1).collect());
    }
    let place = crate::StepPlace { m, inst };
    crate::cad::face(
        &place,
        "#",
        inst.id,
        name_of(inst),
        &g,
        loops,
        edge_ids,
        &vertices,
        None,
        same_sense == flip,
    )
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

fn vertex(m: &Model<'_>, v: &Instance) -> Result<Point3<f64>> {
    let p = m.rec(v, "VERTEX_POINT")?;
    m.point(&m.param_ref(v, p, 1)?)
}

/// The edges of an `EDGE_LOOP`, each as a NURBS curve running in loop order (each distinct
/// `EDGE_CURVE` converted once; a seam edge is used twice).
///
/// A loop runs each edge at most once in each direction (a seam: once each way); an edge
/// used again in the same direction is refused, so a loop repeating one edge thousands of
/// times costs one edge's work, not thousands, before it is refused; so a loop has at most
/// twice as many uses as distinct edges, and its boundary samples (every use, as before)
/// are bounded by the file's own edges.
fn edge_loop(m: &Model<'_>, inst: &Instance) -> Result<Vec<(u64, NurbsCurve)>> {
    let p = m.rec(inst, "EDGE_LOOP")?;
    let mut out = Vec::new();
    // (EDGE_CURVE id, its curve as the edge runs, directions used so far)
    let mut distinct: Vec<(u64, NurbsCurve, [bool; 2])> = Vec::new();
    for (k, oid) in refs(inst, p.get(1), "edge_list")?.into_iter().enumerate() {
        let oe = &m.get(inst, oid)?;
        let op = m.rec(oe, "ORIENTED_EDGE")?;
        let ec = &m.param_ref(oe, op, 3)?;
        let orientation = boolean(oe, op.get(4), "orientation")?;
        let d = match distinct.iter().position(|e| e.0 == ec.id) {
            Some(d) => d,
            None => {
                distinct.push((ec.id, edge_curve(m, ec)?, [false; 2]));
                distinct.len() - 1
            }
        };
        let used = &mut distinct[d].2[usize::from(orientation)];
        if *used {
            return Err(err(
                inst,
                format!(
                    "edge_list[{k}] (#{oid}) runs edge #{} a second time in the same direction: not a loop",
                    ec.id
                ),
            ));
        }
        *used = true;
        let c = &distinct[d].1;
        out.push((ec.id, if orientation { c.clone() } else { c.reversed() }));
    }
    Ok(out)
}

/// An `EDGE_CURVE` from its start vertex to its end vertex along its geometry.
pub(crate) fn edge_curve(m: &Model<'_>, inst: &Instance) -> Result<NurbsCurve> {
    let p = m.rec(inst, "EDGE_CURVE")?;
    let start = vertex(m, &m.param_ref(inst, p, 1)?)?;
    let end = vertex(m, &m.param_ref(inst, p, 2)?)?;
    let geom = &m.param_ref(inst, p, 3)?;
    let same = boolean(inst, p.get(4), "same_sense")?;
    let c = if geom.is("TRIMMED_CURVE") {
        crate::curves::trimmed(m, geom)?
    } else {
        let b = basis(m, geom).map_err(|e| err(inst, format!("edge_geometry: {e}")))?;
        let (ts, te) = (b.param_of(&start), b.param_of(&end));
        let closed = (start - end).norm() <= 1e-9 * (1.0 + start.coords.norm());
        match &b {
            Basis::Conic { .. } if closed => {
                let c = b.piece(inst, ts, ts + TAU)?;
                if same {
                    c
                } else {
                    c.reversed()
                }
            }
            Basis::Conic { .. } => {
                if same {
                    oriented_piece(inst, &b, ts, te, true)?
                } else {
                    oriented_piece(inst, &b, te, ts, true)?.reversed()
                }
            }
            Basis::Nurbs(c) if closed => {
                if same {
                    c.clone()
                } else {
                    c.reversed()
                }
            }
            _ => b.piece(inst, ts, te)?,
        }
    };
    Ok(c)
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
