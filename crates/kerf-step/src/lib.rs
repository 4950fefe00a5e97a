//! Reads cut contours and the faces they lie on from STEP (ISO 10303-21: AP203, AP214, AP242)
//! into `kerf.curves/1`.
//!
//! - **Contours** are the curves of every `GEOMETRIC_SET` / `GEOMETRIC_CURVE_SET` (where CAD
//!   systems put laser trim lines): composite curves of trimmed lines, circles, ellipses and
//!   B-splines (rational or not), trimmed curves, polylines, B-splines, full circles. Each
//!   composite becomes one NURBS curve with a C0 knot at every join and its segments' senses
//!   applied; gaps up to [`ImportOptions::close_gaps_mm`] are closed by moving the two end poles
//!   to their midpoint (the largest move is reported), larger gaps open the contour (reported).
//!   With [`ImportOptions::edges`], the boundary loops of the faces are the contours instead.
//! - **Surfaces**: every face a contour lies on becomes a NURBS surface (exact for B-spline
//!   surfaces, planes, cylinders, cones, spheres, tori, extrusions and revolutions and their
//!   exact offsets; an offset of a free-form surface approximated with a proven bound), cut to the
//!   face's parameter range and oriented so that `Su x Sv` is the face's outward normal. Faces
//!   are found by projection: dense samples of the contour within
//!   [`ImportOptions::face_tolerance_mm`] of the face. A contour over several faces names them all
//!   (the list form of `surface`).
//! - **Units**: lengths to mm (inch, cm, m files), plane angles from degrees or radians.
//! - **Errors** name the entity: `#23805 COMPOSITE_CURVE: segment 12 (#23790): ...`.
//!
//! The reader is kerf's own, on a Part 21 tokenizer (see `docs/step.md` for why not
//! `step-io`).
//!
//! ```
//! let step = r#"ISO-10303-21;
//! HEADER; FILE_SCHEMA(('AUTOMOTIVE_DESIGN')); ENDSEC;
//! DATA;
//! #1=CARTESIAN_POINT('',(0.,0.,0.));
//! #2=DIRECTION('',(0.,0.,1.));
//! #3=DIRECTION('',(1.,0.,0.));
//! #4=AXIS2_PLACEMENT_3D('',#1,#2,#3);
//! #5=CIRCLE('hole',#4,5.);
//! #6=GEOMETRIC_CURVE_SET('cut',(#5));
//! ENDSEC;
//! END-ISO-10303-21;"#;
//! let import = kerf_step::import(step, &kerf_step::ImportOptions::default())?;
//! let c = &import.file.curves[0];
//! assert_eq!(c.id, "hole #5");
//! assert_eq!(c.degree, 2);
//! # Ok::<(), kerf_step::StepError>(())
//! ```

// `!(x > 0.0)` rejects NaN together with the out-of-range values in one test; every such
// comparison in this crate guards file data that may be NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod assembly;
pub mod cad;
mod contour;
mod curves;
mod error;
mod faces;
mod model;
mod parser;
mod shape;
mod sheet;
mod surfaces;

use std::path::Path;

use kerf_format::curves::RawCurvesFile;
use kerf_nurbs::NurbsCurve;

pub use error::{FileError, Result, StepError};
pub use model::{Units, Work};

use crate::model::{name_of, refs, Model};
use crate::shape::Face;

/// Options of [`import`]. Defaults: gaps up to 0.1 mm closed, faces within 0.01 mm, contours
/// from geometric sets.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ImportOptions {
    /// Gaps between consecutive segments up to this (mm) are closed by moving the shared pole;
    /// larger gaps open the contour. Default 0.1 mm (the largest seen on automotive data).
    pub close_gaps_mm: f64,
    /// A contour lies on a face where every dense sample is within this distance (mm) of one
    /// of the faces named. Default 0.01 mm.
    pub face_tolerance_mm: f64,
    /// Take the boundary loops of faces as the contours instead of the geometric sets
    /// (default false; set with [`ImportOptions::with_edges`]).
    pub edges: bool,
    /// With `edges`: only the faces with these `#id`s (default: every face).
    pub faces: Option<Vec<u64>>,
    /// Write every face read as a surface, not only those a contour lies on (default false).
    pub all_faces: bool,
    /// With `edges` and every face: recognise a solid sheet-metal part and cut each
    /// through-feature once (default true; `false` cuts every face loop).
    pub sheet: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl ImportOptions {
    /// Sets [`close_gaps_mm`](Self::close_gaps_mm): gaps between consecutive segments up to
    /// this (mm) are closed by moving the shared pole.
    pub fn with_close_gaps_mm(mut self, close_gaps_mm: f64) -> Self {
        self.close_gaps_mm = close_gaps_mm;
        self
    }

    /// Sets [`face_tolerance_mm`](Self::face_tolerance_mm): a contour lies on a face where
    /// every dense sample is within this distance (mm) of one of the faces named.
    pub fn with_face_tolerance_mm(mut self, face_tolerance_mm: f64) -> Self {
        self.face_tolerance_mm = face_tolerance_mm;
        self
    }

    /// Sets [`faces`](Self::faces): with `edges`, only the faces with these `#id`s (`None`:
    /// every face).
    pub fn with_faces(mut self, faces: Option<Vec<u64>>) -> Self {
        self.faces = faces;
        self
    }

    /// The defaults, as a constant.
    pub const DEFAULT: Self = Self {
        close_gaps_mm: 0.1,
        face_tolerance_mm: 0.01,
        edges: false,
        faces: None,
        all_faces: false,
        sheet: true,
    };

    /// Sets [`sheet`](Self::sheet): with `edges` and every face, recognise a sheet and cut each
    /// through-feature once (`false`: every face loop).
    pub fn with_sheet(mut self, sheet: bool) -> Self {
        self.sheet = sheet;
        self
    }

    /// Write every face read as a surface, used or not.
    pub fn with_all_faces(mut self, all: bool) -> Self {
        self.all_faces = all;
        self
    }

    /// Contours from the boundary loops of these faces (`None`: every face).
    pub fn with_edges(mut self, faces: Option<Vec<u64>>) -> Self {
        self.edges = true;
        self.faces = faces;
        self
    }
}

/// What [`import`] read.
#[derive(Debug, Clone)]
pub struct Import {
    /// The `kerf.curves/1` document (valid: it passes `kerf_format::curves::from_raw`).
    pub file: RawCurvesFile,
    /// What was taken, skipped, closed and opened.
    pub report: Report,
}

impl Import {
    /// The document as kerf's typed, checked curves file (`kerf_format::curves::from_raw`:
    /// every curve and surface built and validated), what a job runs on.
    ///
    /// # Errors
    /// The format's error where the document fails its checks (a reader defect: the readers
    /// write only valid documents, which their tests and fuzz targets hold them to).
    pub fn to_curves(
        &self,
    ) -> std::result::Result<kerf_format::CurvesFile, kerf_format::FormatError> {
        kerf_format::curves::from_raw(self.file.clone(), Path::new("."))
    }
}

/// The account of an import.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// The schemas of `FILE_SCHEMA` (AP203 `CONFIG_CONTROL_DESIGN`, AP214 `AUTOMOTIVE_DESIGN`, ...).
    pub schemas: Vec<String>,
    /// The file's units.
    pub units: Units,
    /// One line per contour written.
    pub taken: Vec<String>,
    /// One line per entity not used, with the reason.
    pub skipped: Vec<String>,
    /// Gaps closed (count) and the largest pole move, mm.
    pub gaps_closed: usize,
    /// The largest distance a pole was moved to close a gap, mm.
    pub largest_move: f64,
    /// One line per gap that opened a contour.
    pub opened: Vec<String>,
    /// Faces read (converted); those that failed are listed in `skipped`.
    pub faces_read: usize,
    /// One line per surface written: its id, kind and the face's name.
    pub surfaces: Vec<String>,
    /// What the reader assumed (a file with no unit context is read in mm).
    pub warnings: Vec<String>,
    /// The file's length uncertainty, mm (its largest `UNCERTAINTY_MEASURE_WITH_UNIT` of a
    /// length): with `edges`, each face-loop contour carries it (at most
    /// [`kerf_format::MAX_CURVE_ON_SURFACE_TOLERANCE_MM`]) as its `on_surface_tolerance_mm`.
    pub uncertainty_mm: Option<f64>,
    /// The work done, counted against the reader's budgets.
    pub work: Work,
    /// With `edges` and every face: the sheet the faces form, its features each cut once
    /// (`None` when no face loop was asked for or `--faces` chose them).
    pub sheet: Option<SheetReport>,
    /// The surfaces written that approximate the file's (offsets of B-spline surfaces), by
    /// their id in the curves file, with what is proven about each.
    pub approximated: Vec<(String, cad::Approximation)>,
}

/// What sheet recognition found (`--edges` on a solid).
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct SheetReport {
    /// Why the faces are not one sheet (then every face loop is a contour, as with `--faces`);
    /// `None` when they are.
    pub not_a_sheet: Option<String>,
    /// The sheet's thickness, mm.
    pub thickness_mm: f64,
    /// How the file writes an entity number before the ids below (`#` in STEP, `D` in IGES).
    pub id_prefix: &'static str,
    /// The faces of the side that is cut, the other side and the walls, as entity numbers.
    pub side: Vec<u64>,
    /// The faces of the other side.
    pub other_side: Vec<u64>,
    /// The wall faces (the edges of the sheet, the walls of holes and cut-outs).
    pub walls: Vec<u64>,
    /// One line per feature: its contour id, length, the face loops it joins and its twin's
    /// faces on the other side (which it replaces).
    pub features: Vec<String>,
}

impl SheetReport {
    /// The account of faces that are not one sheet, with the reason (every face loop is then a
    /// contour).
    pub fn not_a_sheet(why: &str) -> Self {
        Self {
            not_a_sheet: Some(why.to_owned()),
            ..Self::default()
        }
    }
}

/// Reads a STEP file from disk through kerf's one reader (`kerf_io::read_file`: at most 1 GiB,
/// a leading UTF-8 byte-order mark skipped); see [`import`].
///
/// # Errors
/// [`FileError`] naming the file around any [`StepError`].
pub fn import_file(
    path: impl AsRef<Path>,
    opts: &ImportOptions,
) -> std::result::Result<Import, FileError> {
    let path = path.as_ref();
    let bytes = kerf_io::read_file(path).map_err(|source| {
        StepError::Read {
            path: path.to_path_buf(),
            source,
        }
        .in_file(path)
    })?;
    let text = String::from_utf8_lossy(kerf_io::strip_bom(&bytes));
    import(&text, opts).map_err(|e| e.in_file(path))
}

/// Checks the Part 21 syntax of a whole file without interpreting any entity: the number of
/// entity instances in its `DATA` sections. This is the reader's first pass alone (what the
/// parser fuzz target exercises); [`import`] runs it too.
///
/// # Errors
/// [`StepError::Syntax`] naming the line, [`StepError::DuplicateId`], or
/// [`StepError::Budget`] for a file with more instances than the reader accepts.
pub fn check_syntax(text: &str) -> Result<usize> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    Ok(parser::parse(text)?.len())
}

/// Reads the text of a STEP file into a `kerf.curves/1` document (a leading byte-order mark,
/// `U+FEFF`, is skipped).
///
/// # Errors
/// [`StepError::Syntax`] for malformed Part 21, [`StepError::Entity`] naming the entity for a
/// defect in one that is needed (a contour's segment; a face's geometry is skipped and
/// reported instead), [`StepError::NoContour`] if nothing can be cut,
/// [`StepError::Options`] for a non-positive or non-finite option.
pub fn import(text: &str, opts: &ImportOptions) -> Result<Import> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    cad::check_options(opts).map_err(StepError::Options)?;
    let ex = parser::parse(text)?;
    let m = Model::new(&ex)?;
    let mut report = Report {
        schemas: ex.schemas.clone(),
        units: m.units,
        ..Report::default()
    };
    report.warnings = m.warnings.clone();
    let only = if opts.edges && !opts.all_faces {
        opts.faces.as_deref()
    } else {
        None
    };
    let (faces, face_errors) = faces::read_faces(&m, only)?;
    // Assemblies: each face where its part's placements put it, once per instance.
    let placements = assembly::placements(&m)?;
    let faces = place_faces(faces, &placements.faces)?;
    report.faces_read = faces.len();
    report
        .skipped
        .extend(face_errors.into_iter().map(|e| format!("face {e}")));

    // (id, curve, faces named, scrap side)
    let mut contours: Vec<Contour> = Vec::new();
    // Sheet recognition: every face of a solid, no face chosen by hand.
    let mut sheet = if opts.edges && opts.faces.is_none() && opts.sheet {
        Some(sheet::recognise(&faces, |f, n| {
            step_charge(&m, &faces, f, n)
        })?)
    } else {
        None
    };
    if let Some(Ok(s)) = &sheet {
        contours.extend(cad::sheet_contours(s, &faces, opts, &mut report));
    } else if opts.edges {
        if let Some(Err(why)) = &sheet {
            report.sheet = Some(SheetReport::not_a_sheet(why));
        }
        contours.extend(cad::face_loop_contours(&faces, opts, &mut report));
        if let Some(reason) = cad::unknown_face(&faces, opts, "#") {
            return Err(StepError::NoContour { reason });
        }
    } else {
        let mut sets = m.all("GEOMETRIC_SET")?;
        for s in m.all("GEOMETRIC_CURVE_SET")? {
            if !sets.iter().any(|x| x.id == s.id) {
                sets.push(s);
            }
        }
        let mut taken = std::collections::HashSet::new();
        let same_surface = cad::first_with_same_surface(&faces);
        for set in &sets {
            let p = set
                .record("GEOMETRIC_CURVE_SET")
                .or_else(|| set.record("GEOMETRIC_SET"))
                .unwrap_or(&[]);
            for eid in refs(set, p.get(1), "elements")? {
                if !taken.insert(eid) {
                    report
                        .skipped
                        .push(format!("#{eid}: listed again in #{}: taken once", set.id));
                    continue;
                }
                let e = &m.get(set, eid)?;
                if e.is("CARTESIAN_POINT") || e.is("POINT_ON_CURVE") || e.is("POINT_ON_SURFACE") {
                    report
                        .skipped
                        .push(format!("#{eid} {}: a point, not a contour", e.name()));
                    continue;
                }
                if e.is("LINE") {
                    report.skipped.push(format!("#{eid} LINE: unbounded"));
                    continue;
                }
                let is_curve = [
                    "COMPOSITE_CURVE",
                    "TRIMMED_CURVE",
                    "B_SPLINE_CURVE_WITH_KNOTS",
                    "B_SPLINE_CURVE",
                    "BEZIER_CURVE",
                    "CIRCLE",
                    "ELLIPSE",
                    "POLYLINE",
                ]
                .iter()
                .any(|n| e.is(n));
                if !is_curve {
                    report
                        .skipped
                        .push(format!("#{eid} {}: not a curve kerf cuts", e.name()));
                    continue;
                }
                let segs: Vec<(NurbsCurve, String)> = curves::bounded_segments(&m, e)?
                    .into_iter()
                    .map(|(c, id)| (c, format!("#{id}")))
                    .collect();
                let place = StepPlace { m: &m, inst: e };
                // The set's placements: once where it lies, or once per instance of its part.
                let instances: Vec<(Option<usize>, Option<assembly::Rigid>)> =
                    match placements.sets.get(&set.id) {
                        None => vec![(None, None)],
                        Some(v) if v.len() == 1 => vec![(None, Some(v[0]))],
                        Some(v) => v
                            .iter()
                            .enumerate()
                            .map(|(k, t)| (Some(k + 1), Some(*t)))
                            .collect(),
                    };
                for (k, t) in instances {
                    let segs: Vec<(NurbsCurve, String)> = match t {
                        None => segs.clone(),
                        Some(t) => segs
                            .iter()
                            .map(|(c, n)| {
                                (
                                    shape::moved_curve(c, &|p| assembly::point(&t, p)),
                                    n.clone(),
                                )
                            })
                            .collect(),
                    };
                    let tag = match k {
                        None => format!("#{eid}"),
                        Some(k) => format!("#{eid}@{k}"),
                    };
                    contours.extend(cad::curve_contours(
                        &place,
                        &format!("{tag} {}", e.name()),
                        &tag,
                        name_of(e),
                        &segs,
                        &faces,
                        &same_surface,
                        opts,
                        &mut report,
                    )?);
                }
            }
        }
    }
    // A solid with no cut curves that is one sheet: its features are what there is to cut (as
    // with --edges), said in a warning; any other solid still asks for --edges.
    let mut not_a_sheet = None;
    if contours.is_empty() && !opts.edges && opts.sheet && !faces.is_empty() {
        match sheet::recognise(&faces, |f, n| step_charge(&m, &faces, f, n))? {
            Ok(s) => {
                report.warnings.push(format!(
                    "no curve in a GEOMETRIC_SET or GEOMETRIC_CURVE_SET: the {} faces form one sheet {:.3} mm thick, whose {} features are cut (as with the edges option)",
                    faces.len(),
                    s.thickness_mm,
                    s.features.len()
                ));
                contours.extend(cad::sheet_contours(&s, &faces, opts, &mut report));
                sheet = Some(Ok(s));
            }
            Err(why) => not_a_sheet = Some(why),
        }
    }
    if contours.is_empty() {
        let reason = if opts.edges {
            format!(
                "no face boundary loop ({} faces read, {} skipped)",
                faces.len(),
                report.skipped.len()
            )
        } else {
            format!(
                "no curve in a GEOMETRIC_SET or GEOMETRIC_CURVE_SET ({} faces read{}; the edges option, ImportOptions::with_edges, cuts their boundary loops)",
                faces.len(),
                not_a_sheet.map_or_else(String::new, |why| format!(", not one sheet: {why}"))
            )
        };
        return Err(StepError::NoContour { reason });
    }
    let everything = opts.all_faces || matches!(sheet, Some(Ok(_)));
    let face_edges = opts.edges || sheet.as_ref().is_some_and(|s| s.is_ok());
    report.uncertainty_mm = m.uncertainty_mm;
    let file = cad::finish(&faces, contours, everything, face_edges, &mut report);
    report.work = m.work();
    Ok(Import { file, report })
}

/// The most characters of a STEP entity's name kept in a contour's id.
pub const MAX_NAME_CHARS: usize = 120;

use crate::cad::Contour;

/// Charges `n` face tests to face `f` of `faces` (the sheet recognition's budget).
fn step_charge(m: &Model<'_>, faces: &[Face], f: usize, n: usize) -> Result<()> {
    if let Some(i) = m.ex.get(faces[f].id)? {
        m.charge(&i, model::Charge::FaceTests, n)?;
    }
    Ok(())
}

/// Where the STEP reader is: the entity being read names errors and pays for projections
/// (the model's face-test budget).
pub(crate) struct StepPlace<'m, 'a> {
    pub(crate) m: &'m Model<'a>,
    pub(crate) inst: &'m parser::Instance,
}

impl cad::Place for StepPlace<'_, '_> {
    type Error = StepError;

    fn defect(&self, message: String) -> StepError {
        model::err(self.inst, message)
    }

    fn charge(&self, n: usize) -> Result<()> {
        self.m.charge(self.inst, model::Charge::FaceTests, n)
    }
}

/// The faces where their parts' placements put them: a face of a part placed once is moved
/// there (same id); a face of a part placed k > 1 times becomes k faces, `#id@1` .. `#id@k`,
/// whose edge ids carry the instance in their top 16 bits ([`shape::edge_tag`] shows them as
/// `#47@2`), so that two instances share no edge.
///
/// # Errors
/// An edge entity number of 2^48 or more in a part placed more than once (no room for the
/// instance).
fn place_faces(
    faces: Vec<Face>,
    placements: &std::collections::HashMap<u64, std::rc::Rc<Vec<assembly::Rigid>>>,
) -> Result<Vec<Face>> {
    if placements.is_empty() {
        return Ok(faces);
    }
    // The control points the placed copies make, counted before any is made (a face of a
    // 200,000-point surface placed 10,000 times asked for tens of gigabytes).
    let mut points = 0usize;
    for f in &faces {
        let copies = placements.get(&f.id).map_or(0, |v| v.len());
        let (nu, nv) = f.surface.net_size();
        let own = nu * nv + f.loops.iter().flatten().map(NurbsCurve::len).sum::<usize>();
        points = points.saturating_add(own.saturating_mul(copies));
        if points > assembly::MAX_PLACED_POINTS {
            return Err(StepError::Budget {
                what: "control points of placed faces".into(),
                limit: assembly::MAX_PLACED_POINTS as u64,
                place: format!("#{} (placed {copies} times)", f.id),
            });
        }
    }
    // Instances go in the top bits of edge ids: with any part placed more than once, no edge
    // number may reach them.
    if placements.values().any(|v| v.len() > 1) {
        if let Some((f, e)) = faces.iter().find_map(|f| {
            f.edge_ids
                .iter()
                .flatten()
                .find(|&&e| e >> shape::INSTANCE_SHIFT != 0)
                .map(|e| (f, *e))
        }) {
            return Err(StepError::Entity {
                id: f.id,
                name: "face".into(),
                message: format!(
                    "edge #{e}: in a file that places a part more than once, entity numbers of 2^48 and more leave no room to tell the instances apart"
                ),
            });
        }
    }
    let mut out = Vec::with_capacity(faces.len());
    for f in faces {
        match placements.get(&f.id) {
            None => out.push(f),
            Some(v) if v.len() == 1 => {
                if v[0].is_identity() {
                    out.push(f);
                } else {
                    out.push(f.moved(&v[0].r, &v[0].t, None, 0));
                }
            }
            Some(v) => {
                for (k, t) in v.iter().enumerate() {
                    let tag = ((k as u64) + 1) << shape::INSTANCE_SHIFT;
                    out.push(f.moved(&t.r, &t.t, Some(k + 1), tag));
                }
            }
        }
    }
    Ok(out)
}
