//! Whole programs: cutting points from kerf-discretize, arc fitting against the curve, the
//! feed plan, and every cycle checked against the axis limits by finite differences.

mod common;

use common::{circle, freeform, limit_ratios, stations};
use kerf_interp::{
    fit_blocks, fit_program, plan, AxisModel, FitOptions, PaperAcHead, PlanOptions, ProgramPath,
};
use nalgebra::{Point3, Vector3};

fn check_program(
    name: &str,
    m: &PaperAcHead,
    blocks: &[kerf_interp::Block],
    feed: f64,
    cycle: f64,
) -> kerf_interp::Motion {
    check_with(name, m, blocks, &PlanOptions::new(feed, cycle))
}

fn check_with(
    name: &str,
    m: &PaperAcHead,
    blocks: &[kerf_interp::Block],
    opts: &PlanOptions,
) -> kerf_interp::Motion {
    let cycle = opts.cycle_s;
    let motion = plan(m, blocks, opts).expect("plan");
    let rows = motion.setpoints(m);
    assert_eq!(rows.len(), motion.cycles() + 1, "{name}: one row per cycle");
    let (rv, ra, iv, ia) = limit_ratios(m, &rows, cycle);
    println!(
        "{name}: {:?}, {} cycles = {:.3} s, refinements {}, peak velocity {:.3} of limit (cycle {iv}), peak acceleration {:.3} (cycle {ia})",
        motion.counts(),
        motion.cycles(),
        motion.cycles() as f64 * cycle,
        motion.refinements(),
        rv,
        ra
    );
    assert!(rv <= 1.0, "{name}: velocity ratio {rv} at cycle {iv}");
    assert!(ra <= 1.0, "{name}: acceleration ratio {ra} at cycle {ia}");
    assert_eq!(
        rows[0], blocks[0].start_axes,
        "{name}: starts on the first point"
    );
    assert_eq!(
        rows[rows.len() - 1],
        blocks[blocks.len() - 1].end_axes,
        "{name}: stops exactly on the last point"
    );
    motion
}

#[test]
fn circle_becomes_few_arcs_and_stays_within_limits() {
    let m = PaperAcHead::paper_000();
    let c = circle(50.0, 100.0, 50.0, 20.0);
    // Tool tilted 30 degrees outward all around: A constant, C turning once.
    let st = stations(&m, &c, 0.001, |p| {
        let r = Vector3::new(p.x - 100.0, p.y - 50.0, 0.0).normalize();
        (r * 0.5 + Vector3::z() * 0.75f64.sqrt()).normalize()
    });
    let curve = |t: f64| c.point(t);
    let blocks =
        fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::with_tolerance(0.001)).expect("fit");
    let counts = kerf_interp::BlockCounts::of(&blocks);
    println!("circle: {} points -> {:?}", st.len(), counts);
    assert!(counts.arcs >= 2 && counts.total() <= 4, "{counts:?}");
    // The fitted arcs are the circle: every set-point's tip within the chord tolerance.
    let motion = check_program("circle", &m, &blocks, 10000.0, 0.001);
    for b in motion.blocks() {
        if let kerf_interp::Geometry::Arc(a) = &b.geometry {
            assert!((a.radius - 50.0).abs() < 1e-3, "radius {}", a.radius);
        }
    }
}

#[test]
fn freeform_with_varying_tool_axis_stays_within_limits() {
    let m = PaperAcHead::paper_000();
    let c = freeform();
    let st = stations(&m, &c, 0.001, |p| {
        Vector3::new(0.4 * (p.x / 40.0).sin(), 0.3 * (p.y / 25.0).cos(), 1.0).normalize()
    });
    let curve = |t: f64| c.point(t);
    let fitted =
        fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::with_tolerance(0.001)).expect("fit");
    let counts = kerf_interp::BlockCounts::of(&fitted);
    println!("freeform: {} points -> {:?}", st.len(), counts);
    assert!(
        counts.total() < st.len() - 1,
        "fitting reduces the block count"
    );
    check_program("freeform fitted", &m, &fitted, 15000.0, 0.001);
    let loose = plan(
        &m,
        &fitted,
        &PlanOptions::new(15000.0, 0.001).with_chord_tolerance_mm(1.0),
    )
    .expect("plan");
    println!("freeform fitted, no chord cap: {} cycles", loose.cycles());
    // Lines only, one per chord: many short blocks and corners.
    let lines = fit_blocks(
        &m,
        &st,
        None,
        0,
        &FitOptions::default()
            .with_arcs(false)
            .with_merge_lines(false),
    )
    .expect("lines");
    assert_eq!(lines.len(), st.len() - 1, "one line per chord");
    check_program("freeform lines", &m, &lines, 15000.0, 0.001);
}

#[test]
fn path_near_the_pole_limits_the_rotary_axes() {
    // The tool axis passes 0.06 degrees from +z: C swings through about 180 degrees within a
    // few millimetres while A stays tiny. The plan must slow down for C.
    let m = PaperAcHead::paper_000();
    let tips: Vec<Point3<f64>> = (0..=200)
        .map(|i| Point3::new(-50.0 + 0.5 * i as f64, 10.0, 0.0))
        .collect();
    let axes: Vec<Vector3<f64>> = tips
        .iter()
        .map(|p| Vector3::new(0.001, p.x / 500.0, 1.0).normalize())
        .collect();
    let st = kerf_interp::solve_stations(&m, &tips, Some(&axes), None, None).expect("reachable");
    let c_travel = (st[200].axes[4] - st[0].axes[4]).abs();
    assert!(c_travel > 170.0, "C swings: {c_travel}");
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit");
    let motion = check_program("pole", &m, &blocks, 20000.0, 0.001);
    // At 20 m/min the 100 mm would take 0.3 s; C's limits make it slower.
    assert!(
        motion.duration() > 0.3,
        "slowed for C: {} s",
        motion.duration()
    );
}

#[test]
fn two_paths_are_linked_by_a_rapid_move() {
    let m = PaperAcHead::paper_000();
    let c1 = circle(20.0, 0.0, 0.0, 0.0);
    let c2 = circle(10.0, 80.0, 30.0, 5.0);
    let up = |_: &Point3<f64>| Vector3::z();
    let f1 = |t: f64| c1.point(t);
    let f2 = |t: f64| c2.point(t);
    let paths = [
        ProgramPath {
            id: "ring-20".into(),
            stations: stations(&m, &c1, 0.001, up),
            curve: Some(&f1),
        },
        ProgramPath {
            id: "ring-10".into(),
            stations: stations(&m, &c2, 0.001, up),
            curve: Some(&f2),
        },
    ];
    let blocks = fit_program(&m, &paths, &FitOptions::default()).expect("fit");
    let one_call = kerf_interp::interpolate(
        &m,
        &paths,
        &FitOptions::default(),
        &PlanOptions::new(8000.0, 0.002),
    )
    .expect("interpolate");
    assert_eq!(
        one_call.blocks(),
        blocks.as_slice(),
        "interpolate = fit_program + plan"
    );
    // Retract along the tool axis, traverse, approach along the next tool axis.
    let rapids: Vec<_> = blocks.iter().filter(|b| b.rapid).collect();
    assert_eq!(rapids.len(), 3, "retract, traverse, approach");
    let up = rapids[0].end_tip() - rapids[0].start_tip();
    let along = rapids[0].end_tool_axis * 10.0;
    assert!(
        (up - along).norm() < 1e-9,
        "retract is 10 mm along the tool axis: {up:?}"
    );
    let down = rapids[2].end_tip() - rapids[2].start_tip();
    assert!(
        (down + rapids[2].end_tool_axis * 10.0).norm() < 1e-9,
        "approach along the axis"
    );
    let straight =
        fit_program(&m, &paths, &FitOptions::default().with_retract_mm(0.0)).expect("fit");
    assert_eq!(
        straight.iter().filter(|b| b.rapid).count(),
        1,
        "retract 0: one straight rapid move"
    );
    check_program("two rings", &m, &blocks, 8000.0, 0.002);
}

#[test]
fn plan_refuses_bad_options() {
    let m = PaperAcHead::paper_000();
    let st = stations(&m, &circle(5.0, 0.0, 0.0, 0.0), 0.01, |_| Vector3::z());
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.01)).expect("fit");
    for o in [
        PlanOptions::new(f64::NAN, 0.001),
        PlanOptions::new(1000.0, 0.0),
        PlanOptions::new(1000.0, 0.001).with_chord_tolerance_mm(-1.0),
    ] {
        let e = plan(&m, &blocks, &o);
        assert!(
            matches!(e, Err(kerf_interp::InterpError::BadParameter { .. })),
            "{e:?}"
        );
    }
    let e = plan(
        &m,
        &blocks,
        &PlanOptions::new(1.0, 0.001).with_max_cycles(10),
    );
    assert!(
        matches!(e, Err(kerf_interp::InterpError::TooManyCycles { .. })),
        "{e:?}"
    );
    // Empty program: no cycles beyond the start, no panic.
    let motion = plan(&m, &[], &PlanOptions::new(1000.0, 0.001)).expect("empty");
    assert_eq!(motion.setpoints(&m).len(), 0, "no set-points");
    let _ = m.limits();
}

#[test]
fn block_ends_on_cycles() {
    // Paper 000's block-by-block mode: every block end is a set-point, exactly.
    let m = PaperAcHead::paper_000();
    let c = freeform();
    let st = stations(&m, &c, 0.001, |p| {
        Vector3::new(0.4 * (p.x / 40.0).sin(), 0.3 * (p.y / 25.0).cos(), 1.0).normalize()
    });
    let curve = |t: f64| c.point(t);
    let fitted = fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::default()).expect("fit");
    let lines = fit_blocks(
        &m,
        &st,
        None,
        0,
        &FitOptions::default()
            .with_arcs(false)
            .with_merge_lines(false),
    )
    .expect("lines");
    for (name, blocks) in [("fitted", &fitted), ("lines", &lines)] {
        let opts = PlanOptions::new(15000.0, 0.001).with_block_ends_on_cycles(true);
        let motion = check_with(&format!("{name}, block ends on cycles"), &m, blocks, &opts);
        let rows = motion.setpoints(&m);
        let mut r = rows.iter();
        for (b, block) in blocks.iter().enumerate() {
            assert!(
                r.any(|q| *q == block.end_axes),
                "{name}: end of block {b} is a set-point"
            );
        }
    }
}

#[test]
fn plan_error_variants() {
    let m = PaperAcHead::paper_000();
    let c = freeform();
    let st = stations(&m, &c, 0.001, |_| Vector3::z());
    let lines = fit_blocks(
        &m,
        &st,
        None,
        0,
        &FitOptions::default()
            .with_arcs(false)
            .with_merge_lines(false),
    )
    .expect("lines");
    // Block ends on cycles need refinements here; with none allowed the plan says so.
    let opts = PlanOptions::new(15000.0, 0.001)
        .with_block_ends_on_cycles(true)
        .with_max_refinements(0);
    let e = plan(&m, &lines, &opts);
    assert!(
        matches!(e, Err(kerf_interp::InterpError::LimitsNotMet { .. })),
        "{e:?}"
    );
    // A block with NaN axes is refused, not planned.
    let mut bad = lines.clone();
    bad[3].end_axes[1] = f64::NAN;
    let e = plan(&m, &bad, &PlanOptions::new(15000.0, 0.001));
    assert!(
        matches!(e, Err(kerf_interp::InterpError::NonFinite { index: 3 })),
        "{e:?}"
    );
    // An arc bulging past an axis range is reported.
    let mut small = PaperAcHead::paper_000();
    small.limits.range[1] = Some([-10.0, 10.0]);
    let ring = stations(&m, &circle(20.0, 0.0, 30.0, 0.0), 0.001, |_| Vector3::z());
    let blocks = fit_blocks(&m, &ring, None, 0, &FitOptions::default()).expect("fit");
    let e = plan(&small, &blocks, &PlanOptions::new(5000.0, 0.001));
    assert!(
        matches!(e, Err(kerf_interp::InterpError::OutOfRange { .. })),
        "{e:?}"
    );
}
