//! Point counts near the theoretical minimum `N*`.

mod common;

use kerf_discretize::{discretize, minimum_count, Options};
use kerf_nurbs::NurbsCurve;

/// Smooth random curves: clamped, uniform simple knots, unit weights, seeded.
fn smooth_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    kerf_nurbs::smooth_random_curves(degree, count, seed)
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
