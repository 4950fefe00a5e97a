//! The shape constructors against exact geometry: distances from the centre or the axis,
//! the plane of a circle, curvature 1/r, exact end points and sweep, analytic normals, and a
//! revolved line against the cylinder and cone it must be.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use kerf_nurbs::{NurbsCurve, NurbsError, NurbsSurface};
use nalgebra::{Point3, Vector3};

const N: usize = 2000;

fn params(n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| i as f64 / n as f64)
}

fn is_bad_shape<T: std::fmt::Debug>(r: Result<T, NurbsError>, field: &str) {
    match r {
        Err(NurbsError::BadShape {
            field: f,
            ref reason,
        }) => {
            assert_eq!(f, field, "{reason}");
            let msg = r.unwrap_err().to_string();
            assert!(
                msg.starts_with(field),
                "the message names the argument: {msg}"
            );
        }
        other => panic!("expected BadShape({field}), got {other:?}"),
    }
}

#[test]
fn circle_points_lie_on_the_circle_in_its_plane_with_curvature_one_over_r() {
    let center = Point3::new(12.5, -3.0, 40.0);
    for (normal, r) in [
        (Vector3::z(), 1.0),
        (Vector3::new(1.0, 2.0, -0.5), 30.0),
        (Vector3::new(0.0, -1.0, 1e-3), 1e-3),
        (Vector3::x(), 2500.0),
    ] {
        let c = NurbsCurve::circle(center, normal, r).expect("circle");
        assert_eq!(c.domain(), (0.0, 1.0));
        assert_eq!(c.len(), 9, "the standard 9-point circle");
        assert!(c.is_closed());
        let n = normal.normalize();
        // Relative to the coordinates' size: a 1 um circle at 40 mm rounds at 40 mm's ulp.
        let scale = r.max(center.coords.norm());
        for t in params(N) {
            let p = c.point(t);
            let d = p - center;
            assert!(
                (d.norm() - r).abs() <= 1e-12 * scale,
                "t {t}: |p - c| = {}",
                d.norm()
            );
            assert!(d.dot(&n).abs() <= 1e-12 * scale, "t {t}: in the plane");
            let k = c.curvature(t);
            assert!(
                (k * r - 1.0).abs() <= 1e-9,
                "t {t}: curvature {k} vs {}",
                1.0 / r
            );
            // Counter-clockwise about the normal: (p - c) x tangent is along +n.
            let tan = c.tangent(t).expect("tangent");
            assert!((d.cross(&tan) / r - n).norm() < 1e-9, "t {t}: sense");
        }
        // The weights are those of the square construction.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let w = c.weights();
        for (i, w) in w.iter().enumerate() {
            let want = if i % 2 == 1 { h } else { 1.0 };
            assert!((w - want).abs() < 1e-15, "weight {i}: {w}");
        }
    }
}

#[test]
fn circle_angle_per_quarter_is_exactly_ninety_degrees() {
    let c = NurbsCurve::circle(Point3::origin(), Vector3::z(), 2.0).unwrap();
    let x = c.point(0.0).coords;
    for (q, t) in [0.25, 0.5, 0.75, 1.0].iter().enumerate() {
        let p = c.point(*t).coords;
        let angle = x.y.atan2(x.x) + FRAC_PI_2 * (q + 1) as f64;
        let want = Vector3::new(angle.cos(), angle.sin(), 0.0) * 2.0;
        assert!((p - want).norm() < 1e-14, "quarter {q}: {p:?} vs {want:?}");
    }
}

#[test]
fn arcs_have_exact_end_points_sweep_and_fewest_segments() {
    let center = Point3::new(1.0, 2.0, 3.0);
    let x = Vector3::new(1.0, 1.0, 0.0);
    let y = Vector3::new(-1.0, 1.0, 0.5); // not orthogonal: only its orthogonal part counts
    let xu = x.normalize();
    let yu = (y - xu * xu.dot(&y)).normalize();
    let r = 7.5;
    let on = |a: f64| center + xu * (r * a.cos()) + yu * (r * a.sin());
    for (start, sweep, segments) in [
        (0.3, 0.1, 1),
        (0.3, FRAC_PI_2, 1),
        (-1.0, FRAC_PI_2 + 1e-6, 2),
        (2.0, PI, 2),
        (2.0, -PI, 2),
        (0.0, 4.0, 3),
        (-0.7, 5.0, 4),
        (0.0, TAU, 4),
        (1.0, -TAU, 4),
    ] {
        let c = NurbsCurve::arc(center, x, y, r, start, sweep).expect("arc");
        assert_eq!(c.len(), 2 * segments + 1, "sweep {sweep}: segments");
        assert!((c.point(0.0) - on(start)).norm() < 1e-13 * r);
        assert!((c.point(1.0) - on(start + sweep)).norm() < 1e-13 * r);
        // Dense sample: on the circle, in the plane, and the angle advances monotonically by
        // exactly the sweep.
        let mut turned = 0.0;
        let mut prev = start;
        for t in params(N) {
            let p = c.point(t);
            let d = p - center;
            assert!((d.norm() - r).abs() <= 1e-12 * r);
            assert!(d.dot(&xu.cross(&yu)).abs() <= 1e-12 * r);
            assert!((c.curvature(t) * r - 1.0).abs() < 1e-9);
            let a = d.dot(&yu).atan2(d.dot(&xu));
            let step = (a - prev + PI).rem_euclid(TAU) - PI;
            assert!(step * sweep.signum() >= -1e-12, "monotone");
            turned += step;
            prev = a;
        }
        assert!((turned - sweep).abs() < 1e-9, "swept {turned}");
        if sweep.abs() == TAU {
            assert!(c.is_closed(), "a full turn closes exactly");
        }
    }
}

#[test]
fn lines_and_polylines_pass_through_their_points_at_chord_length_parameters() {
    let a = Point3::new(0.0, 0.0, 0.0);
    let b = Point3::new(3.0, 4.0, 0.0);
    let l = NurbsCurve::line(a, b).unwrap();
    assert_eq!(l.degree(), 1);
    for t in params(50) {
        assert!((l.point(t) - (a + (b - a) * t)).norm() < 1e-15);
    }
    let pts = [
        a,
        b,
        Point3::new(3.0, 4.0, 10.0),
        Point3::new(0.0, 0.0, 10.0),
    ];
    let p = NurbsCurve::polyline(&pts).unwrap();
    // Lengths 5, 10, 5: the corners at parameters 1/4 and 3/4.
    assert!((p.point(0.25) - pts[1]).norm() < 1e-14);
    assert!((p.point(0.75) - pts[2]).norm() < 1e-14);
    assert!((p.point(0.5) - Point3::new(3.0, 4.0, 5.0)).norm() < 1e-14);
    assert_eq!(p.c0_breaks().len(), 2, "C0 corners at the inner points");
}

#[test]
fn plane_points_and_normals_are_the_rectangle_and_u_cross_v() {
    let o = Point3::new(10.0, -5.0, 2.0);
    let u = Vector3::new(2.0, 0.0, 1.0);
    let v = Vector3::new(0.0, 3.0, 0.0);
    let s = NurbsSurface::plane(o, u, v, 40.0, 25.0).unwrap();
    let n = u.cross(&v).normalize();
    for a in params(20) {
        for b in params(20) {
            let want = o + u.normalize() * (40.0 * a) + v.normalize() * (25.0 * b);
            assert!((s.point(a, b) - want).norm() < 1e-12);
            assert!((s.normal(a, b).unwrap() - n).norm() < 1e-14);
        }
    }
}

#[test]
fn cylinder_points_are_at_radius_and_normals_radial_outwards() {
    let o = Point3::new(-2.0, 1.0, 0.5);
    let axis = Vector3::new(0.3, -1.0, 2.0);
    let a = axis.normalize();
    let (r, h) = (12.0, 35.0);
    let s = NurbsSurface::cylinder(o, axis, r, h).unwrap();
    for u in params(200) {
        for v in params(20) {
            let p = s.point(u, v);
            let d = p - o;
            let along = d.dot(&a);
            let radial = d - a * along;
            assert!((radial.norm() - r).abs() <= 1e-12 * r, "({u}, {v}) radius");
            assert!((along - h * v).abs() <= 1e-12 * h, "({u}, {v}) height");
            let n = s.normal(u, v).unwrap();
            assert!((n - radial / r).norm() < 1e-10, "({u}, {v}) normal {n:?}");
        }
    }
}

#[test]
fn sphere_points_are_at_radius_and_normals_radial_including_the_poles() {
    let c = Point3::new(5.0, 6.0, -7.0);
    let r = 20.0;
    let s = NurbsSurface::sphere(c, r).unwrap();
    for u in params(100) {
        for v in params(100) {
            let d = s.point(u, v) - c;
            assert!(
                (d.norm() - r).abs() <= 1e-12 * r,
                "({u}, {v}): {}",
                d.norm()
            );
            let n = s.normal(u, v).expect("a normal, also at the poles");
            assert!(
                (n - d / r).norm() < 1e-8,
                "({u}, {v}): normal {n:?} vs {:?}",
                d / r
            );
        }
    }
    assert!((s.point(0.3, 0.0) - (c - Vector3::z() * r)).norm() < 1e-12);
    assert!((s.point(0.3, 1.0) - (c + Vector3::z() * r)).norm() < 1e-12);
}

#[test]
fn revolving_lines_gives_the_cylinder_and_the_cone() {
    let o = Point3::new(1.0, 1.0, 1.0);
    let axis = Vector3::new(0.0, 0.0, 2.0);
    // A line parallel to the axis at distance 4: the cylinder, over a 3/4 turn.
    let line = NurbsCurve::line(Point3::new(5.0, 1.0, 1.0), Point3::new(5.0, 1.0, 9.0)).unwrap();
    let cyl = NurbsSurface::revolve(&line, o, axis, 1.5 * PI).unwrap();
    for u in params(100) {
        for v in params(10) {
            let d = cyl.point(u, v) - o;
            let rho = (d.x * d.x + d.y * d.y).sqrt();
            assert!((rho - 4.0).abs() < 1e-12 * 4.0);
            assert!((d.z - 8.0 * v).abs() < 1e-12 * 8.0);
            let angle = d.y.atan2(d.x).rem_euclid(TAU);
            assert!(angle <= 1.5 * PI + 1e-12, "within the sweep: {angle}");
        }
    }
    assert!(
        (cyl.point(1.0, 0.0) - Point3::new(1.0, -3.0, 1.0)).norm() < 1e-12,
        "swept 270 deg"
    );
    // A line from the axis outwards and up: the cone rho = z / 2 with its apex on the axis.
    let slant = NurbsCurve::line(o, o + Vector3::new(3.0, 0.0, 6.0)).unwrap();
    let cone = NurbsSurface::revolve(&slant, o, axis, TAU).unwrap();
    for u in params(100) {
        for v in params(10) {
            let d = cone.point(u, v) - o;
            let rho = (d.x * d.x + d.y * d.y).sqrt();
            assert!(
                (rho - d.z / 2.0).abs() < 1e-12 * 6.0,
                "({u}, {v}) on the cone"
            );
            assert!((d.z - 6.0 * v).abs() < 1e-12 * 6.0);
            if v > 0.0 {
                // Analytic cone normal: (cos a, sin a, -1/2) normalised, pointing away from the
                // axis and down (the profile runs up, the turn is counter-clockwise).
                let a = d.y.atan2(d.x);
                let want = Vector3::new(a.cos(), a.sin(), -0.5).normalize();
                let n = cone.normal(u, v).unwrap();
                assert!(
                    (n - want).norm() < 1e-9,
                    "({u}, {v}) normal {n:?} vs {want:?}"
                );
            }
        }
    }
}

#[test]
fn degenerate_or_non_finite_input_is_an_error_naming_the_argument() {
    let o = Point3::origin();
    let z = Vector3::z();
    is_bad_shape(NurbsCurve::circle(o, z, 0.0), "radius");
    is_bad_shape(NurbsCurve::circle(o, z, -1.0), "radius");
    is_bad_shape(NurbsCurve::circle(o, z, f64::NAN), "radius");
    is_bad_shape(NurbsCurve::circle(o, Vector3::zeros(), 1.0), "normal");
    is_bad_shape(
        NurbsCurve::circle(Point3::new(f64::INFINITY, 0.0, 0.0), z, 1.0),
        "center",
    );
    let x = Vector3::x();
    is_bad_shape(NurbsCurve::arc(o, x, x * 2.0, 1.0, 0.0, 1.0), "y_axis");
    is_bad_shape(NurbsCurve::arc(o, x, z, 1.0, 0.0, 0.0), "sweep_rad");
    is_bad_shape(NurbsCurve::arc(o, x, z, 1.0, 0.0, 7.0), "sweep_rad");
    is_bad_shape(NurbsCurve::arc(o, x, z, 1.0, f64::NAN, 1.0), "start_rad");
    is_bad_shape(NurbsCurve::line(o, o), "points");
    is_bad_shape(NurbsCurve::polyline(&[o]), "points");
    is_bad_shape(
        NurbsCurve::polyline(&[o, Point3::new(1.0, f64::NAN, 0.0)]),
        "points",
    );
    is_bad_shape(NurbsSurface::plane(o, x, -x, 1.0, 1.0), "v_axis");
    is_bad_shape(NurbsSurface::plane(o, x, z, 0.0, 1.0), "u_len");
    is_bad_shape(NurbsSurface::plane(o, x, z, 1.0, f64::INFINITY), "v_len");
    is_bad_shape(
        NurbsSurface::cylinder(o, Vector3::zeros(), 1.0, 1.0),
        "axis_dir",
    );
    is_bad_shape(NurbsSurface::cylinder(o, z, 1.0, 0.0), "height");
    is_bad_shape(NurbsSurface::sphere(o, 0.0), "radius");
    let on_axis = NurbsCurve::line(o, o + z).unwrap();
    is_bad_shape(NurbsSurface::revolve(&on_axis, o, z, PI), "profile");
    let off = NurbsCurve::line(o + x, o + x + z).unwrap();
    is_bad_shape(NurbsSurface::revolve(&off, o, z, -7.0), "sweep_rad");
    is_bad_shape(
        NurbsSurface::revolve(&off, o, Vector3::zeros(), PI),
        "axis_dir",
    );
}
