//! Inputs that made the planner crawl (issue 26), each held to counted work, never to a time.
//! Independent truths: the set-points' own finite differences against every limit, and a
//! duration bound from the poses alone (stopping at every pose, each axis' rest-to-rest time).

mod common;

use common::ratios;
use kerf_interp::{
    interpolate, stations_from_axes, AxisModel, FitOptions, MachineModel, PlanOptions, ProgramPath,
    Station,
};
use kerf_kinematics::{AxesFile, Machine};

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
