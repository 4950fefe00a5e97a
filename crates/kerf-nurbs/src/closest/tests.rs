//! Unit tests of the curve closest-point search (they use private items via `super::*`).

use super::*;
use proptest::prelude::*;
use std::f64::consts::FRAC_1_SQRT_2;

/// SplitMix64: a small deterministic generator for building random curves from a seed.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// A random valid curve: degree 1..=7, clamped or unclamped knots with repeated interior
/// knots, log-uniform weights in [0.05, 20] (or none), points in [-1, 1]^3.
fn random_curve(seed: u64) -> Option<NurbsCurve> {
    let mut rng = Rng(seed);
    let degree = 1 + (rng.next() * 7.0) as usize;
    let n = degree + 1 + (rng.next() * 6.0) as usize;
    let clamped = rng.next() < 0.7;
    let len = n + degree + 1;
    let mut knots = Vec::with_capacity(len);
    if clamped {
        knots.extend(std::iter::repeat_n(0.0, degree + 1));
        let mut x = 0.0;
        for _ in 0..(n - degree - 1) {
            if rng.next() < 0.7 || x == 0.0 {
                x += rng.range(0.05, 1.0);
            }
            knots.push(x);
        }
        let end = x + rng.range(0.05, 1.0);
        knots.extend(std::iter::repeat_n(end, degree + 1));
    } else {
        // Runs of up to degree + 1 equal knots: the curve may jump at an interior one.
        let mut x = rng.range(-2.0, 2.0);
        let mut run = 0;
        for _ in 0..len {
            knots.push(x);
            run += 1;
            if run > degree || rng.next() < 0.8 {
                x += rng.range(0.05, 1.0);
                run = 0;
            }
        }
    }
    let points = (0..n)
        .map(|_| {
            Point3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            )
        })
        .collect();
    let weights = (rng.next() < 0.7).then(|| {
        (0..n)
            .map(|_| rng.range(0.05f64.ln(), 20f64.ln()).exp())
            .collect()
    });
    NurbsCurve::try_new(degree, knots, points, weights).ok()
}

/// Brute force: the best of `n + 1` uniform samples, refined by golden-section search on
/// the neighbouring sample intervals.
fn brute_force(c: &NurbsCurve, p: &Point3<f64>, n: usize) -> f64 {
    let (a, b) = c.domain();
    let dist = |t: f64| (c.point(t) - p).norm();
    let at = |i: usize| a + (b - a) * (i as f64 / n as f64);
    let best = (0..=n)
        .min_by(|&i, &j| dist(at(i)).total_cmp(&dist(at(j))))
        .expect("samples");
    let (mut lo, mut hi) = (at(best.saturating_sub(1)), at((best + 1).min(n)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if dist(x1) < dist(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    dist(at(best)).min(dist(0.5 * (lo + hi)))
}

fn quarter_circle() -> NurbsCurve {
    let h = FRAC_1_SQRT_2;
    NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ],
        Some(vec![1.0, h, 1.0]),
    )
}

#[test]
fn circle_is_analytic() {
    let c = quarter_circle();
    for i in 0..=90 {
        let a = (i as f64).to_radians();
        for r in [0.0, 0.3, 1.0, 2.0, 50.0] {
            let p = Point3::new(r * a.cos(), r * a.sin(), 0.5);
            let q = c.closest_point(&p);
            let expected = (r - 1.0).hypot(0.5);
            assert!((q.distance - expected).abs() < 1e-13, "from {p}: {q:?}");
            assert!((q.point - c.point(q.t)).norm() == 0.0, "point is C(t)");
            if r > 0.0 {
                let near = c.closest_point_near(&p, 0.5);
                assert!(
                    (near.distance - expected).abs() < 1e-13,
                    "near from {p}: {near:?}"
                );
            }
        }
    }
    // Outside the arc's angular range the ends win.
    let q = c.closest_point(&Point3::new(2.0, -1.0, 0.0));
    assert_eq!(q.t, 0.0, "start of the domain");
    assert!(
        (q.distance - 2f64.sqrt()).abs() < 1e-15,
        "distance to (1, 0, 0)"
    );
    let q = c.closest_point(&Point3::new(-1.0, 3.0, 0.0));
    assert_eq!(q.t, 1.0, "end of the domain");
    let q = c.closest_point_near(&Point3::new(-1.0, 3.0, 0.0), 0.2);
    assert_eq!(q.t, 1.0, "local search stops at the end of the domain");
}

#[test]
fn parabola_beyond_the_centre_of_curvature() {
    // y = x^2 on [-2, 2] as one Bezier piece; from (0, 2) the distance has a local maximum
    // at x = 0 and two minima at x = +-sqrt(1.5), both inside the single piece.
    let c = NurbsCurve::new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(-2.0, 4.0, 0.0),
            Point3::new(0.0, -4.0, 0.0),
            Point3::new(2.0, 4.0, 0.0),
        ],
        None,
    );
    let q = c.closest_point(&Point3::new(0.0, 2.0, 0.0));
    assert!((q.distance - 1.75f64.sqrt()).abs() < 1e-14, "{q:?}");
    assert!((q.point.x.abs() - 1.5f64.sqrt()).abs() < 1e-7, "{q:?}");
    // Newton from the local maximum moves off it.
    let near = c.closest_point_near(&Point3::new(0.0, 2.0, 0.0), 0.5);
    assert!(
        (near.distance - 1.75f64.sqrt()).abs() < 1e-12,
        "near: {near:?}"
    );
}

#[test]
fn polyline_and_degenerate_pieces() {
    // A polyline with a repeated vertex (a zero-length segment) and a kink.
    let c = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 2.0, 3.0, 3.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
        ],
        None,
    );
    let q = c.closest_point(&Point3::new(0.4, -1.0, 0.0));
    assert!(
        (q.distance - 1.0).abs() < 1e-15 && (q.t - 0.4).abs() < 1e-14,
        "{q:?}"
    );
    let q = c.closest_point(&Point3::new(2.0, -1.0, 0.0));
    assert!(
        (q.distance - 2f64.sqrt()).abs() < 1e-15,
        "kink vertex: {q:?}"
    );
    let q = c.closest_point(&Point3::new(3.0, 0.5, 0.0));
    assert!(
        (q.distance - 2.0).abs() < 1e-15 && (q.t - 2.5).abs() < 1e-14,
        "{q:?}"
    );
    let q = c.closest_point(&Point3::new(f64::NAN, 0.0, 0.0));
    assert!(q.distance.is_nan(), "NaN query: {q:?}");
}

#[test]
fn jump_discontinuity_uses_the_left_limit() {
    // Degree 1 with a knot of multiplicity 2 at t = 1: two separate segments.
    let c = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(5.0, 5.0, 0.0),
            Point3::new(6.0, 5.0, 0.0),
        ],
        None,
    );
    let q = c.closest_point(&Point3::new(1.5, 0.0, 0.0));
    assert!(
        (q.distance - 0.5).abs() < 1e-12,
        "left limit at the jump: {q:?}"
    );
    assert_eq!(q.t, float_before(1.0), "represented below the knot");
    assert_eq!(q.point, c.point(q.t), "point is C(t)");
    let q = c.closest_point(&Point3::new(4.5, 5.0, 0.0));
    assert_eq!(q.t, 1.0, "the right piece starts at the knot: {q:?}");
}

#[test]
fn float_before_is_the_previous_float() {
    for t in [1.0, -1.0, 0.0, 3.5e-300, -2.0, 1e300, f64::MIN_POSITIVE] {
        let b = float_before(t);
        assert!(b < t, "{b} < {t}");
        let mid = 0.5 * b + 0.5 * t;
        assert!(mid == b || mid == t, "nothing between {b} and {t}");
    }
}

#[test]
fn results_are_deterministic() {
    for seed in 0..50 {
        let Some(c) = random_curve(seed) else {
            continue;
        };
        let p = Point3::new(0.1, -0.3, 0.7);
        assert_eq!(c.closest_point(&p), c.closest_point(&p), "seed {seed}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn global_matches_brute_force(
        seed in any::<u64>(),
        q in prop::array::uniform3(-2.0f64..2.0),
        t_guess in 0.0f64..1.0,
        near in any::<bool>(),
    ) {
        let c = random_curve(seed);
        prop_assume!(c.is_some());
        let c = c.expect("assumed");
        let (a, b) = c.domain();
        // Half of the queries close to the curve.
        let p = if near {
            c.point(a + (b - a) * t_guess) + nalgebra::Vector3::from(q) * 0.02
        } else {
            Point3::from(q)
        };
        let ours = c.closest_point(&p);
        let truth = brute_force(&c, &p, 10_000);
        prop_assert!(
            ours.distance <= truth + 1e-12,
            "ours {:?} vs brute force {}", ours, truth
        );
        prop_assert!(ours.t >= a && ours.t <= b, "t in the domain");
        prop_assert_eq!(ours.distance, (c.point(ours.t) - p).norm());
        // Local search from the answer stays there; from anywhere it never gets worse.
        let again = c.closest_point_near(&p, ours.t);
        prop_assert!(again.distance <= ours.distance + 1e-14, "{:?} {:?}", again, ours);
        let tg = a + (b - a) * t_guess;
        let local = c.closest_point_near(&p, tg);
        prop_assert!(
            local.distance <= (c.point(tg) - p).norm(),
            "local search got worse: {:?}", local
        );
        prop_assert!(local.distance >= ours.distance - 1e-12, "local beats global");
    }
}
