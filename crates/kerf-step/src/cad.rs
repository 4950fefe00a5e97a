//! What kerf's CAD readers share, whatever the file format (STEP here, IGES in `kerf-iges`):
//! a face built from a surface and its boundary loops, the contours of face loops or of free
//! curves (joined, named, placed on the faces they lie on), and the `kerf.curves/1` document
//! they make. A reader turns its entities into [`Geometry`] and NURBS curves and calls these;
//! every message keeps the reader's own names for its entities (`#23805`, `D45`).

use std::collections::HashMap;

use kerf_format::curves::{RawCurve, RawCurvesFile, RawNurbsSurface, RawSurface, SurfaceRef};
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::Point3;

use crate::contour;
use crate::faces::{reverse_u, EDGE_CHECK_SAMPLES, EDGE_SAMPLES, FULL_TURN_GAP};
use crate::surfaces::angle_range;
use crate::{ImportOptions, Report, MAX_NAME_CHARS};

pub use crate::curves::sub_curve;
pub use crate::faces::Face;
pub use crate::model::Charge;
pub use crate::model::Frame;
pub use crate::surfaces::Geometry;

/// `segments` (in order) joined into one curve with a C0 knot at each join, gaps up to
/// `close_below` mm closed by moving the shared pole (a swept surface's profile given as a
/// composite); `None` if a larger gap splits it or every segment has zero length.
pub fn join_one(segments: &[NurbsCurve], close_below: f64) -> Option<NurbsCurve> {
    let mut j = contour::join(segments, close_below, false);
    (j.contours.len() == 1).then(|| j.contours.remove(0).curve)
}

/// How far an edge may lie from its face's surface (and a trim point from its curve), mm.
pub use crate::curves::ON_GEOMETRY_TOLERANCE_MM;

/// Why `opts` cannot be used (a gap or face tolerance that is negative or not finite).
///
/// # Errors
/// The message naming the option.
pub fn check_options(opts: &ImportOptions) -> Result<(), String> {
    for (name, v) in [
        ("close_gaps_mm", opts.close_gaps_mm),
        ("face_tolerance_mm", opts.face_tolerance_mm),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            return Err(format!("{name} must be a finite number >= 0 mm, got {v}"));
        }
    }
    Ok(())
}

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

/// One contour to write: its id, curve, the faces it names (indices into the faces) and its
/// scrap side (`left`/`right`, where the reader knows it).
#[derive(Debug, Clone)]
pub struct Contour {
    pub(crate) id: String,
    pub(crate) curve: NurbsCurve,
    pub(crate) faces: Vec<usize>,
    pub(crate) scrap: Option<&'static str>,
}

impl Contour {
    /// The contour's id (as written in `kerf.curves/1`).
    pub fn id(&self) -> &str {
        &self.id
    }

    /// The contour's curve, mm.
    pub fn curve(&self) -> &NurbsCurve {
        &self.curve
    }
}

/// Builds a face: the surface `g` cut to the parameter range its boundary covers (every
/// boundary sample, 181 per edge, mapped to natural parameters; an angle range
/// that leaves less than 3 degrees out is the full turn), each edge checked to lie on the cut
/// surface within [`ON_GEOMETRY_TOLERANCE_MM`], `Su x Sv` reversed when `reversed`.
///
/// `sigil` and `id` name the face (`face #12` for STEP, `face D45` for IGES); `edge_ids[l][k]`
/// names edge `k` of loop `l` (the same id in two faces is the edge they share; give distinct
/// ids where the format has no shared edges). `vertices` are boundary points of vertex loops.
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
    natural: Option<ParamBox>,
    reversed: bool,
) -> Result<Face, P::Error> {
    use std::f64::consts::{FRAC_PI_2, TAU};
    // The parameter range: every boundary sample mapped to natural parameters.
    let mut us = Vec::new();
    let mut vs = Vec::new();
    let mut add = |q: &Point3<f64>| {
        let (u, v) = g.params_of(q);
        us.push(u);
        vs.push(v);
    };
    let uses: usize = loops.iter().map(Vec::len).sum();
    place.charge(uses * EDGE_SAMPLES)?;
    for l in &loops {
        for e in l {
            let (a, b) = e.domain();
            for k in 0..EDGE_SAMPLES {
                add(&e.point(a + (b - a) * k as f64 / (EDGE_SAMPLES - 1) as f64));
            }
        }
    }
    for q in vertices {
        add(q);
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
    if let Geometry::Nurbs(s) = g {
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
    let mut surface = g.to_nurbs(u, v).map_err(|m| place.defect(m))?;
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

/// The contours of the faces' boundary loops (`opts.faces`: only those faces; `None`: all),
/// each loop closed where its edges join. With faces chosen by hand, an edge two of them
/// share is cut once: with the first face (in file order) that has it, whose normal it takes;
/// the later face's loop is cut in the open pieces between such edges (each edge left out is
/// named in `report.skipped`).
pub fn face_loop_contours(
    faces: &[Face],
    opts: &ImportOptions,
    report: &mut Report,
) -> Vec<Contour> {
    let mut contours = Vec::new();
    let mut cut_with: HashMap<u64, u64> = HashMap::new();
    for (fi, f) in faces.iter().enumerate() {
        if let Some(only) = &opts.faces {
            if !only.contains(&f.id) {
                continue;
            }
        }
        for (li, l) in f.loops.iter().enumerate() {
            let edge_ids = f.edge_ids.get(li).map_or(&[][..], Vec::as_slice);
            let shared: Vec<bool> = (0..l.len())
                .map(|k| {
                    opts.faces.is_some()
                        && edge_ids.get(k).is_some_and(|e| cut_with.contains_key(e))
                })
                .collect();
            for (k, e) in edge_ids.iter().enumerate() {
                if shared[k] {
                    report.skipped.push(format!(
                            "edge {s}{e} of face {s}{} loop {}: shared with face {s}{}, cut once, with that face's normal",
                            f.id,
                            li + 1,
                            cut_with[e],
                            s = f.sigil
                        ));
                }
            }
            // The loop whole, or its runs of edges not cut already (each open).
            let runs: Vec<Vec<NurbsCurve>> = if shared.iter().any(|&s| s) {
                loop_runs(l, &shared)
            } else {
                vec![l.clone()]
            };
            let closed = runs.len() == 1 && runs[0].len() == l.len();
            let mut pieces = Vec::new();
            for run in &runs {
                let j = contour::join(run, opts.close_gaps_mm, closed);
                note_join(
                    report,
                    &format!("{}{} face loop {}", f.sigil, f.id, li + 1),
                    &j,
                );
                pieces.extend(j.contours);
            }
            let n = pieces.len();
            for (k, c) in pieces.into_iter().enumerate() {
                let id = if n == 1 && closed {
                    format!("{} loop {}", f.label(), li + 1)
                } else {
                    format!("{} loop {}.{}", f.label(), li + 1, k + 1)
                };
                contours.push(Contour {
                    id,
                    curve: c.curve,
                    faces: vec![fi],
                    scrap: None,
                });
            }
            for e in edge_ids {
                cut_with.entry(*e).or_insert(f.id);
            }
        }
    }
    contours
}

/// The contours of one free curve (a cut line the file gives as a curve, not a face's edge):
/// its `segments` joined into as few contours as their gaps allow (gaps up to
/// `opts.close_gaps_mm` closed, larger ones open it, each said in `report`), named
/// `"{name} {tag}"` (or `tag` alone: a name that is not one printable line is left out, a long
/// one cut to [`MAX_NAME_CHARS`]), each placed on the faces its dense samples lie on within
/// `opts.face_tolerance_mm` (none: cut without a surface, said in `report.skipped`).
///
/// `what` names the curve in messages (`#23805 COMPOSITE_CURVE`, `D45 composite curve`);
/// each segment comes with its own name. `same_surface` is
/// [`first_with_same_surface`] of `faces`.
///
/// # Errors
/// `place`'s budget error (projections are charged before they are made).
#[allow(clippy::too_many_arguments)]
pub fn curve_contours<P: Place>(
    place: &P,
    what: &str,
    tag: &str,
    mut name: String,
    segments: &[(NurbsCurve, String)],
    faces: &[Face],
    same_surface: &[usize],
    opts: &ImportOptions,
    report: &mut Report,
) -> Result<Vec<Contour>, P::Error> {
    let mut contours = Vec::new();
    if segments.is_empty() {
        report.skipped.push(format!("{what}: no segment to cut"));
        return Ok(contours);
    }
    let curves_only: Vec<NurbsCurve> = segments.iter().map(|(c, _)| c.clone()).collect();
    let closed_hint = {
        let a = &curves_only[0];
        let b = &curves_only[curves_only.len() - 1];
        (a.point(a.domain().0) - b.point(b.domain().1)).norm() <= opts.close_gaps_mm
    };
    let j = contour::join(&curves_only, opts.close_gaps_mm, closed_hint);
    for (before, after, gap) in &j.opened {
        report.opened.push(format!(
            "{what}: segment {} ({}) does not join segment {} ({}) (gap {gap:.3} mm): opened there",
            before + 1,
            segments[*before].1,
            after + 1,
            segments[*after].1
        ));
    }
    note_join(report, what, &j);
    if let Err(defect) = kerf_io::check_text(&name) {
        // Ids reach G-code comments: a line break in one would add blocks to the
        // program. Keep the contour under its tag alone, and say why.
        report.skipped.push(format!(
            "{what}: its name {defect}; the contour is named {tag} alone"
        ));
        name.clear();
    }
    if name.chars().count() > MAX_NAME_CHARS {
        // An id is written into every output (toolpath, axes, report, picture): a
        // 20 MB name made 140 MB of files. Its head identifies it.
        report.skipped.push(format!(
            "{what}: its name of {} characters is cut to its first {MAX_NAME_CHARS}",
            name.chars().count()
        ));
        name = name.chars().take(MAX_NAME_CHARS).collect();
    }
    let base = if name.is_empty() {
        tag.to_owned()
    } else {
        format!("{name} {tag}")
    };
    let n = j.contours.len();
    if n == 0 {
        report
            .skipped
            .push(format!("{what}: every segment has zero length"));
    }
    for (k, c) in j.contours.into_iter().enumerate() {
        let id = if n == 1 {
            base.clone()
        } else {
            format!("{base}.{}", k + 1)
        };
        let named = match crate::faces::associate(
            &c.curve,
            faces,
            same_surface,
            opts.face_tolerance_mm,
            |n| place.charge(n),
        )? {
            Ok(f) => f,
            Err(worst) => {
                report.skipped.push(if worst.is_finite() {
                    format!(
                        "{id}: on no face (a sample is {worst:.3e} mm from every face, more than {} mm): cut without a surface",
                        opts.face_tolerance_mm
                    )
                } else {
                    format!(
                        "{id}: on no face (no face comes within {} mm of it): cut without a surface",
                        opts.face_tolerance_mm
                    )
                });
                Vec::new()
            }
        };
        contours.push(Contour {
            id,
            curve: c.curve,
            faces: named,
            scrap: None,
        });
    }
    Ok(contours)
}

pub use crate::faces::first_with_same_surface;

/// The `kerf.curves/1` document of `contours`: the surfaces of the faces they name (every
/// face with `every_face`), in file order, each as `face <sigil><id>`; one `report.taken` line
/// per contour and per surface in `report.surfaces`. With `face_edges` (the contours are
/// faces' edges), each contour on a face carries the file's tolerance
/// (`report.uncertainty_mm`, at most [`kerf_format::MAX_CURVE_ON_SURFACE_TOLERANCE_MM`]) as
/// its `on_surface_tolerance_mm`.
pub fn finish(
    faces: &[Face],
    contours: Vec<Contour>,
    every_face: bool,
    face_edges: bool,
    report: &mut Report,
) -> RawCurvesFile {
    // Surfaces: the faces named, in file order.
    let mut used: Vec<usize> = contours
        .iter()
        .flat_map(|c| c.faces.iter().copied())
        .collect();
    // A sheet's cuts name only the side they run on; the other side and the walls are part of
    // the solid the head must clear (traverses), so every face goes in.
    if every_face {
        used = (0..faces.len()).collect();
    }
    used.sort_unstable();
    used.dedup();
    let face_id = |f: &Face| f.label();
    for &fi in &used {
        let f = &faces[fi];
        report.surfaces.push(format!(
            "{} ({}{})",
            face_id(f),
            f.kind,
            if f.name.is_empty() {
                String::new()
            } else {
                format!(", {:?}", f.name)
            }
        ));
    }
    let surfaces: Vec<RawSurface> = used
        .iter()
        .map(|&fi| RawSurface::Nurbs(raw_surface(&face_id(&faces[fi]), &faces[fi].surface)))
        .collect();
    let edge_tolerance = report
        .uncertainty_mm
        .map(|u| u.min(kerf_format::MAX_CURVE_ON_SURFACE_TOLERANCE_MM));
    let mut raw_curves = Vec::with_capacity(contours.len());
    for Contour {
        id,
        curve: c,
        faces: named,
        scrap,
    } in contours
    {
        let surface = match named.len() {
            0 => None,
            1 => Some(SurfaceRef::One(face_id(&faces[named[0]]))),
            _ => Some(SurfaceRef::Many(
                named.iter().map(|&f| face_id(&faces[f])).collect(),
            )),
        };
        report.taken.push(format!(
            "{id}: degree {}, {} control points, {:.3} mm{}",
            c.degree(),
            c.len(),
            c.arc_length(),
            match &surface {
                None => " (no face)".to_string(),
                Some(s) => format!(" on {}", s.ids().join(", ")),
            }
        ));
        let mut raw = raw_curve(id, &c, surface);
        raw.scrap = scrap.map(str::to_owned);
        // A face's edge lies on the face within the file's own tolerance (the reader took
        // it within ON_GEOMETRY_TOLERANCE_MM): the curve says so, and the normals stage takes
        // the looser of it and the run's on-surface tolerance. Face edges are the contours of
        // `edges` and of a sheet recognised without it.
        if face_edges && raw.surface.is_some() {
            raw.on_surface_tolerance_mm = edge_tolerance;
        }
        raw_curves.push(raw);
    }
    RawCurvesFile {
        format: kerf_format::CURVES_FORMAT.into(),
        units: "mm".into(),
        curves: raw_curves,
        surfaces,
    }
}

pub(crate) fn note_join(report: &mut Report, what: &str, j: &contour::JoinResult) {
    for c in &j.contours {
        report.gaps_closed += c.closed.len();
        report.largest_move = report.largest_move.max(c.largest_move);
    }
    for d in &j.dropped {
        report.skipped.push(format!(
            "{what}: segment {} has zero length, dropped",
            d + 1
        ));
    }
}

/// The runs of consecutive edges of the closed loop `l` not marked in `skip`, in loop order
/// (a run may wrap round the loop's start), each to be cut as an open contour.
fn loop_runs(l: &[NurbsCurve], skip: &[bool]) -> Vec<Vec<NurbsCurve>> {
    let n = l.len();
    let Some(first) = (0..n).find(|&k| skip[k]) else {
        return vec![l.to_vec()];
    };
    let mut runs = Vec::new();
    let mut run: Vec<NurbsCurve> = Vec::new();
    for step in 1..=n {
        let k = (first + step) % n;
        if skip[k] {
            if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
        } else {
            run.push(l[k].clone());
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

fn raw_curve(id: String, c: &NurbsCurve, surface: Option<SurfaceRef>) -> RawCurve {
    RawCurve {
        id,
        degree: c.degree(),
        knots: c.knots().to_vec(),
        control_points: c.control_points().iter().map(|p| [p.x, p.y, p.z]).collect(),
        weights: c.is_rational().then(|| c.weights()),
        surface,
        start: None,
        scrap: None,
        on_surface_tolerance_mm: None,
    }
}

fn raw_surface(id: &str, s: &NurbsSurface) -> RawNurbsSurface {
    RawNurbsSurface {
        id: id.to_owned(),
        degree_u: s.degree_u(),
        degree_v: s.degree_v(),
        knots_u: s.knots_u().to_vec(),
        knots_v: s.knots_v().to_vec(),
        control_points: s
            .control_points()
            .iter()
            .map(|row| row.iter().map(|p| [p.x, p.y, p.z]).collect())
            .collect(),
        weights: s.is_rational().then(|| s.weights()),
        flip: false,
    }
}
