//! The whole chain through the binary: run, post, interpolate, gcode, and what a failed run
//! leaves behind.

use std::process::Command;
mod common;
use common::{fixture, kerf, read_json};

fn ok(c: &mut Command) -> std::process::Output {
    let o = c.output().unwrap();
    assert!(
        o.status.success(),
        "{:?}: {}",
        c,
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

#[test]
fn run_writes_every_stage_and_they_agree() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    ok(kerf()
        .arg("run")
        .arg(fixture("dome.json"))
        .arg("-m")
        .arg(fixture("machines/ac_head.json"))
        .args(["-t", "0.01", "--out"])
        .arg(&out));
    for f in [
        "toolpath.json",
        "axes.json",
        "program.nc",
        "setpoints.csv",
        "report.json",
        "plot.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    let tp = kerf_format::toolpath::load(out.join("toolpath.json")).unwrap();
    assert!(
        tp.paths.iter().all(|p| p.points.has_normals()),
        "poses with normals"
    );
    assert!(
        tp.paths.iter().all(|p| p.max_chord_error <= 0.01),
        "certified"
    );
    let axes = kerf_kinematics::AxesFile::from_str(
        &std::fs::read_to_string(out.join("axes.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(
        axes.paths.len(),
        tp.paths.len(),
        "one axes path per toolpath path"
    );
    let csv = std::fs::read_to_string(out.join("setpoints.csv")).unwrap();
    assert!(csv.starts_with("t,X,Y,Z,A,C\n"), "CSV header as formats.md");
    let nc = std::fs::read_to_string(out.join("program.nc")).unwrap();
    assert!(
        nc.contains("dome-latitude-60"),
        "comments name the source curve"
    );
    let svg = std::fs::read_to_string(out.join("plot.svg")).unwrap();
    assert!(
        svg.starts_with("<?xml") || svg.starts_with("<svg"),
        "an SVG"
    );
    let report = read_json(&out.join("report.json"));
    assert_eq!(report["discretize"]["curves"], 2, "report counts curves");
    // The independent checker agrees with the toolpath.
    ok(kerf()
        .arg("check")
        .arg(fixture("dome.json"))
        .arg(out.join("toolpath.json")));
}

#[test]
fn a_failed_run_leaves_the_output_directory_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("keep.txt"), "before").unwrap();
    // The head-table machine's Y travel is too short for the dome: a limit error.
    let o = kerf()
        .arg("run")
        .arg(fixture("dome.json"))
        .arg("-m")
        .arg(fixture("machines/head_table.json"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(1),
        "limit violation exits 1: {stderr}"
    );
    assert!(
        stderr.contains("outside its limits"),
        "names the limit: {stderr}"
    );
    let names: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(
        names,
        vec!["keep.txt".to_string()],
        "nothing added, nothing left behind"
    );
    // Bad input: the same.
    let o = kerf()
        .arg("run")
        .arg(fixture("bad/decreasing_knots.json"))
        .arg("-m")
        .arg(fixture("machines/ac_head.json"))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "bad knots exit 1");
    assert_eq!(
        std::fs::read_dir(&out).unwrap().count(),
        1,
        "directory untouched"
    );
}

#[test]
fn post_interpolate_and_gcode_step_by_step() {
    let dir = tempfile::tempdir().unwrap();
    let tp = dir.path().join("dome.toolpath.json");
    let axes = dir.path().join("dome.axes.json");
    let csv = dir.path().join("dome.csv");
    let machine = fixture("machines/ac_head.json");
    ok(kerf()
        .arg("discretize")
        .arg(fixture("dome.json"))
        .args(["--normals", "-o"])
        .arg(&tp));
    ok(kerf()
        .arg("post")
        .arg(&tp)
        .arg("-m")
        .arg(&machine)
        .arg("-o")
        .arg(&axes));
    ok(kerf()
        .arg("interpolate")
        .arg(&axes)
        .arg("-m")
        .arg(&machine)
        .args(["--feed", "6000", "--cycle", "0.002", "--csv"])
        .arg(&csv));
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert!(rows.len() > 100, "one row per cycle");
    for w in rows.windows(2) {
        assert!((w[1][0] - w[0][0] - 0.002).abs() < 1e-9, "cycle spacing");
    }
    for dialect in ["generic", "sinumerik"] {
        let nc = dir.path().join(format!("dome.{dialect}.nc"));
        ok(kerf()
            .arg("gcode")
            .arg(&tp)
            .arg("-m")
            .arg(&machine)
            .args(["--feed", "6000", "--dialect", dialect, "-o"])
            .arg(&nc));
        let text = std::fs::read_to_string(&nc).unwrap();
        let want = if dialect == "generic" {
            "G1 X"
        } else {
            "TRAORI"
        };
        assert!(text.contains(want), "{dialect} program has {want}");
    }
    // `-o -` and `--csv -` write to standard output, and no file named `-`.
    let o = ok(kerf()
        .current_dir(dir.path())
        .arg("gcode")
        .arg(&axes)
        .arg("-m")
        .arg(&machine)
        .args(["--feed", "6000", "-o", "-"]));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("G1 X"),
        "program on stdout"
    );
    let o = ok(kerf()
        .current_dir(dir.path())
        .arg("interpolate")
        .arg(&axes)
        .arg("-m")
        .arg(&machine)
        .args(["--feed", "6000", "--csv", "-"]));
    assert!(
        String::from_utf8_lossy(&o.stdout).starts_with("t,X,Y,Z,A,C"),
        "CSV on stdout"
    );
    assert!(!dir.path().join("-").exists(), "no file named -");
    // A toolpath without normals cannot be posted.
    let flat = dir.path().join("flat.json");
    ok(kerf()
        .arg("discretize")
        .arg(fixture("mixed.json"))
        .arg("-o")
        .arg(&flat));
    let o = kerf()
        .arg("post")
        .arg(&flat)
        .arg("-m")
        .arg(&machine)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "exit 1");
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("no normals"),
        "says why"
    );
}

/// The generic program is run by a controller that moves the machine axes linearly between
/// two G1 lines: the tool tip must then stay within the linearization tolerance (plus the
/// 6-decimal rounding of the program) of the straight line between the two programmed tips.
#[test]
fn generic_gcode_keeps_the_non_linearity_within_its_tolerance() {
    let dir = tempfile::tempdir().unwrap();
    let nc = dir.path().join("blade.nc");
    let machine_file = fixture("machines/gantry_ac.json");
    ok(kerf()
        .arg("run")
        .arg(fixture("turbine_blade_edge.json"))
        .arg("-m")
        .arg(&machine_file)
        .args(["-q", "--out"])
        .arg(dir.path()));
    std::fs::rename(dir.path().join("program.nc"), &nc).unwrap();
    let machine = kerf_kinematics::Machine::read(&machine_file).unwrap();
    let k = machine.kinematics.clone();
    let mut last: Option<[f64; 5]> = None;
    let mut worst = 0.0f64;
    for line in std::fs::read_to_string(&nc).unwrap().lines() {
        let rapid = line.starts_with("G0");
        if !(line.starts_with("G1") || rapid) {
            continue;
        }
        let mut q = last.unwrap_or([0.0; 5]);
        for w in line.split_whitespace() {
            let (key, val) = w.split_at(1);
            let i = match key {
                "X" => 0,
                "Y" => 1,
                "Z" => 2,
                "A" => 3,
                "C" => 4,
                _ => continue,
            };
            q[i] = val.parse().unwrap();
        }
        if let (Some(p), false) = (last, rapid) {
            let tip = |a: &[f64; 5]| {
                k.forward(&kerf_kinematics::Axes::new(a[0], a[1], a[2], a[3], a[4]))
                    .position
            };
            let (t0, t1) = (tip(&p), tip(&q));
            for s in [0.25, 0.5, 0.75] {
                let mid: Vec<f64> = (0..5).map(|i| p[i] + s * (q[i] - p[i])).collect();
                let m = tip(&[mid[0], mid[1], mid[2], mid[3], mid[4]]);
                worst = worst.max(kerf_check::distance_to_segment(&m, &t0, &t1));
            }
        }
        last = Some(q);
    }
    assert!(worst > 0.0, "the check measured something");
    assert!(
        worst <= 0.005 + 1e-4,
        "tip leaves the line by {worst} mm between two G1 lines"
    );
}

#[test]
fn a_misspelt_machine_key_is_warned_about_even_when_quiet() {
    // `max_jerks` is read as absent (no jerk limit): the run goes on, and says so.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(fixture("machines/ac_head.json")).unwrap();
    let misspelt = text.replacen("\"max_jerk\"", "\"max_jerks\"", 1);
    assert_ne!(misspelt, text, "the fixture has max_jerk");
    let machine = dir.path().join("machine.json");
    std::fs::write(&machine, misspelt).unwrap();
    for command in [vec!["run", "-q", "--out"], vec!["post", "-o"]] {
        let out_path = dir.path().join(format!("out-{}", command[0]));
        let input = if command[0] == "run" {
            fixture("dome.json")
        } else {
            let tp = dir.path().join("dome.tp.json");
            ok(kerf()
                .arg("discretize")
                .arg(fixture("dome.json"))
                .args(["--normals", "-q", "-o"])
                .arg(&tp));
            tp
        };
        let o = ok(kerf()
            .arg(command[0])
            .arg(&input)
            .arg("--machine")
            .arg(&machine)
            .args(&command[1..])
            .arg(&out_path));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("machine.json: max_jerks: unknown key, did you mean \"max_jerk\"?"),
            "{}: {stderr}",
            command[0]
        );
    }
}

/// report.json goes with the program to whoever runs it, so it lists what the run warned about
/// on standard error: the curves file's and the machine file's near-miss keys (each read
/// without them), named by the file they came from.
#[test]
fn the_report_lists_the_input_files_warnings() {
    let dir = tempfile::tempdir().unwrap();
    let machine_text = std::fs::read_to_string(fixture("machines/ac_head.json")).unwrap();
    let machine = dir.path().join("machine.json");
    std::fs::write(
        &machine,
        machine_text.replacen("\"max_jerk\"", "\"max_jerks\"", 1),
    )
    .unwrap();
    let curves_text = std::fs::read_to_string(fixture("dome.json")).unwrap();
    // `scarp` (a swap away from `scrap`, which this curve lacks) on the first curve.
    let misspelt = curves_text.replacen("\"degree\"", "\"scarp\": true, \"degree\"", 1);
    assert_ne!(misspelt, curves_text);
    let curves = dir.path().join("dome.json");
    std::fs::write(&curves, misspelt).unwrap();
    let out = dir.path().join("out");
    ok(kerf()
        .arg("run")
        .arg(&curves)
        .arg("--machine")
        .arg(&machine)
        .args(["-q", "--out"])
        .arg(&out));
    let report = read_json(&out.join("report.json"));
    let warnings: Vec<&str> = report["warnings"]
        .as_array()
        .expect("a warnings list")
        .iter()
        .map(|w| w.as_str().expect("a string"))
        .collect();
    assert_eq!(
        warnings,
        [
            "curves file: curves[0].scarp: unknown key, did you mean \"scrap\"?",
            "machine file: max_jerks: unknown key, did you mean \"max_jerk\"?",
        ],
        "{report:#}"
    );
    // The same files spelt right: an empty list, not a missing key.
    let clean = dir.path().join("clean");
    ok(kerf()
        .arg("run")
        .arg(fixture("dome.json"))
        .arg("--machine")
        .arg(fixture("machines/ac_head.json"))
        .args(["-q", "--out"])
        .arg(&clean));
    let report = read_json(&clean.join("report.json"));
    assert_eq!(report["warnings"], serde_json::json!([]));
}
