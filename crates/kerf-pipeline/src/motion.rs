//! `kerf interpolate` and `kerf gcode`: the interpolator on a `kerf.axes/1` or
//! `kerf.toolpath/1` file.

use std::path::{Path, PathBuf};

use kerf_format::toolpath;
use kerf_interp::{
    gcode_motion, stations_from_axes, stations_from_solved, write_csv, AxisModel, Dialect,
    FitOptions, GcodeOptions, MachineModel, Motion, PlanOptions, ProgramPath,
};
use kerf_kinematics::{solve_path, AxesFile, Machine, PathOptions, Pose};
use nalgebra::Vector3;
use serde_json::json;

use crate::cli::{GcodeArgs, InterpolateArgs, MotionArgs};
use crate::error::CliError;

/// A program ready to be written: the machine model, the path ids and the planned motion.
pub(crate) struct Program {
    /// The machine.
    pub model: MachineModel,
    /// The source curve of each path.
    pub ids: Vec<String>,
    /// The planned motion.
    pub motion: Motion,
    /// The tolerance the blocks were fitted with, mm.
    pub fit_tolerance: f64,
    /// The linearization tolerance the axes were solved with, mm (`None` for an axes file,
    /// which does not record it).
    pub linearization_tolerance: Option<f64>,
}

fn interp_err(file: &Path) -> impl Fn(kerf_interp::InterpError) -> CliError + '_ {
    move |e| CliError::Input(format!("{}: {e}", file.display()))
}

/// The fit for a program run by a controller that interpolates the machine axes linearly
/// (`generic`): one G1 per pose of the kinematics, whose non-linearity error is within the
/// linearization tolerance; no arcs (their chords would move the rotary axes in steps nobody
/// checked) and no merged lines. With tool-tip control (Sinumerik TRAORI) arcs and merges are
/// safe: the controller keeps the tip on the programmed path.
pub(crate) fn fit_options(tolerance: f64, generic: bool, retract: f64) -> FitOptions {
    FitOptions {
        arcs: !generic,
        merge_lines: !generic,
        retract,
        ..FitOptions::with_tolerance(tolerance)
    }
}

/// Reads the input (axes or toolpath), solves it on the machine if needed, fits blocks and
/// plans the motion.
pub(crate) fn program(args: &MotionArgs, generic: bool) -> Result<Program, CliError> {
    let machine = Machine::read(&args.machine)?;
    let model = MachineModel::new(machine.clone()).map_err(interp_err(&args.machine))?;
    let input = &args.input;
    let bytes = kerf_io::read_file(input)
        .map_err(|e| CliError::Input(format!("{}: cannot read: {e}", input.display())))?;
    let format = kerf_io::parse_json(&bytes)
        .ok()
        .and_then(|v| v.get("format").and_then(|f| f.as_str()).map(str::to_owned))
        .unwrap_or_default();
    let mut linearization = None;
    let (ids, paths, file_tol) = if format == kerf_kinematics::AXES_FORMAT {
        let axes = AxesFile::from_slice(&bytes)
            .map_err(|e| CliError::Kinematics(Box::new(e), Some(input.clone())))?;
        let mut paths = Vec::new();
        for p in &axes.paths {
            paths.push(ProgramPath {
                id: p.id.clone(),
                stations: {
                    // Lead-in, cut and lead-out, as the machine runs them.
                    let (positions, poses) = p.run();
                    stations_from_axes(&positions, &poses).map_err(interp_err(input))?
                },
                curve: None,
            });
        }
        (
            axes.paths.iter().map(|p| p.id.clone()).collect(),
            paths,
            None,
        )
    } else {
        let tp = toolpath::from_reader(&bytes[..]).map_err(|e| e.in_file(input))?;
        linearization = Some(PathOptions::default().linearization_tolerance);
        let mut paths = Vec::new();
        for p in &tp.paths {
            let poses: Vec<Pose> = (0..p.points.len())
                .map(|n| {
                    let q = p.points.position(n);
                    let a = p.points.normal(n).unwrap_or_else(Vector3::z);
                    Pose::new(q.x, q.y, q.z, a.x, a.y, a.z)
                })
                .collect();
            let solved = solve_path(
                &machine,
                &kerf_kinematics::PathInput {
                    id: &p.id,
                    poses: &poses,
                    curve: None,
                },
                &PathOptions::default(),
            )
            .map_err(|e| CliError::Kinematics(Box::new(e), Some(input.clone())))?;
            paths.push(ProgramPath {
                id: p.id.clone(),
                stations: stations_from_solved(&solved, Some(&p.params))
                    .map_err(interp_err(input))?,
                curve: None,
            });
        }
        (
            tp.paths.iter().map(|p| p.id.clone()).collect(),
            paths,
            Some(tp.tolerance),
        )
    };
    let fit_tolerance = args.fit_tolerance.or(file_tol).unwrap_or(0.001);
    let mut plan = PlanOptions::new(args.feed, args.cycle);
    if let Some(c) = args.chord_tolerance {
        plan.chord_tolerance = c;
    }
    let motion = kerf_interp::interpolate(
        &model,
        &paths,
        &fit_options(fit_tolerance, generic, args.retract),
        &plan,
    )
    .map_err(interp_err(input))?;
    Ok(Program {
        model,
        ids,
        motion,
        fit_tolerance,
        linearization_tolerance: linearization,
    })
}

/// The planned time of every path and the share at the programmed feed, for the summaries.
pub(crate) fn path_report(motion: &Motion, ids: &[String]) -> serde_json::Value {
    let paths: Vec<serde_json::Value> = motion
        .path_stats()
        .iter()
        .map(|p| {
            json!({
                "id": ids.get(p.path).cloned().unwrap_or_else(|| format!("path {}", p.path)),
                "duration_s": p.duration,
                "cutting_time_s": p.cutting_time,
                "cutting_length_mm": p.cutting_length,
                "time_share_at_feed": if p.cutting_time > 0.0 { p.time_at_feed / p.cutting_time } else { 0.0 },
                "length_share_at_feed": if p.cutting_length > 0.0 { p.length_at_feed / p.cutting_length } else { 0.0 },
            })
        })
        .collect();
    json!(paths)
}

fn summary(args: &MotionArgs, p: &Program, out: Option<&PathBuf>, json: bool, quiet: bool) {
    let c = p.motion.counts();
    if json {
        let text = json!({
                "input": args.input.display().to_string(),
                "machine": p.model.name(),
                "lines": c.lines,
                "arcs": c.arcs,
                "turns": c.turns,
                "cycles": p.motion.cycles(),
                "cycle": args.cycle,
                "duration_s": p.motion.duration(),
                "time_share_at_feed": p.motion.time_share_at_feed(),
                "blend_deviation_mm": p.motion.blend_deviation(),
                "paths": path_report(&p.motion, &p.ids),
                "output": out.map(|o| o.display().to_string()),
        });
        // The summary goes to standard output unless the program or CSV itself does.
        if out.is_some_and(|o| o == Path::new("-")) {
            eprintln!("{text}");
        } else {
            println!("{text}");
        }
    } else if !quiet {
        eprintln!(
            "{}: {} lines, {} arcs, {} turns; {} cycles of {} s = {:.3} s of motion, {:.1} % of the cutting time at the programmed feed{}",
            args.input.display(),
            c.lines,
            c.arcs,
            c.turns,
            p.motion.cycles(),
            args.cycle,
            p.motion.duration(),
            100.0 * p.motion.time_share_at_feed(),
            out.map_or(String::new(), |o| format!(" -> {}", o.display()))
        );
        for st in p.motion.path_stats() {
            let id = p.ids.get(st.path).map_or("?", String::as_str);
            eprintln!(
                "  {id}: {:.3} s ({:.3} s cutting {:.1} mm, {:.1} % of its length at the programmed feed)",
                st.duration,
                st.cutting_time,
                st.cutting_length,
                if st.cutting_length > 0.0 { 100.0 * st.length_at_feed / st.cutting_length } else { 0.0 }
            );
        }
    }
}

/// Runs `kerf interpolate`.
pub(crate) fn run_interpolate(args: &InterpolateArgs) -> Result<(), CliError> {
    if let Some(csv) = &args.csv {
        crate::guard::refuse_overwrite("--csv", csv, &[&args.motion.input, &args.motion.machine])?;
    }
    // Set-points are computed with tool-tip control: arcs are safe.
    let p = program(&args.motion, false)?;
    if let Some(csv) = &args.csv {
        // Streamed cycle by cycle from the plan into the file (or standard output): memory
        // stays bounded however long the program runs.
        write_csv(
            csv,
            p.model.axis_names(),
            args.motion.cycle,
            p.motion.iter(&p.model),
        )
        .map_err(interp_err(csv))?;
    }
    summary(&args.motion, &p, args.csv.as_ref(), args.json, args.quiet);
    Ok(())
}

/// The G-code options of a program for `dialect`: the budget terms, the machine's process
/// codes and pivot length, the source file's name.
pub(crate) fn gcode_options(
    model: &MachineModel,
    dialect: Dialect,
    feed: f64,
    blend_tolerance: f64,
    source: &Path,
) -> GcodeOptions {
    GcodeOptions {
        blend_tolerance,
        pivot_length: Some(model.machine.kinematics.pivot_length()),
        process: model.machine.process.clone(),
        source: Some(source.display().to_string()),
        ..GcodeOptions::new(dialect, feed)
    }
}

/// Writes the G-code of a program.
pub(crate) fn write_program(p: &Program, dest: &Path, opts: &GcodeOptions) -> Result<(), CliError> {
    let text = gcode_motion(&p.model, &p.motion, &p.ids, opts).map_err(interp_err(dest))?;
    if dest == Path::new("-") {
        std::io::Write::write_all(&mut std::io::stdout().lock(), text.as_bytes())?;
        return Ok(());
    }
    kerf_interp::write_atomic(dest, text.as_bytes()).map_err(interp_err(dest))
}

/// Runs `kerf gcode`.
pub(crate) fn run_gcode(args: &GcodeArgs) -> Result<(), CliError> {
    crate::guard::refuse_overwrite(
        "--output",
        &args.output,
        &[&args.motion.input, &args.motion.machine],
    )?;
    let dialect: Dialect = args.dialect.into();
    let p = program(&args.motion, dialect.raw_axes())?;
    let opts = GcodeOptions {
        fit_tolerance: p.fit_tolerance,
        chord_tolerance: args.motion.chord_tolerance.unwrap_or(0.001),
        linearization_tolerance: p.linearization_tolerance,
        ..gcode_options(
            &p.model,
            dialect,
            args.motion.feed,
            args.blend_tolerance,
            &args.motion.input,
        )
    };
    write_program(&p, &args.output, &opts)?;
    summary(&args.motion, &p, Some(&args.output), args.json, args.quiet);
    Ok(())
}
