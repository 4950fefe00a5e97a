//! `kerf gcode` and `kerf post` go through the same pipeline as `kerf run`: the program
//! `kerf gcode` writes from `kerf run`'s axes file is `kerf run`'s own program (the checked
//! traverses of the file's `traverse` keys included), and `kerf post` then `kerf gcode` gives
//! the program `kerf gcode` makes from the toolpath directly.
//!
//! The programs are compared block by block, byte for byte; only the comment lines differ
//! where they must: the source file's name, the set-up line `kerf run` adds, the chord and
//! linearization terms of the budget (an axes file records neither) and the curve
//! parameter of each path's start (an axes file has no parameters).

use std::path::Path;

mod common;
use common::{fixture, kerf};

/// The program's blocks: every line but the comments (`;` or `(`).
fn blocks(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .expect("program")
        .lines()
        .filter(|l| !(l.starts_with(';') || l.starts_with('(')))
        .map(str::to_owned)
        .collect()
}

fn ok(c: &mut std::process::Command) {
    let o = c.output().expect("kerf runs");
    assert!(
        o.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn gcode_on_the_axes_of_run_is_runs_program() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = fixture("machines/ac_head.json");
    for dialect in ["generic", "linuxcnc"] {
        let out = dir.path().join(format!("run-{dialect}"));
        ok(kerf()
            .arg("run")
            .arg(fixture("door_trim.json"))
            .arg("--machine")
            .arg(&machine)
            .args(["--dialect", dialect, "-q", "--out"])
            .arg(&out));
        let axes = out.join("axes.json");
        let text = std::fs::read_to_string(&axes).expect("axes");
        assert!(
            text.contains("\"traverse\""),
            "the part has checked traverses to honour"
        );
        // `kerf gcode` on run's axes file, with run's feed and fit, plus `extra` options.
        let gcode_of = |extra: &[&str], program: &std::path::Path| {
            ok(kerf()
                .arg("gcode")
                .arg(&axes)
                .arg("-m")
                .arg(&machine)
                .args([
                    "-f",
                    "6000",
                    "--fit-tolerance",
                    "0.01",
                    "--dialect",
                    dialect,
                ])
                .args(extra)
                .args(["-q", "-o"])
                .arg(program));
        };
        let gcode = dir.path().join(format!("{dialect}.nc"));
        gcode_of(&[], &gcode);
        let run = blocks(&out.join("program.nc"));
        let from_axes = blocks(&gcode);
        assert!(run.len() > 100, "{dialect}: a real program");
        assert_eq!(run, from_axes, "{dialect}: kerf gcode on run's axes");

        // `--clearance 0`: the unchecked retract instead of the recorded traverses.
        let unchecked = dir.path().join(format!("{dialect}-unchecked.nc"));
        gcode_of(&["--clearance", "0"], &unchecked);
        assert_ne!(
            blocks(&unchecked),
            run,
            "{dialect}: without the recorded traverses the rapids differ"
        );
    }
}

#[test]
fn post_then_gcode_is_gcode_on_the_toolpath() {
    let dir = tempfile::tempdir().expect("tempdir");
    let machine = fixture("machines/ac_head.json");
    let toolpath = dir.path().join("part.toolpath.json");
    ok(kerf()
        .arg("discretize")
        .arg(fixture("dome.json"))
        .args(["--normals", "-t", "0.01", "-q", "-o"])
        .arg(&toolpath));
    let axes = dir.path().join("part.axes.json");
    ok(kerf()
        .arg("post")
        .arg(&toolpath)
        .arg("-m")
        .arg(&machine)
        .args(["-q", "-o"])
        .arg(&axes));
    let gcode = |input: &Path, name: &str| {
        let out = dir.path().join(name);
        ok(kerf()
            .arg("gcode")
            .arg(input)
            .arg("-m")
            .arg(&machine)
            .args(["-f", "6000", "--fit-tolerance", "0.01", "-q", "-o"])
            .arg(&out));
        blocks(&out)
    };
    let direct = gcode(&toolpath, "direct.nc");
    assert!(direct.len() > 10, "a real program");
    assert_eq!(gcode(&axes, "posted.nc"), direct, "post then gcode");
}

#[test]
fn gcode_with_curves_certifies_the_toolpath_or_writes_nothing() {
    // A toolpath from `kerf discretize`: with its curves the header states the chord term as
    // proven; a copy whose first path lost most of its points is refused with exit status 1,
    // the path named, and no program left behind.
    let dir = tempfile::tempdir().expect("tempdir");
    let curves = fixture("door_trim.json");
    let machine = fixture("machines/ac_head.json");
    let tp = dir.path().join("door.toolpath.json");
    ok(kerf()
        .arg("discretize")
        .arg(&curves)
        .args(["-t", "0.01", "--normals", "-q", "-o"])
        .arg(&tp));
    let gcode = |toolpath: &Path, program: &Path| {
        kerf()
            .arg("gcode")
            .arg(toolpath)
            .arg("-m")
            .arg(&machine)
            .args(["-f", "6000", "-q", "--curves"])
            .arg(&curves)
            .arg("-o")
            .arg(program)
            .output()
            .expect("kerf runs")
    };
    let good = dir.path().join("good.nc");
    let o = gcode(&tp, &good);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&good).expect("program");
    assert!(
        text.contains("tolerance budget mm: chord 0.01 + ") && !text.contains("claim"),
        "certified chord term"
    );
    let mut doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&tp).expect("toolpath")).expect("JSON");
    let path = &mut doc["paths"][0];
    let n = path["params"].as_array().expect("params").len();
    for key in ["params", "points"] {
        let all = path[key].as_array().expect("array").clone();
        let kept: Vec<_> = all
            .iter()
            .enumerate()
            .filter(|(i, _)| *i == 0 || *i == n - 1 || i % 5 == 0)
            .map(|(_, v)| v.clone())
            .collect();
        path[key] = serde_json::Value::Array(kept);
    }
    let kept = path["params"].as_array().expect("params").len();
    path["point_count"] = kept.into();
    let thinned = dir.path().join("thinned.toolpath.json");
    std::fs::write(&thinned, doc.to_string()).expect("write");
    let bad = dir.path().join("bad.nc");
    let o = gcode(&thinned, &bad);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("paths[0]") && err.contains("not certified against its curve"),
        "{err}"
    );
    assert!(!bad.exists(), "no program from an uncertified toolpath");
}
