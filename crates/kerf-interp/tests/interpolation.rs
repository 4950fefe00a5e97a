//! Paper 000's interpolators against analytic positions, eq 19, and the error paths.

#[cfg(feature = "research")]
use kerf_interp::{chord_error, max_feed, paper_eq19};
use kerf_interp::{increments, AxisModel, Block, InterpError, PaperAcHead, Station};
use kerf_kinematics::Axes;
use nalgebra::{Point3, Vector3};

/// Paper 000 eq 16, written out independently of the crate.
fn eq16(m: &PaperAcHead, p: Point3<f64>, a_deg: f64, c_deg: f64) -> Axes {
    let (a, c) = (a_deg.to_radians(), c_deg.to_radians());
    Axes::new(
        p.x + m.r_a * a.sin() * c.sin() - m.r_c * c.cos(),
        p.y - m.r_a * a.sin() * c.cos() - m.r_c * c.sin(),
        p.z + m.r_a * a.cos(),
        a_deg,
        c_deg,
    )
}

fn station(m: &PaperAcHead, p: Point3<f64>, a: f64, c: f64) -> Station {
    Station {
        tip: p,
        axis: m.tool_axis(a, c),
        param: None,
        axes: eq16(m, p, a, c),
    }
}

fn assert_close(got: &Axes, want: &Axes, tol: f64, what: &str) {
    for k in 0..5 {
        assert!(
            (got[k] - want[k]).abs() <= tol,
            "{what}: axis {k}: {} vs {}",
            got[k],
            want[k]
        );
    }
}

#[test]
fn space_line_lands_on_the_analytic_positions() {
    let m = PaperAcHead::paper_000();
    let (p1, p2) = (
        Point3::new(10.0, -20.0, 30.0),
        Point3::new(73.0, 15.0, -12.0),
    );
    let (a1, c1, a2, c2) = (10.0, 200.0, -25.0, 140.0); // both rotary axes decrease
    let b = Block::line(&station(&m, p1, a1, c1), &station(&m, p2, a2, c2));
    let (f, t) = (3000.0, 0.008); // 3 m/min, 8 ms: dl = 0.4 mm
    let rows = b.constant_feed(&m, f, t).expect("interpolates");
    let l = (p2 - p1).norm();
    let dl = f / 60.0 * t;
    assert_eq!(rows.len(), (l / dl).ceil() as usize + 1, "cycles");
    for (i, q) in rows.iter().enumerate() {
        let s = (i as f64 * dl).min(l);
        let dir = (p2 - p1) / l; // eq 2: direction cosines
        let p = p1 + dir * s; // eq 3
        let a = a1 + s / l * (a2 - a1); // eq 4
        let c = c1 + s / l * (c2 - c1);
        assert_close(q, &eq16(&m, p, a, c), 1e-9, &format!("cycle {i}"));
    }
    assert_eq!(
        rows[rows.len() - 1],
        b.end_axes,
        "last step lands exactly on the block end"
    );
    // Increments sum back to the displacement.
    let inc = increments(&rows);
    let sum: f64 = inc.iter().map(|d| d[0]).sum();
    assert!(
        (sum - (b.end_axes[0] - b.start_axes[0])).abs() < 1e-9,
        "increments"
    );
}

#[test]
fn space_arc_lands_on_the_analytic_positions() {
    let m = PaperAcHead::paper_000();
    // Circle of radius 25 about o in a tilted plane (orthonormal e, f).
    let o = Point3::new(5.0, 8.0, -3.0);
    let e = Vector3::new(2.0, 1.0, 2.0) / 3.0;
    let f = Vector3::new(-1.0, 2.0, 0.0) / 5f64.sqrt();
    let r = 25.0;
    let at = |th: f64| o + (e * th.cos() + f * th.sin()) * r;
    let (t1, t2, t3) = (0.3, 1.1, 2.6);
    // Rotary axes: A rises then falls, C falls: eq 9-12 driven by the swept angle.
    let (s1, s2, s3) = (
        station(&m, at(t1), 5.0, 30.0),
        station(&m, at(t2), 40.0, 10.0),
        station(&m, at(t3), 20.0, -50.0),
    );
    let b = Block::arc(&s1, &s2, &s3).expect("arc");
    let (feed, t) = (6000.0, 0.001);
    let rows = b.constant_feed(&m, feed, t).expect("interpolates");
    let dl = feed / 60.0 * t;
    let (a12, a13) = (t2 - t1, t3 - t1);
    assert_eq!(rows.len(), (r * a13 / dl).ceil() as usize + 1, "cycles");
    for (i, q) in rows.iter().enumerate() {
        let th = (i as f64 * dl / r).min(a13); // eq 6: theta_i = sum of dl / R
        let p = at(t1 + th);
        let (a, c) = if th < a12 {
            (5.0 + th / a12 * 35.0, 30.0 + th / a12 * -20.0)
        } else {
            let g = (th - a12) / (a13 - a12);
            (40.0 + g * -20.0, 10.0 + g * -60.0)
        };
        assert_close(q, &eq16(&m, p, a, c), 1e-9, &format!("cycle {i}"));
    }
    assert_eq!(
        rows[rows.len() - 1],
        s3.axes,
        "last step lands exactly on the block end"
    );
    assert_eq!(rows[0], s1.axes, "first set-point is the start");
    // Consecutive blocks: the second starts exactly where the first ended (no drift).
    let b2 = Block::line(&s3, &station(&m, Point3::new(0.0, 0.0, 0.0), 0.0, 0.0));
    let rows2 = b2.constant_feed(&m, feed, t).expect("line");
    assert_eq!(rows2[0], rows[rows.len() - 1], "blocks join exactly");
}

#[test]
fn long_block_does_not_drift() {
    // 2 m at 10 um per cycle: 200,000 cycles; positions from the start, not summed.
    let m = PaperAcHead::paper_000();
    let (p1, p2) = (
        Point3::new(-1000.0, -300.0, 50.0),
        Point3::new(1000.0, 300.0, 50.0),
    );
    let b = Block::line(&station(&m, p1, 0.0, 0.0), &station(&m, p2, 0.0, 0.0));
    let rows = b.constant_feed(&m, 600.0, 0.001).expect("line");
    let l = (p2 - p1).norm();
    let mid = rows.len() / 2;
    let s = mid as f64 * 0.01;
    let want = eq16(&m, p1 + (p2 - p1) * (s / l), 0.0, 0.0);
    assert_close(&rows[mid], &want, 1e-9, "middle");
    assert_eq!(rows[rows.len() - 1], b.end_axes, "end exact");
}

#[test]
#[cfg(feature = "research")]
fn eq19_numbers() {
    // F <= sqrt(225000 (2R - 0.001)) mm/min for T = 8 ms, delta = 1 um (eq 19 with the
    // unit slip corrected), and it equals the general bound 60 * 2 sqrt(d (2R - d)) / T.
    let cases = [
        (0.5, 474.104),
        (1.0, 670.653),
        (5.0, 1499.925),
        (10.0, 2121.267),
        (100.0, 6708.187),
        (1000.0, 21213.198),
    ];
    for (r, f) in cases {
        assert!((paper_eq19(r) - f).abs() < 1e-3, "R {r}: {}", paper_eq19(r));
        assert!(
            (max_feed(r, 0.001, 0.008) - paper_eq19(r)).abs() < 1e-9 * f,
            "R {r}"
        );
        // At that feed the chord error is exactly 1 um (eq 17).
        let dl = f / 60.0 * 0.008;
        assert!(
            (chord_error(r, dl) - 0.001).abs() < 1e-8,
            "R {r}: {}",
            chord_error(r, dl)
        );
    }
    // The printed form sqrt(225000 (2R - 1)) is not that bound: at R = 0.5 mm it allows no
    // feed at all, at R = 10 mm it is 2.5 % low.
    let printed = |r: f64| (225000.0 * (2.0 * r - 1.0)).max(0.0).sqrt();
    assert_eq!(printed(0.5), 0.0, "printed form at R = 0.5");
    assert!(
        (printed(10.0) / paper_eq19(10.0) - 0.9747).abs() < 1e-3,
        "printed form at R = 10"
    );
}

#[test]
fn bad_feed_and_cycle_are_errors() {
    let m = PaperAcHead::paper_000();
    let b = Block::line(
        &station(&m, Point3::origin(), 0.0, 0.0),
        &station(&m, Point3::new(1.0, 0.0, 0.0), 0.0, 0.0),
    );
    for (f, t) in [
        (f64::NAN, 0.001),
        (1000.0, 0.0),
        (-5.0, 0.001),
        (1000.0, f64::INFINITY),
    ] {
        let e = b.constant_feed(&m, f, t);
        assert!(
            matches!(e, Err(InterpError::BadParameter { .. })),
            "F {f} T {t}: {e:?}"
        );
    }
    let e = b.constant_feed(&m, 1e-9, 1e-6);
    assert!(matches!(e, Err(InterpError::TooManyCycles { .. })), "{e:?}");
}

#[test]
fn collinear_arc_falls_back_to_a_line() {
    let m = PaperAcHead::paper_000();
    let s = |x: f64| station(&m, Point3::new(x, 2.0 * x, 0.0), 0.0, 0.0);
    let e = Block::arc(&s(0.0), &s(1.0), &s(2.0));
    assert!(matches!(e, Err(InterpError::CollinearArc { .. })), "{e:?}");
    let b = Block::arc_or_line(&s(0.0), &s(1.0), &s(2.0));
    assert!(!b.is_arc(), "documented fallback: a line");
    assert!((b.length() - 2.0 * 5f64.sqrt()).abs() < 1e-12, "length");
}

#[test]
fn pure_rotation_is_a_turn_block() {
    let m = PaperAcHead::paper_000();
    let p = Point3::new(3.0, 4.0, 5.0);
    let b = Block::line(&station(&m, p, 0.0, 0.0), &station(&m, p, 30.0, -60.0));
    assert!(
        matches!(b.geometry, kerf_interp::Geometry::Turn { .. }),
        "turn"
    );
    assert_eq!(
        b.length(),
        60.0,
        "parameter: the larger rotary travel, degrees"
    );
    let rows = b
        .constant_feed(&m, 6000.0, 0.01)
        .expect("turn at 6000 deg/min"); // 1 deg/cycle
    assert_eq!(rows.len(), 61, "cycles");
    assert_close(&rows[30], &eq16(&m, p, 15.0, -30.0), 1e-9, "half way");
}

#[test]
fn station_and_fit_errors() {
    use kerf_interp::{fit_blocks, solve_stations, FitOptions};
    let m = PaperAcHead::paper_000();
    let tips = [Point3::origin(), Point3::new(1.0, 0.0, 0.0)];
    let e = solve_stations(&m, &[], None, None, None);
    assert!(
        matches!(e, Err(InterpError::TooFewPoints { got: 0, .. })),
        "{e:?}"
    );
    let e = solve_stations(&m, &tips, Some(&[Vector3::z()]), None, None);
    assert!(
        matches!(
            e,
            Err(InterpError::LengthMismatch {
                what: "tool axes",
                ..
            })
        ),
        "{e:?}"
    );
    let e = solve_stations(&m, &tips, None, Some(&[0.0]), None);
    assert!(
        matches!(e, Err(InterpError::LengthMismatch { what: "params", .. })),
        "{e:?}"
    );
    let nan = [Point3::origin(), Point3::new(f64::NAN, 0.0, 0.0)];
    let e = solve_stations(&m, &nan, None, None, None);
    assert!(
        matches!(e, Err(InterpError::NonFinite { index: 1 })),
        "{e:?}"
    );
    // A tool axis pointing down is out of A's range: the kinematics' error with the index.
    let down = [Vector3::z(), -Vector3::z()];
    let e = solve_stations(&m, &tips, Some(&down), None, None);
    assert!(
        matches!(e, Err(InterpError::Kinematics { index: 1, .. })),
        "{e:?}"
    );
    // The kinematics' own error is kept as the source.
    let source = e.as_ref().err().and_then(std::error::Error::source);
    assert!(
        matches!(
            source.and_then(|s| s.downcast_ref::<kerf_kinematics::KinematicsError>()),
            Some(kerf_kinematics::KinematicsError::Unreachable { .. })
        ),
        "{e:?}"
    );
    let st = solve_stations(&m, &tips, None, None, None).expect("stations");
    let e = fit_blocks(&m, &st, None, 0, &FitOptions::with_tolerance(f64::NAN));
    assert!(
        matches!(
            e,
            Err(InterpError::BadParameter {
                name: "tolerance_mm",
                ..
            })
        ),
        "{e:?}"
    );
    let one = fit_blocks(&m, &st[..1], None, 0, &FitOptions::default()).expect("one point");
    assert!(one.is_empty(), "a single point gives no block");
}

mod prop {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// Any arc through three points of a circle: every set-point on the circle, steps of
        /// `F T` (the last shorter), and the end exact.
        #[test]
        fn arcs_stay_on_their_circle(
            r in 0.5f64..500.0,
            t1 in 0.0f64..6.0, d12 in 0.05f64..2.0, d23 in 0.05f64..2.0,
            tilt in -1.0f64..1.0, spin in 0.0f64..6.3,
            feed in 100.0f64..30000.0, cycle in 0.0005f64..0.01,
        ) {
            let m = PaperAcHead::paper_000();
            let e = Vector3::new(spin.cos(), spin.sin(), 0.0);
            let f = Vector3::new(-spin.sin() * tilt.cos(), spin.cos() * tilt.cos(), tilt.sin());
            let o = Point3::new(3.0, -7.0, 11.0);
            let at = |th: f64| o + (e * th.cos() + f * th.sin()) * r;
            let s = |th: f64| station(&m, at(th), 10.0, 20.0);
            let (s1, s3) = (s(t1), s(t1 + d12 + d23));
            let b = Block::arc(&s1, &s(t1 + d12), &s3).expect("arc");
            let dl = feed / 60.0 * cycle;
            prop_assume!(b.length() / dl < 200_000.0);
            let rows = b.constant_feed(&m, feed, cycle).expect("interpolates");
            // Rotary axes constant: X, Y, Z = tip + the head's offset (eq 16 at the origin).
            let off = eq16(&m, Point3::origin(), 10.0, 20.0);
            let tip = |q: &Axes| Point3::new(q[0] - off[0], q[1] - off[1], q[2] - off[2]);
            for w in rows.windows(2) {
                let (p, q) = (tip(&w[0]), tip(&w[1]));
                prop_assert!(((q - o).norm() - r).abs() < 1e-9 * r.max(1.0));
                prop_assert!((q - p).norm() <= dl * (1.0 + 1e-9));
            }
            prop_assert_eq!(rows[rows.len() - 1], s3.axes);
        }
    }
}
