//! Surfaces against exact geometry: spheres, cylinders, tori and cones built by hand as
//! rational nets (validation, accessors, points on their quadrics, analytic normals including
//! poles and apexes, closest points); moved here from `src/surface.rs`.

use kerf_nurbs::{basis_funs, find_span, NurbsCurve, NurbsError, NurbsSurface, Result, MAX_ORDER};
use nalgebra::{Point3, Vector3, Vector4};
use std::f64::consts::{FRAC_1_SQRT_2, PI};

const H: f64 = FRAC_1_SQRT_2;

/// The 9-point rational quadratic unit circle in the xy plane, parameter in [0, 1].
fn circle9() -> (Vec<f64>, Vec<(f64, f64)>, Vec<f64>) {
    let knots = vec![
        0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
    ];
    let pts = vec![
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
    let w = vec![1.0, H, 1.0, H, 1.0, H, 1.0, H, 1.0];
    (knots, pts, w)
}

/// The half circle from (0, -1) through (1, 0) to (0, 1), as (rho, z), parameter [0, 1].
fn half5() -> (Vec<f64>, Vec<(f64, f64)>, Vec<f64>) {
    let knots = vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    let pts = vec![(0.0, -1.0), (1.0, -1.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    (knots, pts, vec![1.0, H, 1.0, H, 1.0])
}

const CENTRE: Vector3<f64> = Vector3::new(0.3, -0.2, 0.5);

/// Sphere of radius `r` around CENTRE. With `meridian_u` the rows (u) run along the
/// meridian (poles at u = 0, 1; normal inward); otherwise along the equator (poles at
/// v = 0, 1; normal outward).
fn sphere(r: f64, meridian_u: bool) -> NurbsSurface {
    let (kc, pc, wc) = circle9();
    let (km, pm, wm) = half5();
    let at = |m: usize, c: usize| {
        let (rho, z) = pm[m];
        let (x, y) = pc[c];
        (
            Point3::from(CENTRE + Vector3::new(rho * x, rho * y, z) * r),
            wm[m] * wc[c],
        )
    };
    let (ku, kv, nu, nv) = if meridian_u {
        (km, kc, pm.len(), pc.len())
    } else {
        (kc, km, pc.len(), pm.len())
    };
    let mut pts = vec![];
    let mut ws = vec![];
    for a in 0..nu {
        let (mut row, mut wrow) = (vec![], vec![]);
        for b in 0..nv {
            let (p, w) = if meridian_u { at(a, b) } else { at(b, a) };
            row.push(p);
            wrow.push(w);
        }
        pts.push(row);
        ws.push(wrow);
    }
    NurbsSurface::new(2, 2, ku, kv, pts, Some(ws))
}

/// Cylinder of radius `r` around the z axis, z in [0, height]: u around, v up.
fn cylinder(r: f64, height: f64) -> NurbsSurface {
    let (kc, pc, wc) = circle9();
    let pts = pc
        .iter()
        .map(|&(x, y)| {
            vec![
                Point3::new(r * x, r * y, 0.0),
                Point3::new(r * x, r * y, height),
            ]
        })
        .collect();
    let ws = wc.iter().map(|&w| vec![w, w]).collect();
    NurbsSurface::new(2, 1, kc, vec![0.0, 0.0, 1.0, 1.0], pts, Some(ws))
}

/// Torus around the z axis: tube radius `r`, centre-circle radius `big`. u around the tube,
/// v around the axis.
fn torus(big: f64, r: f64) -> NurbsSurface {
    let (kc, pc, wc) = circle9();
    let mut pts = vec![];
    let mut ws = vec![];
    for a in 0..9 {
        let (cx, cz) = pc[a];
        let rho = big + r * cx;
        let z = r * cz;
        pts.push(
            (0..9)
                .map(|b| Point3::new(rho * pc[b].0, rho * pc[b].1, z))
                .collect(),
        );
        ws.push((0..9).map(|b| wc[a] * wc[b]).collect());
    }
    NurbsSurface::new(2, 2, kc.clone(), kc, pts, Some(ws))
}

/// Cone with apex (0, 0, height) at v = 0 and base circle of radius `r` at z = 0, v = 1.
fn cone(r: f64, height: f64) -> NurbsSurface {
    let (kc, pc, wc) = circle9();
    let pts = pc
        .iter()
        .map(|&(x, y)| {
            vec![
                Point3::new(0.0, 0.0, height),
                Point3::new(r * x, r * y, 0.0),
            ]
        })
        .collect();
    let ws = wc.iter().map(|&w| vec![w, w]).collect();
    NurbsSurface::new(2, 1, kc, vec![0.0, 0.0, 1.0, 1.0], pts, Some(ws))
}

fn plane_grid(n_u: usize, n_v: usize) -> Vec<Vec<Point3<f64>>> {
    (0..n_u)
        .map(|a| {
            (0..n_v)
                .map(|b| Point3::new(a as f64, b as f64, 0.0))
                .collect()
        })
        .collect()
}

fn clamped(degree: usize, n: usize) -> Vec<f64> {
    let inner = n - degree;
    let mut k = vec![0.0; degree + 1];
    k.extend((1..inner).map(|i| i as f64 / inner as f64));
    k.extend(vec![1.0; degree + 1]);
    k
}

fn try_plane(grid: Vec<Vec<Point3<f64>>>, weights: Option<Vec<Vec<f64>>>) -> Result<NurbsSurface> {
    let (nu, nv) = (grid.len(), grid.first().map_or(0, Vec::len));
    NurbsSurface::try_new(2, 1, clamped(2, nu), clamped(1, nv.max(2)), grid, weights)
}

fn params(n: usize) -> impl Iterator<Item = f64> {
    (0..=n).map(move |i| i as f64 / n as f64)
}

#[test]
fn validation_errors() {
    let ok = try_plane(plane_grid(4, 3), None);
    assert!(ok.is_ok(), "a valid plane: {ok:?}");
    let e = NurbsSurface::try_new(0, 1, vec![], clamped(1, 3), plane_grid(4, 3), None);
    assert_eq!(
        e,
        Err(NurbsError::DegreeZero { field: "degree_u" }),
        "degree_u 0"
    );
    let e = NurbsSurface::try_new(2, 30, clamped(2, 4), vec![], plane_grid(4, 3), None);
    assert!(
        matches!(
            e,
            Err(NurbsError::DegreeTooHigh {
                field: "degree_v",
                degree: 30,
                ..
            })
        ),
        "degree_v too high: {e:?}"
    );
    let e = NurbsSurface::try_new(2, 3, clamped(2, 4), vec![0.0; 7], plane_grid(4, 3), None);
    assert_eq!(
        e,
        Err(NurbsError::TooFewPoints {
            field: "control_points",
            got: 3,
            degree: 3,
            needed: 4
        }),
        "too few points along v"
    );
    let e = NurbsSurface::try_new(2, 1, clamped(2, 4), vec![0.0, 1.0], plane_grid(4, 3), None);
    assert_eq!(
        e,
        Err(NurbsError::KnotCount {
            field: "knots_v",
            expected: 5,
            got: 2
        }),
        "knots_v count"
    );
    let e = NurbsSurface::try_new(
        2,
        1,
        vec![0.0, 0.0, 0.0, 0.7, 0.5, 1.0, 1.0],
        clamped(1, 3),
        plane_grid(4, 3),
        None,
    );
    assert!(
        matches!(
            e,
            Err(NurbsError::KnotsDecreasing {
                field: "knots_u",
                index: 4,
                ..
            })
        ),
        "decreasing knots_u: {e:?}"
    );
    let mut grid = plane_grid(4, 3);
    grid[2].pop();
    assert_eq!(
        try_plane(grid, None),
        Err(NurbsError::RaggedGrid {
            field: "control_points",
            row: 2,
            got: 2,
            expected: 3
        }),
        "ragged control net"
    );
    let mut grid = plane_grid(4, 3);
    grid[1][2].y = f64::NAN;
    let e = try_plane(grid, None);
    assert!(
        matches!(&e, Err(NurbsError::PointNotFinite { field: "control_points", index, .. }) if index == "[1][2]"),
        "non-finite point: {e:?}"
    );
    let e = try_plane(plane_grid(4, 3), Some(vec![vec![1.0; 3]; 3]));
    assert_eq!(
        e,
        Err(NurbsError::WeightCount {
            field: "weights",
            expected: 12,
            got: 9
        }),
        "missing row of weights"
    );
    let e = try_plane(
        plane_grid(4, 3),
        Some(vec![vec![1.0; 3], vec![1.0; 4], vec![1.0; 2], vec![1.0; 3]]),
    );
    assert_eq!(
        e,
        Err(NurbsError::RaggedGrid {
            field: "weights",
            row: 1,
            got: 4,
            expected: 3
        }),
        "ragged weights"
    );
    for bad in [0.0, -1.0, f64::INFINITY] {
        let mut w = vec![vec![1.0; 3]; 4];
        w[3][1] = bad;
        let e = try_plane(plane_grid(4, 3), Some(w));
        assert!(
            matches!(&e, Err(NurbsError::BadWeight { field: "weights", index, value }) if index == "[3][1]" && (value == &bad)),
            "bad weight {bad}: {e:?}"
        );
    }
    let mut w = vec![vec![1.0; 3]; 4];
    w[0][0] = f64::NAN;
    let e = try_plane(plane_grid(4, 3), Some(w));
    assert!(
        matches!(&e, Err(NurbsError::BadWeight { index, .. }) if index == "[0][0]"),
        "NaN weight: {e:?}"
    );
    let e = NurbsSurface::try_new(1, 1, vec![0.0; 2], vec![0.0; 4], vec![], None);
    assert!(
        matches!(e, Err(NurbsError::TooFewPoints { got: 0, .. })),
        "empty control net: {e:?}"
    );
    let msg = std::panic::catch_unwind(|| {
        NurbsSurface::new(
            1,
            1,
            vec![0.0; 4],
            vec![0.0, 0.0, 1.0, 1.0],
            plane_grid(2, 2),
            None,
        )
    });
    assert!(msg.is_err(), "new panics on an empty domain");
}

#[test]
fn accessors_round_trip() {
    let mut w = vec![vec![1.0; 3]; 4];
    w[2][1] = 3.0;
    let grid = plane_grid(4, 3);
    let s = try_plane(grid.clone(), Some(w.clone())).expect("valid");
    assert_eq!(s.net_size(), (4, 3), "net size");
    assert_eq!((s.degree_u(), s.degree_v()), (2, 1), "degrees");
    assert_eq!(s.knots_u(), &clamped(2, 4)[..], "knots_u");
    assert_eq!(s.knots_v(), &clamped(1, 3)[..], "knots_v");
    assert_eq!(s.weights(), w, "weights");
    assert_eq!(s.control_points(), grid, "control points");
    assert!(s.is_rational(), "one weight differs");
    assert_eq!(
        s.homogeneous_point(2, 1),
        Vector4::new(6.0, 3.0, 0.0, 3.0),
        "homogeneous"
    );
    assert_eq!(s.homogeneous_points().len(), 12, "flat net");
    assert_eq!(s.domain_u(), (0.0, 1.0), "domain u");
    assert_eq!(s.spans_u().len(), 2, "two spans along u");
    let (lo, hi) = s.bounding_box();
    assert_eq!(
        (lo, hi),
        (Point3::origin(), Point3::new(3.0, 2.0, 0.0)),
        "box"
    );
    assert_eq!(s.collapsed_edges(), [false; 4], "nothing collapsed");
}

#[test]
fn closed_directions_and_collapsed_edges() {
    assert_eq!(
        cylinder(2.0, 1.0).closed_directions(),
        (true, false),
        "cylinder"
    );
    assert_eq!(torus(3.0, 1.0).closed_directions(), (true, true), "torus");
    assert_eq!(
        sphere(1.0, true).closed_directions(),
        (false, true),
        "sphere"
    );
    assert_eq!(cone(1.0, 2.0).closed_directions(), (true, false), "cone");
    let plane = try_plane(plane_grid(4, 3), None).expect("valid");
    assert_eq!(plane.closed_directions(), (false, false), "plane");
    assert_eq!(cylinder(2.0, 1.0).collapsed_edges(), [false; 4], "cylinder");
    assert_eq!(torus(3.0, 1.0).collapsed_edges(), [false; 4], "torus");
}

#[test]
fn exact_surfaces_lie_on_their_quadrics() {
    let cyl = cylinder(2.5, 4.0);
    let sph = [sphere(1.7, true), sphere(1.7, false)];
    let tor = torus(3.0, 0.8);
    for u in params(97) {
        for v in params(89) {
            let p = cyl.point(u, v);
            assert!(
                (p.x.hypot(p.y) / 2.5 - 1.0).abs() < 1e-12,
                "cylinder at {u} {v}"
            );
            for s in &sph {
                let d = (s.point(u, v).coords - CENTRE).norm();
                assert!((d / 1.7 - 1.0).abs() < 1e-12, "sphere at {u} {v}: {d}");
            }
            let p = tor.point(u, v);
            let d = (p.x.hypot(p.y) - 3.0).hypot(p.z);
            assert!((d / 0.8 - 1.0).abs() < 1e-12, "torus at {u} {v}: {d}");
        }
    }
}

#[test]
fn cylinder_and_torus_normals_are_analytic() {
    let cyl = cylinder(2.5, 4.0);
    let tor = torus(3.0, 0.8);
    for u in params(61) {
        for v in params(53) {
            let p = cyl.point(u, v);
            let n = cyl.normal(u, v).expect("regular");
            let radial = Vector3::new(p.x, p.y, 0.0) / 2.5;
            assert!(
                (n - radial).norm() < 1e-12,
                "cylinder normal at {u} {v}: {n}"
            );
            let p = tor.point(u, v);
            let rho = p.x.hypot(p.y);
            let c = Vector3::new(p.x / rho * 3.0, p.y / rho * 3.0, 0.0);
            let expected = (p.coords - c) / 0.8;
            let n = tor.normal(u, v).expect("regular");
            // u runs around the tube counter-clockwise in (rho, z), v around the axis:
            // Su x Sv points into the tube.
            assert!(
                (n + expected).norm() < 1e-10,
                "torus normal at {u} {v}: {n}"
            );
        }
    }
}

#[test]
fn subnormal_weights_are_normalised_exactly() {
    let s = sphere(1.7, false);
    let tiny: Vec<Vec<f64>> = s
        .weights()
        .iter()
        .map(|r| r.iter().map(|w| w * 1e-318).collect())
        .collect();
    let t = NurbsSurface::try_new(
        2,
        2,
        s.knots_u().to_vec(),
        s.knots_v().to_vec(),
        s.control_points(),
        Some(tiny),
    )
    .expect("subnormal weights are normalised, not refused");
    assert!(
        t.weights().iter().flatten().all(|&w| w >= 2f64.powi(-970)),
        "normal weights"
    );
    for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.33)] {
        // The subnormal weights keep ~10 bits, so the surface is not exactly the sphere,
        // but it is the surface the data defines, evaluated at full precision: close.
        let d = (t.point(u, v) - s.point(u, v)).norm();
        assert!(d < 1e-2, "point at ({u}, {v}) off by {d}");
    }
}

#[test]
fn sphere_normals_everywhere_including_poles() {
    for meridian_u in [true, false] {
        let s = sphere(1.7, meridian_u);
        // With the meridian along u, Su x Sv points inward; along v, outward.
        let sign = if meridian_u { -1.0 } else { 1.0 };
        let expect = |u: f64, v: f64| (s.point(u, v).coords - CENTRE) / 1.7 * sign;
        let collapsed = if meridian_u {
            [true, true, false, false]
        } else {
            [false, false, true, true]
        };
        assert_eq!(s.collapsed_edges(), collapsed, "poles detected");
        let mut ts: Vec<f64> = params(40).collect();
        for e in [
            1e-15, 1e-13, 1e-11, 1e-9, 1e-8, 1e-7, 3e-6, 1e-5, 2e-5, 1e-4, 1e-3,
        ] {
            ts.push(e);
            ts.push(1.0 - e);
        }
        for &a in &ts {
            for b in params(36) {
                let (u, v) = if meridian_u { (a, b) } else { (b, a) };
                let n = s.normal(u, v).expect("the sphere has a normal everywhere");
                let e = expect(u, v);
                assert!(
                    (n - e).norm() < 1e-9,
                    "sphere normal at {u} {v}: {n} vs {e}"
                );
                assert!((n.norm() - 1.0).abs() < 1e-14, "unit normal");
            }
        }
        // At the poles exactly the normal is the axis direction.
        for b in params(17) {
            let (south, north) = if meridian_u {
                (s.normal(0.0, b), s.normal(1.0, b))
            } else {
                (s.normal(b, 0.0), s.normal(b, 1.0))
            };
            let south = south.expect("pole");
            let north = north.expect("pole");
            assert!(
                (south - Vector3::new(0.0, 0.0, -sign)).norm() < 1e-14,
                "south pole normal {south}"
            );
            assert!(
                (north - Vector3::new(0.0, 0.0, sign)).norm() < 1e-14,
                "north pole normal {north}"
            );
        }
    }
}

#[test]
fn cone_apex_normal_is_the_limit_along_the_ruling() {
    let (r, h) = (1.5, 2.0);
    let c = cone(r, h);
    assert_eq!(
        c.collapsed_edges(),
        [false, false, true, false],
        "apex at v = 0"
    );
    let len = r.hypot(h);
    for u in params(50) {
        let base = c.point(u, 1.0);
        let (ct, st) = (base.x / r, base.y / r);
        // Su x Sv points into the cone (see the derivation in the test's comment).
        let expected = -Vector3::new(h * ct, h * st, r) / len;
        for v in [0.0, 1e-14, 1e-9, 1e-6, 0.3, 1.0] {
            let n = c.normal(u, v).expect("cone normal");
            assert!(
                (n - expected).norm() < 1e-10,
                "cone normal at {u} {v}: {n} vs {expected}"
            );
        }
    }
}

#[test]
fn degenerate_without_collapsed_edge_uses_taylor_limit() {
    // A bilinear-like patch whose corner has Su = 0 (two coincident corner control points
    // along u) but no collapsed edge: the limit along u is still well defined.
    let pts = vec![
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 2.0, 0.0),
        ],
        vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(1.0, 2.0, 0.0),
        ],
        vec![
            Point3::new(2.0, 0.0, 0.0),
            Point3::new(2.0, 1.0, 0.0),
            Point3::new(2.0, 2.0, 0.0),
        ],
    ];
    let s = NurbsSurface::new(2, 2, clamped(2, 3), clamped(2, 3), pts, None);
    assert_eq!(s.collapsed_edges(), [false; 4], "no collapsed edge");
    let (_, su, _) = s.eval_d1(0.0, 0.0);
    assert!(su.norm() < 1e-15, "Su vanishes at the corner");
    let n = s.normal(0.0, 0.0).expect("limit exists");
    assert!(
        (n - Vector3::z()).norm() < 1e-14,
        "planar patch: normal +z, got {n}"
    );
    // A surface collapsed to a single point has no normal.
    let dot = NurbsSurface::new(
        1,
        1,
        clamped(1, 2),
        clamped(1, 2),
        vec![vec![Point3::origin(); 2]; 2],
        None,
    );
    assert_eq!(dot.normal(0.5, 0.5), None, "a point has no normal");
}

#[test]
fn pure_derivatives_match_isocurves() {
    // Independent truth: the isocurves as NURBS curves (whose derivatives are the curve
    // module's), built from the homogeneous net combined with the basis of the other
    // direction.
    let s = torus(3.0, 0.8);
    let (nu, nv) = s.net_size();
    for u in params(23) {
        for v in params(19) {
            let d = s.derivatives(u, v);
            // v-isocurve at fixed u: control points sum_a N_a(u) P_ab.
            let span = find_span(2, s.knots_u(), nu, u);
            let mut n = [0.0; MAX_ORDER];
            basis_funs(span, u, 2, s.knots_u(), &mut n);
            let cpw: Vec<Vector4<f64>> = (0..nv)
                .map(|b| {
                    (0..=2)
                        .map(|i| s.homogeneous_point(span - 2 + i, b) * n[i])
                        .sum()
                })
                .collect();
            let iso = NurbsCurve::from_homogeneous_unchecked(2, s.knots_v().to_vec(), cpw);
            let c = iso.derivatives(v, 2);
            for k in 0..3 {
                let err = (c[k] - d[0][k]).norm();
                assert!(
                    err < 1e-11 * (1.0 + c[k].norm()),
                    "d^{k}/dv^{k} at {u} {v}: {err}"
                );
            }
            let span = find_span(2, s.knots_v(), nv, v);
            basis_funs(span, v, 2, s.knots_v(), &mut n);
            let cpw: Vec<Vector4<f64>> = (0..nu)
                .map(|a| {
                    (0..=2)
                        .map(|j| s.homogeneous_point(a, span - 2 + j) * n[j])
                        .sum()
                })
                .collect();
            let iso = NurbsCurve::from_homogeneous_unchecked(2, s.knots_u().to_vec(), cpw);
            let c = iso.derivatives(u, 2);
            for k in 0..3 {
                let err = (c[k] - d[k][0]).norm();
                assert!(
                    err < 1e-11 * (1.0 + c[k].norm()),
                    "d^{k}/du^{k} at {u} {v}: {err}"
                );
            }
            let (p, su, sv) = s.eval_d1(u, v);
            assert_eq!((p.coords, su, sv), (d[0][0], d[1][0], d[0][1]), "eval_d1");
            assert!((s.point(u, v).coords - d[0][0]).norm() < 1e-14, "point");
        }
    }
}

#[test]
fn sphere_closest_points_are_analytic() {
    let r = 1.7;
    for meridian_u in [true, false] {
        let s = sphere(r, meridian_u);
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..200 {
            let dir = Vector3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
            let t = [0.05, 0.9, 1.69, 1.71, 2.5, 40.0][i % 6] * r / 1.7;
            let p = Point3::from(CENTRE + dir * t);
            let q = s.closest_point(&p, None);
            assert!(
                (q.distance - (t - r).abs()).abs() < 1e-12,
                "distance from {p}: {q:?}"
            );
            let expected = CENTRE + dir * r;
            assert!(
                (q.point.coords - expected).norm() < 1e-7,
                "closest point from {p}: {q:?} off by {}",
                (q.point.coords - expected).norm()
            );
            let warm = s.closest_point(&p, Some((q.u + 0.01, q.v - 0.01)));
            assert!(
                (warm.distance - q.distance).abs() < 1e-12,
                "warm = cold: {warm:?} {q:?}"
            );
        }
        // The poles and the centre.
        for z in [-1.0, 1.0] {
            let p = Point3::from(CENTRE + Vector3::new(0.0, 0.0, 3.0 * z));
            let q = s.closest_point(&p, None);
            assert!(
                (q.distance - (3.0 - r)).abs() < 1e-12,
                "above a pole: {q:?}"
            );
        }
        let q = s.closest_point(&Point3::from(CENTRE), None);
        assert!((q.distance - r).abs() < 1e-12, "from the centre: {q:?}");
    }
}

#[test]
fn cylinder_closest_points_including_boundary_minima() {
    let (r, h) = (2.5, 4.0);
    let s = cylinder(r, h);
    for i in 0..72 {
        let a = i as f64 * PI / 36.0 + 0.01;
        for (rho, z) in [
            (0.3, 2.0),
            (2.4, 0.5),
            (3.0, 3.9),
            (7.0, 1.0),
            (3.0, 5.0),
            (1.0, -2.0),
            (0.0, 6.0),
        ] {
            let p = Point3::new(rho * a.cos(), rho * a.sin(), z);
            let q = s.closest_point(&p, None);
            let dz = if z > h {
                z - h
            } else if z < 0.0 {
                -z
            } else {
                0.0
            };
            let expected = (rho - r).hypot(dz);
            assert!(
                (q.distance - expected).abs() < 1e-12,
                "from ({rho}, {a}, {z}): {q:?} vs {expected}"
            );
            let warm = s.closest_point(&p, Some((q.u, q.v)));
            assert!(
                (warm.distance - q.distance).abs() < 1e-13,
                "warm start at the answer"
            );
            assert!(
                (warm.u - q.u).abs() < 1e-9 && (warm.v - q.v).abs() < 1e-9 || rho == 0.0,
                "same parameters"
            );
        }
    }
}

#[test]
fn plane_boundary_and_corner_minima() {
    // Degree (3, 2) plane z = 0 over [0, 3] x [0, 2], non-uniform knots.
    let grid: Vec<Vec<Point3<f64>>> = (0..5)
        .map(|a| {
            (0..4)
                .map(|b| Point3::new(a as f64 * 0.75, b as f64 * 2.0 / 3.0, 0.0))
                .collect()
        })
        .collect();
    let s = NurbsSurface::new(
        3,
        2,
        vec![0.0, 0.0, 0.0, 0.0, 0.3, 1.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 0.0, 0.6, 1.0, 1.0, 1.0],
        grid,
        None,
    );
    let cases = [
        (Point3::new(1.0, 1.0, 2.0), 2.0),
        (Point3::new(4.0, 1.0, 1.0), 2f64.sqrt()),
        (Point3::new(-1.0, 1.5, -1.0), 2f64.sqrt()),
        (Point3::new(1.2, -2.0, 0.0), 2.0),
        (Point3::new(4.0, 3.0, 1.0), 3f64.sqrt()),
        (Point3::new(-2.0, -2.0, 0.0), 8f64.sqrt()),
    ];
    for (p, expected) in cases {
        let q = s.closest_point(&p, None);
        assert!((q.distance - expected).abs() < 1e-12, "from {p}: {q:?}");
        let w = s.closest_point(&p, Some((0.5, 0.5)));
        assert!(
            (w.distance - expected).abs() < 1e-12,
            "warm from {p}: {w:?}"
        );
    }
}

#[test]
fn warm_start_tracks_a_point_around_the_torus() {
    // A tool point circling the torus on a wobbly helix: every warm-started query (from the
    // previous answer) agrees with the cold one.
    let (big, r) = (3.0, 0.8);
    let s = torus(big, r);
    let mut prev = None;
    for i in 0..400 {
        let t = i as f64 / 400.0 * 2.0 * PI;
        let (rho, z) = (
            big + 1.2 * (7.0 * t).cos(),
            1.2 * (7.0 * t).sin() + 0.1 * t.cos(),
        );
        let p = Point3::new(rho * t.cos(), rho * t.sin(), z);
        let warm = s.closest_point(&p, prev);
        let cold = s.closest_point(&p, None);
        assert!(
            (warm.distance - cold.distance).abs() < 1e-12,
            "step {i}: warm {warm:?} cold {cold:?}"
        );
        let expected = ((rho - big).hypot(z) - r).abs();
        assert!(
            (warm.distance - expected).abs() < 1e-12,
            "step {i}: analytic"
        );
        prev = Some((warm.u, warm.v));
    }
}

#[test]
fn torus_closest_points() {
    let (big, r) = (3.0, 0.8);
    let s = torus(big, r);
    for i in 0..50 {
        let a = i as f64 * 0.37;
        for (rho, z) in [
            (0.0, 0.0),
            (0.5, 0.3),
            (2.9, 0.1),
            (3.5, -0.5),
            (6.0, 2.0),
            (3.0, 0.0),
        ] {
            let p = Point3::new(rho * a.cos(), rho * a.sin(), z);
            let q = s.closest_point(&p, None);
            let expected = ((rho - big).hypot(z) - r).abs();
            assert!(
                (q.distance - expected).abs() < 1e-12,
                "torus from {p}: {q:?} vs {expected}"
            );
        }
    }
}

#[test]
fn jump_between_cells_uses_the_limit_from_inside() {
    // Degree 1 along u with a knot of multiplicity 2 at u = 1: two separate patches.
    let row = |x: f64, z: f64| vec![Point3::new(x, 0.0, z), Point3::new(x, 1.0, z)];
    let s = NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0, 2.0, 2.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![row(0.0, 0.0), row(1.0, 0.0), row(3.0, 5.0), row(4.0, 5.0)],
        None,
    );
    let p = Point3::new(1.2, 0.5, 0.0);
    for warm in [None, Some((0.5, 0.5))] {
        let q = s.closest_point(&p, warm);
        assert!((q.distance - 0.2).abs() < 1e-12, "limit from inside: {q:?}");
        assert_eq!(q.u, float_before(1.0), "represented below the knot");
        assert_eq!(q.point, s.point(q.u, q.v), "point is S(u, v)");
    }
    // Beyond the jump the second patch wins.
    let q = s.closest_point(&Point3::new(2.5, 0.5, 5.0), None);
    assert!((q.distance - 0.5).abs() < 1e-12, "second patch: {q:?}");
    assert_eq!(q.u, 1.0, "its first edge is at the knot");
}

#[test]
fn nan_query_does_not_panic() {
    let s = sphere(1.0, true);
    let q = s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0), None);
    assert!(q.distance.is_nan(), "NaN in, NaN out: {q:?}");
    let q = s.closest_point(&Point3::new(f64::NAN, 0.0, 0.0), Some((0.5, 0.5)));
    assert!(q.distance.is_nan(), "NaN in, NaN out (warm): {q:?}");
    let p = s.point(f64::NAN, 2.0);
    assert_eq!(
        p,
        s.point(0.0, 1.0),
        "NaN and out-of-domain parameters are clamped"
    );
}

/// The largest double below a positive `t` (`t - ulp/2` at a power of two).
fn float_before(t: f64) -> f64 {
    f64::from_bits(t.to_bits() - 1)
}
