//! The IGES reader on the shipped fixtures (written by Open CASCADE,
//! `scripts/make_iges_fixtures.py`) and on hand-written files, against independent truth: the
//! geometry the fixture script put in (exact circles, an ellipse, a cylinder), the mm file for
//! the inch file, the STEP reader on the STEP file the IGES was written from (itself checked
//! against Open CASCADE), and the conics' own equations. The full comparison with Open
//! CASCADE's IGES reader is `scripts/step_check.py` (CI).

use std::path::{Path, PathBuf};

use kerf_format::curves::{from_raw, RawCurve, RawCurvesFile, RawSurface, SurfaceRef};
use kerf_iges::{import, import_file, IgesError, ImportOptions};
use kerf_nurbs::{NurbsCurve, NurbsSurface};
use nalgebra::{Point3, Vector3};

fn fixture(dir: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(dir)
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

fn samples(c: &NurbsCurve, n: usize) -> Vec<Point3<f64>> {
    let (a, b) = c.domain();
    (0..=n)
        .map(|k| c.point(a + (b - a) * k as f64 / n as f64))
        .collect()
}

fn by_id<'a>(f: &'a RawCurvesFile, id: &str) -> &'a RawCurve {
    f.curves
        .iter()
        .find(|c| c.id == id)
        .unwrap_or_else(|| panic!("no curve {id}"))
}

fn surface_of<'a>(f: &'a RawCurvesFile, c: &RawCurve) -> &'a RawSurface {
    let Some(SurfaceRef::One(id)) = &c.surface else {
        panic!("{} names no single surface: {:?}", c.id, c.surface)
    };
    f.surfaces
        .iter()
        .find(|s| matches!(s, RawSurface::Nurbs(n) if &n.id == id))
        .expect("the named surface is written")
}

#[test]
fn free_curves_are_the_exact_geometry_on_their_faces() {
    let imp = import_file(
        fixture("iges", "curves.igs"),
        &ImportOptions::default().with_all_faces(true),
    )
    .expect("imports");
    let f = &imp.file;
    assert_eq!(f.curves.len(), 6, "six free curves: {:?}", imp.report.taken);
    assert_eq!(f.surfaces.len(), 2, "the plate and the tube");
    assert_eq!(imp.report.units.length_name, "mm");
    // Every contour passes the format's own checks.
    from_raw(f.clone(), Path::new(".")).expect("valid kerf.curves/1");

    // The circle of radius 5 about (20, 20, 0), on the plate, whose normal is +z.
    let circle = by_id(f, "D69");
    let c = curve(circle);
    for p in samples(&c, 400) {
        let r = (p - Point3::new(20.0, 20.0, 0.0)).norm();
        assert!((r - 5.0).abs() < 1e-9, "circle point at radius {r}");
    }
    assert!(c.is_closed(), "a full circle");
    let plate = surface(surface_of(f, circle));
    let pr = plate.closest_point(&Point3::new(20.0, 15.0, 0.0), None);
    let n = plate.normal(pr.u, pr.v).expect("a normal");
    assert!((n - Vector3::z()).norm() < 1e-12, "plate normal {n}");

    // The ellipse arc (12 by 6 about (60, 20, 0)) over three quarters of a turn.
    let e = curve(by_id(f, "D73"));
    for p in samples(&e, 400) {
        let q = ((p.x - 60.0) / 12.0).powi(2) + ((p.y - 20.0) / 6.0).powi(2);
        assert!((q - 1.0).abs() < 1e-9, "ellipse equation {q}");
    }
    let (a, b) = e.domain();
    assert!(
        (e.point(a) - Point3::new(72.0, 20.0, 0.0)).norm() < 1e-9,
        "starts at angle 0"
    );
    assert!(
        (e.point(b) - Point3::new(60.0, 14.0, 0.0)).norm() < 1e-9,
        "ends at 270 degrees"
    );

    // The rounded rectangle: three lines and a quarter circle of radius 10, closed.
    let rr = curve(by_id(f, "D55"));
    let expected = 30.0 + 20.0 + 40.0 + 30.0 + 5.0 * std::f64::consts::PI;
    assert!(
        (rr.arc_length() - expected).abs() < 1e-6,
        "length {}",
        rr.arc_length()
    );
    assert!(rr.is_closed(), "closed wire");

    // The ring round the tube at y = 40, on the tube, whose normal points away from its axis.
    let ring = by_id(f, "D79");
    let rc = curve(ring);
    let tube = surface(surface_of(f, ring));
    for p in samples(&rc, 100) {
        let r = Vector3::new(p.x - 160.0, 0.0, p.z);
        assert!(
            (r.norm() - 20.0).abs() < 1e-9 && (p.y - 40.0).abs() < 1e-9,
            "ring point {p}"
        );
        let pr = tube.closest_point(&p, None);
        assert!(pr.distance < 1e-9, "on the tube: {}", pr.distance);
        let n = tube.normal(pr.u, pr.v).expect("a normal");
        assert!(
            n.dot(&(r / r.norm())) > 1.0 - 1e-9,
            "outward tube normal {n} at {p}"
        );
    }

    // The 3D spline lies on no face: cut without a surface, said in the report.
    assert!(by_id(f, "D83").surface.is_none());
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.starts_with("D83: on no face")),
        "{:?}",
        imp.report.skipped
    );
}

#[test]
fn an_inch_file_is_the_mm_file() {
    let opts = ImportOptions::default().with_all_faces(true);
    let mm = import_file(fixture("iges", "curves.igs"), &opts).expect("mm");
    let inch = import_file(fixture("iges", "curves_inch.igs"), &opts).expect("inch");
    assert_eq!(inch.report.units.length_name, "inch");
    assert_eq!(inch.report.units.mm_per_length, 25.4);
    assert_eq!(mm.file.curves.len(), inch.file.curves.len());
    for (a, b) in mm.file.curves.iter().zip(&inch.file.curves) {
        assert_eq!(a.id, b.id);
        let (ca, cb) = (curve(a), curve(b));
        for (p, q) in samples(&ca, 50).iter().zip(samples(&cb, 50)) {
            assert!((p - q).norm() < 1e-7, "{}: {p} vs {q}", a.id);
        }
    }
}

/// IGES defines 80-character records, not lines: the same file with its records run together
/// (no line breaks, as some systems write it) or with CR LF line ends reads to the same
/// document; a run-together file whose length is not a whole number of records is refused as
/// such, and errors name a run-together record by its number.
#[test]
fn records_without_line_breaks_or_with_crlf_read_the_same() {
    let text = std::fs::read_to_string(fixture("iges", "faces.igs")).expect("fixture");
    let opts = ImportOptions::default().with_edges(None);
    let want = import(text.as_bytes(), &opts).expect("lines").file;
    let packed: String = text.lines().collect();
    assert!(!packed.contains('\n') && packed.len() % 80 == 0);
    assert_eq!(import(packed.as_bytes(), &opts).expect("packed").file, want);
    let crlf = text.replace('\n', "\r\n");
    assert_eq!(import(crlf.as_bytes(), &opts).expect("crlf").file, want);
    let cut = &packed[..packed.len() - 3];
    let e = import(cut.as_bytes(), &opts)
        .expect_err("cut short")
        .to_string();
    assert!(
        e.contains("line 1: records run together") && e.contains("not a whole number"),
        "a run-together file cut short is refused as such: {e}"
    );
    // Errors name the record: spoil the entity type on the second line of directory entry 3
    // (counted from the file's first record, as its line would be).
    let lines: Vec<&str> = text.lines().collect();
    let d_first = lines
        .iter()
        .position(|l| &l[72..73] == "D")
        .expect("D section");
    let at = d_first + 3;
    let mut spoiled: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    spoiled[at].replace_range(0..8, "    9999");
    let e = import(spoiled.concat().as_bytes(), &opts)
        .expect_err("spoiled")
        .to_string();
    assert!(
        e.contains(&format!("line {}:", at + 1)),
        "the record's number: {e}"
    );
}

#[test]
fn every_face_matches_the_step_file_it_was_written_from() {
    let opts = ImportOptions::default()
        .with_edges(None)
        .with_all_faces(true);
    let iges = import_file(fixture("iges", "faces.igs"), &opts).expect("iges");
    let step = kerf_step::import_file(
        fixture("step", "faces.step"),
        &opts.clone().with_sheet(false),
    )
    .expect("step");
    assert!(
        iges.report
            .skipped
            .iter()
            .all(|s| s.contains("not geometry kerf cuts")),
        "no face skipped: {:?}",
        iges.report.skipped
    );
    assert_eq!(
        iges.report.faces_read, step.report.faces_read,
        "one face per STEP face"
    );
    let step_surfaces: Vec<NurbsSurface> = step.file.surfaces.iter().map(surface).collect();
    assert_eq!(iges.file.surfaces.len(), step_surfaces.len());
    for (raw, line) in iges.file.surfaces.iter().zip(&iges.report.surfaces) {
        let s = surface(raw);
        // Interior points of the IGES surface, and the STEP surface they all lie on.
        let (u0, u1) = s.domain_u();
        let (v0, v1) = s.domain_v();
        let pts: Vec<(f64, f64)> = [0.25, 0.5, 0.75]
            .iter()
            .flat_map(|&a| [0.25, 0.5, 0.75].map(|b| (u0 + a * (u1 - u0), v0 + b * (v1 - v0))))
            .collect();
        let worst = |t: &NurbsSurface| {
            pts.iter()
                .map(|&(u, v)| t.closest_point(&s.point(u, v), None).distance)
                .fold(0.0, f64::max)
        };
        let (d, t) = step_surfaces
            .iter()
            .map(|t| (worst(t), t))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .expect("faces");
        assert!(d < 1e-6, "{line}: {d} mm from every STEP face");
        for &(u, v) in &pts {
            let p = s.point(u, v);
            let q = t.closest_point(&p, None);
            let (Some(ni), Some(ns)) = (s.normal(u, v), t.normal(q.u, q.v)) else {
                continue; // a pole
            };
            assert!(
                ni.dot(&ns) > 1.0 - 1e-6,
                "{line}: normal {ni} against the STEP face's {ns} at {p}"
            );
        }
    }
    // Every kind of surface the reader converts is among them.
    for kind in ["plane", "revolution", "extrusion", "b-spline"] {
        assert!(
            iges.report
                .surfaces
                .iter()
                .any(|l| l.contains(&format!("({kind}"))),
            "{kind}: {:?}",
            iges.report.surfaces
        );
    }
    // Each face loop lies on its face.
    for c in &iges.file.curves {
        let s = surface(surface_of(&iges.file, c));
        for p in samples(&curve(c), 40) {
            let d = s.closest_point(&p, None).distance;
            assert!(d < 1e-6, "{}: {d} mm off its face", c.id);
        }
    }
}

/// A hand-written IGES file: `(type, form, matrix DE, status, label, parameters)` per entity,
/// in directory order (entity k is DE 2k+1), millimetres unless `unit` says otherwise.
fn iges_text(unit: &str, entities: &[(i64, i64, i64, &str, &str, &str)]) -> String {
    let mut d = Vec::new();
    let mut p = Vec::new();
    for (k, (ty, form, matrix, status, label, params)) in entities.iter().enumerate() {
        let de = 2 * k + 1;
        let start = p.len() + 1;
        let text = format!("{ty},{params};");
        let chunks: Vec<String> = text
            .as_bytes()
            .chunks(64)
            .map(|c| String::from_utf8_lossy(c).into_owned())
            .collect();
        for c in &chunks {
            p.push(format!("{c:64}{de:>8}P{:>7}", p.len() + 1));
        }
        d.push(format!(
            "{ty:>8}{start:>8}{:>8}{:>8}{:>8}{:>8}{matrix:>8}{:>8}{status:>8}D{:>7}",
            0,
            0,
            0,
            0,
            0,
            d.len() + 1
        ));
        d.push(format!(
            "{ty:>8}{:>8}{:>8}{:>8}{form:>8}{:>8}{:>8}{label:>8}{:>8}D{:>7}",
            0,
            0,
            chunks.len(),
            "",
            "",
            0,
            d.len() + 1
        ));
        let _ = de;
    }
    let g = format!("1H,,1H;,,,,,,,,,,,1.,{unit},,,,,,,,,11,0;");
    let mut out = vec![format!("{:72}S{:>7}", "kerf test", 1)];
    for (i, c) in g.as_bytes().chunks(72).enumerate() {
        out.push(format!("{:72}G{:>7}", String::from_utf8_lossy(c), i + 1));
    }
    out.extend(d);
    out.extend(p);
    out.push(format!("{:72}T{:>7}", "", 1));
    out.join("\n") + "\n"
}

fn read(
    unit: &str,
    entities: &[(i64, i64, i64, &str, &str, &str)],
) -> Result<kerf_iges::Import, IgesError> {
    import(
        iges_text(unit, entities).as_bytes(),
        &ImportOptions::default(),
    )
}

const FREE: &str = "00000000";

#[test]
fn copious_data_transforms_and_composites() {
    // 1: a polyline (106 form 12); 3: a line moved by matrix 5, itself moved by matrix 7;
    // 5: translate by (10, 0, 0); 7: rotate 90 degrees about z; 9: a composite of two lines
    // (11, 13) with a 0.05 mm gap, which is closed.
    let imp = read(
        "2",
        &[
            (106, 12, 0, FREE, "POLY", "2,3,0.,0.,0.,10.,0.,0.,10.,5.,0."),
            (110, 0, 5, FREE, "", "0.,0.,0.,1.,0.,0."),
            (
                124,
                0,
                7,
                "00010000",
                "",
                "1.,0.,0.,10.,0.,1.,0.,0.,0.,0.,1.,0.",
            ),
            (
                124,
                0,
                0,
                "00010000",
                "",
                "0.,-1.,0.,0.,1.,0.,0.,0.,0.,0.,1.,0.",
            ),
            (102, 0, 0, FREE, "C", "2,11,13"),
            (110, 0, 0, "00010000", "", "0.,0.,0.,5.,0.,0."),
            (110, 0, 0, "00010000", "", "5.05,0.,0.,5.05,5.,0."),
        ],
    )
    .expect("imports");
    let f = &imp.file;
    assert_eq!(
        f.curves.len(),
        3,
        "{:?} {:?}",
        imp.report.taken,
        imp.report.skipped
    );
    let poly = by_id(f, "POLY D1");
    assert_eq!(
        poly.control_points,
        vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 5.0, 0.0]]
    );
    // The line (0,0,0)-(1,0,0), translated to x = 10..11, then turned: (0, 10)..(0, 11).
    let line = curve(by_id(f, "D3"));
    let (a, b) = line.domain();
    assert!((line.point(a) - Point3::new(0.0, 10.0, 0.0)).norm() < 1e-12);
    assert!((line.point(b) - Point3::new(0.0, 11.0, 0.0)).norm() < 1e-12);
    // The composite: one open contour, its 0.05 mm gap closed.
    let comp = curve(by_id(f, "C D9"));
    assert!(
        (comp.arc_length() - 10.0).abs() < 0.06,
        "{}",
        comp.arc_length()
    );
    assert_eq!(imp.report.gaps_closed, 1);
}

#[test]
fn an_ellipse_in_general_position_lies_on_its_conic() {
    // x'^2/16 + y'^2/4 = 1 turned by 30 degrees about (3, -2): A x^2 + B xy + C y^2 + D x + E y
    // + F = 0 with the coefficients worked out below; from the point at parameter 0 round to
    // the point at 90 degrees (a quarter).
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let (a2, b2) = (16.0, 4.0);
    let a = c * c / a2 + s * s / b2;
    let b = 2.0 * c * s * (1.0 / a2 - 1.0 / b2);
    let cc = s * s / a2 + c * c / b2;
    let (x0, y0) = (3.0, -2.0);
    let d = -2.0 * a * x0 - b * y0;
    let e = -2.0 * cc * y0 - b * x0;
    let f = a * x0 * x0 + b * x0 * y0 + cc * y0 * y0 - 1.0;
    let p0 = (x0 + 4.0 * c, y0 + 4.0 * s);
    let p1 = (x0 - 2.0 * s, y0 + 2.0 * c);
    let params = format!(
        "{a:e},{b:e},{cc:e},{d:e},{e:e},{f:e},1.5,{:e},{:e},{:e},{:e}",
        p0.0, p0.1, p1.0, p1.1
    );
    let imp = read("2", &[(104, 1, 0, FREE, "ELL", &params)]).expect("imports");
    let el = curve(by_id(&imp.file, "ELL D1"));
    for p in samples(&el, 200) {
        let q = a * p.x * p.x + b * p.x * p.y + cc * p.y * p.y + d * p.x + e * p.y + f;
        assert!(q.abs() < 1e-12, "conic residual {q} at {p}");
        assert!((p.z - 1.5).abs() < 1e-12);
    }
    // A quarter of an ellipse of semi-axes 4 and 2: length 4.844224110 (elliptic integral).
    assert!(
        (el.arc_length() - 4.844224110273838).abs() < 1e-6,
        "{}",
        el.arc_length()
    );
    // A hyperbola arc (x^2 - y^2 = 1 from (1, 0) to (cosh 1.3, sinh 1.3)) and a parabola arc
    // (x^2 = 4 y from (-2, 1) to (4, 4)), each one exact rational quadratic.
    let (ch, sh) = (1.3f64.cosh(), 1.3f64.sinh());
    let hyp = format!("1.,0.,-1.,0.,0.,-1.,0.,1.,0.,{ch:e},{sh:e}");
    let imp = read(
        "2",
        &[
            (104, 2, 0, FREE, "HYP", &hyp),
            (104, 3, 0, FREE, "PAR", "1.,0.,0.,0.,-4.,0.,0.,-2.,1.,4.,4."),
            (104, 3, 0, FREE, "OFF", "1.,0.,0.,0.,-4.,0.,0.,-2.,1.,4.,5."),
        ],
    )
    .expect("imports");
    let h = curve(by_id(&imp.file, "HYP D1"));
    for p in samples(&h, 200) {
        assert!(
            (p.x * p.x - p.y * p.y - 1.0).abs() < 1e-12,
            "hyperbola at {p}"
        );
        assert!(
            p.x > 0.0 && p.y > -1e-12,
            "the right branch's upper arc: {p}"
        );
    }
    let (t0, t1) = h.domain();
    assert!((h.point(t0) - Point3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    assert!((h.point(t1) - Point3::new(ch, sh, 0.0)).norm() < 1e-12);
    let par = curve(by_id(&imp.file, "PAR D3"));
    for p in samples(&par, 200) {
        assert!((p.x * p.x - 4.0 * p.y).abs() < 1e-12, "parabola at {p}");
    }
    // An end point off its conic is refused by name.
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.contains("D5 (104 conic arc)") && s.contains("end point (4, 5)")),
        "{:?}",
        imp.report.skipped
    );
}

#[test]
fn a_bspline_is_cut_to_its_parameter_range_and_units_apply() {
    // A straight cubic from (0,0,0) to (3,0,0) over [0, 1], read over [0.25, 0.75], in cm.
    let params = "3,3,1,0,1,0,0.,0.,0.,0.,1.,1.,1.,1.,1.,1.,1.,1.,0.,0.,0.,1.,0.,0.,2.,0.,0.,3.,0.,0.,0.25,0.75,0.,0.,1.";
    let imp = read("10", &[(126, 0, 0, FREE, "S", params)]).expect("imports");
    let c = curve(by_id(&imp.file, "S D1"));
    let (a, b) = c.domain();
    assert!(
        (c.point(a) - Point3::new(7.5, 0.0, 0.0)).norm() < 1e-12,
        "{}",
        c.point(a)
    );
    assert!(
        (c.point(b) - Point3::new(22.5, 0.0, 0.0)).norm() < 1e-12,
        "{}",
        c.point(b)
    );
    assert_eq!(imp.report.units.length_name, "cm");
}

#[test]
fn bad_files_are_refused_by_place() {
    let line = [(110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,0.")];
    let good = iges_text("2", &line);
    // A line cut short of column 73.
    let mut lines: Vec<&str> = good.lines().collect();
    let short = &lines[2][..60];
    lines[2] = short;
    let e = import(lines.join("\n").as_bytes(), &ImportOptions::default()).expect_err("short");
    assert!(e.to_string().starts_with("line 3: an IGES record"), "{e}");
    // A string longer than its entity.
    let e = read("2", &[(110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,99Hab")]).expect_err("hollerith");
    assert!(e.to_string().contains("runs past the end"), "{e}");
    // A composite that points at an entity not in the file: the composite is skipped by name.
    let e = read("2", &[(102, 0, 0, FREE, "", "1,99")]).expect_err("dangling");
    assert!(e.to_string().contains("no usable contour"), "{e}");
    let imp = read(
        "2",
        &[
            (102, 0, 0, FREE, "", "1,99"),
            (110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,0."),
        ],
    )
    .expect("the line");
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.contains("D1 (102 composite curve)")
                && s.contains("directory entry 99, which is not in the file")),
        "{:?}",
        imp.report.skipped
    );
    // A matrix that is its own matrix: a cycle, refused, not followed for ever.
    let imp = read(
        "2",
        &[
            (110, 0, 3, FREE, "", "0.,0.,0.,1.,0.,0."),
            (
                124,
                0,
                3,
                "00010000",
                "",
                "1.,0.,0.,0.,0.,1.,0.,0.,0.,0.,1.,0.",
            ),
            (110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,0."),
        ],
    )
    .expect("the good line");
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.contains("chain more than 32 deep")),
        "{:?}",
        imp.report.skipped
    );
    // A count larger than the entity: refused by name before anything is allocated for it.
    let imp = read(
        "2",
        &[
            (102, 0, 0, FREE, "", "1000000000,99"),
            (110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,0."),
        ],
    )
    .expect("the line");
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.contains("number of segments") && s.contains("1000000000")),
        "{:?}",
        imp.report.skipped
    );
    // An unknown unit.
    let e = read("3", &line).expect_err("unit");
    assert!(
        e.to_string().contains("unit flag 3 without a unit name"),
        "{e}"
    );
    let e = read("12", &line).expect_err("unit");
    assert!(e.to_string().contains("unit flag 12"), "{e}");
    // A STEP file given as IGES.
    let e = import(b"ISO-10303-21;\nHEADER;\n", &ImportOptions::default()).expect_err("step");
    assert!(e.to_string().starts_with("line 1:"), "{e}");
}

#[test]
fn no_prefix_or_byte_flip_of_a_real_file_panics() {
    let bytes = std::fs::read(fixture("iges", "curves.igs")).expect("fixture");
    let opts = ImportOptions::default().with_all_faces(true);
    let mut refused = 0;
    for cut in (0..bytes.len()).step_by(97) {
        if import(&bytes[..cut], &opts).is_err() {
            refused += 1;
        }
    }
    assert!(refused > 0, "truncated files are refused");
    // Every printable byte position flipped to a digit, a delimiter or a letter in turn.
    for (k, at) in (0..bytes.len()).step_by(13).enumerate() {
        let mut b = bytes.clone();
        b[at] = [b'9', b',', b';', b'H', b'-', b'.'][k % 6];
        let _ = import(&b, &opts);
        let _ = import(&b, &opts.clone().with_edges(None));
    }
}

#[test]
fn a_sheet_metal_solid_is_cut_once_per_feature() {
    // The plate 100 x 60 x 2 with a hole of radius 8 and a 30 x 20 cut-out (Open CASCADE's
    // Boolean cuts): IGES faces share no edges, so the reader sews them (ends and interior
    // points within the file's resolution) before it recognises the sheet.
    let opts = ImportOptions::default().with_edges(None);
    let imp = import_file(fixture("iges", "sheet.igs"), &opts).expect("imports");
    let sheet = imp.report.sheet.as_ref().expect("sheet recognition ran");
    assert!(sheet.not_a_sheet.is_none(), "{:?}", sheet.not_a_sheet);
    assert!(
        (sheet.thickness_mm - 2.0).abs() < 1e-9,
        "{}",
        sheet.thickness_mm
    );
    assert_eq!(
        (sheet.side.len(), sheet.other_side.len(), sheet.walls.len()),
        (1, 1, 9)
    );
    assert_eq!(sheet.id_prefix, "D");
    let mut lengths: Vec<f64> = imp
        .file
        .curves
        .iter()
        .map(|c| curve(c).arc_length())
        .collect();
    lengths.sort_by(f64::total_cmp);
    let want = [16.0 * std::f64::consts::PI, 100.0, 320.0];
    assert_eq!(
        lengths.len(),
        3,
        "each feature once: {:?}",
        imp.report.taken
    );
    for (l, w) in lengths.iter().zip(want) {
        assert!((l - w).abs() < 1e-6, "feature of {l} mm, want {w}");
    }
    // Every feature on the cut side, at one height (z = 0 or z = 2 throughout).
    for c in &imp.file.curves {
        let z: Vec<f64> = samples(&curve(c), 50).iter().map(|p| p.z).collect();
        assert!(
            z.iter()
                .all(|&v| (v - z[0]).abs() < 1e-9 && (v.abs() < 1e-9 || (v - 2.0).abs() < 1e-9)),
            "{}: {z:?}",
            c.id
        );
    }
    // Every face loop on request: both sides' three loops and the walls'.
    let all = import_file(
        fixture("iges", "sheet.igs"),
        &opts.clone().with_sheet(false),
    )
    .expect("all");
    assert_eq!(all.file.curves.len(), 15, "{:?}", all.report.taken);
}

#[test]
fn an_edge_two_chosen_faces_share_is_cut_once() {
    // The top face D35 (the outline, the hole, the cut-out) and the wall D19 beside its
    // outline: sewn, they share one edge, cut with the first face in the file (the wall, whole);
    // the top's outline is cut in the open piece that is left (three of its four sides).
    let opts = ImportOptions::default().with_edges(Some(vec![35, 19]));
    let imp = import_file(fixture("iges", "sheet.igs"), &opts).expect("imports");
    let ids: Vec<&str> = imp.file.curves.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids.len(), 4, "{ids:?}");
    let wall = curve(by_id(&imp.file, "face D19 loop 1"));
    assert!(wall.is_closed(), "the wall, cut whole");
    let outline = curve(by_id(&imp.file, "face D35 loop 1.1"));
    assert!(
        !outline.is_closed(),
        "the outline less the shared edge is open"
    );
    let shared = 320.0 - outline.arc_length();
    assert!(
        (shared - 100.0).abs() < 1e-6 || (shared - 60.0).abs() < 1e-6,
        "one side of the plate left out: {shared} mm"
    );
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.contains("of face D35 loop 1: shared with face D19")),
        "{:?}",
        imp.report.skipped
    );
}

#[test]
fn a_trimmed_surfaces_matrix_moves_it_and_its_boundary() {
    // A 10 x 10 square patch (128) trimmed by four lines (142 over a 102), the 144 moved by
    // +100 in x by its own matrix: the face and its loop are cut at x = 100..110.
    let dep = "00010000";
    let patch = "1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,10.,0.,0.,0.,10.,0.,10.,10.,0.,0.,1.,0.,1.";
    let imp = import(
        iges_text(
            "2",
            &[
                (128, 0, 0, dep, "", patch),
                (110, 0, 0, dep, "", "0.,0.,0.,10.,0.,0."),
                (110, 0, 0, dep, "", "10.,0.,0.,10.,10.,0."),
                (110, 0, 0, dep, "", "10.,10.,0.,0.,10.,0."),
                (110, 0, 0, dep, "", "0.,10.,0.,0.,0.,0."),
                (102, 0, 0, dep, "", "4,3,5,7,9"),
                (142, 0, 0, dep, "", "0,1,0,11,2"),
                (144, 0, 17, FREE, "", "1,1,0,13"),
                (124, 0, 0, dep, "", "1.,0.,0.,100.,0.,1.,0.,0.,0.,0.,1.,0."),
            ],
        )
        .as_bytes(),
        &ImportOptions::default().with_edges(None),
    )
    .expect("imports");
    let c = curve(by_id(&imp.file, "face D15 loop 1"));
    for p in samples(&c, 40) {
        assert!(
            (100.0 - 1e-12..=110.0 + 1e-12).contains(&p.x),
            "loop point {p}"
        );
    }
    let s = surface(surface_of(&imp.file, by_id(&imp.file, "face D15 loop 1")));
    let (lo, hi) = s.bounding_box();
    assert!(
        (lo.x - 100.0).abs() < 1e-12 && (hi.x - 110.0).abs() < 1e-12,
        "{lo} {hi}"
    );
}

/// A 142 that prefers its parameter-space curve (PREF 1, as SolidWorks and CATIA write it)
/// over a model-space copy a little inside it: the face's surface reaches both. A 100 x 100 mm
/// patch over [0, 1]^2 trimmed by the square 10..50 mm; the parameter-space square reaches
/// u = 0.5005 (50.05 mm). One 3 mm out does not map onto the model-space curve: not used.
#[test]
fn the_preferred_parameter_space_boundary_widens_the_face() {
    let x_range = |u_max: &str| {
        let dep = "00010000";
        let patch = "1,1,1,1,0,0,1,0,0,0.,0.,1.,1.,0.,0.,1.,1.,1.,1.,1.,1.,0.,0.,0.,100.,0.,0.,0.,100.,0.,100.,100.,0.,0.,1.,0.,1.";
        let b = [
            format!("0.1,0.1,0.,{u_max},0.1,0."),
            format!("{u_max},0.1,0.,{u_max},0.5,0."),
            format!("{u_max},0.5,0.,0.1,0.5,0."),
            "0.1,0.5,0.,0.1,0.1,0.".to_string(),
        ];
        let imp = import(
            iges_text(
                "2",
                &[
                    (128, 0, 0, dep, "", patch),
                    (110, 0, 0, dep, "", "10.,10.,0.,50.,10.,0."),
                    (110, 0, 0, dep, "", "50.,10.,0.,50.,50.,0."),
                    (110, 0, 0, dep, "", "50.,50.,0.,10.,50.,0."),
                    (110, 0, 0, dep, "", "10.,50.,0.,10.,10.,0."),
                    (102, 0, 0, dep, "", "4,3,5,7,9"),
                    (110, 0, 0, dep, "", &b[0]),
                    (110, 0, 0, dep, "", &b[1]),
                    (110, 0, 0, dep, "", &b[2]),
                    (110, 0, 0, dep, "", &b[3]),
                    (102, 0, 0, dep, "", "4,13,15,17,19"),
                    (142, 0, 0, dep, "", "0,1,21,11,1"),
                    (144, 0, 0, FREE, "", "1,1,0,23"),
                ],
            )
            .as_bytes(),
            &ImportOptions::default().with_edges(None),
        )
        .expect("imports");
        let c = by_id(&imp.file, "face D25 loop 1");
        for p in samples(&curve(c), 40) {
            assert!(
                (10.0 - 1e-12..=50.0 + 1e-12).contains(&p.x),
                "the cut is the model-space curve: {p}"
            );
        }
        let (lo, hi) = surface(surface_of(&imp.file, c)).bounding_box();
        (lo.x, hi.x)
    };
    let (lo, hi) = x_range("0.5005");
    assert!(
        (lo - 10.0).abs() < 1e-9 && (hi - 50.05).abs() < 1e-9,
        "widened: {lo} .. {hi}"
    );
    let (lo, hi) = x_range("0.53");
    assert!(
        (lo - 10.0).abs() < 1e-9 && (hi - 50.0).abs() < 1e-9,
        "a boundary 3 mm off is not used: {lo} .. {hi}"
    );
}

#[test]
fn trailing_pointers_strings_and_huge_matrices() {
    // A composite whose parameters end with one property pointer (to the 406 at D5): the free
    // line D1 is not taken for one of its segments. The 406's string holds the record
    // delimiter and runs over two parameter lines.
    let long = format!("1,70H{};{}", "a".repeat(30), "b".repeat(39));
    let imp = read(
        "2",
        &[
            (110, 0, 0, FREE, "LINE", "0.,0.,0.,1.,0.,0."),
            (102, 0, 0, FREE, "COMP", "2,7,9,0,1,5"),
            (406, 15, 0, FREE, "", &long),
            (110, 0, 0, "00010000", "", "5.,0.,0.,6.,0.,0."),
            (110, 0, 0, "00010000", "", "6.,0.,0.,6.,1.,0."),
        ],
    )
    .expect("imports");
    let ids: Vec<&str> = imp.file.curves.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids, vec!["LINE D1", "COMP D3"], "{:?}", imp.report.skipped);
    // A matrix that moves a line out of range: refused by name, not left where it was.
    let imp = read(
        "2",
        &[
            (110, 0, 3, FREE, "", "0.,0.,0.,1.E10,0.,0."),
            (
                124,
                0,
                0,
                "00010000",
                "",
                "1.E300,0.,0.,0.,0.,1.E300,0.,0.,0.,0.,1.E300,0.",
            ),
            (110, 0, 0, FREE, "", "0.,0.,0.,1.,0.,0."),
        ],
    )
    .expect("the good line");
    assert_eq!(imp.file.curves.len(), 1);
    assert!(
        imp.report
            .skipped
            .iter()
            .any(|s| s.starts_with("D1 (110 line)") && s.contains("moved by its matrices")),
        "{:?}",
        imp.report.skipped
    );
}
