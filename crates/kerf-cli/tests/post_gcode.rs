//! `kerf gcode` and `kerf post` go through the same pipeline as `kerf run`: the program
//! `kerf gcode` writes from `kerf run`'s axes file is `kerf run`'s own program (the checked
//! traverses of the file's `traverse` keys included), and `kerf post` then `kerf gcode` gives
//! the program `kerf gcode` makes from the toolpath directly.
//!
//! The programs are compared block by block, byte for byte; only the comment lines differ
//! where they must: the source file's name, the set-up line `kerf run` adds, the
//! linearization term of the budget (an axes file does not record it) and the curve
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
