//! The STEP reader on the shipped fixtures (made with Open CASCADE, `scripts/make_step_fixtures.py`)
//! and on hand-written files, against independent truth: the geometry the fixture script put
//! in (exact lines, circles and spheres), the mm file for the inch file, and the format's own
//! validator. The full comparison with Open CASCADE's reader is `scripts/step_check.py` (CI).

use std::path::{Path, PathBuf};

use kerf_format::curves::{from_raw, RawCurve, RawSurface, SurfaceRef};
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use kerf_step::{import, import_file, ImportOptions, StepError};
use nalgebra::{Point3, Vector3};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/step")
        .join(name)
}

fn curve(c: &RawCurve) -> NurbsCurve {
    NurbsCurve::try_new(
        c.degree,
        c.knots.clone(),
        c.control_points.iter().map(|&p| Point3::from(p)).collect(),
        c.weights.clone(),
    )
    .expect("valid curve")
}

fn surface(s: &RawSurface) -> NurbsSurface {
    let RawSurface::Nurbs(n) = s else {
        panic!("the reader writes NURBS surfaces only")
    };
    NurbsSurface::try_new(
        n.degree_u,
        n.degree_v,
        n.knots_u.clone(),
        n.knots_v.clone(),
        n.control_points
            .iter()
            .map(|r| r.iter().map(|&p| Point3::from(p)).collect())
            .collect(),
        n.weights.clone(),
    )
    .expect("valid surface")
}

/// `fixtures/realdata/step` (the real STEP parts, shipped with the repository: a test on them
/// cannot pass by skipping them).
fn real_step_dir() -> std::path::PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/realdata/step");
    assert!(dir.is_dir(), "{} is missing", dir.display());
    dir
}

fn samples(c: &NurbsCurve, n: usize) -> Vec<Point3<f64>> {
    let (a, b) = c.domain();
    (0..=n)
        .map(|k| c.point(a + (b - a) * k as f64 / n as f64))
        .collect()
}

#[test]
fn composite_fixture_contours_are_what_the_script_built() {
    let im = import_file(fixture("composite_mm.step"), &ImportOptions::default()).expect("reads");
    // The document is valid kerf.curves/1.
    from_raw(im.file.clone(), Path::new(".")).expect("valid kerf.curves/1");
    let ids: Vec<&str> = im.file.curves.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids.len(), 5, "4 contours, one opened in two: {ids:?}");

    // Contour 1: line (10,10)-(50,10), arc centre (50,30) r 20, rational spline to (10,50),
    // line to (10,10.04): closed, the 0.04 mm gap closed by moving both poles 0.02 mm.
    let c1 = curve(&im.file.curves[0]);
    assert!(c1.is_closed(), "the 0.04 mm gap to the start is closed");
    let (a, b) = c1.domain();
    assert!(
        (c1.point(a) - Point3::new(10.0, 10.02, 20.0)).norm() < 1e-12,
        "start moved to the midpoint: {:?}",
        c1.point(a)
    );
    assert!(
        (im.report.largest_move - 0.02).abs() < 1e-12,
        "largest move {}",
        im.report.largest_move
    );
    assert_eq!(
        im.report.gaps_closed, 1,
        "one real gap closed (rounding gaps are not counted)"
    );
    // The arc: every point of the parameter stretch after the first line (20 mm) for the arc
    // length (20 pi) is on the circle.
    for k in 0..=100 {
        let t = a + 40.0 + 20.0 * std::f64::consts::PI * k as f64 / 100.0;
        let d = (c1.point(t) - Point3::new(50.0, 30.0, 20.0)).norm();
        assert!((d - 20.0).abs() < 1e-9, "arc point at radius {d}");
    }
    // The segments run the way the composite says, although the spline was written reversed
    // (same_sense .F.): after the arc the curve goes to (10, 50), not back to (50, 50).
    let joins = c1.c0_breaks();
    assert!(joins.len() >= 3, "C0 knots at the joins: {joins:?}");
    assert!(
        joins
            .iter()
            .any(|&t| (c1.point(t) - Point3::new(10.0, 50.0, 20.0)).norm() < 1e-9),
        "a join at (10, 50)"
    );
    assert!(b > a, "domain");

    // Contour 2 opened at the 0.3 mm gap, reported with both segments.
    assert!(ids[1].ends_with(".1") && ids[2].ends_with(".2"), "{ids:?}");
    assert_eq!(im.report.opened.len(), 1, "{:?}", im.report.opened);
    assert!(
        im.report.opened[0].contains("COMPOSITE_CURVE: segment 1 (#")
            && im.report.opened[0].contains("(gap 0.300 mm)"),
        "{}",
        im.report.opened[0]
    );

    // Contour 3 runs over the top and the side face: both named, in the list form.
    match &im.file.curves[3].surface {
        Some(SurfaceRef::Many(v)) => assert_eq!(v.len(), 2, "{v:?}"),
        other => panic!("expected two faces, got {other:?}"),
    }
    // The full circle on the side face x = 120: on the circle, in the plane, and starting where
    // Open CASCADE's gp_Ax2 puts the x axis of a placement without reference direction whose
    // axis is +X: (0, 0, 1), so at (120, 50, 15).
    let circle = curve(&im.file.curves[4]);
    for p in samples(&circle, 200) {
        assert!((p.x - 120.0).abs() < 1e-12, "in the plane x = 120");
        assert!(
            ((p - Point3::new(120.0, 50.0, 10.0)).norm() - 5.0).abs() < 1e-12,
            "radius 5"
        );
    }
    let start = circle.point(circle.domain().0);
    // (The file rounds 2 pi to 12 digits: closing that rounding gap moves the start ~1e-12.)
    assert!(
        (start - Point3::new(120.0, 50.0, 15.0)).norm() < 1e-9,
        "start {start:?}"
    );
    assert!(
        matches!(&im.file.curves[4].surface, Some(SurfaceRef::One(_))),
        "one face"
    );
}

#[test]
fn inch_file_gives_the_mm_geometry() {
    let mm = import_file(fixture("composite_mm.step"), &ImportOptions::default()).expect("mm");
    let inch =
        import_file(fixture("composite_inch.step"), &ImportOptions::default()).expect("inch");
    assert_eq!(inch.report.units.length_name, "inch", "unit found");
    assert_eq!(inch.report.units.mm_per_length, 25.4, "factor");
    assert_eq!(
        mm.file.curves.len(),
        inch.file.curves.len(),
        "same contours"
    );
    for (a, b) in mm.file.curves.iter().zip(&inch.file.curves) {
        let (ca, cb) = (curve(a), curve(b));
        for (p, q) in samples(&ca, 300).iter().zip(samples(&cb, 300)) {
            // The inch file holds 12 significant digits of the inch values.
            assert!((p - q).norm() < 1e-8, "{}: {p:?} vs {q:?}", a.id);
        }
    }
}

#[test]
fn faces_of_every_kind_are_exact_and_outward() {
    let opts = ImportOptions::default()
        .with_edges(None)
        .with_all_faces(true);
    let im = import_file(fixture("faces.step"), &opts).expect("reads");
    from_raw(im.file.clone(), Path::new(".")).expect("valid kerf.curves/1");
    let kinds: Vec<&str> = im
        .report
        .surfaces
        .iter()
        .map(|s| s.split('(').nth(1).unwrap_or(""))
        .collect();
    for k in [
        "plane",
        "cylinder",
        "cone",
        "sphere",
        "torus",
        "extrusion",
        "revolution",
        "b-spline",
    ] {
        assert!(
            kinds.iter().any(|s| s.starts_with(k)),
            "a {k} face among {kinds:?}"
        );
    }
    // Analytic truth for the cylinder (axis z through (-150, 0), r 10), sphere (centre
    // (-50, 0, 0), r 9) and torus (centre 0, axis (1,0,1)/sqrt 2, R 15, r 4) of the script:
    // every grid point on the surface, the normal pointing away from the solid's inside.
    let mut seen = 0;
    for (s, line) in im.file.surfaces.iter().zip(&im.report.surfaces) {
        let ns = surface(s);
        let (ua, ub) = ns.domain_u();
        let (va, vb) = ns.domain_v();
        for i in 0..=12 {
            for j in 0..=12 {
                let (u, v) = (
                    ua + (ub - ua) * i as f64 / 12.0,
                    va + (vb - va) * j as f64 / 12.0,
                );
                let p = ns.point(u, v);
                let n = ns.normal(u, v);
                let check = |dist: f64, outward: Vector3<f64>, what: &str| {
                    assert!(dist.abs() < 1e-9, "{line}: {what} off by {dist}");
                    if let Some(n) = n {
                        assert!(
                            n.dot(&outward.normalize()) > 0.999,
                            "{line}: normal {n:?} not outward {outward:?}"
                        );
                    }
                };
                if line.contains("(cylinder") {
                    let r = Vector3::new(p.x + 150.0, p.y, 0.0);
                    check(r.norm() - 10.0, r, "cylinder");
                } else if line.contains("(sphere") {
                    let r = p - Point3::new(-50.0, 0.0, 0.0);
                    check(r.norm() - 9.0, r, "sphere");
                } else if line.contains("(torus") {
                    let axis = Vector3::new(1.0, 0.0, 1.0).normalize();
                    let d = p.coords;
                    let radial = d - axis * d.dot(&axis);
                    let centre = radial.normalize() * 15.0;
                    let r = d - centre;
                    check(r.norm() - 4.0, r, "torus");
                } else {
                    continue;
                }
            }
        }
        seen += usize::from(
            line.contains("(cylinder") || line.contains("(sphere") || line.contains("(torus"),
        );
    }
    assert_eq!(seen, 3, "cylinder, sphere and torus checked");
}

#[test]
fn every_edge_loop_closes_and_lies_on_its_face() {
    let opts = ImportOptions::default().with_edges(None);
    let im = import_file(fixture("faces.step"), &opts).expect("reads");
    let file = from_raw(im.file.clone(), Path::new(".")).expect("valid");
    for c in &file.curves {
        assert!(c.curve.is_closed(), "{}: a face loop is closed", c.id);
        let s = file.surface_of(c).expect("the loop's face");
        let kerf_format::SurfaceGeometry::Nurbs(ns) = &s.geometry else {
            panic!("nurbs")
        };
        for p in samples(&c.curve, 60) {
            let d = ns.closest_point(&p, None).distance;
            assert!(d < 1e-7, "{}: {d} mm off its face", c.id);
        }
    }
}

const HEAD: &str = "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n";
const TAIL: &str = "ENDSEC;\nEND-ISO-10303-21;\n";

fn step(body: &str) -> String {
    format!("{HEAD}{body}{TAIL}")
}

#[test]
fn errors_name_the_entity() {
    let e = import(
        &step("#1=CIRCLE('',#9,5.);\n#2=GEOMETRIC_CURVE_SET('',(#1));\n"),
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "#1 CIRCLE: refers to #9, which the file does not define",
        "dangling"
    );

    let body = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(1.,0.,0.));\n#3=VECTOR('',#2,1.);\n\
        #4=LINE('',#1,#3);\n#5=TRIMMED_CURVE('',#4,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(10.)),.T.,.PARAMETER.);\n\
        #6=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#5);\n#7=COMPOSITE_CURVE('c',(#6,#1),.F.);\n\
        #8=GEOMETRIC_CURVE_SET('',(#7));\n";
    let e = import(&step(body), &ImportOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "#7 COMPOSITE_CURVE: segment 2 (#1) is not a COMPOSITE_CURVE_SEGMENT",
        "bad segment"
    );

    let e = import(
        &step("#1=CARTESIAN_POINT('',(0.,0.,0.));\n"),
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(e, StepError::NoContour { .. }), "{e}");
    assert!(e.to_string().contains("ImportOptions::with_edges"), "{e}");

    let e = import(
        "ISO-10303-21;\nDATA;\n#1=LINE('',#2,#3;\n",
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("line 3:"), "{e}");

    let e = import(
        &step(""),
        &ImportOptions::default().with_close_gaps_mm(f64::NAN),
    )
    .unwrap_err();
    assert!(e.to_string().contains("close_gaps_mm"), "{e}");
}

/// The review's `step/x_nl.step`: a curve named `'a\X\0AG0 X1400 Y700\X\0AM30'` made the
/// whole import fail, and the error named `curves[0].id`, not the STEP entity. The contour is
/// kept under its `#id` and the report names the entity and the character.
#[test]
fn a_name_with_a_line_break_keeps_the_contour_under_its_id() {
    let body = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n\
        #4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CIRCLE('a\\X\\0AG0 X1400\\X\\0AM30',#4,2.);\n\
        #6=CIRCLE('hole',#4,1.);\n#7=GEOMETRIC_CURVE_SET('',(#5,#6));\n";
    let im = import(&step(body), &ImportOptions::default()).expect("reads");
    let ids: Vec<&str> = im.file.curves.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(
        ids,
        ["#5", "hole #6"],
        "both contours, the unsafe name dropped"
    );
    assert!(
        im.report.skipped.iter().any(|s| s
            .starts_with("#5 CIRCLE: its name contains the control character U+000A (line feed)")),
        "{:?}",
        im.report.skipped
    );
}

#[test]
fn a_line_trim_and_degree_units_in_a_hand_written_file() {
    // A circle trimmed from 0 to 90 in a file whose plane angles are degrees and lengths cm.
    let body = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n\
        #4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CIRCLE('',#4,2.);\n\
        #6=TRIMMED_CURVE('q',#5,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(90.)),.T.,.PARAMETER.);\n\
        #7=GEOMETRIC_CURVE_SET('',(#6));\n\
        #10=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.CENTI.,.METRE.));\n\
        #11=(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.));\n\
        #12=PLANE_ANGLE_MEASURE_WITH_UNIT(PLANE_ANGLE_MEASURE(0.0174532925199433),#11);\n\
        #13=(CONVERSION_BASED_UNIT('DEGREE',#12)NAMED_UNIT(*)PLANE_ANGLE_UNIT());\n\
        #14=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT((#10,#13))REPRESENTATION_CONTEXT('',''));\n";
    let im = import(&step(body), &ImportOptions::default()).expect("reads");
    assert_eq!(im.report.units.length_name, "cm", "cm");
    let c = curve(&im.file.curves[0]);
    let (a, b) = c.domain();
    assert!(
        (c.point(a) - Point3::new(20.0, 0.0, 0.0)).norm() < 1e-12,
        "starts at 20 mm on x"
    );
    assert!(
        (c.point(b) - Point3::new(0.0, 20.0, 0.0)).norm() < 1e-9,
        "a quarter turn: {:?}",
        c.point(b)
    );
    for p in samples(&c, 50) {
        assert!((p.coords.norm() - 20.0).abs() < 1e-12, "radius 20 mm");
    }
    assert!(im.file.curves[0].surface.is_none(), "no face in the file");
}

#[test]
fn gaps_above_the_threshold_open_the_contour() {
    let strict = ImportOptions::default().with_close_gaps_mm(0.01);
    let im = import_file(fixture("composite_mm.step"), &strict).expect("reads");
    // The 0.04 mm gap between the end of contour 1 and its start is no longer closed: the
    // contour stays open, its start where the file has it.
    let c1 = curve(&im.file.curves[0]);
    assert!(!c1.is_closed(), "left open");
    assert!(
        (c1.point(c1.domain().0) - Point3::new(10.0, 10.0, 20.0)).norm() < 1e-12,
        "start unmoved"
    );
    assert_eq!(im.report.gaps_closed, 0, "nothing closed");
    assert_eq!(im.report.opened.len(), 1, "{:?}", im.report.opened);
}

#[test]
fn real_sheet_metal_parts_read_with_edges() {
    // Every face loop (`with_sheet(false)`): every face read, every loop closed.
    let dir = real_step_dir();
    for (name, faces) in [("S01094.stp", 24), ("S06298.stp", 75)] {
        let opts = ImportOptions::default().with_edges(None).with_sheet(false);
        let im = import_file(dir.join(name), &opts).expect(name);
        assert_eq!(im.report.faces_read, faces, "{name}: every face read");
        assert!(
            im.report.skipped.is_empty(),
            "{name}: {:?}",
            im.report.skipped
        );
        assert!(im.report.sheet.is_none(), "{name}: no sheet asked for");
        let file = from_raw(im.file, Path::new(".")).expect("valid");
        assert!(
            file.curves.iter().all(|c| c.curve.is_closed()),
            "{name}: loops closed"
        );
    }
}

/// The distance from `p` to the nearest of `surfaces`.
fn distance_to(surfaces: &[&NurbsSurface], p: &Point3<f64>) -> f64 {
    surfaces
        .iter()
        .map(|s| s.closest_point(p, None).distance)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_sheet_metal_solid_has_each_feature_cut_once() {
    // The real bent parts as solids: sheet recognition finds one sheet of the thickness their
    // walls have, and cuts each through-feature once. Independent truths: the file's own face
    // loops (read with `with_sheet(false)`): every stretch of a loop on the cut side that
    // borders a wall is cut (within 1e-6 mm of a contour), and no contour runs beside another
    // at the sheet's thickness (its twin on the other face); the hole of S06298 is a circle of
    // radius 50 mm.
    let dir = real_step_dir();
    for (name, thickness, features) in [("S01094.stp", 2.65, 2), ("S06298.stp", 3.0, 2)] {
        let im =
            import_file(dir.join(name), &ImportOptions::default().with_edges(None)).expect(name);
        // Without --edges: the file has no cut curves, its faces form one sheet, so the same
        // features are cut, said in a warning.
        let plain = import_file(dir.join(name), &ImportOptions::default()).expect(name);
        assert_eq!(plain.file.curves, im.file.curves, "{name}: as with --edges");
        assert!(
            plain
                .report
                .warnings
                .iter()
                .any(|w| w.contains("form one sheet")),
            "{name}: {:?}",
            plain.report.warnings
        );
        let sheet = im.report.sheet.clone().expect("sheet recognition ran");
        assert_eq!(sheet.not_a_sheet, None, "{name}");
        assert!(
            (sheet.thickness_mm - thickness).abs() < 1e-6,
            "{name}: {}",
            sheet.thickness_mm
        );
        assert_eq!(
            sheet.features.len(),
            features,
            "{name}: {:?}",
            sheet.features
        );
        let surf: std::collections::HashMap<String, NurbsSurface> = im
            .file
            .surfaces
            .iter()
            .map(|s| {
                let RawSurface::Nurbs(n) = s else {
                    panic!("NURBS")
                };
                (n.id.clone(), surface(s))
            })
            .collect();
        let by_ids = |ids: &[u64]| -> Vec<&NurbsSurface> {
            ids.iter().map(|i| &surf[&format!("face #{i}")]).collect()
        };
        let (side, other, walls) = (
            by_ids(&sheet.side),
            by_ids(&sheet.other_side),
            by_ids(&sheet.walls),
        );
        // The surfaces a contour names.
        let named_of = |c: &RawCurve| -> Vec<&NurbsSurface> {
            c.surface
                .as_ref()
                .expect("a face")
                .ids()
                .iter()
                .map(|i| &surf[i])
                .collect()
        };
        let cut: Vec<NurbsCurve> = im.file.curves.iter().map(curve).collect();
        let cut_samples: Vec<Vec<Point3<f64>>> = cut.iter().map(|c| samples(c, 200)).collect();
        // Every contour runs along a wall on one side of the sheet (the cut side, or the other
        // where the cut side faces down), with the scrap and the sheet's thickness given, and
        // its surfaces face up or sideways wherever it runs: never down, where the beam would
        // have to come from below (the nozzle then standing off from the far face).
        let mut on_other = 0;
        for (c, s) in im.file.curves.iter().zip(&cut_samples) {
            assert!(c.scrap.is_some(), "{name}: {} has a scrap side", c.id);
            assert_eq!(
                c.sheet_thickness_mm,
                Some(sheet.thickness_mm),
                "{name}: {}",
                c.id
            );
            let named = named_of(c);
            let sided = if distance_to(&side, &s[s.len() / 2]) < 1e-6 {
                &side
            } else {
                on_other += 1;
                &other
            };
            for p in s {
                assert!(
                    distance_to(sided, p) < 1e-6,
                    "{name}: {} leaves its side at {p}",
                    c.id
                );
                assert!(
                    distance_to(&walls, p) < 1e-6,
                    "{name}: {} off the walls at {p}",
                    c.id
                );
                let near = named
                    .iter()
                    .map(|f| (f, f.closest_point(p, None)))
                    .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance))
                    .expect("a face");
                let n = near.0.normal(near.1.u, near.1.v).expect("a normal");
                assert!(
                    n.z > -0.2,
                    "{name}: {} faces down at {p} (normal {n:?})",
                    c.id
                );
            }
        }
        // The scrap side's name holds on every contour, the twins too (their normal and
        // direction both reversed): `left` is the side of n x t, and the wall beside the
        // contour has its outward normal (toward the scrap) that way.
        for (c, k) in im.file.curves.iter().zip(&cut) {
            let (a, b) = k.domain();
            let mut votes = [0usize; 2];
            for j in 1..8 {
                let u = a + (b - a) * j as f64 / 8.0;
                let (p, tangent) = (k.point(u), k.tangent(u).expect("a tangent"));
                let normal_of = |fs: &[&NurbsSurface]| {
                    let (f, at) = fs
                        .iter()
                        .map(|f| (f, f.closest_point(&p, None)))
                        .min_by(|x, y| x.1.distance.total_cmp(&y.1.distance))
                        .expect("a face");
                    f.normal(at.u, at.v).expect("a normal")
                };
                let named = named_of(c);
                let n = normal_of(&named);
                // The wall beside the contour: on it, and along it (at a corner another wall
                // touches the point too, across the contour).
                let w = walls
                    .iter()
                    .filter_map(|f| {
                        let at = f.closest_point(&p, None);
                        let w = f.normal(at.u, at.v)?;
                        (at.distance < 1e-6).then_some(w)
                    })
                    .min_by(|x, y| x.dot(&tangent).abs().total_cmp(&y.dot(&tangent).abs()))
                    .expect("a wall beside the contour");
                votes[usize::from(n.cross(&tangent).dot(&w) > 0.0)] += 1;
            }
            let left = c.scrap.as_deref() == Some("left");
            assert_eq!(
                votes[usize::from(left)],
                7,
                "{name}: {} scrap {:?}, votes (right, left) {votes:?}",
                c.id,
                c.scrap
            );
        }
        // S06298's outline runs over a flange lip whose cut side faces down: three pieces.
        let lip = if name == "S06298.stp" { 3 } else { 0 };
        assert_eq!(on_other, lip, "{name}: pieces on the other side");
        // No twins: no contour's middle is at the thickness from another contour.
        let near = |p: &Point3<f64>, other: usize| cut[other].closest_point(p).distance;
        for a in 0..cut.len() {
            for b in 0..cut.len() {
                if a == b {
                    continue;
                }
                let twin = cut_samples[a]
                    .iter()
                    .filter(|p| (near(p, b) - thickness).abs() < 0.05 * thickness)
                    .count();
                assert!(
                    twin < cut_samples[a].len() / 2,
                    "{name}: {} runs beside {} at the thickness",
                    im.file.curves[a].id,
                    im.file.curves[b].id
                );
            }
        }
        // Coverage: the file's own loops on the cut side, wherever they border a wall.
        let every = import_file(
            dir.join(name),
            &ImportOptions::default().with_edges(None).with_sheet(false),
        )
        .expect(name);
        let side_ids: Vec<String> = sheet.side.iter().map(|i| format!("face #{i}")).collect();
        // Where the cut side faces down, the point is cut on its twin: the thickness behind
        // it along the face's normal, on a contour of the other side.
        let mut checked = 0;
        let mut behind = 0;
        for l in &every.file.curves {
            let Some(SurfaceRef::One(face)) = &l.surface else {
                continue;
            };
            if !side_ids.contains(face) {
                continue;
            }
            for p in samples(&curve(l), 400) {
                if distance_to(&walls, &p) > 1e-9 {
                    continue;
                }
                checked += 1;
                let nearest = |q: &Point3<f64>| {
                    cut.iter()
                        .map(|c| c.closest_point(q).distance)
                        .fold(f64::INFINITY, f64::min)
                };
                let d = nearest(&p);
                if d < 1e-6 {
                    continue;
                }
                let f = &surf[face];
                let at = f.closest_point(&p, None);
                let n = f.normal(at.u, at.v).expect("a normal");
                let twin = p - n * sheet.thickness_mm;
                let d_twin = nearest(&twin);
                assert!(
                    n.z < 0.2 && d_twin < 0.01 * sheet.thickness_mm + 1e-3,
                    "{name}: {} at {p} is not cut ({d} mm; its twin {d_twin} mm, normal {n:?})",
                    l.id
                );
                behind += 1;
            }
        }
        assert_eq!(
            behind > 0,
            lip > 0,
            "{name}: {behind} points cut on their twins"
        );
        assert!(checked > 400, "{name}: {checked} points checked");
        if name == "S06298.stp" {
            let hole = im
                .file
                .curves
                .iter()
                .map(curve)
                .find(|c| (c.arc_length() - 100.0 * std::f64::consts::PI).abs() < 1e-6)
                .expect("the hole");
            let s = samples(&hole, 64);
            let centre = s[..64].iter().fold(Vector3::zeros(), |a, p| a + p.coords) / 64.0;
            assert!(
                s.iter()
                    .all(|p| ((p.coords - centre).norm() - 50.0).abs() < 1e-6),
                "{name}: the hole is a circle of radius 50"
            );
        }
    }
}

#[test]
fn a_placement_moves_what_its_representation_holds_and_a_cycle_is_refused() {
    // A circle's set in representation #10, placed into #11 by the transformation taking the
    // origin to (100, 0, 0): the circle is cut about (100, 0, 0).
    let body = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=CARTESIAN_POINT('',(100.,0.,0.));\n\
        #3=AXIS2_PLACEMENT_3D('',#1,$,$);\n#4=AXIS2_PLACEMENT_3D('',#2,$,$);\n\
        #5=ITEM_DEFINED_TRANSFORMATION('','',#3,#4);\n#6=CIRCLE('',#3,5.);\n#7=GEOMETRIC_CURVE_SET('',(#6));\n\
        #10=SHAPE_REPRESENTATION('',(#3,#7),$);\n#11=SHAPE_REPRESENTATION('',(#4),$);\n\
        #12=(REPRESENTATION_RELATIONSHIP('','',#10,#11)REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#5)SHAPE_REPRESENTATION_RELATIONSHIP());\n";
    let imp = import(&step(body), &ImportOptions::default()).expect("placed");
    let c = curve(&imp.file.curves[0]);
    for p in samples(&c, 40) {
        let r = (p - Point3::new(100.0, 0.0, 0.0)).norm();
        assert!(
            (r - 5.0).abs() < 1e-12,
            "circle point {p} at {r} from (100, 0, 0)"
        );
    }
    // The set in a wireframe representation joined to #10 by a SHAPE_REPRESENTATION_
    // RELATIONSHIP written alone (as SolidWorks joins a part's shape and its B-rep), and #10
    // placed by a lone REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION: moved the same.
    let lone = body
        .replace("#10=SHAPE_REPRESENTATION('',(#3,#7),$);", "#10=SHAPE_REPRESENTATION('',(#3),$);\n#20=GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('',(#7),$);\n#21=SHAPE_REPRESENTATION_RELATIONSHIP('','',#20,#10);")
        .replace("#12=(REPRESENTATION_RELATIONSHIP('','',#10,#11)REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#5)SHAPE_REPRESENTATION_RELATIONSHIP());", "#12=REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION('','',#10,#11,#5);");
    assert!(lone.contains("#21=") && lone.contains("#12=REPRESENTATION_RELATIONSHIP_WITH"));
    // The same with the wireframe representation numbered below the one it is joined to (the
    // lower number of a pair once went unvisited and its curves unplaced).
    let low = lone.replace("#20=", "#8=").replace(
        "#21=SHAPE_REPRESENTATION_RELATIONSHIP('','',#20,#10);",
        "#21=SHAPE_REPRESENTATION_RELATIONSHIP('','',#8,#10);",
    );
    let imp = import(&step(&low), &ImportOptions::default()).expect("placed");
    let c = curve(&imp.file.curves[0]);
    for p in samples(&c, 40) {
        let r = (p - Point3::new(100.0, 0.0, 0.0)).norm();
        assert!(
            (r - 5.0).abs() < 1e-12,
            "lower-numbered representation: circle point {p}"
        );
    }
    let imp = import(&step(&lone), &ImportOptions::default()).expect("placed");
    let c = curve(&imp.file.curves[0]);
    for p in samples(&c, 40) {
        let r = (p - Point3::new(100.0, 0.0, 0.0)).norm();
        assert!(
            (r - 5.0).abs() < 1e-12,
            "lone relationships: circle point {p}"
        );
    }
    // A transformation no relationship uses places nothing.
    let stray = body.replace("#12=", "#99=CARTESIAN_POINT('',(1.,1.,1.));\n#98=");
    let stray = stray.replace("#98=(REPRESENTATION_RELATIONSHIP('','',#10,#11)REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#5)SHAPE_REPRESENTATION_RELATIONSHIP());", "");
    let imp = import(&step(&stray), &ImportOptions::default()).expect("in place");
    let c = curve(&imp.file.curves[0]);
    assert!((c.point(c.domain().0) - Point3::new(5.0, 0.0, 0.0)).norm() < 1e-12);
    // Each placed in the other: refused, not followed for ever.
    let cycle = format!(
        "{body}#13=(REPRESENTATION_RELATIONSHIP('','',#11,#10)REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#5)SHAPE_REPRESENTATION_RELATIONSHIP());\n"
    );
    let e = import(&step(&cycle), &ImportOptions::default()).expect_err("a cycle");
    assert!(e.to_string().contains("is placed in itself"), "{e}");
}

#[test]
fn sheet_features_have_the_scrap_where_the_material_is_not() {
    // fixtures/step/sheet (scripts/make_sheet_steps.py): a 100 x 60 x 2 mm plate with a 12-gon
    // hole of circumradius 10 about (50, 30). Truth from the geometry alone: a point 0.5 mm to
    // the scrap side of each feature (left = n x t, n the cut side's normal, +z or -z) is off
    // the plate: outside the rectangle for the outline, inside the hole for the hole. The same
    // plate with unused ORIENTED_FACE(.F.) entities on its walls reads the same (they flipped
    // every scrap side); a 45-degree beveled hole is not taken for a sheet.
    let in_material = |p: &Point3<f64>| {
        let inside_rect = p.x > 0.0 && p.x < 100.0 && p.y > 0.0 && p.y < 60.0;
        // The 12-gon's inscribed radius is 10 cos 15 deg = 9.66: beyond 10 is material.
        let off_hole = ((p.x - 50.0).powi(2) + (p.y - 30.0).powi(2)).sqrt() > 10.0;
        inside_rect && off_hole
    };
    for name in ["plate.step", "dangling_orient.step"] {
        let im = import_file(
            fixture(&format!("sheet/{name}")),
            &ImportOptions::default().with_edges(None),
        )
        .expect(name);
        let sheet = im.report.sheet.clone().expect("ran");
        assert_eq!(sheet.not_a_sheet, None, "{name}");
        assert!((sheet.thickness_mm - 2.0).abs() < 1e-9, "{name}");
        assert_eq!(im.file.curves.len(), 2, "{name}: the outline and the hole");
        for c in &im.file.curves {
            let curve = curve(c);
            let z = curve.point(curve.domain().0).z;
            let n = if z > 1.0 { Vector3::z() } else { -Vector3::z() };
            let scrap_left = c.scrap.as_deref() == Some("left");
            let (a, b) = curve.domain();
            for k in 0..40 {
                // Off the corners (the knots at 100/320 etc. are sample fractions of 0.5).
                let u = a + (b - a) * (k as f64 + 0.37) / 40.0;
                let p = curve.point(u);
                let t = curve.tangent(u).expect("tangent");
                let left = n.cross(&t).normalize();
                let scrap = p + if scrap_left { left } else { -left } * 0.5;
                let part = p - if scrap_left { left } else { -left } * 0.5;
                assert!(
                    !in_material(&scrap),
                    "{name}: {} scrap at {scrap} is material",
                    c.id
                );
                assert!(
                    in_material(&part),
                    "{name}: {} part side at {part} is not",
                    c.id
                );
            }
        }
    }
    let im = import_file(
        fixture("sheet/bevel_hole.step"),
        &ImportOptions::default().with_edges(None),
    )
    .expect("every face loop instead");
    let why = im
        .report
        .sheet
        .and_then(|s| s.not_a_sheet)
        .expect("not a sheet");
    assert!(why.contains("not at right angles"), "{why}");
}

#[test]
fn a_mapped_item_places_its_representation_where_its_holder_says() {
    // A MAPPED_ITEM placing a geometric set's circle 500 mm away (from #3 at the origin onto
    // #4 at (500, 0, 0)), held by the shape representation #12: the circle is cut about
    // (500, 0, 0).
    let body = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=CARTESIAN_POINT('',(500.,0.,0.));\n\
        #3=AXIS2_PLACEMENT_3D('',#1,$,$);\n#4=AXIS2_PLACEMENT_3D('',#2,$,$);\n\
        #6=CIRCLE('',#3,5.);\n#7=GEOMETRIC_CURVE_SET('',(#6));\n\
        #8=GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('',(#7),$);\n\
        #9=REPRESENTATION_MAP(#3,#8);\n#10=MAPPED_ITEM('',#9,#4);\n\
        #12=SHAPE_REPRESENTATION('',(#10,#3),$);\n";
    let im = import(&step(body), &ImportOptions::default()).expect("placed");
    let c = curve(&im.file.curves[0]);
    assert!(
        samples(&c, 16)
            .iter()
            .all(|p| ((p - Point3::new(500.0, 0.0, 0.0)).norm() - 5.0).abs() < 1e-9),
        "the circle where the mapped item puts it"
    );
    // Held by no representation, it says where nothing goes: refused, naming the item (it
    // was once read where the map's own coordinates put it, 500 mm off).
    let loose = body.replace("#12=SHAPE_REPRESENTATION('',(#10,#3),$);\n", "");
    let e = import(&step(&loose), &ImportOptions::default()).unwrap_err();
    assert!(
        e.to_string().starts_with(
            "#10 MAPPED_ITEM: places the items of #9 from #3 at #4, but no representation kerf knows holds it"
        ),
        "{e}"
    );
    // In place (the same frame as origin and target) it is read where it is.
    let same = loose.replace("#10=MAPPED_ITEM('',#9,#4)", "#10=MAPPED_ITEM('',#9,#3)");
    let im = import(&step(&same), &ImportOptions::default()).expect("in place");
    let c = curve(&im.file.curves[0]);
    assert!(
        samples(&c, 16)
            .iter()
            .all(|p| (p.coords.norm() - 5.0).abs() < 1e-9),
        "the circle where the file puts it"
    );
    // A representation that holds an in-place map of a representation it is also joined to
    // (a part's shape holding its own B-rep): no placement, not a cycle.
    let own = body.replace("#10=MAPPED_ITEM('',#9,#4)", "#10=MAPPED_ITEM('',#9,#3)")
        + "#13=SHAPE_REPRESENTATION_RELATIONSHIP('','',#8,#12);\n";
    let im = import(&step(&own), &ImportOptions::default()).expect("in place, joined");
    let c = curve(&im.file.curves[0]);
    assert!(samples(&c, 16)
        .iter()
        .all(|p| (p.coords.norm() - 5.0).abs() < 1e-9));
    // A transformation operator as the target (it may scale or mirror): refused.
    let op = body.replace(
        "#10=MAPPED_ITEM('',#9,#4)",
        "#11=CARTESIAN_TRANSFORMATION_OPERATOR_3D('','','',$,$,#1,1.,$);\n#10=MAPPED_ITEM('',#9,#11)",
    );
    let e = import(&step(&op), &ImportOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("CARTESIAN_TRANSFORMATION_OPERATOR_3D"),
        "{e}"
    );
}

/// A square face 100 mm across on the plane `z = height`, entity numbers from `base`: the
/// plane, its loop and the face (`#base+30`).
fn square_face(base: usize, height: f64) -> String {
    let b = |k: usize| base + k;
    let mut s = format!(
        "#{}=CARTESIAN_POINT('',(0.,0.,{height:.4}));\n#{}=AXIS2_PLACEMENT_3D('',#{},$,$);\n#{}=PLANE('',#{});\n",
        b(0),
        b(1),
        b(0),
        b(2),
        b(1)
    );
    let corners = [(-50.0, -50.0), (50.0, -50.0), (50.0, 50.0), (-50.0, 50.0)];
    for (k, (x, y)) in corners.iter().enumerate() {
        s += &format!(
            "#{}=CARTESIAN_POINT('',({x:.1},{y:.1},{height:.4}));\n",
            b(3 + k)
        );
        s += &format!("#{}=VERTEX_POINT('',#{});\n", b(7 + k), b(3 + k));
    }
    for k in 0..4 {
        let (p, q) = (b(3 + k), b(3 + (k + 1) % 4));
        let (v, w) = (b(7 + k), b(7 + (k + 1) % 4));
        s += &format!("#{}=POLYLINE('',(#{p},#{q}));\n", b(11 + k));
        s += &format!(
            "#{}=EDGE_CURVE('',#{v},#{w},#{},.T.);\n",
            b(15 + k),
            b(11 + k)
        );
        s += &format!("#{}=ORIENTED_EDGE('',*,*,#{},.T.);\n", b(19 + k), b(15 + k));
    }
    s += &format!(
        "#{}=EDGE_LOOP('',(#{},#{},#{},#{}));\n#{}=FACE_OUTER_BOUND('',#{},.T.);\n#{}=ADVANCED_FACE('',(#{}),#{},.T.);\n",
        b(23),
        b(19),
        b(20),
        b(21),
        b(22),
        b(24),
        b(23),
        b(30),
        b(24),
        b(2)
    );
    s
}

#[test]
fn face_association_works_on_the_faces_a_contour_passes_within_a_budget() {
    // 200 square faces stacked 10 mm apart and one circle on the 8th: the projections are the
    // circle's samples on that face alone (the others' boxes miss the circle's), counted in the
    // report's work beside the faces' own boundary samples.
    let mut body = String::new();
    for k in 0..200 {
        body += &square_face(1000 + 100 * k, 10.0 * k as f64);
    }
    body += "#1=CARTESIAN_POINT('',(0.,0.,70.));\n#2=AXIS2_PLACEMENT_3D('',#1,$,$);\n\
             #3=CIRCLE('',#2,20.);\n#4=GEOMETRIC_CURVE_SET('',(#3));\n";
    let im = import(&step(&body), &ImportOptions::default()).expect("reads");
    assert_eq!(
        im.file.curves[0].surface,
        Some(SurfaceRef::One("face #1730".into()))
    );
    // EDGE_SAMPLES (181) for the range and EDGE_CHECK_SAMPLES (5) on the surface, per edge use.
    let boundary = 200 * 4 * (181 + 5);
    let projected = im.report.work.face_tests as usize - boundary;
    assert!(projected > 0 && projected <= 201, "{projected} projections");
    // A thousand faces over one plane and a thousand circles on it: each surface is projected
    // onto once (it asked for 2e8 projections and minutes before); every circle on the first.
    let mut body = square_face(1000, 0.0);
    for k in 1..1000 {
        body += &format!("#{}=ADVANCED_FACE('',(#1024),#1002,.T.);\n", 200_000 + k);
    }
    let mut set = Vec::new();
    for k in 0..1000 {
        body += &format!(
            "#{}=CIRCLE('',#1001,{:.2});\n",
            300_000 + k,
            1.0 + 0.04 * k as f64
        );
        set.push(format!("#{}", 300_000 + k));
    }
    body += &format!("#9=GEOMETRIC_CURVE_SET('',({}));\n", set.join(","));
    let im = import(&step(&body), &ImportOptions::default()).expect("reads");
    assert_eq!(im.file.curves.len(), 1000);
    assert!(im
        .file
        .curves
        .iter()
        .all(|c| c.surface == Some(SurfaceRef::One("face #1030".into()))));
    let projected = im.report.work.face_tests as usize - 1000 * 4 * (181 + 5);
    assert!(projected <= 1000 * 201, "{projected} projections");
    // Eleven different faces over one another and a polyline of 62,500 spans (a million
    // samples) on them: 11 M projections, over the budget of 10 M: refused before any is made,
    // naming the curve.
    let mut body = String::new();
    for k in 0..11 {
        body += &square_face(1000 + 100 * k, 1e-3 * k as f64);
    }
    let n = 62_501;
    let mut pts = Vec::with_capacity(n);
    for i in 0..n {
        let (x, y) = (
            -40.0 + 80.0 * (i % 2) as f64,
            -40.0 + 80.0 * i as f64 / n as f64,
        );
        body += &format!("#{}=CARTESIAN_POINT('',({x:.4},{y:.4},0.));\n", 100_000 + i);
        pts.push(format!("#{}", 100_000 + i));
    }
    let mults: Vec<String> = (0..n)
        .map(|i| if i == 0 || i == n - 1 { "2" } else { "1" }.to_string())
        .collect();
    let knots: Vec<String> = (0..n).map(|i| format!("{i}.")).collect();
    body += &format!(
        "#5=B_SPLINE_CURVE_WITH_KNOTS('zigzag',1,({}),.UNSPECIFIED.,.F.,.F.,({}),({}),.UNSPECIFIED.);\n#6=GEOMETRIC_CURVE_SET('',(#5));\n",
        pts.join(","),
        mults.join(","),
        knots.join(",")
    );
    let Err(e) = import(&step(&body), &ImportOptions::default()) else {
        panic!("the zigzag over eleven faces is over the budget");
    };
    let msg = e.to_string();
    assert!(
        msg.starts_with("#5 B_SPLINE_CURVE_WITH_KNOTS")
            && msg
                .contains("more points projected onto faces than the reader's budget of 10000000"),
        "{msg}"
    );
}

#[test]
fn hostile_files_give_errors_not_hangs_or_panics() {
    let circle = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n\
        #4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CIRCLE('',#4,2.);\n";
    // A trim parameter far beyond 2 pi: one turn at most, computed without looping.
    let huge = format!(
        "{circle}#6=TRIMMED_CURVE('',#5,(PARAMETER_VALUE(1.E300)),(PARAMETER_VALUE(0.)),.T.,.PARAMETER.);\n#7=GEOMETRIC_CURVE_SET('',(#6));\n"
    );
    let im = import(&step(&huge), &ImportOptions::default()).expect("reads");
    let c = curve(&im.file.curves[0]);
    assert!(
        samples(&c, 20)
            .iter()
            .all(|p| (p.coords.norm() - 2.0).abs() < 1e-9),
        "on the circle"
    );
    // A surface curve that is its own 3D curve, and a composite that contains itself.
    let cycle = "#1=SURFACE_CURVE('',#1,(),.CURVE_3D.);\n#2=GEOMETRIC_CURVE_SET('',(#3));\n\
        #3=COMPOSITE_CURVE('',(#4),.F.);\n#4=COMPOSITE_CURVE_SEGMENT(.CONTINUOUS.,.T.,#3);\n";
    // The composite that contains itself is caught as a piece used twice in one contour.
    let e = import(&step(cycle), &ImportOptions::default()).unwrap_err();
    assert!(e.to_string().contains("already used by #3"), "{e}");
    let e = import(
        &step("#1=SURFACE_CURVE('',#1,(),.CURVE_3D.);\n#2=TRIMMED_CURVE('',#1,(PARAMETER_VALUE(0.)),(PARAMETER_VALUE(1.)),.T.,.PARAMETER.);\n#3=GEOMETRIC_CURVE_SET('',(#2));\n"),
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("deep (a cycle?)"), "{e}");
    // A B-spline record cut short.
    let e = import(
        &step("#1=B_SPLINE_CURVE_WITH_KNOTS('',3);\n#2=GEOMETRIC_CURVE_SET('',(#1));\n"),
        &ImportOptions::default(),
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with("#1 B_SPLINE_CURVE_WITH_KNOTS: "),
        "{e}"
    );
}

#[test]
fn a_byte_order_mark_is_skipped_by_both_entry_points() {
    let path = fixture("composite_mm.step");
    let bytes = std::fs::read(&path).expect("fixture");
    let opts = ImportOptions::default();
    let plain = import_file(&path, &opts).expect("the fixture imports");
    let json = |i: &kerf_step::Import| serde_json::to_string(&i.file).expect("serialises");

    let mut with_bom = b"\xEF\xBB\xBF".to_vec();
    with_bom.extend_from_slice(&bytes);
    let dir = std::env::temp_dir().join(format!("kerf-step-bom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let bom_path = dir.join("composite_mm.step");
    std::fs::write(&bom_path, &with_bom).expect("write");
    let from_file = import_file(&bom_path, &opts).expect("a BOM file imports");
    std::fs::remove_dir_all(&dir).ok();
    assert_eq!(
        json(&from_file),
        json(&plain),
        "the same document as without the BOM"
    );

    let text = format!("\u{feff}{}", String::from_utf8(bytes).expect("ASCII"));
    let from_text = import(&text, &opts).expect("a BOM text imports");
    assert_eq!(
        json(&from_text),
        json(&plain),
        "the same document from text"
    );
}

#[test]
fn a_trim_point_off_its_curve_is_refused_by_name() {
    // A circle of radius 2 trimmed by points (master representation .CARTESIAN.): on the
    // circle the piece is the quarter; at its centre, or 500 mm away, the trim would cut a
    // piece from nowhere (the adversarial round's E1/E3), so the file is refused naming the
    // trimmed curve and the distance.
    let base = "#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=DIRECTION('',(0.,0.,1.));\n#3=DIRECTION('',(1.,0.,0.));\n\
        #4=AXIS2_PLACEMENT_3D('',#1,#2,#3);\n#5=CIRCLE('',#4,2.);\n#8=CARTESIAN_POINT('',(2.,0.,0.));\n";
    let file = |p2: &str| {
        step(&format!(
            "{base}#9=CARTESIAN_POINT('',({p2}));\n\
             #6=TRIMMED_CURVE('arc',#5,(#8),(#9),.T.,.CARTESIAN.);\n#7=GEOMETRIC_CURVE_SET('',(#6));\n"
        ))
    };
    let im = import(&file("0.,2.,0."), &ImportOptions::default()).expect("on the circle");
    let c = curve(&im.file.curves[0]);
    let (_, b) = c.domain();
    assert!((c.point(b) - Point3::new(0.0, 2.0, 0.0)).norm() < 1e-9);
    // 0.05 mm off (a CAD edge tolerance): accepted, projected.
    import(&file("0.,2.05,0."), &ImportOptions::default()).expect("within the tolerance");
    for (p, off) in [("0.,0.,0.", "2.000000"), ("0.,502.,0.", "500.000000")] {
        let e = import(&file(p), &ImportOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("#6") && e.contains(&format!("lies {off} mm off its curve")),
            "{p}: {e}"
        );
    }
}

#[test]
fn an_edge_off_its_face_gets_the_face_refused_by_name() {
    // The plate's front wall (#298, the plane y = 0 through #277, normal -y) moved to y = 5
    // while its edges stay at y = 0: its edges do not bound it. It was read, its parameter
    // range taken from points off it; now the face is skipped naming an edge of it and the
    // distance (5 mm, the move), and the sheet is not recognised with the wall missing. A move
    // of 0.05 mm (a CAD edge tolerance) is accepted, and the plate is the plate.
    let text = std::fs::read_to_string(fixture("sheet/plate.step")).expect("fixture");
    let wall = "#277 = CARTESIAN_POINT('',(0.0,0.0,0.0));";
    assert!(text.contains(wall), "the fixture's front wall origin");
    let moved = |y: &str| text.replace(wall, &format!("#277 = CARTESIAN_POINT('',(0.0,{y},0.0));"));
    let opts = ImportOptions::default().with_edges(None);
    let im = import(&moved("5.0"), &opts).expect("the other faces are read");
    let why = im
        .report
        .skipped
        .iter()
        .find(|s| s.starts_with("face #298 ADVANCED_FACE"))
        .unwrap_or_else(|| panic!("the wall skipped: {:?}", im.report.skipped));
    // #192 is the plate's bottom front edge, y = 0, z = 0: 5 mm from the moved plane.
    assert!(
        why.contains("edge #192 lies 5.000000 mm off the face's plane at (")
            && why.contains(
                ", 0.000000, 0.000000) (at most 0.1 mm): the edge does not bound this face"
            ),
        "{why}"
    );
    assert!(
        im.report
            .sheet
            .as_ref()
            .and_then(|s| s.not_a_sheet.as_ref())
            .is_some(),
        "no sheet without its wall: {:?}",
        im.report.sheet
    );
    let im = import(&moved("0.05"), &opts).expect("within the tolerance");
    let sheet = im.report.sheet.expect("ran");
    assert_eq!(sheet.not_a_sheet, None, "0.05 mm off is a CAD tolerance");
    assert_eq!(im.file.curves.len(), 2, "the outline and the hole");
}

#[test]
fn the_files_length_uncertainty_is_read_in_its_unit_and_given_to_face_loops() {
    // composite_inch.step states 3.937007874016e-9 inch (1e-7 mm, OCCT's default precision)
    // in inches; composite_mm.step 1e-7 mm.
    for name in ["composite_inch.step", "composite_mm.step"] {
        let im = import_file(fixture(name), &ImportOptions::default()).expect("import");
        let u = im.report.uncertainty_mm.expect("the file's uncertainty");
        assert!((u - 1e-7).abs() < 1e-12, "{name}: {u} mm");
        // Contours from geometric sets do not carry it (they were matched to faces within
        // the import's own face tolerance).
        assert!(
            im.file
                .curves
                .iter()
                .all(|c| c.on_surface_tolerance_mm.is_none()),
            "{name}"
        );
    }
    // Face loops carry the file's tolerance as their own.
    let im = import_file(
        fixture("faces.step"),
        &ImportOptions::default().with_edges(None),
    )
    .expect("import");
    let u = im.report.uncertainty_mm.expect("faces.step states one");
    assert!(!im.file.curves.is_empty());
    for c in &im.file.curves {
        assert_eq!(c.on_surface_tolerance_mm, Some(u), "{}", c.id);
    }
    // An uncertainty no context names is not the file's: none.
    let text = std::fs::read_to_string(fixture("sheet/plate.step")).expect("fixture");
    let stray = text.replacen(
        "DATA;\n",
        "DATA;\n#9001 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#9002 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.05),#9001,'','');\n",
        1,
    );
    let im = import(&stray, &ImportOptions::default().with_edges(None)).expect("import");
    assert_eq!(im.report.uncertainty_mm, None, "a stray uncertainty");
    // Named by a context, in micrometres, as a complex instance: 20 um is 0.02 mm; a second,
    // smaller one does not win; one that rounds to 0 mm is left out with a warning.
    let named = text.replacen(
        "DATA;\n",
        "DATA;\n#9001 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MICRO.,.METRE.) );\n#9002 = ( MEASURE_WITH_UNIT(LENGTH_MEASURE(20.),#9001) UNCERTAINTY_MEASURE_WITH_UNIT('distance','') );\n#9004 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(5.),#9001,'','');\n#9005 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-322),#9001,'','');\n#9003 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#9002,#9004,#9005)) REPRESENTATION_CONTEXT('','') );\n",
        1,
    );
    let im = import(&named, &ImportOptions::default().with_edges(None)).expect("import");
    let u = im.report.uncertainty_mm.expect("read");
    assert!((u - 0.02).abs() < 1e-15, "{u}");
    assert!(
        im.report
            .warnings
            .iter()
            .any(|w| w.starts_with("#9005 UNCERTAINTY_MEASURE_WITH_UNIT")),
        "{:?}",
        im.report.warnings
    );
    assert!(im
        .file
        .curves
        .iter()
        .all(|c| c.on_surface_tolerance_mm == Some(u)));
    // A file without one: none.
    let im = import_file(
        fixture("sheet/plate.step"),
        &ImportOptions::default().with_edges(None),
    )
    .expect("import");
    assert_eq!(im.report.uncertainty_mm, None);
    assert!(im
        .file
        .curves
        .iter()
        .all(|c| c.on_surface_tolerance_mm.is_none()));
}

#[test]
fn an_edge_two_chosen_faces_share_is_cut_once_with_the_first_faces_normal() {
    // The plate's top face #170 (the outline, 320 mm, and the hole) and its front wall #298
    // (100 x 2 mm, 204 mm round) share the top front edge #74 (100 mm). Chosen together, the
    // edge is cut once, with #170 (first in the file, whichever order --faces gives); the
    // wall is cut in the open piece of its other three edges, 104 mm.
    let path = fixture("sheet/plate.step");
    for order in [vec![170, 298], vec![298, 170]] {
        let im = import_file(
            path.clone(),
            &ImportOptions::default().with_edges(Some(order.clone())),
        )
        .expect("import");
        let lengths: Vec<(String, f64)> = im
            .file
            .curves
            .iter()
            .map(|c| (c.id.clone(), curve(c).arc_length()))
            .collect();
        let ids: Vec<&str> = lengths.iter().map(|(id, _)| id.as_str()).collect();
        assert_eq!(
            ids,
            ["face #170 loop 1", "face #170 loop 2", "face #298 loop 1.1"],
            "{order:?}"
        );
        assert!((lengths[0].1 - 320.0).abs() < 1e-9, "{lengths:?}");
        assert!((lengths[2].1 - 104.0).abs() < 1e-9, "{lengths:?}");
        // The wall's piece is open: its ends are the shared edge's ends, 100 mm apart.
        let wall = curve(&im.file.curves[2]);
        let (a, b) = wall.domain();
        assert!(((wall.point(a) - wall.point(b)).norm() - 100.0).abs() < 1e-9);
        assert!(
            im.report.skipped.iter().any(|s| s
                == "edge #74 of face #298 loop 1: shared with face #170, cut once, with that face's normal"),
            "{:?}",
            im.report.skipped
        );
    }
    // Alone, the wall's loop is whole.
    let im =
        import_file(path, &ImportOptions::default().with_edges(Some(vec![298]))).expect("import");
    assert_eq!(im.file.curves.len(), 1);
    assert_eq!(im.file.curves[0].id, "face #298 loop 1");
    assert!((curve(&im.file.curves[0]).arc_length() - 204.0).abs() < 1e-9);
}

#[test]
fn offset_and_rectangular_trimmed_surfaces_are_exact() {
    // fixtures/step/offsets.step (scripts/make_step_fixtures.py): one face on each exact kind
    // of OFFSET_SURFACE, and a cylinder of radius 15 along x whose RECTANGULAR_TRIMMED_SURFACE
    // reverses u, so its face's normal points at the axis.
    let imp = import_file(
        fixture("offsets.step"),
        &ImportOptions::default()
            .with_edges(None)
            .with_all_faces(true),
    )
    .expect("imports");
    let by_id = |id: &str| {
        let s = imp
            .file
            .surfaces
            .iter()
            .find(|s| matches!(s, RawSurface::Nurbs(n) if n.id == id))
            .unwrap_or_else(|| panic!("no {id}"));
        surface(s)
    };
    let a = 15f64.to_radians();
    // (face, signed distance from the basis of each grid point (positive along the basis's
    // outward normal), that normal at the point)
    type Check = Box<dyn Fn(&Point3<f64>) -> (f64, Vector3<f64>)>;
    let cases: Vec<(&str, f64, Check)> = vec![
        (
            "face #55",
            3.0,
            Box::new(|p| {
                let r = Vector3::new(p.x, p.y, 0.0);
                (r.norm() - 20.0, r.normalize())
            }),
        ),
        (
            "face #151",
            -2.0,
            Box::new(move |p| {
                let r = Vector3::new(p.x - 100.0, p.y, 0.0);
                let n = r.normalize() * a.cos() - Vector3::z() * a.sin();
                ((r.norm() - 15.0 - p.z * a.tan()) * a.cos(), n)
            }),
        ),
        (
            "face #247",
            5.0,
            Box::new(|p| {
                let r = p - Point3::new(0.0, 100.0, 0.0);
                (r.norm() - 25.0, r.normalize())
            }),
        ),
        (
            "face #345",
            4.0,
            Box::new(|p| {
                let n = Vector3::new(0.0, 1.0, 1.0).normalize();
                ((p - Point3::new(0.0, -100.0, 0.0)).dot(&n), n)
            }),
        ),
        (
            "face #439",
            -3.0,
            Box::new(|p| {
                let d = p - Point3::new(100.0, 100.0, 0.0);
                let rho = Vector3::new(d.x, d.y, 0.0);
                let c = rho.normalize() * 30.0;
                let t = d - c;
                (t.norm() - 8.0, t.normalize())
            }),
        ),
        (
            "face #537",
            0.0,
            Box::new(|p| {
                let r = Vector3::new(0.0, p.y, p.z);
                // The trimmed surface reverses u: its normal is the cylinder's turned round.
                (r.norm() - 15.0, -r.normalize())
            }),
        ),
    ];
    for (id, d, check) in &cases {
        let s = by_id(id);
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        for i in 0..=10 {
            for j in 0..=10 {
                let (u, v) = (
                    u0 + (u1 - u0) * i as f64 / 10.0,
                    v0 + (v1 - v0) * j as f64 / 10.0,
                );
                let p = s.point(u, v);
                let (dist, n) = check(&p);
                assert!(
                    (dist - d).abs() < 1e-9,
                    "{id}: {dist} mm from the basis at {p}, want {d}"
                );
                if let Some(sn) = s.normal(u, v) {
                    assert!(
                        sn.dot(&n) > 1.0 - 1e-9,
                        "{id}: normal {sn} at {p}, want {n}"
                    );
                }
            }
        }
    }
}

#[test]
fn offsets_of_b_spline_surfaces_are_approximated_within_the_bound_they_state() {
    // fixtures/step/offset_freeform.step (scripts/make_step_fixtures.py): a bicubic B-spline
    // sheet of two spans offset by +2.5 (face #47), a rational biquadratic cap by -1.5, an
    // extrusion by +1.5 and a revolution by -1.
    let imp = import_file(
        fixture("offset_freeform.step"),
        &ImportOptions::default()
            .with_edges(None)
            .with_all_faces(true),
    )
    .expect("imports");
    assert_eq!(imp.report.approximated.len(), 4, "every face approximated");
    for (id, a) in &imp.report.approximated {
        assert!(
            a.position_mm > 0.0 && a.position_mm <= kerf_step::cad::OFFSET_APPROXIMATION_MM,
            "{id}: bound {} within the reader's tolerance",
            a.position_mm
        );
    }
    // The sheet's basis, as the script builds it, and its exact offset S + 2.5 n.
    let zs = [
        [0.0, 6.0, -3.0, 2.0],
        [4.0, -2.0, 8.0, 0.0],
        [-3.0, 5.0, 1.0, 4.0],
        [2.0, -4.0, 3.0, -1.0],
        [0.0, 3.0, -2.0, 1.0],
    ];
    let basis = NurbsSurface::try_new(
        3,
        3,
        vec![0.0, 0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        (0..5)
            .map(|i| {
                (0..4)
                    .map(|j| Point3::new(200.0 + 25.0 * i as f64, 80.0 * j as f64 / 3.0, zs[i][j]))
                    .collect()
            })
            .collect(),
        None,
    )
    .expect("basis");
    let (_, bound) = imp
        .report
        .approximated
        .iter()
        .find(|(id, _)| id == "face #47")
        .expect("face #47 approximated");
    let raw = imp
        .file
        .surfaces
        .iter()
        .find(|s| matches!(s, RawSurface::Nurbs(n) if n.id == "face #47"))
        .expect("face #47");
    let a = surface(raw);
    let mut worst: f64 = 0.0;
    let mut worst_normal: f64 = 0.0;
    for i in 0..=80 {
        for j in 0..=80 {
            let (u, v) = (i as f64 / 80.0, j as f64 / 80.0);
            let (p, su, sv) = basis.eval_d1(u, v);
            let n = su.cross(&sv).normalize();
            worst = worst.max((a.point(u, v) - (p + n * 2.5)).norm());
            let an = a.normal(u, v).expect("regular");
            worst_normal = worst_normal.max(an.cross(&n).norm().atan2(an.dot(&n)));
        }
    }
    assert!(
        worst <= bound.position_mm,
        "dense distance {worst:.3e} within the stated {:.3e}",
        bound.position_mm
    );
    assert!(
        worst_normal <= bound.normal_rad,
        "normal {worst_normal:.3e} within the stated {:.3e}",
        bound.normal_rad
    );
    // The contour on the face carries the bound in its on-surface tolerance.
    let c = imp
        .file
        .curves
        .iter()
        .find(|c| matches!(&c.surface, Some(SurfaceRef::One(f)) if f == "face #47"))
        .expect("the sheet's boundary");
    assert!(
        c.on_surface_tolerance_mm
            .is_some_and(|t| t >= bound.position_mm),
        "on-surface tolerance {:?} covers the bound {}",
        c.on_surface_tolerance_mm,
        bound.position_mm
    );
}

#[test]
fn an_assembly_places_each_instance_of_its_parts() {
    // fixtures/step/assembly.step (Open CASCADE's assembly structure): a box placed where it
    // is and again turned 0.5 rad about z and moved by (100, 20, 3); a cylinder of radius 5 and
    // height 8 moved by (-50, 0, 0) inside a sub-assembly moved by (0, -60, 0).
    let imp = import_file(
        fixture("assembly.step"),
        &ImportOptions::default()
            .with_edges(None)
            .with_all_faces(true),
    )
    .expect("imports");
    let by_id = |id: &str| {
        curve(
            imp.file
                .curves
                .iter()
                .find(|c| c.id == id)
                .unwrap_or_else(|| panic!("no {id}")),
        )
    };
    let (s, c) = 0.5f64.sin_cos();
    let place = |p: &Point3<f64>| {
        Point3::new(
            c * p.x - s * p.y + 100.0,
            s * p.x + c * p.y + 20.0,
            p.z + 3.0,
        )
    };
    let mut pairs = 0;
    for k in [43, 163, 263, 310, 357, 364] {
        let a = by_id(&format!("face #{k}@1 loop 1"));
        let b = by_id(&format!("face #{k}@2 loop 1"));
        for (p, q) in samples(&a, 40).iter().zip(samples(&b, 40)) {
            assert!(
                (place(p) - q).norm() < 1e-9,
                "face #{k}: {p} placed is not {q}"
            );
            assert!(
                (-1e-9..=40.0 + 1e-9).contains(&p.x) && (-1e-9..=5.0 + 1e-9).contains(&p.z),
                "the first box where its coordinates put it: {p}"
            );
        }
        pairs += 1;
    }
    assert_eq!(pairs, 6, "every face of the box twice");
    // The cylinder, placed once through two levels: its faces keep their plain ids.
    let mut cylinder = 0;
    for cv in imp.file.curves.iter().filter(|c| !c.id.contains('@')) {
        for p in samples(&curve(cv), 40) {
            let r = ((p.x + 50.0).powi(2) + (p.y + 60.0).powi(2)).sqrt();
            assert!(
                r < 5.0 + 1e-9 && (-1e-9..=8.0 + 1e-9).contains(&p.z),
                "{}: {p}",
                cv.id
            );
        }
        cylinder += 1;
    }
    assert_eq!(cylinder, 3, "the cylinder's two caps and side");
    assert_eq!(imp.file.surfaces.len(), 15);
}
