//! `kerf import` and `kerf run PART.step` through the binary, on the STEP fixtures (made with
//! Open CASCADE, checked against its reader by scripts/step_check.py) and the real parts.

use std::process::Command;
mod common;
use common::{fixture, kerf};

/// `fixtures/realdata/step` (the real STEP parts, shipped with the repository: a test on them
/// cannot pass by skipping them).
fn real_step_dir() -> std::path::PathBuf {
    let dir = fixture("realdata/step");
    assert!(dir.is_dir(), "{} is missing", dir.display());
    dir
}

fn run(c: &mut Command) -> (i32, String, String) {
    let o = c.output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn import_writes_a_valid_curves_file_and_says_what_it_did() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("part.curves.json");
    let (code, _, err) = run(kerf()
        .arg("import")
        .arg(fixture("step/composite_mm.step"))
        .arg("-o")
        .arg(&out));
    assert_eq!(code, 0, "{err}");
    let file = kerf_format::curves::load(&out).expect("valid kerf.curves/1");
    assert_eq!(file.curves.len(), 5, "contours");
    assert_eq!(file.surfaces.len(), 2, "the top and side faces");
    assert!(err.contains("took contour 1 #"), "{err}");
    assert!(
        err.contains("closed 1 gaps between segments, largest pole move 2.000e-2 mm"),
        "{err}"
    );
    assert!(
        err.contains("opened #") && err.contains("(gap 0.300 mm)"),
        "{err}"
    );
}

#[test]
fn no_usable_contour_exits_1_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.curves.json");
    let step = dir.path().join("points.step");
    std::fs::write(
        &step,
        "ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=GEOMETRIC_CURVE_SET('',(#1));\nENDSEC;\nEND-ISO-10303-21;\n",
    )
    .unwrap();
    let (code, _, err) = run(kerf().arg("import").arg(&step).arg("-o").arg(&out));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("no usable contour"), "{err}");
    assert!(!out.exists(), "nothing written");
    // Faces without cut curves: the reader names its option, the command line its flag.
    for cmd in ["import", "run"] {
        let mut c = kerf();
        c.arg(cmd).arg(fixture("step/faces.step"));
        if cmd == "run" {
            c.arg("-m")
                .arg(fixture("machines/gantry_ac.json"))
                .arg("--out")
                .arg(dir.path().join("run"));
        } else {
            c.arg("-o").arg(&out);
        }
        let (code, _, err) = run(&mut c);
        assert_eq!(code, 1, "{err}");
        assert!(
            err.contains("ImportOptions::with_edges") && err.ends_with("[option: --edges]\n"),
            "{cmd}: {err}"
        );
    }

    std::fs::write(&step, "ISO-10303-21;\nDATA;\n#1=CIRCLE('',#2,3.;\n").unwrap();
    let (code, _, err) = run(kerf().arg("import").arg(&step).arg("-o").arg(&out));
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("points.step: line 3:"), "{err}");
    assert!(!out.exists(), "nothing written");

    let (code, _, err) = run(kerf().arg("import").arg(&step).args(["--faces", "12"]));
    assert_eq!(code, 2, "--faces without --edges is a usage error: {err}");
}

#[test]
fn run_takes_a_step_file_and_normals_come_from_the_nearest_face() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(fixture("step/composite_mm.step"))
        .arg("-m")
        .arg(fixture("machines/ac_head.json"))
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 0, "{err}");
    let tp = kerf_format::toolpath::load(out.join("toolpath.json")).unwrap();
    assert_eq!(tp.paths.len(), 5, "every contour cut");
    // The contour over two faces of the block 120 x 80 x 20: on the top (z = 20) the normal is
    // +z, on the side face x = 120 it is +x (the block's outward normals).
    let path = tp
        .paths
        .iter()
        .find(|p| p.id.starts_with("contour 3"))
        .expect("contour 3");
    let mut top = 0;
    let mut side = 0;
    for n in 0..path.params.len() {
        let p = path.points.position(n);
        let nv = path.points.normal(n).expect("normals");
        if p.z > 20.0 - 1e-9 && p.x < 120.0 - 1e-6 {
            assert!(
                (nv - nalgebra::Vector3::z()).norm() < 1e-9,
                "top normal {nv:?} at {p:?}"
            );
            top += 1;
        } else if p.x > 120.0 - 1e-9 && p.z < 20.0 - 1e-6 {
            assert!(
                (nv - nalgebra::Vector3::x()).norm() < 1e-9,
                "side normal {nv:?} at {p:?}"
            );
            side += 1;
        }
    }
    assert!(top > 0 && side > 0, "points on both faces ({top}, {side})");
    for f in ["axes.json", "program.nc", "report.json"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn real_parts_import_with_edges_and_discretize_with_normals() {
    let dir_real = real_step_dir();
    let dir = tempfile::tempdir().unwrap();
    for name in ["S01094.stp", "S06298.stp"] {
        let curves = dir.path().join(format!("{name}.json"));
        let tp = dir.path().join(format!("{name}.tp.json"));
        let (code, _, err) = run(kerf()
            .arg("import")
            .arg(dir_real.join(name))
            .arg("--edges")
            .arg("-o")
            .arg(&curves));
        assert_eq!(code, 0, "{name}: {err}");
        let (code, _, err) = run(kerf()
            .arg("discretize")
            .arg(&curves)
            .args(["-t", "0.01", "--normals", "-o"])
            .arg(&tp));
        assert_eq!(code, 0, "{name}: {err}");
        let (code, out, err) = run(kerf().arg("check").arg(&curves).arg(&tp));
        assert_eq!(code, 0, "{name}: {out}{err}");
    }
}

#[test]
fn run_cuts_the_boundary_loops_of_chosen_faces() {
    // In fixtures/step/faces.step (entity numbers as the fixture script wrote them): a box
    // face, the cylinder's side, the cone's side, the extrusion and the B-spline surface face.
    // Faces whose outward normal points down (the box's bottom) are out of the head's reach.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(fixture("step/faces.step"))
        .args(["--edges", "--faces", "183,#412,529,754,953", "-m"])
        .arg(fixture("machines/ac_head.json"))
        // Along the B-spline face's loop the nozzle, 1.4 mm above its tip, comes within
        // 0.95 mm of that face's surface (refused by default): the head check has its own
        // tests.
        .args(["--cut-clearance", "off"])
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 0, "{err}");
    let tp = kerf_format::toolpath::load(out.join("toolpath.json")).unwrap();
    let ids: Vec<&str> = tp.paths.iter().map(|p| p.id.as_str()).collect();
    for f in ["#183", "#412", "#529", "#754", "#953"] {
        assert!(
            ids.iter().any(|i| i.starts_with(&format!("face {f} "))),
            "{f} cut: {ids:?}"
        );
    }
}

#[test]
fn a_real_sheet_metal_part_is_cut_once_per_feature_and_every_loop_on_request() {
    // S06298.stp, a 3 mm tray with lips: sheet recognition (the default with --edges) gives
    // two features (the outline in pieces, the 100 mm hole) where every face loop gives 78;
    // `kerf run --place auto` cuts them on the gantry, each once.
    let dir_real = real_step_dir();
    let part = dir_real.join("S06298.stp");
    let dir = tempfile::tempdir().unwrap();
    let curves = dir.path().join("sheet.json");
    let (code, out, err) = run(kerf()
        .arg("import")
        .arg(&part)
        .args(["--edges", "--json", "-o"])
        .arg(&curves));
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    let sheet = &summary["sheet"];
    assert_eq!(sheet["not_a_sheet"], serde_json::Value::Null, "{sheet}");
    assert!(
        (sheet["thickness_mm"].as_f64().unwrap() - 3.0).abs() < 1e-6,
        "{sheet}"
    );
    assert_eq!(sheet["features"].as_array().unwrap().len(), 2, "{sheet}");
    assert_eq!(
        summary["surfaces"], 75,
        "every face is an obstacle: {summary}"
    );
    let every = dir.path().join("every.json");
    let (code, out, err) = run(kerf()
        .arg("import")
        .arg(&part)
        .args(["--edges", "--every-face-loop", "--json", "-o"])
        .arg(&every));
    assert_eq!(code, 0, "{err}");
    let summary: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(summary["curves"], 78, "{summary}");
    assert_eq!(summary["sheet"], serde_json::Value::Null);
    // --every-face-loop needs --edges.
    let (code, _, err) = run(kerf().arg("import").arg(&part).arg("--every-face-loop"));
    assert_eq!(code, 2, "{err}");
    // By default the head is checked along every cut: the outline's first piece crosses the
    // inner radius of a 3 mm bend, where the head comes within 0.9 mm of the sheet, and no
    // tilt clears it: refused, naming the piece, a surface and the clearance, and nothing is
    // written.
    let refused = dir.path().join("refused");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(&part)
        .args(["--edges", "--place", "auto", "-m"])
        .arg(fixture("machines/gantry_ac.json"))
        .arg("--out")
        .arg(&refused));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("path \"feature 1 face #239 piece 1\": the head comes too close to the part")
            && err.contains("mm of surface face #")
            && err.contains("(clearance 1 mm)")
            && err.contains("no tilt up to 60 deg"),
        "{err}"
    );
    assert!(
        !refused.exists(),
        "a refused run wrote {}",
        refused.display()
    );
    // The whole run, the close stretches accepted as warnings: one cut per contour of the
    // import, every one of them planned.
    let out_dir = dir.path().join("run");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(&part)
        .args([
            "--edges",
            "--place",
            "auto",
            "--accept-head-collisions",
            "-m",
        ])
        .arg(fixture("machines/gantry_ac.json"))
        .arg("--out")
        .arg(&out_dir));
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("the head comes too close"), "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("report.json")).unwrap())
            .unwrap();
    let imported = kerf_format::curves::load(&curves).unwrap();
    assert_eq!(
        report["program"]["cuts"].as_u64().unwrap() as usize,
        imported.curves.len(),
        "{}",
        report["program"]
    );
}

#[test]
fn what_the_step_import_assumed_is_in_the_run_report_even_when_quiet() {
    // A file with no unit context is read as mm with a warning; under -q nothing is printed,
    // so report.json's warnings must carry it.
    let dir = tempfile::tempdir().unwrap();
    let part = dir.path().join("nounits.step");
    std::fs::write(
        &part,
        "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n\
         #1=CARTESIAN_POINT('',(0.,0.,0.));\n#2=AXIS2_PLACEMENT_3D('',#1,$,$);\n\
         #3=CIRCLE('hole',#2,10.);\n#4=GEOMETRIC_CURVE_SET('cut',(#3));\nENDSEC;\nEND-ISO-10303-21;\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(&part)
        .args(["-q", "-m"])
        .arg(fixture("machines/ac_head.json"))
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 0, "{err}");
    assert!(
        !err.contains("GLOBAL_UNIT_ASSIGNED_CONTEXT"),
        "quiet: {err}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let warnings = report["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with("input: the file has no GLOBAL_UNIT_ASSIGNED_CONTEXT")),
        "{warnings:?}"
    );
}

#[test]
fn an_edge_within_its_files_tolerance_is_cut_and_named_and_beyond_it_refused() {
    // The plate's front wall (#298, the plane y = 0 through #277) moved 0.015 mm off its
    // edges: the wall's own loop (`--faces 298`) lies 0.015 mm from the wall, more than the run's on-surface tolerance (0.01 mm). A file whose uncertainty
    // is 0.02 mm says its edges are good to that: the loop is cut, and the report names it with
    // both distances. The same file stating 0.005 mm, or nothing, is refused by the normals
    // stage naming the distance.
    let text = std::fs::read_to_string(fixture("step/sheet/plate.step")).expect("fixture");
    let wall = "#277 = CARTESIAN_POINT('',(0.0,0.0,0.0));";
    assert!(text.contains(wall), "the fixture's front wall origin");
    let moved = text.replace(wall, "#277 = CARTESIAN_POINT('',(0.0,0.015,0.0));");
    let with_uncertainty = |u: &str| {
        moved.replacen(
            "DATA;\n",
            &format!(
                "DATA;\n#9001 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#9002 = UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({u}),#9001,'distance_accuracy_value','');\n#9003 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#9002)) REPRESENTATION_CONTEXT('','') );\n"
            ),
            1,
        )
    };
    let dir = tempfile::tempdir().expect("tmp");
    let run_on = |name: &str, step: &str| {
        let path = dir.path().join(format!("{name}.step"));
        std::fs::write(&path, step).expect("write");
        let out = dir.path().join(name);
        let (code, _, err) = run(kerf()
            .arg("run")
            .arg(&path)
            .args(["--edges", "--faces", "298", "--place", "auto", "-m"])
            .arg(fixture("machines/gantry_ac.json"))
            .args(["-q", "-o"])
            .arg(&out));
        (code, err, out)
    };
    let (code, err, out) = run_on("within", &with_uncertainty("0.02"));
    assert_eq!(code, 0, "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("report"))
            .expect("JSON");
    let warnings: Vec<&str> = report["warnings"]
        .as_array()
        .expect("warnings")
        .iter()
        .filter_map(|w| w.as_str())
        .filter(|w| w.contains("beyond the run's on-surface tolerance"))
        .collect();
    assert!(!warnings.is_empty(), "{}", report["warnings"]);
    for w in &warnings {
        // The wall's loop: 0.015 mm (the move), within the file's 0.02 mm.
        assert!(
            w.contains("face #298 loop")
                && w.contains("up to 0.015")
                && w.contains("mm from its surface")
                && w.contains("on-surface tolerance (0.01 mm) but within the curve's own (0.02 mm"),
            "{w}"
        );
    }
    // 0.012 mm: looser than the run's 0.01 mm, yet tighter than the 0.015 mm the edge is off.
    for (name, step, tolerance) in [
        ("own", with_uncertainty("0.012"), "0.012 mm"),
        ("tight", with_uncertainty("0.005"), "0.01 mm"),
        ("none", moved.clone(), "0.01 mm"),
    ] {
        let (code, err, out) = run_on(name, &step);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(
            err.contains("face #298 loop")
                && err.contains("1.5")
                && err.contains("e-2 mm from its surface")
                && err.contains(tolerance),
            "{name}: {err}"
        );
        assert!(!out.exists(), "{name}: nothing written");
    }
}

#[test]
fn run_takes_an_iges_file_and_import_refuses_a_broken_one_by_line() {
    // The free curves of the IGES fixture (Open CASCADE wrote it): five on the plate and the
    // tube, one 3D curve on no face, which a laser without its surface cannot orient: cut the
    // plate's and tube's with --place auto on the gantry.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let (code, _, err) = run(kerf()
        .arg("import")
        .arg(fixture("iges/curves.igs"))
        .arg("-o")
        .arg(dir.path().join("c.json")));
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("IGES 5.3 (mm; lengths x1 to mm): 6 contours"),
        "{err}"
    );
    assert!(
        err.contains("took D69: degree 2, 9 control points, 31.416 mm on face D3"),
        "{err}"
    );
    let (code, _, err) = run(kerf()
        .arg("run")
        .arg(fixture("iges/faces.igs"))
        .arg("--edges")
        .arg("--faces")
        .arg("5,197")
        .arg("-m")
        .arg(fixture("machines/gantry_ac.json"))
        .arg("--place")
        .arg("auto")
        .arg("--out")
        .arg(&out));
    assert_eq!(code, 0, "{err}");
    let tp = kerf_format::toolpath::load(out.join("toolpath.json")).unwrap();
    let ids: Vec<&str> = tp.paths.iter().map(|p| p.id.as_str()).collect();
    assert_eq!(ids.len(), 2, "{ids:?}");
    assert!(
        ids.iter()
            .all(|i| i.starts_with("face D5 ") || i.starts_with("face D197 ")),
        "{ids:?}"
    );
    assert!(out.join("program.nc").is_file());

    // A file whose directory line was cut short: exit 1, the line named, nothing written.
    let text = std::fs::read_to_string(fixture("iges/curves.igs")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let k = lines
        .iter()
        .position(|l| l.len() > 72 && &l[72..73] == "D")
        .unwrap();
    lines[k].truncate(50);
    let bad = dir.path().join("bad.igs");
    std::fs::write(&bad, lines.join("\n")).unwrap();
    let dest = dir.path().join("bad.curves.json");
    let (code, _, err) = run(kerf().arg("import").arg(&bad).arg("-o").arg(&dest));
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("bad.igs: line {}: an IGES record", k + 1)),
        "{err}"
    );
    assert!(!dest.exists(), "nothing written");
}
