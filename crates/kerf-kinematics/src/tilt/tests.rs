use super::*;

fn pose(x: f64, y: f64, axis: Vector3<f64>) -> Pose {
    Pose {
        position: nalgebra::Point3::new(x, y, 0.0),
        axis: axis.normalize(),
    }
}

/// The unit axis at `tilt_deg` from +z toward azimuth `azimuth_deg`.
fn axis(tilt_deg: f64, azimuth_deg: f64) -> Vector3<f64> {
    let (t, c) = (tilt_deg.to_radians(), azimuth_deg.to_radians());
    Vector3::new(t.sin() * c.cos(), t.sin() * c.sin(), t.cos())
}

/// Every chosen axis within the tolerance of its own normal, measured directly.
fn assert_in_cone(poses: &[Pose], choice: &TiltChoice, tolerance_deg: f64) {
    for (i, (p, u)) in poses.iter().zip(&choice.axes).enumerate() {
        assert!((u.norm() - 1.0).abs() < 1e-12, "pose {i}: unit axis");
        let dev = p.axis.angle(u).to_degrees();
        assert!(
            dev <= tolerance_deg + 1e-9,
            "pose {i}: {dev} deg off the normal"
        );
    }
}

#[test]
fn no_tolerance_keeps_the_normals() {
    let poses: Vec<Pose> = (0..10)
        .map(|i| pose(i as f64, 0.0, axis(20.0 + i as f64, 5.0 * i as f64)))
        .collect();
    let choice = tilt_within_cone(&poses, 0.0);
    for (p, u) in poses.iter().zip(&choice.axes) {
        assert_eq!(p.axis, *u);
    }
    assert_eq!(choice.report.max_deviation_deg, 0.0);
}

/// A line whose normal circles the pole at 2 degrees: the exact axes need a full turn of C;
/// a 3-degree cone contains the pole everywhere, so C need not turn at all.
#[test]
fn near_the_pole_c_is_held() {
    let poses: Vec<Pose> = (0..=360)
        .map(|i| pose(i as f64, 0.0, axis(2.0, i as f64)))
        .collect();
    let choice = tilt_within_cone(&poses, 3.0);
    assert_in_cone(&poses, &choice, 3.0);
    let r = choice.report;
    assert!(r.rotary_travel_exact_deg > 359.0, "{r:?}");
    // The chosen azimuths (modulo 180, with signed tilt) never move: all the change is tilt.
    let c = Coords::of(&choice.axes);
    let c_travel: f64 = c.c.windows(2).map(|w| (w[1] - w[0]).abs()).sum();
    assert!(
        c_travel.to_degrees() < 1e-6,
        "C travel {}",
        c_travel.to_degrees()
    );
    assert!(r.rotary_travel_deg < 10.0, "{r:?}");
}

/// Normals wiggling +-0.5 degree about a 30-degree tilt: a 1-degree cone holds the axis still.
#[test]
fn small_wiggles_are_not_chased() {
    let poses: Vec<Pose> = (0..200)
        .map(|i| {
            let w = 0.5 * (i as f64 * 0.7).sin();
            pose(i as f64, 0.0, axis(30.0 + w, 40.0 + w))
        })
        .collect();
    let choice = tilt_within_cone(&poses, 1.0);
    assert_in_cone(&poses, &choice, 1.0);
    let r = choice.report;
    assert!(r.rotary_travel_exact_deg > 50.0, "{r:?}");
    assert!(r.rotary_travel_deg < 1e-4, "{r:?}");
}

/// A crease: the normal jumps 30 degrees at one point. With a 2-degree cone the axis turns
/// over the distance where both cones allow it and, at the point itself, by the least angle
/// the cones leave (30 - 2 * 2 = 26 degrees, up to the working fraction).
#[test]
fn a_crease_turns_by_the_least_angle() {
    let mut poses: Vec<Pose> = (0..50)
        .map(|i| pose(i as f64, 0.0, axis(10.0, 0.0)))
        .collect();
    poses.extend((0..50).map(|i| pose(49.0 + i as f64, 0.0, axis(40.0, 0.0))));
    let choice = tilt_within_cone(&poses, 2.0);
    assert_in_cone(&poses, &choice, 2.0);
    let jump = choice.axes[49].angle(&choice.axes[50]).to_degrees();
    let least = 30.0 - 2.0 * 2.0 * TILT_WORKING_FRACTION;
    assert!((jump - least).abs() < 1e-9, "jump {jump}, least {least}");
    // Away from the crease the axis is held: no motion at all within each face.
    for i in 1..49 {
        assert!(
            choice.axes[i - 1].angle(&choice.axes[i]) < 1e-12,
            "pose {i}"
        );
    }
}

/// Two faces whose cones overlap (a 3-degree crease, 2-degree cones): the axis passes the
/// crease without turning at the point.
#[test]
fn a_shallow_crease_is_smoothed_over_a_distance() {
    let mut poses: Vec<Pose> = (0..20)
        .map(|i| pose(i as f64, 0.0, axis(20.0, 0.0)))
        .collect();
    poses.extend((0..20).map(|i| pose(19.0 + i as f64, 0.0, axis(23.0, 0.0))));
    let choice = tilt_within_cone(&poses, 2.0);
    assert_in_cone(&poses, &choice, 2.0);
    assert!(choice.axes[19].angle(&choice.axes[20]) < 1e-12);
    assert!(
        choice.report.rotary_travel_deg < 1e-6,
        "{:?}",
        choice.report
    );
}

/// The taut string against an independent solution of the same problem: the least Dirichlet
/// energy `sum (dy)^2 / dx` within the intervals, found by projected Gauss-Seidel to
/// convergence (the taut string minimises every convex functional of the slope, this one
/// included).
#[test]
fn taut_string_matches_the_least_energy_curve() {
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for case in 0..40 {
        let n = 3 + case % 17;
        let mut x = 0.0;
        let gates: Vec<Gate> = (0..n)
            .map(|i| {
                x += 0.2 + rnd();
                let centre = 3.0 * (i as f64 * 0.9).sin() + rnd();
                let half = 0.1 + rnd();
                Gate {
                    x,
                    lo: centre - half,
                    hi: centre + half,
                    first: i,
                    last: i,
                }
            })
            .collect();
        let mut work = 0;
        let y = taut_string(&gates, usize::MAX, &mut work).expect("within budget");
        // Projected Gauss-Seidel on the energy, free ends.
        let mut z: Vec<f64> = gates.iter().map(|g| 0.5 * (g.lo + g.hi)).collect();
        for _ in 0..200_000 {
            for i in 0..n {
                let (mut num, mut den) = (0.0, 0.0);
                if i > 0 {
                    let w = 1.0 / (gates[i].x - gates[i - 1].x);
                    num += w * z[i - 1];
                    den += w;
                }
                if i + 1 < n {
                    let w = 1.0 / (gates[i + 1].x - gates[i].x);
                    num += w * z[i + 1];
                    den += w;
                }
                z[i] = (num / den).clamp(gates[i].lo, gates[i].hi);
            }
        }
        for i in 0..n {
            assert!(
                y[i] >= gates[i].lo && y[i] <= gates[i].hi,
                "case {case} gate {i}"
            );
            assert!(
                (y[i] - z[i]).abs() < 1e-3,
                "case {case} gate {i}: string {} energy {}",
                y[i],
                z[i]
            );
        }
        assert!(work <= 4 * (n + 2) * (n + 2), "case {case}: work {work}");
    }
}

/// The work is counted and bounded: a long path of alternating narrow gates (every one a
/// bend) stays within the budget, and a budget too small for a string falls back to the
/// normals (still in the cone) and says so.
#[test]
fn work_is_bounded_and_counted() {
    let poses: Vec<Pose> = (0..20_000)
        .map(|i| {
            let w = if i % 2 == 0 { 3.0 } else { -3.0 };
            pose(i as f64, 0.0, axis(30.0 + w, 10.0 * w))
        })
        .collect();
    let choice = tilt_within_cone(&poses, 1.0);
    assert_in_cone(&poses, &choice, 1.0);
    let r = choice.report;
    assert_eq!(r.strings_over_budget, 0);
    assert!(
        r.work <= 2 * (STRING_WORK_FLOOR + STRING_WORK_PER_GATE * 20_000),
        "{r:?}"
    );
    assert!(r.work >= 2 * 20_000, "every gate visited: {r:?}");

    let gates: Vec<Gate> = (0..1000)
        .map(|i| Gate {
            x: i as f64,
            lo: (i % 2) as f64,
            hi: (i % 2) as f64 + 0.1,
            first: i,
            last: i,
        })
        .collect();
    let mut work = 0;
    assert!(taut_string(&gates, 100, &mut work).is_none());
    assert_eq!(work, 101, "stops at the first visit past the budget");
}
