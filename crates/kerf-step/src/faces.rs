//! STEP B-rep faces: their boundary loops as NURBS curves and their surface, built into
//! [`Face`]s by [`crate::cad::face`].

use std::f64::consts::TAU;

use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

use crate::curves::{basis, oriented_piece, Basis};
use crate::error::{Result, StepError};
use crate::model::{boolean, err, name_of, refs, Model};
use crate::parser::{Instance, Value};
use crate::shape::Face;
use crate::surfaces::sensed_geometry;

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
    let (g, turned) =
        sensed_geometry(m, surf_inst).map_err(|e| err(inst, format!("face_geometry: {e}")))?;
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
        &[],
        None,
        (same_sense == flip) ^ turned,
    )
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
