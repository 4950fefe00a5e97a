//! The interpolation certificate (`docs/discretization.md`, "The interpolation certificate"):
//! a segment inside one knot span is bounded from its middle point and the span's third
//! hodograph, without subdivision. Checked against the independent dense brute force of
//! `tests/common`: never below it (on strongly rational random curves too, at every level of
//! refinement), and tight where the hull bound is not (exact on parabolas, within a fraction
//! of a percent on short steps of smooth curves and on twisted cubics, where the scalar form
//! of the bound is not), at a counted cost of at most four evaluations.

mod common;

use common::{brute_chord_error, random_curve};
use kerf_discretize::{Certifier, Scratch};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use proptest::prelude::*;

/// The certificate's answer for `[t0, t1]` with the curve's own end points, asked whether the
/// chord error is at most `limit`, with the evaluations it cost, and the true chord error.
fn ask(c: &NurbsCurve, t0: f64, t1: f64, limit: f64) -> (kerf_discretize::Bound, u64, f64) {
    let cert = Certifier::new(c);
    let (a, b) = (c.point(t0), c.point(t1));
    let brute = brute_chord_error(c, t0, t1, &a, &b);
    let (bd, evals) = kerf_nurbs::counted(|| {
        cert.chord_error(&mut Scratch::default(), t0, t1, &a, &b, limit, 0.0)
    });
    (bd, evals.expect("counted"), brute)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Any curve (degrees 1-7, weights 0.05-20, repeated knots), any step inside a span, from
    /// a thousandth of the span to all of it: the bound is never below the true chord error,
    /// whether asked nothing (the first, cheapest bound answers) or asked whether the error
    /// is within a hair of the truth, which refines through every level (the span's bound, the
    /// third hodograph's piece on the step with the vector form, the probe at the bound's
    /// peak, then the hull) until it certifies or cannot.
    #[test]
    fn never_below_the_dense_maximum(c in random_curve(), at in 0.0f64..1.0, frac in -3.0f64..0.0) {
        let spans = c.spans();
        let (_, lo, hi) = spans[(at * spans.len() as f64) as usize % spans.len()];
        let len = (hi - lo) * 10f64.powf(frac);
        let t0 = lo + (hi - lo - len) * at;
        let t1 = (t0 + len).min(hi);
        prop_assume!(t1 > t0);
        let scale = c.size().max(1.0);
        let (bd, _, brute) = ask(&c, t0, t1, f64::INFINITY);
        prop_assert!(bd.upper >= brute - 1e-12 * scale, "bound {} below the true {brute}", bd.upper);
        for limit in [brute * (1.0 + 1e-4) + 1e-12 * scale, brute * 1.01] {
            let (bd, _, _) = ask(&c, t0, t1, limit);
            prop_assert!(bd.upper >= brute - 1e-12 * scale, "bound {} below the true {brute}", bd.upper);
            prop_assert!(bd.lower <= brute * (1.0 + 1e-9) + 1e-12 * scale, "lower {} above the true {brute}", bd.lower);
        }
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
        let (bd, evals, brute) = ask(&c, t0, t1, f64::INFINITY);
        assert!(bd.upper >= brute, "sound: {} vs {brute}", bd.upper);
        // The rounding margin here is 128 (p + 1) eps * 2 * 100 mm = 1.7e-11 mm.
        assert!(bd.upper - brute <= 2e-11, "exact: {} vs {brute}", bd.upper);
        assert!(evals <= 3, "one middle point, two ends: {evals}");
    }
}

#[test]
fn tight_on_short_steps_of_smooth_curves_at_four_evaluations_at_most() {
    // Steps of 1/16 of a span on smooth random curves of degrees 2-7 (the walk's steps are
    // about 1/20 of a span at 0.01 mm), asked whether the error is within 2 % of its true
    // value: nearly always certified by the interpolation certificate alone (two ends, the
    // middle point, at most one probe), never by a bound below the truth.
    let (mut total, mut tight) = (0usize, 0usize);
    for degree in 2..=7 {
        for c in kerf_nurbs::smooth_random_curves(degree, 4, 7 + degree as u64) {
            for (_, lo, hi) in c.spans() {
                for k in 0..16 {
                    let t0 = lo + (hi - lo) * k as f64 / 16.0;
                    let t1 = lo + (hi - lo) * (k + 1) as f64 / 16.0;
                    let (bd, evals, brute) = ask(&c, t0, t1, 1.02 * brute_of(&c, t0, t1));
                    assert!(bd.upper >= brute, "sound: {} vs {brute}", bd.upper);
                    assert!(bd.lower <= brute * (1.0 + 1e-9), "a lower bound");
                    total += 1;
                    if bd.upper <= 1.02 * brute && evals <= 4 {
                        tight += 1;
                    }
                }
            }
        }
    }
    assert!(
        tight as f64 >= 0.95 * total as f64,
        "{tight} of {total} certified within 2 % at once"
    );
}

fn brute_of(c: &NurbsCurve, t0: f64, t1: f64) -> f64 {
    brute_chord_error(c, t0, t1, &c.point(t0), &c.point(t1))
}

/// The twisted cubic `(t, t^2, k t^3)`: its offset from a chord is across the chord in `y`,
/// its third derivative across the chord in `z`, perpendicular to it.
fn twisted_cubic(k: f64) -> NurbsCurve {
    // The power form t, t^2, k t^3 on [-1, 1] as a Bezier cubic (t = 2 u - 1).
    let p = |x: f64, y: f64, z: f64| Point3::new(x, y, z);
    NurbsCurve::new(
        3,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![
            p(-1.0, 1.0, -k),
            p(-1.0 / 3.0, -1.0 / 3.0, k),
            p(1.0 / 3.0, -1.0 / 3.0, -k),
            p(1.0, 1.0, k),
        ],
        None,
    )
}

#[test]
fn the_vector_form_is_tight_where_the_third_derivative_is_across_the_offset() {
    // Steps centred on t = 0 of the twisted cubic with a large cubic term: the error is the
    // middle point's offset, exactly (by symmetry the cubic term only tilts the chord). The
    // scalar form of the bound adds about c^2 / (128 n) (c / n = 4 here: 12 %), the vector
    // form a fourth-order term: within 0.5 % at four evaluations at most.
    let c = twisted_cubic(4.0);
    for half in [0.1, 0.05] {
        // t = 2 u - 1: the step [-half, half] in t is [0.5 - half / 2, 0.5 + half / 2] in u.
        let (t0, t1) = (0.5 - 0.5 * half, 0.5 + 0.5 * half);
        let brute = brute_of(&c, t0, t1);
        let (bd, evals, _) = ask(&c, t0, t1, 1.005 * brute);
        assert!(bd.upper >= brute, "sound: {} vs {brute}", bd.upper);
        assert!(
            bd.upper <= 1.005 * brute && evals <= 4,
            "half step {half}: bound {} against the true {brute} after {evals} evaluations",
            bd.upper
        );
    }
}

#[test]
fn the_probe_at_the_peak_decides_an_asymmetric_step_without_the_hull() {
    // A step off the twisted cubic's centre: the cubic term moves the largest offset away from
    // the middle, whose distance is then a poor lower bound. Asked for a tolerance between the
    // middle point's distance and the true error, the certificate must say "too long" (a lower
    // bound above the tolerance) from the curve point where its bound peaks, with no
    // subdivision.
    // t in [-0.05, 0.15] (u = (t + 1) / 2): the middle point's distance is 93 % of the error,
    // whose peak is at s - 1/2 = 0.12.
    let c = twisted_cubic(16.0);
    let (t0, t1) = (0.475, 0.575);
    let (a, b) = (c.point(t0), c.point(t1));
    let brute = brute_of(&c, t0, t1);
    let middle = kerf_nurbs::distance_to_segment(&c.point(0.5 * (t0 + t1)), &a, &b);
    assert!(
        middle < 0.95 * brute,
        "the step is asymmetric: middle {middle} vs the true {brute}"
    );
    let limit = 0.5 * (middle + brute);
    let (bd, evals, _) = ask(&c, t0, t1, limit);
    assert!(bd.lower <= brute * (1.0 + 1e-9), "a lower bound");
    assert!(
        bd.lower > limit && evals <= 4,
        "decided too long from the peak: lower {} vs limit {limit} after {evals} evaluations",
        bd.lower
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Any curve (degrees 1-7, weights 0.05-20, repeated knots), any step across an interior
    /// knot, from a thousandth of the shorter span to most of both: the bound is never below
    /// the true chord error. Where the curve is C^2 at the knot the interpolation certificate
    /// over both spans answers (`docs/discretization.md`, "Across a knot"); elsewhere (a
    /// multiple knot, degree 2, a step over two knots) the hull does.
    #[test]
    fn never_below_the_dense_maximum_across_a_knot(
        c in random_curve(),
        at in 0.0f64..1.0,
        left in -3.0f64..0.0,
        right in -3.0f64..0.0,
    ) {
        let spans = c.spans();
        prop_assume!(spans.len() >= 2);
        let k = 1 + (at * (spans.len() - 1) as f64) as usize % (spans.len() - 1);
        let (_, lo, knot) = spans[k - 1];
        let (_, _, hi) = spans[k];
        let t0 = knot - (knot - lo) * 10f64.powf(left) * 0.999;
        let t1 = knot + (hi - knot) * 10f64.powf(right) * 0.999;
        prop_assume!(t0 < knot && knot < t1);
        let scale = c.size().max(1.0);
        let (bd, _, brute) = ask(&c, t0, t1, f64::INFINITY);
        prop_assert!(bd.upper >= brute - 1e-12 * scale, "bound {} below the true {brute}", bd.upper);
        prop_assert!(bd.lower <= brute * (1.0 + 1e-9) + 1e-12 * scale, "lower {} above the true {brute}", bd.lower);
        for limit in [brute * (1.0 + 1e-4) + 1e-12 * scale, brute * 1.01] {
            let (bd, _, _) = ask(&c, t0, t1, limit);
            prop_assert!(bd.upper >= brute - 1e-12 * scale, "bound {} below the true {brute}", bd.upper);
        }
    }
}

#[test]
fn tight_across_a_knot_where_the_curve_is_c2_at_three_evaluations() {
    // Steps of 1/16 of a span that straddle a simple knot of smooth random curves of degrees
    // 3-7 (the walk's steps cross a knot about once in twenty at 0.01 mm), asked whether the
    // error is within 2 % of its true value: answered by the two ends and the middle point,
    // no hull subdivision, nearly always; never below the truth.
    let (mut total, mut tight) = (0usize, 0usize);
    for degree in 3..=7 {
        for c in kerf_nurbs::smooth_random_curves(degree, 4, 11 + degree as u64) {
            let spans = c.spans();
            for pair in spans.windows(2) {
                let ((_, lo, knot), (_, _, hi)) = (pair[0], pair[1]);
                for k in 1..16 {
                    let len = (hi - lo) / 32.0;
                    let t0 = knot - len * k as f64 / 16.0;
                    let t1 = t0 + len;
                    let brute = brute_of(&c, t0, t1);
                    let (bd, evals, _) = ask(&c, t0, t1, 1.02 * brute);
                    assert!(bd.upper >= brute, "sound: {} vs {brute}", bd.upper);
                    assert!(bd.lower <= brute * (1.0 + 1e-9), "a lower bound");
                    total += 1;
                    if bd.upper <= 1.02 * brute && evals <= 3 {
                        tight += 1;
                    }
                }
            }
        }
    }
    assert!(total > 1000, "{total} steps");
    assert!(
        tight as f64 >= 0.95 * total as f64,
        "{tight} of {total} certified within 2 % at once"
    );
}
