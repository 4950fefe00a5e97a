//! `kerf post`: machine axes for a toolpath with normals (`kerf.toolpath/1` with
//! `[x, y, z, i, j, k]` points), written as `kerf.axes/1`: argument parsing and printing over
//! [`kerf_pipeline::post_toolpath`].

use std::time::Instant;

use kerf_format::toolpath;
use kerf_kinematics::PathOptions;
use kerf_pipeline::{post_toolpath, MissingNormals};
use serde_json::json;

use crate::cli::PostArgs;
use crate::error::CliError;

/// The path options the arguments ask for.
pub(crate) fn options(args: &PostArgs) -> PathOptions {
    let d = PathOptions::default();
    d.with_linearization_tolerance_mm(
        args.linearization_tolerance
            .unwrap_or(d.linearization_tolerance_mm),
    )
    .with_max_rotary_step_deg(args.max_rotary_step.unwrap_or(d.max_rotary_step_deg))
    .with_pole_tolerance_deg(args.pole_tolerance.unwrap_or(d.pole_tolerance_deg))
    .with_tilt_tolerance_deg(
        args.tilt_tolerance
            .unwrap_or(kerf_pipeline::DEFAULT_TILT_TOLERANCE_DEG),
    )
}

/// Runs `kerf post`.
pub(crate) fn run(args: &PostArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let dest = args.output.clone().unwrap_or_else(|| {
        crate::input::default_output(&args.toolpath, "toolpath", ".toolpath", ".axes.json")
    });
    crate::guard::refuse_overwrite("--output", &dest, &[&args.toolpath, &args.machine])?;
    let machine = crate::input::load_machine(&args.machine)?;
    let tp = toolpath::load(&args.toolpath)?;
    let opts = options(args);
    let posted = post_toolpath(
        &machine,
        &tp,
        &opts,
        args.place.unwrap_or_default(),
        MissingNormals::Error,
        Some(&args.toolpath),
    )?;
    posted.axes.write(&dest)?;
    let (solved, placed) = (&posted.solved, &posted.placed);
    let ids: Vec<&str> = tp.paths.iter().map(|p| p.id.as_str()).collect();
    let inserted: usize = solved.iter().map(|s| s.inserted).sum();
    let points: usize = solved.iter().map(|s| s.poses.len()).sum();
    let max_rot = solved
        .iter()
        .map(|s| s.max_rotary_step_between_cutting_points)
        .fold(0.0, f64::max);
    let max_lin = solved
        .iter()
        .map(|s| s.max_linearization_error)
        .fold(0.0, f64::max);
    let pole: usize = solved.iter().map(|s| s.pole_points).sum();
    let pole_err = solved.iter().map(|s| s.pole_tip_error).fold(0.0, f64::max);
    let elapsed = start.elapsed().as_secs_f64();
    if args.json {
        let summary = json!({
            "toolpath": args.toolpath.display().to_string(),
            "machine": machine.name,
            "output": dest.display().to_string(),
            "paths": solved.len(),
            "points": points,
            "inserted": inserted,
            "max_rotary_step_between_cutting_points": max_rot,
            "max_linearization_error": max_lin,
            "linearization_tolerance": opts.linearization_tolerance_mm,
            "pole_points": pole,
            "pole_tip_error": pole_err,
            "placement": placed.report(&ids),
            "seconds": elapsed,
        });
        crate::input::print_summary(&summary, Some(&dest));
    } else if !args.quiet {
        eprintln!(
            "{}: {} paths on {:?}, {points} poses ({inserted} inserted), largest rotary step \
             between cutting points {max_rot:.3} deg, worst non-linearity {max_lin:.2e} mm <= {} mm, \
             {pole} points at the pole (tip error {pole_err:.1e} mm), {elapsed:.3} s -> {}{}",
            args.toolpath.display(),
            solved.len(),
            machine.name,
            opts.linearization_tolerance_mm,
            dest.display(),
            if placed.is_identity() {
                String::new()
            } else {
                format!("; {}", placed.summary())
            }
        );
    }
    Ok(())
}
