//! The pipeline as a library: a job from files and from code, every stage's result, the
//! error type, the generic-dialect rule and the outputs, checked against independent truth
//! (`kerf-check`'s brute-force measurement, the exact circle, forward kinematics).

use std::sync::Mutex;

use kerf_check::{check, CheckOptions, RawToolpath};
use kerf_interp::{Dialect, Geometry};
use kerf_nurbs::NurbsCurve;
use kerf_pipeline::{
    plan_program, CertifiedToolpath, Error, Job, JobOptions, MissingSurface, MotionInput,
    MotionOptions, OrientOptions, Progress, Stage,
};
use nalgebra::Point3;

mod common;
use common::{fixture, machine};

/// A straight line from `a` to `b` (degree 1).
fn line(a: [f64; 3], b: [f64; 3]) -> NurbsCurve {
    NurbsCurve::try_new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Point3::from(a), Point3::from(b)],
        None,
    )
    .expect("line")
}

#[test]
fn a_job_from_files_gives_every_stage_and_its_toolpath_passes_the_independent_check() {
    // `mixed`'s curves run under its tilted plane: the head meets it (refused by default; the
    // head check has its own tests).
    let job = Job::from_files(fixture("mixed.json"), fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(
            JobOptions::default()
                .with_tolerance_mm(0.01)
                .with_cut_clearance_mm(None),
        );
    let out = job.run().expect("run");
    let n = job.curves().curves.len();
    assert_eq!(out.discretizations.len(), n, "one discretization per curve");
    assert_eq!(out.oriented.len(), n, "one oriented path per curve");
    assert_eq!(out.toolpath.paths.len(), n, "one toolpath path per curve");
    assert_eq!(out.solved.len(), n, "one cut per curve");
    assert_eq!(out.axes.paths.len(), n, "one axes path per cut");
    assert_eq!(out.programs.len(), 1, "one set-up");
    // The toolpath, as text, measured by the checker (dense sampling, not the certificate).
    let mut text = Vec::new();
    out.write_toolpath(&mut text).expect("toolpath to memory");
    let tp = RawToolpath::from_slice(&text).expect("toolpath reads back");
    let report = check(&job.curves().curves, &tp, &CheckOptions::default());
    assert!(report.passed(), "{:?}", report.violations);
    assert!(
        report.measured_chord_error() <= 0.01,
        "{}",
        report.measured_chord_error()
    );
    // Curves without a surface get the vertical beam.
    for (rec, o) in job.curves().curves.iter().zip(&out.oriented) {
        if rec.surface.is_none() {
            assert!(
                o.normals().iter().all(|v| (v.z - 1.0).abs() < 1e-15),
                "{}",
                rec.id
            );
        }
    }
    // Forward kinematics after the pipeline's inverse, on every pose of every cut.
    for p in &out.axes.paths {
        let (axes, poses) = p.run();
        for (q, pose) in axes.iter().zip(&poses) {
            let back = job
                .machine()
                .kinematics
                .forward(&kerf_kinematics::Axes::from_array(*q))
                .to_array();
            for k in 0..6 {
                assert!(
                    (back[k] - pose[k]).abs() < 1e-9,
                    "{}: {back:?} vs {pose:?}",
                    p.id
                );
            }
        }
    }
    assert_eq!(
        out.report.discretize.curves, n,
        "the report counts the curves"
    );
}

#[test]
fn generic_programs_get_neither_arcs_nor_merged_lines_whatever_the_caller_sets() {
    // A dome has long circular contours: with tool-tip control they become arcs.
    let base =
        Job::from_files(fixture("dome.json"), fixture("machines/ac_head.json")).expect("inputs");
    let sinumerik = base
        .clone()
        .with_options(JobOptions::default().with_dialect(Dialect::Sinumerik))
        .run()
        .expect("sinumerik");
    assert!(
        sinumerik.programs[0].motion.counts().arcs > 0,
        "arcs where the controller keeps the tip on the path"
    );
    for dialect in [Dialect::Generic, Dialect::Linuxcnc] {
        let out = base
            .clone()
            .with_options(JobOptions::default().with_dialect(dialect))
            .run()
            .expect("raw axes");
        for b in out.programs[0].motion.blocks().iter().filter(|b| !b.rapid) {
            assert!(
                !matches!(b.geometry, Geometry::Arc(_)),
                "{dialect:?}: an arc"
            );
            assert_eq!(
                b.stations[1],
                b.stations[0] + 1,
                "{dialect:?}: a merged line"
            );
        }
    }
    // The motion stage alone: the same rule from the dialect, and no G-code without one.
    let input = MotionInput::Toolpath(sinumerik.toolpath.clone());
    let generic = plan_program(&machine(), &input, &MotionOptions::default(), None).expect("plan");
    assert_eq!(generic.motion.counts().arcs, 0, "generic: no arcs");
    assert!(
        generic.gcode().expect("gcode").contains("G1 X"),
        "axis words"
    );
    let setpoints = MotionOptions::default().with_dialect(None);
    let p = plan_program(&machine(), &input, &setpoints, None).expect("plan");
    assert!(p.motion.counts().arcs > 0, "set-points follow arcs");
    assert!(
        matches!(p.gcode(), Err(Error::NoDialect)),
        "no program without a dialect"
    );
    let mut csv = Vec::new();
    p.write_setpoints(&mut csv).expect("set-points to memory");
    let rows = String::from_utf8(csv).expect("utf-8").lines().count();
    assert_eq!(
        rows,
        p.motion.cycles() + 2,
        "a header and one row per cycle end"
    );
}

#[test]
fn errors_name_the_file_the_curve_and_keep_the_stage_error() {
    let path = fixture("mixed.json");
    let mut opts = JobOptions::default();
    opts.discretize.max_points = 3;
    let e = Job::from_files(&path, fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(opts)
        .run()
        .expect_err("three points cannot certify these curves");
    let Error::Discretize {
        file, index, id, ..
    } = &e
    else {
        panic!("a discretizer error: {e:?}");
    };
    assert_eq!(file.as_deref(), Some(path.as_path()), "the file");
    let text = e.to_string();
    assert!(
        text.starts_with(&format!("{}: curves[{index}] ({id:?}): ", path.display())),
        "{text}"
    );
    let source = std::error::Error::source(&e).expect("the stage error is kept");
    assert!(
        source
            .downcast_ref::<kerf_discretize::DiscretizeError>()
            .is_some(),
        "{source:?}"
    );
    // Normals refused for a curve without a surface, when asked to.
    let e = Job::from_files(&path, fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(
            JobOptions::default()
                .with_orient(OrientOptions::default().with_missing_surface(MissingSurface::Error)),
        )
        .run()
        .expect_err("mixed.json has curves without a surface");
    assert!(
        matches!(&e, Error::MissingSurface { index: 0, id, .. } if id == "v-corner"),
        "{e:?}"
    );
}

#[test]
fn a_model_built_in_code_is_checked_as_a_file_would_be() {
    let l = || line([100.0, 100.0, 0.0], [140.0, 100.0, 0.0]);
    let e = Job::on_machine(machine())
        .run()
        .expect_err("nothing to cut");
    assert!(matches!(e, Error::NoCurves { .. }), "{e:?}");
    let e = Job::on_machine(machine())
        .with_curve("a", l(), Some("nowhere"))
        .run()
        .expect_err("unknown surface");
    assert!(
        matches!(&e, Error::UnknownSurface { index: 0, surface, .. } if surface == "nowhere"),
        "{e:?}"
    );
    let e = Job::on_machine(machine())
        .with_curve("a", l(), None)
        .with_curve("a", l(), None)
        .run()
        .expect_err("duplicate id");
    assert!(e.to_string().contains("curves[1] (\"a\")"), "{e}");
    let e = Job::on_machine(machine())
        .with_curve("a\nM30", l(), None)
        .run()
        .expect_err("an id that would add a block");
    assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
    // A valid one: a 40 mm straight cut with a vertical beam; the cutting points are the
    // line's ends and the certified chord error is the rounding margin only.
    let out = Job::on_machine(machine())
        .with_curve("slit", l(), None)
        .run()
        .expect("run");
    let p = &out.toolpath.paths[0];
    assert_eq!(p.points.len(), 2, "a line needs its two ends");
    assert!(
        p.max_chord_error < 1e-9,
        "a chord of a line: {}",
        p.max_chord_error
    );
}

#[test]
fn progress_reports_every_stage_and_every_curve() {
    let seen = Mutex::new(Vec::<Progress>::new());
    // `mixed`'s curves run under its tilted plane: the head meets it (refused by default; the
    // head check has its own tests).
    let job = Job::from_files(fixture("mixed.json"), fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(JobOptions::default().with_cut_clearance_mm(None));
    job.run_with_progress(&|p| seen.lock().expect("lock").push(p))
        .expect("run");
    let seen = seen.into_inner().expect("lock");
    let n = job.curves().curves.len();
    for stage in [Stage::Discretize, Stage::Normals] {
        let done: Vec<usize> = seen
            .iter()
            .filter(|p| p.stage == stage)
            .map(|p| p.done)
            .collect();
        assert_eq!(
            done.len(),
            n + 1,
            "{stage:?}: a start and one report per curve"
        );
        assert_eq!(done.iter().max(), Some(&n), "{stage:?}: all curves");
    }
    for stage in [Stage::Kinematics, Stage::Interpolate, Stage::Report] {
        assert!(seen.iter().any(|p| p.stage == stage), "{stage:?} reported");
    }
}

#[test]
fn the_output_directory_is_written_all_or_nothing() {
    let out = Job::from_files(fixture("dome.json"), fixture("machines/ac_head.json"))
        .expect("inputs")
        .run()
        .expect("run");
    let dir = tempfile::tempdir().expect("temp dir");
    out.write_dir(dir.path()).expect("write");
    for name in out.file_names() {
        assert!(dir.path().join(&name).is_file(), "{name} written");
    }
    let program = std::fs::read_to_string(dir.path().join("program.nc")).expect("program");
    assert_eq!(
        program, out.programs[0].text,
        "the program in memory is the file"
    );
    // A directory where a file must go: refused before anything is written, nothing changed.
    let dir2 = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir2.path().join("report.json")).expect("mkdir");
    let e = out
        .write_dir(dir2.path())
        .expect_err("report.json is a directory");
    assert!(
        matches!(&e, Error::Write { path: Some(p), .. } if p.ends_with("report.json")),
        "{e:?}"
    );
    let left: Vec<_> = std::fs::read_dir(dir2.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(
        left,
        vec![std::ffi::OsString::from("report.json")],
        "nothing else written"
    );
}

#[test]
fn a_program_states_the_chord_term_only_as_far_as_kerf_proved_it() {
    let job = Job::from_files(fixture("dome.json"), fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(JobOptions::default().with_tolerance_mm(0.01));
    let out = job.run().expect("run");
    let budget = |text: &str| -> String {
        text.lines()
            .filter(|l| l.contains("tolerance budget"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let gcode = |input: MotionInput| -> String {
        plan_program(&machine(), &input, &MotionOptions::default(), None)
            .expect("plan")
            .gcode()
            .expect("gcode")
    };
    // kerf run certified every segment: the term stands unqualified.
    let own = budget(&out.programs[0].text);
    assert!(
        own.contains("chord 0.01 + ") && !own.contains("known terms"),
        "{own}"
    );
    // The same cutting points read as a toolpath: only the file's claim.
    let tp = out.toolpath.clone();
    let claimed = budget(&gcode(MotionInput::Toolpath(tp.clone())));
    assert!(
        claimed.contains("the toolpath file's claim, not verified"),
        "{claimed}"
    );
    // An axes file records no chord tolerance: unknown, and left out of the total.
    let axes = budget(&gcode(MotionInput::Axes(out.axes.clone())));
    assert!(axes.contains("chord unknown"), "{axes}");
    // Certified again against the curves: the bound covers what the brute force measures.
    let certified = CertifiedToolpath::new(tp.clone(), job.curves(), None).expect("certifies");
    let raw = |tp: &kerf_format::toolpath::ToolpathFile| {
        let mut text = Vec::new();
        kerf_format::toolpath::to_writer(tp, &mut text).expect("toolpath to memory");
        RawToolpath::from_slice(&text).expect("reads back")
    };
    let measured =
        check(&job.curves().curves, &raw(&tp), &CheckOptions::default()).measured_chord_error();
    assert!(
        measured <= certified.bound_mm() && certified.bound_mm() <= 0.01,
        "measured {measured}, certified {}",
        certified.bound_mm()
    );
    assert_eq!(
        budget(&gcode(MotionInput::Certified(certified))),
        own,
        "certified like kerf run's"
    );
    // Segments merged into one (dropping points that are no knots, as few as take the chord
    // over the tolerance by the checker's own measurement): the certificate refuses, naming
    // the path.
    let curve = &job.curves().curves[0].curve;
    let path = &tp.paths[0];
    let inside = |k: usize| !curve.knots().contains(&path.params[k]);
    let pos = |k: usize| path.points.position(k);
    let (k, m) = (1..path.params.len() - 1)
        .flat_map(|k| (1..8).map(move |m| (k, m)))
        .find(|&(k, m)| {
            k + m < path.params.len()
                && (k..k + m).all(inside)
                && kerf_check::segment_chord_error(
                    curve,
                    path.params[k - 1],
                    path.params[k + m],
                    &pos(k - 1),
                    &pos(k + m),
                    32,
                )
                .error
                    > 0.01
        })
        .expect("a run of points to drop");
    let mut merged = tp.clone();
    merged.paths[0].params.drain(k..k + m);
    if let kerf_format::toolpath::ToolpathPoints::Poses(p) = &mut merged.paths[0].points {
        p.drain(k..k + m);
    }
    let report = check(
        &job.curves().curves,
        &raw(&merged),
        &CheckOptions::default(),
    );
    assert!(report.measured_chord_error() > 0.01, "the premise");
    let err = CertifiedToolpath::new(merged, job.curves(), None).expect_err("refused");
    assert!(
        matches!(
            &err,
            Error::NotCertified {
                index: 0,
                source: Some(_),
                ..
            }
        ),
        "{err}"
    );
    // A point moved 0.02 mm off its curve: its chords may be that far off; refused.
    let mut moved = tp.clone();
    if let kerf_format::toolpath::ToolpathPoints::Poses(p) = &mut moved.paths[1].points {
        p[1][2] += 0.02;
    }
    let err = CertifiedToolpath::new(moved, job.curves(), None).expect_err("refused");
    assert!(
        matches!(
            &err,
            Error::NotCertified {
                index: 1,
                source: None,
                ..
            }
        ) && err.to_string().contains("2.000e-2 mm from the curve"),
        "{err}"
    );
}

#[test]
fn sinumerik_arcs_and_merged_lines_stay_within_chord_plus_fit_of_the_curve() {
    // With tool-tip control the program's blocks are arcs and lines merged over several
    // cutting points; the budget states `chord + fit` for them. Every cutting block that
    // carries curve parameters is measured against the curve itself, densely sampled between
    // them (64 points), with the block's exact geometry.
    let job = Job::from_files(fixture("door_trim.json"), fixture("machines/ac_head.json"))
        .expect("inputs")
        .with_options(
            JobOptions::default()
                .with_tolerance_mm(0.01)
                .with_dialect(Dialect::Sinumerik),
        );
    let out = job.run().expect("run");
    let text = &out.programs[0].text;
    assert!(
        text.contains("chord 0.01 + fit 0.01 + "),
        "{}",
        text.lines().find(|l| l.contains("budget")).unwrap_or("")
    );
    let program = &out.programs[0];
    let (mut measured, mut merged) = (0.0f64, 0usize);
    for b in program.motion.blocks().iter().filter(|b| !b.rapid) {
        let Some([t0, t1]) = b.params.filter(|p| p[1] > p[0]) else {
            continue;
        };
        let id = &program.ids[b.path];
        let curve = &job
            .curves()
            .curves
            .iter()
            .find(|c| &c.id == id)
            .expect("curve")
            .curve;
        // The cut's parameters: the contour from its start point `u_s` round to it again
        // (`+ period` past the seam), the lead-in below `u_s`, the lead-out above the end.
        let params = &out
            .toolpath
            .paths
            .iter()
            .find(|p| &p.id == id)
            .expect("toolpath path")
            .params;
        let start = out
            .axes
            .paths
            .iter()
            .find(|p| &p.id == id)
            .and_then(|p| p.start_point)
            .unwrap_or(0);
        let (a, e) = curve.domain();
        let period = e - a;
        let u_s = params[start];
        let u_e = if start > 0 { u_s + period } else { e };
        let (lo, hi) = (t0.max(u_s), t1.min(u_e));
        if hi <= lo {
            continue; // a lead-in or lead-out block: not on the curve, no claim
        }
        if b.stations[1] > b.stations[0] + 1 {
            merged += 1;
        }
        for k in 0..=64 {
            let u = lo + (hi - lo) * k as f64 / 64.0;
            let p = curve.point(if u > e { u - period } else { u });
            let d = match b.geometry {
                Geometry::Line { start, end } => kerf_nurbs::distance_to_segment(&p, &start, &end),
                Geometry::Arc(arc) => arc.distance(&p).0,
                Geometry::Turn { at } => (p - at).norm(),
            };
            measured = measured.max(d);
        }
    }
    assert!(merged > 10, "arcs and merged lines to test: {merged}");
    assert!(measured <= 0.01 + 0.01, "{measured} mm from the curve");
}

/// A run has one retract: the job's `retract_mm`, raised to the traverse checks' own where
/// that is longer (`JobOptions::checked_traverse`). The head backs off at least that far
/// along the tool axis before every checked traverse (the first waypoint of each, read back
/// against the end of the cut before it), and the report states the retract used.
#[test]
fn the_retract_is_the_jobs_raised_to_what_the_traverse_check_needs() {
    let run = |retract_mm: f64, clearance_mm: f64| {
        let traverse = kerf_process::TraverseOptions::default().with_clearance(clearance_mm);
        // `mixed`'s curves run under its tilted plane: the head meets it (refused by default).
        let options = JobOptions::default()
            .with_retract_mm(retract_mm)
            .with_traverse(Some(traverse))
            .with_cut_clearance_mm(None);
        assert_eq!(
            options.checked_traverse().map(|t| t.retract_mm),
            Some(retract_mm.max(1.5 * clearance_mm))
        );
        let job = Job::from_files(fixture("mixed.json"), fixture("machines/ac_head.json"))
            .expect("inputs")
            .with_options(options);
        job.run().expect("run")
    };
    for (retract_mm, clearance_mm, want) in [(12.0, 5.0, 12.0), (10.0, 10.0, 15.0)] {
        let out = run(retract_mm, clearance_mm);
        assert_eq!(out.report.traverses.retract_mm, Some(want), "stated");
        // Each traverse starts on the tool-axis line above the end of some cut (the one
        // before it in cutting order), at least the retract up.
        let ends: Vec<[f64; 6]> = (out.axes.paths.iter())
            .map(|p| {
                let last = p.lead_out.as_ref().map_or(&p.poses, |m| &m.poses);
                last[last.len() - 1]
            })
            .collect();
        let mut seen = 0;
        for t in out.axes.paths.iter().filter_map(|p| p.traverse.as_ref()) {
            let first = t.poses[0];
            let (up, off) = ends
                .iter()
                .map(|e| {
                    let d: [f64; 3] = std::array::from_fn(|k| first[k] - e[k]);
                    let up: f64 = (0..3).map(|k| d[k] * e[k + 3]).sum();
                    let off = (0..3).map(|k| (d[k] - up * e[k + 3]).powi(2)).sum::<f64>();
                    (up, off.sqrt())
                })
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .expect("cuts");
            assert!(off < 1e-6, "on a cut end's tool-axis line ({off} mm off)");
            assert!(up >= want - 1e-6, "backed off {up} mm, want {want}");
            seen += 1;
        }
        assert!(seen > 0, "checked traverses");
    }
}
