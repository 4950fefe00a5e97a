//! [`Job::run`]: the whole pipeline in memory. Discretize (certified chord error), normals,
//! placement, cuts, machine axes, interpolation and G-code, with a report and a picture
//! ([`Output`]); [`Output::write_dir`] writes them all into one directory only once every
//! stage has succeeded.

use std::path::Path;
use std::time::Instant;

use kerf_discretize::Discretization;
use kerf_interp::{gcode_motion, stations_from_solved, ChordTerm, MachineModel, PlanOptions};
use kerf_kinematics::{solve_paths, AxesFile, PathCurve, PathInput, Pose};
use kerf_normals::Oriented;

use crate::discretize::{discretize_curves_within, orient_curves, toolpath_of_poses};
use crate::error::{interp, kin, Result};
use crate::job::Job;
use crate::output::{Output, SetupProgram};
use crate::report::{
    DiscretizeReport, InterpolationReport, KinematicsReport, MicroJoint, MicroJointPath,
    MicroJointsReport, NormalsReport, ProgramReport, Report, TechnologyReport, TiltPath,
    TiltTotals,
};
use crate::timing::{Lap, Timings};
use crate::{Progress, Stage};

impl Job {
    /// Runs every stage in memory.
    ///
    /// # Errors
    /// The first stage's [`Error`](crate::Error), naming the file (see [`Job::with_source`]) and the curve.
    pub fn run(&self) -> Result<Output> {
        self.run_with_progress(&|_| {})
    }

    /// [`Job::run`], calling `progress` as the stages advance (from several threads in the
    /// parallel stages: per curve in [`Stage::Discretize`] and [`Stage::Normals`], once per
    /// stage elsewhere).
    ///
    /// # Errors
    /// As [`Job::run`].
    pub fn run_with_progress(&self, progress: &(dyn Fn(Progress) + Sync)) -> Result<Output> {
        run(self, progress)
    }
}

/// How many times `--place auto` is tried again with a wider margin when the program's motion
/// (a lead, a retract, a traverse, a pierce point or a blend) leaves a linear axis' travel.
pub const PLACEMENT_RETRIES: usize = 3;

/// The stages of [`Job::run_with_progress`], in order. A placement that `auto` chose must hold
/// every move of the program, not only the cutting poses it was checked with: the search keeps
/// the retract (or the pierce standoff, if longer) plus 1 mm from every linear limit, and if
/// the motion still leaves a linear axis' range by `d` mm (a lead's pose, a set-point or a
/// pierce point), the placement is searched again keeping `d + 1` mm more, at most
/// [`PLACEMENT_RETRIES`] times; then the search's own refusal ("no placement fits") or the
/// range error stands. Each search runs the whole job again (a failure case only). A placement
/// the user gave is never moved: its range error is reported as it is.
fn run(job: &Job, progress: &(dyn Fn(Progress) + Sync)) -> Result<Output> {
    let mut extra = 0.0;
    let mut attempt = 0;
    // The searches a wider margin replaced, timed as one stage before the others.
    let mut earlier = Timings::default();
    loop {
        let lap = Lap::start();
        match run_placed(job, progress, extra, attempt) {
            Err(e)
                if job.options.place == crate::PlaceMode::Auto && attempt < PLACEMENT_RETRIES =>
            {
                match linear_overshoot(&e) {
                    Some(d) => {
                        extra += d + 1.0;
                        attempt += 1;
                        lap.stop(&mut earlier, "earlier placements");
                    }
                    None => return Err(e),
                }
            }
            Ok(mut out) => {
                if !earlier.stages.is_empty() {
                    out.prepend_timings(earlier);
                }
                return Ok(out);
            }
            r => return r,
        }
    }
}

/// How far (mm) the program's motion leaves a linear axis' range, if that is the error: a
/// set-point or pierce point of the plan, or a pose of a lead the placement search did not see.
fn linear_overshoot(e: &crate::Error) -> Option<f64> {
    let over = |axis: &str, value: f64, min: f64, max: f64| {
        let over = (min - value).max(value - max);
        (matches!(axis, "X" | "Y" | "Z") && over.is_finite() && over > 0.0).then_some(over)
    };
    let source = match e {
        crate::Error::Interp { source, .. } => source,
        // A lead-in, lead-out or inserted pose the search did not see.
        crate::Error::Kinematics { source, .. } => {
            return match source.without_file() {
                kerf_kinematics::KinematicsError::OutOfLimits {
                    axis,
                    value,
                    min,
                    max,
                    ..
                } => over(axis, *value, *min, *max),
                _ => None,
            };
        }
        _ => return None,
    };
    let (axis, value, min, max) = match source {
        kerf_interp::InterpError::OutOfRange {
            axis,
            value,
            min,
            max,
            ..
        }
        | kerf_interp::InterpError::PierceOutOfRange {
            axis,
            value,
            min,
            max,
            ..
        }
        | kerf_interp::InterpError::RetractOutOfRange {
            axis,
            value,
            min,
            max,
            ..
        } => (axis, *value, *min, *max),
        _ => return None,
    };
    over(axis, value, min, max)
}

/// The stages once, the placement search keeping `extra_margin_mm` more from the linear
/// limits (`attempt` is reported).
fn run_placed(
    job: &Job,
    progress: &(dyn Fn(Progress) + Sync),
    extra_margin_mm: f64,
    attempt: usize,
) -> Result<Output> {
    let start = Instant::now();
    let mut timings = Timings::default();
    let mut lap = Lap::start();
    let path = job.source.as_deref();
    let file = &job.curves;
    let machine = &job.machine;
    let o = &job.options;
    job.validate()?;
    let dopts = o.discretize;
    // With a kerf width, each path is first offset by half of it toward the scrap.
    let kerf = o
        .kerf_width_mm
        .map(|w| (w, "the run's kerf_width_mm"))
        .or_else(|| {
            o.technology
                .as_ref()
                .and_then(|t| t.kerf_width_mm)
                .map(|w| (w, "technology entry"))
        })
        .or_else(|| {
            machine
                .process
                .kerf_width_mm
                .map(|w| (w, "machine file process.kerf_width_mm"))
        })
        .map(|(width_mm, source)| crate::cuts::Kerf {
            width_mm,
            source,
            tolerance_mm: dopts.tolerance_mm,
            in_control: o.kerf_in_control,
        });
    // A dialect that cannot program this machine is refused before any work.
    MachineModel::new(machine.clone())
        .and_then(|m| o.dialect.check_machine(&m))
        .map_err(interp(path))?;
    // 1. Cutting points with a certified chord error. With a kerf, the contour's chords take
    // 9/10 of the tolerance and the offset's own term the rest (docs/process.md, "Kerf
    // compensation"): a hole's offset chords then need no more points.
    if kerf.as_ref().is_some_and(|k| k.in_control) && o.dialect != kerf_interp::Dialect::Linuxcnc {
        return Err(crate::Error::BadOption {
            name: "kerf_in_control",
            value: 1.0,
            requirement: format!(
                "the controller's kerf compensation is written for the linuxcnc dialect only (G41.1/G42.1), not {}; compensate in the computer instead",
                o.dialect.name()
            ),
        });
    }
    // In the controller too: it offsets the same cutting points, so that its path and kerf's
    // own offset agree (tests/linuxcnc), and the chord polygon's offset keeps the same margin.
    let contour_opts = match &kerf {
        Some(_) => dopts.with_tolerance_mm(dopts.tolerance_mm * crate::cuts::KERF_CONTOUR_SHARE),
        None => dopts,
    };
    let mut discs: Vec<Discretization> =
        discretize_curves_within(file, &contour_opts, o.max_total_points, path, progress)?;
    // 1b. Where closed cuts start when the file pins it (`start`) or only corners offer it (a
    // polygon: the middle of its longest edge), made a (certified) cutting point.
    let starts: Vec<Option<f64>> = discs
        .iter_mut()
        .zip(&file.curves)
        .map(|(d, r)| {
            kerf_process::prepare_start(&r.curve, d, r.start, &o.leads, contour_opts.tolerance_mm)
        })
        .collect();
    lap.split(&mut timings, "discretize");
    // 2. Normals (+z for curves that name no surface, unless the options refuse them).
    let oriented: Vec<Oriented> =
        orient_curves(file, &discs, &contour_opts, &o.orient, path, progress)?;
    let mut tp = toolpath_of_poses(file, dopts.tolerance_mm, &oriented);
    // Curves taken within their own tolerance (a CAD edge on its face within its file's),
    // beyond the run's: each named with both.
    let edge_warnings = crate::discretize::beyond_run_tolerance(
        file,
        &oriented,
        o.orient.normals.on_surface_tolerance_mm,
    );
    lap.split(&mut timings, "normals");
    // 3. Machine axes, points inserted on the curve against the non-linearity error.
    let popts = o.path;
    progress(Progress::new(Stage::Kinematics, 0, 1));
    // 2b. Contours on a thin wall through the sheet (a hole's wall named instead of the sheet's
    // face): the beam along the wall, the scrap where the wall's normal points.
    let walls = crate::cuts::walls(file, &oriented, o.wall_axis_max_mm);
    let poses: Vec<Vec<Pose>> = oriented
        .iter()
        .zip(&walls)
        .map(|(o, w)| match w {
            Some(w) => w.poses.iter().copied().map(Pose::from_array).collect(),
            None => o.poses().into_iter().map(Pose::from_array).collect(),
        })
        .collect();
    // Checked traverses (None: the unchecked retract); never a shorter retract than asked.
    let topts = o.traverse.map(|mut t| {
        t.retract_mm = t.retract_mm.max(o.retract_mm);
        t
    });
    // 3a. Which side of the sheet each contour is cut from, where kerf chooses (`--place
    // auto`, checked traverses): the side from which the nozzle's line along the tool axis
    // does not meet the part, reach permitting (the placement checks it).
    let head_lines = match (o.place, &topts) {
        (crate::PlaceMode::Auto, Some(t)) => {
            Some(crate::place::sides_by_head_lines(file, &poses, t, path)?)
        }
        _ => None,
    };
    lap.split(&mut timings, "sides");
    // 3b. Where the part goes on the machine; from here on, workpiece coordinates. The search
    // keeps the longest move off the cut along the tool axis (the retract or the pierce
    // standoff) and 1 mm of blending from every linear limit.
    let standoff = machine.process.pierce_standoff.unwrap_or(0.0);
    let placement_margin = o.retract_mm.max(standoff).max(0.0) + 1.0 + extra_margin_mm;
    let id_refs: Vec<&str> = file.curves.iter().map(|c| c.id.as_str()).collect();
    let placed = crate::place::place(
        machine,
        &id_refs,
        head_lines.as_ref().map_or(&poses, |(_, turned)| turned),
        o.place,
        &kerf_kinematics::AutoPlaceOptions::default()
            .with_path_options(popts)
            .with_margin_mm(placement_margin)
            // A thick sheet's contours are never turned over (the import put each on the
            // side that faces up): with any in the file, the placement turns none.
            .with_flip(!file.curves.iter().any(|c| c.sheet_thickness_mm.is_some())),
        path,
    )?;
    let placed = match head_lines {
        Some((h, _)) => placed.with_head_lines(h),
        None => placed,
    };
    lap.split(&mut timings, "place");
    // 3c. The cuts: start points, lead-ins and lead-outs on the scrap side, holes before their
    // outlines, the shortest traverse; in part coordinates, then placed.
    let (cuts, cut_plans, compensated) = crate::cuts::plan(
        file,
        &oriented,
        &walls,
        &placed,
        &starts,
        &o.leads,
        kerf.as_ref(),
        path,
    )?;
    // Memory: what no later stage reads is dropped as soon as it is done with (the poses for
    // the placement here, the placed cut poses after the kinematics, every path's stations
    // once its blocks are fitted), so that the plan of the motion, the largest part of a run,
    // is not made beside them.
    drop(poses);
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
    lap.split(&mut timings, "cuts");
    // Micro-joints: where the beam leaves each part's outline (and big cut-outs) uncut.
    let (joints, joint_warnings) = match o.micro_joints {
        Some((length, spacing)) => {
            crate::cuts::micro_joints(file, &cuts, &cut_plans, length, spacing)
        }
        None => (vec![Vec::new(); cuts.len()], Vec::new()),
    };
    let joints_report: Vec<MicroJointPath> = cuts
        .iter()
        .zip(&joints)
        .enumerate()
        .filter(|(_, (_, j))| !j.is_empty())
        .map(|(k, (c, j))| {
            let placed: Vec<[f64; 3]> = cut_poses[k]
                .iter()
                .map(|p| [p.position.x, p.position.y, p.position.z])
                .collect();
            MicroJointPath {
                id: file.curves[c.curve].id.clone(),
                joints: j
                    .iter()
                    .map(|&[a, b]| MicroJoint {
                        start_mm: a,
                        end_mm: b,
                        start: crate::cuts::point_along(&placed, a),
                        end: crate::cuts::point_along(&placed, b),
                    })
                    .collect(),
            }
        })
        .collect();
    let mut solved = solve_paths(machine, &inputs, &popts).map_err(kin(path))?;
    lap.split(&mut timings, "kinematics");
    // 3d. The head against every surface of the file along every cut, set-up by set-up; the
    // tool axis tilted within the tilt tolerance where it comes too close.
    let mut head_report = Vec::new();
    let mut head_tip_zone: Option<f64> = None;
    let mut head_warnings: Vec<String> = Vec::new();
    // The machine's head (or kerf's default) and the nozzle's standoff above the tip: the
    // head check's and the 3D view's.
    let head = machine
        .head
        .clone()
        .unwrap_or_else(kerf_kinematics::Head::laser_default);
    let head_standoff_mm = machine
        .process
        .standoff_mm
        .unwrap_or(kerf_kinematics::DEFAULT_STANDOFF_MM);
    // The program's fit follows from the dialect, no option can change it (the head check
    // needs its orientation tolerance, the interpolation the rest).
    let fit = crate::motion::fit_options(dopts.tolerance_mm, Some(o.dialect), o.retract_mm);
    if let Some(clearance) = o.cut_clearance_mm {
        let hopts = kerf_process::HeadCheckOptions::default()
            .with_clearance_mm(clearance)
            .with_standoff_mm(head_standoff_mm)
            .with_max_tilt_deg(popts.tilt_tolerance_deg.max(HEAD_CHECK_MIN_TILT_DEG))
            // The controller's tip leaves the chords by the non-linearity error and its
            // blending (an infinite tolerance leaves the check unproven).
            .with_path_deviation_mm(popts.linearization_tolerance_mm + o.blend_tolerance_mm)
            // Where the program's blocks merge poses (lines and arcs over several), each
            // pose's axis is held within the fit's orientation tolerance only.
            .with_axis_deviation_deg(if fit.merge_lines || fit.arcs {
                fit.orientation_tolerance_deg
            } else {
                0.0
            });
        for setup in 0..placed.plan.setups.len() {
            let ks: Vec<usize> = (0..solved.len())
                .filter(|&k| placed.plan.setup_of(cuts[k].curve) == setup)
                .collect();
            let Some(&first) = ks.first() else { continue };
            let placement = placed.placement_of(cuts[first].curve);
            // Each cut against the part it lies on: the surfaces its curve names and every
            // surface joined to those (a wall beside a hole), not another part the file holds.
            let all =
                kerf_process::Obstacles::from_all_surfaces(file, |p| placement.apply_point(p))
                    .map_err(|source| crate::Error::Process {
                        file: path.map(Path::to_path_buf),
                        source,
                    })?;
            let parts = all.parts(PART_JOIN_TOLERANCE_MM);
            let r = crate::head::check_and_clear(
                machine,
                |k| all.of_parts(&parts, &file.curves[cuts[k].curve].surfaces),
                &head,
                &hopts,
                &popts,
                &inputs,
                &ks,
                &mut solved,
                o.accept_head_collisions,
            );
            head_report.extend(r.report);
            head_warnings.extend(r.warnings);
            head_tip_zone = r.tip_zone_mm.or(head_tip_zone);
            if let Some(source) = r.refusal {
                return Err(crate::Error::Process {
                    file: path.map(Path::to_path_buf),
                    source,
                });
            }
        }
        lap.split(&mut timings, "head");
    }
    drop(inputs);
    drop(cut_poses);
    // The controller's compensation: G41.1/G42.1 per path, where the beam stands vertical
    // and still along the whole cut (the compensation offsets X and Y only).
    let in_control =
        crate::cuts::controller_compensation(file, kerf.as_ref(), &compensated, &cuts, &solved)
            .map_err(|e| crate::Error::Process {
                file: path.map(std::path::Path::to_path_buf),
                source: e,
            })?;
    let mut axes = AxesFile::new(machine, &solved);
    crate::cuts::split_axes(&mut axes, &cuts, &solved);
    // 4. Interpolation and G-code, one program per set-up.
    progress(Progress::new(Stage::Interpolate, 0, 1));
    let model = MachineModel::new(machine.clone()).map_err(interp(path))?;
    let dialect = o.dialect;
    let mut plan = PlanOptions::new(o.feed_mm_per_min, o.cycle_s);
    plan.blend_tolerance_mm = o.blend_tolerance_mm; // the planner's blend and the controller's
    let source_name = path.map(|p| p.display().to_string());
    let gopts = crate::motion::gcode_options(
        &model,
        dialect,
        o.feed_mm_per_min,
        o.blend_tolerance_mm,
        source_name.as_deref(),
    )
    .with_fit_tolerance_mm(dopts.tolerance_mm)
    // Every segment was certified within the tolerance by the discretizer (and re-certified
    // where the normals or the start point inserted points).
    .with_chord_term(ChordTerm::Certified(dopts.tolerance_mm))
    .with_chord_tolerance_mm(plan.chord_tolerance_mm)
    .with_linearization_tolerance_mm(Some(popts.linearization_tolerance_mm))
    .with_power(o.technology.as_ref().map(laser_power));
    // The technology's small-hole rule: which cuts run at its feed and power factors.
    let small = o.technology.as_ref().and_then(|t| t.small_hole).map(|h| {
        (
            h,
            crate::cuts::small_holes(&cuts, &cut_plans, h.max_diameter_mm),
        )
    });
    let small_ids: Vec<&str> = small.as_ref().map_or(Vec::new(), |(_, holes)| {
        cuts.iter()
            .zip(holes)
            .filter(|(_, &h)| h)
            .map(|(c, _)| file.curves[c.curve].id.as_str())
            .collect()
    });
    let mut motions = Vec::new();
    let mut programs = Vec::new();
    let mut setup_ids: Vec<Vec<String>> = Vec::new();
    let mut traverse_tally = crate::traverses::Tally::default();
    // The traverses for the plot, part coordinates.
    let mut plot_traverses: Vec<Vec<nalgebra::Point3<f64>>> = Vec::new();
    let mut warnings: Vec<String> = edge_warnings;
    warnings.extend(head_warnings);
    warnings.extend(joint_warnings.iter().cloned());
    // The offset paths go into the toolpath (`kerf_offset`), where `kerf check` measures them.
    for c in &compensated {
        if let crate::cuts::Outcome::Offset(p) = &c.outcome {
            tp.paths[c.curve].kerf_offset = Some(crate::cuts::kerf_offset_record(p));
        }
    }
    let uncompensated: Vec<&str> = compensated
        .iter()
        .filter(|c| !c.outcome.is_compensated())
        .map(|c| file.curves[c.curve].id.as_str())
        .collect();
    if !uncompensated.is_empty() {
        let shown: Vec<String> = uncompensated
            .iter()
            .take(5)
            .map(|id| format!("{id:?}"))
            .collect();
        warnings.push(format!(
            "{} contours without a `scrap` key whose scrap side is not known (open, or a loop round a tube) are cut on the contour, not kerf-compensated: {}{} (report: compensation.paths)",
            uncompensated.len(),
            shown.join(", "),
            if uncompensated.len() > 5 { ", ..." } else { "" }
        ));
    }
    lap.split(&mut timings, "kinematics");
    for setup in 0..placed.plan.setups.len() {
        let mut fitted = Vec::new();
        let mut comps: Vec<Option<kerf_interp::CutterCompensation>> = Vec::new();
        let mut feed_factors: Vec<f64> = Vec::new();
        let mut power_factors: Vec<f64> = Vec::new();
        let mut path_joints: Vec<Vec<[f64; 2]>> = Vec::new();
        let mut ids: Vec<String> = Vec::new();
        let in_setup: Vec<usize> = (0..solved.len())
            .filter(|&k| placed.plan.setup_of(cuts[k].curve) == setup)
            .collect();
        // 3e. Traverses that clear the part's surfaces, placed with this set-up.
        let routed = crate::traverses::route_setup(
            &crate::traverses::SetupCuts {
                file,
                path,
                placed: &placed,
                cuts: &cuts,
                solved: &solved,
                setup,
                in_setup: &in_setup,
            },
            machine,
            topts.as_ref(),
            o.retract_mm,
            &mut axes,
            &mut traverse_tally,
        )?;
        warnings.extend(routed.warnings);
        plot_traverses.extend(routed.plot);
        let traverses = routed.stations;
        lap.split(&mut timings, "traverses");
        for (k, s) in solved.iter().enumerate() {
            if placed.plan.setup_of(cuts[k].curve) != setup {
                continue;
            }
            let curve: &(dyn Fn(f64) -> nalgebra::Point3<f64> + Sync) = points[k].as_ref();
            // What `kerf_interp::interpolate_through` does, path by path: the stations are
            // dropped once the path's blocks are fitted.
            let stations = stations_from_solved(s, Some(&cuts[k].params)).map_err(interp(path))?;
            fitted.push(
                kerf_interp::fit_blocks(&model, &stations, Some(curve), fitted.len(), &fit)
                    .map_err(interp(path))?,
            );
            ids.push(s.id.clone());
            comps.push(in_control[k]);
            let (feed_factor, power_factor) = match &small {
                Some((h, holes)) if holes[k] => (h.feed_factor, h.power_factor),
                _ => (1.0, 1.0),
            };
            feed_factors.push(feed_factor);
            power_factors.push(power_factor);
            path_joints.push(joints[k].clone());
        }
        let blocks = kerf_interp::link_paths_through(&model, fitted, &traverses, fit.retract_mm);
        drop(traverses);
        let plan_k = plan
            .clone()
            .with_feed_factors(feed_factors)
            .with_corner_slowdown(o.technology.as_ref().and_then(|t| t.corner).map(|c| {
                kerf_interp::CornerSlowdown {
                    min_turn_deg: c.min_turn_deg,
                    length_mm: c.length_mm,
                    feed_factor: c.feed_factor,
                }
            }));
        let motion = kerf_interp::plan_owned(&model, blocks, &plan_k).map_err(interp(path))?;
        lap.split(&mut timings, "plan");
        let mut gopts_k = gopts
            .clone()
            .with_cutter_compensation(comps)
            .with_power_factors(power_factors)
            .with_micro_joints(path_joints);
        gopts_k.header = vec![
            format!(
                "set-up {} of {}: {} contours; placement (part to workpiece): {}",
                setup + 1,
                placed.plan.setups.len(),
                ids.len(),
                placed.plan.setups[setup].placement
            ),
            "work offset: none; every coordinate is in the machine's workpiece frame with the placement applied: clamp the part there".to_string(),
            crate::cuts::kerf_header(kerf.as_ref(), &compensated),
        ];
        gopts_k
            .header
            .extend(technology_header(o.technology.as_ref()));
        let mut text = gcode_motion(&model, &motion, &ids, &gopts_k).map_err(interp(path))?;
        text.shrink_to_fit();
        programs.push(text);
        setup_ids.push(ids);
        motions.push(motion);
        lap.split(&mut timings, "gcode");
    }
    let process =
        kerf_interp::ProcessCodes::resolve(dialect, &machine.process).map_err(interp(path))?;
    // 5. The 3D view, the picture and the report.
    progress(Progress::new(Stage::Report, 0, 1));
    let input_name = path.map_or_else(
        || "curves".to_string(),
        |path| {
            path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        },
    );
    let program_files = crate::output::program_names(motions.len());
    let view_setups: Vec<crate::view::SetupInput<'_>> = motions
        .iter()
        .enumerate()
        .map(|(k, m)| crate::view::SetupInput {
            placement: placed
                .plan
                .setups
                .get(k)
                .map_or(kerf_kinematics::Placement::IDENTITY, |s| s.placement),
            motion: m,
            ids: &setup_ids[k],
            program: &program_files[k],
        })
        .collect();
    let view = crate::view::scene(
        &input_name,
        file,
        &cuts,
        &view_setups,
        &model,
        &head,
        head_standoff_mm,
        o.feed_mm_per_min,
        process.pierce_standoff,
    );
    drop(view_setups);
    lap.split(&mut timings, "view");
    let svg = picture(
        &Picture {
            file,
            tp: &tp,
            axes: &axes,
            machine,
            input_name: &input_name,
            cuts: &cuts,
            placed: &placed,
            joints: &joints,
        },
        plot_traverses,
    )?;
    let placement_report = {
        let mut p = placed.report(&id_refs);
        p.walls = Some(crate::cuts::walls_report(file, &walls));
        if placed.auto {
            // The margin the search kept from the linear limits, and how many searches it took
            // for every move of the program to stay within the travel.
            p.margin_mm = Some(placement_margin);
            p.searches = Some(attempt + 1);
        }
        p.walls_note = Some(format!(
            "contours whose only named surface is a wall at most {} mm wide across them (its control net's extent along n x t, the wall's direction across the contour; 0 = off): a hole's or slot's wall, the sheet's edge face, named instead of the sheet's face. The beam runs along the wall (side 'given' is the head on the face of the sheet that holds the contour, away from the wall), the lead-ins lie across it, on the side the wall's outward normal points to (the scrap); curves with a scrap key or several surfaces are not looked at",
            o.wall_axis_max_mm
        ));
        p
    };
    // Everything the caller was warned about, where the report goes: the input files' near-miss
    // keys (read without them) and the run's own warnings.
    let all_warnings: Vec<String> = job
        .input_warnings
        .iter()
        .map(|w| format!("input: {w}"))
        .chain(file.warnings.iter().map(|w| format!("curves file: {w}")))
        .chain(
            machine
                .warnings
                .iter()
                .map(|w| format!("machine file: {w}")),
        )
        .chain(warnings.iter().cloned())
        .collect();
    lap.split(&mut timings, "report");
    let report = Report {
        input: source_name,
        machine: machine.name.clone(),
        warnings: all_warnings,
        tolerance_budget_mm: crate::report::budget(&gopts),
        program: ProgramReport::of(dialect, &process, &motions, program_files.clone()),
        compensation: crate::cuts::compensation_report(file, kerf.as_ref(), &compensated),
        technology: technology_report(
            o.technology.as_ref(),
            &small_ids,
            o.dialect.commands_power(),
        ),
        micro_joints: o
            .micro_joints
            .map(|(length_mm, spacing_mm)| MicroJointsReport {
                length_mm,
                spacing_mm,
                paths: joints_report,
                left_out: joint_warnings,
            }),
        head: crate::head::head_report(o.cut_clearance_mm, machine, head_tip_zone, head_report),
        discretize: DiscretizeReport::of(file, &discs, &tp, dopts.tolerance_mm),
        normals: NormalsReport::of(file, &oriented),
        kinematics: KinematicsReport::of(&solved, tilt_report(&solved, popts.tilt_tolerance_deg)),
        placement: placement_report,
        process: crate::cuts::report(file, &cuts, &cut_plans),
        traverses: traverse_tally.report(topts.as_ref()),
        interpolation: InterpolationReport::of(
            &motions,
            &setup_ids,
            o.feed_mm_per_min,
            o.cycle_s,
            &gopts,
        ),
        seconds: start.elapsed().as_secs_f64(),
        timings,
    };
    let programs = SetupProgram::numbered(motions, programs, setup_ids);
    Ok(Output {
        discretizations: discs,
        oriented,
        toolpath: tp,
        placement: placed,
        solved,
        axes,
        programs,
        report,
        plot_svg: svg,
        scene: view,
        warnings,
        model,
        cycle_s: o.cycle_s,
    })
}

/// What the picture (`plot.svg`) shows of a run.
struct Picture<'a> {
    file: &'a kerf_format::CurvesFile,
    tp: &'a kerf_format::toolpath::ToolpathFile,
    axes: &'a AxesFile,
    machine: &'a kerf_kinematics::Machine,
    input_name: &'a str,
    cuts: &'a [crate::cuts::CutPath],
    placed: &'a crate::place::Placed,
    /// Per cut, its micro-joints (mm along the cut).
    joints: &'a [Vec<[f64; 2]>],
}

/// The picture: the paths and their axes, the process over them (pierces numbered in cutting
/// order, leads, micro-joints) and `traverses` (part coordinates), set-up by set-up as the
/// programs run them.
fn picture(p: &Picture<'_>, traverses: Vec<Vec<nalgebra::Point3<f64>>>) -> Result<String> {
    let mut scene = kerf_plot::Scene::new(p.file, p.tp, &kerf_plot::SceneOptions::default())?;
    scene.title = format!("kerf run \u{2014} {} on {}", p.input_name, p.machine.name);
    scene.axes = Some(kerf_plot::AxesChart::new(p.axes, Some(p.machine))?);
    // The process over the paths (part coordinates): pierces numbered in cutting order,
    // lead-ins, lead-outs and the traverses, set-up by set-up as the programs run them.
    let pt = |q: &kerf_process::PoseArray| nalgebra::Point3::new(q[0], q[1], q[2]);
    let mut order: Vec<usize> = (0..p.cuts.len()).collect();
    order.sort_by_key(|&k| p.placed.plan.setup_of(p.cuts[k].curve));
    scene.process = Some(kerf_plot::ProcessPicture {
        cuts: order
            .iter()
            .map(|&k| {
                let c = &p.cuts[k];
                let [m, n, _] = c.counts;
                kerf_plot::CutPicture {
                    id: p.file.curves[c.curve].id.clone(),
                    pierce: pt(&c.poses[0]),
                    lead_in: if m > 0 {
                        c.poses[..=m].iter().map(pt).collect()
                    } else {
                        Vec::new()
                    },
                    lead_out: if m + n < c.poses.len() {
                        c.poses[m + n - 1..].iter().map(pt).collect()
                    } else {
                        Vec::new()
                    },
                    micro_joints: {
                        let part: Vec<[f64; 3]> =
                            c.poses.iter().map(|q| [q[0], q[1], q[2]]).collect();
                        let at =
                            |s: f64| nalgebra::Point3::from(crate::cuts::point_along(&part, s));
                        p.joints[k].iter().map(|&[a, b]| [at(a), at(b)]).collect()
                    },
                }
            })
            .collect(),
        traverses,
    });
    let mut svg = kerf_plot::render(&scene);
    svg.shrink_to_fit();
    Ok(svg)
}

/// The power of a technology entry: its cutting power at its feed, following the tip's
/// speed down to its floor, and its pierce power (the cutting power without a pierce).
fn laser_power(t: &kerf_kinematics::TechnologyEntry) -> kerf_interp::LaserPower {
    kerf_interp::LaserPower::new(t.power_percent, t.feed_mm_per_min)
        .with_min_percent(t.power_min())
        .with_pierce_percent(t.pierce.map_or(t.power_percent, |p| p.power_percent))
}

/// The program header's lines on the technology entry (their text goes through the comment
/// sanitizer like every header line).
fn technology_header(t: Option<&kerf_kinematics::TechnologyEntry>) -> Vec<String> {
    let Some(t) = t else {
        return vec![
            "technology: none (feed from the run's feed_mm_per_min, process codes from the machine file)".into(),
        ];
    };
    let pierce = t.pierce.map_or(String::new(), |p| {
        format!(
            ": pierce {} s at {} mm and {} %",
            p.time_s, p.height_mm, p.power_percent
        )
    });
    let small = t.small_hole.map_or(String::new(), |h| {
        format!(
            "; holes up to {} mm at {} x feed and {} x power",
            h.max_diameter_mm, h.feed_factor, h.power_factor
        )
    });
    vec![
        format!(
            "technology: {}: feed {} mm/min, power {} % at that feed, following the tip speed down to {} %",
            t.label(),
            t.feed_mm_per_min,
            t.power_percent,
            t.power_min(),
        ),
        format!("technology: {}{pierce}{small}", t.label()),
    ]
}

/// The report's `technology` object: the entry used and the ids of the cuts its small-hole
/// rule slowed, or null.
fn technology_report(
    t: Option<&kerf_kinematics::TechnologyEntry>,
    small_holes: &[&str],
    commands_power: bool,
) -> Option<TechnologyReport> {
    let t = t?;
    let (power, holes) = if commands_power {
        ("its power is commanded following the tip speed (its power at its feed, down to power_min_percent), its pierce power at the pierce", "feed and power factors")
    } else {
        ("its power is not commanded (the dialect has no power word that acts with the motion: the program's header says why)", "feed factor")
    };
    Some(TechnologyReport {
        entry: t.label(),
        material: t.material.clone(),
        thickness_mm: t.thickness_mm,
        gas: t.gas.clone(),
        gas_pressure_bar: t.gas_pressure_bar,
        feed_mm_per_min: t.feed_mm_per_min,
        power_percent: t.power_percent,
        focus_mm: t.focus_mm,
        standoff_mm: t.standoff_mm,
        kerf_width_mm: t.kerf_width_mm,
        pierce: t.pierce,
        small_hole: t.small_hole,
        corner: t.corner,
        power_min_percent: t.power_min(),
        small_holes: small_holes.iter().map(|s| s.to_string()).collect(),
        note: format!("the entry's feed is the run's unless the run sets its own feed_mm_per_min; its pierce, standoff and kerf width replace the machine file's; {power}; holes within the small-hole rule run at its {holes}, corners within its corner rule at its feed factor; gas and focus are stated, not commanded"),
    })
}

/// How near a surface's boundary must come to another for the two to be one part, mm (CAD
/// edges meet within hundredths of a millimetre).
const PART_JOIN_TOLERANCE_MM: f64 = 0.05;

/// The least tilt the head check's tip zone allows for, degrees: a lead-in's or a blended
/// pose's axis may stand a little off the surface normal even without a tilt tolerance.
const HEAD_CHECK_MIN_TILT_DEG: f64 = 10.0;

/// What the tilt tolerance did (`kinematics.tilt` of the report): the tolerance, the largest
/// angle between a tool axis and its surface normal with the path and the place, and the
/// rotary travel `sum |d tilt| + |d C|` (degrees) of the exact normals and of the chosen axes,
/// in all and per path. `null` without a tolerance.
fn tilt_report(solved: &[kerf_kinematics::SolvedPath], tolerance_deg: f64) -> Option<TiltTotals> {
    if tolerance_deg <= 0.0 {
        return None;
    }
    let mut worst: Option<(f64, &str, [f64; 3])> = None;
    let mut paths = Vec::new();
    let (mut exact, mut chosen) = (0.0, 0.0);
    for s in solved {
        let Some(t) = s.tilt else { continue };
        // Where: the tip of the cutting point (lead-ins count: they are poses of the cut).
        let at = s
            .source
            .iter()
            .position(|v| *v == Some(t.max_deviation_at))
            .map_or([f64::NAN; 3], |j| {
                let p = s.poses[j].position;
                [p.x, p.y, p.z]
            });
        if worst.is_none_or(|w| t.max_deviation_deg > w.0) {
            worst = Some((t.max_deviation_deg, &s.id, at));
        }
        exact += t.rotary_travel_exact_deg;
        chosen += t.rotary_travel_deg;
        paths.push(TiltPath {
            id: s.id.clone(),
            max_deg: t.max_deviation_deg,
            at_mm: at,
            rotary_travel_exact_deg: t.rotary_travel_exact_deg,
            rotary_travel_deg: t.rotary_travel_deg,
            strings_over_budget: t.strings_over_budget,
        });
    }
    let (max_deg, max_path, max_at) = worst.map_or((0.0, None, None), |(d, id, at)| {
        (d, Some(id.to_owned()), Some(at))
    });
    Some(TiltTotals {
        tolerance_deg,
        max_deg,
        max_path,
        max_at_mm: max_at,
        rotary_travel_exact_deg: exact,
        rotary_travel_deg: chosen,
        paths,
    })
}
