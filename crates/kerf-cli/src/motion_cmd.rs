//! `kerf interpolate` and `kerf gcode`: the pipeline's motion stage
//! ([`kerf_pipeline::plan_program`]) on a `kerf.axes/1` or `kerf.toolpath/1` file.

use std::path::{Path, PathBuf};

use kerf_interp::{AxisModel, Dialect};
use kerf_pipeline::{
    path_report, plan_program, CertifiedToolpath, MotionInput, MotionOptions, Program,
};
use serde_json::json;

use crate::cli::{GcodeArgs, InterpolateArgs, MotionArgs};
use crate::error::CliError;

/// Reads the input (axes or toolpath) and the machine, and plans the program with `options`
/// (dialect, blending) and the arguments' feed, cycle and tolerances.
fn program(args: &MotionArgs, options: MotionOptions) -> Result<Program, CliError> {
    let machine = crate::input::load_machine(&args.machine)?;
    let mut input = MotionInput::read(&args.input)?;
    if let Some(curves) = &args.curves {
        let MotionInput::Toolpath(tp) = input else {
            return Err(CliError::Usage(format!(
                "--curves certifies a kerf.toolpath/1 input; {} is an axes file",
                args.input.display()
            )));
        };
        let curves = crate::input::load_curves(curves)?;
        input = MotionInput::Certified(CertifiedToolpath::new(tp, &curves, Some(&args.input))?);
    }
    let options = options
        .with_feed_mm_per_min(args.feed)
        .with_cycle_s(args.cycle)
        .with_fit_tolerance_mm(args.fit_tolerance)
        .with_chord_tolerance_mm(args.chord_tolerance)
        .with_retract_mm(args.retract)
        .with_recorded_traverses(args.clearance > 0.0);
    Ok(plan_program(&machine, &input, &options, Some(&args.input))?)
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
        crate::input::print_summary(&text, out.map(PathBuf::as_path));
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

/// Writes `dest` (`-`: standard output; a file atomically, through `kerf_io`) with `write`.
fn write_output(
    dest: &Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> kerf_pipeline::Result<()>,
) -> Result<(), CliError> {
    let written = kerf_io::write_file(dest, |w| {
        write(w).map_err(|e| match e {
            kerf_pipeline::Error::Write { source, .. } => source,
            other => std::io::Error::other(other.to_string()),
        })
    });
    written.map_err(|source| {
        if dest == Path::new("-") {
            // A closed pipe is the reader's choice, not our failure (main says nothing).
            CliError::Output(source)
        } else {
            kerf_pipeline::Error::Write {
                path: Some(dest.to_path_buf()),
                source,
            }
            .into()
        }
    })
}

/// Runs `kerf interpolate`.
pub(crate) fn run_interpolate(args: &InterpolateArgs) -> Result<(), CliError> {
    if let Some(csv) = &args.csv {
        crate::guard::refuse_overwrite("--csv", csv, &[&args.motion.input, &args.motion.machine])?;
    }
    // Set-points are computed with tool-tip control: arcs are safe.
    let p = program(&args.motion, MotionOptions::default().with_dialect(None))?;
    if let Some(csv) = &args.csv {
        // Streamed cycle by cycle from the plan into the file (or standard output): memory
        // stays bounded however long the program runs.
        write_output(csv, |w| p.write_setpoints(w))?;
    }
    summary(&args.motion, &p, args.csv.as_ref(), args.json, args.quiet);
    Ok(())
}

/// Runs `kerf gcode`.
pub(crate) fn run_gcode(args: &GcodeArgs) -> Result<(), CliError> {
    crate::guard::refuse_overwrite(
        "--output",
        &args.output,
        &[&args.motion.input, &args.motion.machine],
    )?;
    let dialect: Dialect = args.dialect.into();
    let p = program(
        &args.motion,
        MotionOptions::default()
            .with_dialect(Some(dialect))
            .with_blend_tolerance_mm(args.blend_tolerance),
    )?;
    // The text first: a program the writer refuses leaves no file.
    let text = p.gcode()?;
    write_output(&args.output, |w| {
        w.write_all(text.as_bytes())
            .map_err(|source| kerf_pipeline::Error::Write { path: None, source })
    })?;
    summary(&args.motion, &p, Some(&args.output), args.json, args.quiet);
    Ok(())
}
