//! Stages 1 and 2 of a job: cutting points with a certified chord error for every curve of a
//! [`CurvesFile`], then the normal of every cutting point from the curve's surface (one normal
//! source per surface, built once; the +z fallback for curves without a surface), and both as
//! `kerf.toolpath/1` records.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use kerf_discretize::{Batch, BatchError, BatchRefusal, Discretization, Options};
use kerf_format::toolpath::{ToolpathFile, ToolpathPoints, ToolpathRecord};
use kerf_format::{CurveRecord, CurvesFile, Pose, SurfaceGeometry};
use kerf_normals::{orient, Hint, MeshNormals, NormalSource, NurbsNormals, Oriented, Projection};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::job::{MissingSurface, OrientOptions};
use crate::{Progress, Stage};

/// The default limit on the cutting points of all curves of [`discretize_curves`] together
/// (20 million, about 2 GB held as a `kerf.toolpath/1` document; `kerf discretize` of 100,000
/// circles at 0.01 mm makes 15.7 million). A whole run costs far more per point: see
/// [`crate::JobOptions::max_total_points`].
pub const DEFAULT_MAX_TOTAL_POINTS: usize = 20_000_000;

/// Discretizes every curve of `file` (in parallel, results in input order), calling
/// `progress` as each curve is done, with at most [`DEFAULT_MAX_TOTAL_POINTS`] cutting points
/// in all ([`discretize_curves_within`]). `source` names the file in errors.
///
/// # Errors
/// As [`discretize_curves_within`].
pub fn discretize_curves(
    file: &CurvesFile,
    opts: &Options,
    source: Option<&Path>,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Discretization>> {
    discretize_curves_within(file, opts, DEFAULT_MAX_TOTAL_POINTS, source, progress)
}

/// [`discretize_curves`] with at most `max_total_points` cutting points over all curves
/// together (`opts.max_points` still limits each curve): one batch of the discretizer
/// ([`curves_batch`], [`Batch::with_max_total_points`], which says exactly what the limit
/// guarantees). In short: a curve whose estimate (the discretizer's own, before it allocates
/// anything) is more than twice what the others have left is refused at once; the estimate is
/// not a bound, so the total itself is then counted exactly: a curve that takes it past the
/// limit fails the job and stops the curves not yet started. Memory stays within about three
/// times the limit on one thread (twice the limit more per further thread) whatever the input;
/// the error names the curve that passed it, which with several threads depends on their
/// timing. The curves are one group, so every thread is busy to the end.
///
/// # Errors
/// [`Error::Options`] for an option out of range, [`Error::Discretize`] for a curve whose
/// tolerance is below its rounding margin (both before any walk); [`Error::TooManyPoints`]
/// when the curves together need more than `max_total_points`; else [`Error::Discretize`]
/// naming the first curve (in file order) that failed.
pub fn discretize_curves_within(
    file: &CurvesFile,
    opts: &Options,
    max_total_points: usize,
    source: Option<&Path>,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Discretization>> {
    let batch = curves_batch(file, opts, source)?.with_max_total_points(max_total_points);
    let mut discs = Vec::with_capacity(file.curves.len());
    discretize_batch(&batch, source, progress, |_, d| {
        discs.push(d);
        Ok::<(), Error>(())
    })?;
    Ok(discs)
}

/// Every curve of `file` as one batch of the discretizer ([`Batch`], one group, no total
/// limit: set them with [`Batch::in_groups_of`] and [`Batch::with_max_total_points`]), checked
/// before any walk: the options, then every curve's tolerance against its rounding margin, so
/// that a tolerance a curve late in the file cannot hold is refused at once, not after the
/// walks of the curves before it. Run it with [`discretize_batch`]; `source` names the file in
/// errors.
///
/// # Errors
/// [`Error::Options`]; [`Error::Discretize`] naming the first curve (in file order) whose
/// tolerance is below its rounding margin.
pub fn curves_batch<'a>(
    file: &'a CurvesFile,
    opts: &Options,
    source: Option<&Path>,
) -> Result<Batch<'a, CurveRecord>> {
    Batch::new(&file.curves, |r| &r.curve, opts).map_err(|refusal| match refusal {
        BatchRefusal::Options(error) => Error::Options(error),
        BatchRefusal::Curve {
            index,
            source: error,
        } => Error::Discretize {
            file: source.map(Path::to_path_buf),
            index,
            id: file.curves[index].id.clone(),
            source: error,
        },
    })
}

/// Runs `batch` (from [`curves_batch`]; [`Batch::each`]): gives `sink` the discretization of
/// every curve on the calling thread, in file order, with its index, while the thread pool
/// discretizes the next group; `progress` as each curve is done. The first error ends it.
/// `source` names the file in errors.
///
/// # Errors
/// [`Error::TooManyPoints`] when the batch has a total limit and a group passes it (checked
/// before the sink sees that group); else [`Error::Discretize`] naming the first curve (in
/// file order) that failed, or the sink's error.
pub fn discretize_batch<E: From<Error>>(
    batch: &Batch<'_, CurveRecord>,
    source: Option<&Path>,
    progress: &(dyn Fn(Progress) + Sync),
    mut sink: impl FnMut(usize, Discretization) -> std::result::Result<(), E>,
) -> std::result::Result<(), E> {
    let records = batch.items();
    let file_path = || source.map(Path::to_path_buf);
    let ran = batch.each(
        &|done, total| progress(Progress::new(Stage::Discretize, done, total)),
        |index, r| match r {
            Ok(d) => sink(index, d),
            Err(error) => Err(E::from(Error::Discretize {
                file: file_path(),
                index,
                id: records[index].id.clone(),
                source: error,
            })),
        },
    );
    ran.map_err(|e| match e {
        BatchError::TooManyPoints {
            limit,
            reached,
            index,
        } => E::from(Error::TooManyPoints {
            file: file_path(),
            limit,
            reached,
            index,
            id: records[index].id.clone(),
        }),
        BatchError::Sink { source, .. } => source,
    })
}

/// The `kerf.toolpath/1` document of `discs` (positions only, no normals): one path per
/// curve of `file`, with the curve's id and the certified chord error.
pub fn toolpath_of_points(
    file: &CurvesFile,
    tolerance_mm: f64,
    discs: &[Discretization],
) -> ToolpathFile {
    toolpath(
        file,
        tolerance_mm,
        discs.iter().map(|d| {
            let points = d.points().iter().map(|p| [p.x, p.y, p.z]).collect();
            (
                d.params(),
                ToolpathPoints::Positions(points),
                d.max_chord_error(),
            )
        }),
    )
}

/// The `kerf.toolpath/1` document of `oriented` (`[x, y, z, i, j, k]` points): one path per
/// curve of `file`.
pub fn toolpath_of_poses(
    file: &CurvesFile,
    tolerance_mm: f64,
    oriented: &[Oriented],
) -> ToolpathFile {
    toolpath(
        file,
        tolerance_mm,
        oriented.iter().map(|o| {
            (
                o.params(),
                ToolpathPoints::Poses(o.poses().iter().map(Pose::to_array).collect()),
                o.max_chord_error(),
            )
        }),
    )
}

/// One path per curve: its id, then the params, points and chord error given.
fn toolpath<'a>(
    file: &CurvesFile,
    tolerance_mm: f64,
    paths: impl Iterator<Item = (&'a [f64], ToolpathPoints, f64)>,
) -> ToolpathFile {
    ToolpathFile {
        units: file.units,
        tolerance: tolerance_mm,
        paths: file
            .curves
            .iter()
            .zip(paths)
            .map(|(rec, (params, points, max_chord_error))| ToolpathRecord {
                id: rec.id.clone(),
                params: params.to_vec(),
                points,
                max_chord_error,
                kerf_offset: None,
            })
            .collect(),
    }
}

/// The normal source of every surface the curves use, built once per surface.
fn normal_sources(
    path: Option<&Path>,
    file: &CurvesFile,
    crease_deg: f64,
) -> Result<Vec<Option<Box<dyn NormalSource>>>> {
    file.surfaces
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let used = file
                .curves
                .iter()
                .any(|c| surface_ids(c).any(|id| id == &s.id));
            if !used {
                return Ok(None);
            }
            let src: Box<dyn NormalSource> = match &s.geometry {
                SurfaceGeometry::Nurbs(n) => Box::new(NurbsNormals::new(n.clone(), s.flip)),
                SurfaceGeometry::Mesh {
                    vertices,
                    triangles,
                } => Box::new(
                    MeshNormals::new(vertices.clone(), triangles.clone(), crease_deg, s.flip)
                        .map_err(|error| Error::Normals {
                            file: path.map(Path::to_path_buf),
                            place: format!("surfaces[{i}] ({:?})", s.id),
                            source: error,
                        })?,
                ),
            };
            Ok(Some(src))
        })
        .collect()
}

/// The surfaces a curve names: its `surfaces` list, or its `surface` when a file built in
/// code left the list empty.
fn surface_ids(c: &kerf_format::CurveRecord) -> impl Iterator<Item = &String> {
    let list = if c.surfaces.is_empty() {
        c.surface.as_slice()
    } else {
        c.surfaces.as_slice()
    };
    list.iter()
}

/// Normals for every curve (in parallel, results in input order): `discs[i]` is the
/// discretization of `file.curves[i]` with `opts`. A curve that states its own
/// `on_surface_tolerance_mm` looser than the options' is checked against its own (a CAD edge on
/// its face within its file's tolerance); [`beyond_run_tolerance`] names those it took beyond
/// the options'. A curve without a surface is cut with the
/// tool axis +z at every point (flat 2D cutting) or refused, as `orient_opts.missing_surface`
/// says. `source` names the file in errors.
///
/// # Errors
/// [`Error::Normals`] naming the curve or surface; [`Error::MissingSurface`],
/// [`Error::UnknownSurface`]; [`Error::Inconsistent`] if `discs` does not have one entry per
/// curve.
pub fn orient_curves(
    file: &CurvesFile,
    discs: &[Discretization],
    opts: &Options,
    orient_opts: &OrientOptions,
    source: Option<&Path>,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Oriented>> {
    if discs.len() != file.curves.len() {
        return Err(Error::Inconsistent(format!(
            "{} discretizations for {} curves",
            discs.len(),
            file.curves.len()
        )));
    }
    let file_path = || source.map(Path::to_path_buf);
    // Every surface id resolved before any work (the reader guarantees it for files; a file
    // built in code may name a surface it lacks).
    let mut picks: Vec<Vec<usize>> = Vec::with_capacity(file.curves.len());
    for (i, rec) in file.curves.iter().enumerate() {
        let mut idx = Vec::new();
        for id in surface_ids(rec) {
            let Some(si) = file.surfaces.iter().position(|s| &s.id == id) else {
                return Err(Error::UnknownSurface {
                    file: file_path(),
                    index: i,
                    id: rec.id.clone(),
                    surface: id.clone(),
                });
            };
            idx.push(si);
        }
        if idx.is_empty() && orient_opts.missing_surface == MissingSurface::Error {
            return Err(Error::MissingSurface {
                file: file_path(),
                index: i,
                id: rec.id.clone(),
            });
        }
        picks.push(idx);
    }
    let nopts = orient_opts.normals;
    let sources = normal_sources(source, file, orient_opts.crease_angle_deg)?;
    let place = |i: usize| format!("curves[{i}] ({:?})", file.curves[i].id);
    let total = file.curves.len();
    let done = AtomicUsize::new(0);
    progress(Progress::new(Stage::Normals, 0, total));
    file.curves
        .par_iter()
        .enumerate()
        .map(|(i, rec)| {
            let d = &discs[i];
            let picked: Vec<&dyn NormalSource> = picks[i]
                .iter()
                .filter_map(|&si| sources[si].as_deref())
                .collect();
            let result = if picked.is_empty() {
                Ok(Oriented::vertical(d))
            } else {
                let nearest;
                let src: &dyn NormalSource = if picked.len() == 1 {
                    picked[0]
                } else {
                    nearest = Nearest(picked);
                    &nearest
                };
                // The curve's own tolerance where it is looser (a CAD edge on its face within
                // its file's tolerance).
                let nopts = match rec.on_surface_tolerance_mm {
                    Some(t) if t > nopts.on_surface_tolerance_mm => {
                        nopts.with_on_surface_tolerance_mm(t)
                    }
                    _ => nopts,
                };
                orient(&rec.curve, d, src, opts, &nopts).map_err(|error| Error::Normals {
                    file: file_path(),
                    place: place(i),
                    source: error,
                })
            };
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(Progress::new(Stage::Normals, n, total));
            result
        })
        .collect()
}

/// One line per curve whose points lie farther from its surface than `run_tolerance_mm` (the
/// run's on-surface tolerance), taken within the curve's own looser `on_surface_tolerance_mm`
/// ([`orient_curves`]), with both figures: what a caller tells the user.
pub fn beyond_run_tolerance(
    file: &CurvesFile,
    oriented: &[Oriented],
    run_tolerance_mm: f64,
) -> Vec<String> {
    file.curves
        .iter()
        .zip(oriented)
        .enumerate()
        .filter(|(_, (_, or))| or.max_surface_distance > run_tolerance_mm)
        .map(|(i, (c, or))| {
            format!(
                "curves[{i}] ({:?}): its points lie up to {} mm from its surface, beyond the run's on-surface tolerance ({run_tolerance_mm} mm) but within the curve's own ({} mm): taken",
                c.id,
                or.max_surface_distance,
                c.on_surface_tolerance_mm.unwrap_or(run_tolerance_mm)
            )
        })
        .collect()
}

/// Several surfaces as one normal source: each query goes to every surface (cold-started, as
/// their parameters are unrelated) and the nearest answers (the list form of a curve's
/// `surface`; ties go to the first listed).
struct Nearest<'a>(Vec<&'a dyn NormalSource>);

impl NormalSource for Nearest<'_> {
    fn project(&self, p: &nalgebra::Point3<f64>, _hint: Hint) -> Projection {
        let mut best: Option<Projection> = None;
        for s in &self.0 {
            let pr = s.project(p, Hint::None);
            if best.as_ref().is_none_or(|b| pr.distance < b.distance) {
                best = Some(pr);
            }
        }
        let mut b = best.expect("a list of surfaces is never empty");
        b.hint = Hint::None;
        b
    }
}
