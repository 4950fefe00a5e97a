//! The stages of one run ([`crate::Job::run`]), each a function with typed input and output,
//! in the order `run_placed` (`run.rs`) calls them: discretize, orient, place, plan the cuts,
//! solve the axes (micro-joints and the head check with them), then per set-up route the
//! traverses and plan and write the program. What every stage reads of the job is a
//! [`Run`]; each stage's result is a struct named by what it holds.

use std::path::Path;

use kerf_discretize::{Discretization, Options};
use kerf_format::toolpath::ToolpathFile;
use kerf_format::CurvesFile;
use kerf_interp::{
    gcode_motion, stations_from_solved, ChordTerm, FitOptions, GcodeOptions, MachineModel, Motion,
    PlanOptions,
};
use kerf_kinematics::{
    solve_paths, AxesFile, Head, Machine, PathCurve, PathInput, Pose, SmallHole, SolvedPath,
};
use kerf_normals::Oriented;
use nalgebra::Point3;

use crate::cuts::{Compensated, CutPath, Kerf, SetupPlans};
use crate::discretize::{discretize_curves_within, orient_curves, toolpath_of_poses};
use crate::error::{interp, kin, Result};
use crate::job::{Job, JobOptions};
use crate::place::Placed;
use crate::report::{
    DiscretizeReport, HeadPath, InterpolationReport, KinematicsReport, MicroJoint, MicroJointPath,
    MicroJointsReport, NormalsReport, ProgramReport, Report, TechnologyReport, TiltPath,
    TiltTotals,
};
use crate::timing::{Lap, Timings};
use crate::Progress;

use crate::head::PART_JOIN_TOLERANCE_MM;

/// The least tilt the head check's tip zone allows for, degrees: a lead-in's or a blended
/// pose's axis may stand a little off the surface normal even without a tilt tolerance.
const HEAD_CHECK_MIN_TILT_DEG: f64 = 10.0;

/// The stage times of a run: a lap split at the end of each stage.
pub(crate) struct Clock {
    lap: Lap,
    pub(crate) timings: Timings,
}

impl Clock {
    /// A clock started now, no stage timed yet.
    pub(crate) fn start() -> Self {
        Self {
            lap: Lap::start(),
            timings: Timings::default(),
        }
    }

    /// The time since the last split, as (part of) `stage`.
    pub(crate) fn split(&mut self, stage: &'static str) {
        self.lap.split(&mut self.timings, stage);
    }
}

/// What every stage reads of the job, and what the options decide once.
pub(crate) struct Run<'a> {
    pub(crate) job: &'a Job,
    pub(crate) path: Option<&'a Path>,
    pub(crate) file: &'a CurvesFile,
    pub(crate) machine: &'a Machine,
    pub(crate) o: &'a JobOptions,
    pub(crate) progress: &'a (dyn Fn(Progress) + Sync),
    /// The kerf compensation (the run's width, the technology entry's or the machine's).
    pub(crate) kerf: Option<Kerf>,
    /// The program's fit, which follows from the dialect (the head check needs its
    /// orientation tolerance, the interpolation the rest).
    pub(crate) fit: FitOptions,
    /// The machine's head (or kerf's default): the head check's and the 3D view's.
    pub(crate) head: Head,
    /// The nozzle's standoff above the tip, mm.
    pub(crate) head_standoff_mm: f64,
    /// Checked traverses (`None`: the unchecked retract); never a shorter retract than asked.
    pub(crate) traverse: Option<kerf_process::TraverseOptions>,
}

impl<'a> Run<'a> {
    /// The run of `job`, its options checked; a dialect that cannot program the machine, or
    /// the controller's compensation asked of a dialect without it, is refused before any
    /// work.
    ///
    /// # Errors
    /// The job's invalid option, or the dialect's refusal.
    pub(crate) fn new(job: &'a Job, progress: &'a (dyn Fn(Progress) + Sync)) -> Result<Self> {
        let path = job.source.as_deref();
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
            .map(|(width_mm, source)| Kerf {
                width_mm,
                source,
                tolerance_mm: dopts.tolerance_mm,
                in_control: o.kerf_in_control,
                dialect: o.dialect,
            });
        MachineModel::new(machine.clone())
            .and_then(|m| o.dialect.check_machine(&m))
            .map_err(interp(path))?;
        if kerf.as_ref().is_some_and(|k| k.in_control) && !o.dialect.controller_compensation() {
            return Err(crate::Error::BadOption {
                name: "kerf_in_control",
                value: 1.0,
                requirement: format!(
                    "the controller's kerf compensation is written for the linuxcnc (G41.1/G42.1) and sinumerik (CUT3DC with G41/G42) dialects only, not {}; compensate in the computer instead",
                    o.dialect.name()
                ),
            });
        }
        Ok(Self {
            job,
            path,
            file: &job.curves,
            machine,
            o,
            progress,
            kerf,
            fit: crate::motion::fit_options(dopts.tolerance_mm, Some(o.dialect), o.retract_mm),
            head: machine.head.clone().unwrap_or_else(Head::laser_default),
            head_standoff_mm: machine
                .process
                .standoff_mm
                .unwrap_or(kerf_kinematics::DEFAULT_STANDOFF_MM),
            traverse: o.checked_traverse(),
        })
    }

    /// A process error of this run's file.
    fn process_error(&self, source: kerf_process::ProcessError) -> crate::Error {
        crate::Error::Process {
            file: self.path.map(Path::to_path_buf),
            source,
        }
    }
}

/// Stage 1: the cutting points.
pub(crate) struct Points {
    /// Per curve, its certified discretization.
    pub(crate) discs: Vec<Discretization>,
    /// Per curve, where a closed cut starts when the file pins it or only corners offer it.
    pub(crate) starts: Vec<Option<f64>>,
    /// The options the contours were discretized with (a share of the tolerance with a kerf).
    pub(crate) contour_opts: Options,
}

/// Stage 1: cutting points with a certified chord error. With a kerf, the contour's chords
/// take 9/10 of the tolerance and the offset's own term the rest (docs/process.md, "Kerf
/// compensation"): a hole's offset chords then need no more points. In the controller too: it
/// offsets the same cutting points, so that its path and kerf's own offset agree
/// (tests/linuxcnc). Then where closed cuts start when the file pins it (`start`) or only
/// corners offer it (a polygon: the middle of its longest edge), made a (certified) cutting
/// point.
pub(crate) fn discretize(r: &Run<'_>) -> Result<Points> {
    let dopts = r.o.discretize;
    let contour_opts = match &r.kerf {
        Some(_) => dopts.with_tolerance_mm(dopts.tolerance_mm * crate::cuts::KERF_CONTOUR_SHARE),
        None => dopts,
    };
    let mut discs = discretize_curves_within(
        r.file,
        &contour_opts,
        r.o.max_total_points,
        r.path,
        r.progress,
    )?;
    let starts = discs
        .iter_mut()
        .zip(&r.file.curves)
        .map(|(d, c)| {
            kerf_process::prepare_start(&c.curve, d, c.start, &r.o.leads, contour_opts.tolerance_mm)
        })
        .collect();
    Ok(Points {
        discs,
        starts,
        contour_opts,
    })
}

/// Stage 2: the normals.
pub(crate) struct Normals {
    /// Per curve, its points with their normals.
    pub(crate) oriented: Vec<Oriented>,
    /// The `kerf.toolpath/1` document of the oriented points.
    pub(crate) toolpath: ToolpathFile,
    /// Curves taken within their own tolerance (a CAD edge on its face within its file's),
    /// beyond the run's: each named with both.
    pub(crate) warnings: Vec<String>,
}

/// Stage 2: normals (+z for curves that name no surface, unless the options refuse them).
pub(crate) fn orient(r: &Run<'_>, points: &Points) -> Result<Normals> {
    let oriented = orient_curves(
        r.file,
        &points.discs,
        &points.contour_opts,
        &r.o.orient,
        r.path,
        r.progress,
    )?;
    let toolpath = toolpath_of_poses(r.file, r.o.discretize.tolerance_mm, &oriented);
    let warnings = crate::discretize::beyond_run_tolerance(
        r.file,
        &oriented,
        r.o.orient.normals.on_surface_tolerance_mm,
    );
    Ok(Normals {
        oriented,
        toolpath,
        warnings,
    })
}

/// Stage 3a and 3b: the part on the machine.
pub(crate) struct Part {
    /// Per curve, the wall through the sheet it is cut along, if it is.
    pub(crate) walls: Vec<Option<kerf_process::Wall>>,
    /// Where each path goes and from which side it is cut.
    pub(crate) placed: Placed,
    /// The margin the placement kept from the linear limits, mm.
    pub(crate) margin_mm: f64,
}

/// Stages 3a and 3b. Contours on a thin wall through the sheet (a hole's wall named instead of
/// the sheet's face) get the beam along the wall, the scrap where the wall's normal points.
/// Which side of the sheet each contour is cut from, where kerf chooses (`--place auto`,
/// checked traverses): the side from which the nozzle's line along the tool axis does not meet
/// the part, reach permitting (the placement checks it). Then where the part goes on the
/// machine; from here on, workpiece coordinates. The search keeps the longest move off the cut
/// along the tool axis (the retract or the pierce standoff) and 1 mm of blending, and
/// `extra_margin_mm`, from every linear limit.
pub(crate) fn place(
    r: &Run<'_>,
    normals: &Normals,
    extra_margin_mm: f64,
    clock: &mut Clock,
) -> Result<Part> {
    (r.progress)(Progress::new(crate::Stage::Kinematics, 0, 1));
    let (file, o) = (r.file, r.o);
    let walls = crate::cuts::walls(file, &normals.oriented, o.wall_axis_max_mm);
    let poses: Vec<Vec<Pose>> = normals
        .oriented
        .iter()
        .zip(&walls)
        .map(|(o, w)| match w {
            Some(w) => w.poses.clone(),
            None => o.poses(),
        })
        .collect();
    let head_lines = match (o.place, &r.traverse) {
        (crate::PlaceMode::Auto, Some(t)) => {
            Some(crate::place::sides_by_head_lines(file, &poses, t, r.path)?)
        }
        _ => None,
    };
    clock.split("sides");
    let standoff = r.machine.process.pierce_standoff.unwrap_or(0.0);
    let margin_mm = o.retract_mm.max(standoff).max(0.0) + 1.0 + extra_margin_mm;
    let ids: Vec<&str> = file.curves.iter().map(|c| c.id.as_str()).collect();
    let placed = crate::place::place(
        r.machine,
        &ids,
        head_lines.as_ref().map_or(&poses, |(_, turned)| turned),
        o.place,
        &kerf_kinematics::AutoPlaceOptions::default()
            .with_path_options(o.path)
            .with_margin_mm(margin_mm)
            // A thick sheet's contours are never turned over (the import put each on the
            // side that faces up): with any in the file, the placement turns none.
            .with_flip(!file.curves.iter().any(|c| c.sheet_thickness_mm.is_some())),
        r.path,
    )?;
    let placed = match head_lines {
        Some((h, _)) => placed.with_head_lines(h),
        None => placed,
    };
    clock.split("place");
    Ok(Part {
        walls,
        placed,
        margin_mm,
    })
}

/// Stage 3c: the cuts.
pub(crate) struct Cuts {
    /// Every cut, in cutting order within each set-up, in part coordinates.
    pub(crate) cuts: Vec<CutPath>,
    /// The plan of each set-up.
    pub(crate) plans: SetupPlans,
    /// What the kerf compensation did to each path.
    pub(crate) compensated: Vec<Compensated>,
}

/// Stage 3c: the cuts: start points, lead-ins and lead-outs on the scrap side, holes before
/// their outlines, the shortest traverse; in part coordinates.
pub(crate) fn plan_cuts(
    r: &Run<'_>,
    points: &Points,
    normals: &Normals,
    part: &Part,
) -> Result<Cuts> {
    let (cuts, plans, compensated) = crate::cuts::plan(
        r.file,
        &normals.oriented,
        &part.walls,
        &part.placed,
        &points.starts,
        &r.o.leads,
        r.kerf.as_ref(),
        r.path,
    )?;
    Ok(Cuts {
        cuts,
        plans,
        compensated,
    })
}

/// The offset paths into the toolpath (`kerf_offset`), where `kerf check` measures them.
pub(crate) fn record_offsets(toolpath: &mut ToolpathFile, compensated: &[Compensated]) {
    for c in compensated {
        if let crate::cuts::Outcome::Offset(p) = &c.outcome {
            toolpath.paths[c.curve].kerf_offset = Some(crate::cuts::kerf_offset_record(p));
        }
    }
}

/// Each cut's exact point function, placed (workpiece coordinates).
pub(crate) type PlacedCurve<'a> = Box<dyn kerf_nurbs::CurvePoint + Sync + 'a>;

/// The placed point function of every cut.
pub(crate) fn placed_curves<'a>(cuts: &'a [CutPath], placed: &Placed) -> Vec<PlacedCurve<'a>> {
    cuts.iter()
        .map(|c| {
            let placement = placed.placement_of(c.curve);
            let f = &c.point;
            Box::new(move |u| placement.apply_point(&f.point_at(u))) as PlacedCurve<'a>
        })
        .collect()
}

/// Stage 3d: the machine axes and what was decided with them.
pub(crate) struct Solved {
    /// Every cut solved, in the order of the cuts.
    pub(crate) solved: Vec<SolvedPath>,
    /// Per cut, its micro-joints (start and end along the cut from the lead-in's start, mm).
    pub(crate) joints: Vec<Vec<[f64; 2]>>,
    /// The report's micro-joints per contour.
    pub(crate) joints_report: Vec<MicroJointPath>,
    /// The joints no place was found for.
    pub(crate) joint_warnings: Vec<String>,
    /// The head check's report per path.
    pub(crate) head_report: Vec<HeadPath>,
    /// The head check's collisions accepted as warnings.
    pub(crate) head_warnings: Vec<String>,
    /// The tip zone the head check left out, mm.
    pub(crate) head_tip_zone_mm: Option<f64>,
    /// Per cut, where the picture marks what the head check did (empty without it).
    pub(crate) head_marks: Vec<crate::head::HeadMarks>,
    /// Per set-up, every surface of the file placed with it and the part of each, as the head
    /// check built them (the traverses' head check takes them again); empty without it, `None`
    /// for a set-up without cuts.
    pub(crate) head_surfaces: Vec<Option<(kerf_process::Obstacles, Vec<usize>)>>,
}

/// Stage 3d: the cuts placed, micro-joints where the beam leaves each part's outline (and big
/// cut-outs) uncut, the machine axes (points inserted on the curve against the non-linearity
/// error), then the head against every surface of the file along every cut, set-up by set-up,
/// the tool axis tilted within the tilt tolerance where it comes too close.
pub(crate) fn solve(r: &Run<'_>, cuts: &Cuts, part: &Part, clock: &mut Clock) -> Result<Solved> {
    let (file, placed) = (r.file, &part.placed);
    let cut_poses: Vec<Vec<Pose>> = cuts
        .cuts
        .iter()
        .map(|c| placed.apply_one(c.curve, &c.poses))
        .collect();
    let points = placed_curves(&cuts.cuts, placed);
    let inputs: Vec<PathInput<'_>> = cuts
        .cuts
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
    clock.split("cuts");
    let (joints, joint_warnings) = match r.o.micro_joints {
        Some((length, spacing)) => {
            crate::cuts::micro_joints(file, &cuts.cuts, &cuts.plans, length, spacing)
        }
        None => (vec![Vec::new(); cuts.cuts.len()], Vec::new()),
    };
    let joints_report = micro_joints_report(file, &cuts.cuts, &cut_poses, &joints);
    let mut solved = solve_paths(r.machine, &inputs, &r.o.path).map_err(kin(r.path))?;
    clock.split("kinematics");
    let mut out = Solved {
        solved: Vec::new(),
        joints,
        joints_report,
        joint_warnings,
        head_report: Vec::new(),
        head_warnings: Vec::new(),
        head_tip_zone_mm: None,
        head_marks: vec![crate::head::HeadMarks::default(); cuts.cuts.len()],
        head_surfaces: Vec::new(),
    };
    if let Some(clearance) = r.o.cut_clearance_mm {
        check_heads(
            r,
            clearance,
            &cuts.cuts,
            placed,
            &inputs,
            &mut solved,
            &mut out,
        )?;
        clock.split("head");
    }
    out.solved = solved;
    Ok(out)
}

/// The report's micro-joints: per contour with joints, each joint's ends along the cut and
/// as tip points of the placed cut.
fn micro_joints_report(
    file: &CurvesFile,
    cuts: &[CutPath],
    cut_poses: &[Vec<Pose>],
    joints: &[Vec<[f64; 2]>],
) -> Vec<MicroJointPath> {
    cuts.iter()
        .zip(joints)
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
        .collect()
}

/// The head check's options at `clearance` mm: the machine's standoff, the run's tilt
/// tolerance (at least [`HEAD_CHECK_MIN_TILT_DEG`] for the tip zone), the controller's path
/// deviation and, where the program's blocks merge poses, the fit's orientation tolerance.
fn head_options(r: &Run<'_>, clearance: f64) -> kerf_process::HeadCheckOptions {
    let (o, popts) = (r.o, &r.o.path);
    kerf_process::HeadCheckOptions::default()
        .with_clearance_mm(clearance)
        .with_standoff_mm(r.head_standoff_mm)
        .with_max_tilt_deg(popts.tilt_tolerance_deg.max(HEAD_CHECK_MIN_TILT_DEG))
        // The controller's tip leaves the chords by the non-linearity error and its blending
        // (an infinite tolerance leaves the check unproven).
        .with_path_deviation_mm(popts.linearization_tolerance_mm + o.blend_tolerance_mm)
        // Where the program's blocks merge poses (lines and arcs over several), each pose's
        // axis is held within the fit's orientation tolerance only.
        .with_axis_deviation_deg(if r.fit.merge_lines || r.fit.arcs {
            r.fit.orientation_tolerance_deg
        } else {
            0.0
        })
}

/// The head check of every set-up at `clearance` mm ([`crate::head::check_and_clear`]): each
/// cut against the part it lies on, the surfaces its curve names and every surface joined to
/// those (a wall beside a hole), not another part the file holds.
///
/// # Errors
/// The first path that could not be cleared, unless the options accept it.
fn check_heads(
    r: &Run<'_>,
    clearance: f64,
    cuts: &[CutPath],
    placed: &Placed,
    inputs: &[PathInput<'_>],
    solved: &mut [SolvedPath],
    out: &mut Solved,
) -> Result<()> {
    let (file, o, popts) = (r.file, r.o, &r.o.path);
    let hopts = head_options(r, clearance);
    out.head_surfaces = (0..placed.plan.setups.len()).map(|_| None).collect();
    for setup in 0..placed.plan.setups.len() {
        let ks: Vec<usize> = (0..solved.len())
            .filter(|&k| placed.plan.setup_of(cuts[k].curve) == setup)
            .collect();
        let Some(&first) = ks.first() else { continue };
        let placement = placed.placement_of(cuts[first].curve);
        let all = kerf_process::Obstacles::from_all_surfaces(file, |p| placement.apply_point(p))
            .map_err(|e| r.process_error(e))?;
        let parts = all.parts(PART_JOIN_TOLERANCE_MM);
        let h = crate::head::check_and_clear(
            r.machine,
            |k| all.of_parts(&parts, &file.curves[cuts[k].curve].surfaces),
            &r.head,
            &hopts,
            popts,
            inputs,
            &ks,
            solved,
            o.accept_head_collisions,
        );
        out.head_report.extend(h.report);
        out.head_warnings.extend(h.warnings);
        out.head_tip_zone_mm = h.tip_zone_mm.or(out.head_tip_zone_mm);
        for (k, m) in h.marks {
            out.head_marks[k] = m;
        }
        if let Some(source) = h.refusal {
            return Err(r.process_error(source));
        }
        out.head_surfaces[setup] = Some((all, parts));
    }
    Ok(())
}

/// Stage 4: the programs.
pub(crate) struct Programs {
    /// The machine's model the motion was planned on.
    pub(crate) model: MachineModel,
    /// The G-code options every set-up's program shares.
    pub(crate) gcode: GcodeOptions,
    /// The axes document, lead-ins, lead-outs and checked traverses apart.
    pub(crate) axes: AxesFile,
    /// Per set-up, the planned motion.
    pub(crate) motions: Vec<Motion>,
    /// Per set-up, the program's text.
    pub(crate) texts: Vec<String>,
    /// Per set-up, the ids of its paths in cutting order.
    pub(crate) setup_ids: Vec<Vec<String>>,
    /// What the traverses came to.
    pub(crate) traverses: crate::traverses::Tally,
    /// The traverses for the picture, part coordinates.
    pub(crate) plot_traverses: Vec<Vec<Point3<f64>>>,
    /// The ids of the cuts a technology's small-hole rule slowed.
    pub(crate) small_ids: Vec<String>,
    /// The run's warnings so far, in order.
    pub(crate) warnings: Vec<String>,
}

/// What every set-up's program is made from: the run's cuts, their axes and the options and
/// per-cut decisions all set-ups share ([`setup_program`] takes one set-up's paths of them).
struct SetupShared<'a> {
    r: &'a Run<'a>,
    cuts: &'a Cuts,
    placed: &'a Placed,
    solved: &'a Solved,
    model: &'a MachineModel,
    plan: &'a PlanOptions,
    gcode: &'a GcodeOptions,
    /// Per cut, the controller's compensation.
    in_control: &'a [Option<kerf_interp::CutterCompensation>],
    /// The small-hole rule and, per cut, whether it applies.
    small: Option<&'a (SmallHole, Vec<bool>)>,
    /// Each cut's placed point function.
    points: &'a [PlacedCurve<'a>],
}

/// Stage 4: the controller's compensation per path (LinuxCNC's G41.1/G42.1 where the beam
/// stands vertical and still along the whole cut, Sinumerik's CUT3DC at any orientation), the
/// axes document, then per set-up the checked traverses, the fit, the feed plan and the
/// G-code.
pub(crate) fn programs(
    r: &Run<'_>,
    cuts: &Cuts,
    part: &Part,
    solved: &Solved,
    normals: &Normals,
    clock: &mut Clock,
) -> Result<Programs> {
    let (file, o, path, placed) = (r.file, r.o, r.path, &part.placed);
    let in_control = crate::cuts::controller_compensation(
        file,
        r.kerf.as_ref(),
        &cuts.compensated,
        &cuts.cuts,
        &solved.solved,
    )
    .map_err(|e| r.process_error(e))?;
    let mut axes = AxesFile::new(r.machine, &solved.solved);
    crate::cuts::split_axes(&mut axes, &cuts.cuts, &solved.solved);
    (r.progress)(Progress::new(crate::Stage::Interpolate, 0, 1));
    let model = MachineModel::new(r.machine.clone()).map_err(interp(path))?;
    let mut plan = PlanOptions::new(o.feed_mm_per_min, o.cycle_s);
    plan.blend_tolerance_mm = o.blend_tolerance_mm; // the planner's blend and the controller's
    let source_name = path.map(|p| p.display().to_string());
    let tolerance_mm = o.discretize.tolerance_mm;
    let gcode = crate::motion::gcode_options(
        &model,
        o.dialect,
        o.feed_mm_per_min,
        o.blend_tolerance_mm,
        source_name.as_deref(),
    )
    .with_fit_tolerance_mm(tolerance_mm)
    // Every segment was certified within the tolerance by the discretizer (and re-certified
    // where the normals or the start point inserted points).
    .with_chord_term(ChordTerm::Certified(tolerance_mm))
    .with_chord_tolerance_mm(plan.chord_tolerance_mm)
    .with_linearization_tolerance_mm(Some(o.path.linearization_tolerance_mm))
    .with_power(o.technology.as_ref().map(laser_power));
    // The technology's small-hole rule: which cuts run at its feed and power factors.
    let small = o.technology.as_ref().and_then(|t| t.small_hole).map(|h| {
        (
            h,
            crate::cuts::small_holes(&cuts.cuts, &cuts.plans, h.max_diameter_mm),
        )
    });
    let small_ids: Vec<String> = small.as_ref().map_or(Vec::new(), |(_, holes)| {
        cuts.cuts
            .iter()
            .zip(holes)
            .filter(|(_, &h)| h)
            .map(|(c, _)| file.curves[c.curve].id.clone())
            .collect()
    });
    let mut warnings: Vec<String> = normals.warnings.clone();
    warnings.extend(solved.head_warnings.iter().cloned());
    warnings.extend(solved.joint_warnings.iter().cloned());
    warnings.extend(uncompensated_warning(file, &cuts.compensated));
    clock.split("kinematics");
    let points = placed_curves(&cuts.cuts, placed);
    let shared = SetupShared {
        r,
        cuts,
        placed,
        solved,
        model: &model,
        plan: &plan,
        gcode: &gcode,
        in_control: &in_control,
        small: small.as_ref(),
        points: &points,
    };
    let mut out = Programs {
        model: model.clone(),
        gcode: gcode.clone(),
        axes,
        motions: Vec::new(),
        texts: Vec::new(),
        setup_ids: Vec::new(),
        traverses: crate::traverses::Tally::default(),
        plot_traverses: Vec::new(),
        small_ids,
        warnings,
    };
    for setup in 0..placed.plan.setups.len() {
        setup_program(&shared, setup, &mut out, clock)?;
    }
    Ok(out)
}

/// One warning naming the contours that are cut on the contour because their scrap side is
/// not known, if there are any.
fn uncompensated_warning(file: &CurvesFile, compensated: &[Compensated]) -> Option<String> {
    let uncompensated: Vec<&str> = compensated
        .iter()
        .filter(|c| !c.outcome.is_compensated())
        .map(|c| file.curves[c.curve].id.as_str())
        .collect();
    if uncompensated.is_empty() {
        return None;
    }
    let shown: Vec<String> = uncompensated
        .iter()
        .take(5)
        .map(|id| format!("{id:?}"))
        .collect();
    Some(format!(
        "{} contours without a `scrap` key whose scrap side is not known (open, or a loop round a tube) are cut on the contour, not kerf-compensated: {}{} (report: compensation.paths)",
        uncompensated.len(),
        shown.join(", "),
        if uncompensated.len() > 5 { ", ..." } else { "" }
    ))
}

/// The program of one set-up: its traverses routed and checked (stage 3e), its paths' blocks
/// fitted (the stations dropped once each path's blocks are made), linked through the
/// traverses, the feed planned and the G-code written into `out`.
fn setup_program(
    s: &SetupShared<'_>,
    setup: usize,
    out: &mut Programs,
    clock: &mut Clock,
) -> Result<()> {
    let (r, cuts, placed) = (s.r, &s.cuts.cuts, s.placed);
    let (o, path, solved) = (r.o, r.path, &s.solved.solved);
    let in_setup: Vec<usize> = (0..solved.len())
        .filter(|&k| placed.plan.setup_of(cuts[k].curve) == setup)
        .collect();
    let routed = crate::traverses::route_setup(
        &crate::traverses::SetupCuts {
            file: r.file,
            path,
            placed,
            cuts,
            solved,
            setup,
            in_setup: &in_setup,
        },
        r.machine,
        r.traverse.as_ref(),
        o.cut_clearance_mm
            .zip(s.solved.head_surfaces.get(setup).and_then(Option::as_ref))
            .map(|(c, (obstacles, parts))| crate::traverses::HeadAlong {
                head: &r.head,
                // The traverses' rapids are one block per waypoint (no merged axes).
                opts: head_options(r, c).with_axis_deviation_deg(0.0),
                accept: o.accept_head_collisions,
                obstacles,
                parts,
            })
            .as_ref(),
        o.retract_mm,
        &mut out.axes,
        &mut out.traverses,
    )?;
    out.warnings.extend(routed.warnings);
    out.plot_traverses.extend(routed.plot);
    let traverses = routed.stations;
    clock.split("traverses");
    let mut fitted = Vec::new();
    let mut comps: Vec<Option<kerf_interp::CutterCompensation>> = Vec::new();
    let mut feed_factors: Vec<f64> = Vec::new();
    let mut power_factors: Vec<f64> = Vec::new();
    let mut path_joints: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut ids: Vec<String> = Vec::new();
    for &k in &in_setup {
        let sp = &solved[k];
        let curve: &dyn kerf_nurbs::CurvePoint = s.points[k].as_ref();
        // What `kerf_interp::interpolate_through` does, path by path.
        let stations = stations_from_solved(sp, Some(&cuts[k].params)).map_err(interp(path))?;
        fitted.push(
            kerf_interp::fit_blocks(s.model, &stations, Some(curve), fitted.len(), &r.fit)
                .map_err(interp(path))?,
        );
        ids.push(sp.id.clone());
        comps.push(s.in_control[k]);
        let (feed_factor, power_factor) = match s.small {
            Some((h, holes)) if holes[k] => (h.feed_factor, h.power_factor),
            _ => (1.0, 1.0),
        };
        feed_factors.push(feed_factor);
        power_factors.push(power_factor);
        path_joints.push(s.solved.joints[k].clone());
    }
    let blocks = kerf_interp::link_paths_through(s.model, fitted, &traverses, r.fit.retract_mm);
    drop(traverses);
    let plan = s
        .plan
        .clone()
        .with_feed_factors(feed_factors)
        .with_corner_slowdown(o.technology.as_ref().and_then(|t| t.corner).map(|c| {
            kerf_interp::CornerSlowdown {
                min_turn_deg: c.min_turn_deg,
                length_mm: c.length_mm,
                feed_factor: c.feed_factor,
            }
        }));
    let motion = kerf_interp::plan_owned(s.model, blocks, &plan).map_err(interp(path))?;
    clock.split("plan");
    let mut gcode = s
        .gcode
        .clone()
        .with_cutter_compensation(comps)
        .with_power_factors(power_factors)
        .with_micro_joints(path_joints);
    gcode.header = vec![
        format!(
            "set-up {} of {}: {} contours; placement (part to workpiece): {}",
            setup + 1,
            placed.plan.setups.len(),
            ids.len(),
            placed.plan.setups[setup].placement
        ),
        "work offset: none; every coordinate is in the machine's workpiece frame with the placement applied: clamp the part there".to_string(),
        crate::cuts::kerf_header(r.kerf.as_ref(), &s.cuts.compensated),
    ];
    gcode
        .header
        .extend(technology_header(o.technology.as_ref()));
    let mut text = gcode_motion(s.model, &motion, &ids, &gcode).map_err(interp(path))?;
    text.shrink_to_fit();
    out.texts.push(text);
    out.setup_ids.push(ids);
    out.motions.push(motion);
    clock.split("gcode");
    Ok(())
}

/// The input's name in the view and the picture: the file's name, `curves` for a job built
/// in code.
fn input_name(path: Option<&Path>) -> String {
    path.map_or_else(
        || "curves".to_string(),
        |path| {
            path.file_name().map_or_else(
                || path.display().to_string(),
                |n| n.to_string_lossy().into_owned(),
            )
        },
    )
}

/// Stage 5: the 3D view, the picture and the report, and every stage's result as the
/// [`crate::Output`].
pub(crate) fn output(
    r: &Run<'_>,
    (points, normals, part, cuts, solved, programs): (
        Points,
        Normals,
        Part,
        Cuts,
        Solved,
        Programs,
    ),
    attempt: usize,
    started: std::time::Instant,
    mut clock: Clock,
) -> Result<crate::Output> {
    let (file, o, path, machine) = (r.file, r.o, r.path, r.machine);
    let placed = &part.placed;
    let process =
        kerf_interp::ProcessCodes::resolve(o.dialect, &machine.process).map_err(interp(path))?;
    (r.progress)(Progress::new(crate::Stage::Report, 0, 1));
    let input_name = input_name(path);
    let program_files = crate::output::program_names(programs.motions.len());
    let view = view_scene(
        r,
        placed,
        &cuts.cuts,
        &programs,
        &input_name,
        &program_files,
        process.pierce_standoff,
    );
    clock.split("view");
    let svg = picture(
        &Picture {
            file,
            tp: &normals.toolpath,
            axes: &programs.axes,
            machine,
            input_name: &input_name,
            cuts: &cuts.cuts,
            placed,
            joints: &solved.joints,
            head_marks: &solved.head_marks,
        },
        programs.plot_traverses,
    )?;
    let placement = placement_report(r, &part, attempt);
    let all_warnings = all_warnings(r, &programs.warnings);
    clock.split("report");
    let report = Report {
        input: path.map(|p| p.display().to_string()),
        machine: machine.name.clone(),
        warnings: all_warnings,
        tolerance_budget_mm: crate::report::budget(&programs.gcode),
        program: ProgramReport::of(o.dialect, &process, &programs.motions, program_files),
        compensation: crate::cuts::compensation_report(file, r.kerf.as_ref(), &cuts.compensated),
        technology: technology_report(
            o.technology.as_ref(),
            programs.small_ids,
            o.dialect.commands_power(),
        ),
        micro_joints: o
            .micro_joints
            .map(|(length_mm, spacing_mm)| MicroJointsReport {
                length_mm,
                spacing_mm,
                paths: solved.joints_report,
                left_out: solved.joint_warnings,
            }),
        head: crate::head::head_report(
            o.cut_clearance_mm,
            machine,
            solved.head_tip_zone_mm,
            solved.head_report,
        ),
        discretize: DiscretizeReport::of(
            file,
            &points.discs,
            &normals.toolpath,
            o.discretize.tolerance_mm,
        ),
        normals: NormalsReport::of(file, &normals.oriented),
        kinematics: KinematicsReport::of(
            &solved.solved,
            tilt_report(&solved.solved, o.path.tilt_tolerance_deg),
        ),
        placement,
        process: crate::cuts::report(file, &cuts.cuts, &cuts.plans),
        traverses: programs.traverses.report(r.traverse.as_ref()),
        interpolation: InterpolationReport::of(
            &programs.motions,
            &programs.setup_ids,
            o.feed_mm_per_min,
            o.cycle_s,
            &programs.gcode,
        ),
        seconds: started.elapsed().as_secs_f64(),
        timings: clock.timings,
    };
    Ok(crate::Output {
        discretizations: points.discs,
        oriented: normals.oriented,
        toolpath: normals.toolpath,
        placement: part.placed,
        solved: solved.solved,
        axes: programs.axes,
        programs: crate::output::SetupProgram::numbered(
            programs.motions,
            programs.texts,
            programs.setup_ids,
        ),
        report,
        plot_svg: svg,
        scene: view,
        warnings: programs.warnings,
        model: programs.model,
        cycle_s: o.cycle_s,
    })
}

/// The report's `placement`: the placement's own, with the walls, and with `--place auto` the
/// margin the search kept and how many searches it took (`attempt` + 1).
fn placement_report(r: &Run<'_>, part: &Part, attempt: usize) -> crate::report::PlacementReport {
    let (file, o, placed) = (r.file, r.o, &part.placed);
    let ids: Vec<&str> = file.curves.iter().map(|c| c.id.as_str()).collect();
    let mut placement = placed.report(&ids);
    placement.walls = Some(crate::cuts::walls_report(file, &part.walls));
    if placed.auto {
        // The margin the search kept from the linear limits, and how many searches it took
        // for every move of the program to stay within the travel.
        placement.margin_mm = Some(part.margin_mm);
        placement.searches = Some(attempt + 1);
    }
    placement.walls_note = Some(format!(
        "contours whose only named surface is a wall at most {} mm wide across them (its control net's extent along n x t, the wall's direction across the contour; 0 = off): a hole's or slot's wall, the sheet's edge face, named instead of the sheet's face. The beam runs along the wall (side 'given' is the head on the face of the sheet that holds the contour, away from the wall), the lead-ins lie across it, on the side the wall's outward normal points to (the scrap); curves with a scrap key or several surfaces are not looked at",
        o.wall_axis_max_mm
    ));
    placement
}

/// Everything the caller was warned about, where the report goes: the input files' near-miss
/// keys (read without them) and the run's own `warnings`.
fn all_warnings(r: &Run<'_>, warnings: &[String]) -> Vec<String> {
    let (file, machine) = (r.file, r.machine);
    r.job
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
        .collect()
}

/// The 3D view's scene: the part, the cuts and every set-up's motion with its program's name.
fn view_scene(
    r: &Run<'_>,
    placed: &Placed,
    cuts: &[CutPath],
    programs: &Programs,
    input_name: &str,
    program_files: &[String],
    pierce_standoff_mm: f64,
) -> kerf_view::Scene {
    let (file, o) = (r.file, r.o);
    let view_setups: Vec<crate::view::SetupInput<'_>> = programs
        .motions
        .iter()
        .enumerate()
        .map(|(k, m)| crate::view::SetupInput {
            placement: placed
                .plan
                .setups
                .get(k)
                .map_or(kerf_kinematics::Placement::IDENTITY, |s| s.placement),
            motion: m,
            ids: &programs.setup_ids[k],
            program: &program_files[k],
        })
        .collect();
    crate::view::scene(
        input_name,
        file,
        cuts,
        &view_setups,
        &programs.model,
        &r.head,
        r.head_standoff_mm,
        o.feed_mm_per_min,
        pierce_standoff_mm,
    )
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
    /// Per cut, what the head check tilted and found close.
    head_marks: &'a [crate::head::HeadMarks],
}

/// The polylines through `poses` (part coordinates) of the ranges `[first, last]`, each
/// widened by a cutting point on either side where it has one (a single point is a segment).
fn marked(poses: &[Pose], ranges: &[[usize; 2]]) -> Vec<Vec<nalgebra::Point3<f64>>> {
    ranges
        .iter()
        .filter(|[a, _]| *a < poses.len())
        .map(|&[a, b]| {
            let hi = (b + 1).min(poses.len() - 1);
            poses[a.saturating_sub(1)..=hi]
                .iter()
                .map(|q| q.position)
                .collect()
        })
        .collect()
}

/// The picture: the paths and their axes, the process over them (pierces numbered in cutting
/// order, leads, micro-joints, what the head check tilted or found close) and `traverses`
/// (part coordinates), set-up by set-up as the programs run them.
fn picture(p: &Picture<'_>, traverses: Vec<Vec<nalgebra::Point3<f64>>>) -> Result<String> {
    let mut scene = kerf_plot::Scene::new(p.file, p.tp, &kerf_plot::SceneOptions::default())?;
    scene.title = format!("kerf run \u{2014} {} on {}", p.input_name, p.machine.name);
    scene.axes = Some(kerf_plot::AxesChart::new(p.axes, Some(p.machine))?);
    // The process over the paths (part coordinates): pierces numbered in cutting order,
    // lead-ins, lead-outs and the traverses, set-up by set-up as the programs run them.
    let pt = |q: &Pose| q.position;
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
                    head_tilted: marked(&c.poses, &p.head_marks[k].tilted),
                    head_close: marked(&c.poses, &p.head_marks[k].close),
                    micro_joints: {
                        let part: Vec<[f64; 3]> =
                            c.poses.iter().map(|q| q.position.into()).collect();
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
    small_holes: Vec<String>,
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
        small_holes,
        note: format!("the entry's feed is the run's unless the run sets its own feed_mm_per_min; its pierce, standoff and kerf width replace the machine file's; {power}; holes within the small-hole rule run at its {holes}, corners within its corner rule at its feed factor; gas and focus are stated, not commanded"),
    })
}

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
