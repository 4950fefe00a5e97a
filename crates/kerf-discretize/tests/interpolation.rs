//! The interpolation certificate (`docs/discretization.md`, "The interpolation certificate"):
//! a segment inside one knot span is bounded from its middle point and the span's hodographs,
//! without subdivision. Checked against the independent dense brute force of `tests/common`:
//! never below it (on strongly rational random curves too), and tight where the hull bound is
//! not (exact on parabolas, within a fraction of a percent on short steps of smooth curves),
//! at a counted cost of at most three evaluations.

mod common;

use common::{brute_chord_error, random_curve};
use kerf_discretize::{Certifier, Scratch};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use proptest::prelude::*;

/// The bound of `[t0, t1]` with the curve's own end points, asking for nothing (`limit`
/// infinite, no lower edge): the first certificate that applies answers.
fn bound(c: &NurbsCurve, t0: f64, t1: f64) -> (f64, f64) {
    let cert = Certifier::new(c);
    let (a, b) = (c.point(t0), c.point(t1));
    let bd = cert.chord_error(&mut Scratch::default(), t0, t1, &a, &b, f64::INFINITY, 0.0);
    (bd.upper, brute_chord_error(c, t0, t1, &a, &b))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Any curve (degrees 1-7, weights 0.05-20, repeated knots), any step inside a span, from
    /// a thousandth of the span to all of it: the bound is never below the true chord error.
    #[test]
    fn never_below_the_dense_maximum(c in random_curve(), at in 0.0f64..1.0, frac in -3.0f64..0.0) {
        let spans = c.spans();
        let (_, lo, hi) = spans[(at * spans.len() as f64) as usize % spans.len()];
        let len = (hi - lo) * 10f64.powf(frac);
        let t0 = lo + (hi - lo - len) * at;
        let t1 = (t0 + len).min(hi);
        prop_assume!(t1 > t0);
        let (upper, brute) = bound(&c, t0, t1);
        let scale = c.size().max(1.0);
        prop_assert!(upper >= brute - 1e-12 * scale, "bound {upper} below the true {brute}");
    }
}

#[test]
fn exact_on_a_parabola_where_the_hull_bound_is_twice_the_error() {
    // y = x^2 on [-10, 10] as one quadratic Bezier span: the hull bound of a step is 2x its
    // sagitta, the interpolation bound is the sagitta (up to the rounding margin).
    let c = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(-10.0, 100.0, 0.0),
            Point3::new(0.0, -100.0, 0.0),
            Point3::new(10.0, 100.0, 0.0),
        ],
        None,
    );
    for (t0, t1) in [(0.1, 0.2), (0.45, 0.55), (0.0, 1.0), (0.7, 0.71)] {
        let (upper, brute) = bound(&c, t0, t1);
        assert!(upper >= brute, "sound: {upper} vs {brute}");
        // The rounding margin here is 128 (p + 1) eps * 2 * 100 mm = 1.7e-11 mm.
        assert!(upper - brute <= 2e-11, "exact: {upper} vs {brute}");
    }
}

#[test]
fn tight_on_short_steps_of_smooth_curves_and_three_evaluations_at_most() {
    // Steps of 1/16 of a span on smooth random curves of degrees 2-7 (the walk's steps are
    // about 1/20 of a span at 0.01 mm): the bound is within 2 % of the true error nearly
    // everywhere (the band the walk aims at is 3 % wide), and each costs at most 3 evaluations.
    let (mut total, mut tight) = (0usize, 0usize);
    for degree in 2..=7 {
        for c in kerf_nurbs::smooth_random_curves(degree, 4, 7 + degree as u64) {
            let cert = Certifier::new(&c);
            let mut scratch = Scratch::default();
            for (_, lo, hi) in c.spans() {
                for k in 0..16 {
                    let t0 = lo + (hi - lo) * k as f64 / 16.0;
                    let t1 = lo + (hi - lo) * (k + 1) as f64 / 16.0;
                    let (a, b) = (c.point(t0), c.point(t1));
                    let (bd, evals) = kerf_nurbs::counted(|| {
                        cert.chord_error(&mut scratch, t0, t1, &a, &b, f64::INFINITY, 0.0)
                    });
                    let brute = brute_chord_error(&c, t0, t1, &a, &b);
                    assert!(bd.upper >= brute, "sound: {} vs {brute}", bd.upper);
                    assert!(bd.lower <= brute * (1.0 + 1e-9), "a lower bound");
                    assert!(evals.expect("counted") <= 3, "one middle point, two ends");
                    total += 1;
                    if bd.upper <= 1.02 * brute {
                        tight += 1;
                    }
                }
            }
        }
    }
    assert!(
        tight as f64 >= 0.95 * total as f64,
        "{tight} of {total} within 2 %"
    );
}
