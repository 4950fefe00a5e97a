//! What kerf's CAD readers share, whatever the file format (STEP here, IGES in `kerf-iges`):
//! a face built from a surface and its boundary loops, the contours of face loops or of free
//! curves (joined, named, placed on the faces they lie on), and the `kerf.curves/1` document
//! they make. A reader turns its entities into [`Geometry`] and NURBS curves and calls these;
//! every message keeps the reader's own names for its entities (`#23805`, `D45`).

use std::collections::HashMap;

use kerf_format::curves::{RawCurve, RawCurvesFile, RawNurbsSurface, RawSurface, SurfaceRef};
use kerf_nurbs::{NurbsCurve, NurbsSurface};

use crate::contour;
use crate::{ImportOptions, Report, SheetReport, MAX_NAME_CHARS};

pub use crate::curves::sub_curve;
pub use crate::model::Charge;
pub use crate::model::Frame;
use crate::shape::associate;
pub use crate::shape::{
    face, first_with_same_surface, sew, Face, ParamBox, Place, PROJECTIONS_PER_OFFSET_CELL,
};
pub use crate::surfaces::{Approximation, Geometry, SurfaceRangeError, OFFSET_APPROXIMATION_MM};

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

/// One contour to write: its id, curve, the faces it names (indices into the faces) and its
/// scrap side (`left`/`right`, where the reader knows it).
#[derive(Debug, Clone)]
pub struct Contour {
    pub(crate) id: String,
    pub(crate) curve: NurbsCurve,
    pub(crate) faces: Vec<usize>,
    pub(crate) scrap: Option<&'static str>,
    /// The thickness of the sheet whose face it lies on (a recognised sheet's feature), mm.
    pub(crate) sheet_thickness_mm: Option<f64>,
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

/// Why `opts.faces` (the faces chosen by hand) cannot be cut: the first id that is no face
/// read, as `{sigil}{id} is not a face kerf could read (N faces read)`; `None` when every one
/// is (or none was chosen).
pub fn unknown_face(faces: &[Face], opts: &ImportOptions, sigil: &str) -> Option<String> {
    let only = opts.faces.as_ref()?;
    only.iter()
        .find(|id| !faces.iter().any(|f| f.id == **id))
        .map(|id| {
            format!(
                "{sigil}{id} is not a face kerf could read ({} faces read)",
                faces.len()
            )
        })
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
    let mut cut_with: HashMap<u64, String> = HashMap::new();
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
                        "edge {} of {} loop {}: shared with {}, cut once, with that face's normal",
                        crate::shape::edge_tag(f.sigil, *e),
                        f.label(),
                        li + 1,
                        cut_with[e],
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
                note_join(report, &format!("{} face loop {}", f.tag(), li + 1), &j);
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
                    sheet_thickness_mm: None,
                });
            }
            for e in edge_ids {
                cut_with.entry(*e).or_insert_with(|| f.label());
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
        let named = match associate(&c.curve, faces, same_surface, opts.face_tolerance_mm, |n| {
            place.charge(n)
        })? {
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
            sheet_thickness_mm: None,
        });
    }
    Ok(contours)
}

pub use crate::sheet::Sheet;

/// Whether `faces` form one sheet-metal solid (two sides at a constant thickness joined by
/// walls, every edge shared by two faces: `docs/step.md` "Sheet-metal solids"), and its features;
/// `Ok(Err(reason))` when they do not. `charge(face index, n)` pays for the projections.
///
/// # Errors
/// Only what `charge` returns.
pub fn recognise_sheet<E>(
    faces: &[Face],
    charge: impl Fn(usize, usize) -> Result<(), E>,
) -> Result<Result<Sheet, String>, E> {
    crate::sheet::recognise(faces, charge)
}

impl Sheet {
    /// The sheet's thickness, mm.
    pub fn thickness_mm(&self) -> f64 {
        self.thickness_mm
    }

    /// How many through-features (holes, cut-outs, the outline) it has.
    pub fn feature_count(&self) -> usize {
        self.features.len()
    }
}

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
            "{} ({}{}{})",
            face_id(f),
            f.kind,
            if f.name.is_empty() {
                String::new()
            } else {
                format!(", {:?}", f.name)
            },
            f.approximation.map_or(String::new(), |a| format!(
                ", approximated within {:.1e} mm of the exact offset, normals within {:.1e} rad",
                a.position_mm, a.normal_rad
            ))
        ));
        if let Some(a) = f.approximation {
            report.approximated.push((face_id(f), a));
        }
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
        sheet_thickness_mm,
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
        // A sheet's feature is cut from its side only (the import already put each piece on
        // the side that faces up): the pipeline never turns it over.
        raw.sheet_thickness_mm = sheet_thickness_mm;
        // A face's edge lies on the face within the file's own tolerance (the reader took
        // it within ON_GEOMETRY_TOLERANCE_MM): the curve says so, and the normals stage takes
        // the looser of it and the run's on-surface tolerance. Face edges are the contours of
        // `edges` and of a sheet recognised without it.
        if face_edges && raw.surface.is_some() {
            raw.on_surface_tolerance_mm = edge_tolerance;
        }
        // A face whose surface approximates the file's (an offset of a B-spline surface): the
        // contour lies on the file's surface, within the approximation's proven distance of
        // the one written.
        let approximated = named
            .iter()
            .filter_map(|&f| faces[f].approximation)
            .map(|a| a.position_mm)
            .fold(0.0, f64::max);
        if approximated > 0.0 && raw.surface.is_some() {
            raw.on_surface_tolerance_mm = Some(
                (raw.on_surface_tolerance_mm.unwrap_or(0.0) + approximated)
                    .min(kerf_format::MAX_CURVE_ON_SURFACE_TOLERANCE_MM),
            );
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
    RawCurve::new(
        id,
        c.degree(),
        c.knots().to_vec(),
        c.control_points().iter().map(|p| [p.x, p.y, p.z]).collect(),
    )
    .with_weights(c.is_rational().then(|| c.weights()))
    .with_surface(surface)
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

/// The contours of a recognised sheet ([`recognise_sheet`]): each through-feature once, on the
/// side the sheet is cut from, in pieces where it must be, with the sheet's account in
/// `report.sheet`.
pub fn sheet_contours(
    s: &Sheet,
    faces: &[Face],
    opts: &ImportOptions,
    report: &mut Report,
) -> Vec<Contour> {
    let mut out = Vec::new();
    let ids = |fs: &[usize]| fs.iter().map(|&f| faces[f].id).collect::<Vec<_>>();
    let mut r = SheetReport {
        thickness_mm: s.thickness_mm,
        side: ids(&s.side),
        other_side: ids(&s.other),
        walls: ids(&s.walls),
        id_prefix: faces.first().map_or("#", |f| f.sigil),
        ..SheetReport::default()
    };
    for (k, f) in s.features.iter().enumerate() {
        let id = format!("feature {} {}", k + 1, faces[f.faces[0]].label());
        let scrap = match f.scrap {
            crate::sheet::ScrapSide::Left => "left",
            crate::sheet::ScrapSide::Right => "right",
        };
        let closed = f.pieces.len() == 1;
        for (p, piece) in f.pieces.iter().enumerate() {
            let pid = if closed {
                id.clone()
            } else {
                format!("{id} piece {}", p + 1)
            };
            // A piece whose side faces down is cut on its twin, from the other side.
            let twin = f.twins.get(p).and_then(Option::as_ref);
            let (edges, edge_faces): (Vec<NurbsCurve>, Vec<usize>) = match twin {
                Some(t) => (t.edges.clone(), t.edge_faces.clone()),
                None => (
                    piece.iter().map(|&e| f.edges[e].clone()).collect(),
                    piece.iter().map(|&e| f.edge_faces[e]).collect(),
                ),
            };
            let j = contour::join(&edges, opts.close_gaps_mm, closed);
            note_join(report, &pid, &j);
            let n = j.contours.len();
            for (i, c) in j.contours.into_iter().enumerate() {
                let cid = if n == 1 {
                    pid.clone()
                } else {
                    format!("{pid}.{}", i + 1)
                };
                // The faces this piece runs along.
                let mut named: Vec<usize> = Vec::new();
                for &fi in &edge_faces {
                    if !named.contains(&fi) {
                        named.push(fi);
                    }
                }
                out.push(Contour {
                    id: cid,
                    curve: c.curve,
                    faces: named,
                    scrap: Some(scrap),
                    sheet_thickness_mm: Some(s.thickness_mm),
                });
            }
        }
        let loops: Vec<String> = f
            .loops
            .iter()
            .map(|&(fi, li)| format!("{} loop {}", faces[fi].tag(), li + 1))
            .collect();
        let twins: Vec<String> = f.twin_faces.iter().map(|&fi| faces[fi].tag()).collect();
        // Pieces that face down: cut on their twins, or (no twin found) as they are.
        let down = |on_twin: bool| -> Vec<String> {
            (0..f.pieces.len())
                .filter(|&p| f.facing[p] < 0 && f.twins[p].is_some() == on_twin)
                .map(|p| (p + 1).to_string())
                .collect()
        };
        let (turned, kept) = (down(true), down(false));
        let which = |ps: &[String]| match (closed, ps.len()) {
            (true, _) => "it faces".to_string(),
            (false, 1) => format!("piece {} faces", ps[0]),
            _ => format!("pieces {} face", ps.join(", ")),
        };
        let mut other_side = String::new();
        if !turned.is_empty() {
            other_side += &format!(
                "; {} down on this side: cut on the twin behind, on the other side, which faces up",
                which(&turned)
            );
        }
        if !kept.is_empty() {
            other_side += &format!(
                "; {} down and no twin was found behind: cut as on this side",
                which(&kept)
            );
        }
        r.features.push(format!(
            "{id}: {:.3} mm, scrap {scrap}, {}, from {} edges of {}; its twin on faces {} and the walls between not cut where this side is{other_side}",
            f.length_mm,
            if closed {
                "one closed cut".to_string()
            } else {
                format!("{} open pieces (the side's normal turns between up and down along it)", f.pieces.len())
            },
            f.edges.len(),
            loops.join(", "),
            twins.join(", ")
        ));
    }
    report.sheet = Some(r);
    out
}
