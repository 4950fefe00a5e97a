//! Options and error paths.

mod common;

use common::{arc, check};
use kerf_discretize::{discretize, DiscretizeError, Options};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

#[test]
fn every_bad_option_is_named() {
    let c = arc(10.0, 1.0);
    let cases: Vec<(Options, &str)> = vec![
        (Options::with_tolerance(0.0), "tolerance_mm"),
        (Options::with_tolerance(-1.0), "tolerance_mm"),
        (Options::with_tolerance(f64::NAN), "tolerance_mm"),
        (Options::with_tolerance(f64::INFINITY), "tolerance_mm"),
        (Options::default().with_band(1.0), "band"),
        (Options::default().with_band(0.0), "band"),
        (
            Options::default().with_max_segment_length_mm(0.0),
            "max_segment_length_mm",
        ),
        (
            Options::default().with_min_segment_length_mm(f64::NAN),
            "min_segment_length_mm",
        ),
        (
            Options::default()
                .with_min_segment_length_mm(5.0)
                .with_max_segment_length_mm(1.0),
            "min_segment_length_mm",
        ),
        (Options::default().with_max_turn_deg(-1.0), "max_turn_deg"),
    ];
    for (opts, name) in cases {
        match discretize(&c, &opts) {
            Err(DiscretizeError::BadOption { name: n, .. }) => assert_eq!(n, name, "option named"),
            other => panic!("{name}: expected BadOption, got {other:?}"),
        }
    }
}

#[test]
fn max_turn_limits_the_tangent_turn_per_segment() {
    let c = arc(100.0, 2.0);
    let opts = Options::with_tolerance(0.1).with_max_turn_deg(0.05f64.to_degrees());
    let d = discretize(&c, &opts).unwrap();
    check(&c, &d, 0.1);
    for w in d.params().windows(2) {
        // The turn between the end tangents of each segment.
        let u = c.tangent(w[0]).unwrap();
        let v = c.tangent(w[1]).unwrap();
        assert!(u.angle(&v) <= 0.05 + 1e-9, "turn {} > 0.05", u.angle(&v));
    }
    let free = discretize(&c, &Options::with_tolerance(0.1)).unwrap();
    assert!(d.segments() > free.segments(), "the turn limit adds points");
}

#[test]
fn min_segment_length_keeps_proposals_long_but_tolerance_wins() {
    let c = arc(5.0, 2.5);
    let opts = Options::with_tolerance(0.01).with_min_segment_length_mm(3.0);
    let d = discretize(&c, &opts).unwrap();
    check(&c, &d, 0.01);
}

#[test]
fn a_jump_is_a_clear_error() {
    // Knot 0.5 of multiplicity degree + 1 = 3 with different points on either side.
    let c = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(5.0, 0.0, 0.0),
            Point3::new(6.0, 1.0, 0.0),
            Point3::new(7.0, 0.0, 0.0),
        ],
        None,
    );
    match discretize(&c, &Options::with_tolerance(0.01)) {
        Err(DiscretizeError::Discontinuous { t, gap }) => {
            assert_eq!(t, 0.5, "jump parameter");
            assert!((gap - 3.0).abs() < 1e-12, "gap {gap}");
        }
        other => panic!("expected Discontinuous, got {other:?}"),
    }
}

#[test]
fn a_joined_multiplicity_p_plus_one_knot_is_fine() {
    // Same knot structure, but both sides meet: a C0 corner written with p + 1 knots.
    let c = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(3.0, 1.0, 0.0),
            Point3::new(4.0, 0.0, 0.0),
        ],
        None,
    );
    let d = discretize(&c, &Options::with_tolerance(0.001)).unwrap();
    check(&c, &d, 0.001);
}

#[test]
fn too_many_points_is_refused_before_work() {
    let c = arc(1000.0, 3.0);
    let opts = Options::with_tolerance(1e-7).with_max_points(1000);
    assert!(
        matches!(
            discretize(&c, &opts),
            Err(DiscretizeError::TooManyPoints { limit: 1000, .. })
        ),
        "limit enforced"
    );
}

#[test]
fn a_tolerance_below_double_precision_is_an_error() {
    // A small arc one billion millimetres from the origin: coordinates carry ~1e-7 mm of
    // rounding, so 1e-12 mm cannot be certified; the margin is known before the walk.
    let far = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(1e9, 0.0, 0.0),
            Point3::new(1e9 + 1.0, 1.0, 0.0),
            Point3::new(1e9 + 2.0, 0.0, 0.0),
        ],
        None,
    );
    let r = discretize(&far, &Options::with_tolerance(1e-12));
    assert!(
        matches!(r, Err(DiscretizeError::ToleranceBelowMargin { margin, .. }) if margin > 1e-7),
        "got {r:?}"
    );
}
