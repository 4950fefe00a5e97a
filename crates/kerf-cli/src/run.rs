//! `kerf run`: the whole pipeline in one command. Discretize (certified chord error), normals,
//! machine axes, interpolation and G-code, with a report and a picture, all written into one
//! output directory only once every stage has succeeded.

use std::path::Path;
use std::time::Instant;

use kerf_discretize::Discretization;
use kerf_format::toolpath::{self, ToolPath, ToolPathPoints, ToolpathFile};
use kerf_interp::{
    gcode_motion, stations_from_solved, write_csv_to, AxisModel, Dialect, GcodeOptions,
    MachineModel, PathInput as InterpPath, PlanOptions,
};
use kerf_io::DirEntry;
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
    for name in OUTPUTS {
        crate::guard::refuse_overwrite(
            "--out",
            &args.out.join(name),
            &[path, args.machine.as_path()],
        )?;
    }
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
    let mut discs: Vec<Discretization> = discretize_file(path, &file, &dopts)?;
    // 1b. Where closed cuts start when the file pins it (`start`) or only corners offer it (a
    // polygon: the middle of its longest edge), made a cutting point.
    let starts: Vec<Option<f64>> = discs
        .iter_mut()
        .zip(&file.curves)
        .map(|(d, r)| kerf_process::prepare_start(&r.curve, d, r.start, &args.lead_options()))
        .collect();
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
    // 3a. Where the part goes on the machine; from here on, workpiece coordinates.
    let id_refs: Vec<&str> = file.curves.iter().map(|c| c.id.as_str()).collect();
    let placed = crate::place::place(
        &machine,
        &id_refs,
        &poses,
        args.place.as_ref(),
        &popts,
        args.retract.max(0.0) + 1.0,
        path,
    )?;
    // 3b. The cuts: start points, lead-ins and lead-outs on the scrap side, holes before their
    // outlines, the shortest traverse; in part coordinates, then placed.
    let (cuts, cut_plans) =
        crate::cuts::plan(&file, &oriented, &placed, &starts, &args.lead_options())?;
    let cut_poses: Vec<Vec<Pose>> = cuts
        .iter()
        .map(|c| {
            let p: Vec<Pose> = c.poses.iter().copied().map(Pose::from_array).collect();
            placed.apply_one(c.curve, &p)
        })
        .collect();
    let points: Vec<Box<dyn Fn(f64) -> nalgebra::Point3<f64> + Sync + '_>> = cuts
        .iter()
        .map(|c| {
            let placement = placed.placement_of(c.curve);
            let f = &c.point;
            Box::new(move |u| placement.apply_point(&f(u)))
                as Box<dyn Fn(f64) -> nalgebra::Point3<f64> + Sync>
        })
        .collect();
    let inputs: Vec<PathInput<'_>> = cuts
        .iter()
        .enumerate()
        .map(|(k, c)| PathInput {
            id: &file.curves[c.curve].id,
            poses: &cut_poses[k],
            curve: Some(PathCurve {
                params: &c.params,
                point: points[k].as_ref(),
            }),
        })
        .collect();
    let solved = solve_paths(&machine, &inputs, &popts)
        .map_err(|e| CliError::Kinematics(Box::new(e), Some(args.curves.clone())))?;
    let mut axes = AxesFile::new(&machine, &solved);
    crate::cuts::split_axes(&mut axes, &cuts, &solved);
    // 4. Interpolation and G-code, one program per set-up.
    let model = MachineModel::new(machine.clone()).map_err(interp(path))?;
    let dialect: Dialect = args.dialect.into();
    let fit = crate::motion::fit_options(dopts.tolerance, dialect.raw_axes(), args.retract);
    let plan = PlanOptions::new(args.feed, args.cycle);
    let gopts = GcodeOptions {
        fit_tolerance: dopts.tolerance,
        chord_tolerance: plan.chord_tolerance,
        linearization_tolerance: Some(popts.linearization_tolerance),
        ..crate::motion::gcode_options(&model, dialect, args.feed, args.blend_tolerance, path)
    };
    let mut motions = Vec::new();
    let mut programs = Vec::new();
    let mut setup_ids: Vec<Vec<String>> = Vec::new();
    let topts = args.traverse_options();
    let limits = machine.limits.map(|r| r.map(|r| (r.min, r.max)));
    let mut rapid_report = Vec::new();
    let mut blocked_report = Vec::new();
    for setup in 0..placed.plan.setups.len() {
        let mut ipaths = Vec::new();
        let mut ids: Vec<String> = Vec::new();
        let in_setup: Vec<usize> = (0..solved.len())
            .filter(|&k| placed.plan.setup_of(cuts[k].curve) == setup)
            .collect();
        // Traverses that clear the part's surfaces, placed with this set-up.
        let mut traverses = Vec::new();
        if let (Some(topts), Some(&first)) = (&topts, in_setup.first()) {
            let placement = placed.placement_of(cuts[first].curve);
            let obs =
                kerf_process::Obstacles::from_file(&file, &placed.plan.setups[setup].paths, |p| {
                    placement.apply_point(p)
                })
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
            let gaps: Vec<kerf_process::Gap> = in_setup
                .windows(2)
                .map(|w| {
                    let (a, b) = (&solved[w[0]], &solved[w[1]]);
                    let ax = |q: &kerf_kinematics::Axes| [q.x, q.y, q.z, q.tilt, q.c];
                    // The solved pose of a cut's k-th pose (lead-in, contour, lead-out).
                    let at = |s: &kerf_kinematics::SolvedPath, k: usize| {
                        let j = s.source.iter().position(|v| *v == Some(k)).unwrap_or(0);
                        let p = s.poses[j].position;
                        [p.x, p.y, p.z]
                    };
                    let [m, c, _] = cuts[w[0]].counts;
                    kerf_process::Gap {
                        from: a.poses[a.poses.len() - 1].to_array(),
                        from_axes: ax(&a.axes[a.axes.len() - 1]),
                        to: b.poses[0].to_array(),
                        to_axes: ax(&b.axes[0]),
                        from_contour: at(a, m + c - 1),
                        to_contour: at(b, cuts[w[1]].counts[0]),
                        from_surfaces: file.curves[cuts[w[0]].curve].surfaces.clone(),
                        to_surfaces: file.curves[cuts[w[1]].curve].surfaces.clone(),
                    }
                })
                .collect();
            let rapids =
                kerf_process::plan_rapids(machine.kinematics.as_ref(), &limits, &obs, &gaps, topts);
            for (w, planned) in in_setup.windows(2).zip(&rapids) {
                let (t, r, absent) = match planned {
                    Ok(p) => p,
                    Err(e) => {
                        // No checked route: the unchecked retract traverse, said loudly.
                        if !args.quiet {
                            eprintln!(
                                "warning: {}: {e}; this traverse is NOT checked",
                                path.display()
                            );
                        }
                        blocked_report.push(json!({
                            "after": solved[w[0]].id,
                            "before": solved[w[1]].id,
                            "reason": e.to_string(),
                        }));
                        traverses.push(Vec::new());
                        continue;
                    }
                };
                axes.paths[w[1]].traverse = Some(kerf_kinematics::AxesMove {
                    positions: r.axes.clone(),
                    poses: r.poses.clone(),
                });
                traverses.push(
                    r.axes
                        .iter()
                        .zip(&r.poses)
                        .map(|(a, p)| kerf_interp::Station {
                            tip: nalgebra::Point3::new(p[0], p[1], p[2]),
                            axis: nalgebra::Vector3::new(p[3], p[4], p[5]),
                            param: None,
                            axes: *a,
                        })
                        .collect::<Vec<_>>(),
                );
                rapid_report.push((t.clone(), r.clone(), absent.clone()));
            }
        }
        for (k, s) in solved.iter().enumerate() {
            if placed.plan.setup_of(cuts[k].curve) != setup {
                continue;
            }
            let curve: &(dyn Fn(f64) -> nalgebra::Point3<f64> + Sync) = points[k].as_ref();
            ipaths.push(InterpPath {
                id: s.id.clone(),
                stations: stations_from_solved(s, Some(&cuts[k].params)).map_err(interp(path))?,
                curve: Some(curve),
            });
            ids.push(s.id.clone());
        }
        let motion = kerf_interp::interpolate_through(&model, &ipaths, &traverses, &fit, &plan)
            .map_err(interp(path))?;
        let mut gopts_k = gopts.clone();
        gopts_k.header = vec![
            format!(
                "set-up {} of {}: {} contours; placement (part to workpiece): {}",
                setup + 1,
                placed.plan.setups.len(),
                ids.len(),
                placed.plan.setups[setup].placement
            ),
            "work offset: none; every coordinate is in the machine's workpiece frame with the placement applied: clamp the part there".to_string(),
        ];
        programs.push(gcode_motion(&model, &motion, &ids, &gopts_k).map_err(interp(path))?);
        setup_ids.push(ids);
        motions.push(motion);
    }
    let process =
        kerf_interp::ProcessCodes::resolve(dialect, &machine.process).map_err(interp(path))?;
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
    let mut counts = motions[0].counts();
    for m in &motions[1..] {
        let c = m.counts();
        counts.lines += c.lines;
        counts.arcs += c.arcs;
        counts.turns += c.turns;
    }
    let duration: f64 = motions.iter().map(|m| m.duration()).sum();
    let cycles: usize = motions.iter().map(|m| m.cycles()).sum();
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
            "controller_blending": gopts.blend_tolerance,
            "total": gopts.budget_total(),
        },
        "program": {
            "dialect": dialect.name(),
            "beam_on": process.beam_on,
            "beam_off": process.beam_off,
            "pierce_dwell_s": process.pierce_dwell_s,
            "pierce_standoff_mm": process.pierce_standoff,
            "cuts": motions.iter().map(|motion| motion.blocks().iter().enumerate().filter(|(i, b)| !b.rapid && (*i == 0 || motion.blocks()[i - 1].rapid)).count()).sum::<usize>(),
            "files": program_names(programs.len()),
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
        "placement": placed.json(&id_refs),
        "process": crate::cuts::report(&file, &cuts, &cut_plans),
        "traverses": crate::cuts::traverse_report(topts.as_ref(), &rapid_report, blocked_report),
        "interpolation": {
            "feed_mm_per_min": args.feed,
            "cycle_s": args.cycle,
            "lines": counts.lines,
            "arcs": counts.arcs,
            "turns": counts.turns,
            "cycles": cycles,
            "duration_s": duration,
            "time_share_at_feed": if duration > 0.0 {
                motions.iter().map(|m| m.time_share_at_feed() * m.duration()).sum::<f64>() / duration
            } else {
                0.0
            },
            "paths": motions
                .iter()
                .zip(&setup_ids)
                .flat_map(|(m, ids)| {
                    crate::motion::path_report(m, ids)
                        .as_array()
                        .cloned()
                        .unwrap_or_default()
                })
                .collect::<Vec<_>>(),
        },
        "seconds": start.elapsed().as_secs_f64(),
    });
    // 6. Write everything at once; the set-points are streamed from the plan into the file.
    let names = program_names(programs.len());
    let csv_names = csv_names(programs.len());
    for name in names.iter().chain(&csv_names) {
        crate::guard::refuse_overwrite(
            "--out",
            &args.out.join(name),
            &[path, args.machine.as_path()],
        )?;
    }
    let toolpath_text = toolpath::to_string(&tp)?;
    let axes_text = axes
        .to_json()
        .map_err(|e| CliError::Kinematics(Box::new(e), None))?;
    let report_text = serde_json::to_string_pretty(&report).unwrap_or_else(|_| report.to_string());
    let text = |s: &str| {
        let bytes = s.as_bytes().to_vec();
        Box::new(move |w: &mut dyn std::io::Write| w.write_all(&bytes)) as kerf_io::Contents<'_>
    };
    let axis_names = model.axis_names();
    let mut entries = vec![
        DirEntry {
            name: OUTPUTS[0],
            contents: text(&toolpath_text),
        },
        DirEntry {
            name: OUTPUTS[1],
            contents: text(&axes_text),
        },
    ];
    for (k, (program, motion)) in programs.iter().zip(&motions).enumerate() {
        entries.push(DirEntry {
            name: names[k].as_str(),
            contents: text(program),
        });
        let model = &model;
        entries.push(DirEntry {
            name: csv_names[k].as_str(),
            contents: Box::new(move |w| {
                write_csv_to(w, axis_names, args.cycle, motion.iter(model))
            }),
        });
    }
    entries.push(DirEntry {
        name: OUTPUTS[4],
        contents: text(&report_text),
    });
    entries.push(DirEntry {
        name: OUTPUTS[5],
        contents: text(&svg),
    });
    kerf_io::write_dir_all_or_nothing(&args.out, entries)
        .map_err(|e| CliError::Input(e.to_string()))?;
    if args.json {
        println!("{report}");
    } else if !args.quiet {
        eprintln!(
            "{}: {} curves -> {} cutting points (N* {nstar:.1}), {} poses on {:?}, {} lines + {} arcs, \
             {:.2} s of motion at {} mm/min; wrote {} in {:.2} s{}",
            path.display(),
            file.curves.len(),
            tp.paths.iter().map(|p| p.params.len()).sum::<usize>(),
            solved.iter().map(|s| s.poses.len()).sum::<usize>(),
            machine.name,
            counts.lines,
            counts.arcs,
            duration,
            args.feed,
            args.out.display(),
            start.elapsed().as_secs_f64(),
            if placed.is_identity() {
                String::new()
            } else {
                format!("; {}", placed.summary())
            }
        );
    }
    Ok(())
}

/// `program.nc` for one set-up; `program-1.nc`, `program-2.nc`, ... for several (each set-up is
/// a job of its own: the part is clamped anew between them).
fn program_names(setups: usize) -> Vec<String> {
    if setups == 1 {
        vec!["program.nc".to_string()]
    } else {
        (1..=setups).map(|k| format!("program-{k}.nc")).collect()
    }
}

/// The set-point files matching [`program_names`].
fn csv_names(setups: usize) -> Vec<String> {
    if setups == 1 {
        vec!["setpoints.csv".to_string()]
    } else {
        (1..=setups).map(|k| format!("setpoints-{k}.csv")).collect()
    }
}

fn interp(file: &Path) -> impl Fn(kerf_interp::InterpError) -> CliError + '_ {
    move |e| CliError::Input(format!("{}: {e}", file.display()))
}

/// The files `kerf run` writes into its output directory, all or nothing (through
/// [`kerf_io::write_dir_all_or_nothing`]).
const OUTPUTS: [&str; 6] = [
    "toolpath.json",
    "axes.json",
    "program.nc",
    "setpoints.csv",
    "report.json",
    "plot.svg",
];
