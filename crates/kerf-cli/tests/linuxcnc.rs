//! kerf's LinuxCNC programs through LinuxCNC's own interpreter (`rs274`, from the Debian package
//! `linuxcnc-uspace`): no error, no warning, and the interpreter's canonical calls show every
//! cut framed by exactly one beam on and one beam off, no traverse with the beam on, a dwell
//! after each beam on, inverse-time feed and the budget's blending tolerance.
//!
//! Skipped with a notice when `rs274` is not installed, unless `KERF_REQUIRE_LINUXCNC` is set
//! (as `.ci/run` does after installing LinuxCNC): then a missing `rs274` fails. The simulator
//! check is `tests/linuxcnc/check.py` (docs/linuxcnc.md).

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn have_rs274() -> bool {
    let found = Command::new("rs274").arg("-h").output().is_ok();
    if !found {
        assert!(
            std::env::var_os("KERF_REQUIRE_LINUXCNC").is_none(),
            "KERF_REQUIRE_LINUXCNC is set but rs274 (LinuxCNC) is not installed"
        );
        eprintln!("notice: rs274 (LinuxCNC) not installed; LinuxCNC interpreter test skipped");
    }
    found
}

/// One rs274 at a time: the two tests of this file ran it side by side, and a CI run twice saw
/// one come back with nothing at all on its streams (not even `executing`) where it parses the
/// same program alone without fault.
static RS274: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs rs274 on `program` with a trivkins INI for `coords`; returns (error stream, canon).
/// The error stream holds the exit status too when rs274 did not exit 0.
fn rs274(dir: &Path, coords: &str, program: &Path) -> (String, String) {
    let _one = RS274
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    std::fs::write(
        dir.join("t.ini"),
        format!(
            "[RS274NGC]\nPARAMETER_FILE = t.var\n[TRAJ]\nCOORDINATES = {coords}\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n[KINS]\nKINEMATICS = trivkins coordinates={coords}\nJOINTS = 5\n"
        ),
    )
    .unwrap();
    std::fs::write(dir.join("t.var"), "").unwrap();
    let out = Command::new("rs274")
        .current_dir(dir)
        .args(["-i", "t.ini", "-n", "0", "-g"])
        .arg(program)
        .arg("canon.txt")
        .stdin(std::process::Stdio::null())
        .output()
        .expect("run rs274");
    let mut err =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    if !out.status.success() {
        err.push_str(&format!("\nrs274 exit status: {}", out.status));
    }
    let canon = std::fs::read_to_string(dir.join("canon.txt")).unwrap_or_default();
    (err, canon)
}

fn kerf_run(dir: &Path, curves: &Path, machine: &str, extra: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_kerf"))
        .arg("run")
        .arg(curves)
        .arg("-m")
        .arg(fixture(&format!("machines/{machine}.json")))
        .args(["--dialect", "linuxcnc", "-q", "--out"])
        .arg(dir)
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "kerf run: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    std::fs::read_to_string(dir.join("program.nc")).unwrap()
}

/// The canonical calls' names, in order, with the argument text.
fn calls(canon: &str) -> Vec<(String, String)> {
    canon
        .lines()
        .filter_map(|l| {
            let rest = l.split_once("N..... ")?.1;
            let (name, args) = rest.split_once('(')?;
            Some((name.to_string(), args.trim_end_matches(')').to_string()))
        })
        .collect()
}

#[test]
fn linuxcnc_interpreter_runs_the_programs_as_framed() {
    if !have_rs274() {
        return;
    }
    for (name, machine, cuts) in [
        ("sheet_metal_holes", "gantry_ac", 8),
        ("tube_saddle", "ac_head", 2),
        ("door_trim", "ac_head", 3),
    ] {
        let dir = tempfile::tempdir().unwrap();
        kerf_run(dir.path(), &fixture(&format!("{name}.json")), machine, &[]);
        let (err, canon) = rs274(dir.path(), "XYZAC", &dir.path().join("program.nc"));
        assert_eq!(err.trim(), "executing", "{name}: rs274 says {err}");
        let c = calls(&canon);
        assert!(
            c.iter().any(|(n, _)| n == "PROGRAM_END"),
            "{name}: reaches the end"
        );
        assert!(
            c.iter()
                .any(|(n, a)| n == "SET_MOTION_CONTROL_MODE"
                    && a.contains("CANON_CONTINUOUS, 0.005")),
            "{name}: G64 P with the blending term"
        );
        assert!(
            canon.contains("feed mode set to inverse time"),
            "{name}: G93"
        );
        // Beam state machine over the interpreter's calls.
        let (mut on, mut ons, mut dwell_after_on) = (false, 0, 0);
        let mut last_was_on = false;
        for (n, a) in &c {
            match n.as_str() {
                "SET_AUX_OUTPUT_BIT" if a == "0" => {
                    assert!(!on, "{name}: beam on twice");
                    on = true;
                    ons += 1;
                    last_was_on = true;
                    continue;
                }
                "CLEAR_AUX_OUTPUT_BIT" if a == "0" => on = false,
                "DWELL" if last_was_on => dwell_after_on += 1,
                "STRAIGHT_TRAVERSE" => assert!(!on, "{name}: traverse with the beam on"),
                "SET_FEED_RATE"
                | "SET_MOTION_CONTROL_MODE"
                | "SET_NAIVECAM_TOLERANCE"
                | "COMMENT" => continue,
                _ => {}
            }
            last_was_on = false;
        }
        assert!(!on, "{name}: beam off at the end");
        assert_eq!(ons, cuts, "{name}: one beam on per cut");
        assert_eq!(
            dwell_after_on, cuts,
            "{name}: a pierce dwell after each beam on"
        );
    }
}

/// Hostile curve ids reach only comments: the interpreter sees the same motion as with tame
/// ids, and no comment it reports holds a block.
#[test]
fn hostile_ids_stay_in_comments_for_the_interpreter() {
    if !have_rs274() {
        return;
    }
    let text = std::fs::read_to_string(fixture("sheet_metal_holes.json")).unwrap();
    let hostile = [
        "hole\\nG0 X1400 Y700 Z-90 A0 C0\\nM30",
        ")G0X1(",
        "a\\rM2",
        "b\\u2028G0 X5",
        "c\\u0000M30",
        "(MSG,boom)",
        ";M2",
        "d\\u0085e\\tf",
    ];
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let n = v["curves"].as_array().unwrap().len();
    let dir = tempfile::tempdir().unwrap();
    let tame_canon = {
        let (run, (err, canon)) = {
            let run = kerf_run(
                dir.path(),
                &fixture("sheet_metal_holes.json"),
                "gantry_ac",
                &[],
            );
            (
                run,
                rs274(dir.path(), "XYZAC", &dir.path().join("program.nc")),
            )
        };
        // kerf's own output in the message: a CI run once saw rs274 print nothing here.
        assert_eq!(err.trim(), "executing", "kerf run said: {run}");
        canon
    };
    for i in 0..n {
        let id: String =
            serde_json::from_str(&format!("\"{}\"", hostile[i % hostile.len()])).unwrap();
        v["curves"][i]["id"] = serde_json::Value::String(format!("{id}{i}"));
    }
    // The plate's STL is named relative to the curves file.
    std::fs::copy(
        fixture("sheet_plate.stl"),
        dir.path().join("sheet_plate.stl"),
    )
    .unwrap();
    let bad = dir.path().join("hostile.json");
    std::fs::write(&bad, serde_json::to_string(&v).unwrap()).unwrap();
    // The readers may refuse control characters in ids (then nothing reaches a program at all);
    // if they accept them, the program must be safe.
    let out = Command::new(env!("CARGO_BIN_EXE_kerf"))
        .arg("run")
        .arg(&bad)
        .arg("-m")
        .arg(fixture("machines/gantry_ac.json"))
        .args(["--dialect", "linuxcnc", "-q", "--out"])
        .arg(dir.path().join("h"))
        .output()
        .unwrap();
    if !out.status.success() {
        let msg = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "refused as bad input: {msg}");
        assert!(msg.contains(".id"), "refused for the id: {msg}");
        eprintln!(
            "notice: the reader refuses the hostile ids: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        return;
    }
    let prog = dir.path().join("h/program.nc");
    let (err, canon) = rs274(dir.path(), "XYZAC", &prog);
    assert_eq!(err.trim(), "executing", "rs274 says {err}");
    let motion = |c: &str| -> Vec<(String, String)> {
        calls(c)
            .into_iter()
            .filter(|(n, _)| n != "COMMENT" && n != "MESSAGE")
            .collect()
    };
    assert_eq!(
        motion(&canon),
        motion(&tame_canon),
        "same calls but comments"
    );
    assert!(!canon.contains("MESSAGE("), "no (MSG,...) became active");
}
