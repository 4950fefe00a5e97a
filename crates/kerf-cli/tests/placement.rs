//! `--place`: every real part runs end to end with `--place auto` on a shipped machine, and the
//! outputs are checked independently: every axis value within the machine file's limits, the
//! forward kinematics of every axis vector giving its pose, and the first and last pose of
//! every path equal to the toolpath's cutting point moved by the placement the report states
//! (the rotation rebuilt here from the reported angles, not by the library).

mod common;

use std::path::PathBuf;

use kerf_kinematics::{Axes, Machine};
use nalgebra::{Matrix3, Vector3};
use serde_json::Value;

use common::{fixture, kerf, read_json};

fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn rot_y(a: f64) -> Matrix3<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.to_radians().sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

fn vec3(v: &Value) -> Vector3<f64> {
    let a = v.as_array().expect("array");
    Vector3::new(
        a[0].as_f64().expect("x"),
        a[1].as_f64().expect("y"),
        a[2].as_f64().expect("z"),
    )
}

/// Runs `kerf run` with `place` and checks the outputs; returns the report.
fn run_placed(curves: &str, machine: &str, place: &str) -> Value {
    run_placed_in(curves, machine, place).0
}

/// The head check's option for `curves`: off for the real JSON files, whose bend and blade
/// edges the head meets (refused by default; kerf-pipeline's tests/head_sweep.rs sweeps them).
fn head_option(curves: &str) -> &'static [&'static str] {
    if curves.starts_with("realdata/") {
        &["--cut-clearance", "off"]
    } else {
        &[]
    }
}

/// [`run_placed`], with the run's directory (its files for further checks).
fn run_placed_in(curves: &str, machine: &str, place: &str) -> (Value, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let machine_path = fixture("machines").join(machine);
    let out = kerf()
        .arg("run")
        .arg(fixture(curves))
        .arg("--machine")
        .arg(&machine_path)
        .arg("--place")
        .arg(place)
        .args(head_option(curves))
        .arg("--out")
        .arg(dir.path())
        .arg("-q")
        .output()
        .expect("run kerf");
    assert!(
        out.status.success(),
        "kerf run {curves} --place {place} on {machine}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = read_json(&dir.path().join("report.json"));
    let axes = read_json(&dir.path().join("axes.json"));
    let toolpath = read_json(&dir.path().join("toolpath.json"));
    let m = Machine::read(&machine_path).expect("machine");
    let placement = &report["placement"];
    let setups = placement["setups"].as_array().expect("setups");
    let flipped: Vec<&str> = placement["flipped_paths"]
        .as_array()
        .expect("flipped_paths")
        .iter()
        .map(|v| v.as_str().expect("id"))
        .collect();
    // Contours cut along their wall (a hole's wall named as their surface): their tool axis
    // is not the surface's normal but perpendicular to it and to the contour.
    let walls: Vec<&str> = placement["walls"]
        .as_array()
        .expect("walls")
        .iter()
        .map(|w| w["id"].as_str().expect("id"))
        .collect();
    let tpaths = toolpath["paths"].as_array().expect("toolpath paths");
    let apaths = axes["paths"].as_array().expect("axes paths");
    assert_eq!(
        tpaths.len(),
        apaths.len(),
        "one axes path per toolpath path"
    );
    let mut seen = 0;
    for s in setups {
        let r = s["rotation_deg"].as_array().expect("rotation");
        let [rx, ry, rz] = [0, 1, 2].map(|k| r[k].as_f64().expect("angle"));
        let rot = rot_z(rz) * rot_y(ry) * rot_x(rx);
        let t = vec3(&s["translation_mm"]);
        for id in s["paths"].as_array().expect("paths") {
            let id = id.as_str().expect("id");
            seen += 1;
            let tp = tpaths
                .iter()
                .find(|p| p["id"] == id)
                .expect("path in the toolpath");
            let ap = apaths
                .iter()
                .find(|p| p["id"] == id)
                .expect("path in the axes file");
            let tpts = tp["points"].as_array().expect("points");
            let poses = ap["poses"].as_array().expect("poses");
            let sign = if flipped.contains(&id) { -1.0 } else { 1.0 };
            // The cut begins at its start point (closed contours run round to it again).
            let sp = ap["start_point"].as_u64().map_or(0, |v| v as usize);
            let xyz = |v: &Value| -> Vector3<f64> {
                let a = v.as_array().expect("point");
                Vector3::new(
                    a[0].as_f64().expect("x"),
                    a[1].as_f64().expect("y"),
                    a[2].as_f64().expect("z"),
                )
            };
            let closed = (xyz(&tpts[0]) - xyz(&tpts[tpts.len() - 1])).norm() < 1e-6;
            let end = if closed && sp > 0 { sp } else { tpts.len() - 1 };
            for (tpi, api) in [(sp, 0), (end, poses.len() - 1)] {
                let q: Vec<f64> = tpts[tpi]
                    .as_array()
                    .expect("point")
                    .iter()
                    .map(|v| v.as_f64().expect("number"))
                    .collect();
                let want_p = rot * Vector3::new(q[0], q[1], q[2]) + t;
                let want_u = rot * Vector3::new(q[3], q[4], q[5]) * sign;
                let got: Vec<f64> = poses[api]
                    .as_array()
                    .expect("pose")
                    .iter()
                    .map(|v| v.as_f64().expect("number"))
                    .collect();
                let gp = Vector3::new(got[0], got[1], got[2]);
                let gu = Vector3::new(got[3], got[4], got[5]);
                assert!((gp - want_p).norm() < 1e-6, "{id}: tip {gp} vs {want_p}");
                if walls.contains(&id) {
                    // Along the wall: a unit vector perpendicular to the wall's normal and to
                    // the contour's chord through the neighbouring cutting points.
                    let (a, b) = (tpi.saturating_sub(1), (tpi + 1).min(tpts.len() - 1));
                    let chord = rot * (xyz(&tpts[b]) - xyz(&tpts[a])).normalize();
                    assert!((gu.norm() - 1.0).abs() < 1e-9, "{id}: {gu}");
                    assert!(gu.dot(&want_u).abs() < 1e-9, "{id}: {gu} against {want_u}");
                    assert!(gu.dot(&chord).abs() < 1e-3, "{id}: {gu} against {chord}");
                    continue;
                }
                // Within the tilt tolerance (the default 1 degree) of the placed normal, and
                // within what the axes file reports.
                let tilt = ap["tilt_max_deg"].as_f64();
                assert_eq!(
                    tilt.is_some(),
                    kerf_pipeline::DEFAULT_TILT_TOLERANCE_DEG > 0.0,
                    "{id}: tilt_max_deg reported exactly when a tolerance is in force"
                );
                let angle = gu.angle(&want_u).to_degrees();
                let allowed = tilt.map_or(1e-7, |t| t + 1e-9);
                assert!(
                    angle <= allowed && allowed <= kerf_pipeline::DEFAULT_TILT_TOLERANCE_DEG + 1e-7,
                    "{id}: tool axis {gu} vs {want_u}: {angle} deg, reported {tilt:?}"
                );
            }
            let mut positions: Vec<&Value> = Vec::new();
            let mut all_poses: Vec<&Value> = Vec::new();
            for part in [&ap["lead_in"], ap, &ap["lead_out"]] {
                if let (Some(q), Some(p)) = (part["positions"].as_array(), part["poses"].as_array())
                {
                    positions.extend(q);
                    all_poses.extend(p);
                }
            }
            let poses = all_poses;
            for (n, pos) in positions.iter().enumerate() {
                let q: Vec<f64> = pos
                    .as_array()
                    .expect("axes")
                    .iter()
                    .map(|v| v.as_f64().expect("number"))
                    .collect();
                let a = Axes::new(q[0], q[1], q[2], q[3], q[4]);
                if let Some((axis, range)) = m.violation(&a, 1e-9) {
                    panic!("{id}: point {n}: {axis:?} outside {range:?}: {q:?}");
                }
                let fk = m.kinematics.forward(&a);
                let pose: Vec<f64> = poses[n]
                    .as_array()
                    .expect("pose")
                    .iter()
                    .map(|v| v.as_f64().expect("number"))
                    .collect();
                let dp = (fk.position.coords - Vector3::new(pose[0], pose[1], pose[2])).norm();
                assert!(
                    dp < 1e-6,
                    "{id}: point {n}: forward kinematics off by {dp} mm"
                );
                let cos = fk.axis.dot(&Vector3::new(pose[3], pose[4], pose[5]));
                assert!(cos > 1.0 - 1e-9, "{id}: point {n}: tool axis off");
            }
        }
    }
    assert_eq!(seen, tpaths.len(), "every path in exactly one set-up");
    (report, dir)
}

#[test]
fn every_real_part_runs_with_place_auto() {
    let prop = run_placed("realdata/occt_propeller.json", "gantry_ac.json", "auto");
    assert_eq!(
        prop["placement"]["setups"].as_array().map(Vec::len),
        Some(1),
        "the propeller fits in one set-up: {}",
        prop["placement"]
    );
    assert!(
        !prop["placement"]["flipped_paths"]
            .as_array()
            .expect("list")
            .is_empty(),
        "some propeller faces face down and are cut from the other side"
    );
    // Eight parts whose bend edges need more tilt than one orientation gives: several set-ups.
    let sheet = run_placed("realdata/nori_sheetmetal.json", "gantry_ac.json", "auto");
    let n = sheet["placement"]["setups"].as_array().map_or(0, Vec::len);
    assert!(
        n > 1,
        "sheet metal needs several set-ups on a +-135 deg head"
    );
    // On the table machines a rapid between two of its pieces turns C by 251 degrees at
    // A = 90: planned along the tip's line instead of the joints' (the way G0 runs it), it
    // swung Z out of the travel and the part got no program. And every traverse is checked:
    // a route was refused where the tip's straight line (not the machine's straight move in
    // its axes) left the travel, and two gaps fell back to unchecked moves. The written
    // traverses' waypoints are within the travel (the machine runs each rapid straight in its
    // axes, so between them too).
    for machine in ["table_table.json", "head_table.json"] {
        let (table, dir) = run_placed_in("realdata/nori_sheetmetal.json", machine, "auto");
        assert!(
            table["placement"]["setups"].as_array().map_or(0, Vec::len) > 1,
            "{machine}: several set-ups"
        );
        let t = &table["traverses"];
        assert_eq!(t["unchecked"], serde_json::json!([]), "{machine}: {t}");
        assert_eq!(
            t["checked_count"], t["count"],
            "{machine}: every gap routed"
        );
        let axes = read_json(&dir.path().join("axes.json"));
        let m = Machine::read(fixture("machines").join(machine)).expect("machine");
        let mut waypoints = 0;
        for p in axes["paths"].as_array().expect("paths") {
            let Some(rows) = p["traverse"]["positions"].as_array() else {
                continue;
            };
            for row in rows {
                waypoints += 1;
                for (k, v) in row.as_array().expect("row").iter().enumerate() {
                    let v = v.as_f64().expect("number");
                    if let Some(r) = m.limits[k] {
                        assert!(
                            v >= r.min - 1e-9 && v <= r.max + 1e-9,
                            "{machine}: path {}: axis {k} = {v} outside [{}, {}]",
                            p["id"],
                            r.min,
                            r.max
                        );
                    }
                }
            }
        }
        assert!(waypoints > 100, "{machine}: {waypoints} waypoints checked");
    }
}

#[test]
fn a_given_placement_is_applied_and_reported() {
    let report = run_placed("door_trim.json", "ac_head.json", "10,-20,30");
    let s = &report["placement"]["setups"][0];
    assert_eq!(
        s["translation_mm"],
        serde_json::json!([10.0, -20.0, 30.0]),
        "{s}"
    );
    assert_eq!(report["placement"]["mode"], "given");
    // A rotation too: a quarter turn about z keeps the door trim within the travel.
    run_placed("door_trim.json", "ac_head.json", "0,0,0,0,0,90");
}

#[test]
fn a_bad_place_is_a_usage_error_and_no_fit_is_named() {
    for bad in ["1,2", "auto-ish", "1,2,nan"] {
        let out = kerf()
            .arg("run")
            .arg(fixture("door_trim.json"))
            .arg("--machine")
            .arg(fixture("machines/ac_head.json"))
            .arg("--place")
            .arg(bad)
            .output()
            .expect("run kerf");
        assert_eq!(out.status.code(), Some(2), "--place {bad}: usage error");
    }
    // The 3.5 m blade edge is one contour longer than the 800 mm X travel of the trunnion
    // table in every orientation: the error names the axis and the shortfall.
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = kerf()
        .arg("run")
        .arg(fixture("turbine_blade_edge.json"))
        .arg("--machine")
        .arg(fixture("machines/table_table.json"))
        .arg("--place")
        .arg("auto")
        .arg("--out")
        .arg(dir.path())
        .output()
        .expect("run kerf");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("no placement fits the machine"), "{err}");
    assert!(err.contains(" short"), "{err}");
    assert!(
        std::fs::read_dir(dir.path()).expect("dir").next().is_none(),
        "nothing written"
    );
}

#[test]
fn step_parts_run_with_place_auto() {
    // The shipped STEP fixtures (composite contours over their faces) straight from STEP.
    for f in ["step/composite_mm.step", "step/composite_inch.step"] {
        run_placed(f, "gantry_ac.json", "auto");
    }
    // The real sheet-metal parts (shipped in fixtures/realdata/step).
    let real = fixture("realdata/step");
    let dir = std::fs::read_dir(&real).expect("fixtures/realdata/step");
    let mut files: Vec<PathBuf> = dir.filter_map(|e| e.ok().map(|e| e.path())).collect();
    files.retain(|p| p.extension().is_some_and(|x| x == "stp" || x == "step"));
    files.sort();
    assert!(!files.is_empty(), "no STEP file in {}", real.display());
    for f in files {
        let out = tempfile::tempdir().expect("temporary directory");
        let r = kerf()
            .arg("run")
            .arg(&f)
            .arg("--edges")
            .arg("--machine")
            .arg(fixture("machines/gantry_ac.json"))
            .arg("--place")
            .arg("auto")
            // Their outlines cross tight inner bend radii, where the nozzle comes within 1 mm
            // (refused by default: tests/head.rs).
            .args(["--cut-clearance", "off"])
            .arg("--out")
            .arg(out.path())
            .arg("-q")
            .output()
            .expect("run kerf");
        assert!(
            r.status.success(),
            "{}: {}",
            f.display(),
            String::from_utf8_lossy(&r.stderr)
        );
        // A recognised sheet's features lie on the side the head reaches (each piece that
        // faces down was taken on its twin) and carry the sheet's thickness: none is turned
        // over, which would stand the nozzle off from the far face, inside the sheet.
        let report = read_json(&out.path().join("report.json"));
        assert_eq!(
            report["placement"]["flipped_paths"],
            serde_json::json!([]),
            "{}",
            f.display()
        );
        // On S06298 the nozzle's line meets the part from the given side on four outline
        // pieces (flanges rise beside them): the report says they keep their side because
        // they lie on the sheet's face.
        if f.ends_with("S06298.stp") {
            let kept = report["placement"]["sides"]
                .as_array()
                .expect("sides")
                .iter()
                .filter(|s| {
                    s["side"] == "given"
                        && s["reason"]
                            .as_str()
                            .is_some_and(|r| r.contains("never turned over"))
                })
                .count();
            assert!(kept >= 1, "{}", report["placement"]["sides"]);
        }
    }
}

/// A plate at z = 0 whose face looks down (-z), with a 40 mm circle on it; with
/// `sheet_thickness_mm` where given.
fn plate_facing_down(thickness: Option<f64>) -> String {
    let w = std::f64::consts::FRAC_1_SQRT_2;
    let mut curve = serde_json::json!({
        "id": "hole",
        "degree": 2,
        "knots": [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1],
        "control_points": [[20, 0, 0], [20, -20, 0], [0, -20, 0], [-20, -20, 0], [-20, 0, 0],
            [-20, 20, 0], [0, 20, 0], [20, 20, 0], [20, 0, 0]],
        "weights": [1, w, 1, w, 1, w, 1, w, 1],
        "surface": "plate",
        "scrap": "left"
    });
    if let Some(t) = thickness {
        curve["sheet_thickness_mm"] = serde_json::json!(t);
    }
    serde_json::json!({
        "format": "kerf.curves/1",
        "units": "mm",
        "curves": [curve],
        "surfaces": [{
            "id": "plate", "type": "nurbs", "degree_u": 1, "degree_v": 1,
            "knots_u": [0, 0, 1, 1], "knots_v": [0, 0, 1, 1],
            "control_points": [[[-50, -50, 0], [-50, 50, 0]], [[50, -50, 0], [50, 50, 0]]],
            "flip": true
        }]
    })
    .to_string()
}

#[test]
fn a_thick_sheets_contour_is_never_turned_over() {
    // The plate's face looks down, out of the A/C head's reach: a contour with no thickness
    // is taken for a thin sheet's and turned over (the beam from above, through the same
    // points); one on a 3 mm sheet is not (the nozzle would stand 2 mm inside the plate), so
    // the part is turned instead, and the report says why the contour keeps its side.
    let dir = tempfile::tempdir().expect("temporary directory");
    for (thickness, turned) in [(None, true), (Some(3.0), false)] {
        let input = dir.path().join("plate.json");
        std::fs::write(&input, plate_facing_down(thickness)).expect("write");
        let out = dir.path().join(format!("out-{turned}"));
        let r = kerf()
            .arg("run")
            .arg(&input)
            .arg("--machine")
            .arg(fixture("machines/gantry_ac.json"))
            .arg("--place")
            .arg("auto")
            .arg("--out")
            .arg(&out)
            .arg("-q")
            .output()
            .expect("run kerf");
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let report = read_json(&out.join("report.json"));
        let placement = &report["placement"];
        assert_eq!(
            placement["flipped_paths"] == serde_json::json!(["hole"]),
            turned,
            "{thickness:?}: {placement}"
        );
        // The tool axes as written: with the plate turned over by the placement, or the
        // contour turned, the beam comes from above either way.
        let axes = read_json(&out.join("axes.json"));
        assert!(axes["paths"].as_array().is_some_and(|p| !p.is_empty()));
        if !turned {
            let rot = placement["setups"][0]["rotation_deg"].clone();
            assert_ne!(
                rot,
                serde_json::json!([0.0, 0.0, 0.0]),
                "the part is turned: {rot}"
            );
        }
    }
}
