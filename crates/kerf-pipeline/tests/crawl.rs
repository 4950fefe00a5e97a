//! Small inputs on which the planner crawled (issue 26), run through the whole pipeline and held
//! to counted work (`Motion::work`), never to a time. Independent truths: the set-points' own
//! finite differences against every limit, and the contour's own length at the feed.

mod common;

use common::{circle, fixture, machine};
use kerf_interp::{AxisModel, MachineModel, Motion};
use kerf_kinematics::Machine;
use kerf_pipeline::{Job, JobOptions, PlaceMode};

/// The largest ratio over every cycle and axis of the set-points' velocity, acceleration and jerk
/// (finite differences, at rest before the first and after the last) to the machine's limits.
fn ratios(m: &MachineModel, motion: &Motion) -> [f64; 3] {
    let rows = motion.setpoints(m);
    let lim = m.limits();
    let t = motion.cycle();
    let n = rows.len() as isize;
    let at = |i: isize| rows[i.clamp(0, n - 1) as usize];
    let mut r = [0.0f64; 3];
    for i in -2..=n + 2 {
        for k in 0..5 {
            let v = (at(i)[k] - at(i - 1)[k]) / t;
            let a = (at(i + 1)[k] - 2.0 * at(i)[k] + at(i - 1)[k]) / (t * t);
            let j =
                (at(i + 1)[k] - 3.0 * at(i)[k] + 3.0 * at(i - 1)[k] - at(i - 2)[k]) / (t * t * t);
            r[0] = r[0].max(v.abs() / lim.max_velocity[k]);
            r[1] = r[1].max(a.abs() / lim.max_acceleration[k]);
            if let Some(jm) = lim.max_jerk {
                r[2] = r[2].max(j.abs() / jm[k]);
            }
        }
    }
    r
}

/// Prints what planning `motion` cost, checks every set-point against every limit by its own
/// finite differences and the work against `max_grid_points`, and returns the motion's
/// duration.
fn check(m: &MachineModel, motion: &Motion, max_grid_points: usize) -> f64 {
    let w = motion.work();
    let cut: f64 = motion.path_stats().iter().map(|p| p.cutting_length).sum();
    println!(
        "{} cycles ({:.3} s), {cut:.2} mm cut, {w:?}",
        motion.cycles(),
        motion.duration()
    );
    assert!(w.grid_points <= max_grid_points, "{w:?}");
    assert!(w.refinements <= 5, "{w:?}");
    let r = ratios(m, motion);
    assert!(
        r.iter().all(|&v| v <= 1.0 + 1e-9),
        "within every limit: {r:?}"
    );
    motion.duration()
}

#[test]
fn a_hole_of_ten_nanometres_with_the_default_lead_in_is_planned_in_a_fraction_of_a_second() {
    // The default lead-in (2 mm line, 1 mm arc) ends in a 0.087 mm chord that meets the hole's
    // 1.4e-8 mm chords: the C2 spline through both rang (the tip's derivative reached 9e5), the
    // blend's window fell to 5e-20 mm and its derivatives by differences over 1e-3 mm were
    // taken outside the run: a 1,299 s program after 29 s of planning. Such a jump of the node
    // spacing now ends the run, and a window under 1e-4 mm blends nothing.
    let job = Job::on_machine(machine()).with_curve("tiny", circle(100.0, 50.0, 1e-8), None);
    let out = job.run().expect("run");
    let m = MachineModel::new(machine()).expect("model");
    // The lead-in and lead-out are a few mm at 100 mm/s: well under a second with every stop.
    let duration = check(&m, &out.programs[0].motion, 5_000);
    assert!(duration < 1.0, "{duration}");
}

#[test]
fn a_pure_rotation_at_a_point_is_planned_at_the_rotary_limits() {
    // Contour 3 of fixtures/step/composite_mm.step runs over the 90 degree edge between two
    // faces; on a head without offsets (r_a = r_c = 0) the tool turns 90 degrees about a tip
    // that stands (nearly) still. Parameterized by the tip's travel alone that asked for 7.5e9
    // cycles; the rotation counted, the turn takes what A and C need at their limits.
    let text = std::fs::read_to_string(fixture("machines/ac_head.json")).expect("machine");
    let text = text.replace(
        "\"r_a\": 180.0, \"r_c\": 95.0",
        "\"r_a\": 0.0, \"r_c\": 0.0",
    );
    assert!(
        text.contains("\"r_a\": 0.0"),
        "the fixture's offsets were replaced"
    );
    let zero = Machine::from_str(&text).expect("zero-offset machine");
    let curves = kerf_format::curves::load(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/bent_contour.curves.json"),
    )
    .expect("curves");
    // The head check off: half-way through the turn the nozzle's cone, 1.35 mm above its tip,
    // is about 0.4 mm from both faces ((1 + 1.35) cos 45 - 1.8 sin 45), and the check spends
    // its work budget there and refuses the cut; the planner's work is what is asserted here.
    let out = Job::new(curves, zero.clone())
        .with_options(JobOptions::default().with_cut_clearance_mm(None))
        .run()
        .expect("run");
    let m = MachineModel::new(zero).expect("model");
    let motion = &out.programs[0].motion;
    let cut: f64 = motion.path_stats().iter().map(|p| p.cutting_length).sum();
    // The 90 degree turn of A and C at their limits (600 deg/s, 20,000 deg/s^2, 10 ms jerk
    // time) takes about 0.2 s, the 54.5 mm at 100 mm/s 0.55 s; a few stops more.
    let duration = check(&m, motion, 20_000);
    assert!(
        duration < cut / 100.0 + 1.0,
        "bounded by the geometry: {duration} s"
    );
}

#[test]
fn the_creases_under_the_tilt_cone_are_planned_with_work_bounded_by_the_poses() {
    // fixtures/trim_creases.json placed automatically, generic dialect (one line a pose): at each
    // crease the tilt cone holds the axes still while the tool turns about a tip that moves
    // 1.5e-8 mm a pose (0.07 mm of the path parameter each), then the tip leaves on moves of
    // 8e-7, 1.6e-6, ... mm. The turn and the move shared a run, the turn's poses were graded to
    // the move's spacing (up to 4,096 nodes each): 420,282 grid points and 6 refinements on
    // ac_head, 12 s of CPU for 697 poses. The switch from the rotation to the tip's travel now
    // ends the run.
    let file = kerf_format::curves::load(fixture("trim_creases.json")).expect("fixture");
    for name in ["ac_head", "gantry_ac"] {
        let machine = Machine::read(fixture(&format!("machines/{name}.json"))).expect("machine");
        let out = Job::new(file.clone(), machine.clone())
            .with_options(
                JobOptions::default()
                    .with_place(PlaceMode::Auto)
                    // Up the flange the head's body meets the panel (refused by default).
                    .with_cut_clearance_mm(None),
            )
            .run()
            .expect("run");
        let m = MachineModel::new(machine).expect("model");
        let motion = &out.programs[0].motion;
        let blocks = motion.blocks().len();
        println!("{name}: {blocks} blocks, {} runs", motion.runs());
        // A few dozen grid points a block over the first plan and every re-plan.
        let duration = check(&m, motion, 50 * blocks);
        // Independent truth: the cut at the programmed feed (6000 mm/min) is a lower bound; the
        // turns at the creases and the stops add a few seconds.
        let cut: f64 = motion.path_stats().iter().map(|p| p.cutting_length).sum();
        assert!(cut > 1000.0, "{cut}");
        assert!(
            duration >= cut / 100.0 && duration < 1.5 * cut / 100.0,
            "{name}: {duration} s for {cut} mm"
        );
    }
}
