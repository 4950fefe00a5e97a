//! `kerf run`: the whole pipeline in one command ([`kerf_pipeline::Job::run`]), all files
//! written into one output directory only once every stage has succeeded.

use std::time::Instant;

use kerf_kinematics::PathOptions;
use kerf_normals::NormalOptions;
use kerf_pipeline::{Job, JobOptions, Lap, OrientOptions, Timings};

use crate::cli::RunArgs;
use crate::error::CliError;
use crate::input::{load_curves, ProgressBar};

/// The feed of a run that names none and no technology, mm/min.
const DEFAULT_FEED_MM_PER_MIN: f64 = 6000.0;

/// The job options the arguments ask for.
fn job_options(args: &RunArgs) -> JobOptions {
    let mut discretize = kerf_discretize::Options::with_tolerance(args.tolerance);
    discretize.max_segment_length_mm = args.max_segment_length.unwrap_or(f64::INFINITY);
    let mut normals = NormalOptions::default();
    if let Some(deg) = args.max_normal_step {
        normals.max_normal_step_deg = deg;
    }
    let d = PathOptions::default();
    let path = d
        .with_linearization_tolerance_mm(
            args.linearization_tolerance
                .unwrap_or(d.linearization_tolerance_mm),
        )
        .with_max_rotary_step_deg(args.max_rotary_step.unwrap_or(f64::INFINITY))
        .with_tilt_tolerance_deg(
            args.tilt_tolerance
                .unwrap_or(kerf_pipeline::DEFAULT_TILT_TOLERANCE_DEG),
        );
    JobOptions::default()
        .with_discretize(discretize)
        .with_orient(OrientOptions::default().with_normals(normals))
        .with_path(path)
        .with_place(args.place.unwrap_or_default())
        .with_leads(args.lead_options())
        .with_feed_mm_per_min(args.feed.unwrap_or(DEFAULT_FEED_MM_PER_MIN))
        .with_cycle_s(args.cycle)
        .with_dialect(args.dialect.into())
        .with_blend_tolerance_mm(args.blend_tolerance)
        .with_retract_mm(args.retract)
        .with_traverse(args.traverse_options())
        .with_max_total_points(
            args.max_total_points
                .map_or(kerf_pipeline::DEFAULT_MAX_TOTAL_POINTS_RUN, |n| {
                    usize::try_from(n).unwrap_or(usize::MAX)
                }),
        )
        .with_wall_axis_max_mm(args.max_wall)
        .with_kerf_width_mm(args.kerf_width)
        .with_kerf_in_control(args.kerf_in_control)
        .with_cut_clearance_mm(
            args.cut_clearance
                .map_or(kerf_pipeline::DEFAULT_CUT_CLEARANCE_MM, |c| c.0),
        )
        .with_accept_head_collisions(args.accept_head_collisions)
        .with_micro_joints(args.micro_joints)
}

/// Runs `kerf run`.
pub(crate) fn run(args: &RunArgs) -> Result<(), CliError> {
    if args.accept_head_collisions && args.cut_clearance.is_some_and(|c| c.0.is_none()) {
        return Err(CliError::Usage(
            "--accept-head-collisions has nothing to accept with --cut-clearance off".into(),
        ));
    }
    let start = Instant::now();
    let path = args.curves.as_path();
    let refuse = |names: &[String]| {
        names.iter().try_for_each(|name| {
            crate::guard::refuse_overwrite(
                "--out",
                &args.out.join(name),
                &[path, args.machine.as_path()],
            )
        })
    };
    refuse(&kerf_pipeline::OUTPUTS.map(str::to_owned))?;
    let mut read = Timings::default();
    let lap = Lap::start();
    let job = if crate::import::is_cad(path) {
        let machine = crate::input::load_machine(&args.machine)?;
        // The library reads the STEP or IGES file (and puts what it had to assume among the
        // report's warnings); the account is printed here.
        let opts = crate::import::options(&args.step_args)?;
        let (job, report) = Job::from_cad(path, machine, &opts)?;
        if !args.quiet && !args.json {
            crate::import::print_account(path, &report, job.curves());
        }
        job
    } else {
        let file = load_curves(path)?;
        let machine = crate::input::load_machine(&args.machine)?;
        Job::new(file, machine).with_source(path)
    };
    lap.stop(&mut read, "read");
    let mut job = job.with_options(job_options(args));
    // The table: --technology, else the machine file's `process.technology` (relative to the
    // machine file).
    let table_file = args.technology.clone().or_else(|| {
        job.machine().process.technology.as_ref().map(|t| {
            args.machine
                .parent()
                .unwrap_or_else(|| std::path::Path::new("."))
                .join(t)
        })
    });
    if let (Some(_), None) = (&args.material, &table_file) {
        return Err(CliError::Usage(
            "--material needs a technology table: --technology FILE, or the machine file's process.technology".into(),
        ));
    }
    if let (Some(file), Some(material)) = (&table_file, &args.material) {
        let table = kerf_kinematics::Technology::read(file)?;
        let entry = table.entry(material, args.thickness).map_err(|error| {
            kerf_kinematics::KinematicsError::File {
                file: file.display().to_string(),
                error: Box::new(error),
            }
        })?;
        job = job.with_technology(entry.clone());
        if let Some(feed) = args.feed {
            job = job.with_feed_mm_per_min(feed);
        }
    }
    let feed = job.options().feed_mm_per_min;
    let bar = ProgressBar::new(job.curves().curves.len());
    let out = job.run_with_progress(&|p| bar.update(p));
    bar.finish();
    let mut out = out?;
    out.prepend_timings(read);
    if !args.quiet {
        for w in &out.warnings {
            eprintln!(
                "warning: {}: {}",
                path.display(),
                crate::error::with_flags(w.clone())
            );
        }
    }
    // Several set-ups number their programs: check those names too.
    refuse(&out.file_names())?;
    let lap = Lap::start();
    out.write_dir(&args.out)?;
    // The whole write, report and picture included (`report.json` states what came before it).
    lap.stop(&mut out.report.timings, "write");
    let r = &out.report;
    if args.json {
        println!("{}", serde_json::to_string(r).unwrap_or_default());
    } else if !args.quiet {
        eprintln!(
            "{}: {} curves -> {} cutting points (N* {:.1}), {} poses on {:?}, {} lines + {} arcs, \
             {:.2} s of motion at {} mm/min; wrote {} in {:.2} s (CPU {:.2} s: {}){}",
            path.display(),
            job.curves().curves.len(),
            out.toolpath
                .paths
                .iter()
                .map(|p| p.params.len())
                .sum::<usize>(),
            r.discretize.n_star,
            out.solved.iter().map(|s| s.poses.len()).sum::<usize>(),
            job.machine().name,
            r.interpolation.lines,
            r.interpolation.arcs,
            r.interpolation.duration_s,
            feed,
            args.out.display(),
            start.elapsed().as_secs_f64(),
            r.timings.cpu_s(),
            r.timings.summary(3),
            if out.placement.is_identity() {
                String::new()
            } else {
                format!("; {}", out.placement.summary())
            }
        );
    }
    Ok(())
}
