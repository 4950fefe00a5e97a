//! The whole chain on every shipped fixture with surfaces, through the built `kerf` binary:
//! `validate`, `discretize --normals`, `check`, `post`, `interpolate`, `gcode` (generic and
//! Sinumerik; the other dialects have tests of their own) and `plot`, each output read back and
//! checked against the fixture and the machine.
//!
//! The fixtures come from `cargo run --release --example make_fixtures` (see
//! `fixtures/README.md`); the machines from `fixtures/machines/`.

use std::path::Path;
use std::process::Output;

use serde_json::Value;
mod common;
use common::{fixture, kerf};

const TOLERANCE: f64 = 0.01;
const FEED: &str = "6000";

/// Runs `kerf args...`, asserting success; returns standard output.
fn run(args: &[&std::ffi::OsStr]) -> String {
    let out = kerf().args(args).output().expect("run kerf");
    assert!(
        out.status.success(),
        "kerf {:?} failed ({}): {}",
        args,
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// Runs `kerf args...` expecting failure with status 1; returns standard error.
fn run_fails(args: &[&std::ffi::OsStr]) -> String {
    let out: Output = kerf().args(args).output().expect("run kerf");
    assert_eq!(
        out.status.code(),
        Some(1),
        "kerf {args:?} should fail with status 1: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stderr).expect("UTF-8 errors")
}

fn json(text: &str) -> Value {
    serde_json::from_str(text).unwrap_or_else(|e| panic!("JSON summary ({e}): {text}"))
}

/// The limits of a machine file: `(axis name, min, max)`, `None` for a continuous axis.
fn limits(machine: &Path) -> Vec<(String, Option<(f64, f64)>)> {
    let m = json(&std::fs::read_to_string(machine).expect("machine file"));
    m["limits"]
        .as_object()
        .expect("limits")
        .iter()
        .map(|(k, v)| {
            let range = v
                .as_array()
                .map(|r| (r[0].as_f64().expect("min"), r[1].as_f64().expect("max")));
            (k.clone(), range)
        })
        .collect()
}

/// Every stage on one fixture; `curves` is the number of curves it holds.
fn pipeline(name: &str, machine: &str, curves: usize) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let input = fixture(name);
    let machine = fixture("machines").join(machine);
    let stem = name.trim_end_matches(".json");
    let tp = dir.path().join(format!("{stem}.toolpath.json"));
    let axes = dir.path().join(format!("{stem}.axes.json"));
    let csv = dir.path().join(format!("{stem}.csv"));
    let nc = dir.path().join(format!("{stem}.nc"));
    let mpf = dir.path().join(format!("{stem}.mpf"));
    let svg = dir.path().join(format!("{stem}.svg"));

    // validate: the file is valid and every curve is carried by a surface.
    let v = json(&run(&[
        "validate".as_ref(),
        "--json".as_ref(),
        input.as_os_str(),
    ]));
    let listed = v["curves"].as_array().expect("curves");
    assert_eq!(listed.len(), curves, "{name}: curve count");
    for c in listed {
        assert!(
            c["surface"].is_string(),
            "{name}: {} has a surface",
            c["id"]
        );
    }

    // discretize --normals: certified chord error, every point on its surface.
    let d = json(&run(&[
        "discretize".as_ref(),
        input.as_os_str(),
        "--normals".as_ref(),
        "-t".as_ref(),
        "0.01".as_ref(),
        "-o".as_ref(),
        tp.as_os_str(),
        "--json".as_ref(),
    ]));
    assert!(
        d["max_chord_error"].as_f64().expect("max_chord_error") <= TOLERANCE,
        "{name}: {d}"
    );
    assert!(
        d["max_surface_distance"].as_f64().expect("distance") <= TOLERANCE,
        "{name}: {d}"
    );
    let toolpath = kerf_format::toolpath::load(&tp).expect("toolpath reads back");
    let file = kerf_format::curves::load(&input).expect("fixture loads");
    assert_eq!(toolpath.paths.len(), curves, "{name}: one path per curve");
    for (p, c) in toolpath.paths.iter().zip(&file.curves) {
        assert_eq!(p.id, c.id, "{name}: same ids, same order");
        assert!(p.points.has_normals(), "{name}: {} has normals", p.id);
        assert!(p.max_chord_error <= TOLERANCE, "{name}: {} bound", p.id);
        for &b in &c.curve.c0_breaks() {
            assert!(p.params.contains(&b), "{name}: {} keeps corner {b}", p.id);
        }
    }

    // check: the independent brute-force verification agrees.
    let report = json(&run(&[
        "check".as_ref(),
        input.as_os_str(),
        tp.as_os_str(),
        "--json".as_ref(),
    ]));
    assert_eq!(report["passed"], true, "{name}: kerf check: {report}");

    // post: machine axes within the machine's limits, non-linearity within tolerance.
    let s = json(&run(&[
        "post".as_ref(),
        tp.as_os_str(),
        "-m".as_ref(),
        machine.as_os_str(),
        "-o".as_ref(),
        axes.as_os_str(),
        "--json".as_ref(),
    ]));
    assert!(
        s["max_linearization_error"].as_f64().expect("lin") <= 0.005,
        "{name}: {s}"
    );
    let lim = limits(&machine);
    let axes_doc = json(&std::fs::read_to_string(&axes).expect("axes file"));
    assert_eq!(axes_doc["format"], "kerf.axes/1", "{name}: axes format");
    let paths = axes_doc["paths"].as_array().expect("paths");
    assert_eq!(paths.len(), curves, "{name}: one axes path per curve");
    let names: Vec<&str> = axes_doc["axes"]
        .as_array()
        .expect("axis names")
        .iter()
        .map(|a| a.as_str().expect("name"))
        .collect();
    for p in paths {
        for row in p["positions"].as_array().expect("positions") {
            for (k, axis) in names.iter().enumerate() {
                let x = row[k].as_f64().expect("number");
                let range = lim.iter().find(|(n, _)| n == axis).expect("limit").1;
                if let Some((lo, hi)) = range {
                    assert!(
                        (lo - 1e-9..=hi + 1e-9).contains(&x),
                        "{name}: {axis} = {x} outside [{lo}, {hi}]"
                    );
                }
            }
        }
    }

    // interpolate: one CSV row per cycle, time increasing, every axis within its limits.
    let i = json(&run(&[
        "interpolate".as_ref(),
        axes.as_os_str(),
        "-m".as_ref(),
        machine.as_os_str(),
        "--feed".as_ref(),
        FEED.as_ref(),
        "--fit-tolerance".as_ref(),
        "0.01".as_ref(),
        "--csv".as_ref(),
        csv.as_os_str(),
        "--json".as_ref(),
    ]));
    let text = std::fs::read_to_string(&csv).expect("CSV");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(header[0], "t", "{name}: CSV header {header:?}");
    assert_eq!(&header[1..], &names[..], "{name}: CSV header {header:?}");
    let mut rows = 0;
    let mut last_t = f64::NEG_INFINITY;
    for line in lines {
        let v: Vec<f64> = line
            .split(',')
            .map(|x| x.parse().expect("number"))
            .collect();
        assert!(v[0] > last_t, "{name}: time increases at row {rows}");
        last_t = v[0];
        for (k, axis) in names.iter().enumerate() {
            if let Some((lo, hi)) = lim.iter().find(|(n, _)| n == axis).expect("limit").1 {
                assert!(
                    (lo - 1e-9..=hi + 1e-9).contains(&v[k + 1]),
                    "{name}: set-point {axis} = {} outside [{lo}, {hi}]",
                    v[k + 1]
                );
            }
        }
        rows += 1;
    }
    // The first row is the start position at t = 0, then one row per cycle.
    assert_eq!(
        rows as u64,
        i["cycles"].as_u64().expect("cycles") + 1,
        "{name}: the start and one row per cycle"
    );

    // gcode, generic and Sinumerik: one program, every curve announced.
    for (dialect, out) in [("generic", &nc), ("sinumerik", &mpf)] {
        run(&[
            "gcode".as_ref(),
            axes.as_os_str(),
            "-m".as_ref(),
            machine.as_os_str(),
            "--feed".as_ref(),
            FEED.as_ref(),
            "--fit-tolerance".as_ref(),
            "0.01".as_ref(),
            "--dialect".as_ref(),
            dialect.as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
            "-q".as_ref(),
        ]);
        let program = std::fs::read_to_string(out).expect("program");
        assert!(
            program.contains("\nG1 ") || program.contains("\nCIP "),
            "{name} {dialect}: moves"
        );
        for c in &file.curves {
            assert!(
                program.contains(&format!("; curve {}", c.id)),
                "{name} {dialect}: curve {} announced",
                c.id
            );
        }
    }

    // plot: one SVG with the axes chart.
    run(&[
        "plot".as_ref(),
        input.as_os_str(),
        tp.as_os_str(),
        "--axes".as_ref(),
        axes.as_os_str(),
        "-m".as_ref(),
        machine.as_os_str(),
        "-o".as_ref(),
        svg.as_os_str(),
        "-q".as_ref(),
    ]);
    let picture = std::fs::read_to_string(&svg).expect("SVG");
    assert!(
        picture.contains("<svg") && picture.trim_end().ends_with("</svg>"),
        "{name}: a whole SVG"
    );
}

#[test]
fn door_trim_on_the_ac_head() {
    pipeline("door_trim.json", "ac_head.json", 3);
}

#[test]
fn tube_saddle_on_the_exact_cylinders() {
    pipeline("tube_saddle.json", "ac_head.json", 2);
}

#[test]
fn tube_saddle_on_the_stl_tube() {
    pipeline("tube_saddle_stl.json", "ac_head.json", 1);
}

#[test]
fn turbine_blade_edge_on_the_large_gantry() {
    pipeline("turbine_blade_edge.json", "gantry_ac.json", 1);
}

#[test]
fn sheet_metal_part_on_the_stl_plate() {
    pipeline("sheet_metal_holes.json", "ac_head.json", 8);
}

#[test]
fn dome_on_the_ac_head() {
    pipeline("dome.json", "ac_head.json", 2);
}

/// The 3.5 m blade does not fit the 3 m gantry of `ac_head.json`: `kerf post` says which axis
/// and leaves no output file.
#[test]
fn turbine_blade_edge_exceeds_the_small_gantry() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let tp = dir.path().join("blade.toolpath.json");
    let axes = dir.path().join("blade.axes.json");
    run(&[
        "discretize".as_ref(),
        fixture("turbine_blade_edge.json").as_os_str(),
        "--normals".as_ref(),
        "-o".as_ref(),
        tp.as_os_str(),
        "-q".as_ref(),
    ]);
    let err = run_fails(&[
        "post".as_ref(),
        tp.as_os_str(),
        "-m".as_ref(),
        fixture("machines/ac_head.json").as_os_str(),
        "-o".as_ref(),
        axes.as_os_str(),
    ]);
    assert!(
        err.contains("X = ") && err.contains("outside its limits [-1500, 1500]"),
        "names the axis and its limits: {err}"
    );
    assert!(!axes.exists(), "no partial output");
}

/// The STL tube's facets lie up to their sagitta (0.0074 mm) inside the exact cylinder the
/// curve is on: within the default on-surface tolerance, refused at 0.005 mm.
#[test]
fn stl_sagitta_against_the_on_surface_tolerance() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let tp = dir.path().join("saddle.toolpath.json");
    let input = fixture("tube_saddle_stl.json");
    let d = json(&run(&[
        "discretize".as_ref(),
        input.as_os_str(),
        "--normals".as_ref(),
        "-o".as_ref(),
        tp.as_os_str(),
        "--json".as_ref(),
    ]));
    let distance = d["max_surface_distance"].as_f64().expect("distance");
    assert!(
        (0.005..0.0075).contains(&distance),
        "up to the sagitta 60 (1 - cos(pi / 200)) = 0.0074 mm: {distance}"
    );
    std::fs::remove_file(&tp).expect("remove");
    let err = run_fails(&[
        "discretize".as_ref(),
        input.as_os_str(),
        "--normals".as_ref(),
        "--on-surface-tolerance".as_ref(),
        "0.005".as_ref(),
        "-o".as_ref(),
        tp.as_os_str(),
    ]);
    assert!(
        err.contains("does not lie on the surface"),
        "off-surface error: {err}"
    );
    assert!(!tp.exists(), "no partial output");
}

/// The same input gives the same bytes: discretize twice.
#[test]
fn discretize_with_normals_is_deterministic() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let (a, b) = (dir.path().join("a.json"), dir.path().join("b.json"));
    for out in [&a, &b] {
        run(&[
            "discretize".as_ref(),
            fixture("door_trim.json").as_os_str(),
            "--normals".as_ref(),
            "-o".as_ref(),
            out.as_os_str(),
            "-q".as_ref(),
        ]);
    }
    assert_eq!(
        std::fs::read(&a).expect("a"),
        std::fs::read(&b).expect("b"),
        "bit for bit"
    );
}
