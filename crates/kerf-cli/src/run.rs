//! `kerf run`: the whole pipeline in one command. Discretize (certified chord error), normals,
//! machine axes, interpolation and G-code, with a report and a picture, all written into one
//! output directory only once every stage has succeeded.

use std::path::{Path, PathBuf};
use std::time::Instant;

use kerf_discretize::Discretization;
use kerf_format::toolpath::{self, ToolPath, ToolPathPoints, ToolpathFile};
use kerf_interp::{
    csv_string, gcode, stations_from_solved, AxisModel, GcodeOptions, MachineModel,
    PathInput as InterpPath, PlanOptions,
};
use kerf_kinematics::{solve_paths, AxesFile, Machine, PathCurve, PathInput, PathOptions, Pose};
use kerf_normals::Oriented;
use serde_json::json;

use crate::cli::RunArgs;
use crate::discretize::{discretize_file, load_curves, normals_for_file, NormalArgs};
use crate::error::CliError;

/// Runs `kerf run`.
pub(crate) fn run(args: &RunArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let path = args.curves.as_path();
    let file = if crate::import::is_step(path) {
        let (file, import) = crate::import::load_step(path, &args.step_args)?;
        if !args.quiet && !args.json {
            crate::import::print_account(path, &import);
        }
        file
    } else {
        load_curves(path)?
    };
    let machine = Machine::read(&args.machine)?;
    let dopts = kerf_discretize::Options {
        max_segment_length: args.max_segment_length.unwrap_or(f64::INFINITY),
        ..kerf_discretize::Options::with_tolerance(args.tolerance)
    };
    // 1. Cutting points with a certified chord error.
    let discs: Vec<Discretization> = discretize_file(path, &file, &dopts)?;
    // 2. Normals (+z for curves that name no surface).
    let nargs = NormalArgs {
        max_normal_step: args.max_normal_step,
        ..NormalArgs::default()
    };
    let oriented: Vec<Oriented> = normals_for_file(path, &file, &discs, &dopts, &nargs, true)?;
    let tp = ToolpathFile {
        units: file.units,
        tolerance: dopts.tolerance,
        paths: file
            .curves
            .iter()
            .zip(&oriented)
            .map(|(rec, o)| ToolPath {
                id: rec.id.clone(),
                params: o.params.clone(),
                points: ToolPathPoints::Poses(o.poses()),
                max_chord_error: o.max_chord_error,
            })
            .collect(),
    };
    // 3. Machine axes, points inserted on the curve against the non-linearity error.
    let popts = PathOptions {
        linearization_tolerance: args
            .linearization_tolerance
            .unwrap_or(PathOptions::default().linearization_tolerance),
        max_rotary_step: args.max_rotary_step.unwrap_or(f64::INFINITY),
        ..PathOptions::default()
    };
    let poses: Vec<Vec<Pose>> = oriented
        .iter()
        .map(|o| o.poses().into_iter().map(Pose::from_array).collect())
        .collect();
    let points: Vec<Box<dyn Fn(f64) -> nalgebra::Point3<f64> + Sync>> = file
        .curves
        .iter()
        .map(|r| {
            let c = r.curve.clone();
            Box::new(move |t| c.point(t)) as Box<dyn Fn(f64) -> nalgebra::Point3<f64> + Sync>
        })
        .collect();
    let inputs: Vec<PathInput<'_>> = file
        .curves
        .iter()
        .enumerate()
        .map(|(i, rec)| PathInput {
            id: &rec.id,
            poses: &poses[i],
            curve: Some(PathCurve {
                params: &oriented[i].params,
                point: points[i].as_ref(),
            }),
        })
        .collect();
    let solved = solve_paths(&machine, &inputs, &popts)
        .map_err(|e| CliError::Kinematics(Box::new(e), Some(args.curves.clone())))?;
    let axes = AxesFile::new(&machine, &solved);
    // 4. Interpolation and G-code.
    let model = MachineModel::new(machine.clone()).map_err(interp(path))?;
    let mut ipaths = Vec::with_capacity(solved.len());
    for (i, s) in solved.iter().enumerate() {
        let curve: &(dyn Fn(f64) -> nalgebra::Point3<f64> + Sync) = points[i].as_ref();
        ipaths.push(InterpPath {
            id: s.id.clone(),
            stations: stations_from_solved(s, Some(&oriented[i].params)).map_err(interp(path))?,
            curve: Some(curve),
        });
    }
    let fit = crate::motion::fit_options(
        dopts.tolerance,
        args.dialect == crate::cli::DialectArg::Generic,
        args.retract,
    );
    let plan = PlanOptions::new(args.feed, args.cycle);
    let motion = kerf_interp::interpolate(&model, &ipaths, &fit, &plan).map_err(interp(path))?;
    let ids: Vec<String> = file.curves.iter().map(|c| c.id.clone()).collect();
    let gopts = GcodeOptions {
        fit_tolerance: dopts.tolerance,
        ..GcodeOptions::new(args.dialect.into(), args.feed)
    };
    let program = gcode(
        &model,
        motion.blocks(),
        &ids,
        Some(&motion.block_feeds()),
        &gopts,
    )
    .map_err(interp(path))?;
    let setpoints = csv_string(model.axis_names(), args.cycle, &motion.setpoints(&model));
    // 5. Picture and report.
    let mut scene = kerf_plot::Scene::new(&file, &tp, &kerf_plot::SceneOptions::default())
        .map_err(|e| CliError::Plot(e.to_string()))?;
    scene.title = format!(
        "kerf run \u{2014} {} on {}",
        path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned()
        ),
        machine.name
    );
    scene.axes = Some(
        kerf_plot::AxesChart::new(&axes, Some(&machine))
            .map_err(|e| CliError::Plot(e.to_string()))?,
    );
    let svg = kerf_plot::render(&scene);
    let counts = motion.counts();
    let nstar: f64 = file
        .curves
        .iter()
        .map(|r| kerf_discretize::minimum_count(&r.curve, dopts.tolerance))
        .sum();
    let segments: usize = discs.iter().map(Discretization::segments).sum();
    let report = json!({
        "input": path.display().to_string(),
        "machine": machine.name,
        "tolerance_budget_mm": {
            "chord": dopts.tolerance,
            "linearization": popts.linearization_tolerance,
            "interpolation_chord": plan.chord_tolerance,
            "total": dopts.tolerance + popts.linearization_tolerance + plan.chord_tolerance,
        },
        "discretize": {
            "curves": file.curves.len(),
            "segments": segments,
            "n_star": nstar,
            "max_chord_error": tp.paths.iter().map(|p| p.max_chord_error).fold(0.0, f64::max),
            "c0_breaks": discs.iter().map(|d| d.c0_breaks.len()).sum::<usize>(),
        },
        "normals": {
            "points": oriented.iter().map(|o| o.points.len()).sum::<usize>(),
            "inserted": oriented.iter().map(|o| o.inserted).sum::<usize>(),
            "max_surface_distance": oriented.iter().map(|o| o.max_surface_distance).fold(0.0, f64::max),
            "jumps": oriented.iter().map(|o| o.jumps.len()).sum::<usize>(),
            "curves_without_surface": file.curves.iter().filter(|c| c.surface.is_none()).count(),
        },
        "kinematics": {
            "poses": solved.iter().map(|s| s.poses.len()).sum::<usize>(),
            "inserted": solved.iter().map(|s| s.inserted).sum::<usize>(),
            "max_rotary_step_between_cutting_points": solved.iter().map(|s| s.max_rotary_step_between_cutting_points).fold(0.0, f64::max),
            "max_linearization_error": solved.iter().map(|s| s.max_linearization_error).fold(0.0, f64::max),
            "pole_points": solved.iter().map(|s| s.pole_points).sum::<usize>(),
            "pole_tip_error": solved.iter().map(|s| s.pole_tip_error).fold(0.0, f64::max),
        },
        "interpolation": {
            "feed_mm_per_min": args.feed,
            "cycle_s": args.cycle,
            "lines": counts.lines,
            "arcs": counts.arcs,
            "turns": counts.turns,
            "cycles": motion.cycles(),
            "duration_s": motion.duration(),
        },
        "seconds": start.elapsed().as_secs_f64(),
    });
    // 6. Write everything at once.
    let files: Vec<(&str, String)> = vec![
        ("toolpath.json", toolpath::to_string(&tp)?),
        (
            "axes.json",
            axes.to_json()
                .map_err(|e| CliError::Kinematics(Box::new(e), None))?,
        ),
        ("program.nc", program),
        ("setpoints.csv", setpoints),
        (
            "report.json",
            serde_json::to_string_pretty(&report).unwrap_or_else(|_| report.to_string()),
        ),
        ("plot.svg", svg),
    ];
    write_all(&args.out, &files)?;
    if args.json {
        println!("{report}");
    } else if !args.quiet {
        eprintln!(
            "{}: {} curves -> {} cutting points (N* {nstar:.1}), {} poses on {:?}, {} lines + {} arcs, \
             {:.2} s of motion at {} mm/min; wrote {} in {:.2} s",
            path.display(),
            file.curves.len(),
            tp.paths.iter().map(|p| p.params.len()).sum::<usize>(),
            solved.iter().map(|s| s.poses.len()).sum::<usize>(),
            machine.name,
            counts.lines,
            counts.arcs,
            motion.duration(),
            args.feed,
            args.out.display(),
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

fn interp(file: &Path) -> impl Fn(kerf_interp::InterpError) -> CliError + '_ {
    move |e| CliError::Input(format!("{}: {e}", file.display()))
}

/// Writes every file into `dir`, all or nothing: the new files are written into a staging
/// directory inside `dir`; then, file by file, an existing old file is moved aside into the
/// staging directory and the new one renamed into place. If any step fails, the files already
/// placed are removed and the old ones put back, so `dir` is left as it was. (A crash between
/// two renames can still leave a mix; the staging directory then remains, named `.kerf-run-*`.)
fn write_all(dir: &Path, files: &[(&str, String)]) -> Result<(), CliError> {
    let io = |what: &Path, e: std::io::Error| {
        CliError::Input(format!("{}: cannot write: {e}", what.display()))
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let stage = tempfile::Builder::new()
        .prefix(".kerf-run-")
        .tempdir_in(dir)
        .map_err(|e| io(dir, e))?;
    for (name, text) in files {
        let p = stage.path().join(name);
        std::fs::write(&p, text).map_err(|e| io(&p, e))?;
    }
    let mut old: Vec<(PathBuf, PathBuf)> = Vec::new();
    let mut placed: Vec<PathBuf> = Vec::new();
    let mut swap = || -> Result<(), CliError> {
        for (name, _) in files {
            let to = dir.join(name);
            if std::fs::symlink_metadata(&to).is_ok() {
                let aside = stage.path().join(format!("{name}.old"));
                std::fs::rename(&to, &aside).map_err(|e| io(&to, e))?;
                old.push((aside, to.clone()));
            }
            std::fs::rename(stage.path().join(name), &to).map_err(|e| io(&to, e))?;
            placed.push(to);
        }
        Ok(())
    };
    let result = swap();
    if result.is_err() {
        for p in placed.iter().rev() {
            let _ = std::fs::remove_file(p);
        }
        for (aside, to) in old.iter().rev() {
            let _ = std::fs::rename(aside, to);
        }
    }
    result
}
