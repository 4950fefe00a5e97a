//! `kerf discretize`: cutting points with a certified chord error for every curve of a
//! `kerf.curves/1` file, written as `kerf.toolpath/1` (the pipeline's first two stages).

use std::path::Path;
use std::time::Instant;

use kerf_discretize::{Discretization, Options};
use kerf_format::toolpath;
use kerf_format::CurvesFile;
use kerf_normals::NormalOptions;
use kerf_pipeline::{
    discretize_curves, orient_curves, toolpath_of_poses, MissingSurface, OrientOptions,
};
use serde_json::json;

use crate::cli::DiscretizeArgs;
use crate::error::CliError;
use crate::input::{load_curves, ProgressBar};

/// The discretizer options the arguments ask for.
pub(crate) fn options(args: &DiscretizeArgs) -> Options {
    let d = Options::default();
    Options::with_tolerance(args.tolerance)
        .with_band(args.band.unwrap_or(d.band))
        .with_max_segment_length_mm(args.max_segment_length.unwrap_or(d.max_segment_length_mm))
        .with_min_segment_length_mm(args.min_segment_length.unwrap_or(d.min_segment_length_mm))
        .with_max_turn_deg(args.max_turn.unwrap_or(d.max_turn_deg))
        .with_strategy(args.strategy.into())
        .with_max_points(
            args.max_points
                .map_or(d.max_points, |n| usize::try_from(n).unwrap_or(usize::MAX)),
        )
}

/// The normals-stage options the arguments ask for (`--normals` refuses curves without a
/// surface).
fn orient_options(args: &DiscretizeArgs) -> OrientOptions {
    let d = NormalOptions::default();
    let normals = d
        .with_on_surface_tolerance_mm(
            args.on_surface_tolerance
                .unwrap_or(d.on_surface_tolerance_mm),
        )
        .with_max_normal_step_deg(args.max_normal_step.unwrap_or(d.max_normal_step_deg));
    let o = OrientOptions::default()
        .with_normals(normals)
        .with_missing_surface(MissingSurface::Error);
    match args.crease_angle {
        Some(deg) => o.with_crease_angle_deg(deg),
        None => o,
    }
}

/// What the summary reports, summed over the curves as they are written.
#[derive(Debug, Default)]
struct Totals {
    points: usize,
    segments: usize,
    worst: f64,
    n_star: f64,
    breaks: usize,
}

impl Totals {
    fn add(&mut self, d: &Discretization, tolerance: f64) {
        self.points += d.points().len();
        self.segments += d.segments();
        self.worst = self.worst.max(d.max_chord_error());
        // N* (a diagnostic) comes from the curvature the walk evaluated at its points (no
        // quadrature of its own; `Discretization::n_star`).
        self.n_star += d.n_star(tolerance);
        self.breaks += d.c0_breaks().len();
    }
}

/// Curves discretized together (in parallel) and then written, group after group, so that the
/// points of a large file are never all in memory: the process holds the input and two groups'
/// output, and the output goes to the file as it comes.
const GROUP: usize = 256;

/// Discretizes every curve and writes its cutting points to `dest` as they come (positions
/// only), in input order; on any failure `dest` is untouched (`toolpath::write_with`).
///
/// One batch of the discretizer in groups of [`GROUP`] (`kerf_discretize::Batch`): the
/// refusals known from the control points come before any walk and before `dest` is opened (a
/// curve late in the file whose tolerance is below its rounding margin is refused at once, not
/// after the walks of the curves before it, which took minutes at 1e-10 mm). Writing is serial
/// (one file, in order), so it overlaps the discretization: while this thread formats and
/// writes group `g`, the thread pool discretizes group `g + 1`. The bytes are those of
/// discretizing and writing one group after the other; the CPU time is the same, the wall time
/// on two cores drops by about the writing's share.
fn discretize_to_file(
    file: &CurvesFile,
    input: &Path,
    opts: &Options,
    dest: &Path,
    bar: &ProgressBar,
) -> Result<Totals, CliError> {
    let batch = kerf_pipeline::curves_batch(file, opts, Some(input))?.in_groups_of(GROUP);
    let mut totals = Totals::default();
    let progress = |p| bar.update(p);
    toolpath::write_with(dest, file.units, opts.tolerance_mm, |w| {
        kerf_pipeline::discretize_batch(&batch, Some(input), &progress, |index, d| {
            let rec = &file.curves[index];
            w.path(&rec.id, d.params(), d.points(), d.max_chord_error())
                .map_err(|e| e.in_file(dest))?;
            totals.add(&d, opts.tolerance_mm);
            Ok::<(), CliError>(())
        })
    })?;
    Ok(totals)
}

/// Runs `kerf discretize`.
pub(crate) fn run(args: &DiscretizeArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let path = args.curves.as_path();
    // Standard input goes to standard output.
    let dest = args
        .output
        .clone()
        .unwrap_or_else(|| match path == Path::new("-") {
            true => "-".into(),
            false => crate::input::default_output(path, "curves", "", ".toolpath.json"),
        });
    crate::guard::refuse_overwrite("--output", &dest, &[path])?;
    let file = load_curves(path)?;
    let opts = options(args);
    let bar = ProgressBar::new(file.curves.len());
    let (totals, oriented) = if args.normals {
        let progress = |p| bar.update(p);
        let results = discretize_curves(&file, &opts, Some(path), &progress);
        bar.finish();
        let results = results?;
        let oriented = orient_curves(
            &file,
            &results,
            &opts,
            &orient_options(args),
            Some(path),
            &|_| {},
        )?;
        let run_tolerance = orient_options(args).normals.on_surface_tolerance_mm;
        for w in kerf_pipeline::beyond_run_tolerance(&file, &oriented, run_tolerance) {
            eprintln!("warning: {}: {w}", path.display());
        }
        let out = toolpath_of_poses(&file, opts.tolerance_mm, &oriented);
        // `-` is standard output; kerf_io also writes devices and FIFOs through.
        toolpath::write(&out, &dest)?;
        let mut totals = Totals::default();
        for d in &results {
            totals.add(d, opts.tolerance_mm);
        }
        totals.points = out.paths.iter().map(|p| p.params.len()).sum();
        (totals, Some(oriented))
    } else {
        let totals = discretize_to_file(&file, path, &opts, &dest, &bar);
        bar.finish();
        (totals?, None)
    };
    let Totals {
        points,
        segments,
        worst,
        n_star: nstar,
        breaks,
    } = totals;
    let (added, surface_dist, jumps) = oriented.as_ref().map_or((0, 0.0, 0), |o| {
        (
            o.iter().map(|o| o.inserted).sum::<usize>(),
            o.iter().map(|o| o.max_surface_distance).fold(0.0, f64::max),
            o.iter().map(|o| o.jumps.len()).sum::<usize>(),
        )
    });
    let elapsed = start.elapsed().as_secs_f64();
    if args.json {
        let summary = json!({
            "file": path.display().to_string(),
            "output": dest.display().to_string(),
            "curves": file.curves.len(),
            "points": points,
            "segments": segments,
            "c0_breaks": breaks,
            "tolerance": opts.tolerance_mm,
            "max_chord_error": worst,
            "n_star": nstar,
            // null when N* is 0 (no ratio; `n_star_text`).
            "segments_over_n_star": (nstar > 0.0).then(|| segments as f64 / nstar),
            "seconds": elapsed,
            "normals": args.normals,
            "normal_points_added": added,
            "max_surface_distance": surface_dist,
            "normal_jumps": jumps,
        });
        crate::input::print_summary(&summary, Some(&dest));
    } else if !args.quiet {
        if args.normals {
            eprintln!(
                "normals: {added} points added for the normal step, worst curve-to-surface \
                 distance {surface_dist:.2e} mm, {jumps} normal jumps at sharp edges"
            );
        }
        eprintln!(
            "{}: {} curves, {points} points ({segments} segments from the discretizer, {breaks} C0 corners kept), \
             worst certified chord error {worst:.3e} mm <= {} mm, {}, {:.3} s -> {}",
            path.display(),
            file.curves.len(),
            opts.tolerance_mm,
            n_star_text(segments, nstar),
            elapsed,
            dest.display()
        );
    }
    Ok(())
}

/// The summary's account of `N*`: with the ratio when `N*` is positive; when it is 0 (straight
/// pieces, a retraced line, or a curvature too small for double precision to measure) there
/// is no ratio to give, and the text says why instead of printing NaN.
fn n_star_text(segments: usize, nstar: f64) -> String {
    if nstar > 0.0 {
        format!(
            "N* {nstar:.1} (segments / N* = {:.3})",
            segments as f64 / nstar
        )
    } else {
        format!("N* {nstar:.1} (no curvature measured, so no segments / N* ratio)")
    }
}
