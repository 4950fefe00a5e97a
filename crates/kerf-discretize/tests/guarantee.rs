//! The chord-error guarantee, checked by an independent brute force.

mod common;

use common::{arc, brute_chord_error, check, random_curve};
use kerf_discretize::{discretize, minimum_count, Options, Strategy};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use proptest::prelude::*;

#[test]
fn single_span_arcs_have_the_exact_circle_count() {
    for &(r, phi_deg, tol) in &[
        (50.0, 90.0, 0.01),
        (50.0, 170.0, 0.001),
        (3.0, 120.0, 0.01),
        (1000.0, 60.0, 0.001),
        (7.5, 150.0, 0.1),
    ] {
        let phi = f64::to_radians(phi_deg);
        let c = arc(r, phi);
        let opts = Options::with_tolerance(tol).with_band(0.999);
        let d = discretize(&c, &opts).unwrap();
        check(&c, &d, tol);
        let theta = 2.0 * (1.0 - tol / r).acos();
        let exact = (phi / theta).ceil() as usize;
        let n = d.segments();
        assert!(
            n == exact || n == exact + 1,
            "r={r} phi={phi_deg} tol={tol}: {n} segments, circle formula {exact}"
        );
    }
}

#[test]
fn a_straight_line_is_one_segment_or_what_max_length_demands() {
    let line = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Point3::new(0.0, 0.0, 0.0), Point3::new(100.0, 20.0, -5.0)],
        None,
    );
    let d = discretize(&line, &Options::with_tolerance(0.001)).unwrap();
    assert_eq!(d.segments(), 1, "a line needs one segment");
    let cubic_line = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
            Point3::new(70.0, 0.0, 0.0),
            Point3::new(100.0, 0.0, 0.0),
        ],
        None,
    );
    let d = discretize(&cubic_line, &Options::with_tolerance(0.001)).unwrap();
    assert_eq!(d.segments(), 1, "a straight cubic needs one segment");
    let opts = Options::with_tolerance(0.001).with_max_segment_length_mm(7.0);
    let d = discretize(&line, &opts).unwrap();
    let len = (100.0f64 * 100.0 + 400.0 + 25.0).sqrt();
    assert_eq!(
        d.segments(),
        (len / 7.0).ceil() as usize,
        "max segment length"
    );
    for w in d.points().windows(2) {
        assert!(
            (w[1] - w[0]).norm() <= 7.0 + 1e-9,
            "segment longer than the maximum"
        );
    }
}

#[test]
fn c0_corners_are_cutting_points() {
    // A cubic with a corner: interior knot of multiplicity 3.
    let c = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 5.0, 0.0),
            Point3::new(20.0, 5.0, 0.0),
            Point3::new(30.0, 0.0, 0.0),
            Point3::new(30.0, 10.0, 3.0),
            Point3::new(35.0, 20.0, 0.0),
            Point3::new(40.0, 30.0, 0.0),
        ],
        None,
    );
    let d = discretize(&c, &Options::with_tolerance(0.01)).unwrap();
    check(&c, &d, 0.01);
    assert!(d.params().contains(&0.5), "the corner is a cutting point");
}

fn full_circle(r: f64) -> NurbsCurve {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let pts = [
        (1.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (-1.0, 1.0),
        (-1.0, 0.0),
        (-1.0, -1.0),
        (0.0, -1.0),
        (1.0, -1.0),
        (1.0, 0.0),
    ];
    NurbsCurve::new(
        2,
        vec![
            0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
        ],
        pts.iter()
            .map(|&(x, y)| Point3::new(r * x, r * y, 0.0))
            .collect(),
        Some(vec![1.0, h, 1.0, h, 1.0, h, 1.0, h, 1.0]),
    )
}

#[test]
fn full_circle_of_four_spans() {
    let c = full_circle(50.0);
    for tol in [0.1, 0.01, 0.001] {
        let d = discretize(&c, &Options::with_tolerance(tol)).unwrap();
        check(&c, &d, tol);
        // Every accepted segment has an error in the band [0.9 tol, tol].
        let theta = 2.0 * (1.0 - 0.9 * tol / 50.0).acos();
        let per_quarter = (std::f64::consts::FRAC_PI_2 / theta).ceil() as usize;
        assert!(
            d.segments() <= 4 * (per_quarter + 1),
            "tol {tol}: {} segments",
            d.segments()
        );
    }
}

#[test]
fn every_strategy_keeps_the_guarantee() {
    let c = full_circle(20.0);
    let mut counts = Vec::new();
    for s in [
        Strategy::ReferenceSphere,
        Strategy::EqualError,
        Strategy::EqualParameter,
        Strategy::EqualChordLength,
    ] {
        let opts = Options::with_tolerance(0.01).with_strategy(s);
        let d = discretize(&c, &opts).unwrap();
        check(&c, &d, 0.01);
        counts.push(d.segments());
    }
    let nstar = minimum_count(&c, 0.01);
    assert!(
        counts[0] as f64 <= 1.1 * nstar + 4.0,
        "reference sphere near N*: {counts:?} vs {nstar}"
    );
}

#[test]
fn hostile_curves_finish_and_hold_the_guarantee() {
    let tol = 0.01;
    // Hairpin: goes out and comes straight back.
    let hairpin = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(100.0, 0.0, 0.0),
            Point3::new(100.0, 0.1, 0.0),
            Point3::new(0.0, 0.1, 0.0),
        ],
        None,
    );
    // A loop crossing itself.
    let looped = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(30.0, 30.0, 0.0),
            Point3::new(-10.0, 30.0, 0.0),
            Point3::new(20.0, 0.0, 0.0),
        ],
        None,
    );
    // A cusp: C'(0.5) = 0 by symmetric control points.
    let cusp = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(20.0, 20.0, 0.0),
            Point3::new(-10.0, 20.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
        ],
        None,
    );
    // Repeated control points: zero first derivative at the start.
    let repeated = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 5.0, 0.0),
            Point3::new(20.0, 0.0, 1.0),
        ],
        None,
    );
    // 1e6:1 weights.
    let heavy = NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 10.0, 0.0),
            Point3::new(20.0, -10.0, 5.0),
            Point3::new(30.0, 0.0, 0.0),
        ],
        Some(vec![1.0, 1e6, 1.0, 1e-0]),
    );
    // 1,000 control points in a cluster.
    let mut s = 12345u64;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<Point3<f64>> = (0..1000)
        .map(|_| Point3::new(rnd() * 0.01, rnd() * 0.01, rnd() * 0.01))
        .collect();
    let mut knots = vec![0.0; 4];
    knots.extend((1..997).map(|i| i as f64 / 997.0));
    knots.extend([1.0; 4]);
    let cluster = NurbsCurve::new(3, knots, pts, None);
    // Zero-length piece: all control points equal.
    let dot = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![Point3::new(1.0, 2.0, 3.0); 3],
        None,
    );
    for (name, c) in [
        ("hairpin", hairpin),
        ("loop", looped),
        ("cusp", cusp),
        ("repeated", repeated),
        ("heavy", heavy),
        ("cluster", cluster),
        ("dot", dot),
    ] {
        let d =
            discretize(&c, &Options::with_tolerance(tol)).unwrap_or_else(|e| panic!("{name}: {e}"));
        check(&c, &d, tol);
    }
}

#[test]
fn same_output_sequential_and_parallel() {
    let curves: Vec<NurbsCurve> = (0..16).map(|i| full_circle(5.0 + i as f64)).collect();
    let opts = Options::with_tolerance(0.001);
    let par = kerf_discretize::discretize_all(&curves, &opts);
    for (c, p) in curves.iter().zip(par) {
        let s = discretize(c, &opts).unwrap();
        assert_eq!(s, p.unwrap(), "parallel result differs from sequential");
    }
}

#[test]
fn brute_force_checker_sees_a_known_sagitta() {
    // Sanity of the test's own checker: a half circle's chord has sagitta r.
    let c = arc(10.0, std::f64::consts::FRAC_PI_2);
    let (a, b) = (c.point(0.0), c.point(1.0));
    let e = brute_chord_error(&c, 0.0, 1.0, &a, &b);
    let exact = 10.0 * (1.0 - std::f64::consts::FRAC_PI_4.cos());
    assert!((e - exact).abs() < 1e-9, "checker: {e} vs {exact}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

    #[test]
    fn random_curves_hold_the_guarantee(c in random_curve(), tol_exp in 1u32..4) {
        let tol = 10f64.powi(-(tol_exp as i32));
        let d = discretize(&c, &Options::with_tolerance(tol)).unwrap();
        check(&c, &d, tol);
    }
}

#[test]
fn a_range_keeps_its_ends_inner_breaks_and_the_guarantee() {
    let c = full_circle(30.0);
    let d =
        kerf_discretize::discretize_range(&c, 0.1, 0.6, &Options::with_tolerance(0.001)).unwrap();
    assert_eq!(d.params()[0], 0.1, "starts at a");
    assert_eq!(*d.params().last().unwrap(), 0.6, "ends at b");
    assert!(
        d.params().contains(&0.25) && d.params().contains(&0.5),
        "inner breaks kept"
    );
    assert!(!d.params().contains(&0.75), "outer break not added");
    for i in 1..d.params().len() {
        let e = brute_chord_error(
            &c,
            d.params()[i - 1],
            d.params()[i],
            &d.points()[i - 1],
            &d.points()[i],
        );
        assert!(e <= 0.001, "segment {i}: {e}");
    }
    assert!(
        kerf_discretize::discretize_range(&c, 0.6, 0.1, &Options::default()).is_err(),
        "reversed range refused"
    );
}
