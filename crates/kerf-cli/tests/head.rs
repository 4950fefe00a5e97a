//! The head check from the command line: the library's messages name its options
//! (`tilt_tolerance_deg`, `accept_head_collisions`), the command line adds the flags a process
//! engineer types, and following the refusal's advice gets the program.

mod common;

use common::{fixture, kerf};

/// `kerf run` of the U-channel's trim line on the gantry (the head checked at its default 1 mm
/// unless `extra` says otherwise).
fn run(extra: &[&str]) -> (std::process::Output, tempfile::TempDir) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = kerf()
        .arg("run")
        .arg(fixture("head_channel.json"))
        .arg("--machine")
        .arg(fixture("machines/gantry_ac.json"))
        .args(extra)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .expect("run kerf");
    (out, dir)
}

#[test]
fn the_refusal_names_the_flag_that_clears_it_and_the_flag_works() {
    // The trim line inside the narrow channel: the straight-down head meets its wall.
    let (out, dir) = run(&[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!dir.path().join("out").exists(), "nothing written");
    assert!(
        err.contains("a tilt_tolerance_deg of 6 allows it")
            && err.contains(
                "[options: --accept-head-collisions, --tilt-tolerance (degrees), --cut-clearance]"
            ),
        "{err}"
    );
    // The tolerance it names clears it.
    let (out, dir) = run(&["--tilt-tolerance", "6"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = common::read_json(&dir.path().join("out/report.json"));
    let path = &report["head"]["paths"][0];
    assert_eq!(path["proven"], true, "{path}");
    assert!(
        path["min_distance_mm"].as_f64().expect("distance") >= 1.0
            && path["tilted"]["cutting_points"].as_u64() > Some(0),
        "tilted to clear the 1 mm: {path}"
    );
    // Accepted as a warning, the warning names the flag that accepted it.
    let (out, _dir) = run(&["--accept-head-collisions"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("(accepted: accept_head_collisions)")
            && err.contains("[options: --accept-head-collisions, --tilt-tolerance (degrees)]"),
        "{err}"
    );
}

/// The head is checked by default at 1 mm (the report says so); `--cut-clearance off` leaves it
/// out (the channel's trim line then runs upright into the wall, the report says unchecked);
/// a clearance that is neither a size nor `off` is a usage error.
#[test]
fn the_check_is_on_by_default_and_off_turns_it_off() {
    let (out, dir) = run(&[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "refused by default: {err}");
    assert!(
        err.contains("the head comes too close") && err.contains("(clearance 1 mm)"),
        "{err}"
    );
    assert!(!dir.path().join("out").exists(), "nothing written");
    let (out, dir) = run(&["--accept-head-collisions"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = common::read_json(&dir.path().join("out/report.json"));
    assert_eq!(report["head"]["checked"], true, "{}", report["head"]);
    assert_eq!(report["head"]["clearance_mm"], 1.0, "{}", report["head"]);
    let (out, dir) = run(&["--cut-clearance", "off"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = common::read_json(&dir.path().join("out/report.json"));
    assert_eq!(report["head"]["checked"], false, "{}", report["head"]);
    let (out, _dir) = run(&["--cut-clearance", "off", "--accept-head-collisions"]);
    assert_eq!(
        out.status.code(),
        Some(2),
        "nothing to accept with the check off"
    );
    for bad in ["0", "-1", "nan", "of"] {
        let (out, _dir) = run(&["--cut-clearance", bad]);
        assert_eq!(out.status.code(), Some(2), "--cut-clearance {bad}");
    }
}
