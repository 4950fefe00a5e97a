//! The feed plan against independent time-optimal references: the analytic trapezoid and
//! S-curve of a straight line, and a dense phase-plane integration of a circle written here
//! (forward with the hardest acceleration, backward with the hardest braking, both clipped to
//! the maximum velocity curve: the Bobrow / Pfeiffer-Johanni construction, not the planner's
//! reachability passes), on analytic derivatives of the circle. Every plan's set-points are
//! also checked by finite differences against every limit, jerk included.

mod common;

use common::{circle, gantry, one_line_per_pose, ratios, stations};
use kerf_interp::{fit_blocks, plan, FitOptions, PaperAcHead, PlanOptions, Station};
use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

/// Dense phase-plane reference for a full circle of radius `r` in the XY plane traversed
/// from rest to rest, each of X and Y limited to `vmax` and `amax`, tip speed to `feed`.
/// With `theta = s / r`: `q' = (-sin, cos)`, `q'' = -(cos, sin) / r`.
fn circle_reference(r: f64, vmax: f64, amax: f64, feed: f64) -> f64 {
    let n = 400_000;
    let len = std::f64::consts::TAU * r;
    let d = len / n as f64;
    let derivs = |i: usize| {
        let th = i as f64 * d / r;
        let (s, c) = th.sin_cos();
        ([-s, c], [-c / r, -s / r])
    };
    // u range at (i, x) from both axes; None when empty.
    let range = |i: usize, x: f64| -> Option<(f64, f64)> {
        let (a, b) = derivs(i);
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for k in 0..2 {
            if a[k].abs() < 1e-12 {
                if (b[k] * x).abs() > amax {
                    return None;
                }
                continue;
            }
            let p = (amax - b[k] * x) / a[k];
            let q = (-amax - b[k] * x) / a[k];
            lo = lo.max(p.min(q));
            hi = hi.min(p.max(q));
        }
        (lo <= hi).then_some((lo, hi))
    };
    // Maximum velocity curve by bisection on feasibility.
    let mvc: Vec<f64> = (0..=n)
        .map(|i| {
            let (a, _) = derivs(i);
            let mut cap = feed * feed;
            for ak in a {
                if ak.abs() > 0.0 {
                    cap = cap.min((vmax / ak.abs()).powi(2));
                }
            }
            let (mut lo, mut hi) = (0.0, cap);
            if range(i, hi).is_some() {
                return hi;
            }
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if range(i, mid).is_some() {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            lo
        })
        .collect();
    let mut x = vec![0.0; n + 1];
    for i in 0..n {
        let up = range(i, x[i]).map_or(0.0, |(_, h)| h);
        x[i + 1] = (x[i] + 2.0 * d * up).clamp(0.0, mvc[i + 1]);
    }
    x[n] = 0.0;
    for i in (0..n).rev() {
        let down = range(i + 1, x[i + 1]).map_or(0.0, |(l, _)| l);
        x[i] = x[i].min((x[i + 1] - 2.0 * d * down).max(0.0));
    }
    (0..n)
        .map(|i| 2.0 * d / (x[i].sqrt() + x[i + 1].sqrt()))
        .sum()
}

fn vertical(_: &Point3<f64>) -> Vector3<f64> {
    Vector3::z()
}

#[test]
fn circles_plan_within_five_percent_of_the_dense_reference() {
    let m = gantry();
    for (radius, feeds) in [
        (35.0, [6000.0, 20000.0, 40000.0]),
        (5.0, [6000.0, 20000.0, 40000.0]),
    ] {
        let c = circle(radius, 100.0, 50.0, 0.0);
        let st = stations(&m, &c, 0.01, vertical);
        let curve = |t: f64| c.point(t);
        let blocks =
            fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::with_tolerance(0.01)).expect("fit");
        for feed in feeds {
            // The reference has no chord cap: lift it out of the way.
            let opts = PlanOptions::new(feed, 0.001).with_chord_tolerance_mm(1.0);
            let motion = plan(&m, &blocks, &opts).expect("plan");
            let reference = circle_reference(
                radius,
                m.limits.max_velocity[0],
                m.limits.max_acceleration[0],
                feed / 60.0,
            );
            let ratio = motion.duration() / reference;
            let r = ratios(&m, &motion.setpoints(&m), 0.001);
            println!(
                "R {radius} at {feed}: kerf {:.4} s, reference {reference:.4} s, {ratio:.4} x, {} runs, {} refinements, limits {r:?}",
                motion.duration(),
                motion.runs(),
                motion.refinements()
            );
            assert_eq!(motion.runs(), 1, "a circle has no corner");
            assert!(ratio <= 1.05, "R {radius} at {feed}: {ratio} x the optimum");
            assert!(
                ratio >= 0.99,
                "R {radius} at {feed}: faster than the optimum ({ratio})"
            );
            assert!(
                r[0] <= 1.0 && r[1] <= 1.0,
                "R {radius} at {feed}: limits {r:?}"
            );
            assert!(
                motion.refinements() <= 10,
                "work: {} re-plans",
                motion.refinements()
            );
        }
    }
}

/// Share of the length at the programmed feed `feed` (mm/min, within 0.1 %) from set-points
/// alone, cycle `t`; the tool vertical and the path in a plane of constant Z, so the tip moves
/// as X and Y do.
fn share_at_feed(rows: &[Axes], feed: f64, t: f64) -> f64 {
    let (mut total, mut at_feed) = (0.0, 0.0);
    for w in rows.windows(2) {
        let step = ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
        total += step;
        if step / t >= feed / 60.0 * 0.999 {
            at_feed += step;
        }
    }
    at_feed / total
}

/// The 70 mm hole (upright tool) fitted as blocks on `m` at 0.01 mm.
fn hole_70_blocks(m: &PaperAcHead) -> Vec<kerf_interp::Block> {
    let c = circle(35.0, 0.0, 0.0, 0.0);
    let st = stations(m, &c, 0.01, vertical);
    let curve = |t: f64| c.point(t);
    fit_blocks(m, &st, Some(&curve), 0, &FitOptions::with_tolerance(0.01)).expect("fit")
}

#[test]
fn the_70_mm_hole_runs_at_the_programmed_feed_with_one_modal_f_word() {
    let m = gantry();
    let blocks = hole_70_blocks(&m);
    let feed = 20000.0;
    let motion = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
    for (b, f) in motion.block_feeds().iter().enumerate() {
        assert_eq!(*f, feed, "block {b}: the programmed feed, modal");
    }
    // Share of the length at the programmed feed, from the set-points alone (tool vertical:
    // the tip moves as X, Y, Z do).
    let share = share_at_feed(&motion.setpoints(&m), feed, 0.001);
    let st = &motion.path_stats()[0];
    println!(
        "70 mm hole at 20 m/min: {:.3} s, {:.1} % of the length at feed (planner says {:.1} %)",
        motion.duration(),
        100.0 * share,
        100.0 * st.length_at_feed / st.cutting_length
    );
    assert!(share >= 0.90, "{share}");
    assert!((st.length_at_feed / st.cutting_length - share).abs() < 0.01);
}

#[test]
fn the_70_mm_hole_cut_one_line_per_chord_keeps_the_feed() {
    // The generic dialect's program: one line per chord. The discretizer ends each span of the
    // circle with a short chord between full ones (more than 4 times shorter); graded as if
    // the long chords were straight edges, the spline kinked there and the hole fell to 70 %
    // at feed. Truth: the set-points' own speeds (tool vertical: the tip moves as X, Y do).
    let c = circle(35.0, 0.0, 0.0, 0.0);
    let feed = 20000.0;
    for (name, m) in [
        ("acceleration", gantry()),
        ("jerk", common::gantry_with_jerk()),
    ] {
        let st = stations(&m, &c, 0.01, vertical);
        let len = |i: usize| (st[i + 1].tip - st[i].tip).norm();
        let jumps = (1..st.len() - 1)
            .filter(|&i| len(i) > 4.0 * len(i - 1) || len(i - 1) > 4.0 * len(i))
            .count();
        assert!(
            jumps > 0,
            "the case under test: chord lengths jumping 4 times"
        );
        let motion = plan(
            &m,
            &one_line_per_pose(&m, &st),
            &PlanOptions::new(feed, 0.001),
        )
        .expect("plan");
        let rows = motion.setpoints(&m);
        let share = share_at_feed(&rows, feed, 0.001);
        println!(
            "{name}: {jumps} chord jumps, {:.1} % at feed",
            100.0 * share
        );
        assert!(share >= 0.90, "{name}: {share}");
        assert!(
            ratios(&m, &rows, 0.001).iter().all(|&r| r <= 1.0),
            "{name}: limits"
        );
    }
}

fn line_stations(m: &PaperAcHead, len: f64) -> Vec<Station> {
    let tips: Vec<Point3<f64>> = (0..=100)
        .map(|i| Point3::new(len * i as f64 / 100.0 - 0.5 * len, 20.0, 0.0))
        .collect();
    kerf_interp::solve_stations(m, &tips, None, None, None).expect("reachable")
}

#[test]
fn a_straight_line_is_the_analytic_trapezoid_and_s_curve() {
    // Along X only: the optimum is the trapezoid L / v + v / a, and with jerk j the S-curve
    // L / v + v / a + a / j (both limits reached); the planner's filter is JERK_FILTER_WIDTH
    // jerk times wide, so it takes L / v + v / a + 1.25 a / j (each ramp at 80 % of the jerk).
    let mut m = PaperAcHead::paper_000();
    let (len, feed) = (400.0, 20000.0);
    let blocks =
        fit_blocks(&m, &line_stations(&m, len), None, 0, &FitOptions::default()).expect("fit");
    let (v, a) = (feed / 60.0, m.limits.max_acceleration[0]);
    let trapezoid = len / v + v / a;
    let motion = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
    let ratio = motion.duration() / trapezoid;
    println!(
        "line: {:.5} s against {trapezoid:.5} s ({ratio:.5} x)",
        motion.duration()
    );
    assert!((0.999..=1.011).contains(&ratio), "trapezoid: {ratio}");
    let j = 500_000.0;
    m.limits.max_jerk = Some([j, j, 400_000.0, 1_000_000.0, 1_000_000.0]);
    let s_curve = trapezoid + kerf_interp::JERK_FILTER_WIDTH * a / j;
    let jerked = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
    let r = ratios(&m, &jerked.setpoints(&m), 0.001);
    let ratio = jerked.duration() / s_curve;
    println!(
        "line with jerk: {:.5} s against {s_curve:.5} s ({ratio:.5} x), limits {r:?}",
        jerked.duration()
    );
    assert!((0.999..=1.011).contains(&ratio), "S-curve: {ratio}");
    assert!(r.iter().all(|&x| x <= 1.0), "limits {r:?}");
}

#[test]
fn a_short_line_takes_its_acceleration_reversal_within_the_jerk() {
    // 20 mm along X on the gantry at 40 m/min: too short to reach the feed, so the
    // acceleration-limited optimum is a triangle (+A, then at once -A). The jerk-optimal
    // rest-to-rest motion (7-phase S-curve without cruise, A reached since L > 2 A^3 / J^2)
    // takes T = 2 (2 T_j + T_a) with T_j = A / J and A (T_j + T_a)(2 T_j + T_a) = L. The plan
    // must not beat it (that would be a limit violation) and the reversal must not need the
    // verification's refinements (the filter alone would take it at 160 % of the jerk; the
    // plateau at the peak keeps it within).
    let m = common::gantry_with_jerk();
    let len = 20.0;
    let blocks =
        fit_blocks(&m, &line_stations(&m, len), None, 0, &FitOptions::default()).expect("fit");
    let (a, j) = (
        m.limits.max_acceleration[0],
        m.limits.max_jerk.expect("jerk")[0],
    );
    let tj = a / j;
    // (tj + ta)(2 tj + ta) = len / a: ta^2 + 3 tj ta + 2 tj^2 - len / a = 0.
    let ta = 0.5 * (-3.0 * tj + (tj * tj + 4.0 * len / a).sqrt());
    let optimum = 2.0 * (2.0 * tj + ta);
    let motion = plan(&m, &blocks, &PlanOptions::new(40000.0, 0.001)).expect("plan");
    let r = ratios(&m, &motion.setpoints(&m), 0.001);
    let ratio = motion.duration() / optimum;
    println!(
        "20 mm line with jerk: {:.5} s against the jerk-optimal {optimum:.5} s ({ratio:.4} x), \
         {} refinements, limits {r:?}",
        motion.duration(),
        motion.refinements()
    );
    assert!(
        ratio >= 0.999,
        "faster than the jerk-limited optimum: {ratio}"
    );
    assert!(ratio <= 1.05, "{ratio}");
    assert_eq!(motion.refinements(), 0, "the reversal needed refinements");
    assert!(r.iter().all(|&x| x <= 1.0), "limits {r:?}");
}

#[test]
fn jerk_limited_plans_stay_within_every_limit_and_near_the_optimum() {
    // Circles of 70 and 10 mm and a free-form curve with a varying tool axis, with the jerk
    // limits of fixtures/machines/ac_head.json (10 ms jerk time, 1000 m/s^3 on X and Y): every
    // cycle within the jerk limit, and the target, 1.25 x the acceleration-limited plan
    // on paths over 100 mm. (With 20 ms jerk times the free-form curve takes 1.26 x at 40 m/min.)
    let mut m = PaperAcHead::paper_000();
    let free = common::freeform();
    let cases = [
        (circle(35.0, 0.0, 0.0, 0.0), false),
        (circle(5.0, 0.0, 0.0, 0.0), false),
        (free, true),
    ];
    for (c, tilted) in cases {
        let st = stations(&m, &c, 0.01, |p| {
            if tilted {
                Vector3::new(0.4 * (p.x / 40.0).sin(), 0.3 * (p.y / 25.0).cos(), 1.0).normalize()
            } else {
                Vector3::z()
            }
        });
        let curve = |t: f64| c.point(t);
        let blocks =
            fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::with_tolerance(0.01)).expect("fit");
        let len: f64 = blocks.iter().map(|b| b.length()).sum();
        for feed in [6000.0, 20000.0, 40000.0] {
            m.limits.max_jerk = None;
            let acc = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
            m.limits.max_jerk = Some([1e6, 1e6, 8e5, 2e6, 2e6]);
            let jerk = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("plan");
            let r = ratios(&m, &jerk.setpoints(&m), 0.001);
            let ratio = jerk.duration() / acc.duration();
            println!(
                "{len:.1} mm at {feed}: {:.3} s acceleration-limited, {:.3} s jerk-limited ({ratio:.3} x), {} refinements, limits {r:?}",
                acc.duration(),
                jerk.duration(),
                jerk.refinements()
            );
            assert!(r.iter().all(|&x| x <= 1.0), "{len} mm at {feed}: {r:?}");
            if len > 100.0 {
                assert!(ratio <= 1.25, "{len} mm at {feed}: {ratio}");
            }
            assert!(jerk.refinements() <= 30, "work: {}", jerk.refinements());
        }
    }
}

#[test]
fn planning_work_is_bounded_on_a_long_path() {
    // 10,000 poses along a wavy line: the grid grows linearly with the path, not more.
    let m = PaperAcHead::paper_000();
    let tips: Vec<Point3<f64>> = (0..10_000)
        .map(|i| {
            let x = i as f64 * 0.25;
            Point3::new(x - 1200.0, 30.0 * (x / 40.0).sin(), 0.0)
        })
        .collect();
    let st = kerf_interp::solve_stations(&m, &tips, None, None, None).expect("reachable");
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.01)).expect("fit");
    let motion = plan(&m, &blocks, &PlanOptions::new(20000.0, 0.001)).expect("plan");
    println!(
        "10,000 poses: {} blocks, {} grid points, {} refinements, {:.3} s",
        blocks.len(),
        motion.grid_points(),
        motion.refinements(),
        motion.duration()
    );
    assert!(
        motion.grid_points() <= 20 * 10_000,
        "grid {}",
        motion.grid_points()
    );
    assert!(
        motion.refinements() <= 10,
        "re-plans {}",
        motion.refinements()
    );
    let r = ratios(&m, &motion.setpoints(&m), 0.001);
    assert!(r[0] <= 1.0 && r[1] <= 1.0, "{r:?}");
}

#[test]
fn the_smooth_path_stays_on_the_curve() {
    // Cutting points of the free-form curve and of a 10 mm hole at chord tolerance 0.01 mm, one
    // line per chord (the generic fit): the set-points follow the spline through the points,
    // whose distance from the true curve (closest point on the NURBS) is far below the chord
    // error of the polyline. Tool vertical: the tip is XYZ - (-r_c, 0, r_a).
    //
    // Bounds: on the hole (even spacing) the spline is far inside the chord error. On the
    // free-form curve the planner straightens a chord more than 4 times as long as its
    // neighbour (the guard against the spline ringing where spacing jumps; such chords sit at
    // inflections, where the walk's steps grow), so there the set-points follow the chord,
    // whose certified distance from the curve is the chord tolerance itself (measured 9.9 um
    // with the walk's band 0.97): the bound is that tolerance.
    let m = PaperAcHead::paper_000();
    for (name, c, bound) in [
        ("free-form", common::freeform(), 0.01),
        ("hole", circle(5.0, 0.0, 0.0, 0.0), 0.002),
    ] {
        let st = stations(&m, &c, 0.01, vertical);
        let lines = one_line_per_pose(&m, &st);
        let motion = plan(&m, &lines, &PlanOptions::new(6000.0, 0.001)).expect("plan");
        let mut worst = 0.0f64;
        for q in motion.iter(&m) {
            let tip = Point3::new(q[0] + m.r_c, q[1], q[2] - m.r_a);
            worst = worst.max(c.closest_point(&tip).distance);
        }
        println!(
            "{name}: {} set-points, largest distance from the curve {worst:.2e} mm",
            motion.cycles() + 1
        );
        assert!(worst <= bound, "{name}: {worst} > {bound}");
    }
}

#[test]
fn a_hole_too_small_for_the_feed_gets_one_lower_modal_f_word() {
    // A 10 mm hole at 20 m/min: the centripetal limit sqrt(A R) = 173 mm/s (10.4 m/min) is below
    // the feed, so the F word is lower, and the same on every block of the hole.
    let m = gantry();
    let c = circle(5.0, 0.0, 0.0, 0.0);
    let st = stations(&m, &c, 0.01, vertical);
    let lines = one_line_per_pose(&m, &st);
    let motion = plan(&m, &lines, &PlanOptions::new(20000.0, 0.001)).expect("plan");
    let feeds = motion.block_feeds();
    let first = feeds[0];
    println!(
        "10 mm hole at 20 m/min: {} blocks, F{first:.1}",
        feeds.len()
    );
    assert!(feeds.iter().all(|f| *f == first), "one modal F: {feeds:?}");
    let limit = (m.limits.max_acceleration[0] * 5.0).sqrt() * 60.0; // at 0, 90, 180, 270 degrees
    assert!(
        first < 20000.0 && first <= limit * 1.001,
        "F{first} vs the limit {limit}"
    );
    assert!(
        first > 0.8 * limit,
        "not needlessly low: F{first} vs {limit}"
    );
}

#[test]
fn the_set_points_stay_within_the_proven_spline_bound_of_the_blocks() {
    // `Motion::spline_deviation_bound` is a proof (Bezier hulls of the tip spline against the
    // chords of its nodes); the set-points, measured against the program's blocks (one line
    // per chord: the polyline of cutting points), must stay within it, and it must not be loose
    // (within 2 x of the largest measured distance plus a micron). With a curve that is cut
    // at 0.01 mm, the set-points are then within chord + bound of the curve.
    let m = PaperAcHead::paper_000();
    for (name, c) in [
        ("free-form", common::freeform()),
        ("hole", circle(5.0, 0.0, 0.0, 0.0)),
    ] {
        let st = stations(&m, &c, 0.01, vertical);
        let lines = one_line_per_pose(&m, &st);
        let polyline: Vec<Point3<f64>> = st.iter().map(|s| s.tip).collect();
        let motion = plan(&m, &lines, &PlanOptions::new(6000.0, 0.001)).expect("plan");
        let bound = motion.spline_deviation_bound();
        let (mut from_blocks, mut from_curve) = (0.0f64, 0.0f64);
        for q in motion.iter(&m) {
            let tip = Point3::new(q[0] + m.r_c, q[1], q[2] - m.r_a);
            let d = polyline
                .windows(2)
                .map(|w| kerf_nurbs::distance_to_segment(&tip, &w[0], &w[1]))
                .fold(f64::INFINITY, f64::min);
            from_blocks = from_blocks.max(d);
            from_curve = from_curve.max(c.closest_point(&tip).distance);
        }
        println!("{name}: spline bound {bound:.2e} mm, set-points {from_blocks:.2e} mm from the blocks, {from_curve:.2e} mm from the curve");
        assert!(
            from_blocks <= bound + 1e-12,
            "{name}: {from_blocks} > {bound}"
        );
        assert!(
            bound <= 2.0 * from_blocks + 1e-3,
            "{name}: loose bound {bound}"
        );
        assert!(from_curve <= 0.01 + bound, "{name}: {from_curve}");
    }
}

/// A path's feed factor (a small hole of a technology) is the programmed feed of that path:
/// the set-points never pass `factor x feed`, reach it on most of the length, and the share
/// at feed is measured against it. A factor outside (0, 1] is refused by name.
#[test]
fn a_feed_factor_plans_the_path_at_its_share_of_the_feed() {
    let m = gantry();
    let blocks = hole_70_blocks(&m);
    let feed = 20000.0;
    let opts = PlanOptions::new(feed, 0.001).with_feed_factors(vec![0.5]);
    let motion = plan(&m, &blocks, &opts).expect("plan");
    let rows = motion.setpoints(&m);
    let top = rows
        .windows(2)
        .map(|w| ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt() / 0.001 * 60.0)
        .fold(0.0, f64::max);
    assert!(top <= 0.5 * feed * 1.001, "{top} mm/min");
    let share = share_at_feed(&rows, 0.5 * feed, 0.001);
    assert!(share >= 0.9, "{share}");
    let stats = &motion.path_stats()[0];
    assert!((stats.length_at_feed / stats.cutting_length - share).abs() < 0.01);
    for (b, f) in motion.block_feeds().iter().enumerate() {
        assert_eq!(*f, 0.5 * feed, "block {b}");
    }
    for bad in [0.0, 1.5, f64::NAN] {
        let e = plan(&m, &blocks, &opts.clone().with_feed_factors(vec![bad])).unwrap_err();
        assert!(e.to_string().contains("feed_factors"), "{e}");
    }
}

/// The corner rule: a square (side 40 mm, started mid-edge) at 6000 mm/min on the gantry;
/// within 2 mm of the path on each side of a corner the tip runs at no more than half the
/// feed, mid-edge at the feed. Without the rule the tip passes 1.5 mm from a corner at more
/// than 0.6 x the feed (the gantry brakes in 0.83 mm), so the rule is what slows it.
#[test]
fn the_corner_rule_slows_the_tip_near_sharp_corners_only() {
    let m = gantry();
    let pts: Vec<Point3<f64>> = [
        (20., 0.),
        (40., 0.),
        (40., 40.),
        (0., 40.),
        (0., 0.),
        (20., 0.),
    ]
    .iter()
    .map(|&(x, y)| Point3::new(x, y, 0.0))
    .collect();
    let square =
        kerf_nurbs::NurbsCurve::new(1, vec![0., 0., 0.2, 0.4, 0.6, 0.8, 1., 1.], pts, None);
    let st = stations(&m, &square, 0.01, vertical);
    let blocks = one_line_per_pose(&m, &st);
    let feed = 6000.0;
    let speeds_at = |rule: Option<kerf_interp::CornerSlowdown>| -> Vec<(f64, f64)> {
        let opts = PlanOptions::new(feed, 0.001).with_corner_slowdown(rule);
        let rows = plan(&m, &blocks, &opts).expect("plan").setpoints(&m);
        let mut s = 0.0;
        rows.windows(2)
            .map(|w| {
                let step = ((w[1][0] - w[0][0]).powi(2) + (w[1][1] - w[0][1]).powi(2)).sqrt();
                s += step;
                (s, step / 0.001 * 60.0)
            })
            .collect()
    };
    let corner_gap = |s: f64| {
        [20.0, 60.0, 100.0, 140.0]
            .iter()
            .map(|c| (s - c).abs())
            .fold(f64::INFINITY, f64::min)
    };
    let rule = kerf_interp::CornerSlowdown {
        min_turn_deg: 45.0,
        length_mm: 2.0,
        feed_factor: 0.5,
    };
    let slowed = speeds_at(Some(rule));
    for &(s, v) in &slowed {
        if corner_gap(s) <= 1.5 {
            assert!(
                v <= 0.5 * feed * 1.02,
                "{v} mm/min at {s} mm, {} mm from a corner",
                corner_gap(s)
            );
        }
    }
    assert!(
        slowed
            .iter()
            .any(|&(s, v)| corner_gap(s) > 15.0 && v >= 0.99 * feed),
        "mid-edge at the feed"
    );
    let free = speeds_at(None);
    assert!(
        free.iter()
            .any(|&(s, v)| (corner_gap(s) - 1.5).abs() < 0.1 && v > 0.6 * feed),
        "without the rule the tip passes near the corners faster"
    );
    let bad =
        PlanOptions::new(feed, 0.001).with_corner_slowdown(Some(kerf_interp::CornerSlowdown {
            min_turn_deg: 0.0,
            ..rule
        }));
    assert!(
        plan(&m, &blocks, &bad).is_err(),
        "a turn of 0 degrees is no corner rule"
    );
}
