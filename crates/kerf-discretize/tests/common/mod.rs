//! Test support: an independent brute-force chord-error checker and random curves.
#![allow(dead_code, unreachable_pub)]

use kerf_discretize::Discretization;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use proptest::prelude::*;

pub use kerf_nurbs::distance_to_segment as seg_dist;

/// True chord error of [t0, t1] by dense sampling (per knot span) and golden-section refinement
/// around the best samples. Independent of the discretizer's Bezier bound.
pub fn brute_chord_error(
    c: &NurbsCurve,
    t0: f64,
    t1: f64,
    a: &Point3<f64>,
    b: &Point3<f64>,
) -> f64 {
    // Sample points: the knots inside plus a uniform grid.
    let mut ts: Vec<f64> = c
        .knots()
        .iter()
        .copied()
        .filter(|&k| k > t0 && k < t1)
        .collect();
    let n = 96;
    for i in 0..=n {
        ts.push(t0 + (t1 - t0) * i as f64 / n as f64);
    }
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    let f = |t: f64| seg_dist(&c.point(t), a, b);
    let vals: Vec<f64> = ts.iter().map(|&t| f(t)).collect();
    let mut best = vals.iter().copied().fold(0.0, f64::max);
    // Refine each local maximum by golden-section search in its bracket.
    for i in 1..ts.len().saturating_sub(1) {
        if vals[i] >= vals[i - 1] && vals[i] >= vals[i + 1] && vals[i] > 0.3 * best {
            let (mut lo, mut hi) = (ts[i - 1], ts[i + 1]);
            let g = 0.618_033_988_749_894_9;
            let mut x1 = hi - g * (hi - lo);
            let mut x2 = lo + g * (hi - lo);
            let (mut f1, mut f2) = (f(x1), f(x2));
            for _ in 0..60 {
                if f1 > f2 {
                    hi = x2;
                    x2 = x1;
                    f2 = f1;
                    x1 = hi - g * (hi - lo);
                    f1 = f(x1);
                } else {
                    lo = x1;
                    x1 = x2;
                    f1 = f2;
                    x2 = lo + g * (hi - lo);
                    f2 = f(x2);
                }
            }
            best = best.max(f1).max(f2);
        }
    }
    best
}

/// Checks everything a discretization promises, with the brute-force checker; returns the
/// worst true chord error.
pub fn check(c: &NurbsCurve, d: &Discretization, tol: f64) -> f64 {
    let (a, b) = c.domain();
    assert_eq!(
        d.params().len(),
        d.points().len(),
        "one point per parameter"
    );
    assert!(d.params().len() >= 2, "at least one segment");
    assert_eq!(d.params()[0], a, "first parameter is the domain start");
    assert_eq!(
        *d.params().last().unwrap(),
        b,
        "last parameter is the domain end"
    );
    for w in d.params().windows(2) {
        assert!(
            w[1] > w[0],
            "parameters strictly increase: {} then {}",
            w[0],
            w[1]
        );
    }
    // Rounding of the coordinates themselves: a point 1e9 mm from the origin is only known to
    // ~1e-7 mm, however it is evaluated.
    let far = c
        .control_points()
        .iter()
        .map(|p| p.coords.amax())
        .fold(0.0, f64::max);
    let size = c.size().max(1e-300) + 1e4 * far;
    for (t, p) in d.params().iter().zip(d.points()) {
        let q = c.point(*t);
        assert!(
            (q - p).norm() <= 1e-12 * size,
            "point at t={t} is on the curve ({} off)",
            (q - p).norm()
        );
    }
    for br in c.c0_breaks() {
        assert!(d.params().contains(&br), "C0 break {br} is a cutting point");
    }
    assert!(
        d.max_chord_error() <= tol,
        "certified bound {} <= tol {tol}",
        d.max_chord_error()
    );
    let mut worst = 0.0f64;
    for i in 1..d.params().len() {
        let e = brute_chord_error(
            c,
            d.params()[i - 1],
            d.params()[i],
            &d.points()[i - 1],
            &d.points()[i],
        );
        assert!(
            e <= tol * (1.0 + 1e-9) + 1e-12 * size,
            "segment {i} [{}, {}]: brute-force chord error {e} > tol {tol}",
            d.params()[i - 1],
            d.params()[i]
        );
        assert!(
            e <= d.max_chord_error() * (1.0 + 1e-9) + 1e-12 * size,
            "segment {i}: brute-force error {e} above the certified bound {}",
            d.max_chord_error()
        );
        worst = worst.max(e);
    }
    worst
}

/// A single-span rational quadratic arc of radius r and opening angle phi (< pi) in the xy
/// plane, centred at the origin, starting on +x.
pub fn arc(r: f64, phi: f64) -> NurbsCurve {
    let h = phi / 2.0;
    // The middle control point lies on the bisector at distance r / cos(phi / 2).
    let mid = Point3::new(r, r * h.tan(), 0.0);
    NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(r, 0.0, 0.0),
            mid,
            Point3::new(r * phi.cos(), r * phi.sin(), 0.0),
        ],
        Some(vec![1.0, h.cos(), 1.0]),
    )
}

/// Strategy: random valid NURBS curves, degrees 1..=7, weights 0.05..20, knot vectors with
/// multiplicities, clamped or unclamped.
pub fn random_curve() -> impl Strategy<Value = NurbsCurve> {
    (1usize..=7, 0usize..8, any::<bool>(), any::<u64>()).prop_map(|(p, extra, clamped, seed)| {
        let mut s = seed | 1;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let n = p + 1 + extra;
        let pts: Vec<Point3<f64>> = (0..n)
            .map(|_| {
                Point3::new(
                    100.0 * rnd() - 50.0,
                    100.0 * rnd() - 50.0,
                    40.0 * rnd() - 20.0,
                )
            })
            .collect();
        let w: Vec<f64> = (0..n).map(|_| 0.05 * (400.0f64).powf(rnd())).collect();
        // Interior knots with random multiplicities up to p.
        // Interior knots with multiplicities up to p (C0 breaks allowed, no jumps): a value
        // drawn twice must not add up beyond p.
        let n_int = n - p - 1;
        let mut interior: Vec<f64> = Vec::new();
        while interior.len() < n_int {
            let v = ((rnd() * 1000.0).round() / 1000.0).clamp(0.001, 0.999);
            let have = interior.iter().filter(|&&k| k == v).count();
            let m = (1 + (rnd() * p as f64) as usize).min(p - have.min(p));
            for _ in 0..m.min(n_int - interior.len()) {
                interior.push(v);
            }
        }
        interior.sort_by(f64::total_cmp);
        let mut knots = Vec::new();
        if clamped {
            knots.extend(std::iter::repeat_n(0.0, p + 1));
            knots.extend(interior);
            knots.extend(std::iter::repeat_n(1.0, p + 1));
        } else {
            for i in 0..=p {
                knots.push(-(p as f64 - i as f64) * 0.1 - 0.0001 * i as f64);
            }
            knots.extend(interior);
            for i in 0..=p {
                knots.push(1.0 + i as f64 * 0.1);
            }
            knots.sort_by(f64::total_cmp);
        }
        NurbsCurve::try_new(p, knots, pts, Some(w)).expect("generated curve is valid")
    })
}
