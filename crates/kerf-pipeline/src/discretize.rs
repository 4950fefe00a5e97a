//! `kerf discretize`: cutting points with a certified chord error for every curve of a
//! `kerf.curves/1` file, written as `kerf.toolpath/1`.

use std::io;
use std::path::Path;
use std::time::Instant;

use kerf_discretize::{Discretization, Options};
use kerf_format::toolpath::{self, ToolpathFile, ToolpathPoints, ToolpathRecord};
use kerf_format::{curves, CurvesFile, SurfaceGeometry};
use kerf_normals::{
    orient, Hint, MeshNormals, NormalOptions, NormalSource, NurbsNormals, Oriented, Projection,
};
use rayon::prelude::*;
use serde_json::json;

use crate::cli::DiscretizeArgs;
use crate::error::CliError;

/// Loads a curves file, or standard input for `-`.
pub(crate) fn load_curves(path: &Path) -> Result<CurvesFile, CliError> {
    let loaded = if path == Path::new("-") {
        curves::from_reader(io::stdin().lock(), Path::new(".")).map_err(|e| e.in_file("<stdin>"))
    } else {
        curves::load(path)
    };
    Ok(loaded?)
}

/// The discretizer options the arguments ask for.
// `..d` keeps the defaults of options added to `Options` later (every field is set today).
#[allow(clippy::needless_update)]
pub(crate) fn options(args: &DiscretizeArgs) -> Options {
    let d = Options::default();
    Options {
        tolerance: args.tolerance,
        band: args.band.unwrap_or(d.band),
        max_segment_length: args.max_segment_length.unwrap_or(d.max_segment_length),
        min_segment_length: args.min_segment_length.unwrap_or(d.min_segment_length),
        max_turn: args.max_turn.map_or(d.max_turn, f64::to_radians),
        strategy: args.strategy.into(),
        max_points: args
            .max_points
            .map_or(d.max_points, |n| usize::try_from(n).unwrap_or(usize::MAX)),
        ..d
    }
}

/// Discretizes every curve of `file` (in parallel, results in input order).
pub(crate) fn discretize_file(
    path: &Path,
    file: &CurvesFile,
    opts: &Options,
) -> Result<Vec<Discretization>, CliError> {
    opts.validate().map_err(CliError::Options)?;
    // The records are discretized in place (no copy of the curves), in parallel, with a
    // progress bar on a terminal for long batches; results come back in input order.
    let bar =
        show_progress(file.curves.len()).then(|| progress_bar(file.curves.len(), "discretizing"));
    let results: Vec<_> = file
        .curves
        .par_iter()
        .map(|r| {
            let d = kerf_discretize::discretize(&r.curve, opts);
            if let Some(b) = &bar {
                b.inc(1);
            }
            d
        })
        .collect();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    results
        .into_iter()
        .enumerate()
        .map(|(i, r)| {
            r.map_err(|error| CliError::Discretize {
                file: path.to_path_buf(),
                index: i,
                id: file.curves[i].id.clone(),
                error,
            })
        })
        .collect()
}

/// Runs `kerf discretize`.
pub(crate) fn run(args: &DiscretizeArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let path = args.curves.as_path();
    let dest = args.output.clone().unwrap_or_else(|| default_output(path));
    crate::guard::refuse_overwrite("--output", &dest, &[path])?;
    let file = load_curves(path)?;
    let opts = options(args);
    let results = discretize_file(path, &file, &opts)?;
    let oriented = if args.normals {
        Some(normals_for_file(
            path,
            &file,
            &results,
            &opts,
            &normal_args(args),
            false,
        )?)
    } else {
        None
    };
    let paths = match &oriented {
        None => file
            .curves
            .iter()
            .zip(&results)
            .map(|(rec, d)| ToolpathRecord {
                id: rec.id.clone(),
                params: d.params().to_vec(),
                points: ToolpathPoints::Positions(
                    d.points().iter().map(|p| [p.x, p.y, p.z]).collect(),
                ),
                max_chord_error: d.max_chord_error(),
            })
            .collect(),
        Some(o) => file
            .curves
            .iter()
            .zip(o)
            .map(|(rec, o)| ToolpathRecord {
                id: rec.id.clone(),
                params: o.params.clone(),
                points: ToolpathPoints::Poses(o.poses()),
                max_chord_error: o.max_chord_error,
            })
            .collect(),
    };
    let out = ToolpathFile {
        units: file.units,
        tolerance: opts.tolerance,
        paths,
    };
    // `-` is standard output; kerf_io also writes devices and FIFOs through.
    toolpath::write(&out, &dest)?;
    let segments: usize = results.iter().map(Discretization::segments).sum();
    let points: usize = out.paths.iter().map(|p| p.params.len()).sum();
    let worst = out
        .paths
        .iter()
        .map(|p| p.max_chord_error)
        .fold(0.0, f64::max);
    let (added, surface_dist, jumps) = oriented.as_ref().map_or((0, 0.0, 0), |o| {
        (
            o.iter().map(|o| o.inserted).sum::<usize>(),
            o.iter().map(|o| o.max_surface_distance).fold(0.0, f64::max),
            o.iter().map(|o| o.jumps.len()).sum::<usize>(),
        )
    });
    // N* (a diagnostic) comes from the curvature the walk evaluated at its points (no
    // quadrature of its own; `Discretization::n_star`).
    let nstar: f64 = results.iter().map(|d| d.n_star(opts.tolerance)).sum();
    let elapsed = start.elapsed().as_secs_f64();
    let breaks: usize = results.iter().map(|d| d.c0_breaks().len()).sum();
    if args.json {
        let summary = json!({
            "file": path.display().to_string(),
            "output": dest.display().to_string(),
            "curves": file.curves.len(),
            "points": points,
            "segments": segments,
            "c0_breaks": breaks,
            "tolerance": opts.tolerance,
            "max_chord_error": worst,
            "n_star": nstar,
            "segments_over_n_star": if nstar > 0.0 { segments as f64 / nstar } else { f64::NAN },
            "seconds": elapsed,
            "normals": args.normals,
            "normal_points_added": added,
            "max_surface_distance": surface_dist,
            "normal_jumps": jumps,
        });
        // The summary goes to standard output unless the toolpath itself does.
        if dest == Path::new("-") {
            eprintln!("{summary}");
        } else {
            println!("{summary}");
        }
    } else if !args.quiet {
        if args.normals {
            eprintln!(
                "normals: {added} points added for the normal step, worst curve-to-surface \
                 distance {surface_dist:.2e} mm, {jumps} normal jumps at sharp edges"
            );
        }
        eprintln!(
            "{}: {} curves, {points} points ({segments} segments from the discretizer, {breaks} C0 corners kept), \
             worst certified chord error {worst:.3e} mm <= {} mm, N* {nstar:.1} \
             (segments / N* = {:.3}), {:.3} s -> {}",
            path.display(),
            file.curves.len(),
            opts.tolerance,
            if nstar > 0.0 {
                segments as f64 / nstar
            } else {
                f64::NAN
            },
            elapsed,
            dest.display()
        );
    }
    Ok(())
}

/// `dir/part.json` -> `part.toolpath.json` in the current directory (the input's folder may be
/// read-only).
fn default_output(input: &Path) -> std::path::PathBuf {
    if input == Path::new("-") {
        return "-".into();
    }
    let stem = input.file_stem().map_or_else(
        || "curves".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    format!("{stem}.toolpath.json").into()
}

/// The options of the normals stage (shared by `discretize --normals` and `run`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct NormalArgs {
    /// mm.
    pub on_surface_tolerance: Option<f64>,
    /// Degrees.
    pub max_normal_step: Option<f64>,
    /// Degrees.
    pub crease_angle: Option<f64>,
}

fn normal_args(args: &DiscretizeArgs) -> NormalArgs {
    NormalArgs {
        on_surface_tolerance: args.on_surface_tolerance,
        max_normal_step: args.max_normal_step,
        crease_angle: args.crease_angle,
    }
}

/// The normal source of every surface the curves use, built once per surface.
fn normal_sources(
    path: &Path,
    file: &CurvesFile,
    args: &NormalArgs,
) -> Result<Vec<Option<Box<dyn NormalSource>>>, CliError> {
    let crease = args
        .crease_angle
        .unwrap_or(kerf_normals::DEFAULT_CREASE_ANGLE_DEG);
    file.surfaces
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let used = file
                .curves
                .iter()
                .any(|c| c.surfaces.iter().any(|id| id == &s.id));
            if !used {
                return Ok(None);
            }
            let src: Box<dyn NormalSource> = match &s.geometry {
                SurfaceGeometry::Nurbs(n) => Box::new(NurbsNormals::new(n.clone(), s.flip)),
                SurfaceGeometry::Mesh {
                    vertices,
                    triangles,
                } => Box::new(
                    MeshNormals::new(vertices.clone(), triangles.clone(), crease, s.flip).map_err(
                        |error| CliError::Normals {
                            file: path.to_path_buf(),
                            place: format!("surfaces[{i}] ({:?})", s.id),
                            error,
                        },
                    )?,
                ),
            };
            Ok(Some(src))
        })
        .collect()
}

/// Normals for every curve (in parallel, results in input order). A curve without a surface is
/// an error, or, with `vertical_without_surface`, gets the tool axis +z at every point (flat
/// 2D cutting).
pub(crate) fn normals_for_file(
    path: &Path,
    file: &CurvesFile,
    results: &[Discretization],
    opts: &Options,
    args: &NormalArgs,
    vertical_without_surface: bool,
) -> Result<Vec<Oriented>, CliError> {
    let defaults = NormalOptions::default();
    let nopts = NormalOptions {
        on_surface_tolerance: args
            .on_surface_tolerance
            .unwrap_or(defaults.on_surface_tolerance),
        max_normal_step: args
            .max_normal_step
            .map_or(defaults.max_normal_step, f64::to_radians),
        ..defaults
    };
    let sources = normal_sources(path, file, args)?;
    let place = |i: usize| format!("curves[{i}] ({:?})", file.curves[i].id);
    file.curves
        .par_iter()
        .enumerate()
        .map(|(i, rec)| {
            let Some(sid) = &rec.surface else {
                if vertical_without_surface {
                    let d = &results[i];
                    return Ok(Oriented {
                        params: d.params().to_vec(),
                        points: d.points().to_vec(),
                        normals: vec![nalgebra::Vector3::z(); d.points().len()],
                        max_chord_error: d.max_chord_error(),
                        ..Default::default()
                    });
                }
                return Err(CliError::Input(format!(
                    "{}: {}: --normals needs a surface, but the curve names none (add \"surface\": \"<id>\")",
                    path.display(),
                    place(i)
                )));
            };
            let _ = sid;
            let picked: Vec<&dyn NormalSource> = rec
                .surfaces
                .iter()
                .map(|id| {
                    let si = file
                        .surfaces
                        .iter()
                        .position(|s| &s.id == id)
                        .expect("the reader resolved every surface id");
                    sources[si].as_deref().expect("a source exists for every used surface")
                })
                .collect();
            let nearest;
            let src: &dyn NormalSource = if picked.len() == 1 {
                picked[0]
            } else {
                nearest = Nearest(picked);
                &nearest
            };
            orient(&rec.curve, &results[i], src, opts, &nopts).map_err(|error| CliError::Normals {
                file: path.to_path_buf(),
                place: place(i),
                error,
            })
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

/// A progress bar is worth showing for batches long enough to wait for, and only when
/// standard error is a terminal (never in pipes, logs or CI).
pub(crate) fn show_progress(items: usize) -> bool {
    use std::io::IsTerminal;
    items >= 200 && io::stderr().is_terminal()
}

/// A progress bar on standard error.
pub(crate) fn progress_bar(len: usize, what: &str) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::new(len as u64);
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} curves, {eta} left")
    {
        bar.set_style(style);
    }
    bar.set_message(what.to_string());
    bar
}
