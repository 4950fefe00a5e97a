//! Kerf compensation against closed-form geometry: the beam's path offset by half the kerf,
//! checked by exact distance functions (a circle, a rounded square, a square) and, for a
//! tilted beam, by projecting along the beam and measuring against a dense polygon of the
//! exact contour. The checks run on the chords the machine runs, sampled densely, not on the
//! path's own points only.

use kerf_discretize::{discretize, Options};
use kerf_nurbs::{NurbsCurve, Segment};
use kerf_process::{offset, OffsetInput, OffsetOptions, OffsetPath, Pose, ProcessError, Side};
use nalgebra::{Point3, Vector2, Vector3};

const TOL: f64 = 0.01;

/// The discretized contour with a fixed tool axis.
fn contour(curve: &NurbsCurve, axis: Vector3<f64>) -> (Vec<f64>, Vec<Pose>) {
    let d = discretize(curve, &Options::with_tolerance(TOL)).expect("discretize");
    let a = axis.normalize();
    let poses = d
        .points()
        .iter()
        .map(|p| Pose::new(p.x, p.y, p.z, a.x, a.y, a.z))
        .collect();
    (d.params().to_vec(), poses)
}

fn run(
    curve: &NurbsCurve,
    axis: Vector3<f64>,
    normals: Option<&[[f64; 3]]>,
    scrap: Side,
    kerf: f64,
) -> Result<OffsetPath, ProcessError> {
    let (params, poses) = contour(curve, axis);
    let owned: Vec<[f64; 3]>;
    let normals = match normals {
        Some(m) => {
            owned = vec![m[0]; poses.len()];
            Some(owned.as_slice())
        }
        None => None,
    };
    offset(
        &OffsetInput {
            id: "c",
            curve,
            params: &params,
            poses: &poses,
            surface_normals: normals,
            scrap,
            closed: curve.is_closed(),
        },
        &OffsetOptions::new(kerf, TOL),
    )
}

/// Points along every chord of the path (what the machine runs), 8 per chord.
fn along_chords(path: &OffsetPath) -> Vec<Point3<f64>> {
    let p: Vec<Point3<f64>> = path.poses.iter().map(|q| q.position).collect();
    let mut out = Vec::new();
    for w in p.windows(2) {
        for k in 0..8 {
            out.push(w[0] + (w[1] - w[0]) * (k as f64 / 8.0));
        }
    }
    out.push(p[p.len() - 1]);
    out
}

fn circle(radius: f64) -> NurbsCurve {
    NurbsCurve::circle(Point3::origin(), Vector3::z(), radius).expect("circle")
}

/// A square of half-size `h` with corners rounded to `rho` (exact: lines and rational
/// quarter circles, degree 2), counter-clockwise seen from +z.
fn rounded_square(h: f64, rho: f64) -> NurbsCurve {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let e = h - rho;
    let pts = [
        (h, -e, 1.0),
        (h, 0.0, 1.0),
        (h, e, 1.0),
        (h, h, w),
        (e, h, 1.0),
        (0.0, h, 1.0),
        (-e, h, 1.0),
        (-h, h, w),
        (-h, e, 1.0),
        (-h, 0.0, 1.0),
        (-h, -e, 1.0),
        (-h, -h, w),
        (-e, -h, 1.0),
        (0.0, -h, 1.0),
        (e, -h, 1.0),
        (h, -h, w),
        (h, -e, 1.0),
    ];
    let mut knots = vec![0.0; 3];
    for k in 1..8 {
        knots.extend([k as f64, k as f64]);
    }
    knots.extend([8.0; 3]);
    NurbsCurve::new(
        2,
        knots,
        pts.iter().map(|p| Point3::new(p.0, p.1, 0.0)).collect(),
        Some(pts.iter().map(|p| p.2).collect()),
    )
}

/// Signed distance to the rounded square (negative inside).
fn rounded_sdf(p: &Point3<f64>, h: f64, rho: f64) -> f64 {
    let q = Vector2::new(p.x.abs(), p.y.abs()) - Vector2::repeat(h - rho);
    let outside = Vector2::new(q.x.max(0.0), q.y.max(0.0)).norm();
    outside + q.x.max(q.y).min(0.0) - rho
}

fn square(h: f64) -> NurbsCurve {
    NurbsCurve::polyline(&[
        Point3::new(h, -h, 0.0),
        Point3::new(h, h, 0.0),
        Point3::new(-h, h, 0.0),
        Point3::new(-h, -h, 0.0),
        Point3::new(h, -h, 0.0),
    ])
    .expect("square")
}

/// Every point along the chords is `target` (signed distance) from the contour, to the
/// tolerance.
fn assert_at(path: &OffsetPath, sdf: impl Fn(&Point3<f64>) -> f64, target: f64, what: &str) {
    let worst = along_chords(path)
        .iter()
        .map(|p| (sdf(p) - target).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= TOL + 1e-9,
        "{what}: a chord point is {worst:.3e} mm off the offset (tolerance {TOL})"
    );
}

/// The largest distance from a point of the contour to the path (the cut edge must reach
/// every point of the contour: this is `r` up to the tolerance where nothing is left).
fn contour_to_path(curve: &NurbsCurve, path: &OffsetPath) -> (f64, f64) {
    let segs: Vec<Segment<3>> = path
        .poses
        .windows(2)
        .map(|w| Segment::between(&w[0].position, &w[1].position))
        .collect();
    let (a, b) = curve.domain();
    let mut lo = f64::INFINITY;
    let mut hi = 0.0_f64;
    for k in 0..2000 {
        let c = curve.point(a + (b - a) * k as f64 / 2000.0);
        let d = segs
            .iter()
            .map(|s| s.distance_to(&c))
            .fold(f64::INFINITY, f64::min);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    (lo, hi)
}

#[test]
fn a_hole_shrinks_and_an_outline_grows_by_half_the_kerf_exactly() {
    let radius = 5.0;
    let c = circle(radius);
    for kerf in [0.1, 0.2, 0.3] {
        let r = kerf / 2.0;
        // Counter-clockwise from +z: the left is the inside.
        let hole = run(&c, Vector3::z(), None, Side::Left, kerf).expect("hole");
        assert!(hole.proven, "a flat contour at a fixed axis is proven");
        assert!(hole.max_chord_error_mm <= TOL);
        assert_at(&hole, |p| p.coords.norm() - radius, -r, "hole");
        let outline = run(&c, Vector3::z(), None, Side::Right, kerf).expect("outline");
        assert!(outline.proven);
        assert_at(&outline, |p| p.coords.norm() - radius, r, "outline");
        // Closed paths close exactly, and the cut edge reaches the whole contour.
        for p in [&hole, &outline] {
            assert_eq!(p.poses[0], p.poses[p.poses.len() - 1]);
            assert_eq!((p.outside_corners, p.inside_corners), (0, 0));
            let (lo, hi) = contour_to_path(&c, p);
            assert!(lo >= r - TOL && hi <= r + TOL, "kerf {kerf}: {lo} {hi}");
        }
    }
}

#[test]
fn a_rounded_square_keeps_its_size_inside_and_out() {
    let (h, rho) = (10.0, 2.0);
    let c = rounded_square(h, rho);
    for kerf in [0.1, 0.2, 0.3] {
        let r = kerf / 2.0;
        let hole = run(&c, Vector3::z(), None, Side::Left, kerf).expect("hole");
        assert!(hole.proven);
        assert_at(&hole, |p| rounded_sdf(p, h, rho), -r, "rounded hole");
        let outline = run(&c, Vector3::z(), None, Side::Right, kerf).expect("outline");
        assert!(outline.proven);
        assert_at(&outline, |p| rounded_sdf(p, h, rho), r, "rounded outline");
        for p in [&hole, &outline] {
            // Lines meet arcs tangentially: no corner.
            assert_eq!((p.outside_corners, p.inside_corners), (0, 0));
            let (lo, hi) = contour_to_path(&c, p);
            assert!(lo >= r - TOL && hi <= r + TOL, "kerf {kerf}: {lo} {hi}");
        }
    }
}

#[test]
fn sharp_corners_get_arcs_outside_and_cut_backs_inside() {
    let h = 10.0;
    let c = square(h);
    let sdf = |p: &Point3<f64>| {
        let q = Vector2::new(p.x.abs() - h, p.y.abs() - h);
        Vector2::new(q.x.max(0.0), q.y.max(0.0)).norm() + q.x.max(q.y).min(0.0)
    };
    for kerf in [0.1, 0.2, 0.3] {
        let r = kerf / 2.0;
        let outline = run(&c, Vector3::z(), None, Side::Right, kerf).expect("outline");
        assert_eq!(outline.outside_corners, 4, "the start is a corner too");
        assert_eq!(outline.inside_corners, 0);
        assert!(outline.proven);
        // On the arcs the path is r from the corner: still r from the square.
        assert_at(&outline, sdf, r, "square outline");
        let (lo, hi) = contour_to_path(&c, &outline);
        assert!(lo >= r - TOL && hi <= r + TOL, "{lo} {hi}");
        assert_eq!(outline.poses[0], outline.poses[outline.poses.len() - 1]);

        let hole = run(&c, Vector3::z(), None, Side::Left, kerf).expect("hole");
        assert_eq!(hole.inside_corners, 4);
        assert_eq!(hole.outside_corners, 0);
        // Cut back at the crossing: exactly r inside both sides, the square of side
        // 2 (h - r), never closer to the part.
        assert_at(&hole, sdf, -r, "square hole");
        assert_eq!(hole.poses.len(), 5, "{:?}", hole.poses);
        for q in &hole.poses {
            assert!(
                (q.position.x.abs() - (h - r)).abs() < 1e-9
                    && (q.position.y.abs() - (h - r)).abs() < 1e-9
            );
        }
        // A round beam leaves (sqrt 2 - 1) r in each inside corner.
        let left = (2f64.sqrt() - 1.0) * r;
        assert!((hole.max_corner_material_mm - left).abs() < 1e-9);
        let (_, hi) = contour_to_path(&c, &hole);
        assert!((hi - r * 2f64.sqrt()).abs() < 1e-9, "{hi}");
        assert_eq!(hole.poses[0], hole.poses[hole.poses.len() - 1]);
    }
}

/// Projects along `a` onto the plane across it.
fn across(a: &Vector3<f64>, p: &Point3<f64>) -> Vector2<f64> {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = helper.cross(a).normalize();
    let e2 = a.cross(&e1);
    Vector2::new(p.coords.dot(&e1), p.coords.dot(&e2))
}

#[test]
fn a_tilted_beam_touches_the_contour_with_its_edge_at_the_surface() {
    let radius = 5.0;
    let c = circle(radius);
    // The dense contour, 20,000 sides: within 3e-6 mm of the circle.
    let dense: Vec<Point3<f64>> = (0..20_000)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / 20_000.0;
            Point3::new(radius * t.cos(), radius * t.sin(), 0.0)
        })
        .collect();
    for tilt_deg in [0.0_f64, 10.0, 20.0, 30.0] {
        let t = tilt_deg.to_radians();
        let a = Vector3::new(0.0, t.sin(), t.cos());
        let flat: Vec<Vector2<f64>> = dense.iter().map(|p| across(&a, p)).collect();
        let poly: Vec<Segment<2>> = (0..flat.len())
            .map(|k| Segment::new(flat[k], flat[(k + 1) % flat.len()]))
            .collect();
        for kerf in [0.1, 0.2, 0.3] {
            let r = kerf / 2.0;
            for side in [Side::Left, Side::Right] {
                let path = run(&c, a, Some(&[[0.0, 0.0, 1.0]]), side, kerf).expect("tilted");
                assert!(path.proven, "a fixed tilted axis on a plane is proven");
                for q in &path.poses {
                    assert!(q.position.z.abs() < 1e-9, "the tip is on the sheet: {q:?}");
                }
                // Seen along the beam, the beam's centre is r from the contour.
                let worst = along_chords(&path)
                    .iter()
                    .map(|p| {
                        let d = poly
                            .iter()
                            .map(|s| s.distance(&across(&a, p)))
                            .fold(f64::INFINITY, f64::min);
                        (d - r).abs()
                    })
                    .fold(0.0, f64::max);
                assert!(
                    worst <= TOL + 1e-5,
                    "tilt {tilt_deg}, kerf {kerf}, {side:?}: {worst:.3e}"
                );
            }
        }
    }
}

fn compensation_reason(e: ProcessError) -> String {
    match e {
        ProcessError::Compensation { reason, .. } => reason,
        other => panic!("expected a compensation refusal, got {other}"),
    }
}

#[test]
fn a_hole_smaller_than_the_kerf_is_refused_with_its_size() {
    let e = run(&circle(0.05), Vector3::z(), None, Side::Left, 0.2).expect_err("refused");
    let reason = compensation_reason(e);
    assert!(reason.contains("radius of 0.0500 mm"), "{reason}");
    assert!(reason.contains("0.1000 mm"), "{reason}");
    // The same circle as an outline is fine: the kerf goes outside.
    let ok = run(&circle(0.05), Vector3::z(), None, Side::Right, 0.2).expect("outline");
    assert!(ok.proven);
}

#[test]
fn a_notch_narrower_than_the_kerf_is_refused() {
    // An outline with a notch 0.15 mm wide and 5 mm deep in its top edge.
    let pts = [
        (0.0, 0.0),
        (20.0, 0.0),
        (20.0, 10.0),
        (10.075, 10.0),
        (10.075, 5.0),
        (9.925, 5.0),
        (9.925, 10.0),
        (0.0, 10.0),
        (0.0, 0.0),
    ];
    let c = NurbsCurve::polyline(
        &pts.iter()
            .map(|p| Point3::new(p.0, p.1, 0.0))
            .collect::<Vec<_>>(),
    )
    .expect("outline");
    let e = run(&c, Vector3::z(), None, Side::Right, 0.2).expect_err("refused");
    let reason = compensation_reason(e);
    assert!(reason.contains("narrower than the kerf"), "{reason}");
    // A 0.25 mm notch takes a 0.2 mm kerf.
    let wide = [
        (0.0, 0.0),
        (20.0, 0.0),
        (20.0, 10.0),
        (10.125, 10.0),
        (10.125, 5.0),
        (9.875, 5.0),
        (9.875, 10.0),
        (0.0, 10.0),
        (0.0, 0.0),
    ];
    let c = NurbsCurve::polyline(
        &wide
            .iter()
            .map(|p| Point3::new(p.0, p.1, 0.0))
            .collect::<Vec<_>>(),
    )
    .expect("outline");
    let path = run(&c, Vector3::z(), None, Side::Right, 0.2).expect("a wider notch");
    assert_eq!(path.inside_corners, 2);
}

#[test]
fn the_point_budget_stops_the_offset() {
    let (params, poses) = contour(&circle(5.0), Vector3::z());
    let input = OffsetInput {
        id: "c",
        curve: &circle(5.0),
        params: &params,
        poses: &poses,
        surface_normals: None,
        scrap: Side::Left,
        closed: true,
    };
    let e = offset(&input, &OffsetOptions::new(0.2, TOL).with_max_points(10)).expect_err("budget");
    assert!(compensation_reason(e).contains("point budget"));
    let bad = offset(&input, &OffsetOptions::new(0.0, TOL)).expect_err("no kerf");
    assert!(matches!(
        bad,
        ProcessError::BadOption {
            name: "kerf_width_mm",
            ..
        }
    ));
}

#[test]
fn point_at_runs_on_the_exact_offset_between_points() {
    let radius = 5.0;
    let c = circle(radius);
    let path = run(&c, Vector3::z(), None, Side::Left, 0.2).expect("hole");
    let n = path.poses.len();
    for k in 0..(n - 1) * 7 {
        let u = k as f64 / 7.0;
        let p = path.point_at(u, &c);
        assert!(
            (p.coords.norm() - (radius - 0.1)).abs() < 1e-9,
            "u {u}: {p}"
        );
    }
    for (k, q) in path.poses.iter().enumerate() {
        let p = path.point_at(k as f64, &c);
        assert!((p - q.position).norm() < 1e-12);
    }
}

/// A surface's unit normal at a point, in closed form.
type NormalFn = Box<dyn Fn(&Point3<f64>) -> Vector3<f64>>;

/// A closed contour on a curved surface with its analytic unit normal.
struct OnSurface {
    name: &'static str,
    curve: NurbsCurve,
    normal: NormalFn,
}

/// The largest `|d - r|` over points along every chord of the path, `d` the distance from the
/// beam's line there (the tip with the axis interpolated along the chord) to the contour: the
/// beam's edge on the contour. The distance is minimized over the exact contour, a scan of
/// 2,000 points refined by golden sections.
fn beam_to_contour(path: &OffsetPath, curve: &NurbsCurve, r: f64) -> f64 {
    let (a, b) = curve.domain();
    let scan: Vec<(f64, Point3<f64>)> = (0..2000)
        .map(|k| {
            let t = a + (b - a) * k as f64 / 2000.0;
            (t, curve.point(t))
        })
        .collect();
    let line_dist = |p: &Point3<f64>, axis: &Vector3<f64>, c: &Point3<f64>| {
        let v = c - p;
        (v - axis * v.dot(axis)).norm()
    };
    let mut worst = 0.0_f64;
    for w in path.poses.windows(2) {
        let (p0, p1) = (w[0].position, w[1].position);
        let (a0, a1) = (w[0].axis, w[1].axis);
        for k in 0..8 {
            let f = k as f64 / 8.0;
            let p = p0 + (p1 - p0) * f;
            let axis = (a0 * (1.0 - f) + a1 * f).normalize();
            let (mut best, mut bt) = (f64::INFINITY, a);
            for (t, c) in &scan {
                let d = line_dist(&p, &axis, c);
                if d < best {
                    best = d;
                    bt = *t;
                }
            }
            let step = (b - a) / 2000.0;
            let (mut lo, mut hi) = (bt - 2.0 * step, bt + 2.0 * step);
            let g = 0.5 * (5f64.sqrt() - 1.0);
            let at = |t: f64| {
                let t = if t < a {
                    t + (b - a)
                } else if t > b {
                    t - (b - a)
                } else {
                    t
                };
                line_dist(&p, &axis, &curve.point(t))
            };
            for _ in 0..80 {
                let (m1, m2) = (hi - g * (hi - lo), lo + g * (hi - lo));
                if at(m1) < at(m2) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            worst = worst.max((at(0.5 * (lo + hi)).min(best) - r).abs());
        }
    }
    worst
}

fn curved_cases() -> Vec<OnSurface> {
    let saddle = kerf_format::curves::load(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/tube_saddle.json"),
    )
    .expect("tube_saddle");
    let hole = saddle
        .curves
        .iter()
        .find(|c| c.id == "main-tube-hole")
        .expect("main-tube-hole")
        .curve
        .clone();
    vec![
        // A latitude circle at z = 30 on a sphere of radius 50 about the origin.
        OnSurface {
            name: "sphere",
            curve: NurbsCurve::circle(Point3::new(0.0, 0.0, 30.0), Vector3::z(), 40.0)
                .expect("latitude"),
            normal: Box::new(|p| p.coords.normalize()),
        },
        // A circle of radius 20 at z = 10 on the cone z = 30 - rho (45 degrees).
        OnSurface {
            name: "cone",
            curve: NurbsCurve::circle(Point3::new(0.0, 0.0, 10.0), Vector3::z(), 20.0)
                .expect("cone circle"),
            normal: Box::new(|p| {
                let rho = (p.x * p.x + p.y * p.y).sqrt();
                Vector3::new(p.x / rho, p.y / rho, 1.0).normalize()
            }),
        },
        // The saddle where a tube of radius 30 along z meets the main tube of radius 60 along
        // x (axis at y = 0, z = 60): the fixture's curve, the main tube's exact normal.
        OnSurface {
            name: "saddle",
            curve: hole,
            normal: Box::new(|p| Vector3::new(0.0, p.y, p.z - 60.0).normalize()),
        },
    ]
}

#[test]
fn on_curved_surfaces_and_tilted_beams_the_beams_edge_runs_on_the_contour() {
    for case in curved_cases() {
        let d = discretize(&case.curve, &Options::with_tolerance(0.9 * TOL)).expect("discretize");
        let normals: Vec<Vector3<f64>> = d.points().iter().map(|p| (case.normal)(p)).collect();
        for tilt_deg in [0.0_f64, 10.0, 20.0, 30.0] {
            let beta = tilt_deg.to_radians();
            // The beam leans sideways: the normal turned about the contour's tangent.
            let poses: Vec<Pose> = d
                .points()
                .iter()
                .zip(d.params())
                .zip(&normals)
                .map(|((p, &t), n)| {
                    let tangent = case.curve.tangent(t).expect("tangent");
                    let a = n * beta.cos() + tangent.cross(n) * beta.sin();
                    Pose::new(p.x, p.y, p.z, a.x, a.y, a.z)
                })
                .collect();
            let m: Vec<[f64; 3]> = normals.iter().map(|n| [n.x, n.y, n.z]).collect();
            for kerf in [0.1, 0.2, 0.3] {
                for side in [Side::Left, Side::Right] {
                    let path = offset(
                        &OffsetInput {
                            id: case.name,
                            curve: &case.curve,
                            params: d.params(),
                            poses: &poses,
                            surface_normals: Some(&m),
                            scrap: side,
                            closed: true,
                        },
                        &OffsetOptions::new(kerf, TOL),
                    )
                    .expect("offset");
                    assert!(
                        path.proven,
                        "{} tilt {tilt_deg} kerf {kerf} {side:?}: every chord proven",
                        case.name
                    );
                    assert!(path.max_chord_error_mm <= TOL);
                    let worst = beam_to_contour(&path, &case.curve, kerf / 2.0);
                    assert!(
                        worst <= TOL,
                        "{} tilt {tilt_deg} kerf {kerf} {side:?}: the beam's edge {worst:.3e} mm off the contour",
                        case.name
                    );
                    assert_eq!(path.poses[0], path.poses[path.poses.len() - 1], "closed");
                }
            }
        }
    }
}

#[test]
fn a_repeated_cutting_point_a_zero_axis_and_an_open_closure_are_handled() {
    // A square hole whose polygon repeats a vertex: a zero-length chord, skipped.
    let h = 10.0;
    let c = NurbsCurve::try_new(
        1,
        vec![0.0, 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 5.0],
        vec![
            Point3::new(h, -h, 0.0),
            Point3::new(h, h, 0.0),
            Point3::new(h, h, 0.0),
            Point3::new(-h, h, 0.0),
            Point3::new(-h, -h, 0.0),
            Point3::new(h, -h, 0.0),
        ],
        None,
    )
    .expect("a polygon with a repeated vertex");
    let path = run(&c, Vector3::z(), None, Side::Left, 0.2).expect("offset");
    assert_eq!(path.inserted, 0, "no point inserted on straight chords");
    assert_eq!(path.inside_corners, 4);
    // The closing corner cut back: the first point's source lies on the first edge, before the
    // second point's, and the sources never decrease.
    assert!(path.source[0] < path.source[1], "{:?}", path.source);
    assert!(
        path.source.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        path.source
    );
    let curve = circle(5.0);
    let (params, mut poses) = contour(&curve, Vector3::z());
    poses[3].axis = Vector3::zeros();
    let zero = OffsetInput {
        id: "c",
        curve: &curve,
        params: &params,
        poses: &poses,
        surface_normals: None,
        scrap: Side::Left,
        closed: true,
    };
    let e = offset(&zero, &OffsetOptions::new(0.2, TOL)).expect_err("zero axis");
    assert!(
        e.to_string()
            .contains("cutting point 3: the tool axis is not a unit vector"),
        "{e}"
    );
    let (_, poses) = contour(&curve, Vector3::z());
    let open = OffsetInput {
        id: "c",
        curve: &curve,
        params: &params[..params.len() - 1],
        poses: &poses[..poses.len() - 1],
        surface_normals: None,
        scrap: Side::Left,
        closed: true,
    };
    let e = offset(&open, &OffsetOptions::new(0.2, TOL)).expect_err("not closed");
    assert!(e.to_string().contains("not its first"), "{e}");
}

#[test]
fn roundings_tighter_than_half_the_kerf_are_cut_back_like_corners() {
    // Corners rounded to 0.05 mm, a 0.2 mm kerf: inside the hole the beam cannot follow the
    // roundings; the straight sides' offsets are cut back to their crossing, as at a sharp
    // corner, and every chord point stays r from the contour.
    let (h, rho) = (10.0, 0.05);
    let c = rounded_square(h, rho);
    let r = 0.1;
    let hole = run(&c, Vector3::z(), None, Side::Left, 2.0 * r).expect("hole");
    assert_eq!(hole.inside_corners, 4, "one cut-back per rounding");
    assert!(
        hole.proven,
        "the chords kept are proven, the cut-backs lie on them"
    );
    assert_at(
        &hole,
        |p| rounded_sdf(p, h, rho),
        -r,
        "hole with tight roundings",
    );
    assert!(
        hole.source.windows(2).all(|w| w[0] <= w[1]),
        "{:?}",
        hole.source
    );
    assert_eq!(hole.poses[0], hole.poses[hole.poses.len() - 1]);
    // Round the outside the roundings turn away from the scrap: offset as they are.
    let outline = run(&c, Vector3::z(), None, Side::Right, 2.0 * r).expect("outline");
    assert_eq!((outline.outside_corners, outline.inside_corners), (0, 0));
    assert_at(
        &outline,
        |p| rounded_sdf(p, h, rho),
        r,
        "outline with tight roundings",
    );
}
