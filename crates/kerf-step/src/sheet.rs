//! Sheet recognition for `--edges`: a solid sheet-metal part as one sheet with its
//! through-features, each cut once.
//!
//! A sheet-metal solid is two *sides* (the faces of the sheet, flat and bent, each side one
//! smooth surface: its faces meet tangentially at the bends) joined by *walls* as wide as the
//! sheet is thick (the edge faces of the outline, the walls of holes and cut-outs), which meet
//! the sides at sharp edges. Every through-feature is a closed chain of sharp edges between one
//! side and the walls, with a twin chain on the other side. kerf cuts each chain of the chosen
//! side once, on that side's faces (the beam along their normal, through the sheet), with the
//! scrap where the wall's outward normal points; a stretch where that side faces down is cut on
//! its twin instead, from the other side, which faces up there. The derivation and its limits are in
//! `docs/step.md` ("Sheet-metal solids").

use std::collections::HashMap;

use kerf_nurbs::{distance_to_box, NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

use crate::shape::Face;

/// Largest angle between the two faces' outward normals along an edge for the faces to meet
/// tangentially (a bend's edge, the same side of the sheet), degrees. Sheet-metal bends are
/// tangent to within the file's precision; walls meet the sides at tens of degrees.
pub(crate) const SMOOTH_DEG: f64 = 2.0;

/// Points per edge where the faces' normals are compared.
const EDGE_TESTS: usize = 3;

/// Points per feature edge where the distance to the other side is measured.
const THICKNESS_TESTS: usize = 4;

/// Largest angle between a side's normal and the direction to the other side's nearest point
/// for that point to be the twin across the thickness, degrees.
const AXIAL_DEG: f64 = 5.0;

/// Relative spread of the thickness over the features' edges above which the part is not taken
/// for one sheet of constant thickness (beyond `THICKNESS_SLACK_MM`).
const THICKNESS_SPREAD: f64 = 0.02;
/// Largest distance, as a share of the thickness (plus `THICKNESS_SLACK_MM`), of a feature
/// point moved the thickness through the sheet from an edge of the other side: 1 % (a wall 0.6
/// degrees off square).
const TWIN_SLACK: f64 = 0.01;

/// Absolute slack of the thickness, mm (file precision).
const THICKNESS_SLACK_MM: f64 = 1e-3;

/// Which side of a contour is scrap, seen along it with the face's normal toward the viewer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ScrapSide {
    Left,
    Right,
}

/// One through-feature: a closed chain of sharp edges between the cut side and the walls.
pub(crate) struct Feature {
    /// The chain's edges as the side's face loops run them (material on the left).
    pub(crate) edges: Vec<NurbsCurve>,
    /// The faces of the cut side it runs along (indices into the faces), in order of first use.
    pub(crate) faces: Vec<usize>,
    /// The face of the cut side each edge bounds.
    pub(crate) edge_faces: Vec<usize>,
    /// The face loops the chain takes edges from, `(face index, loop index)`.
    pub(crate) loops: Vec<(usize, usize)>,
    /// The faces of the other side its twin chain runs along.
    pub(crate) twin_faces: Vec<usize>,
    /// Where the scrap is.
    pub(crate) scrap: ScrapSide,
    /// Length of the chain, mm.
    pub(crate) length_mm: f64,
    /// The chain cut into pieces whose side's normals face one way along z (indices into
    /// `edges`, in chain order): one piece for a feature the head reaches from one side, more
    /// where the side's normal turns from up to down (a flange's lip): each piece is then an
    /// open contour.
    pub(crate) pieces: Vec<Vec<usize>>,
    /// Which way each piece's side normals face along z: +1 up, -1 down, 0 sideways.
    pub(crate) facing: Vec<i8>,
    /// For each piece, the stretch of the twin chain behind it where the piece faces down:
    /// what is cut instead, from the other side of the sheet, which faces up there.
    pub(crate) twins: Vec<Option<Twin>>,
}

/// The stretch of a feature's twin chain (on the other side of the sheet) behind one of its
/// pieces, as the other side's loops run it.
pub(crate) struct Twin {
    /// The edges (the first and last cut where the piece's ends lie behind them).
    pub(crate) edges: Vec<NurbsCurve>,
    /// The face of the other side each edge bounds.
    pub(crate) edge_faces: Vec<usize>,
}

/// A recognised sheet.
pub struct Sheet {
    /// Thickness, mm (the median of the features' distances to the other side).
    pub(crate) thickness_mm: f64,
    /// The faces of the side that is cut (its normals point toward the head).
    pub(crate) side: Vec<usize>,
    /// The faces of the other side.
    pub(crate) other: Vec<usize>,
    /// The wall faces.
    pub(crate) walls: Vec<usize>,
    /// The features, longest first.
    pub(crate) features: Vec<Feature>,
}

/// One use of an edge by a face loop.
#[derive(Clone, Copy)]
struct Use {
    face: usize,
    lp: usize,
    pos: usize,
}

/// Recognises the faces as one sheet, or says why they are not (the caller then cuts every face
/// loop as before).
///
/// The work is charged to the reader's face-test budget: `EDGE_TESTS` x 2 projections per
/// edge and `THICKNESS_TESTS` per feature edge and nearby face of the other side.
///
/// # Errors
/// Only what `charge` returns (the reader's budget, charged per face index); a part that is
/// not a sheet is `Ok(Err(reason))`.
pub(crate) fn recognise<E>(
    faces: &[Face],
    charge: impl Fn(usize, usize) -> std::result::Result<(), E>,
) -> std::result::Result<std::result::Result<Sheet, String>, E> {
    if faces.len() < 4 {
        return Ok(Err(format!(
            "{} faces: a sheet has at least four",
            faces.len()
        )));
    }
    // Every edge's uses.
    let mut uses: HashMap<u64, Vec<Use>> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        for (lp, ids) in face.edge_ids.iter().enumerate() {
            for (pos, &e) in ids.iter().enumerate() {
                uses.entry(e).or_default().push(Use { face: f, lp, pos });
            }
        }
    }
    let mut edges: Vec<(u64, Vec<Use>)> = uses.into_iter().collect();
    edges.sort_unstable_by_key(|e| e.0);
    // Regions of faces joined by tangent edges (union-find).
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    fn root(parent: &mut [usize], mut a: usize) -> usize {
        while parent[a] != a {
            parent[a] = parent[parent[a]];
            a = parent[a];
        }
        a
    }
    let mut sharp: Vec<(u64, Use, Use)> = Vec::new();
    for (id, u) in &edges {
        match u.as_slice() {
            [a, b] if a.face == b.face => {} // a seam: inside the face
            [a, b] => {
                charge(a.face, 2 * EDGE_TESTS)?;
                let curve = &faces[a.face].loops[a.lp][a.pos];
                if tangent(curve, &faces[a.face].surface, &faces[b.face].surface) {
                    let (ra, rb) = (root(&mut parent, a.face), root(&mut parent, b.face));
                    parent[ra] = rb;
                } else {
                    sharp.push((*id, *a, *b));
                }
            }
            other => {
                let names: Vec<String> = other.iter().map(|u| faces[u.face].label()).collect();
                return Ok(Err(format!(
                    "edge {} bounds {} face loops ({}): not a closed solid (each edge bounds two)",
                    crate::shape::edge_tag(faces[other[0].face].sigil, *id),
                    other.len(),
                    names.join(", ")
                )));
            }
        }
    }
    let region: Vec<usize> = (0..faces.len()).map(|f| root(&mut parent, f)).collect();
    // Each region's area and area-weighted normal.
    let mut area: HashMap<usize, (f64, Vector3<f64>)> = HashMap::new();
    for (f, face) in faces.iter().enumerate() {
        let (a, n) = area_and_normal(&face.surface);
        let e = area.entry(region[f]).or_insert((0.0, Vector3::zeros()));
        e.0 += a;
        e.1 += n;
    }
    let mut by_area: Vec<(usize, f64, Vector3<f64>)> =
        area.iter().map(|(&r, &(a, n))| (r, a, n)).collect();
    by_area.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
    if by_area.len() < 3 {
        return Ok(Err(format!(
            "{} smooth regions: a sheet has two sides and walls",
            by_area.len()
        )));
    }
    // The two largest regions are the sides; the cut side is the one facing +z most.
    let (mut a, mut b) = (by_area[0], by_area[1]);
    if b.2.z > a.2.z {
        std::mem::swap(&mut a, &mut b);
    }
    let (ra, rb) = (a.0, b.0);
    let class = |f: usize| {
        if region[f] == ra {
            0
        } else if region[f] == rb {
            1
        } else {
            2
        }
    };
    // Every wall region touches both sides; no edge joins the two sides.
    let mut touches: HashMap<usize, [bool; 2]> = HashMap::new();
    for (id, x, y) in &sharp {
        match (class(x.face), class(y.face)) {
            (0, 1) | (1, 0) => {
                return Ok(Err(format!(
                    "edge {} joins {} and {} of the two sides directly",
                    crate::shape::edge_tag(faces[x.face].sigil, *id),
                    faces[x.face].label(),
                    faces[y.face].label()
                )));
            }
            (s @ (0 | 1), 2) => touches.entry(region[y.face]).or_default()[s] = true,
            (2, s @ (0 | 1)) => touches.entry(region[x.face]).or_default()[s] = true,
            _ => {}
        }
    }
    for (f, face) in faces.iter().enumerate() {
        if class(f) == 2 && touches.get(&region[f]).is_none_or(|t| !(t[0] && t[1])) {
            return Ok(Err(format!(
                "{} is neither side of a sheet nor a wall between them",
                face.label()
            )));
        }
    }
    // The chains: sharp edges between a side and a wall, as the side's loops run them.
    let chains = |s: usize| -> std::result::Result<Vec<Vec<Use>>, String> {
        let mut on: Vec<Use> = sharp
            .iter()
            .filter_map(|(_, x, y)| match (class(x.face), class(y.face)) {
                (c, 2) if c == s => Some(*x),
                (2, c) if c == s => Some(*y),
                _ => None,
            })
            .collect();
        on.sort_by_key(|u| (u.face, u.lp, u.pos));
        chain(faces, on)
    };
    let ours = match chains(0) {
        Ok(c) => c,
        Err(e) => return Ok(Err(e)),
    };
    let theirs = match chains(1) {
        Ok(c) => c,
        Err(e) => return Ok(Err(e)),
    };
    if ours.is_empty() || ours.len() != theirs.len() {
        return Ok(Err(format!(
            "{} edge chains on one side, {} on the other: not one sheet",
            ours.len(),
            theirs.len()
        )));
    }
    let side: Vec<usize> = (0..faces.len()).filter(|&f| class(f) == 0).collect();
    let other: Vec<usize> = (0..faces.len()).filter(|&f| class(f) == 1).collect();
    let walls: Vec<usize> = (0..faces.len()).filter(|&f| class(f) == 2).collect();
    // The thickness: every feature edge's distance to the other side, along the side's normal
    // (a face of the other side nearer in another direction, an untrimmed surface reaching
    // round a corner, is not the twin).
    let boxes: Vec<(Point3<f64>, Point3<f64>)> = other
        .iter()
        .map(|&f| faces[f].surface.bounding_box())
        .collect();
    let along = AXIAL_DEG.to_radians().cos();
    let mut thickness: Vec<f64> = Vec::new();
    let mut samples = 0usize;
    for c in &ours {
        for u in c {
            let e = &faces[u.face].loops[u.lp][u.pos];
            let (t0, t1) = e.domain();
            for k in 0..THICKNESS_TESTS {
                samples += 1;
                let p = e.point(t0 + (t1 - t0) * (k as f64 + 0.5) / THICKNESS_TESTS as f64);
                let Some(n) = normal_at(&faces[u.face].surface, &p) else {
                    continue;
                };
                // The boxes' distances, charged at 1/64 of a projection each (a box test costs
                // about that): a sheet of thousands of faces stays far below the budget, a
                // hostile one crosses it in bounded time.
                charge(u.face, boxes.len().div_ceil(64))?;
                let mut best = f64::INFINITY;
                let mut order: Vec<(f64, usize)> = boxes
                    .iter()
                    .enumerate()
                    .map(|(i, (lo, hi))| (distance_to_box(&p, lo, hi), i))
                    .collect();
                order.sort_by(|x, y| x.0.total_cmp(&y.0));
                for (gap, i) in order {
                    if gap >= best {
                        break;
                    }
                    charge(other[i], 1)?;
                    let pr = faces[other[i]].surface.closest_point(&p, None);
                    let d = p - pr.point;
                    if pr.distance > 0.0 && d.dot(&n) >= along * pr.distance {
                        best = best.min(pr.distance);
                    }
                }
                if best.is_finite() {
                    thickness.push(best);
                }
            }
        }
    }
    if thickness.is_empty() || thickness.len() * 2 < samples {
        return Ok(Err(format!(
            "{} of {samples} points of the features have the other side along their normal: not one sheet",
            thickness.len()
        )));
    }
    thickness.sort_by(f64::total_cmp);
    let t = thickness[thickness.len() / 2];
    let (lo, hi) = (thickness[0], thickness[thickness.len() - 1]);
    if t > kerf_format::MAX_SHEET_THICKNESS_MM {
        return Ok(Err(format!(
            "the walls are {t:.1} mm wide: thicker than any sheet ({} mm, the largest `sheet_thickness_mm`)",
            kerf_format::MAX_SHEET_THICKNESS_MM
        )));
    }
    if !(t > 0.0) || hi - lo > THICKNESS_SPREAD * t + THICKNESS_SLACK_MM {
        return Ok(Err(format!(
            "the features' distance to the other side runs from {lo:.4} to {hi:.4} mm: not one sheet of constant thickness (or beveled walls)"
        )));
    }
    // The walls are at right angles to the sheet: every feature point, moved the thickness
    // against its side's normal, lies on a sharp edge of the other side (its twin). The
    // distance above is to the other side's untrimmed surfaces, which reach under a beveled
    // hole and past a slanted outline: this is the test that refuses them.
    let twin_edges: Vec<(&NurbsCurve, Point3<f64>, Point3<f64>)> = theirs
        .iter()
        .flatten()
        .map(|u| {
            let c = &faces[u.face].loops[u.lp][u.pos];
            let (lo, hi) = curve_box(c);
            (c, lo, hi)
        })
        .collect();
    let slack = TWIN_SLACK * t + THICKNESS_SLACK_MM;
    for c in &ours {
        for u in c {
            let e = &faces[u.face].loops[u.lp][u.pos];
            let (t0, t1) = e.domain();
            charge(
                u.face,
                THICKNESS_TESTS * (1 + twin_edges.len().div_ceil(64)),
            )?;
            for k in 0..THICKNESS_TESTS {
                let p = e.point(t0 + (t1 - t0) * (k as f64 + 0.5) / THICKNESS_TESTS as f64);
                let Some(n) = normal_at(&faces[u.face].surface, &p) else {
                    return Ok(Err(format!(
                        "{} has no normal at ({:.3}, {:.3}, {:.3})",
                        faces[u.face].label(),
                        p.x,
                        p.y,
                        p.z
                    )));
                };
                let q = p - n * t;
                let mut best = f64::INFINITY;
                for (c, lo, hi) in &twin_edges {
                    if distance_to_box(&q, lo, hi) <= slack {
                        best = best.min(c.closest_point(&q).distance);
                        if best <= slack {
                            break;
                        }
                    }
                }
                if best > slack {
                    return Ok(Err(format!(
                        "a wall of {} is not at right angles to the sheet: no edge of the other side within {slack:.4} mm of ({:.3}, {:.3}, {:.3}), {t:.3} mm behind its edge point ({:.3}, {:.3}, {:.3}): beveled or slanted walls are not cut as a sheet",
                        faces[u.face].label(), q.x, q.y, q.z, p.x, p.y, p.z
                    )));
                }
            }
        }
    }
    let mut features: Vec<Feature> = ours.iter().map(|c| feature(faces, &sharp, c)).collect();
    // Twins by the nearest chain centroid: for the report, and the chain a piece that faces
    // down is cut on (`twin_stretch` checks that it lies behind the piece).
    let centroid = |c: &[Use]| -> Point3<f64> {
        // Length-weighted mean of points along every edge (a one-edge hole's middle point is
        // on the circle, not at its centre).
        let (mut s, mut w) = (Vector3::zeros(), 0.0);
        for u in c {
            let e = &faces[u.face].loops[u.lp][u.pos];
            let (t0, t1) = e.domain();
            let l = e.arc_length() / 8.0;
            for k in 0..8 {
                s += e.point(t0 + (t1 - t0) * (k as f64 + 0.5) / 8.0).coords * l;
                w += l;
            }
        }
        Point3::from(s / w.max(f64::MIN_POSITIVE))
    };
    let twin_centroids: Vec<Point3<f64>> = theirs.iter().map(|c| centroid(c)).collect();
    for (f, c) in features.iter_mut().zip(&ours) {
        let p = centroid(c);
        if let Some((k, _)) = twin_centroids
            .iter()
            .enumerate()
            .min_by(|x, y| (x.1 - p).norm().total_cmp(&(y.1 - p).norm()))
        {
            let mut fs: Vec<usize> = Vec::new();
            for u in &theirs[k] {
                if !fs.contains(&u.face) {
                    fs.push(u.face);
                }
            }
            f.twin_faces = fs;
            // A piece whose side faces down is cut from the other side: its twin stretch
            // there faces up (the nozzle stands off from the face the beam enters).
            for (j, piece) in f.pieces.iter().enumerate() {
                if f.facing[j] >= 0 {
                    continue;
                }
                let whole = f.pieces.len() == 1;
                let tests = if whole { WHOLE_TWIN_TESTS } else { 2 };
                charge(c[piece[0]].face, tests * (theirs[k].len() + 1))?;
                f.twins[j] = twin_stretch(faces, c, piece, &theirs[k], t, slack, whole);
            }
        }
    }
    features.sort_by(|x, y| y.length_mm.total_cmp(&x.length_mm));
    Ok(Ok(Sheet {
        thickness_mm: t,
        side,
        other,
        walls,
        features,
    }))
}

/// True if the two surfaces' outward normals agree within [`SMOOTH_DEG`] at `EDGE_TESTS`
/// points of the edge.
fn tangent(edge: &NurbsCurve, a: &NurbsSurface, b: &NurbsSurface) -> bool {
    let (t0, t1) = edge.domain();
    let cos = SMOOTH_DEG.to_radians().cos();
    // The samples run along the edge: each foot starts from the previous one's.
    let (mut warm_a, mut warm_b) = (None, None);
    (0..EDGE_TESTS).all(|k| {
        let p = edge.point(t0 + (t1 - t0) * (k as f64 + 1.0) / (EDGE_TESTS as f64 + 1.0));
        let fa = crate::surfaces::foot_near(a, &p, &mut warm_a, 0.0);
        let fb = crate::surfaces::foot_near(b, &p, &mut warm_b, 0.0);
        match (a.normal(fa.u, fa.v), b.normal(fb.u, fb.v)) {
            (Some(na), Some(nb)) => na.dot(&nb) >= cos,
            _ => false,
        }
    })
}

/// The outward unit normal of `s` at its point nearest `p`.
fn normal_at(s: &NurbsSurface, p: &Point3<f64>) -> Option<Vector3<f64>> {
    let pr = s.closest_point(p, None);
    s.normal(pr.u, pr.v)
}

/// The surface's area over its parameter range and the area-weighted normal (an 8 x 8
/// midpoint rule: enough to tell a sheet's sides from its walls).
fn area_and_normal(s: &NurbsSurface) -> (f64, Vector3<f64>) {
    const N: usize = 8;
    let ((u0, u1), (v0, v1)) = (s.domain_u(), s.domain_v());
    let (du, dv) = ((u1 - u0) / N as f64, (v1 - v0) / N as f64);
    let mut area = 0.0;
    let mut normal = Vector3::zeros();
    for i in 0..N {
        for j in 0..N {
            let (u, v) = (u0 + (i as f64 + 0.5) * du, v0 + (j as f64 + 0.5) * dv);
            let d = s.derivatives(u, v);
            let n = d[1][0].cross(&d[0][1]) * (du * dv);
            area += n.norm();
            normal += n;
        }
    }
    (area, normal)
}

/// The box of a curve's control points (which holds the curve).
fn curve_box(c: &NurbsCurve) -> (Point3<f64>, Point3<f64>) {
    let pts = c.control_points();
    let mut lo = pts[0];
    let mut hi = pts[0];
    for p in pts {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
}

/// Chains the side's sharp edges into closed loops: each edge is followed by the unused edge
/// whose start is nearest its end (the shared vertex, within 1e-3 mm). Starts are sorted by x
/// and searched in a window of +-1e-3 mm, `O(n log n)` for edges in general position; the
/// window scans are counted, and a file whose edge ends pile up at one x beyond
/// `64 n + 2^20` scans is not taken for a sheet (bounded work, whatever the file).
fn chain(faces: &[Face], on: Vec<Use>) -> std::result::Result<Vec<Vec<Use>>, String> {
    const NEAR: f64 = 1e-3;
    let n = on.len();
    let ends: Vec<(Point3<f64>, Point3<f64>)> = on
        .iter()
        .map(|u| {
            let c = &faces[u.face].loops[u.lp][u.pos];
            let (t0, t1) = c.domain();
            (c.point(t0), c.point(t1))
        })
        .collect();
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| ends[a].0.x.total_cmp(&ends[b].0.x).then(a.cmp(&b)));
    let xs: Vec<f64> = order.iter().map(|&i| ends[i].0.x).collect();
    let mut used = vec![false; n];
    let mut scans = 0usize;
    let budget = 64 * n + (1 << 20);
    let mut out = Vec::new();
    for first in (0..n).rev() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let (start, mut end) = ends[first];
        let mut loop_ = vec![on[first]];
        let close = (1e-6 * (1.0 + start.coords.norm())).max(1e-6);
        while (end - start).norm() > close {
            let lo = xs.partition_point(|&x| x < end.x - NEAR);
            let mut best: Option<(usize, f64)> = None;
            for &i in order[lo..]
                .iter()
                .take_while(|&&i| ends[i].0.x <= end.x + NEAR)
            {
                scans += 1;
                if used[i] {
                    continue;
                }
                let d = (ends[i].0 - end).norm();
                if best.is_none_or(|b| d < b.1) {
                    best = Some((i, d));
                }
            }
            if scans > budget {
                return Err(format!(
                    "{n} sharp edges whose ends pile up ({scans} comparisons): not taken for a sheet"
                ));
            }
            match best {
                Some((i, d)) if d <= NEAR => {
                    used[i] = true;
                    end = ends[i].1;
                    loop_.push(on[i]);
                }
                _ => {
                    return Err(format!(
                        "the sharp edges of {} do not close into a loop at ({:.3}, {:.3}, {:.3})",
                        faces[on[first].face].label(),
                        end.x,
                        end.y,
                        end.z
                    ));
                }
            }
        }
        out.push(loop_);
    }
    Ok(out)
}

/// A chain as a feature: its edges, faces, loops, length and scrap side.
fn feature(faces: &[Face], sharp: &[(u64, Use, Use)], c: &[Use]) -> Feature {
    let edges: Vec<NurbsCurve> = c
        .iter()
        .map(|u| faces[u.face].loops[u.lp][u.pos].clone())
        .collect();
    let mut fs: Vec<usize> = Vec::new();
    let mut loops: Vec<(usize, usize)> = Vec::new();
    for u in c {
        if !fs.contains(&u.face) {
            fs.push(u.face);
        }
        if !loops.contains(&(u.face, u.lp)) {
            loops.push((u.face, u.lp));
        }
    }
    let lengths: Vec<f64> = edges.iter().map(NurbsCurve::arc_length).collect();
    // The scrap: where the wall's outward normal points, at the middle of the longest edge.
    let (k, _) = lengths
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.total_cmp(y.1))
        .unwrap_or((0, &0.0));
    let u = c[k];
    let wall = sharp
        .iter()
        .find_map(|(_, x, y)| {
            if (x.face, x.lp, x.pos) == (u.face, u.lp, u.pos) {
                Some(y.face)
            } else if (y.face, y.lp, y.pos) == (u.face, u.lp, u.pos) {
                Some(x.face)
            } else {
                None
            }
        })
        .unwrap_or(u.face);
    let e = &edges[k];
    let (t0, t1) = e.domain();
    let tm = 0.5 * (t0 + t1);
    let (p, tangent) = (e.point(tm), e.tangent(tm).unwrap_or_else(Vector3::zeros));
    let n = normal_at(&faces[u.face].surface, &p).unwrap_or_else(Vector3::z);
    let w = normal_at(&faces[wall].surface, &p).unwrap_or_else(Vector3::zeros);
    let scrap = if n.cross(&tangent).dot(&w) > 0.0 {
        ScrapSide::Left
    } else {
        ScrapSide::Right
    };
    // Which way each edge's side normal faces along z (0: sideways, either way).
    let facing: Vec<i8> = c
        .iter()
        .zip(&edges)
        .map(|(u, e)| {
            let (t0, t1) = e.domain();
            let n = normal_at(&faces[u.face].surface, &e.point(0.5 * (t0 + t1)))
                .unwrap_or_else(Vector3::zeros);
            if n.z > SIDEWAYS_Z {
                1
            } else if n.z < -SIDEWAYS_Z {
                -1
            } else {
                0
            }
        })
        .collect();
    let pieces = pieces(&facing);
    // Sideways edges joined the run before them, so each run's first edge that faces one way
    // gives the run's facing (0 only for a chain that is sideways throughout).
    let piece_facing: Vec<i8> = pieces
        .iter()
        .map(|run| {
            run.iter()
                .map(|&e| facing[e])
                .find(|&x| x != 0)
                .unwrap_or(0)
        })
        .collect();
    Feature {
        twins: pieces.iter().map(|_| None).collect(),
        facing: piece_facing,
        pieces,
        edge_faces: c.iter().map(|u| u.face).collect(),
        edges,
        faces: fs,
        loops,
        twin_faces: Vec::new(),
        scrap,
        length_mm: lengths.iter().sum(),
    }
}

/// Points of a closed chain checked to lie behind its twin before the whole twin is cut.
const WHOLE_TWIN_TESTS: usize = 8;

/// The stretch of the twin chain `twin` (uses of the other side's loops, in their order) that
/// lies the thickness `t` behind the piece `piece` of the chain `ours`: from behind the piece's
/// end to behind its start, since the other side's loops run the other way round (each side's
/// loops keep their face on the left seen from outside). The whole twin chain for a closed
/// piece (`whole`), once up to [`WHOLE_TWIN_TESTS`] points of the chain have their points behind
/// on it. `None` where a point behind is farther than `slack` from the twin chain, or the
/// stretch is much longer than the piece (not its twin).
fn twin_stretch(
    faces: &[Face],
    ours: &[Use],
    piece: &[usize],
    twin: &[Use],
    t: f64,
    slack: f64,
    whole: bool,
) -> Option<Twin> {
    let edge = |u: &Use| &faces[u.face].loops[u.lp][u.pos];
    let behind_at = |u: &Use, s: f64| -> Option<Point3<f64>> {
        let e = edge(u);
        let (a, b) = e.domain();
        let p = e.point(a + (b - a) * s);
        Some(p - normal_at(&faces[u.face].surface, &p)? * t)
    };
    let behind = |u: &Use, at_end: bool| behind_at(u, if at_end { 1.0 } else { 0.0 });
    let piece_len: f64 = piece.iter().map(|&k| edge(&ours[k]).arc_length()).sum();
    let plausible = |twin_len: f64| twin_len <= 1.5 * piece_len + 10.0 * t;
    if whole {
        // The chain was matched by its centroid: its points must lie behind this one's.
        let near = |q: Point3<f64>| {
            twin.iter()
                .map(|u| edge(u).closest_point(&q).distance)
                .fold(f64::INFINITY, f64::min)
        };
        let step = piece.len().div_ceil(WHOLE_TWIN_TESTS).max(1);
        for &k in piece.iter().step_by(step) {
            if near(behind_at(&ours[k], 0.5)?) > slack {
                return None;
            }
        }
        let twin_len: f64 = twin.iter().map(|u| edge(u).arc_length()).sum();
        return plausible(twin_len).then(|| Twin {
            edges: twin.iter().map(|u| edge(u).clone()).collect(),
            edge_faces: twin.iter().map(|u| u.face).collect(),
        });
    }
    let (first, last) = (&ours[*piece.first()?], &ours[*piece.last()?]);
    // Where a point lies on the twin chain: (edge, parameter), moved to the next edge's start
    // when it is the end of its edge.
    let n = twin.len();
    let locate = |q: Point3<f64>| -> Option<(usize, f64)> {
        let (i, pr) = twin
            .iter()
            .enumerate()
            .map(|(i, u)| (i, edge(u).closest_point(&q)))
            .min_by(|x, y| x.1.distance.total_cmp(&y.1.distance))?;
        if pr.distance > slack {
            return None;
        }
        // Within the slack of an end of its edge: that end (a wall a little off square puts
        // the point behind a hair short of the twin's vertex; no sliver is cut for it).
        let e = edge(&twin[i]);
        let (a, b) = e.domain();
        if (e.point(b) - pr.point).norm() <= slack {
            let j = (i + 1) % n;
            Some((j, edge(&twin[j]).domain().0))
        } else if (e.point(a) - pr.point).norm() <= slack {
            Some((i, a))
        } else {
            Some((i, pr.t))
        }
    };
    let (mut i, mut from) = locate(behind(last, true)?)?;
    let (i_end, to) = locate(behind(first, false)?)?;
    let mut out = Twin {
        edges: Vec::new(),
        edge_faces: Vec::new(),
    };
    for step in 0..=n {
        let e = edge(&twin[i]);
        let (a, b) = e.domain();
        let eps = 1e-9 * (b - a);
        if i == i_end && (step > 0 || to >= from) {
            if to > from + eps {
                out.edges.push(crate::curves::sub_curve(e, from, to).ok()?);
                out.edge_faces.push(twin[i].face);
            }
            break;
        }
        if from < b - eps {
            out.edges.push(crate::curves::sub_curve(e, from, b).ok()?);
            out.edge_faces.push(twin[i].face);
        }
        i = (i + 1) % n;
        from = edge(&twin[i]).domain().0;
        if step == n {
            return None;
        }
    }
    let twin_len: f64 = out.edges.iter().map(NurbsCurve::arc_length).sum();
    (!out.edges.is_empty() && plausible(twin_len)).then_some(out)
}

/// `|n_z|` below which an edge's side normal counts as sideways (reachable from either side of
/// the sheet): within about 11.5 degrees of horizontal.
const SIDEWAYS_Z: f64 = 0.2;

/// The runs of a closed chain whose edges face one way along z (`facing`: +1 up, -1 down, 0
/// sideways, which joins the run before it): one run of every edge when they all agree,
/// otherwise runs starting where the facing turns.
fn pieces(facing: &[i8]) -> Vec<Vec<usize>> {
    let n = facing.len();
    let Some(first) = facing.iter().position(|&f| f != 0) else {
        return vec![(0..n).collect()];
    };
    // Sideways edges take the facing of the last edge before them that has one.
    let mut f = vec![0i8; n];
    let mut last = facing[first];
    for k in 0..n {
        let i = (first + k) % n;
        if facing[i] != 0 {
            last = facing[i];
        }
        f[i] = last;
    }
    let Some(turn) = (0..n).find(|&i| f[i] != f[(i + n - 1) % n]) else {
        return vec![(0..n).collect()];
    };
    let mut out: Vec<Vec<usize>> = Vec::new();
    for k in 0..n {
        let i = (turn + k) % n;
        if k == 0 || f[i] != f[(i + n - 1) % n] {
            out.push(Vec::new());
        }
        if let Some(run) = out.last_mut() {
            run.push(i);
        }
    }
    out
}
