//! `kerf run --micro-joints LENGTH,SPACING` (issue 29): the program replayed block by block
//! (the beam state as LinuxCNC applies its codes: `M64`/`M65` at once, `M62`/`M63` where the
//! next move starts) must leave exactly the report's joints dark, each `LENGTH` long, at its
//! planned place, none within 1 mm of a corner of the path, as many per contour as the rule
//! gives; the options and the dialects that cannot write them are refused. The controller's
//! execution is checked in tests/linuxcnc/check.py.

mod common;
use common::{fixture, kerf};

use common::run_flat as run;

/// The tool tip of a block's axes (workpiece frame), from kerf's forward kinematics.
fn tip(m: &kerf_kinematics::Machine, line: &str) -> Option<[f64; 3]> {
    let v: Vec<f64> = ['X', 'Y', 'Z', 'A', 'C']
        .iter()
        .filter_map(|&n| {
            line.split_whitespace()
                .find(|w| w.starts_with(n))
                .and_then(|w| w[1..].parse().ok())
        })
        .collect();
    (v.len() == 5).then(|| {
        let p = m
            .kinematics
            .forward(&kerf_kinematics::Axes::from_array([
                v[0], v[1], v[2], v[3], v[4],
            ]))
            .position;
        [p.x, p.y, p.z]
    })
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// One dark stretch of a cut: the curve, its start and end points and its length.
struct Dark {
    id: String,
    start: [f64; 3],
    end: [f64; 3],
    length: f64,
}

/// The flat part in `dialect` with joints of 0.5 mm every 40 mm: its program and report.
fn with_joints(dialect: &str) -> (String, serde_json::Value, String) {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let r = run(&["--dialect", dialect, "--micro-joints", "0.5,40"], &out);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let program = std::fs::read_to_string(out.join("program.nc")).expect("program");
    let plot = std::fs::read_to_string(out.join("plot.svg")).expect("plot");
    (program, common::read_json(&out.join("report.json")), plot)
}

/// How many joints the report plans (and the picture marks: one bar a joint in each of its
/// four views).
fn joints_in(report: &serde_json::Value) -> usize {
    report["micro_joints"]["paths"]
        .as_array()
        .expect("paths")
        .iter()
        .map(|p| p["joints"].as_array().expect("joints").len())
        .sum()
}

#[test]
fn the_joints_are_dark_where_the_report_plans_them_and_nowhere_else() {
    let (program, report, plot) = with_joints("linuxcnc");
    let m = kerf_kinematics::Machine::read(fixture("machines/gantry_ac.json")).expect("machine");
    // Replay: the beam state each move runs with, the moves of each cut after its descent.
    let (mut id, mut beam, mut pending) = (String::new(), false, None::<bool>);
    let mut last: Option<[f64; 3]> = None;
    let mut in_cut = false;
    let mut dark: Vec<Dark> = Vec::new();
    let mut cut_moves: Vec<(String, [f64; 3], [f64; 3], bool)> = Vec::new();
    for l in program.lines() {
        if let Some(rest) = l.strip_prefix("(curve ") {
            id = rest.split(',').next().expect("id").to_string();
        }
        match l {
            "M64 P0" => (beam, in_cut) = (true, true),
            "M65 P0" => (beam, in_cut) = (false, false),
            "M62 P0" => pending = Some(true),
            "M63 P0" => pending = Some(false),
            _ => {}
        }
        let Some(p) = tip(&m, l) else { continue };
        if let Some(b) = pending.take() {
            beam = b;
        }
        if let (Some(a), true, true) = (last, in_cut, l.starts_with("G1")) {
            cut_moves.push((id.clone(), a, p, beam));
            if !beam {
                match dark.last_mut() {
                    Some(d) if d.end == a && d.id == id => {
                        d.end = p;
                        d.length += dist(&a, &p);
                    }
                    _ => dark.push(Dark {
                        id: id.clone(),
                        start: a,
                        end: p,
                        length: dist(&a, &p),
                    }),
                }
            }
        }
        last = Some(p);
    }
    let planned: Vec<(String, [f64; 3], [f64; 3], f64)> = report["micro_joints"]["paths"]
        .as_array()
        .expect("paths")
        .iter()
        .flat_map(|p| {
            let id = p["id"].as_str().expect("id").to_string();
            p["joints"]
                .as_array()
                .expect("joints")
                .iter()
                .map(move |j| {
                    let v = |k: &str| -> [f64; 3] {
                        std::array::from_fn(|i| j[k][i].as_f64().expect("coordinate"))
                    };
                    let len =
                        j["end_mm"].as_f64().expect("end") - j["start_mm"].as_f64().expect("start");
                    (id.clone(), v("start"), v("end"), len)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(
        dark.len(),
        planned.len(),
        "dark stretches against planned joints"
    );
    for (d, (pid, start, end, len)) in dark.iter().zip(&planned) {
        assert_eq!(&d.id, pid);
        assert!((len - 0.5).abs() < 1e-9, "{pid}: planned {len} mm");
        assert!(
            (d.length - 0.5).abs() < 1e-4,
            "{pid}: dark over {} mm",
            d.length
        );
        // The program's coordinates carry 6 decimals.
        assert!(
            dist(&d.start, start) < 1e-5,
            "{pid}: dark from {:?}, planned {start:?}",
            d.start
        );
        assert!(
            dist(&d.end, end) < 1e-5,
            "{pid}: dark to {:?}, planned {end:?}",
            d.end
        );
        // No corner of the path (a turn above 20 degrees between two moves) within 1 mm.
        for w in cut_moves.windows(2) {
            let ((ia, a0, a1, _), (ib, _, b1, _)) = (&w[0], &w[1]);
            if ia != pid || ib != pid || dist(a0, a1) < 1e-9 || dist(a1, b1) < 1e-9 {
                continue;
            }
            let u: [f64; 3] = std::array::from_fn(|k| a1[k] - a0[k]);
            let v: [f64; 3] = std::array::from_fn(|k| b1[k] - a1[k]);
            let cos = (u[0] * v[0] + u[1] * v[1] + u[2] * v[2]) / (dist(a1, a0) * dist(b1, a1));
            if cos < 20f64.to_radians().cos() {
                let near = dist(a1, &d.start).min(dist(a1, &d.end));
                assert!(near >= 1.0 - 1e-6, "{pid}: a corner {near} mm from a joint");
            }
        }
    }
    // How many per contour: max(1, round(P / 40)) on the outline, floor(P / 40) on cut-outs
    // (none on the 10 mm holes: 31 mm round).
    let count = |id: &str| planned.iter().filter(|p| p.0 == id).count();
    assert_eq!(count("hole-d10-1"), 0);
    let hole_70 = std::f64::consts::PI * 70.0;
    assert_eq!(count("hole-d70"), (hole_70 / 40.0).floor() as usize);
    assert!(count("outline") >= 1);
    // The picture marks them: one bar a joint in each of the four views.
    assert_eq!(
        plot.matches("class=\"micro-joint\"").count(),
        4 * planned.len()
    );
    // The beam is on everywhere else on the cuts.
    let lit = cut_moves.iter().filter(|m| m.3).count();
    assert!(lit > 600, "{lit} lit moves");
}

#[test]
fn micro_joints_that_cannot_be_written_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases: [(&[&str], &str, i32); 6] = [
        (&["--micro-joints", "0,40"], "LENGTH", 2),
        (&["--micro-joints", "11,40"], "LENGTH", 2),
        (&["--micro-joints", "5,3"], "SPACING", 2),
        (&["--micro-joints", "5,5"], "less than SPACING", 2),
        (
            &["--micro-joints", "0.5,40", "--dialect", "sinumerik"],
            "micro-joints are written for the linuxcnc and generic dialects",
            1,
        ),
        (
            &[
                "--micro-joints",
                "0.5,40",
                "--dialect",
                "linuxcnc",
                "--kerf-width",
                "0.2",
                "--kerf-in-control",
            ],
            "while the controller compensates",
            1,
        ),
    ];
    for (k, (args, want, code)) in cases.iter().enumerate() {
        let out = dir.path().join(format!("out{k}"));
        let r = run(args, &out);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(*code), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(
            !out.join("program.nc").exists(),
            "{args:?}: nothing written"
        );
    }
}

#[test]
fn the_generic_dialect_switches_with_the_machines_codes_between_blocks() {
    let (program, report, _) = with_joints("generic");
    let joints = joints_in(&report);
    let cuts = report["program"]["cuts"].as_u64().expect("cuts") as usize;
    // One beam-on per cut and one per joint; one beam-off per joint, per cut and the preamble's.
    assert_eq!(program.matches("\nM3\n").count(), cuts + joints);
    assert_eq!(program.matches("\nM5\n").count(), cuts + joints + 1);
}

/// A real sheet-metal part (placed in several set-ups) with a technology and micro-joints:
/// every joint the report plans is switched off and on again with motion in the programs,
/// every cut's power is commanded.
#[test]
fn a_real_part_runs_with_technology_and_micro_joints() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let r = kerf()
        .args(["run"])
        .arg(fixture("realdata/nori_sheetmetal.json"))
        .arg("-m")
        .arg(fixture("machines/gantry_ac.json"))
        .args(["--place", "auto", "--dialect", "linuxcnc", "--technology"])
        .arg(fixture("technology/fiber_3kw_example.json"))
        .args(["--material", "mild steel", "--thickness", "2"])
        // Bend edges: the head meets the flanges on their inner radius (the head's own tests).
        .args(["--cut-clearance", "off"])
        .args(["--micro-joints", "0.4,50", "-q", "-o"])
        .arg(&out)
        .output()
        .expect("kerf runs");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let joints = joints_in(&common::read_json(&out.join("report.json")));
    assert!(joints >= 8, "{joints} joints");
    let (mut off, mut on, mut cuts, mut scaled) = (0, 0, 0, 0);
    for entry in std::fs::read_dir(&out).expect("dir") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "nc") {
            let text = std::fs::read_to_string(&path).expect("program");
            off += text.matches("\nM63 P0\n").count();
            on += text.matches("\nM62 P0\n").count();
            cuts += text.matches("\nM64 P0\n").count();
            scaled += text.matches("\nM67 E0 Q").count();
        }
    }
    assert_eq!(
        (off, on),
        (joints, joints),
        "every joint switched with motion"
    );
    assert_eq!(scaled, cuts, "every cut's power commanded");
    assert!(cuts > 0);
}

/// A technology entry's `micro_joints` are the run's unless `--micro-joints` names others.
#[test]
fn a_technology_entry_sets_the_default_joints() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = dir.path().join("table.json");
    std::fs::write(
        &table,
        r#"{"format": "kerf.technology/1", "entries": [{"material": "steel", "thickness_mm": 2, "feed_mm_per_min": 4000, "power_percent": 80, "micro_joints": {"length_mm": 0.3, "spacing_mm": 60}}]}"#,
    )
    .expect("write");
    let table = table.to_str().expect("path");
    for (extra, want) in [
        (&[][..], (0.3, 60.0)),
        (&["--micro-joints", "0.5,40"][..], (0.5, 40.0)),
    ] {
        let out = dir.path().join(format!("out{}", extra.len()));
        let mut args = vec!["--technology", table, "--material", "steel"];
        args.extend_from_slice(extra);
        let r = run(&args, &out);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let report = common::read_json(&out.join("report.json"));
        let mj = &report["micro_joints"];
        assert_eq!(
            (mj["length_mm"].as_f64(), mj["spacing_mm"].as_f64()),
            (Some(want.0), Some(want.1))
        );
        assert!(joints_in(&report) > 0);
    }
}
