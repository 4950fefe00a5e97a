//! The jerk-limited plan on the geometry that made it slow (a slot: lines meeting arcs, where the
//! curvature jumps) and the rotary axes at their limits. Independent truths: the slot's exact
//! geometry (the distance of a point from a stadium is `| dist(p, centre segment) - R |`), the
//! axis ranges, and the set-points' own finite differences against every limit.

mod common;

use common::{gantry_with_jerk as gantry, one_line_per_pose, ratios};
use kerf_interp::{fit_blocks, plan, solve_stations, FitOptions, InterpError, PlanOptions};
use nalgebra::{Point3, Vector3};

/// A 60 x 12 slot (the stadium of centres (+-24, 0), radius 6) from (-24, -6), counter-clockwise:
/// points every 1 mm on the lines and every 2 degrees on the half circles.
fn slot() -> Vec<Point3<f64>> {
    let mut p = Vec::new();
    for i in 0..48 {
        p.push(Point3::new(-24.0 + i as f64, -6.0, 0.0));
    }
    for i in 0..90 {
        let a = (-90.0 + 2.0 * i as f64).to_radians();
        p.push(Point3::new(24.0 + 6.0 * a.cos(), 6.0 * a.sin(), 0.0));
    }
    for i in 0..48 {
        p.push(Point3::new(24.0 - i as f64, 6.0, 0.0));
    }
    for i in 0..=90 {
        let a = (90.0 + 2.0 * i as f64).to_radians();
        p.push(Point3::new(-24.0 + 6.0 * a.cos(), 6.0 * a.sin(), 0.0));
    }
    p
}

/// Distance of `p` from the slot's contour (in its plane).
fn slot_distance(p: &Point3<f64>) -> f64 {
    let x = p.x.clamp(-24.0, 24.0);
    let d = ((p.x - x).powi(2) + p.y.powi(2)).sqrt();
    ((d - 6.0).powi(2) + p.z.powi(2)).sqrt()
}

#[test]
fn a_slot_is_blended_within_the_tolerance_and_planned_near_the_optimum() {
    let mut m = gantry();
    let st = solve_stations(&m, &slot(), None, None, None).expect("reachable");
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.001)).expect("fit");
    for feed in [20000.0, 40000.0] {
        let opts = PlanOptions::new(feed, 0.001);
        let jerk = plan(&m, &blocks, &opts).expect("plan");
        let unblended =
            plan(&m, &blocks, &opts.clone().with_blend_tolerance_mm(0.0)).expect("plan");
        let limits = m.limits.max_jerk.take();
        let acc = plan(&m, &blocks, &opts).expect("plan");
        m.limits.max_jerk = limits;
        let rows = jerk.setpoints(&m);
        let r = ratios(&m, &rows, 0.001);
        // Tool vertical: the tip is XYZ - (-r_c, 0, r_a).
        let worst = rows
            .iter()
            .map(|q| slot_distance(&Point3::new(q[0] + m.r_c, q[1], q[2] - m.r_a)))
            .fold(0.0, f64::max);
        let ratio = jerk.duration() / acc.duration();
        println!(
            "slot at {feed}: acceleration-limited {:.3} s, jerk {:.3} s ({ratio:.3} x), unblended {:.3} s, limits {r:?}, blend {:.2e} mm, from the slot {worst:.2e} mm, {} refinements",
            acc.duration(),
            jerk.duration(),
            unblended.duration(),
            jerk.blend_deviation(),
            jerk.refinements()
        );
        assert!(r.iter().all(|&x| x <= 1.0), "{feed}: {r:?}");
        assert!(ratio <= 1.25, "{feed}: {ratio}");
        assert!(
            jerk.duration() < 0.98 * unblended.duration(),
            "{feed}: the blend buys time"
        );
        assert!(jerk.blend_deviation() <= opts.blend_tolerance_mm, "{feed}");
        assert!(
            jerk.blend_deviation() > 0.2 * opts.blend_tolerance_mm,
            "{feed}"
        );
        assert_eq!(acc.blend_deviation(), 0.0, "no blend without jerk limits");
        // The set-points against the exact slot: the blend plus the spline's own few um.
        assert!(worst <= opts.blend_tolerance_mm + 0.002, "{feed}: {worst}");
    }
}

#[test]
fn a_negative_blend_tolerance_is_refused() {
    let m = gantry();
    let st = solve_stations(&m, &slot(), None, None, None).expect("reachable");
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.001)).expect("fit");
    for bad in [-0.001, f64::NAN, f64::INFINITY] {
        let opts = PlanOptions::new(20000.0, 0.001).with_blend_tolerance_mm(bad);
        let err = plan(&m, &blocks, &opts).expect_err("refused");
        assert!(
            matches!(err, InterpError::BadParameter { name, .. } if name == "blend_tolerance_mm"),
            "{err}"
        );
    }
}

#[test]
fn a_pose_exactly_on_the_tilt_limit_is_reached_and_never_passed() {
    // A line along X whose tool axis tilts up to a peak and straight back, faster up than down
    // (a lopsided tent: the C2 spline through such stations swings past the peak, by 0.02 degree
    // in the unit test of `smooth.rs`), the tilt range set to exactly the peak station's tilt. One line block per station, so every station is a spline node.
    for jerk in [false, true] {
        let mut m = gantry();
        if !jerk {
            m.limits.max_jerk = None;
        }
        let tips: Vec<Point3<f64>> = (0..=80)
            .map(|i| Point3::new(-40.0 + i as f64, 10.0, 0.0))
            .collect();
        let axes: Vec<Vector3<f64>> = tips
            .iter()
            .map(|p| {
                // Steeper up than down, so that the spline's slope at the peak is not 0.
                let down = if p.x < 0.0 { 0.75 * -p.x } else { 0.25 * p.x };
                let theta = (30.0 - down).to_radians();
                Vector3::new(theta.sin(), 0.0, theta.cos())
            })
            .collect();
        let st = solve_stations(&m, &tips, Some(&axes), None, None).expect("reachable");
        let peak = st
            .iter()
            .map(|s| s.axes[3])
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .expect("stations");
        let range = [-peak.abs(), peak.abs()];
        m.limits.range[3] = Some(range);
        let blocks = one_line_per_pose(&m, &st);
        for feed in [6000.0, 20000.0] {
            let motion = plan(&m, &blocks, &PlanOptions::new(feed, 0.001)).expect("planned");
            let rows = motion.setpoints(&m);
            let (lo, hi) = rows
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), q| {
                    (l.min(q[3]), h.max(q[3]))
                });
            let r = ratios(&m, &rows, 0.001);
            println!(
                "jerk {jerk}, {feed}: tilt {lo:.6} .. {hi:.6} in [{:.6}, {:.6}], limits {r:?}",
                range[0], range[1]
            );
            assert!(
                rows.iter().all(|q| q[3] >= range[0] && q[3] <= range[1]),
                "a set-point outside the tilt range"
            );
            // The peak is reached (within what one cycle at the feed moves the tilt).
            let near = if peak > 0.0 {
                hi - range[1]
            } else {
                range[0] - lo
            };
            assert!(near.abs() < 0.01, "peak {peak}: {lo} .. {hi}");
            assert!(r.iter().all(|&x| x <= 1.0), "{r:?}");
        }
    }
}

/// Distance of `p` from the polyline `poly`.
fn polyline_distance(p: &Point3<f64>, poly: &[Point3<f64>]) -> f64 {
    poly.windows(2)
        .map(|w| {
            let d = w[1] - w[0];
            let t = ((p - w[0]).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
            (p - (w[0] + d * t)).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_long_edge_between_two_corners_stays_straight() {
    // The corner of the fixtures' sheet outline: 160 mm up, 275 mm left, 105 mm down, square
    // corners. Each edge is a run of its own; its end slopes must be its own direction (an
    // estimate from the circle through the edge and the next edge across the corner bent the
    // 275 mm edge 35 mm off the contour). Every set-point on the polyline, with and without jerk.
    let mut m = gantry();
    let tips = [
        Point3::new(40.0, -15.0, 0.0),
        Point3::new(40.0, 145.0, 0.0),
        Point3::new(-235.0, 145.0, 0.0),
        Point3::new(-235.0, 40.0, 0.0),
    ];
    let st = solve_stations(&m, &tips, None, None, None).expect("reachable");
    let blocks = one_line_per_pose(&m, &st);
    for jerk in [true, false] {
        if !jerk {
            m.limits.max_jerk = None;
        }
        let motion = plan(&m, &blocks, &PlanOptions::new(20000.0, 0.001)).expect("plan");
        assert_eq!(motion.runs(), 3, "three edges, three runs");
        let worst = motion
            .iter(&m)
            .map(|q| polyline_distance(&Point3::new(q[0] + m.r_c, q[1], q[2] - m.r_a), &tips))
            .fold(0.0, f64::max);
        println!("jerk {jerk}: largest distance from the edges {worst:.2e} mm");
        assert!(worst < 1e-6, "jerk {jerk}: {worst}");
    }
}

/// Distance of `p` from the contour of the 40 x 20 mm rectangle with 3 mm rounded corners
/// centred on the origin (its signed distance function, in the plane).
fn rounded_rectangle_distance(p: &Point3<f64>) -> f64 {
    let (qx, qy) = (p.x.abs() - 17.0, p.y.abs() - 7.0);
    let outside = (qx.max(0.0).powi(2) + qy.max(0.0).powi(2)).sqrt();
    ((outside + qx.max(qy).min(0.0) - 3.0).powi(2) + p.z.powi(2)).sqrt()
}

#[test]
fn long_edges_between_fine_corners_do_not_make_the_spline_ring() {
    // A rounded rectangle cut as one line per chord: 10 degree chords on the 3 mm corners
    // (0.52 mm), each straight edge two long chords (17 and 7 mm). Where the spline's node
    // spacing jumps from 0.52 mm to 17 mm a C2 spline rings (0.14 mm off the contour here before
    // the spacing was graded; the door trim's switch cut-out swung 0.11 mm off). The set-points
    // must stay within the chords' own sagitta, 3 (1 - cos 5 deg) = 11 um, of the exact contour
    // (plus the blend with jerk limits).
    let mut m = gantry();
    let mut tips = Vec::new();
    let corners = [(17.0, -7.0), (17.0, 7.0), (-17.0, 7.0), (-17.0, -7.0)];
    let mids = [(0.0, -10.0), (20.0, 0.0), (0.0, 10.0), (-20.0, 0.0)];
    tips.push(Point3::new(-17.0, -10.0, 0.0));
    for (k, ((cx, cy), (mx, my))) in corners.iter().zip(mids).enumerate() {
        tips.push(Point3::new(mx, my, 0.0));
        for i in 0..=9 {
            let a = (-90.0 + 90.0 * k as f64 + 10.0 * i as f64).to_radians();
            tips.push(Point3::new(cx + 3.0 * a.cos(), cy + 3.0 * a.sin(), 0.0));
        }
    }
    let st = solve_stations(&m, &tips, None, None, None).expect("reachable");
    let blocks = one_line_per_pose(&m, &st);
    for jerk in [false, true] {
        if !jerk {
            m.limits.max_jerk = None;
        } else {
            m = gantry();
        }
        let opts = PlanOptions::new(6000.0, 0.001);
        let motion = plan(&m, &blocks, &opts).expect("plan");
        println!("{} runs", motion.runs());
        let worst = motion
            .iter(&m)
            .map(|q| rounded_rectangle_distance(&Point3::new(q[0] + m.r_c, q[1], q[2] - m.r_a)))
            .fold(0.0, f64::max);
        println!("jerk {jerk}: largest distance from the rounded rectangle {worst:.2e} mm");
        let sagitta = 3.0 * (1.0 - 5f64.to_radians().cos());
        let blend = if jerk { opts.blend_tolerance_mm } else { 0.0 };
        assert!(worst <= sagitta + blend + 1e-4, "jerk {jerk}: {worst}");
    }
}

#[test]
fn a_jerk_limit_that_cannot_bind_plans_like_none() {
    // A jerk limit of 1e14 mm/s^3 (or an acceleration of 1e300 with a real jerk limit) made
    // the filter width A / J degenerate: the slot was planned for days (the review's dome: 1.3e6
    // s). Within the cycle, an axis' acceleration changes by at most 2 A per cycle, a jerk of
    // 2 A / T < J: the plan is the acceleration-limited one. An acceleration beyond
    // sqrt(2 J V) is unreachable and plans like that bound. Both are verified against every
    // limit by the set-points' own finite differences.
    let mut m = gantry();
    m.limits.max_jerk = None;
    let st = solve_stations(&m, &slot(), None, None, None).expect("reachable");
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(0.001)).expect("fit");
    let opts = PlanOptions::new(20000.0, 0.001);
    let acc = plan(&m, &blocks, &opts).expect("plan").duration();
    for jerk in [1e14, 1e300] {
        let mut j = m.clone();
        j.limits.max_jerk = Some([jerk; 5]);
        let motion = plan(&j, &blocks, &opts).expect("plan");
        let r = ratios(&j, &motion.setpoints(&j), 0.001);
        assert!(r.iter().all(|&x| x <= 1.0), "{jerk}: {r:?}");
        assert!(
            (motion.duration() - acc).abs() <= 0.01 * acc,
            "{jerk}: {} s against {acc} s acceleration-limited",
            motion.duration()
        );
    }
    let mut huge = gantry();
    let jerk: [f64; 5] = huge.limits.max_jerk.expect("jerk");
    huge.limits.max_acceleration = [1e300; 5];
    let motion = plan(&huge, &blocks, &opts).expect("plan");
    let r = ratios(&huge, &motion.setpoints(&huge), 0.001);
    assert!(r.iter().all(|&x| x <= 1.0), "{r:?}");
    // The reachable acceleration's plan: the same limits with A = sqrt(2 J V).
    let mut reach = gantry();
    reach.limits.max_acceleration = std::array::from_fn(|k| {
        (2.0 * jerk[k] * reach.limits.max_velocity[k])
            .sqrt()
            .min(1e300)
    });
    let expected = plan(&reach, &blocks, &opts).expect("plan").duration();
    assert!(
        (motion.duration() - expected).abs() <= 1e-9 * expected,
        "{} s against {expected} s",
        motion.duration()
    );
}
