//! Tests of [`NurbsCurve`] against independent truth: exact conics and polynomial curves with
//! closed-form geometry, an independent Cox-de Boor evaluator, central finite differences, and
//! the invariance of the curve under knot insertion, splitting and Bezier extraction.

mod common;

use std::f64::consts::{FRAC_1_SQRT_2, PI, TAU};

use common::{
    breakpoint_interval, breakpoints, curve, curve_data, distance_to_breakpoint, max_deviation,
    reference_point,
};
use kerf_nurbs::{NurbsCurve, NurbsError};
use nalgebra::{Point3, Rotation3, Vector3};
use proptest::prelude::*;

// ---------------------------------------------------------------------------------------------
// Exact rational quadratic circles
// ---------------------------------------------------------------------------------------------

/// A circle (or arc) of radius `r` made of `quarters` rational quadratic quarter arcs, starting
/// at angle 0 of its own plane, placed by `rot` and `centre`. Knots `t0 + k * dt` at the joints.
struct Circle {
    curve: NurbsCurve,
    r: f64,
    centre: Point3<f64>,
    rot: Rotation3<f64>,
    quarters: usize,
}

impl Circle {
    fn new(
        r: f64,
        quarters: usize,
        centre: Point3<f64>,
        rot: Rotation3<f64>,
        t0: f64,
        dt: f64,
    ) -> Self {
        let mut points = Vec::new();
        let mut weights = Vec::new();
        let local = |x: f64, y: f64| centre + rot * Vector3::new(x, y, 0.0);
        for q in 0..quarters {
            let a0 = q as f64 * PI / 2.0;
            let a1 = a0 + PI / 2.0;
            if q == 0 {
                points.push(local(r * a0.cos(), r * a0.sin()));
                weights.push(1.0);
            }
            // The corner of the square circumscribing the quarter arc.
            points.push(local(r * (a0.cos() + a1.cos()), r * (a0.sin() + a1.sin())));
            weights.push(FRAC_1_SQRT_2);
            points.push(local(r * a1.cos(), r * a1.sin()));
            weights.push(1.0);
        }
        let mut knots = vec![t0; 3];
        for k in 1..quarters {
            knots.push(t0 + k as f64 * dt);
            knots.push(t0 + k as f64 * dt);
        }
        knots.extend([t0 + quarters as f64 * dt; 3]);
        let curve = NurbsCurve::try_new(2, knots, points, Some(weights)).expect("valid circle");
        Self {
            curve,
            r,
            centre,
            rot,
            quarters,
        }
    }

    /// The polar angle in `[0, 2 pi)` of a point in the circle's own plane.
    fn angle(&self, p: &Point3<f64>) -> f64 {
        let l = self.rot.inverse() * (p - self.centre);
        l.y.atan2(l.x).rem_euclid(TAU)
    }

    /// The plane normal (the circle runs counter-clockwise about it).
    fn axis(&self) -> Vector3<f64> {
        self.rot * Vector3::z()
    }
}

/// The circles every circle test runs on: radii 0.7 and 123.4; quarter, 3/4 and full circle;
/// at the origin in the xy plane and off-origin, tilted in 3D, with a shifted knot range.
fn circles() -> Vec<Circle> {
    let mut out = Vec::new();
    let tilt = Rotation3::from_euler_angles(0.3, -1.1, 2.0);
    for r in [0.7, 123.4] {
        for quarters in [1, 3, 4] {
            out.push(Circle::new(
                r,
                quarters,
                Point3::origin(),
                Rotation3::identity(),
                0.0,
                1.0,
            ));
            out.push(Circle::new(
                r,
                quarters,
                Point3::new(3.0, -7.5, 12.25) * (r / 10.0 + 1.0),
                tilt,
                -2.5,
                0.37,
            ));
        }
    }
    out
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn circle_points_lie_at_radius() {
    for c in circles() {
        let (a, b) = c.curve.domain();
        for i in 0..=2000 {
            let t = a + (b - a) * i as f64 / 2000.0;
            let p = c.curve.point(t);
            let d = (p - c.centre).norm();
            assert!(
                rel(d, c.r) <= 1e-12,
                "r = {}, {} quarters: |C({t}) - centre| = {d}",
                c.r,
                c.quarters
            );
            let plane = (p - c.centre).dot(&c.axis());
            assert!(
                plane.abs() <= 1e-12 * c.r,
                "point off the circle's plane by {plane}"
            );
        }
        // The ends sit at the expected angles.
        let a_end = c.angle(&c.curve.point(b));
        let expected = (c.quarters as f64 * PI / 2.0).rem_euclid(TAU);
        let diff = (a_end - expected).abs().min(TAU - (a_end - expected).abs());
        assert!(diff <= 1e-12, "end angle {a_end}, expected {expected}");
    }
}

#[test]
fn circle_curvature_is_one_over_r() {
    for c in circles() {
        let (a, b) = c.curve.domain();
        for i in 0..=500 {
            let t = a + (b - a) * i as f64 / 500.0;
            let k = c.curve.curvature(t);
            assert!(
                rel(k, 1.0 / c.r) <= 1e-12,
                "r = {}: curvature {k} at {t}, expected {}",
                c.r,
                1.0 / c.r
            );
            let dk = c.curve.curvature_derivative(t);
            // dk/ds has units 1/length^2.
            assert!(
                dk.abs() * c.r * c.r <= 1e-10,
                "r = {}: dk/ds = {dk} at {t}",
                c.r
            );
        }
    }
}

#[test]
fn circle_frenet_normal_points_at_centre() {
    for c in circles() {
        let (a, b) = c.curve.domain();
        for i in 0..=500 {
            let t = a + (b - a) * i as f64 / 500.0;
            let p = c.curve.point(t);
            let f = c
                .curve
                .frenet_frame(t)
                .expect("a circle has a Frenet frame");
            let to_centre = (c.centre - p) / c.r;
            assert!(
                (f.normal - to_centre).norm() <= 1e-11,
                "normal {:?} does not point at the centre ({:?})",
                f.normal,
                to_centre
            );
            assert!(
                (f.binormal - c.axis()).norm() <= 1e-11,
                "binormal {:?} is not the plane normal {:?}",
                f.binormal,
                c.axis()
            );
            assert!(
                f.tangent.dot(&to_centre).abs() <= 1e-12,
                "tangent not perpendicular to the radius"
            );
            // The tangent is the counter-clockwise direction about the axis.
            let expected_tangent = c.axis().cross(&(p - c.centre)) / c.r;
            assert!(
                (f.tangent - expected_tangent).norm() <= 1e-11,
                "tangent {:?}, expected {:?}",
                f.tangent,
                expected_tangent
            );
        }
    }
}

#[test]
fn circle_arc_length() {
    for c in circles() {
        let expected = c.quarters as f64 * PI / 2.0 * c.r;
        let l = c.curve.arc_length();
        assert!(
            rel(l, expected) <= 1e-10,
            "r = {}, {} quarters: length {l}, expected {expected}",
            c.r,
            c.quarters
        );
        // Between arbitrary parameters: the angle swept times r.
        let (a, b) = c.curve.domain();
        let (t0, t1) = (a + 0.137 * (b - a), a + 0.861 * (b - a));
        let sweep = (c.angle(&c.curve.point(t1)) - c.angle(&c.curve.point(t0))).rem_euclid(TAU);
        let l01 = c.curve.arc_length_between(t0, t1);
        assert!(
            rel(l01, sweep * c.r) <= 1e-10,
            "length between {t0} and {t1}: {l01}, expected {}",
            sweep * c.r
        );
    }
}

#[test]
fn circle_param_at_length_inverts_arc_length() {
    for c in circles() {
        let (a, _) = c.curve.domain();
        let total = c.curve.arc_length();
        for i in 0..=40 {
            let s = total * i as f64 / 40.0;
            let t = c.curve.param_at_length(s).expect("s is within the length");
            let back = c.curve.arc_length_between(a, t);
            assert!(
                (back - s).abs() <= 1e-10 * total,
                "arc_length_between(a, param_at_length({s})) = {back}"
            );
            // Independent: the point at arc length s is at angle s / r (modulo 2 pi).
            let angle = c.angle(&c.curve.point(t));
            let expected = (s / c.r).rem_euclid(TAU);
            let diff = (angle - expected).abs();
            let diff = diff.min(TAU - diff);
            assert!(
                diff <= 1e-10,
                "r = {}: angle at length {s} is {angle}, expected {expected}",
                c.r
            );
        }
    }
}

#[test]
fn circle_is_closed_and_arcs_are_not() {
    for c in circles() {
        assert_eq!(
            c.curve.is_closed(),
            c.quarters == 4,
            "is_closed of a {}-quarter arc",
            c.quarters
        );
    }
}

#[test]
fn circle_bezier_pieces_stay_on_circle() {
    for c in circles() {
        let (a, b) = c.curve.domain();
        let (t0, t1) = (a + 0.1 * (b - a), a + 0.95 * (b - a));
        let pieces = c.curve.bezier_pieces(t0, t1).expect("valid interval");
        for piece in &pieces {
            assert!(
                piece.homogeneous().iter().all(|q| q.w > 0.0),
                "Bezier weights must be positive"
            );
            for i in 0..=50 {
                let p = piece.point_local(i as f64 / 50.0);
                assert!(
                    rel((p - c.centre).norm(), c.r) <= 1e-12,
                    "Bezier piece point off the circle"
                );
            }
        }
    }
}

#[test]
fn circle_reversed_keeps_geometry_and_flips_binormal() {
    for c in circles() {
        let rev = c.curve.reversed();
        let (a, b) = c.curve.domain();
        assert_eq!(rev.domain(), (a, b), "reversal keeps the domain");
        for i in 0..=100 {
            let t = a + (b - a) * i as f64 / 100.0;
            let (p, d1) = c.curve.eval_d1(t);
            let (q, e1) = rev.eval_d1(a + b - t);
            assert!((p - q).norm() <= 1e-12 * c.r, "reversed point differs");
            assert!(
                (d1 + e1).norm() <= 1e-11 * d1.norm(),
                "reversed tangent is not opposite"
            );
            let f = rev.frenet_frame(a + b - t).expect("frame");
            assert!(
                (f.binormal + c.axis()).norm() <= 1e-11,
                "reversed circle turns the other way"
            );
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Analytic curvature of exact polynomial curves (and their rational reparametrisations)
// ---------------------------------------------------------------------------------------------

/// The parabola `y = x^2` on `x in [x0, x1]` as a quadratic Bezier; with `c != 1` the weights
/// `(1, c, c^2)` give a rational (Moebius) reparametrisation of the same parabola.
fn parabola(x0: f64, x1: f64, c: f64) -> NurbsCurve {
    NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(x0, x0 * x0, 0.0),
            Point3::new(0.5 * (x0 + x1), x0 * x1, 0.0),
            Point3::new(x1, x1 * x1, 0.0),
        ],
        Some(vec![1.0, c, c * c]),
    )
    .expect("valid parabola")
}

#[test]
fn parabola_curvature_matches_closed_form() {
    for c in [1.0, 0.3, 4.0] {
        let curve = parabola(-1.5, 2.0, c);
        for i in 0..=400 {
            let t = i as f64 / 400.0;
            let p = curve.point(t);
            assert!(
                (p.y - p.x * p.x).abs() <= 1e-13 * (1.0 + p.y.abs()),
                "point ({}, {}) is not on y = x^2",
                p.x,
                p.y
            );
            let x = p.x;
            let g = 1.0 + 4.0 * x * x;
            let k = 2.0 / g.powf(1.5);
            assert!(
                rel(curve.curvature(t), k) <= 1e-12,
                "weights (1, {c}, {c}^2): curvature {} at x = {x}, expected {k}",
                curve.curvature(t)
            );
            // Along increasing x: dk/ds = (dk/dx) / (ds/dx) = -24 x / (1 + 4 x^2)^3.
            let dk = -24.0 * x / (g * g * g);
            assert!(
                (curve.curvature_derivative(t) - dk).abs() <= 1e-11 * (1.0 + dk.abs()),
                "weights (1, {c}, {c}^2): dk/ds {} at x = {x}, expected {dk}",
                curve.curvature_derivative(t)
            );
            // The parabola opens upwards: the normal has a positive y component.
            let f = curve.frenet_frame(t).expect("frame");
            let n_expected = Vector3::new(-2.0 * x, 1.0, 0.0) / g.sqrt();
            assert!(
                (f.normal - n_expected).norm() <= 1e-12,
                "normal {:?}, expected {:?}",
                f.normal,
                n_expected
            );
        }
    }
}

/// The twisted cubic `(s, s^2, s^3)`, `s in [0, 1]`, as a cubic Bezier over the knots
/// `[t0, t1]` (so `s = (t - t0) / (t1 - t0)`).
fn twisted_cubic(t0: f64, t1: f64) -> NurbsCurve {
    NurbsCurve::try_new(
        3,
        vec![t0, t0, t0, t0, t1, t1, t1, t1],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0 / 3.0, 0.0, 0.0),
            Point3::new(2.0 / 3.0, 1.0 / 3.0, 0.0),
            Point3::new(1.0, 1.0, 1.0),
        ],
        None,
    )
    .expect("valid cubic")
}

#[test]
fn twisted_cubic_curvature_matches_closed_form() {
    // C' = (1, 2s, 3s^2), C'' = (0, 2, 6s): |C' x C''| = 2 sqrt(9s^4 + 9s^2 + 1),
    // |C'|^2 = 1 + 4s^2 + 9s^4, k = 2 f^(1/2) g^(-3/2) with f = 9s^4 + 9s^2 + 1, g = |C'|^2.
    let curve = twisted_cubic(-0.4, 1.6);
    for i in 0..=400 {
        let s = i as f64 / 400.0;
        let t = -0.4 + 2.0 * s;
        let f = 9.0 * s.powi(4) + 9.0 * s * s + 1.0;
        let g = 1.0 + 4.0 * s * s + 9.0 * s.powi(4);
        let k = 2.0 * f.sqrt() / g.powf(1.5);
        assert!(
            rel(curve.curvature(t), k) <= 1e-12,
            "curvature {} at s = {s}, expected {k}",
            curve.curvature(t)
        );
        // dk/ds_arc = k'(s) / |C'(s)| (curvature and arc length do not depend on t vs s).
        let fp = 36.0 * s.powi(3) + 18.0 * s;
        let gp = 8.0 * s + 36.0 * s.powi(3);
        let kp = f.powf(-0.5) * fp * g.powf(-1.5) - 3.0 * f.sqrt() * g.powf(-2.5) * gp;
        let dk = kp / g.sqrt();
        assert!(
            (curve.curvature_derivative(t) - dk).abs() <= 1e-11 * (1.0 + dk.abs()),
            "dk/ds {} at s = {s}, expected {dk}",
            curve.curvature_derivative(t)
        );
        // Derivatives with respect to t are those in s divided by (dt/ds)^k = 2^k.
        let d = curve.derivatives(t, 4);
        let exact = [
            Vector3::new(s, s * s, s * s * s),
            Vector3::new(1.0, 2.0 * s, 3.0 * s * s) / 2.0,
            Vector3::new(0.0, 2.0, 6.0 * s) / 4.0,
            Vector3::new(0.0, 0.0, 6.0) / 8.0,
            Vector3::zeros(),
        ];
        for (k, (got, want)) in d.iter().zip(exact.iter()).enumerate() {
            assert!(
                (got - want).norm() <= 1e-13,
                "derivative {k} at s = {s}: {got:?}, expected {want:?}"
            );
        }
    }
}

#[test]
fn straight_line_has_zero_curvature_and_no_frame() {
    let line = NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 1.0),
            Point3::new(3.0, 3.0, 3.0),
        ],
        Some(vec![1.0, 2.0, 0.5]),
    )
    .expect("valid");
    for i in 0..=10 {
        let t = i as f64 / 10.0;
        assert!(line.curvature(t) <= 1e-14, "a line has no curvature");
        assert!(line.frenet_frame(t).is_none(), "a line has no Frenet frame");
        assert!(
            line.curvature_derivative(t).abs() <= 1e-12,
            "dk/ds of a line"
        );
    }
}

#[test]
fn tangent_limit_at_a_cusp_of_the_parametrisation() {
    // Repeated first control point: C'(0) = 0, the curve leaves along P2 - P0.
    let c = NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(3.0, 4.0, 0.0),
        ],
        None,
    )
    .expect("valid");
    assert!(c.tangent(0.0).is_none(), "C'(0) vanishes");
    let t = c.tangent_limit(0.0).expect("C''(0) does not vanish");
    assert!(
        (t - Vector3::new(0.6, 0.8, 0.0)).norm() <= 1e-15,
        "tangent limit {t:?}"
    );
    let t1 = c.tangent(0.5).expect("regular point");
    assert!(
        (t1 - Vector3::new(0.6, 0.8, 0.0)).norm() <= 1e-15,
        "tangent {t1:?}"
    );
}

// ---------------------------------------------------------------------------------------------
// Random curves: evaluation against Cox-de Boor, derivatives against finite differences
// ---------------------------------------------------------------------------------------------

/// The width of the knot span around `t` and a first finite-difference step there, or `None`
/// if `t` is too close to a breakpoint (where the curve need not be smooth). The step is less
/// than half the distance to the nearest breakpoint, so that every difference stays inside
/// the span, where the curve is a rational function with a positive denominator.
fn fd_step(c: &NurbsCurve, t: f64) -> Option<(f64, f64)> {
    let (lo, hi) = breakpoint_interval(c, t);
    let width = hi - lo;
    let dist = distance_to_breakpoint(c, t);
    (dist > 0.02 * width).then_some(((0.5 * dist).min(0.01 * width), width))
}

/// The derivative of `f` at `t` by Ridders' method (central differences with steps `h`,
/// `h / 1.4`, `h / 1.4^2`, ... extrapolated to step 0 in a Neville tableau; Numerical Recipes
/// 3rd ed. section 5.7), with its error estimate. It adapts to curves whose features are much
/// narrower than their knot spans (large weight ratios, high degrees).
fn ridders(f: impl Fn(f64) -> Vector3<f64>, t: f64, h: f64) -> (Vector3<f64>, f64) {
    const CON: f64 = 1.4;
    const N: usize = 12;
    let mut tab = [[Vector3::zeros(); N]; N];
    let mut hh = h;
    tab[0][0] = (f(t + hh) - f(t - hh)) / (2.0 * hh);
    let (mut best, mut err) = (tab[0][0], f64::INFINITY);
    for i in 1..N {
        hh /= CON;
        tab[0][i] = (f(t + hh) - f(t - hh)) / (2.0 * hh);
        let mut fac = CON * CON;
        for j in 1..=i {
            tab[j][i] = (tab[j - 1][i] * fac - tab[j - 1][i - 1]) / (fac - 1.0);
            fac *= CON * CON;
            let e = (tab[j][i] - tab[j - 1][i])
                .norm()
                .max((tab[j][i] - tab[j - 1][i - 1]).norm());
            if e <= err {
                err = e;
                best = tab[j][i];
            }
        }
        if (tab[i][i] - tab[i - 1][i - 1]).norm() >= 2.0 * err {
            break;
        }
    }
    (best, err)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn point_matches_cox_de_boor(c in curve(), u in 0.0..=1.0f64) {
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let got = c.point(t);
        let want = reference_point(&c, t);
        prop_assert!(
            (got - want).norm() <= 1e-12 * c.size(),
            "C({}) = {:?}, Cox-de Boor gives {:?}", t, got, want
        );
        // At every breakpoint too (span search at knots, the domain ends included).
        for k in breakpoints(&c) {
            let got = c.point(k);
            let want = reference_point(&c, k);
            prop_assert!(
                (got - want).norm() <= 1e-12 * c.size(),
                "C({}) = {:?} at a knot, Cox-de Boor gives {:?}", k, got, want
            );
        }
    }

    #[test]
    fn derivatives_match_finite_differences(c in curve(), u in 0.0..=1.0f64) {
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        // Inside a knot span the curve is analytic; across a knot it need not be smooth.
        let step = fd_step(&c, t);
        prop_assume!(step.is_some());
        let (h, width) = step.expect("assumed");
        let order = (c.degree() + 2).clamp(4, 7);
        let d = c.derivatives(t, order);
        prop_assert_eq!(d.len(), order + 1, "derivatives(t, n) returns n + 1 vectors");
        prop_assert!(
            (d[0] - c.point(t).coords).norm() <= 1e-14 * c.size(),
            "derivatives()[0] is not the point"
        );
        for k in 1..=order {
            let (fd, err) = ridders(|s| c.derivatives(s, k - 1)[k - 1], t, h);
            // The error of a difference scales with the size of the derivative and of the
            // function differenced over the span width.
            let scale = d[k].norm() + d[k - 1].norm() / width;
            // Skip the rare point where the differences are unreliable (Ridders' own estimate).
            prop_assume!(err <= 1e-7 * scale);
            prop_assert!(
                (fd - d[k]).norm() <= 1e-6 * scale,
                "degree {}: derivative {} at {} is {:?}, finite difference {:?} +- {} (h = {})",
                c.degree(), k, t, d[k], fd, err, h
            );
        }
    }

    #[test]
    fn fixed_order_evaluators_agree_with_derivatives(c in curve(), u in -0.2..=1.2f64) {
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let d = c.derivatives(t, 3);
        let scale = |v: &Vector3<f64>| 1e-14 * (1.0 + v.norm());
        let (p1, e1) = c.eval_d1(t);
        let (p2, f1, f2) = c.eval_d2(t);
        let g = c.eval_d3(t);
        prop_assert!((p1.coords - d[0]).norm() <= scale(&d[0]), "eval_d1 point");
        prop_assert!((e1 - d[1]).norm() <= scale(&d[1]), "eval_d1 derivative");
        prop_assert!((p2.coords - d[0]).norm() <= scale(&d[0]), "eval_d2 point");
        prop_assert!((f1 - d[1]).norm() <= scale(&d[1]), "eval_d2 first derivative");
        prop_assert!((f2 - d[2]).norm() <= scale(&d[2]), "eval_d2 second derivative");
        for k in 0..4 {
            prop_assert!((g[k] - d[k]).norm() <= scale(&d[k]), "eval_d3 derivative {}", k);
        }
        prop_assert!((c.point(t).coords - d[0]).norm() <= scale(&d[0]), "point()");
        prop_assert!((c.speed(t) - d[1].norm()).abs() <= scale(&d[1]), "speed()");
    }

    #[test]
    fn polynomial_derivatives_vanish_above_degree(d in curve_data(), u in 0.0..=1.0f64) {
        let mut d = d;
        d.weights = None;
        let c = d.curve();
        prop_assert!(!c.is_rational(), "equal weights make a polynomial curve");
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let p = c.degree();
        let ders = c.derivatives(t, p + 3);
        let (lo, hi) = breakpoint_interval(&c, t);
        let width = hi - lo;
        // The p-th derivative is constant on the span; orders above are zero (up to the
        // rounding of the weight derivatives, which are sums of basis derivatives of size
        // 1 / width^k that cancel).
        for k in p + 1..=p + 3 {
            let scale = c.size() / width.powi(k as i32);
            prop_assert!(
                ders[k].norm() <= 1e-9 * scale,
                "degree {}: derivative {} is {:?}", p, k, ders[k]
            );
        }
    }

    #[test]
    fn rational_derivatives_beyond_degree_match_finite_differences(
        c in common::curve_data_with(1..=3, 4).prop_filter("rational", |d| d.weights.is_some())
            .prop_map(|d| d.curve()),
        u in 0.0..=1.0f64,
    ) {
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let step = fd_step(&c, t);
        prop_assume!(step.is_some());
        let (h, width) = step.expect("assumed");
        let p = c.degree();
        let k = p + 1;
        let d = c.derivatives(t, k);
        let (fd, err) = ridders(|s| c.derivatives(s, p)[p], t, h);
        let scale = d[k].norm() + d[k - 1].norm() / width;
        prop_assume!(err <= 1e-7 * scale);
        prop_assert!(
            (fd - d[k]).norm() <= 1e-6 * scale,
            "degree {}: derivative {} is {:?}, finite difference {:?}", p, k, d[k], fd
        );
    }

    #[test]
    fn curvature_and_frame_agree_with_derivatives(c in curve(), u in 0.0..=1.0f64) {
        // k = |C' x C''| / |C'|^3 and the Frenet frame from derivatives().
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let d = c.derivatives(t, 2);
        let speed = d[1].norm();
        prop_assume!(speed > 1e-6 * c.size());
        let k = d[1].cross(&d[2]).norm() / speed.powi(3);
        prop_assert!(
            (c.curvature(t) - k).abs() <= 1e-12 * k.max(1.0 / c.size()),
            "curvature {} vs {}", c.curvature(t), k
        );
        if let Some(f) = c.frenet_frame(t) {
            let tangent = d[1] / speed;
            prop_assert!((f.tangent - tangent).norm() <= 1e-12, "Frenet tangent");
            prop_assert!(f.normal.dot(&tangent).abs() <= 1e-10, "normal not orthogonal");
            prop_assert!((f.normal.norm() - 1.0).abs() <= 1e-12, "normal not unit");
            // The normal points to the side C'' bends towards.
            prop_assert!(f.normal.dot(&d[2]) >= -1e-12 * d[2].norm(), "normal points away from the bend");
            prop_assert!(
                (f.binormal - f.tangent.cross(&f.normal)).norm() <= 1e-12,
                "binormal is not T x N"
            );
        }
    }

    #[test]
    fn curvature_derivative_matches_finite_differences(
        c in common::curve_data_with(2..=7, 8).prop_map(|d| d.curve()),
        u in 0.0..=1.0f64,
    ) {
        // dk/ds against a finite difference of curvature() in t, divided by the speed.
        let (a, b) = c.domain();
        let t = a + u * (b - a);
        let speed = c.speed(t);
        let k = c.curvature(t);
        let step = fd_step(&c, t);
        prop_assume!(step.is_some() && speed > 1e-6 * c.size() && k > 1e-6 / c.size());
        let (h, width) = step.expect("assumed");
        let kk = |s: f64| Vector3::new(c.curvature(s), 0.0, 0.0);
        let (dk_dt, err) = ridders(kk, t, h);
        let dk_dt = dk_dt.x;
        prop_assume!(err <= 1e-7 * (dk_dt.abs() + k / width));
        let dk_ds = dk_dt / speed;
        let got = c.curvature_derivative(t);
        let scale = got.abs() + k / (width * speed);
        prop_assert!(
            (got - dk_ds).abs() <= 1e-6 * scale,
            "dk/ds {} vs finite difference {}", got, dk_ds
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Knot insertion, splitting, reversal, Bezier extraction
// ---------------------------------------------------------------------------------------------

/// A parameter in the domain: either `u` in `[0, 1]` mapped into it, or an existing knot.
fn pick_parameter(c: &NurbsCurve, u: f64, knot_index: Option<usize>) -> f64 {
    let (a, b) = c.domain();
    match knot_index {
        Some(i) => {
            let bp = breakpoints(c);
            bp[i % bp.len()]
        }
        None => a + u * (b - a),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn knot_insertion_preserves_the_curve(
        c in curve(),
        u in 0.0..=1.0f64,
        knot in prop::option::of(0..20usize),
        times_fraction in 0.0..1.0f64,
    ) {
        let v = pick_parameter(&c, u, knot);
        let p = c.degree();
        let s = c.knots().iter().filter(|&&k| k == v).count();
        // Up to the degree: 1 ..= p - s insertions.
        prop_assume!(s < p);
        let times = 1 + (times_fraction * (p - s) as f64) as usize;
        let q = c.insert_knot(v, times).expect("insertion within the degree");
        prop_assert_eq!(q.len(), c.len() + times, "one control point per inserted knot");
        prop_assert_eq!(q.knots().len(), c.knots().len() + times, "knot count");
        prop_assert_eq!(
            q.knots().iter().filter(|&&k| k == v).count(), s + times, "multiplicity of {}", v
        );
        prop_assert!(q.knots().windows(2).all(|w| w[0] <= w[1]), "knots stay sorted");
        prop_assert_eq!(q.domain(), c.domain(), "domain unchanged");
        prop_assert!(q.weights().iter().all(|&w| w > 0.0), "weights stay positive");
        let (a, b) = c.domain();
        let dev = max_deviation(a, b, 400, |t| c.point(t), |t| q.point(t));
        prop_assert!(
            dev <= 1e-12 * c.size(),
            "inserting {} x{} into degree {} moved the curve by {} (size {})",
            v, times, p, dev, c.size()
        );
        // Exactly at the breakpoints too.
        let dev = breakpoints(&c)
            .into_iter()
            .map(|t| (c.point(t) - q.point(t)).norm())
            .fold(0.0, f64::max);
        prop_assert!(dev <= 1e-12 * c.size(), "moved at a knot by {}", dev);
    }

    #[test]
    fn split_halves_reproduce_the_curve(
        c in curve(),
        u in 0.001..=0.999f64,
        knot in prop::option::of(1..20usize),
    ) {
        let (a, b) = c.domain();
        // An interior breakpoint (if there is one) or a parameter strictly inside.
        let interior: Vec<f64> = breakpoints(&c).into_iter().filter(|&k| k > a && k < b).collect();
        let t = match knot {
            Some(i) if !interior.is_empty() => interior[i % interior.len()],
            _ => a + u * (b - a),
        };
        prop_assume!(t > a && t < b);
        let (l, r) = c.split(t).expect("t inside the domain");
        prop_assert_eq!(l.domain(), (a, t), "left domain");
        prop_assert_eq!(r.domain(), (t, b), "right domain");
        let p = c.degree();
        // Both halves are clamped at t.
        prop_assert!(l.knots()[l.knots().len() - p - 1..].iter().all(|&k| k == t), "left clamped at t");
        prop_assert!(r.knots()[..=p].iter().all(|&k| k == t), "right clamped at t");
        let tol = 1e-12 * c.size();
        let dl = max_deviation(a, t, 300, |s| c.point(s), |s| l.point(s));
        // The left half at t is the left limit of the curve; sample [a, t) and check the end
        // separately.
        let dl_open = max_deviation(a, t - (t - a) * 1e-9, 300, |s| c.point(s), |s| l.point(s));
        let dr = max_deviation(t, b, 300, |s| c.point(s), |s| r.point(s));
        prop_assert!(dr <= tol, "right half deviates by {}", dr);
        prop_assert!(dl_open <= tol, "left half deviates by {}", dl_open);
        if c.knots().iter().filter(|&&k| k == t).count() <= p {
            // The curve is continuous at t: the halves meet and reproduce it everywhere.
            prop_assert!(dl <= tol, "left half deviates by {}", dl);
            prop_assert!((l.point(t) - r.point(t)).norm() <= tol, "halves do not meet");
        }
    }

    #[test]
    fn reversed_maps_t_to_a_plus_b_minus_t(c in curve(), u in 0.0..=1.0f64) {
        let r = c.reversed();
        let (a, b) = c.domain();
        prop_assert_eq!(r.domain(), (a, b), "reversal keeps the domain");
        let t = a + u * (b - a);
        // `a + b - t` and the mirrored knots are rounded: a parameter error of a few ulps of
        // |a| + |b| moves a point by the speed times that.
        let tol = |s: f64| 1e-12 * c.size() + c.speed(s) * 8.0 * f64::EPSILON * (a.abs() + b.abs());
        prop_assert!((r.point(a + b - t) - c.point(t)).norm() <= tol(t), "reversed point");
        for i in 0..=200 {
            let s = a + (b - a) * f64::from(i) / 200.0;
            let dev = (c.point(s) - r.point(a + b - s)).norm();
            prop_assert!(dev <= tol(s), "reversed curve deviates by {} at {}", dev, s);
        }
        let dist = distance_to_breakpoint(&c, t);
        let (lo, hi) = breakpoint_interval(&c, t);
        if dist > 1e-3 * (hi - lo) {
            let d = c.derivatives(t, 2);
            let e = r.derivatives(a + b - t, 2);
            prop_assert!((d[1] + e[1]).norm() <= 1e-10 * (d[1].norm() + c.size() / (b - a)), "C' flips sign");
            prop_assert!((d[2] - e[2]).norm() <= 1e-9 * (d[2].norm() + d[1].norm() / (hi - lo)), "C'' keeps its sign");
        }
        let rr = r.reversed();
        for i in 0..=50 {
            let s = a + (b - a) * f64::from(i) / 50.0;
            let dev = (c.point(s) - rr.point(s)).norm();
            prop_assert!(dev <= 2.0 * tol(s), "double reversal deviates by {} at {}", dev, s);
        }
    }

    #[test]
    fn bezier_pieces_reproduce_the_curve(
        c in curve(),
        u0 in 0.0..=1.0f64,
        u1 in 0.0..=1.0f64,
        k0 in prop::option::of(0..20usize),
    ) {
        let (a, b) = c.domain();
        let t0 = pick_parameter(&c, u0.min(u1), k0);
        let t1 = a + u0.max(u1) * (b - a);
        prop_assume!(t0 < t1);
        let pieces = c.bezier_pieces(t0, t1).expect("valid interval");
        // One piece per knot span met: the breakpoints strictly inside (t0, t1) plus one.
        let inside = breakpoints(&c).iter().filter(|&&k| k > t0 && k < t1).count();
        prop_assert_eq!(pieces.len(), inside + 1, "number of pieces");
        prop_assert_eq!(pieces[0].t0, t0, "first piece starts at t0");
        prop_assert_eq!(pieces[pieces.len() - 1].t1, t1, "last piece ends at t1");
        for w in pieces.windows(2) {
            prop_assert_eq!(w[0].t1, w[1].t0, "pieces are contiguous");
        }
        let tol = 1e-12 * c.size();
        for piece in &pieces {
            prop_assert_eq!(piece.degree, c.degree(), "degree");
            prop_assert!(piece.t0 < piece.t1, "non-empty piece");
            prop_assert!(
                piece.homogeneous().iter().all(|q| q.w > 0.0 && q.w.is_finite()),
                "Bezier weights must be positive: {:?}", piece.homogeneous()
            );
            let cps: Vec<Point3<f64>> = piece.control_points().collect();
            let (lo, hi) = cps.iter().fold(
                (Point3::from(Vector3::repeat(f64::INFINITY)), Point3::from(Vector3::repeat(f64::NEG_INFINITY))),
                |(lo, hi), p| (lo.inf(p), hi.sup(p)),
            );
            // The end control points interpolate the curve.
            prop_assert!((cps[0] - c.point(piece.t0)).norm() <= tol, "first control point");
            // At t1 the piece gives the left limit; compare with the piece's own span.
            for i in 0..=64 {
                let s = i as f64 / 64.0;
                let t = piece.t0 + s * (piece.t1 - piece.t0);
                let q = piece.point_local(s);
                if i < 64 {
                    prop_assert!(
                        (q - c.point(t)).norm() <= tol,
                        "piece [{}, {}] at local {}: {:?} vs curve {:?}", piece.t0, piece.t1, s, q, c.point(t)
                    );
                }
                // Convex hull property: the box of the control points contains the piece, and
                // so does every half-space bounding them (support function test).
                let slack = 1e-12 * c.size();
                prop_assert!(
                    q.x >= lo.x - slack && q.y >= lo.y - slack && q.z >= lo.z - slack
                        && q.x <= hi.x + slack && q.y <= hi.y + slack && q.z <= hi.z + slack,
                    "point {:?} outside the control box {:?}..{:?}", q, lo, hi
                );
                for dir in [Vector3::new(1.0, 2.0, -3.0), Vector3::new(-0.3, 0.1, 0.9), Vector3::new(1.0, -1.0, 1.0)] {
                    let dir = dir.normalize();
                    let support = cps.iter().map(|p| p.coords.dot(&dir)).fold(f64::NEG_INFINITY, f64::max);
                    prop_assert!(q.coords.dot(&dir) <= support + slack, "outside the convex hull");
                }
            }
        }
    }

    #[test]
    fn bezier_subdivide_and_segment(
        c in curve(),
        u in 0.0..=1.0f64,
        split in 0.01..=0.99f64,
        a in 0.0..=1.0f64,
        b in 0.0..=1.0f64,
    ) {
        let (da, db) = c.domain();
        let t = da + u * (db - da);
        let span = c.span(t);
        let (s0, s1) = (c.knots()[span], c.knots()[span + 1]);
        prop_assert!(s0 < s1 && s0 <= t && t <= s1, "span() returns a non-empty span holding t");
        let piece = c.bezier_in_span(span, s0, s1);
        prop_assert_eq!((piece.t0, piece.t1), (s0, s1), "piece interval");
        let tol = 1e-12 * c.size();
        let dev = max_deviation(0.0, 1.0 - 1e-12, 64, |s| piece.point_local(s), |s| c.point(s0 + s * (s1 - s0)));
        prop_assert!(dev <= tol, "span piece deviates by {}", dev);

        let (l, r) = piece.subdivide(split);
        let tm = s0 + split * (s1 - s0);
        prop_assert!((l.t0, r.t1) == (s0, s1) && (l.t1 - tm).abs() <= 1e-15 * tm.abs().max(1.0) && l.t1 == r.t0, "subdivide intervals");
        let dl = max_deviation(0.0, 1.0, 64, |s| l.point_local(s), |s| piece.point_local(s * split));
        let dr = max_deviation(0.0, 1.0, 64, |s| r.point_local(s), |s| piece.point_local(split + s * (1.0 - split)));
        prop_assert!(dl <= tol && dr <= tol, "subdivision deviates by {} / {}", dl, dr);
        prop_assert!(l.homogeneous().iter().chain(r.homogeneous()).all(|q| q.w > 0.0), "subdivided weights positive");

        let (lo, hi) = (a.min(b), a.max(b));
        prop_assume!(hi - lo > 1e-3);
        let seg = piece.segment(lo, hi);
        let dev = max_deviation(0.0, 1.0, 64, |s| seg.point_local(s), |s| piece.point_local(lo + s * (hi - lo)));
        prop_assert!(dev <= tol, "segment [{}, {}] deviates by {}", lo, hi, dev);
        prop_assert!(
            (seg.t0 - (s0 + lo * (s1 - s0))).abs() <= 1e-14 * (s1 - s0 + s0.abs())
                && (seg.t1 - (s0 + hi * (s1 - s0))).abs() <= 1e-14 * (s1 - s0 + s0.abs()),
            "segment interval [{}, {}]", seg.t0, seg.t1
        );
        // The whole segment and the edge cases a = 0, b = 1.
        prop_assert_eq!(piece.segment(0.0, 1.0), piece, "segment(0, 1) is the piece");
        let head = piece.segment(0.0, hi);
        let tail = piece.segment(lo, 1.0);
        prop_assert!(max_deviation(0.0, 1.0, 32, |s| head.point_local(s), |s| piece.point_local(s * hi)) <= tol, "segment(0, b)");
        prop_assert!(max_deviation(0.0, 1.0, 32, |s| tail.point_local(s), |s| piece.point_local(lo + s * (1.0 - lo))) <= tol, "segment(a, 1)");
    }

    #[test]
    fn bounding_box_contains_the_curve(c in curve()) {
        let (lo, hi) = c.bounding_box();
        let (a, b) = c.domain();
        let slack = 1e-12 * c.size();
        for i in 0..=200 {
            let p = c.point(a + (b - a) * i as f64 / 200.0);
            prop_assert!(
                (p - lo).iter().all(|&d| d >= -slack) && (hi - p).iter().all(|&d| d >= -slack),
                "point {:?} outside the control box", p
            );
        }
    }

    #[test]
    fn evaluation_outside_the_domain_clamps(c in curve(), u in prop_oneof![-1e6..-1e-9f64, 1e-9..1e6f64]) {
        let (a, b) = c.domain();
        let t = if u < 0.0 { a + u } else { b + u };
        let end = if u < 0.0 { a } else { b };
        prop_assert_eq!(c.point(t), c.point(end), "clamped point");
        prop_assert_eq!(c.derivatives(t, 3), c.derivatives(end, 3), "clamped derivatives");
        prop_assert_eq!(c.curvature(t).to_bits(), c.curvature(end).to_bits(), "clamped curvature");
    }
}

#[test]
fn bezier_pieces_on_unclamped_uniform_cubic() {
    // A uniform unclamped cubic: the domain [3, 7] is four spans; pieces over [3.5, 6.25].
    let knots: Vec<f64> = (0..11).map(f64::from).collect();
    let points: Vec<Point3<f64>> = (0..7)
        .map(|i| {
            let x = f64::from(i);
            Point3::new(x, (x * 1.3).sin() * 3.0, (x * 0.7).cos())
        })
        .collect();
    let weights = vec![1.0, 0.2, 5.0, 1.0, 0.7, 3.0, 1.0];
    let c = NurbsCurve::try_new(3, knots, points, Some(weights)).expect("valid");
    assert_eq!(c.domain(), (3.0, 7.0), "unclamped domain");
    let pieces = c.bezier_pieces(3.5, 6.25).expect("valid interval");
    let ivals: Vec<(f64, f64)> = pieces.iter().map(|p| (p.t0, p.t1)).collect();
    assert_eq!(
        ivals,
        vec![(3.5, 4.0), (4.0, 5.0), (5.0, 6.0), (6.0, 6.25)],
        "one piece per span"
    );
    for piece in &pieces {
        for i in 0..=100 {
            let s = f64::from(i) / 100.0;
            let t = piece.t0 + s * (piece.t1 - piece.t0);
            let d = (piece.point_local(s) - reference_point(&c, t)).norm();
            assert!(d <= 1e-13 * c.size(), "piece deviates by {d} at {t}");
        }
    }
    // The whole domain.
    let all = c.bezier_pieces(3.0, 7.0).expect("whole domain");
    assert_eq!(all.len(), 4, "four spans");
}

#[test]
fn insertion_at_the_ends_of_an_unclamped_domain() {
    let knots: Vec<f64> = (0..11).map(|i| f64::from(i) * 0.5).collect();
    let points: Vec<Point3<f64>> = (0..7)
        .map(|i| {
            let x = f64::from(i);
            Point3::new(x, (x * 1.3).sin() * 3.0, (x * 0.7).cos())
        })
        .collect();
    let weights = vec![1.0, 0.2, 5.0, 1.0, 0.7, 3.0, 1.0];
    let c = NurbsCurve::try_new(3, knots, points, Some(weights)).expect("valid");
    let (a, b) = c.domain();
    for v in [a, b] {
        for times in 1..=2 {
            let q = c
                .insert_knot(v, times)
                .expect("multiplicity stays <= degree");
            assert_eq!(q.domain(), (a, b), "domain after inserting {v} x{times}");
            let dev = max_deviation(a, b, 400, |t| c.point(t), |t| q.point(t));
            assert!(
                dev <= 1e-13 * c.size(),
                "inserting the domain end {v} x{times} moved the curve by {dev}"
            );
        }
    }
}

#[test]
fn c0_breaks_are_knots_of_multiplicity_at_least_degree() {
    // Degree 3: knot 1 simple, 2 of multiplicity 2 (C1), 3 of multiplicity 3 (C0), 4 of
    // multiplicity 4 (possibly discontinuous), then two more spans so that the span search
    // at 4 is a binary search, not the domain-end shortcut.
    let p = 3;
    let mut knots = vec![0.0; 4];
    knots.extend([1.0, 2.0, 2.0, 3.0, 3.0, 3.0, 4.0, 4.0, 4.0, 4.0, 4.5]);
    knots.extend([5.0; 4]);
    let n = knots.len() - p - 1;
    let points: Vec<Point3<f64>> = (0..n)
        .map(|i| {
            let x = i as f64;
            Point3::new(x, (x * 0.9).sin(), (x * 0.4).cos())
        })
        .collect();
    let c = NurbsCurve::try_new(p, knots, points.clone(), None).expect("valid");
    assert_eq!(c.c0_breaks(), vec![3.0, 4.0], "multiplicity p and p + 1");
    // At multiplicity p the curve is continuous; at p + 1 it jumps from one control point to
    // the next (the left limit is the control point before the copies, the value the next).
    let eps = 1e-9;
    assert!(
        (c.point(3.0 - eps) - c.point(3.0)).norm() < 1e-6,
        "continuous at a knot of multiplicity p"
    );
    let before = c.point(4.0 - eps);
    let at = c.point(4.0);
    // Index of the control point at the left limit: knots before the first 4.0 minus p + 1 ...
    let first4 = c.knots().iter().position(|&k| k == 4.0).expect("knot 4");
    assert!(
        (before - points[first4 - 1]).norm() < 1e-6,
        "left limit at a knot of multiplicity p + 1 is P[{}]",
        first4 - 1
    );
    assert!(
        (at - points[first4]).norm() < 1e-12,
        "value at a knot of multiplicity p + 1 is P[{first4}]"
    );
    // The split there gives the left limit to the left half.
    let (l, r) = c.split(4.0).expect("interior");
    assert!(
        (l.point(4.0) - points[first4 - 1]).norm() < 1e-12,
        "left half ends at the left limit"
    );
    assert!(
        (r.point(4.0) - points[first4]).norm() < 1e-12,
        "right half starts at the right value"
    );
    // Degree 1: every interior knot is a C0 break.
    let poly = NurbsCurve::try_new(
        1,
        vec![0.0, 0.0, 0.5, 0.7, 1.0, 1.0],
        vec![Point3::origin(); 4],
        None,
    )
    .expect("valid");
    assert_eq!(poly.c0_breaks(), vec![0.5, 0.7], "polyline corners");
    // A clamped curve without repeated interior knots has none; neither do the domain ends.
    let smooth = twisted_cubic(0.0, 1.0);
    assert!(smooth.c0_breaks().is_empty(), "no interior knots");
}

// ---------------------------------------------------------------------------------------------
// Errors: every variant, its Display message
// ---------------------------------------------------------------------------------------------

fn pts(n: usize) -> Vec<Point3<f64>> {
    (0..n)
        .map(|i| Point3::new(i as f64, (i * i) as f64, 0.0))
        .collect()
}

fn err(
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Point3<f64>>,
    weights: Option<Vec<f64>>,
) -> NurbsError {
    NurbsCurve::try_new(degree, knots, points, weights).expect_err("invalid data must be rejected")
}

#[test]
fn construction_errors_and_messages() {
    let cases: Vec<(NurbsError, &str)> = vec![
        (
            err(0, vec![0.0, 1.0], pts(1), None),
            "degree: degree must be at least 1 (got 0)",
        ),
        (
            err(25, vec![0.0; 52], pts(26), None),
            "degree: degree 25 is above the maximum 24",
        ),
        (
            err(3, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts(3), None),
            "control_points: 3 control points are too few for degree 3 (need at least 4)",
        ),
        (
            err(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts(4), None),
            "knots: expected 7 knots (control points + degree + 1), got 6",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, f64::NAN, 1.0, 1.0, 1.0, 1.0],
                pts(4),
                None,
            ),
            "knots[2]: knot must be finite (got NaN)",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0, f64::INFINITY],
                pts(4),
                None,
            ),
            "knots[6]: knot must be finite (got inf)",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 0.3, 0.7, 0.5, 1.0, 1.0, 1.0],
                pts(6),
                None,
            ),
            "knots[5]: knots must be non-decreasing (0.5 after 0.7)",
        ),
        (
            err(2, vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts(4), None),
            "knots[3]: knot 0 is repeated 4 times, more than degree + 1 = 3",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0],
                pts(7),
                None,
            ),
            "knots[6]: knot 0.5 is repeated 4 times, more than degree + 1 = 3",
        ),
        (
            err(1, vec![0.0, 1.0, 1.0, 2.0], pts(2), None),
            "knots: empty parameter domain [1, 1]",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                vec![
                    Point3::new(0.0, 0.0, 0.0),
                    Point3::new(1.0, f64::NAN, 0.0),
                    Point3::new(2.0, 0.0, 0.0),
                ],
                None,
            ),
            "control_points[1]: control point must be finite (got [1, NaN, 0])",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                pts(3),
                Some(vec![1.0, 1.0]),
            ),
            "weights: expected 3 weights (one per control point), got 2",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                pts(3),
                Some(vec![1.0, 0.0, 1.0]),
            ),
            "weights[1]: weight must be finite and > 0 (got 0)",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                pts(3),
                Some(vec![1.0, 1.0, -2.5]),
            ),
            "weights[2]: weight must be finite and > 0 (got -2.5)",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                pts(3),
                Some(vec![f64::NAN, 1.0, 1.0]),
            ),
            "weights[0]: weight must be finite and > 0 (got NaN)",
        ),
        (
            err(
                2,
                vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
                pts(3),
                Some(vec![1.0, f64::INFINITY, 1.0]),
            ),
            "weights[1]: weight must be finite and > 0 (got inf)",
        ),
    ];
    for (e, msg) in &cases {
        assert_eq!(e.to_string(), *msg, "message of {e:?}");
    }
    // The variants, not only the messages.
    assert!(
        matches!(cases[0].0, NurbsError::DegreeZero { field: "degree" }),
        "DegreeZero"
    );
    assert!(
        matches!(
            cases[1].0,
            NurbsError::DegreeTooHigh {
                degree: 25,
                max: 24,
                ..
            }
        ),
        "DegreeTooHigh"
    );
    assert!(
        matches!(
            cases[2].0,
            NurbsError::TooFewPoints {
                got: 3,
                degree: 3,
                needed: 4,
                ..
            }
        ),
        "TooFewPoints"
    );
    assert!(
        matches!(
            cases[3].0,
            NurbsError::KnotCount {
                expected: 7,
                got: 6,
                ..
            }
        ),
        "KnotCount"
    );
    assert!(
        matches!(cases[4].0, NurbsError::KnotNotFinite { index: 2, .. }),
        "KnotNotFinite"
    );
    assert!(
        matches!(cases[6].0, NurbsError::KnotsDecreasing { index: 5, .. }),
        "KnotsDecreasing"
    );
    assert!(
        matches!(
            cases[7].0,
            NurbsError::KnotMultiplicity {
                index: 3,
                multiplicity: 4,
                max: 3,
                ..
            }
        ),
        "KnotMultiplicity"
    );
    assert!(
        matches!(cases[9].0, NurbsError::EmptyDomain { .. }),
        "EmptyDomain"
    );
    assert!(
        matches!(cases[10].0, NurbsError::PointNotFinite { .. }),
        "PointNotFinite"
    );
    assert!(
        matches!(
            cases[11].0,
            NurbsError::WeightCount {
                expected: 3,
                got: 2,
                ..
            }
        ),
        "WeightCount"
    );
    assert!(
        matches!(cases[12].0, NurbsError::BadWeight { .. }),
        "BadWeight"
    );
}

#[test]
fn equal_weights_other_than_one_are_polynomial_and_valid() {
    let c = NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        pts(3),
        Some(vec![3.0; 3]),
    )
    .expect("valid");
    assert!(!c.is_rational(), "equal weights are not rational");
    let d =
        NurbsCurve::try_new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], pts(3), None).expect("valid");
    for i in 0..=10 {
        let t = f64::from(i) / 10.0;
        assert!(
            (c.point(t) - d.point(t)).norm() <= 1e-15,
            "common weight cancels"
        );
    }
}

#[test]
#[should_panic(expected = "invalid NURBS curve: degree: degree must be at least 1 (got 0)")]
fn new_panics_with_the_error_message() {
    let _ = NurbsCurve::new(0, vec![0.0, 1.0], pts(1), None);
}

#[test]
fn operation_errors_and_messages() {
    let c = NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0],
        pts(4),
        Some(vec![1.0, 2.0, 0.5, 1.0]),
    )
    .expect("valid");
    let outside = |e: NurbsError| {
        assert!(
            matches!(e, NurbsError::ParameterOutsideDomain { .. }),
            "expected ParameterOutsideDomain, got {e:?}"
        );
        e.to_string()
    };
    assert_eq!(
        outside(c.insert_knot(1.5, 1).expect_err("outside")),
        "parameter 1.5 is outside the domain [0, 1]",
        "insert_knot above the domain"
    );
    assert_eq!(
        outside(c.insert_knot(f64::NAN, 1).expect_err("NaN")),
        "parameter NaN is outside the domain [0, 1]",
        "insert_knot at NaN"
    );
    assert_eq!(
        outside(c.split(0.0).expect_err("domain start")),
        "parameter 0 is outside the domain [0, 1]",
        "split at the domain start"
    );
    assert_eq!(
        outside(c.split(1.0).expect_err("domain end")),
        "parameter 1 is outside the domain [0, 1]",
        "split at the domain end"
    );
    assert_eq!(
        outside(c.split(f64::NAN).expect_err("NaN")),
        "parameter NaN is outside the domain [0, 1]",
        "split at NaN"
    );
    assert_eq!(
        outside(c.bezier_pieces(-0.25, 0.5).expect_err("outside")),
        "parameter -0.25 is outside the domain [0, 1]",
        "bezier_pieces starting before the domain"
    );
    assert_eq!(
        outside(c.bezier_pieces(0.25, f64::INFINITY).expect_err("outside")),
        "parameter inf is outside the domain [0, 1]",
        "bezier_pieces ending at infinity"
    );
    let total = c.arc_length();
    assert_eq!(
        outside(c.param_at_length(-1.0).expect_err("negative length")),
        format!("parameter -1 is outside the domain [0, {total}]"),
        "param_at_length below 0"
    );
    assert_eq!(
        outside(c.param_at_length(total * 1.5).expect_err("too long")),
        format!(
            "parameter {} is outside the domain [0, {total}]",
            total * 1.5
        ),
        "param_at_length beyond the length"
    );
    assert!(
        c.param_at_length(f64::NAN).is_err(),
        "param_at_length at NaN"
    );

    let e = c
        .insert_knot(0.5, 2)
        .expect_err("multiplicity 3 > degree 2");
    assert!(
        matches!(
            e,
            NurbsError::InsertionTooMany {
                times: 2,
                degree: 2,
                ..
            }
        ),
        "InsertionTooMany"
    );
    assert_eq!(
        e.to_string(),
        "inserting 0.5 2 times would raise its multiplicity above the degree 2",
        "InsertionTooMany message"
    );
    assert_eq!(
        c.insert_knot(0.25, 3).expect_err("3 > degree").to_string(),
        "inserting 0.25 3 times would raise its multiplicity above the degree 2",
        "InsertionTooMany at a new knot"
    );
    // Inserting zero times is the identity.
    assert_eq!(c.insert_knot(0.25, 0).expect("no-op"), c, "insert 0 times");

    for (t0, t1) in [(0.6, 0.3), (0.5, 0.5)] {
        let e = c.bezier_pieces(t0, t1).expect_err("empty or reversed");
        assert_eq!(
            e,
            NurbsError::BadInterval { t0, t1 },
            "BadInterval for [{t0}, {t1}]"
        );
        assert_eq!(
            e.to_string(),
            format!("interval [{t0}, {t1}] is empty or reversed"),
            "BadInterval message"
        );
    }

    // RaggedGrid is produced by surfaces only; its message format is checked here.
    let e = NurbsError::RaggedGrid {
        field: "control_points",
        row: 2,
        got: 3,
        expected: 4,
    };
    assert_eq!(
        e.to_string(),
        "control_points[2]: row has 3 entries, expected 4",
        "RaggedGrid message"
    );
}

#[test]
fn evaluation_at_nan_and_infinity_does_not_panic() {
    let c = Circle::new(
        2.0,
        3,
        Point3::new(1.0, 2.0, 3.0),
        Rotation3::identity(),
        0.0,
        1.0,
    )
    .curve;
    let (a, b) = c.domain();
    for t in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e300, 1e300] {
        let p = c.point(t);
        assert!(
            p.iter().all(|x| x.is_finite()),
            "point({t}) is not finite: {p:?}"
        );
        let expected = if t > b { c.point(b) } else { c.point(a) };
        assert_eq!(p, expected, "point({t}) clamps to the domain");
        for d in c.derivatives(t, 5) {
            assert!(d.iter().all(|x| x.is_finite()), "derivative at {t}");
        }
        assert!(c.curvature(t).is_finite(), "curvature at {t}");
        assert!(c.curvature_derivative(t).is_finite(), "dk/ds at {t}");
        assert!(c.frenet_frame(t).is_some(), "frame at {t}");
        assert!(c.tangent(t).is_some(), "tangent at {t}");
        assert!(c.tangent_limit(t).is_some(), "tangent_limit at {t}");
        let _ = c.eval_d3(t);
        assert!(c.speed(t).is_finite(), "speed at {t}");
        assert!(c.span(t) >= c.degree(), "span at {t}");
        let l = c.arc_length_between(t, b);
        assert!(
            l.is_finite() && l >= 0.0,
            "arc_length_between({t}, b) = {l}"
        );
        let l = c.arc_length_between(a, t);
        assert!(
            l.is_finite() && l >= 0.0,
            "arc_length_between(a, {t}) = {l}"
        );
    }
}

#[test]
fn bezier_weights_positive_for_extreme_weights() {
    // Weights spanning six orders of magnitude; the blossom's de Boor steps are convex
    // combinations, so every Bezier weight stays positive.
    let knots = vec![0.0, 0.0, 0.0, 0.0, 0.1, 0.1, 0.4, 0.9, 1.0, 1.0, 1.0, 1.0];
    let weights = vec![1e-3, 1e3, 1e-3, 1e3, 1e-3, 1e3, 1e-3, 1e3];
    let c = NurbsCurve::try_new(3, knots, pts(8), Some(weights)).expect("valid");
    for piece in c.bezier_pieces(0.05, 0.95).expect("valid") {
        assert!(
            piece.homogeneous().iter().all(|q| q.w > 0.0),
            "positive weights"
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Arc length on random curves
// ---------------------------------------------------------------------------------------------

/// The length of the polyline through `n` evenly spaced parameters per breakpoint interval.
fn chord_length(c: &NurbsCurve, t0: f64, t1: f64, n: usize) -> f64 {
    let bp = breakpoints(c);
    let mut cuts: Vec<f64> = vec![t0];
    cuts.extend(bp.iter().copied().filter(|&k| k > t0 && k < t1));
    cuts.push(t1);
    let mut total = 0.0;
    for w in cuts.windows(2) {
        let mut prev = c.point(w[0]);
        for i in 1..=n {
            // The last point of a piece is its left limit (the piece is continuous up to it).
            let t = if i == n {
                w[1]
            } else {
                w[0] + (w[1] - w[0]) * i as f64 / n as f64
            };
            let q = if i == n {
                c.bezier_in_span(c.span(w[0]), w[0], w[1]).point_local(1.0)
            } else {
                c.point(t)
            };
            total += (q - prev).norm();
            prev = q;
        }
    }
    total
}

/// The length by composite 3-point Gauss-Legendre quadrature of `|C'|` on `n` equal panels
/// per breakpoint interval.
fn composite_gauss_length(c: &NurbsCurve, t0: f64, t1: f64, n: usize) -> f64 {
    let x = (0.6f64).sqrt();
    let nodes = [(-x, 5.0 / 9.0), (0.0, 8.0 / 9.0), (x, 5.0 / 9.0)];
    let mut cuts: Vec<f64> = vec![t0];
    cuts.extend(breakpoints(c).into_iter().filter(|&k| k > t0 && k < t1));
    cuts.push(t1);
    let mut total = 0.0;
    for w in cuts.windows(2) {
        let h = (w[1] - w[0]) / n as f64;
        for i in 0..n {
            let m = w[0] + (i as f64 + 0.5) * h;
            for (xi, wi) in nodes {
                total += wi * 0.5 * h * c.speed(m + 0.5 * h * xi);
            }
        }
    }
    total
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn arc_length_matches_composite_quadrature(c in curve(), u0 in 0.0..=1.0f64, u1 in 0.0..=1.0f64) {
        let (a, b) = c.domain();
        let (t0, t1) = (a + u0.min(u1) * (b - a), a + u0.max(u1) * (b - a));
        prop_assume!(t1 > t0);
        let l = c.arc_length_between(t0, t1);
        // No polyline is longer than the arc.
        let chords = chord_length(&c, t0, t1, 50);
        // (up to the quadrature's documented accuracy: 1e-13 relative or the absolute floor at
        // the coordinates' rounding, `length_floor`, whichever is larger)
        let slack = chords * 1e-12 + c.length_floor(c.spans().len());
        prop_assert!(l >= chords - slack, "a chord is never longer than its arc: {} < {} - {}", l, chords, slack);
        // Composite 3-point Gauss on 64 and 128 panels per smooth piece (an open rule: the
        // speed is never taken at a knot, where it may jump); only where the two agree to
        // 1e-9 (narrow features of large weight ratios need more panels).
        let g1 = composite_gauss_length(&c, t0, t1, 64);
        let g2 = composite_gauss_length(&c, t0, t1, 128);
        prop_assume!((g2 - g1).abs() <= 1e-9 * g2);
        prop_assert!(
            (l - g2).abs() <= (g2 - g1).abs() + 1e-12 * l + 1e-13 * c.size(),
            "length {} vs composite Gauss {} ({} on half the panels)", l, g2, g1
        );
        // Additivity across an interior split point.
        let tm = 0.5 * (t0 + t1);
        let parts = c.arc_length_between(t0, tm) + c.arc_length_between(tm, t1);
        prop_assert!((parts - l).abs() <= 1e-11 * l + 1e-13 * c.size(), "additivity: {} vs {}", parts, l);
    }

}

proptest! {
    // param_at_length integrates the length again at every Newton step: few cases.
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn param_at_length_inverts_arc_length_on_random_curves(
        c in common::curve_data_with(1..=5, 5).prop_map(|d| d.curve()),
        f in 0.0..=1.0f64,
    ) {
        let (a, b) = c.domain();
        let total = c.arc_length();
        prop_assume!(total > 1e-9 * c.size());
        let s = f * total;
        let t = c.param_at_length(s).expect("s is within the length");
        prop_assert!((a..=b).contains(&t), "parameter {} outside the domain", t);
        let back = c.arc_length_between(a, t);
        prop_assert!((back - s).abs() <= 1e-10 * total, "length to {} is {}, wanted {}", t, back, s);
    }
}

/// Issue 13: the arc length's quadrature has a floor and a budget, and a guaranteed bracket
/// that catches speed peaks its Gauss nodes miss.
#[test]
fn arc_length_of_extreme_weights_and_far_small_circles_is_budgeted() {
    let arc = |w: f64| {
        NurbsCurve::new(
            2,
            vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            vec![
                Point3::new(50.0, 0.0, 0.0),
                Point3::new(50.0, 50.0, 0.0),
                Point3::new(0.0, 50.0, 0.0),
            ],
            Some(vec![1.0, w, 1.0]),
        )
    };
    let budget = 30 + 40 * kerf_nurbs::SPLITS_PER_SPAN;
    // Weight 1e12: the curve is the control polygon's two legs (length 100 to 1e-10), traced
    // within 1e-11 of the parameter's ends, where no Gauss node of a coarse panel looks.
    let q = arc(1e12).arc_length_quadrature(0.0, 1.0);
    assert!(q.evaluations <= budget, "{q:?}");
    assert!((q.value - 100.0).abs() <= 1e-6 + q.error, "{q:?}");
    // Weight 1e-12: the straight chord, length 50 sqrt 2.
    let q = arc(1e-12).arc_length_quadrature(0.0, 1.0);
    assert!(q.evaluations <= budget, "{q:?}");
    assert!((q.value - 50.0 * 2f64.sqrt()).abs() < 1e-6, "{q:?}");
    // A 0.1 mm circle at x = 1400: 1e-13 of its size is below the coordinates' rounding; the
    // floor stops the quadrature at once instead of recursing to the full depth.
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let sq = [
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
    let hole = NurbsCurve::new(
        2,
        vec![
            0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
        ],
        sq.iter()
            .map(|&(x, y)| Point3::new(1400.0 + 0.05 * x, 700.0 + 0.05 * y, 0.0))
            .collect(),
        Some(vec![1.0, h, 1.0, h, 1.0, h, 1.0, h, 1.0]),
    );
    let q = hole.arc_length_quadrature(0.0, 1.0);
    assert!(q.converged, "converged at the rounding floor: {q:?}");
    assert!(q.evaluations <= 4 * budget, "{q:?}");
    assert!(
        (q.value - std::f64::consts::PI * 0.1).abs() < 1e-10,
        "{q:?}"
    );
}

/// The review's `d3tiny_*` curves: random control points in a 1 um box on uniform knots in
/// `[0, 1]`. With many spans the rounding of the Gauss nodes' parameters (an ulp of `t ~ 0.5`
/// against spans `1 / n` wide) moves each panel's estimate by more than its share of `1e-13 L`,
/// so the quadrature split noise: 20,000 spans took 418 evaluations per span, 50,000 took 659,
/// 200,000 ran for minutes. The parameter's rounding is part of the floor now, and the work per
/// span stays flat.
#[test]
fn arc_length_work_per_span_does_not_grow_with_the_span_count() {
    let jagged = |n: usize| {
        let mut s: u64 = 12345;
        let mut r = || {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut knots = vec![0.0; 4];
        knots.extend((1..n - 3).map(|k| k as f64 / (n - 3) as f64));
        knots.extend([1.0; 4]);
        let points = (0..n)
            .map(|_| Point3::new(1e-3 * r(), 1e-3 * r(), 0.0))
            .collect();
        NurbsCurve::new(3, knots, points, None)
    };
    for n in [2_000, 20_000] {
        let c = jagged(n);
        let q = c.arc_length_quadrature(0.0, 1.0);
        assert!(q.converged, "{n} spans: {q:?}");
        assert!(
            q.evaluations <= 150 * n,
            "{n} spans: {} evaluations",
            q.evaluations
        );
        // The claim still holds: span by span (each its own quadrature, far from the noise)
        // the lengths add up to the whole within the reported error.
        let by_span: f64 = c
            .spans()
            .into_iter()
            .map(|(_, a, b)| c.arc_length_between(a, b))
            .sum();
        assert!(
            (by_span - q.value).abs() <= q.error.max(1e-12 * q.value),
            "{n} spans: {by_span} by span, {q:?}"
        );
        assert!(q.error <= 1e-10 * q.value, "{n} spans: {q:?}");
    }
}

/// The quadrature never exceeds its budget, whatever the integrand does.
#[test]
fn integrate_stops_at_its_budget_on_a_hostile_integrand() {
    use kerf_nurbs::integrate;
    // Rough everywhere: no accuracy is reachable.
    let q = integrate(
        |t| (1e6 * t).sin().abs() * 1e3,
        None,
        &[(0.0, 1.0)],
        1e-15,
        0.0,
        50,
    );
    assert_eq!(q.evaluations, 30 + 40 * 50, "the budget is exact: {q:?}");
    assert!(!q.converged, "reported unconverged");
    // NaN somewhere: never reported converged, never loops.
    let q = integrate(
        |t| if t > 0.5 { f64::NAN } else { 1.0 },
        None,
        &[(0.0, 1.0)],
        1e-9,
        0.0,
        20,
    );
    assert!(!q.converged && q.evaluations <= 30 + 40 * 20, "{q:?}");
}
