//! Point-to-segment distance against a dense brute force over the segment and exact cases.

use kerf_nurbs::{distance_to_segment, nearest_on_segment, Segment};
use nalgebra::{Point3, Vector2};
use proptest::prelude::*;

/// The smallest distance from `q` to `n + 1` equally spaced points of `a b`, with its parameter.
fn brute(q: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>, n: usize) -> (f64, f64) {
    (0..=n)
        .map(|k| {
            let s = k as f64 / n as f64;
            ((q - (a + (b - a) * s)).norm(), s)
        })
        .fold((f64::INFINITY, 0.0), |m, x| if x.0 < m.0 { x } else { m })
}

#[test]
fn exact_cases_clamp_to_the_ends() {
    let a = Point3::new(0.0, 0.0, 0.0);
    let b = Point3::new(4.0, 0.0, 0.0);
    // Beside the middle: the perpendicular distance.
    assert_eq!(
        nearest_on_segment(&Point3::new(1.0, 3.0, 0.0), &a, &b),
        (3.0, 0.25),
        "inside"
    );
    // Beyond b: the distance to b (3-4-5), at s = 1.
    assert_eq!(
        nearest_on_segment(&Point3::new(7.0, 4.0, 0.0), &a, &b),
        (5.0, 1.0),
        "past b"
    );
    // Before a: the distance to a, at s = 0.
    assert_eq!(
        nearest_on_segment(&Point3::new(-3.0, 0.0, 4.0), &a, &b),
        (5.0, 0.0),
        "before a"
    );
    // A segment of no length is its point.
    assert_eq!(
        distance_to_segment(&Point3::new(0.0, 1.0, 0.0), &a, &a),
        1.0,
        "point segment"
    );
    // The ends of the segment are at distance exactly 0.
    assert_eq!(distance_to_segment(&b, &a, &b), 0.0, "end");
    assert_eq!(distance_to_segment(&a, &a, &b), 0.0, "start");
}

#[test]
fn two_dimensional_segments_measure_the_same() {
    let s = Segment::new(Vector2::new(0.0, 0.0), Vector2::new(0.0, 2.0));
    assert_eq!(s.nearest(&Vector2::new(3.0, 1.0)), (3.0, 0.5), "beside");
    assert_eq!(s.distance(&Vector2::new(0.0, 5.0)), 3.0, "past the end");
}

proptest! {
    #[test]
    fn matches_dense_sampling(
        a in prop::array::uniform3(-100.0..100.0f64),
        b in prop::array::uniform3(-100.0..100.0f64),
        q in prop::array::uniform3(-100.0..100.0f64),
    ) {
        let (a, b, q) = (Point3::from(a), Point3::from(b), Point3::from(q));
        let (d, s) = nearest_on_segment(&q, &a, &b);
        let n = 20_000;
        let (bd, bs) = brute(&q, &a, &b, n);
        // The nearest sample is at most half a sample spacing from the true nearest point.
        let spacing = (b - a).norm() / n as f64;
        prop_assert!(d <= bd + 1e-9, "never farther than a sample: {d} vs {bd}");
        prop_assert!(bd - d <= spacing + 1e-9, "samples approach from above: {d} vs {bd}");
        prop_assert!((0.0..=1.0).contains(&s), "parameter in [0, 1]: {s}");
        // The parameter's point lies at the distance returned.
        let p = a + (b - a) * s;
        prop_assert!(((q - p).norm() - d).abs() <= 1e-9 * (1.0 + d), "point at s");
        // Where the nearest point is inside and unique, the best sample is next to it.
        if (b - a).norm() > 1.0 && s > 0.0 && s < 1.0 {
            prop_assert!((bs - s).abs() <= 2.0 / n as f64, "s {s} vs sample {bs}");
        }
    }
}
