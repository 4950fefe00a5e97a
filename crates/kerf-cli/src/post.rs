//! `kerf post`: machine axes for a toolpath with normals (`kerf.toolpath/1` with
//! `[x, y, z, i, j, k]` points), written as `kerf.axes/1`.

use std::path::Path;
use std::time::Instant;

use kerf_format::toolpath::{self, ToolpathPoints};
use kerf_kinematics::{solve_paths, AxesFile, Machine, PathInput, PathOptions, Pose};
use serde_json::json;

use crate::cli::PostArgs;
use crate::error::CliError;

/// The path options the arguments ask for.
pub(crate) fn options(args: &PostArgs) -> PathOptions {
    let d = PathOptions::default();
    PathOptions {
        linearization_tolerance: args
            .linearization_tolerance
            .unwrap_or(d.linearization_tolerance),
        max_rotary_step_deg: args.max_rotary_step.unwrap_or(d.max_rotary_step_deg),
        pole_tolerance_rad: args.pole_tolerance.unwrap_or(d.pole_tolerance_rad),
        ..d
    }
}

/// Runs `kerf post`.
pub(crate) fn run(args: &PostArgs) -> Result<(), CliError> {
    let start = Instant::now();
    let dest = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.toolpath));
    crate::guard::refuse_overwrite("--output", &dest, &[&args.toolpath, &args.machine])?;
    let machine = Machine::read(&args.machine)?;
    let tp = toolpath::load(&args.toolpath)?;
    let mut poses = Vec::with_capacity(tp.paths.len());
    for (i, p) in tp.paths.iter().enumerate() {
        match &p.points {
            ToolpathPoints::Poses(v) => {
                poses.push(v.iter().copied().map(Pose::from_array).collect::<Vec<_>>())
            }
            ToolpathPoints::Positions(_) => {
                return Err(kerf_pipeline::Error::NoNormals {
                    file: Some(args.toolpath.clone()),
                    index: i,
                    id: p.id.clone(),
                }
                .into())
            }
        }
    }
    let opts = options(args);
    let ids: Vec<&str> = tp.paths.iter().map(|p| p.id.as_str()).collect();
    let placed = kerf_pipeline::place(
        &machine,
        &ids,
        &poses,
        args.place.unwrap_or_default(),
        &opts,
        kerf_pipeline::AUTO_CLEARANCE_MM,
        Some(&args.toolpath),
    )?;
    let poses = placed.apply(&poses);
    let inputs: Vec<PathInput<'_>> = tp
        .paths
        .iter()
        .zip(&poses)
        .map(|(p, q)| PathInput {
            id: &p.id,
            poses: q,
            curve: None,
        })
        .collect();
    let solved = solve_paths(&machine, &inputs, &opts)
        .map_err(|e| kerf_pipeline::Error::from(e).in_file(&args.toolpath))?;
    let file = AxesFile::new(&machine, &solved);
    file.write(&dest)?;
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
            "linearization_tolerance": opts.linearization_tolerance,
            "pole_points": pole,
            "pole_tip_error": pole_err,
            "placement": placed.json(&ids),
            "seconds": elapsed,
        });
        if dest == Path::new("-") {
            eprintln!("{summary}");
        } else {
            println!("{summary}");
        }
    } else if !args.quiet {
        eprintln!(
            "{}: {} paths on {:?}, {points} poses ({inserted} inserted), largest rotary step \
             between cutting points {max_rot:.3} deg, worst non-linearity {max_lin:.2e} mm <= {} mm, \
             {pole} points at the pole (tip error {pole_err:.1e} mm), {elapsed:.3} s -> {}{}",
            args.toolpath.display(),
            solved.len(),
            machine.name,
            opts.linearization_tolerance,
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

/// `dir/part.toolpath.json` -> `part.axes.json` in the current directory.
fn default_output(input: &Path) -> std::path::PathBuf {
    let stem = input.file_stem().map_or_else(
        || "toolpath".to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let stem = stem.strip_suffix(".toolpath").unwrap_or(&stem).to_string();
    format!("{stem}.axes.json").into()
}
