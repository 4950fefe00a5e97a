//! Reads cut contours and the faces they lie on from IGES (5.x, ASCII fixed form) into
//! `kerf.curves/1`, through the same CAD layer as the STEP reader ([`kerf_step::cad`]).
//!
//! - **Contours** are the free-standing curves of the file (status: not physically dependent,
//!   entity use geometry; a curve another entity uses is part of that entity): lines (110),
//!   circular arcs (100), conic arcs (104: ellipses, hyperbolas, parabolas), polylines (106
//!   forms 11-13, 63), rational B-splines (126) and composites of these (102); each becomes one
//!   NURBS curve with a C0 knot at every join, gaps up to [`ImportOptions`]'s `close_gaps_mm`
//!   closed. With `edges` ([`ImportOptions::with_edges`]), the boundary loops of the trimmed
//!   surfaces (144, through their model-space curves 142) are the contours instead; the faces
//!   are sewn ([`kerf_step::cad::sew`]) so that a sheet-metal solid's features are cut once.
//! - **Surfaces**: every trimmed surface (144) and every free-standing untrimmed surface is a
//!   face: B-spline surfaces (128), planes (108, 190), surfaces of revolution (120) and
//!   tabulated cylinders (122), exact, cut to the face's boundary. A contour names the faces
//!   its dense samples lie on.
//! - **Transformations** (124) apply to every entity, chained through the matrices' own.
//! - **Units**: the global section's unit flag (inch, mm, feet, ..., 3 with the unit's name);
//!   the file's resolution (global field 19) is the edges' tolerance, as for a STEP file's
//!   uncertainty, and the sewing tolerance.
//! - **Errors** name the entity by its directory entry: `D45 (126 rational B-spline curve): ...`.
//!
//! Not read (said in the import's report, never guessed): compressed and binary IGES, the
//! B-rep form (186 solids of 510 faces), bounded surfaces (143), offset curves and surfaces,
//! a boundary given only in parameter space. `docs/iges.md` has the details.
//!
//! ```
//! # fn main() -> Result<(), kerf_iges::IgesError> {
//! // A full circle of radius 5 about (10, 0, 0), in mm (unit flag 2).
//! let g = ",,,,,,,,,,,,,2,,,,,,,,,;";
//! let iges = [
//!     format!("{:72}S      1", "a circle"),
//!     format!("{g:72}G      1"),
//!     format!("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D      1", 100, 1, 0, 0, 0, 0, 0, 0, "00000000"),
//!     format!("{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}D      2", 100, 0, 0, 1, 0, "", "", "HOLE", 0),
//!     format!("{:64}{:>8}P      1", "100,0.,10.,0.,15.,0.,15.,0.;", 1),
//!     format!("{:72}T      1", "S      1G      1D      2P      1"),
//! ]
//! .join("\n");
//! let import = kerf_iges::import(iges.as_bytes(), &kerf_iges::ImportOptions::default())?;
//! let c = &import.file.curves[0];
//! assert_eq!(c.id, "HOLE D1");
//! assert_eq!(c.degree, 2);
//! # Ok(())
//! # }
//! ```

// `!(x > 0.0)` rejects NaN together with the out-of-range values in one test; every such
// comparison in this crate guards file data that may be NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod entities;
mod error;
mod parser;

use std::collections::HashSet;
use std::path::Path;

use kerf_nurbs::NurbsCurve;
use kerf_step::cad::{self, Face, Place};
use kerf_step::{Report, Units, Work};

pub use error::{FileError, IgesError, Result};
pub use kerf_step::{Import, ImportOptions};

use crate::entities::{err, int, kind_name, Reader};
use crate::parser::{Entry, Token};
use kerf_step::cad::Charge;

/// Where the IGES reader is: the entity being read names errors and pays for projections.
struct IgesPlace<'r, 'a> {
    reader: &'r Reader<'a>,
    entry: &'r Entry,
}

impl Place for IgesPlace<'_, '_> {
    type Error = IgesError;

    fn defect(&self, message: String) -> IgesError {
        err(self.entry, message)
    }

    fn charge(&self, n: usize) -> Result<()> {
        self.reader.charge(self.entry, Charge::FaceTests, n)
    }
}

/// Reads an IGES file from disk through kerf's one reader (`kerf_io::read_file`: at most
/// 1 GiB); see [`import`].
///
/// # Errors
/// [`FileError`] naming the file around any [`IgesError`].
pub fn import_file(
    path: impl AsRef<Path>,
    opts: &ImportOptions,
) -> std::result::Result<Import, FileError> {
    let path = path.as_ref();
    let bytes = kerf_io::read_file(path).map_err(|source| {
        IgesError::Read {
            path: path.to_path_buf(),
            source,
        }
        .in_file(path)
    })?;
    import(&bytes, opts).map_err(|e| e.in_file(path))
}

/// Whether `bytes` look like an IGES file: an 80-column first record with `S` (or `G`) in
/// column 73 (for a file whose extension says nothing).
pub fn looks_like_iges(bytes: &[u8]) -> bool {
    let bytes = kerf_io::strip_bom(bytes);
    let first = bytes.split(|&b| b == b'\n').next().unwrap_or(&[]);
    let first = first.strip_suffix(b"\r").unwrap_or(first);
    first.len() >= 73 && matches!(first[72], b'S' | b'G')
}

/// The length units of global field 14 (and 15 for flag 3): mm per unit and the unit's name.
fn units(iges: &parser::Iges) -> std::result::Result<(f64, &'static str), String> {
    let flag = match iges.global_field(14) {
        Token::Empty => 1,
        Token::Raw(s) => s
            .parse::<f64>()
            .ok()
            .filter(|x| x.fract() == 0.0)
            .map(|x| x as i64)
            .ok_or_else(|| format!("global field 14 (unit flag) {s:?} is not an integer"))?,
        Token::Text(_) => return Err("global field 14 (unit flag) is a string".into()),
    };
    let named = |name: &str| -> Option<(f64, &'static str)> {
        Some(match name.trim().to_ascii_uppercase().as_str() {
            "IN" | "INCH" => (25.4, "inch"),
            "MM" => (1.0, "mm"),
            "FT" => (304.8, "foot"),
            "MI" => (1_609_344.0, "mile"),
            "M" => (1000.0, "m"),
            "KM" => (1_000_000.0, "km"),
            "MIL" => (0.0254, "mil"),
            "UM" | "MICRON" => (0.001, "micron"),
            "CM" => (10.0, "cm"),
            "UIN" => (2.54e-5, "microinch"),
            _ => return None,
        })
    };
    Ok(match flag {
        1 => (25.4, "inch"),
        2 => (1.0, "mm"),
        3 => match iges.global_field(15) {
            Token::Text(s) => named(s).ok_or_else(|| {
                format!("unit flag 3 names the unit {s:?}, which kerf does not know")
            })?,
            _ => return Err("unit flag 3 without a unit name (global field 15)".into()),
        },
        4 => (304.8, "foot"),
        5 => (1_609_344.0, "mile"),
        6 => (1000.0, "m"),
        7 => (1_000_000.0, "km"),
        8 => (0.0254, "mil"),
        9 => (0.001, "micron"),
        10 => (10.0, "cm"),
        11 => (2.54e-5, "microinch"),
        f => return Err(format!("unit flag {f} is not one of IGES's (1 to 11)")),
    })
}

/// Whether an entity stands on its own: its subordinate switch is 00 (independent) or 02
/// (logically dependent: referred to by a group or another associativity only, as Open
/// CASCADE writes every shape of a compound), not 01 or 03 (physically dependent: part of
/// another entity).
fn free_standing(e: &Entry) -> bool {
    matches!(e.status[1], 0 | 2)
}

/// The sewing tolerance of a file that gives no resolution, mm.
const SEW_DEFAULT_MM: f64 = 1e-3;
/// The least sewing tolerance, mm: above the rounding of 10 printed digits on a metre-sized
/// part (two copies of one edge written through different matrices).
const SEW_FLOOR_MM: f64 = 1e-6;

/// The entity types that are curves kerf cuts.
const CURVE_TYPES: [i64; 6] = [100, 102, 104, 106, 110, 126];
/// The entity types that are surfaces kerf reads.
const SURFACE_TYPES: [i64; 5] = [108, 120, 122, 128, 190];

/// Reads the bytes of an IGES file into a `kerf.curves/1` document (a leading byte-order mark
/// is skipped).
///
/// # Errors
/// [`IgesError::Syntax`] for a file not laid out as IGES, [`IgesError::Entity`] naming the
/// entity for a defect in a contour (a face's defect is skipped and reported instead),
/// [`IgesError::NoContour`] if nothing can be cut, [`IgesError::Budget`], and
/// [`IgesError::Options`] for a non-positive or non-finite option.
pub fn import(bytes: &[u8], opts: &ImportOptions) -> Result<Import> {
    cad::check_options(opts).map_err(IgesError::Options)?;
    let iges = parser::parse(bytes)?;
    let (mm, unit_name) = units(&iges).map_err(|m| IgesError::Syntax {
        line: 1,
        message: m,
    })?;
    let mut report = Report {
        schemas: vec![version(&iges)],
        units: Units {
            mm_per_length: mm,
            rad_per_angle: 1.0,
            length_name: unit_name,
        },
        ..Report::default()
    };
    if let Token::Raw(s) = iges.global_field(13) {
        if s.parse::<f64>().is_ok_and(|x| x != 1.0) {
            report.warnings.push(format!(
                "the model space scale (global field 13) is {s}: coordinates are read as model space, unscaled (as Open CASCADE reads them)"
            ));
        }
    }
    // The file's resolution: how far apart two points may be and still be one.
    if let Token::Raw(s) = iges.global_field(19) {
        if let Some(r) = s
            .replace(['D', 'd'], "E")
            .parse::<f64>()
            .ok()
            .filter(|r| r.is_finite() && *r > 0.0)
        {
            report.uncertainty_mm = Some(r * mm);
        }
    }
    let reader = Reader::new(&iges, mm);

    // What other entities use: a curve some surface or composite uses is not a cut line.
    let mut used: HashSet<usize> = HashSet::new();
    for e in &iges.entries {
        let refs: Vec<usize> = match e.ty {
            // N, then N segment pointers (optional associativity and property pointers may
            // follow: not entities this one is made of).
            102 => {
                let n = int(e, 0, "N").unwrap_or(0).clamp(0, e.params.len() as i64) as usize;
                (1..=n).collect()
            }
            120 => vec![0, 1],
            122 => vec![0],
            142 => vec![1, 2, 3],
            144 => {
                let n2 = int(e, 2, "N2").unwrap_or(0).clamp(0, e.params.len() as i64) as usize;
                let mut v = vec![0, 3];
                v.extend(4..4 + n2);
                v
            }
            108 => vec![4],
            190 => vec![0, 1, 2],
            // TYPE, SPTR, N, then N boundary pointers.
            143 => {
                let n = int(e, 2, "N").unwrap_or(0).clamp(0, e.params.len() as i64) as usize;
                let mut v = vec![1];
                v.extend(3..3 + n);
                v
            }
            // TYPE, PREF, SPTR, N, then per curve: CRVPT, SENSE, K, K parameter-space curves.
            141 => {
                let mut v = vec![2];
                let n = int(e, 3, "N").unwrap_or(0).clamp(0, e.params.len() as i64) as usize;
                let mut i = 4;
                for _ in 0..n {
                    if i + 2 >= e.params.len() {
                        break;
                    }
                    v.push(i);
                    let k = int(e, i + 2, "K")
                        .unwrap_or(0)
                        .clamp(0, e.params.len() as i64) as usize;
                    v.extend(i + 3..(i + 3 + k).min(e.params.len()));
                    i += 3 + k;
                }
                v
            }
            _ => Vec::new(),
        };
        for i in refs {
            if let Ok(de) = int(e, i, "pointer") {
                if de > 0 {
                    used.insert(de as usize);
                }
            }
        }
    }

    // Entities that carry no geometry kerf cuts (colours, properties, groups, notes, views):
    // one line per type.
    let mut ignored: std::collections::BTreeMap<i64, (usize, usize)> = Default::default();
    for e in &iges.entries {
        let read = CURVE_TYPES.contains(&e.ty)
            || SURFACE_TYPES.contains(&e.ty)
            || matches!(e.ty, 116 | 123 | 124 | 141..=144 | 186 | 192..=198 | 502..=514);
        if !read {
            let n = ignored.entry(e.ty).or_insert((e.de, 0));
            n.1 += 1;
        }
    }
    for (ty, (first, n)) in ignored {
        report.skipped.push(format!(
            "{n} entities of type {ty} ({}), the first D{first}: not geometry kerf cuts, ignored",
            kind_name(ty)
        ));
    }
    // Faces: every trimmed surface, and every surface nothing uses (untrimmed): read, their
    // edges sewn (IGES faces share no edge entities), then built.
    let mut pending: Vec<Pending<'_>> = Vec::new();
    for e in &iges.entries {
        let outline = match e.ty {
            144 => Some(trimmed_outline(&reader, e)),
            ty if SURFACE_TYPES.contains(&ty)
                && free_standing(e)
                && !used.contains(&e.de)
                && !matches!(ty, 108 | 190) =>
            {
                Some(untrimmed_outline(&reader, e))
            }
            141 | 143 => {
                report.skipped.push(format!(
                    "D{} ({} {}): bounded surfaces are not read; export trimmed surfaces (144)",
                    e.de,
                    e.ty,
                    kind_name(e.ty)
                ));
                None
            }
            186 | 510 | 514 => {
                report.skipped.push(format!(
                    "D{} ({} {}): the B-rep form of IGES is not read; export trimmed surfaces (144)",
                    e.de,
                    e.ty,
                    kind_name(e.ty)
                ));
                None
            }
            _ => None,
        };
        match outline {
            Some(Ok(p)) => pending.push(p),
            Some(Err(x @ IgesError::Budget { .. })) => return Err(x),
            Some(Err(x)) => report.skipped.push(format!("face {x}")),
            None => {}
        }
    }
    // Two faces' copies of one edge coincide to the file's resolution (what the writer cannot
    // tell apart); parts have real features a few micrometres wide (S06298's 0.002 mm steps),
    // so nothing looser. A file without a resolution: 0.001 mm, STEP's usual uncertainty.
    let sew_tolerance = report
        .uncertainty_mm
        .unwrap_or(SEW_DEFAULT_MM)
        .clamp(SEW_FLOOR_MM, cad::ON_GEOMETRY_TOLERANCE_MM);
    let sewn = {
        let loops: Vec<&[Vec<NurbsCurve>]> = pending.iter().map(|p| p.loops.as_slice()).collect();
        let ids: Vec<Vec<Vec<u64>>> = pending.iter().map(|p| p.ids.clone()).collect();
        cad::sew(&loops, &ids, sew_tolerance, |f, n| {
            reader.charge(pending[f].entry, Charge::FaceTests, n)
        })?
    };
    let mut faces: Vec<Face> = Vec::new();
    for (p, ids) in pending.into_iter().zip(sewn) {
        let place = IgesPlace {
            reader: &reader,
            entry: p.entry,
        };
        let reversed = revolution_reversed(&p.g);
        match cad::face(
            &place,
            "D",
            p.entry.de as u64,
            p.entry.label.clone(),
            &p.g,
            p.loops,
            ids,
            &[],
            &p.params,
            p.natural,
            reversed,
        ) {
            Ok(f) => faces.push(f),
            Err(x @ IgesError::Budget { .. }) => return Err(x),
            Err(x) => report.skipped.push(format!("face {x}")),
        }
    }
    report.faces_read = faces.len();
    let charge = |f: usize, n: usize| {
        let e = iges
            .entry(faces[f].id() as usize)
            .unwrap_or(&iges.entries[0]);
        reader.charge(e, Charge::FaceTests, n)
    };

    let mut contours = Vec::new();
    // Sheet recognition: every face of a solid, no face chosen by hand.
    let mut sheet = if opts.edges && opts.faces.is_none() && opts.sheet {
        Some(cad::recognise_sheet(&faces, charge)?)
    } else {
        None
    };
    if let Some(Ok(s)) = &sheet {
        contours = cad::sheet_contours(s, &faces, opts, &mut report);
    } else if opts.edges {
        if let Some(Err(why)) = &sheet {
            report.sheet = Some(kerf_step::SheetReport::not_a_sheet(why));
        }
        if let Some(reason) = cad::unknown_face(&faces, opts, "D") {
            return Err(IgesError::NoContour { reason });
        }
        contours = cad::face_loop_contours(&faces, opts, &mut report);
    } else {
        let same_surface = cad::first_with_same_surface(&faces);
        for e in &iges.entries {
            if !CURVE_TYPES.contains(&e.ty) || used.contains(&e.de) {
                continue;
            }
            if !free_standing(e) {
                continue; // physically dependent: part of something else
            }
            if e.status[2] != 0 {
                report.skipped.push(format!(
                    "D{} ({} {}): entity use {} ({}), not geometry to cut",
                    e.de,
                    e.ty,
                    kind_name(e.ty),
                    e.status[2],
                    match e.status[2] {
                        1 => "annotation",
                        2 => "definition",
                        3 => "other",
                        4 => "logical/positional",
                        5 => "2D parametric",
                        6 => "construction geometry",
                        _ => "unknown",
                    }
                ));
                continue;
            }
            let segs = match reader.curve(e, &[]) {
                Ok(s) => s,
                Err(x @ IgesError::Budget { .. }) => return Err(x),
                Err(x) => {
                    report.skipped.push(x.to_string());
                    continue;
                }
            };
            let place = IgesPlace {
                reader: &reader,
                entry: e,
            };
            let name = if e.subscript != 0 && !e.label.is_empty() {
                format!("{}({})", e.label, e.subscript)
            } else {
                e.label.clone()
            };
            contours.extend(cad::curve_contours(
                &place,
                &format!("D{} {}", e.de, kind_name(e.ty)),
                &format!("D{}", e.de),
                name,
                &segs,
                &faces,
                &same_surface,
                opts,
                &mut report,
            )?);
        }
        // No free curve, and the faces are one sheet: its features are what there is to cut
        // (as with --edges), said in a warning.
        if contours.is_empty() && opts.sheet && !faces.is_empty() {
            if let Ok(s) = cad::recognise_sheet(&faces, charge)? {
                report.warnings.push(format!(
                    "no free curve: the {} faces form one sheet {:.3} mm thick, whose {} features are cut (as with the edges option)",
                    faces.len(),
                    s.thickness_mm(),
                    s.feature_count()
                ));
                contours = cad::sheet_contours(&s, &faces, opts, &mut report);
                sheet = Some(Ok(s));
            }
        }
    }
    if contours.is_empty() {
        let reason = if opts.edges {
            format!(
                "no trimmed surface's boundary loop ({} faces read, {} skipped{})",
                faces.len(),
                report.skipped.len(),
                report
                    .skipped
                    .first()
                    .map_or_else(String::new, |s| format!("; the first: {s}"))
            )
        } else {
            format!(
                "no free-standing curve ({} faces read; the edges option, ImportOptions::with_edges, cuts their boundary loops)",
                faces.len()
            )
        };
        return Err(IgesError::NoContour { reason });
    }
    let is_sheet = matches!(sheet, Some(Ok(_)));
    let file = cad::finish(
        &faces,
        contours,
        opts.all_faces || is_sheet,
        opts.edges || is_sheet,
        &mut report,
    );
    let mut work = Work::default();
    work.instances = iges.entries.len() as u64;
    work.segments = reader.spent(Charge::Segments);
    work.curve_points = reader.spent(Charge::CurvePoints);
    work.surface_points = reader.spent(Charge::SurfacePoints);
    work.face_tests = reader.spent(Charge::FaceTests);
    report.work = work;
    Ok(Import { file, report })
}

/// The IGES version of global field 23, as the report's schema line.
fn version(iges: &parser::Iges) -> String {
    let v = match iges.global_field(23) {
        Token::Raw(s) => s.parse::<i64>().unwrap_or(0),
        _ => 0,
    };
    let name = match v {
        1 => "1.0",
        3 => "2.0",
        4 => "3.0",
        6 => "4.0",
        8 => "5.0",
        9 => "5.1",
        10 => "5.2",
        11 => "5.3",
        2 | 5 | 7 => "ANSI/ASME Y14.26M",
        _ => "(version not given)",
    };
    format!("IGES {name}")
}

/// A face read but not yet built: its surface and loops, with the loops' edge ids (their
/// curve entities) until they are sewn.
struct Pending<'e> {
    entry: &'e Entry,
    g: kerf_step::cad::Geometry,
    natural: Option<kerf_step::cad::ParamBox>,
    loops: Vec<Vec<NurbsCurve>>,
    ids: Vec<Vec<u64>>,
    /// Boundary points in the surface's parameters (from the 142s' parameter-space curves).
    params: Vec<(f64, f64)>,
}

/// A 144: its surface and its boundary loops (the 142s' model-space curves; on a B-spline
/// surface their parameter-space curves widen the face's parameter range, see
/// [`parameter_points`]).
fn trimmed_outline<'e>(reader: &Reader<'e>, e: &'e Entry) -> Result<Pending<'e>> {
    let s = reader.get(e, int(e, 0, "surface")?, "its surface")?;
    // The 144's own matrix moves its surface and its boundaries (as Open CASCADE reads it).
    let (g, natural) = reader.surface(s, &[e])?;
    let n1 = int(e, 1, "N1")?;
    let n2 = int(e, 2, "N2")?;
    let n2 = usize::try_from(n2)
        .ok()
        .filter(|&n| n <= e.params.len())
        .ok_or_else(|| err(e, format!("N2 (inner boundaries) is {n2}")))?;
    let mut loops: Vec<Vec<NurbsCurve>> = Vec::new();
    let mut ids: Vec<Vec<u64>> = Vec::new();
    let mut params = Vec::new();
    if n1 == 0 {
        let Some(b) = natural else {
            return Err(err(
                e,
                "its outer boundary is its surface's, but a plane has none".into(),
            ));
        };
        let (l, i) = box_loop(e, &g, b)?;
        loops.push(l);
        ids.push(i);
    } else {
        let de = int(e, 3, "outer boundary")?;
        let (l, i) = boundary(reader, e, de, "outer boundary")?;
        if let kerf_step::cad::Geometry::Nurbs(surface) = &g {
            params.extend(parameter_points(reader, e, de, surface, &l)?);
        }
        loops.push(l);
        ids.push(i);
    }
    for k in 0..n2 {
        let de = int(e, 4 + k, "inner boundary")?;
        let (l, i) = boundary(reader, e, de, &format!("inner boundary {}", k + 1))?;
        if let kerf_step::cad::Geometry::Nurbs(surface) = &g {
            params.extend(parameter_points(reader, e, de, surface, &l)?);
        }
        loops.push(l);
        ids.push(i);
    }
    Ok(Pending {
        entry: e,
        g,
        natural,
        loops,
        ids,
        params,
    })
}

/// An untrimmed surface, bounded by its parameter box.
fn untrimmed_outline<'e>(reader: &Reader<'e>, e: &'e Entry) -> Result<Pending<'e>> {
    let (g, natural) = reader.surface(e, &[])?;
    let Some(b) = natural else {
        return Err(err(e, "an unbounded plane has no boundary to cut".into()));
    };
    let (l, i) = box_loop(e, &g, b)?;
    Ok(Pending {
        entry: e,
        g,
        natural,
        loops: vec![l],
        ids: vec![i],
        params: Vec::new(),
    })
}

/// IGES parametrizes a surface of revolution (120) with u along the generatrix and v the
/// angle, so its natural normal is `C'(u) x dS/dv`, the opposite of kerf's
/// [`Geometry::Revolution`] (angle first); the face is turned round to the file's normal (as
/// Open CASCADE reads it).
///
/// [`Geometry::Revolution`]: kerf_step::cad::Geometry::Revolution
fn revolution_reversed(g: &kerf_step::cad::Geometry) -> bool {
    matches!(g, kerf_step::cad::Geometry::Revolution { .. })
}

/// The boundary of the parameter box as a loop of four edges (the surface's iso-curves at
/// the box's sides), an edge of zero length (a pole) left out. The ids are the face's own
/// number with the side (`4 de + side`), distinct from every curve's.
fn box_loop(
    e: &Entry,
    g: &kerf_step::cad::Geometry,
    b: ((f64, f64), (f64, f64)),
) -> Result<(Vec<NurbsCurve>, Vec<u64>)> {
    let s = g.to_nurbs(b.0, b.1).map_err(|m| err(e, m.to_string()))?;
    let (nu, nv) = s.net_size();
    let pts = s.control_points();
    let w = s.weights();
    let side = |p: Vec<nalgebra::Point3<f64>>, ws: Vec<f64>, knots: &[f64], degree: usize| {
        NurbsCurve::try_new(degree, knots.to_vec(), p, Some(ws)).map_err(|x| err(e, x.to_string()))
    };
    let col = |b: usize| {
        (
            (0..nu).map(|a| pts[a][b]).collect::<Vec<_>>(),
            (0..nu).map(|a| w[a][b]).collect::<Vec<_>>(),
        )
    };
    let row = |a: usize| (pts[a].clone(), w[a].clone());
    let (p0, w0) = col(0);
    let (p1, w1) = row(nu - 1);
    let (p2, w2) = col(nv - 1);
    let (p3, w3) = row(0);
    let sides = [
        side(p0, w0, s.knots_u(), s.degree_u())?,
        side(p1, w1, s.knots_v(), s.degree_v())?,
        side(p2, w2, s.knots_u(), s.degree_u())?.reversed(),
        side(p3, w3, s.knots_v(), s.degree_v())?.reversed(),
    ];
    let mut loop_ = Vec::new();
    let mut ids = Vec::new();
    for (k, c) in sides.into_iter().enumerate() {
        if c.size() > 0.0 {
            loop_.push(c);
            ids.push(4 * e.de as u64 + k as u64);
        }
    }
    Ok((loop_, ids))
}

/// The extremes in u and in v of a 142's parameter-space curve (none where it has none): a
/// B-spline surface's parameters at the boundary's least and greatest u and v, each found on
/// 181 samples per segment and refined by golden-section search about the extreme sample
/// (the better of the two taken).
///
/// A 142's PREF says which of its curves the file prefers; CAD systems commonly write 1, the
/// parameter-space curve, with a model-space copy that lies up to a few micrometres off it
/// (3e-3 mm on pyiges' SolidWorks impeller). kerf cuts the model-space curve (`edges`), and
/// the face's parameter range covers both: the projections of the model-space curve and these
/// points, so the face's surface reaches the boundary the file prefers too. The curve is read
/// in its own space: its matrix applies; the 142's and the face's (which move model space)
/// and the unit scale do not. A parameter-space curve kerf cannot read (a pointer or a curve
/// that is not one), or whose extremes do not map within [`cad::ON_GEOMETRY_TOLERANCE_MM`] of
/// the model-space curve (another parametrisation, a wrong curve), is not used. The samples
/// and the four checks are charged to the face-test budget before they are made.
fn parameter_points(
    reader: &Reader<'_>,
    face: &Entry,
    de: i64,
    surface: &kerf_nurbs::NurbsSurface,
    edges: &[NurbsCurve],
) -> Result<Vec<(f64, f64)>> {
    const SAMPLES: usize = 181;
    let b = reader.get_typed(face, de, "its boundary", 142)?;
    let pc = int(b, 2, "parameter-space curve").unwrap_or(0);
    if pc <= 0 {
        return Ok(Vec::new());
    }
    // The parameter-space curve only widens the range: one kerf cannot read is left out (the
    // model-space curve, which kerf cuts, is read as before); the work budget still binds.
    let segs = match reader
        .get(b, pc, "its parameter-space curve")
        .and_then(|ce| reader.parameter_curve(ce))
    {
        Ok(segs) => segs,
        Err(x @ IgesError::Budget { .. }) => return Err(x),
        Err(_) => return Ok(Vec::new()),
    };
    // Per segment its samples and four searches; per boundary four checks on every edge.
    reader.charge(
        face,
        Charge::FaceTests,
        segs.len() * (SAMPLES + 4 * (GOLDEN_STEPS + 2)) + 4 * edges.len(),
    )?;
    // extremes[axis][0]: the least, [1]: the greatest, as (value, point).
    let mut extremes = [[(f64::INFINITY, (0.0, 0.0)); 2]; 2];
    for (c, _) in &segs {
        let (a, z) = c.domain();
        let t_at = |k: usize| a + (z - a) * k as f64 / (SAMPLES - 1) as f64;
        let values: Vec<(f64, f64)> = (0..SAMPLES)
            .map(|k| {
                let p = c.point(t_at(k));
                (p.x, p.y)
            })
            .collect();
        for axis in [0, 1] {
            let coord = |q: (f64, f64)| if axis == 0 { q.0 } else { q.1 };
            for (end, sign) in [(0, -1.0), (1, 1.0)] {
                // The extreme sample, then the search about it (the better of the two).
                let best = (0..SAMPLES)
                    .max_by(|&i, &j| {
                        (sign * coord(values[i])).total_cmp(&(sign * coord(values[j])))
                    })
                    .unwrap_or(0);
                let lo = t_at(best.saturating_sub(1));
                let hi = t_at((best + 1).min(SAMPLES - 1));
                let p = c.point(golden_max(|t| sign * c.point(t)[axis], lo, hi));
                let mut found = values[best];
                if sign * coord((p.x, p.y)) > sign * coord(found) {
                    found = (p.x, p.y);
                }
                let key = -sign * coord(found);
                if key < extremes[axis][end].0 {
                    extremes[axis][end] = (key, found);
                }
            }
        }
    }
    let points: Vec<(f64, f64)> = extremes
        .iter()
        .flatten()
        .filter(|(key, _)| key.is_finite())
        .map(|&(_, q)| q)
        .collect();
    for &(u, v) in &points {
        let on = surface.point(u, v);
        let off = edges
            .iter()
            .filter(|e| {
                let (lo, hi) = e.bounding_box();
                kerf_nurbs::distance_to_box(&on, &lo, &hi) <= cad::ON_GEOMETRY_TOLERANCE_MM
            })
            .map(|e| e.closest_point(&on).distance)
            .fold(f64::INFINITY, f64::min);
        if !(off <= cad::ON_GEOMETRY_TOLERANCE_MM) {
            return Ok(Vec::new());
        }
    }
    Ok(points)
}

/// Steps of [`golden_max`]: the bracket (two of 180 sample intervals) shrinks by 0.618^60
/// (3e-13), below the resolution of a parameter there.
const GOLDEN_STEPS: usize = 60;

/// The argument of the largest value of `f` on `[lo, hi]` where `f` rises then falls there,
/// by golden-section search ([`GOLDEN_STEPS`] steps, two evaluations to start).
fn golden_max(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = hi - r * (hi - lo);
    let mut x2 = lo + r * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_STEPS {
        if f1 < f2 {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        }
    }
    0.5 * (lo + hi)
}

/// A 142's model-space curve as the edges of a loop (each edge named by its curve entity).
fn boundary(
    reader: &Reader<'_>,
    face: &Entry,
    de: i64,
    what: &str,
) -> Result<(Vec<NurbsCurve>, Vec<u64>)> {
    let b = reader.get_typed(face, de, &format!("its {what}"), 142)?;
    let c = int(b, 3, "model-space curve")?;
    if c == 0 {
        return Err(err(
            face,
            format!(
                "its {what} D{} has only a parameter-space curve (no model-space curve to cut)",
                b.de
            ),
        ));
    }
    let ce = reader.get(b, c, "its model-space curve")?;
    // The curve's matrices, then the 142's, then the face's.
    let segs = reader.curve(ce, &[b, face]).map_err(|x| match x {
        x @ IgesError::Budget { .. } => x,
        x => err(face, format!("{what} D{}: {x}", b.de)),
    })?;
    let ids = segs
        .iter()
        .map(|(_, n)| n.trim_start_matches('D').parse::<u64>().unwrap_or(0))
        .collect();
    Ok((segs.into_iter().map(|s| s.0).collect(), ids))
}

#[cfg(test)]
mod tests {
    use super::golden_max;

    /// The golden-section search finds an interior maximum to rounding, and an end maximum at
    /// the end, of functions that rise then fall (or only rise) on the bracket.
    #[test]
    fn golden_max_finds_the_top_of_the_bracket() {
        let t = golden_max(|t| -(t - 0.3141592653589793).powi(2), 0.0, 1.0);
        assert!((t - 0.3141592653589793).abs() < 1e-7, "{t}");
        let t = golden_max(|t| (3.0 * t).sin(), 0.0, 1.0);
        assert!((t - std::f64::consts::FRAC_PI_6).abs() < 1e-7, "{t}");
        let t = golden_max(|t| t, 2.0, 3.0);
        assert!((t - 3.0).abs() < 1e-12, "{t}");
    }
}
