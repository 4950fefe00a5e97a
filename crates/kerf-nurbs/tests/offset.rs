//! Offsets of NURBS surfaces against closed forms: a cylinder's offsets are cylinders, a
//! height field's offset is `S + d (-z_x, -z_y, 1) / |.|` with the partial derivatives taken
//! from the Bernstein polynomials directly, and the bound proven is checked by dense sampling.

use kerf_nurbs::{NurbsSurface, SurfaceOffsetError, SurfaceOffsetOptions};
use nalgebra::{Point3, Vector3};

/// The angle between two vectors, rad.
fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

#[test]
fn a_cylinders_offsets_are_the_cylinders_of_the_radius_plus_and_minus_the_distance() {
    let r = 20.0;
    let c = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), r, 10.0).expect("cylinder");
    for d in [2.0, -2.0, 0.5] {
        let tol = 1e-4;
        let o = c
            .offset(d, &SurfaceOffsetOptions::new(tol))
            .expect("certified");
        assert!(
            o.position_bound_mm <= tol,
            "bound {} within the tolerance",
            o.position_bound_mm
        );
        // The rational circle's `W n` is a polynomial: the interpolation is exact and the
        // bound is the rounding allowance, never zero.
        assert!(
            o.position_bound_mm > 0.0,
            "the bound keeps its rounding allowance"
        );
        let mut worst: f64 = 0.0;
        let mut worst_normal: f64 = 0.0;
        for i in 0..=200 {
            for j in 0..=10 {
                let (u, v) = (i as f64 / 200.0, j as f64 / 10.0);
                let p = o.surface.point(u, v);
                // Against the closed form: the radius r + d, at the same height and angle.
                let s = c.point(u, v);
                let radial = Vector3::new(s.x, s.y, 0.0) / r;
                let exact = s + radial * d;
                worst = worst.max((p - exact).norm());
                let n = o.surface.normal(u, v).expect("regular");
                worst_normal = worst_normal.max(angle(&n, &radial));
            }
        }
        assert!(
            worst <= o.position_bound_mm,
            "d {d}: the dense distance {worst:.3e} is within the bound {:.3e}",
            o.position_bound_mm
        );
        assert!(
            worst_normal <= o.normal_bound_rad,
            "d {d}: normal angle {worst_normal:.3e} within the bound {:.3e}",
            o.normal_bound_rad
        );
        // Not vacuous: the bound is within two orders of the error found.
        assert!(
            o.position_bound_mm < 100.0 * worst.max(1e-9),
            "d {d}: bound {:.3e} vs measured {worst:.3e}",
            o.position_bound_mm
        );
    }
}

/// Bernstein basis of degree 3 and its derivative at `t`.
fn bern3(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

#[test]
fn a_height_fields_offset_follows_its_analytic_normal() {
    // z(u, v) = sum z_ij B_i(u) B_j(v) over x = 100 u, y = 80 v (linear precision).
    let z = [
        [0.0, 12.0, -6.0, 3.0],
        [8.0, -4.0, 15.0, 0.0],
        [-5.0, 10.0, 2.0, 9.0],
        [4.0, -8.0, 6.0, -2.0],
    ];
    let (lx, ly) = (100.0, 80.0);
    let net: Vec<Vec<Point3<f64>>> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| Point3::new(lx * i as f64 / 3.0, ly * j as f64 / 3.0, z[i][j]))
                .collect()
        })
        .collect();
    let k = || vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let s = NurbsSurface::try_new(3, 3, k(), k(), net, None).expect("patch");
    let d = 3.0;
    let tol = 1e-4;
    let o = s
        .offset(d, &SurfaceOffsetOptions::new(tol))
        .expect("certified");
    assert!(o.cells > 1, "a curved patch is split ({} cells)", o.cells);
    let mut worst: f64 = 0.0;
    let mut worst_normal: f64 = 0.0;
    for i in 0..=120 {
        for j in 0..=120 {
            let (u, v) = (i as f64 / 120.0, j as f64 / 120.0);
            let ((bu, du), (bv, dv)) = (bern3(u), bern3(v));
            let (mut h, mut hu, mut hv) = (0.0, 0.0, 0.0);
            for a in 0..4 {
                for b in 0..4 {
                    h += z[a][b] * bu[a] * bv[b];
                    hu += z[a][b] * du[a] * bv[b];
                    hv += z[a][b] * bu[a] * dv[b];
                }
            }
            let n = Vector3::new(-hu / lx, -hv / ly, 1.0).normalize();
            let exact = Point3::new(lx * u, ly * v, h) + n * d;
            worst = worst.max((o.surface.point(u, v) - exact).norm());
            let na = o.surface.normal(u, v).expect("regular");
            worst_normal = worst_normal.max(angle(&na, &n));
        }
    }
    assert!(
        worst <= o.position_bound_mm && o.position_bound_mm <= tol,
        "dense {worst:.3e} <= bound {:.3e} <= {tol}",
        o.position_bound_mm
    );
    assert!(
        worst_normal <= o.normal_bound_rad,
        "normal {worst_normal:.3e} <= bound {:.3e}",
        o.normal_bound_rad
    );
}

#[test]
fn a_plane_offsets_exactly_and_a_fold_or_a_pole_is_refused_within_the_budget() {
    let plane = NurbsSurface::plane(
        Point3::new(1.0, 2.0, 3.0),
        Vector3::x(),
        Vector3::y(),
        50.0,
        20.0,
    )
    .expect("plane");
    let o = plane
        .offset(-1.5, &SurfaceOffsetOptions::new(1e-6))
        .expect("plane");
    assert_eq!(o.cells, 1, "a plane needs one cell");
    let p = o.surface.point(0.25, 0.75);
    assert!(
        (p - Point3::new(13.5, 17.0, 1.5)).norm() <= 1e-9,
        "the plane moved 1.5 against its normal: {p}"
    );
    // A cylinder of radius 20 offset 25 inward folds over: refused, within the budget.
    let c = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), 20.0, 10.0).expect("cylinder");
    let budget = 300;
    let fold = c.offset(
        -25.0,
        &SurfaceOffsetOptions::new(1e-4).with_max_work(budget),
    );
    assert!(
        matches!(fold, Err(SurfaceOffsetError::Folds { distance_mm, .. }) if distance_mm == -25.0),
        "a fold must be refused, got {fold:?}"
    );
    // A sphere's poles have no normal polynomial direction: refused, naming it.
    let sphere = NurbsSurface::sphere(Point3::origin(), 10.0).expect("sphere");
    let pole = sphere.offset(1.0, &SurfaceOffsetOptions::new(1e-4).with_max_work(budget));
    assert!(
        matches!(pole, Err(SurfaceOffsetError::NormalVanishes { .. })),
        "a pole must be refused, got {pole:?}"
    );
    // A tolerance no cell reaches spends the budget, and stops there.
    let fine = c.offset(2.0, &SurfaceOffsetOptions::new(1e-30).with_max_work(budget));
    match fine {
        Err(SurfaceOffsetError::Budget { cells, work, .. }) => {
            // The cylinder is rational (degree 3 once raised): 7 bicubic cells each.
            assert_eq!(work, 7 * cells, "each rational bicubic cell weighs 7");
            assert!(
                work <= budget && work + 7 > budget,
                "the work {work} stops within one cell of the budget {budget}"
            )
        }
        other => panic!("an unreachable tolerance must stop at the budget, got {other:?}"),
    }
    assert!(
        matches!(
            c.offset(f64::NAN, &SurfaceOffsetOptions::new(1e-4)),
            Err(SurfaceOffsetError::Arguments { .. })
        ),
        "NaN refused"
    );
}

#[test]
fn an_offset_near_the_radius_of_curvature_is_built_and_past_it_refused() {
    // A cubic Bezier arc of 60 degrees and radius 20 about the y axis (not rational: its
    // radius of curvature is 20 to within 0.1 %), extruded 30 mm along y; its normal points
    // away from the axis. Offset by -19 it comes within about 1 mm of the axis without turning
    // inside out, and is built within the tolerance; by -21 it turns inside out, which the
    // exact offset's normal `(S_u + d n_u) x (S_v + d n_v)` shows at a grid point.
    let (r, phi) = (20.0_f64, 60f64.to_radians());
    let k = 4.0 / 3.0 * (phi / 4.0).tan();
    let at = |t: f64| Point3::new(r * t.sin(), 0.0, r * t.cos());
    let tangent = |t: f64| Vector3::new(t.cos(), 0.0, -t.sin());
    let (a, b) = (-phi / 2.0, phi / 2.0);
    let arc = [
        at(a),
        at(a) + tangent(a) * (k * r),
        at(b) - tangent(b) * (k * r),
        at(b),
    ];
    let net: Vec<Vec<Point3<f64>>> = arc
        .iter()
        .map(|p| vec![*p, p + Vector3::y() * 30.0])
        .collect();
    let s = NurbsSurface::try_new(
        3,
        1,
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        net,
        None,
    )
    .expect("patch");
    let tol = 1e-4;
    let o = s
        .offset(-19.0, &SurfaceOffsetOptions::new(tol))
        .expect("no fold: built");
    let mut worst: f64 = 0.0;
    for i in 0..=200 {
        for j in 0..=4 {
            let (u, v) = (i as f64 / 200.0, j as f64 / 4.0);
            let (p, su, sv) = s.eval_d1(u, v);
            let exact = p + su.cross(&sv).normalize() * -19.0;
            worst = worst.max((o.surface.point(u, v) - exact).norm());
        }
    }
    assert!(
        worst <= o.position_bound_mm && o.position_bound_mm <= tol,
        "dense {worst:.3e} <= bound {:.3e} <= {tol}",
        o.position_bound_mm
    );
    let past = s.offset(-21.0, &SurfaceOffsetOptions::new(tol));
    assert!(
        matches!(past, Err(SurfaceOffsetError::Folds { .. })),
        "past the radius it folds: {past:?}"
    );
}

#[test]
fn a_crease_tears_the_offset_and_a_focal_offset_is_refused_at_once() {
    // Two flat panels meeting at a 30-degree crease (degree 1 in u, a knot of full
    // multiplicity at 0.5): the offsets of the two sides part along the crease.
    let rows = [
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(20.0, 0.0, 0.0),
        Point3::new(
            20.0 + 20.0 * 30f64.to_radians().cos(),
            0.0,
            20.0 * 30f64.to_radians().sin(),
        ),
    ];
    let net: Vec<Vec<Point3<f64>>> = rows
        .iter()
        .map(|p| vec![*p, p + Vector3::y() * 10.0])
        .collect();
    let creased = NurbsSurface::try_new(
        1,
        1,
        vec![0.0, 0.0, 0.5, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        net,
        None,
    )
    .expect("panels");
    match creased.offset(2.0, &SurfaceOffsetOptions::new(1e-4)) {
        Err(SurfaceOffsetError::Crease { gap_mm, .. }) => {
            // The two sides' normals differ by 30 degrees: their offsets by 2 mm part by
            // 2 * 2 sin 15 deg at the crease (the shared edge row's largest difference).
            let want = 2.0 * 2.0 * 15f64.to_radians().sin();
            assert!(
                gap_mm > 0.5 * want && gap_mm <= want + 1e-9,
                "gap {gap_mm} against {want}"
            );
        }
        other => panic!("a crease must be refused, got {other:?}"),
    }
    // The same panels meeting flat (no crease) offset exactly.
    let flat = NurbsSurface::try_new(
        1,
        1,
        vec![0.0, 0.0, 0.5, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        [0.0, 20.0, 40.0]
            .iter()
            .map(|&x| vec![Point3::new(x, 0.0, 0.0), Point3::new(x, 10.0, 0.0)])
            .collect(),
        None,
    )
    .expect("flat");
    let o = flat
        .offset(2.0, &SurfaceOffsetOptions::new(1e-4))
        .expect("flat");
    assert!(
        (o.surface.point(0.7, 0.3) - Point3::new(28.0, 3.0, 2.0)).norm() <= 1e-9,
        "moved 2 mm up"
    );
    // A cylinder of radius 20 offset by exactly -20 collapses onto its axis (a focal line):
    // refused at the first cells, not after spending the budget.
    let c = NurbsSurface::cylinder(Point3::origin(), Vector3::z(), 20.0, 10.0).expect("cylinder");
    let focal = c.offset(-20.0, &SurfaceOffsetOptions::new(1e-4).with_max_work(300));
    assert!(
        matches!(focal, Err(SurfaceOffsetError::Folds { work, .. }) if work < 300),
        "{focal:?}"
    );
}
