//! Inputs that made the planner crawl (issue 26), each held to counted work, never to a time.
//! Independent truths: the set-points' own finite differences against every limit, and a
//! duration bound from the poses alone (stopping at every pose, each axis' rest-to-rest time).

mod common;

use common::{circle, gantry_with_jerk, one_line_per_pose, ratios, stations};
use kerf_interp::{
    fit_blocks, interpolate, plan, stations_from_axes, AxisModel, FitOptions, InterpError,
    MachineModel, PlanOptions, ProgramPath, Station,
};
use kerf_kinematics::{AxesFile, Machine};
use nalgebra::Vector3;

fn machine(name: &str) -> MachineModel {
    let path = format!(
        "{}/../../fixtures/machines/{name}.json",
        env!("CARGO_MANIFEST_DIR")
    );
    MachineModel::new(Machine::read(path).expect("machine file")).expect("limits")
}

/// The stations of every path of an axes file in `tests/data`.
fn axes_stations(file: &str) -> Vec<Vec<Station>> {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let axes = AxesFile::read(path).expect("axes file");
    axes.paths
        .iter()
        .map(|p| {
            let (q, poses) = p.run();
            stations_from_axes(&q, &poses).expect("stations")
        })
        .collect()
}

/// An upper bound of any sensible plan's duration from the poses alone: the machine stops at
/// every pose and moves each interval rest to rest, each axis within its limits
/// (`d / V + 2 sqrt(d / A) + 2 A / J` bounds the jerk-limited rest-to-rest time of a travel
/// `d`), the tip no faster than the feed.
fn stop_at_every_pose(m: &dyn AxisModel, st: &[Station], feed_mm_s: f64) -> f64 {
    let lim = m.limits();
    st.windows(2)
        .map(|w| {
            let tip = (w[1].tip - w[0].tip).norm() / feed_mm_s;
            (0..5)
                .map(|k| {
                    let d = (w[1].axes[k] - w[0].axes[k]).abs();
                    if d == 0.0 {
                        return 0.0;
                    }
                    let (v, a) = (lim.max_velocity[k], lim.max_acceleration[k]);
                    let j = lim.max_jerk.map_or(0.0, |j| 2.0 * a / j[k]);
                    d / v + 2.0 * (d / a).sqrt() + j
                })
                .fold(tip, f64::max)
        })
        .sum()
}

#[test]
fn a_tool_turning_about_a_still_tip_is_planned_at_the_rotary_limits() {
    // 201 poses of a real trim line on the large gantry's A/C head: the tip stands still while
    // C turns 24 degrees (poses 8-33), later moves 0.006 mm per pose while C turns 1.2 degrees.
    // Parameterized by the tip's arc length alone, `dC/ds` reached 1e6 degrees per mm and the
    // plan asked for 114 M cycles after more than 6 CPU minutes.
    let m = machine("gantry_ac");
    let paths = axes_stations("pole_crawl.axes.json");
    assert_eq!(paths.len(), 1);
    let st = &paths[0];
    assert_eq!(st.len(), 201);
    let feed = 6000.0;
    let program = [ProgramPath {
        id: "trim-line-piece".into(),
        stations: st.clone(),
        curve: None,
    }];
    for fit in [
        FitOptions::with_tolerance(0.001),
        FitOptions::with_tolerance(0.001)
            .with_arcs(false)
            .with_merge_lines(false),
    ] {
        let motion = interpolate(&m, &program, &fit, &PlanOptions::new(feed, 0.001)).expect("plan");
        let w = motion.work();
        let bound = stop_at_every_pose(&m, st, feed / 60.0);
        println!(
            "{} cycles ({:.3} s, stop-at-every-pose bound {bound:.3} s), {w:?}",
            motion.cycles(),
            motion.duration()
        );
        assert!(
            motion.duration() <= bound,
            "the geometry bounds the plan: {} s against {bound} s",
            motion.duration()
        );
        // The work: grid points and verified set-points in proportion to the poses and the
        // program, not to the rounding.
        assert!(w.grid_points <= 200 * st.len(), "{w:?}");
        assert!(w.refinements <= 6, "{w:?}");
        assert!(
            w.verified_cycles <= (w.refinements + 1) * (motion.cycles() + 1),
            "{w:?}"
        );
        let rows = motion.setpoints(&m);
        let r = ratios(&m, &rows, 0.001);
        assert!(
            r.iter().all(|&v| v <= 1.0 + 1e-9),
            "within every limit: {r:?}"
        );
        assert_eq!(
            rows[rows.len() - 1],
            st[st.len() - 1].axes,
            "ends on the last pose"
        );
    }
}

#[test]
fn a_plan_that_fails_its_check_is_repaired_window_by_window() {
    // The test hook plans with 130 % of every limit: the first plan breaks them wherever it
    // reaches one, the verification must find every such cycle and slow its window until every
    // cycle is within every limit; with no refinement allowed the plan is refused, saying where.
    let m = gantry_with_jerk();
    let tilted = |p: &nalgebra::Point3<f64>| {
        Vector3::new(0.3 * p.x / 20.0, 0.3 * p.y / 20.0, 1.0).normalize()
    };
    let st = stations(&m, &circle(20.0, 0.0, 0.0, 0.0), 0.01, tilted);
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit");
    for feed in [6000.0, 20000.0, 40000.0] {
        let opts = PlanOptions::new(feed, 0.001);
        let honest = plan(&m, &blocks, &opts).expect("plan");
        let mut forced = opts.clone();
        forced.planned_limit_scale = 1.3;
        let refused = plan(&m, &blocks, &forced.clone().with_max_refinements(0));
        let Err(InterpError::LimitsNotMet {
            cycle, block, path, ..
        }) = refused
        else {
            panic!("the unrepaired plan breaks a limit: {refused:?}");
        };
        println!("{feed}: unrepaired fails at cycle {cycle}, block {block} of path {path}");
        assert!(block < blocks.len() && path == 0);
        let repaired = plan(&m, &blocks, &forced).expect("repaired");
        let w = repaired.work();
        let rows = repaired.setpoints(&m);
        let r = ratios(&m, &rows, 0.001);
        println!(
            "{feed}: honest {:.4} s ({} refinements), repaired {:.4} s, {w:?}, ratios {r:?}",
            honest.duration(),
            honest.refinements(),
            repaired.duration()
        );
        assert!(w.refinements >= 1, "{w:?}");
        assert!(
            r.iter().all(|&v| v <= 1.0 + 1e-9),
            "within every limit: {r:?}"
        );
        // Counted work: each round re-plans only the runs it touches and verifies once.
        assert!(w.refinements <= 30, "{w:?}");
        assert!(
            w.verified_cycles <= (w.refinements + 1) * (repaired.cycles() + 1),
            "{w:?}"
        );
        // The repair slows only where needed: not far from the honest plan.
        assert!(
            repaired.duration() <= 1.5 * honest.duration(),
            "{} vs {}",
            repaired.duration(),
            honest.duration()
        );
        assert_eq!(rows[rows.len() - 1], st[st.len() - 1].axes);
    }
}

#[test]
fn a_tiny_cycle_is_planned_once_and_refused_before_the_work_when_too_long() {
    // At a 10 us cycle the verification's finite differences divide by T^3 = 1e-15: the jerk
    // filter's difference of two large integrals and the set-points' own rounding were taken for
    // limit violations, the refinements slowed the plan round after round (a 189 s circle grew
    // to 819 s) and the program was refused after 143 s of work. Now: one verification, no
    // refinement, every cycle within every limit.
    let m = gantry_with_jerk();
    let st = stations(&m, &circle(2.0, 300.0, 0.0, 0.0), 0.001, |_| Vector3::z());
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit");
    let opts = PlanOptions::new(100.0, 0.00001);
    let motion = plan(&m, &blocks, &opts).expect("plan");
    let w = motion.work();
    let len = 2.0 * std::f64::consts::PI * 2.0;
    println!(
        "{} cycles, {:.4} s for {:.4} s at the feed, {w:?}",
        motion.cycles(),
        motion.duration(),
        len / (100.0 / 60.0)
    );
    assert_eq!(w.refinements, 0, "{w:?}");
    assert_eq!(w.verified_cycles, motion.cycles() + 1, "{w:?}");
    assert!(motion.duration() < 1.01 * len / (100.0 / 60.0));
    let rows = motion.setpoints(&m);
    let r = ratios(&m, &rows, 0.00001);
    assert!(
        r.iter().all(|&v| v <= 1.0 + 1e-9),
        "within every limit: {r:?}"
    );
    // Too long for the limit: refused before any planning, by a lower bound that is below the
    // real count (so nothing is refused that would fit) and within 1 % of it here.
    let e = plan(
        &m,
        &blocks,
        &opts.clone().with_max_cycles(motion.cycles() / 2),
    );
    let Err(InterpError::TooManyCycles { cycles, .. }) = e else {
        panic!("{e:?}");
    };
    assert!(
        cycles <= motion.cycles() as f64 && cycles > 0.99 * motion.cycles() as f64,
        "{cycles}"
    );
}

#[test]
fn a_tip_path_whose_spacing_jumps_is_graded_in_few_nodes() {
    // Fifty 0.07 mm lines, then lines from 1e-6 mm doubling up to 0.5 mm, three times over: the
    // line next to the 1e-6 mm one was graded to 2e-6 mm nodes (4,096 of them, the next ones
    // too), 41,637 grid points for 71 poses and 4.7 s of planning. Graded geometrically, the
    // nodes double from the short line's spacing: work proportional to the poses.
    let m = gantry_with_jerk();
    let mut x = 300.0;
    let mut tips = vec![nalgebra::Point3::new(x, 0.0, 0.0)];
    for _ in 0..3 {
        for _ in 0..50 {
            x += 0.07;
            tips.push(nalgebra::Point3::new(x, 0.0, 0.0));
        }
        let mut d = 1e-6;
        while d < 0.5 {
            x += d;
            d *= 2.0;
            tips.push(nalgebra::Point3::new(x, 0.0, 0.0));
        }
    }
    let axes = vec![Vector3::z(); tips.len()];
    let st = kerf_interp::solve_stations(&m, &tips, Some(&axes), None, None).expect("stations");
    let blocks = one_line_per_pose(&m, &st);
    for feed in [6000.0, 40000.0] {
        let motion = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
        let w = motion.work();
        let bound = stop_at_every_pose(&m, &st, feed / 60.0);
        println!(
            "{feed}: {} poses, {w:?}, {:.4} s (stopping at every pose {bound:.4} s)",
            st.len(),
            motion.duration()
        );
        assert!(w.grid_points <= 20 * st.len(), "{w:?}");
        assert!(w.refinements <= 5, "{w:?}");
        assert!(motion.duration() <= bound, "{}", motion.duration());
        let r = ratios(&m, &motion.setpoints(&m), 0.001);
        assert!(
            r.iter().all(|&v| v <= 1.0 + 1e-9),
            "within every limit: {r:?}"
        );
    }
}
