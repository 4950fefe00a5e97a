//! `Discretization::certify`: the only way besides the discretizer to make a `Discretization`
//! (its fields are private), so a claimed set of cutting parameters (e.g. read back from a
//! toolpath file) becomes a certificate only after every segment has been proven.

mod common;

use kerf_discretize::{discretize, Discretization, DiscretizeError, Options};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

fn circle(r: f64) -> NurbsCurve {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let pts = [
        (r, 0.0),
        (r, r),
        (0.0, r),
        (-r, r),
        (-r, 0.0),
        (-r, -r),
        (0.0, -r),
        (r, -r),
        (r, 0.0),
    ];
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 1., 1., 2., 2., 3., 3., 4., 4., 4.],
        pts.iter().map(|&(x, y)| Point3::new(x, y, 0.0)).collect(),
        Some(vec![1.0, h, 1.0, h, 1.0, h, 1.0, h, 1.0]),
    )
}

#[test]
fn the_discretizers_own_parameters_certify_and_the_bound_holds_by_brute_force() {
    for c in kerf_nurbs::smooth_random_curves(4, 6, 3) {
        let d = discretize(&c, &Options::with_tolerance(0.01)).expect("discretizes");
        let again = Discretization::certify(&c, d.params(), 0.01).expect("certifies");
        assert_eq!(again.params(), d.params(), "same parameters");
        // Evaluated by `point` (the walk's come from `eval_d1`: the same up to rounding).
        for (p, q) in again.points().iter().zip(d.points()) {
            assert!((p - q).norm() <= 1e-12, "points evaluated on the curve");
        }
        assert!(again.max_chord_error() <= 0.01, "certified");
        // The independent brute force of tests/common agrees with the claim.
        let worst = common::check(&c, &again, 0.01);
        assert!(worst <= again.max_chord_error(), "bound {worst} above");
    }
}

#[test]
fn a_claim_that_is_too_coarse_is_refused_with_the_segment() {
    let c = circle(50.0);
    // Equal parameter steps of 0.25 on an r = 50 circle: the first chord spans the angle of
    // C(0.25) (21.6 degrees: the rational parametrization is not uniform in angle), so its
    // true chord error is the sagitta 50 (1 - cos(angle / 2)) = 0.8855 mm.
    let params: Vec<f64> = (0..=16).map(|i| i as f64 * 0.25).collect();
    let q = c.point(0.25);
    let sagitta = 50.0 * (1.0 - (0.5 * q.y.atan2(q.x)).cos());
    match Discretization::certify(&c, &params, 0.01) {
        Err(DiscretizeError::NotCertified { index, bound, .. }) => {
            assert_eq!(index, 0, "the first segment fails");
            assert!(
                bound >= sagitta,
                "bound {bound} at least the sagitta {sagitta}"
            );
        }
        other => panic!("expected NotCertified, got {other:?}"),
    }
    // Fine enough: 0.01 steps are 0.9 degree, sagitta 50 (1 - cos(0.45 deg)) = 1.5e-3 mm.
    let fine: Vec<f64> = (0..=400).map(|i| i as f64 * 0.01).collect();
    let d = Discretization::certify(&c, &fine, 0.01).expect("certifies");
    assert!(d.max_chord_error() <= 0.01, "certified");
    assert!(d.max_chord_error() >= 1.5e-3, "at least the true sagitta");
}

#[test]
fn malformed_parameters_are_refused() {
    let c = circle(10.0);
    let cases: [(&[f64], &str); 4] = [
        (&[0.0], "two"),
        (&[0.0, 2.0, 2.0, 4.0], "increasing"),
        (&[0.5, 4.0], "ends"),
        (&[0.0, 3.0, 2.0, 4.0], "increasing"),
    ];
    for (params, word) in cases {
        match Discretization::certify(&c, params, 1.0) {
            Err(e @ DiscretizeError::NotCertified { .. }) => {
                assert!(e.to_string().contains(word), "{e}")
            }
            other => panic!("{params:?}: expected NotCertified, got {other:?}"),
        }
    }
    assert!(
        matches!(
            Discretization::certify(&c, &[0.0, 4.0], f64::NAN),
            Err(DiscretizeError::BadOption { .. })
        ),
        "NaN tolerance"
    );
}

#[test]
fn a_missing_c0_break_is_refused() {
    // An L: a degree-1 polyline, whose interior knot t = 0.5 is a C0 break (the corner).
    let c = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 0.5, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(10.0, 0.0, 0.0),
            Point3::new(10.0, 10.0, 0.0),
        ],
        None,
    );
    match Discretization::certify(&c, &[0.0, 0.25, 1.0], 0.01) {
        Err(e @ DiscretizeError::NotCertified { .. }) => {
            assert!(e.to_string().contains("C0 break"), "{e}")
        }
        other => panic!("expected NotCertified, got {other:?}"),
    }
    let d = Discretization::certify(&c, &[0.0, 0.5, 1.0], 0.01).expect("certifies");
    assert_eq!(d.c0_breaks(), &[0.5], "the corner");
    assert!(d.max_chord_error() < 1e-9, "straight legs");
}
