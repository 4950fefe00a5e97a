//! The shipped fixtures (`fixtures/`): the valid ones load and mean what `fixtures/README.md`
//! says; each broken one fails with its documented message.

use std::path::{Path, PathBuf};

use kerf_format::{curves, FormatError, SurfaceGeometry, SurfaceSource};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

#[test]
fn circle_is_an_exact_closed_circle_of_radius_50() {
    let file = curves::load(fixture("circle.json")).expect("valid");
    let c = &file.curves[0].curve;
    assert_eq!((c.degree(), c.len()), (2, 9), "rational quadratic, 4 spans");
    assert!(c.is_rational() && c.is_closed(), "rational and closed");
    for i in 0..=100 {
        let p = c.point(f64::from(i) / 100.0);
        assert!(
            (p.coords.norm() - 50.0).abs() < 1e-12,
            "on the circle at {i}"
        );
    }
    let length = c.arc_length();
    assert!(
        (length - 100.0 * std::f64::consts::PI).abs() < 1e-6,
        "circumference {length}"
    );
    // Interior knots of multiplicity = degree count as possible C0 breaks (the discretizer puts
    // a cutting point on each), although this circle is geometrically smooth there.
    assert_eq!(
        c.c0_breaks(),
        [0.25, 0.5, 0.75],
        "double knots of a quadratic"
    );
}

#[test]
fn quarter_arc_is_a_quarter_of_the_circle() {
    let file = curves::load(fixture("quarter_arc.json")).expect("valid");
    let c = &file.curves[0].curve;
    let length = c.arc_length();
    assert!(
        (length - 25.0 * std::f64::consts::PI).abs() < 1e-6,
        "quarter circumference {length}"
    );
    assert!(!c.is_closed(), "open");
}

#[test]
fn mixed_has_a_corner_a_line_a_quintic_and_a_carried_curve() {
    let file = curves::load(fixture("mixed.json")).expect("valid");
    let ids: Vec<&str> = file.curves.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(
        ids,
        ["v-corner", "straight", "freeform-quintic", "slot-on-plane"],
        "curves in order"
    );
    assert_eq!(file.curves[0].curve.c0_breaks(), [0.5], "the corner");
    assert_eq!(file.curves[1].curve.degree(), 1, "line");
    assert_eq!(file.curves[2].curve.degree(), 5, "quintic");
    assert!(file.curves[2].curve.is_rational(), "quintic is rational");
    let carrier = file.surface_of(&file.curves[3]).expect("carried");
    let SurfaceGeometry::Nurbs(plane) = &carrier.geometry else {
        panic!("a NURBS plane");
    };
    // The slot lies in the plane z = 0.2 x.
    for i in 0..=10 {
        let p = file.curves[3].curve.point(f64::from(i) / 10.0);
        assert!((p.z - 0.2 * p.x).abs() < 1e-12, "in the plane at {i}");
    }
    assert_eq!(plane.net_size(), (2, 2), "bilinear");
}

#[test]
fn mesh_surfaces_inline_and_stl_are_the_same_cube() {
    let file = curves::load(fixture("mesh_surfaces.json")).expect("valid");
    let SurfaceGeometry::Mesh {
        vertices: v1,
        triangles: t1,
    } = &file.surfaces[0].geometry
    else {
        panic!("inline mesh");
    };
    let SurfaceGeometry::Mesh {
        vertices: v2,
        triangles: t2,
    } = &file.surfaces[1].geometry
    else {
        panic!("STL mesh");
    };
    assert_eq!((v1.len(), t1.len()), (8, 12), "inline cube");
    assert_eq!((v2.len(), t2.len()), (8, 12), "STL cube");
    assert!(
        matches!(&file.surfaces[1].source, SurfaceSource::Stl { path, dropped_facets: 0 } if path.ends_with("cube.stl")),
        "source {:?}",
        file.surfaces[1].source
    );
    // Same triangles, facet by facet.
    for (a, b) in t1.iter().zip(t2) {
        assert_eq!(
            a.map(|i| v1[i as usize]),
            b.map(|i| v2[i as usize]),
            "facet"
        );
    }
}

#[test]
fn every_valid_fixture_loads() {
    for entry in std::fs::read_dir(fixture("")).expect("fixtures dir") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "json") {
            curves::load(&path).unwrap_or_else(|e| panic!("{e}"));
        }
    }
}

/// The real parts of `fixtures/realdata/` (converted by another tool) read as the format says.
#[test]
fn real_parts_load_with_every_surface_resolved() {
    for (name, curves, surfaces) in [
        ("realdata/nori_sheetmetal.json", 81, 65),
        ("realdata/occt_propeller.json", 47, 24),
    ] {
        let file = curves::load(fixture(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (file.curves.len(), file.surfaces.len()),
            (curves, surfaces),
            "{name}: counts"
        );
        for c in &file.curves {
            assert!(file.surface_of(c).is_some(), "{name}: {} is carried", c.id);
        }
    }
}

#[test]
fn each_broken_fixture_fails_with_its_message() {
    let cases = [
        (
            "decreasing_knots.json",
            "curves[1].knots[5]: knots must be non-decreasing (0.5 after 0.7)",
        ),
        (
            "negative_weight.json",
            "curves[0].weights[2]: weight must be finite and > 0 (got -1)",
        ),
        (
            "unknown_surface_type.json",
            "surfaces[1]: unknown type \"nurb\" (expected one of nurbs, mesh, stl)",
        ),
        (
            "unknown_format.json",
            "format: unsupported format \"kerf.curves/2\" (this reader reads \"kerf.curves/1\")",
        ),
        (
            "malformed.json",
            "curves[0].degree: invalid JSON at line 8, column 7: expected `,` or `}`",
        ),
        (
            "empty.json",
            "the file is empty (expected a kerf.curves/1 JSON document)",
        ),
        (
            "missing_surface.json",
            "curves[0].surface: no surface with id \"panel\" (surfaces: \"plane\")",
        ),
        (
            "short_point.json",
            "curves[0].control_points[1]: invalid length 2, expected an array of length 3",
        ),
        (
            "huge_number.json",
            "curves[0].control_points[1][0]: invalid JSON at line 9, column 42: number out of range",
        ),
        (
            "bad_triangle.json",
            "surfaces[0].triangles[4][1]: vertex index 9 out of range (8 vertices)",
        ),
        ("missing_stl.json", "surfaces[0].path: "),
        ("inches.json", "units: unsupported units \"in\""),
    ];
    let listed: Vec<_> = cases.iter().map(|(name, _)| *name).collect();
    for entry in std::fs::read_dir(fixture("bad")).expect("bad dir") {
        let entry = entry.expect("entry");
        // Subdirectories (`io/`) carry their own list of cases and tests.
        if entry.file_type().expect("file type").is_dir() {
            continue;
        }
        let name = entry.file_name();
        let name = name.to_string_lossy();
        assert!(
            listed.contains(&name.as_ref()),
            "{name} has a test case here"
        );
    }
    for (name, expected) in cases {
        let path = fixture("bad").join(name);
        let err = curves::load(&path).expect_err(name);
        assert_eq!(err.file(), Some(path.as_path()), "{name}: names the file");
        let message = err.without_file().to_string();
        assert!(
            message.starts_with(expected),
            "{name}: got {message:?}, expected it to start with {expected:?}"
        );
        assert!(
            err.to_string()
                .starts_with(&format!("{}: ", path.display())),
            "{name}: {err}"
        );
    }
    let err = curves::load(fixture("bad/missing_stl.json")).expect_err("missing STL");
    assert!(
        matches!(err.without_file(), FormatError::Stl { .. }),
        "{err:?}"
    );
    assert!(
        err.to_string().contains("does_not_exist.stl: cannot read"),
        "{err}"
    );
}

/// The review's `surf/stl_fifo.json`: an STL path naming a FIFO hung forever in `open()`, and
/// `/dev/zero` was read 1 GiB deep before the size limit refused it. Both are refused at once,
/// naming the JSON path of the `path`.
#[cfg(unix)]
#[test]
fn an_stl_path_that_is_a_fifo_or_a_device_is_refused_without_reading() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let made = std::process::Command::new("mkfifo")
        .arg(dir.path().join("fifo"))
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo");
    for path in ["fifo", "/dev/zero"] {
        let json = dir.path().join("part.json");
        std::fs::write(
            &json,
            format!(
                r#"{{"format": "kerf.curves/1", "units": "mm",
                "curves": [{{"id": "c", "degree": 1, "knots": [0, 0, 1, 1],
                  "control_points": [[10, 10, 0], [90, 10, 0]], "surface": "m"}}],
                "surfaces": [{{"id": "m", "type": "stl", "path": "{path}"}}]}}"#
            ),
        )
        .expect("write");
        let err = curves::load(&json).expect_err(path).to_string();
        assert!(err.contains("surfaces[0].path"), "{err}");
        assert!(err.contains("not a regular file"), "{err}");
    }
}
