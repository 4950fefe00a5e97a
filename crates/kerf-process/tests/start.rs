//! Start points prepared on the discretization: a polygon of corners starts mid-edge, a pinned
//! `start` parameter becomes a cutting point on the curve; checked against the exact polygon.

use kerf_discretize::{discretize, Discretization, Options};
use kerf_nurbs::NurbsCurve;
use kerf_process::{index_of_param, plan_cuts, prepare_start, Contour, LeadOptions, Pose};
use nalgebra::Point3;

/// A closed degree-1 rectangle `w` x `h` (counter-clockwise from the origin), domain [0, 4].
fn rectangle(w: f64, h: f64) -> NurbsCurve {
    let p = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h), (0.0, 0.0)];
    NurbsCurve::try_new(
        1,
        vec![0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 4.0],
        p.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect(),
        None,
    )
    .expect("rectangle")
}

fn poses(points: &[Point3<f64>]) -> Vec<Pose> {
    points
        .iter()
        .map(|p| Pose::new(p.x, p.y, p.z, 0.0, 0.0, 1.0))
        .collect()
}

#[test]
fn a_polygon_of_corners_starts_in_the_middle_of_its_longest_edge() {
    let c = rectangle(40.0, 10.0);
    let mut d = discretize(&c, &Options::with_tolerance(0.01)).expect("discretize");
    assert_eq!(d.points().len(), 5, "only the corners: {:?}", d.points());
    let t = prepare_start(&c, &mut d, None, &LeadOptions::default(), 0.01).expect("a start");
    assert_eq!(
        t, 0.5,
        "the middle of the first 40 mm edge (parameters 0..1)"
    );
    assert_eq!(d.points().len(), 6, "one point inserted");
    let i = index_of_param(d.params(), t);
    assert!(
        (d.points()[i] - Point3::new(20.0, 0.0, 0.0)).norm() < 1e-12,
        "{:?}",
        d.points()[i]
    );
    // The plan starts there, off every corner, with its lead-in outside the rectangle.
    let p = poses(d.points());
    let contour = Contour {
        id: "rect",
        poses: &p,
        scrap: None,
        start: Some(i),
    };
    let plan = plan_cuts(&[contour], &LeadOptions::default()).expect("plan");
    assert_eq!(plan.leads[0].start, i, "the pinned start");
    assert!(!plan.leads[0].pierce_on_contour, "a full lead-in fits");
    for q in &plan.leads[0].lead_in {
        assert!(
            q.position.y < -1e-9,
            "the lead-in lies outside (below the bottom edge): {q:?}"
        );
    }
}

#[test]
fn a_pinned_start_becomes_a_cutting_point_on_the_curve() {
    let c = rectangle(40.0, 10.0);
    let mut d = discretize(&c, &Options::with_tolerance(0.01)).expect("discretize");
    let before = d.max_chord_error();
    let t = prepare_start(&c, &mut d, Some(2.25), &LeadOptions::default(), 0.01).expect("a start");
    assert_eq!(t, 2.25, "the pinned parameter");
    let i = index_of_param(d.params(), t);
    // C(2.25) on the top edge from (40, 10) to (0, 10): a quarter along it.
    assert!(
        (d.points()[i] - Point3::new(30.0, 10.0, 0.0)).norm() < 1e-12,
        "{:?}",
        d.points()[i]
    );
    assert!(d.max_chord_error() <= before, "the certified bound holds");
    // The end of the domain is its start; an existing cutting point is not duplicated.
    let n = d.points().len();
    assert_eq!(
        prepare_start(&c, &mut d, Some(4.0), &LeadOptions::default(), 0.01),
        Some(0.0),
        "t = 4 is t = 0"
    );
    assert_eq!(
        prepare_start(&c, &mut d, Some(1.0), &LeadOptions::default(), 0.01),
        Some(1.0),
        "a corner pinned"
    );
    assert_eq!(d.points().len(), n, "nothing inserted");
}

#[test]
fn smooth_or_open_curves_are_left_to_the_plan() {
    // An open line: nothing to prepare.
    let line = NurbsCurve::try_new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Point3::origin(), Point3::new(10.0, 0.0, 0.0)],
        None,
    )
    .expect("line");
    let mut d = discretize(&line, &Options::with_tolerance(0.01)).expect("discretize");
    assert_eq!(
        prepare_start(&line, &mut d, None, &LeadOptions::default(), 0.01),
        None,
        "open"
    );
    // A full circle (rational quadratic): smooth stretches everywhere, the plan chooses.
    let w = std::f64::consts::FRAC_1_SQRT_2;
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
    let circle = NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0],
        pts.iter()
            .map(|&(x, y)| Point3::new(10.0 * x, 10.0 * y, 0.0))
            .collect(),
        Some(vec![1.0, w, 1.0, w, 1.0, w, 1.0, w, 1.0]),
    )
    .expect("circle");
    let mut d = discretize(&circle, &Options::with_tolerance(0.01)).expect("discretize");
    let n = d.points().len();
    assert_eq!(
        prepare_start(&circle, &mut d, None, &LeadOptions::default(), 0.01),
        None,
        "smooth"
    );
    assert_eq!(d.points().len(), n, "untouched");
}

#[test]
fn a_pinned_start_certifies_only_its_two_new_chords() {
    // A circle of radius 100 at 0.001 mm: about 700 cutting points. Pinning a start between
    // two of them costs a handful of evaluations (the two new chords), not a certificate of
    // every segment again; the exact chord error of each new chord, `r (1 - cos(a / 2))` for
    // the angle `a` it spans, is within the certified bound the discretization then claims.
    let r = 100.0;
    let circle = NurbsCurve::circle(Point3::origin(), nalgebra::Vector3::z(), r).expect("circle");
    let tol = 0.001;
    let mut d = discretize(&circle, &Options::with_tolerance(tol)).expect("discretize");
    let n = d.points().len();
    assert!(n > 500, "{n} points");
    let i = n / 3;
    let want =
        0.5 * (d.params()[i] + d.params()[i + 1]) + 1e-3 * (d.params()[i + 1] - d.params()[i]);
    let (t, evaluations) = kerf_nurbs::counted(|| {
        prepare_start(&circle, &mut d, Some(want), &LeadOptions::default(), tol)
    });
    assert_eq!(t, Some(want), "inserted");
    assert_eq!(d.points().len(), n + 1);
    let evaluations = evaluations.expect("kerf-nurbs counts evaluations in this test");
    // Certifying every segment again evaluates each cutting point at least once.
    let (_, all) = kerf_nurbs::counted(|| Discretization::certify(&circle, d.params(), tol));
    let all = all.expect("counted");
    assert!(all >= n as u64, "{all}");
    assert!(
        evaluations < 100,
        "{evaluations} evaluations (certifying all: {all})"
    );
    // Exact chord errors of the two new chords, from the angles of their ends.
    let angle = |p: &Point3<f64>| p.y.atan2(p.x);
    let j = index_of_param(d.params(), want);
    for k in [j - 1, j] {
        let (a, b) = (d.points()[k], d.points()[k + 1]);
        assert!((a.coords.norm() - r).abs() < 1e-9 && (b.coords.norm() - r).abs() < 1e-9);
        let mut span = (angle(&b) - angle(&a)).abs();
        if span > std::f64::consts::PI {
            span = std::f64::consts::TAU - span;
        }
        let exact = r * (1.0 - (0.5 * span).cos());
        assert!(
            exact <= d.max_chord_error(),
            "{exact} against {}",
            d.max_chord_error()
        );
        assert!(d.max_chord_error() <= tol);
    }
}
