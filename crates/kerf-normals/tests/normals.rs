//! Normals against analytic truth: exact NURBS plane, cylinder, sphere and torus; meshes; real
//! parts.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use kerf_discretize::{discretize, Options};
use kerf_normals::{orient, MeshNormals, NormalOptions, NormalsError, NurbsNormals};
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

const H: f64 = FRAC_1_SQRT_2;
const CIRCLE_KNOTS: [f64; 12] = [
    0.0, 0.0, 0.0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1.0, 1.0, 1.0,
];
const CIRCLE: [(f64, f64, f64); 9] = [
    (1.0, 0.0, 1.0),
    (1.0, 1.0, H),
    (0.0, 1.0, 1.0),
    (-1.0, 1.0, H),
    (-1.0, 0.0, 1.0),
    (-1.0, -1.0, H),
    (0.0, -1.0, 1.0),
    (1.0, -1.0, H),
    (1.0, 0.0, 1.0),
];

/// A surface of revolution about z from a profile `(rho, z, w)` (exact rational quadratic in u).
fn revolve(profile: &[(f64, f64, f64)], degree_v: usize, knots_v: Vec<f64>) -> NurbsSurface {
    let mut pts = Vec::new();
    let mut ws = Vec::new();
    for &(cx, cy, cw) in &CIRCLE {
        pts.push(
            profile
                .iter()
                .map(|&(r, z, _)| Point3::new(r * cx, r * cy, z))
                .collect(),
        );
        ws.push(profile.iter().map(|&(_, _, w)| w * cw).collect());
    }
    NurbsSurface::new(2, degree_v, CIRCLE_KNOTS.to_vec(), knots_v, pts, Some(ws))
}

fn cylinder(r: f64, h: f64) -> NurbsSurface {
    revolve(&[(r, 0.0, 1.0), (r, h, 1.0)], 1, vec![0.0, 0.0, 1.0, 1.0])
}

fn sphere(r: f64) -> NurbsSurface {
    revolve(
        &[
            (0.0, -r, 1.0),
            (r, -r, H),
            (r, 0.0, 1.0),
            (r, r, H),
            (0.0, r, 1.0),
        ],
        2,
        vec![0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0],
    )
}

fn torus(big: f64, small: f64) -> NurbsSurface {
    let prof: Vec<(f64, f64, f64)> = CIRCLE
        .iter()
        .map(|&(x, y, w)| (big + small * x, small * y, w))
        .collect();
    revolve(&prof, 2, CIRCLE_KNOTS.to_vec())
}

fn circle_curve(r: f64, z: f64) -> NurbsCurve {
    NurbsCurve::new(
        2,
        CIRCLE_KNOTS.to_vec(),
        CIRCLE
            .iter()
            .map(|&(x, y, _)| Point3::new(r * x, r * y, z))
            .collect(),
        Some(CIRCLE.iter().map(|&(_, _, w)| w).collect()),
    )
}

/// A cubic B-spline whose control points are `n` samples of `f` on [0, 1] (close to `f`).
fn sampled(n: usize, f: impl Fn(f64) -> Point3<f64>) -> NurbsCurve {
    let pts: Vec<Point3<f64>> = (0..n).map(|i| f(i as f64 / (n - 1) as f64)).collect();
    let mut knots = vec![0.0; 4];
    knots.extend((1..n - 3).map(|i| i as f64 / (n - 3) as f64));
    knots.extend([1.0; 4]);
    NurbsCurve::new(3, knots, pts, None)
}

fn run(
    curve: &NurbsCurve,
    src: &dyn kerf_normals::NormalSource,
    tol: f64,
) -> kerf_normals::Result<kerf_normals::Oriented> {
    let opts = Options::with_tolerance(tol);
    let d = discretize(curve, &opts).unwrap();
    orient(curve, &d, src, &opts, &NormalOptions::default())
}

fn assert_normals(
    o: &kerf_normals::Oriented,
    truth: impl Fn(&Point3<f64>) -> Vector3<f64>,
    eps: f64,
) {
    for (p, n) in o.points().iter().zip(o.normals()) {
        let t = truth(p);
        assert!(
            (n - t).norm() < eps,
            "normal {n:?} vs analytic {t:?} at {p:?}"
        );
    }
}

#[test]
fn plane_normal_is_constant() {
    let plane = NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![
            vec![
                Point3::new(-100.0, -100.0, 5.0),
                Point3::new(-100.0, 100.0, 5.0),
            ],
            vec![
                Point3::new(100.0, -100.0, 5.0),
                Point3::new(100.0, 100.0, 5.0),
            ],
        ],
        None,
    );
    let src = NurbsNormals::new(plane, false);
    let o = run(&circle_curve(30.0, 5.0), &src, 0.01).unwrap();
    assert_normals(&o, |_| Vector3::z(), 1e-12);
    assert_eq!(o.inserted, 0, "constant normal needs no insertion");
}

#[test]
fn cylinder_normal_is_radial_on_a_helix_and_a_circle() {
    let src = NurbsNormals::new(cylinder(20.0, 100.0), false);
    let radial = |p: &Point3<f64>| Vector3::new(p.x, p.y, 0.0).normalize();
    let o = run(&circle_curve(20.0, 40.0), &src, 0.001).unwrap();
    assert_normals(&o, radial, 1e-9);
    let helix = sampled(400, |s| {
        let a = 4.0 * PI * s;
        Point3::new(20.0 * a.cos(), 20.0 * a.sin(), 10.0 + 60.0 * s)
    });
    let o = run(&helix, &src, 0.01).unwrap();
    assert_normals(&o, radial, 1e-9);
    assert!(
        o.max_normal_angle <= 1f64.to_radians() + 1e-12,
        "normal step held"
    );
    assert!(o.max_chord_error() <= 0.01, "chord error still certified");
}

#[test]
fn saddle_curve_of_two_tubes() {
    // Main tube: radius 50 around the x axis (the cylinder rotated), branch radius 20 along z.
    let main = cylinder(50.0, 200.0);
    // Rotate the surface's control points so that its axis is x: (x, y, z) -> (z - 100, y, -x).
    let pts: Vec<Vec<Point3<f64>>> = main
        .control_points()
        .into_iter()
        .map(|row| {
            row.into_iter()
                .map(|p| Point3::new(p.z - 100.0, p.y, -p.x))
                .collect()
        })
        .collect();
    let tube = NurbsSurface::new(
        2,
        1,
        main.knots_u().to_vec(),
        main.knots_v().to_vec(),
        pts,
        Some(main.weights()),
    );
    let src = NurbsNormals::new(tube, false);
    let saddle = sampled(600, |s| {
        let a = 2.0 * PI * s;
        let (x, y) = (20.0 * a.cos(), 20.0 * a.sin());
        Point3::new(x, y, (2500.0 - y * y).sqrt())
    });
    let o = run(&saddle, &src, 0.005).unwrap();
    // Outward normal of the main tube: radial from the x axis.
    assert_normals(&o, |p| Vector3::new(0.0, p.y, p.z).normalize(), 1e-9);
}

#[test]
fn sphere_latitude_and_torus() {
    let src = NurbsNormals::new(sphere(30.0), false);
    for z in [-25.0, 0.0, 12.0, 29.0] {
        let r = (900.0f64 - z * z).sqrt();
        let o = run(&circle_curve(r, z), &src, 0.001).unwrap();
        assert_normals(&o, |p| p.coords / 30.0, 1e-9);
    }
    let src = NurbsNormals::new(torus(60.0, 15.0), false);
    for (rho, z) in [(75.0, 0.0), (45.0, 0.0)] {
        let o = run(&circle_curve(rho, z), &src, 0.001).unwrap();
        assert_normals(
            &o,
            |p| {
                let c = Vector3::new(p.x, p.y, 0.0).normalize() * 60.0;
                (p.coords - c).normalize()
            },
            1e-9,
        );
    }
}

#[test]
fn off_surface_curve_is_rejected_with_its_distance() {
    let src = NurbsNormals::new(cylinder(20.0, 100.0), false);
    match run(&circle_curve(20.05, 40.0), &src, 0.01) {
        Err(NormalsError::OffSurface { distance, .. }) => {
            assert!((distance - 0.05).abs() < 1e-9, "distance {distance}");
        }
        other => panic!("expected OffSurface, got {other:?}"),
    }
}

/// An STL-like cylinder mesh with `n` facets around (duplicated vertices per triangle, as STL
/// stores them), outward winding.
fn cylinder_mesh(r: f64, h: f64, n: usize, flip: bool) -> (Vec<Point3<f64>>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for i in 0..n {
        let a0 = 2.0 * PI * i as f64 / n as f64;
        // The seam uses angle 0 again (not 2 pi), so that shared vertices are bit-identical as
        // in a real STL export.
        let a1 = 2.0 * PI * ((i + 1) % n) as f64 / n as f64;
        let p = |a: f64, z: f64| Point3::new(r * a.cos(), r * a.sin(), z);
        for tri in [
            [p(a0, 0.0), p(a1, 0.0), p(a1, h)],
            [p(a0, 0.0), p(a1, h), p(a0, h)],
        ] {
            let base = v.len() as u32;
            v.extend(tri);
            t.push(if flip {
                [base, base + 2, base + 1]
            } else {
                [base, base + 1, base + 2]
            });
        }
    }
    (v, t)
}

#[test]
fn cylinder_mesh_normals_within_the_facet_bound() {
    let n = 72;
    let (v, t) = cylinder_mesh(20.0, 100.0, n, false);
    let mesh = MeshNormals::new(v, t, 30.0, false).unwrap();
    assert_eq!(mesh.triangle_count(), 2 * n, "facet count");
    // The circle at mid height lies inside the facets (the mesh is inscribed): use one on it
    // by projecting, with a generous on-surface tolerance for the facet sagitta.
    let sag = 20.0 * (1.0 - (PI / n as f64).cos());
    let curve = circle_curve(20.0 - sag / 2.0, 50.0);
    let opts = Options::with_tolerance(0.01);
    let d = discretize(&curve, &opts).unwrap();
    let nopts = NormalOptions::default().with_on_surface_tolerance_mm(sag);
    let o = orient(&curve, &d, &mesh, &opts, &nopts).unwrap();
    let bound = PI / n as f64; // half the facet angle
    for (p, nrm) in o.points().iter().zip(o.normals()) {
        let truth = Vector3::new(p.x, p.y, 0.0).normalize();
        assert!(
            nrm.angle(&truth) <= bound + 1e-9,
            "normal {} off the analytic",
            nrm.angle(&truth)
        );
    }
    // Smooth inside faces: neighbouring normals differ by no more than the step.
    assert!(
        o.max_normal_angle <= 1f64.to_radians() + 1e-12,
        "continuous normals"
    );
    assert!(o.jumps.is_empty(), "no jumps on a smooth mesh");
    // Reversed winding flips every normal.
    let (v, t) = cylinder_mesh(20.0, 100.0, n, true);
    let flipped = MeshNormals::new(v, t, 30.0, false).unwrap();
    let of = orient(&curve, &d, &flipped, &opts, &nopts).unwrap();
    assert_eq!(o.params(), of.params(), "same points");
    // (Exactly, except where a point is equidistant from two facets and the two meshes pick
    // different ones: then both normals are valid and differ by ~1e-5 rad.)
    for ((a, b), p) in o.normals().iter().zip(of.normals()).zip(o.points()) {
        assert!(
            (a + b).norm() < 1e-4,
            "reversed winding reverses the normal at {p:?}: {a:?} {b:?}"
        );
    }
}

fn box_mesh() -> (Vec<Point3<f64>>, Vec<[u32; 3]>) {
    // Unit-less box [0,10]^3, outward winding, 12 triangles.
    let c = |x: f64, y: f64, z: f64| Point3::new(10.0 * x, 10.0 * y, 10.0 * z);
    let v = vec![
        c(0., 0., 0.),
        c(1., 0., 0.),
        c(1., 1., 0.),
        c(0., 1., 0.),
        c(0., 0., 1.),
        c(1., 0., 1.),
        c(1., 1., 1.),
        c(0., 1., 1.),
    ];
    let t = vec![
        [0, 2, 1],
        [0, 3, 2],
        [4, 5, 6],
        [4, 6, 7],
        [0, 1, 5],
        [0, 5, 4],
        [1, 2, 6],
        [1, 6, 5],
        [2, 3, 7],
        [2, 7, 6],
        [3, 0, 4],
        [3, 4, 7],
    ];
    (v, t)
}

#[test]
fn box_mesh_edges_are_not_blended() {
    let (v, t) = box_mesh();
    let mesh = MeshNormals::new(v, t, 30.0, false).unwrap();
    // A line on the top face, then down the side: a polyline with a corner on the 90 degree edge.
    let curve = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 0.5, 1.0, 1.0],
        vec![
            Point3::new(2.0, 5.0, 10.0),
            Point3::new(10.0, 5.0, 10.0),
            Point3::new(10.0, 5.0, 2.0),
        ],
        None,
    );
    let o = run(&curve, &mesh, 0.01).unwrap();
    for (p, n) in o.points().iter().zip(o.normals()) {
        if p.z > 10.0 - 1e-9 && p.x < 10.0 - 1e-9 {
            assert!(
                (n - Vector3::z()).norm() < 1e-12,
                "top face normal at {p:?}: {n:?}"
            );
        }
        if p.x > 10.0 - 1e-9 && p.z < 10.0 - 1e-9 {
            assert!(
                (n - Vector3::x()).norm() < 1e-12,
                "side face normal at {p:?}: {n:?}"
            );
        }
    }
    assert_eq!(o.jumps.len(), 1, "one jump, at the edge");
    assert!((o.jumps[0] - 0.5).abs() < 1e-6, "the jump is at the corner");
}

#[test]
fn an_inconsistently_oriented_mesh_is_an_error() {
    // A flat strip of two squares; the second square's triangles are wound the other way.
    let v = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(10.0, 0.0, 0.0),
        Point3::new(10.0, 10.0, 0.0),
        Point3::new(0.0, 10.0, 0.0),
        Point3::new(20.0, 0.0, 0.0),
        Point3::new(20.0, 10.0, 0.0),
    ];
    let t = vec![[0, 1, 2], [0, 2, 3], [1, 2, 5], [1, 5, 4]];
    let strip = MeshNormals::new(v, t, 30.0, false).unwrap();
    let across = NurbsCurve::new(
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![Point3::new(2.0, 5.0, 0.0), Point3::new(18.0, 5.0, 0.0)],
        None,
    );
    match run(&across, &strip, 0.01) {
        Err(NormalsError::Reversed { angle, t }) => {
            assert!(angle > 170.0, "angle {angle}");
            assert!(
                (t - 0.5).abs() < 1e-6,
                "found where the curve crosses x = 10: {t}"
            );
        }
        other => panic!("expected Reversed, got {other:?}"),
    }
}

#[test]
fn real_parts_get_normals_and_never_reverse() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/realdata");
    for file in ["nori_sheetmetal.json", "occt_propeller.json"] {
        let doc = kerf_format::curves::load(root.join(file)).unwrap();
        for rec in &doc.curves {
            let sid = rec.surface.as_ref().expect("real curves name their face");
            let surf = doc.surface(sid).expect("surface exists");
            let kerf_format::SurfaceGeometry::Nurbs(s) = &surf.geometry else {
                panic!("realdata faces are NURBS");
            };
            let src = NurbsNormals::new(s.clone(), false);
            let o =
                run(&rec.curve, &src, 0.01).unwrap_or_else(|e| panic!("{file} {}: {e}", rec.id));
            assert_eq!(
                o.points().len(),
                o.normals().len(),
                "every point has a normal"
            );
            for w in o.normals().windows(2) {
                assert!(w[0].dot(&w[1]) > 0.0, "{file} {}: normal reverses", rec.id);
            }
            assert!(
                o.max_chord_error() <= 0.01,
                "{file} {}: guarantee kept",
                rec.id
            );
        }
    }
}

#[test]
fn large_parameter_values_do_not_recurse_forever_at_a_jump() {
    // Parameters near 1e7 are 1.9e-9 apart, coarser than 1e-9 of the domain: the split must
    // stop when the midpoint is no longer strictly inside, and report the jump.
    let (v, t) = box_mesh();
    let mesh = MeshNormals::new(v, t, 30.0, false).unwrap();
    let base = 1e7;
    let curve = NurbsCurve::new(
        1,
        vec![base, base, base + 0.5, base + 1.0, base + 1.0],
        vec![
            Point3::new(2.0, 5.0, 10.0),
            Point3::new(10.0, 5.0, 10.0),
            Point3::new(10.0, 5.0, 2.0),
        ],
        None,
    );
    let o = run(&curve, &mesh, 0.01).unwrap();
    assert_eq!(o.jumps.len(), 1, "one jump at the edge");
    for w in o.params().windows(2) {
        assert!(w[1] > w[0], "params strictly increase");
    }
}

/// Issue 13: a degree-1 curve down one generator of an exact NURBS cone, through the apex and
/// up the opposite generator. At the apex (a collapsed edge of the surface) the normal is the
/// limit along the curve: the incoming generator's for the apex point, the outgoing one's for
/// everything after it; the 90-degree change is reported as a jump at the apex, not squeezed
/// into normal-step points.
#[test]
fn cone_apex_normals_are_the_limits_along_the_curve() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/hostile/hostile_cone_apex.json");
    let file = kerf_format::curves::load(&path).expect("fixture loads");
    let rec = &file.curves[0];
    let kerf_format::SurfaceGeometry::Nurbs(surface) = &file.surfaces[0].geometry else {
        panic!("a NURBS cone");
    };
    let src = NurbsNormals::new(surface.clone(), false);
    // Short segments, so that many cutting points lie just past the apex.
    let dopts = Options::with_tolerance(0.01).with_max_segment_length_mm(0.5);
    let disc = discretize(&rec.curve, &dopts).expect("discretized");
    let o = orient(&rec.curve, &disc, &src, &dopts, &NormalOptions::default()).expect("oriented");
    // Analytic: on z = r (half angle 45 degrees) Su x Sv points along (x / r, y / r, -1).
    let analytic = |p: &Point3<f64>, incoming: bool| {
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let (cx, cy) = if r > 1e-9 {
            (p.x / r, p.y / r)
        } else if incoming {
            (1.0, 0.0)
        } else {
            (-1.0, 0.0)
        };
        Vector3::new(cx, cy, -1.0).normalize()
    };
    for (i, (t, (p, n))) in o
        .params()
        .iter()
        .zip(o.points().iter().zip(o.normals()))
        .enumerate()
    {
        let want = analytic(p, *t <= 0.5);
        assert!(
            n.angle(&want) < 1e-6,
            "point {i} at t = {t} ({p:?}): normal {n:?}, analytic {want:?}"
        );
    }
    assert!(
        o.params()
            .iter()
            .filter(|&&t| t > 0.5 && t < 0.5 + 1e-3)
            .count()
            <= 1,
        "no normal-step points squeezed after the apex: {:?}",
        o.params()
            .iter()
            .filter(|&&t| t > 0.5 && t < 0.51)
            .collect::<Vec<_>>()
    );
    assert_eq!(o.jumps, vec![0.5], "one jump, at the apex");
}

#[test]
fn meshes_beyond_the_coordinate_bound_are_refused_not_panicked_on() {
    // A triangle reaching 1e155 mm made parry's point query unwrap a None (the squared
    // distances overflow); one at 1e100 mm lost its face normal to the overflow of |n|^2. Both
    // are refused with the vertex named; a mesh 1e8 mm out still gives its exact normal.
    use kerf_normals::MAX_MESH_COORDINATE_MM;
    use kerf_normals::{Hint, NormalSource};
    for far in [1e100, 1e155, 2.0 * MAX_MESH_COORDINATE_MM] {
        let v = vec![
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(far, 0.0, 0.0),
            Point3::new(0.0, far, 0.0),
        ];
        match MeshNormals::new(v, vec![[0, 1, 2]], 30.0, false) {
            Err(NormalsError::BadMesh(m)) => assert!(m.contains("vertex 1"), "{far}: {m}"),
            other => panic!("{far}: expected a refusal, got {other:?}"),
        }
    }
    let far = 0.5 * MAX_MESH_COORDINATE_MM;
    let v = vec![
        Point3::new(far, far, 0.0),
        Point3::new(far + 10.0, far, 0.0),
        Point3::new(far, far + 10.0, 0.0),
    ];
    let mesh = MeshNormals::new(v, vec![[0, 1, 2]], 30.0, false).expect("within the bound");
    let p = mesh.project(&Point3::new(far + 2.0, far + 3.0, 1.0), Hint::None);
    assert_eq!(p.normal, Some(Vector3::z()), "the winding's normal");
    assert!((p.distance - 1.0).abs() < 1e-6, "{}", p.distance);
}
