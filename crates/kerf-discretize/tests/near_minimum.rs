//! Point counts near the theoretical minimum `N*`.

mod common;

use kerf_discretize::{discretize, minimum_count, Options};
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

/// Smooth random curves: clamped, uniform simple knots, unit weights, seeded.
fn smooth_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    let mut s = seed;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let n = degree + 1 + 8;
            let pts: Vec<Point3<f64>> = (0..n)
                .map(|i| Point3::new(20.0 * i as f64 + 10.0 * rnd(), 60.0 * rnd(), 20.0 * rnd()))
                .collect();
            let mut knots = vec![0.0; degree + 1];
            let inner = n - degree - 1;
            knots.extend((1..=inner).map(|i| i as f64 / (inner + 1) as f64));
            knots.extend(vec![1.0; degree + 1]);
            NurbsCurve::new(degree, knots, pts, None)
        })
        .collect()
}

#[test]
fn smooth_cubic_and_quintic_stay_within_five_percent_of_n_star() {
    for degree in [3, 5] {
        for tol in [0.01, 0.001] {
            let curves = smooth_curves(degree, 24, 7 + degree as u64);
            let (mut segs, mut nstar, mut pieces) = (0usize, 0.0, 0usize);
            for c in &curves {
                let d = discretize(c, &Options::with_tolerance(tol)).unwrap();
                segs += d.segments();
                nstar += minimum_count(c, tol);
                pieces += 1 + d.c0_breaks.len();
            }
            let ratio = segs as f64 / nstar;
            eprintln!(
                "degree {degree} tol {tol}: {segs} segments, N* {nstar:.1}, ratio {ratio:.4}"
            );
            assert!(
                (segs as f64) <= 1.05 * nstar + pieces as f64,
                "degree {degree} tol {tol}: {segs} segments vs N* {nstar:.1}"
            );
        }
    }
}
