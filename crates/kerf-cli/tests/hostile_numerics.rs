//! Issue 13 through the binary: hostile numerical inputs end at once with a certified result
//! or an error that gives the real reason, in readable numbers, naming the option to change.

use std::path::Path;
use std::process::{Command, Output};
mod common;
use common::fixture;

fn kerf(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
        .args(args)
        .output()
        .expect("kerf runs")
}

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn a_tolerance_below_the_margin_is_refused_with_the_smallest_that_works() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.json");
    let o = kerf(&[
        "discretize",
        path(&fixture("mixed.json")),
        "-t",
        "1e-12",
        "-o",
        path(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "bad input");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("use a tolerance of at least"), "{err}");
    assert!(err.contains("curves[0]"), "names the curve: {err}");
    assert!(!out.exists(), "no output written");
}

#[test]
fn too_many_points_names_the_option() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.json");
    let o = kerf(&[
        "discretize",
        path(&fixture("circle.json")),
        "-t",
        "0.001",
        "--max-points",
        "100",
        "-o",
        path(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "bad input");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--max-points"), "{err}");
    // A larger limit lets it through.
    let o = kerf(&[
        "discretize",
        path(&fixture("circle.json")),
        "-t",
        "0.001",
        "--max-points",
        "1000",
        "-o",
        path(&out),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `kerf discretize` writes each curve's points as they come (it never holds the whole output):
/// a curve that fails after others were written must still leave no output and no temporary
/// file, and an existing output untouched.
#[test]
fn a_curve_failing_midway_leaves_the_output_as_it_was() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.json");
    std::fs::write(&out, "old").expect("write");
    // mixed.json at 0.01 mm: 53, 2, 81 and 55 points; 60 refuses the third curve only.
    let o = kerf(&[
        "discretize",
        path(&fixture("mixed.json")),
        "-t",
        "0.01",
        "--max-points",
        "60",
        "-o",
        path(&out),
    ]);
    assert_eq!(o.status.code(), Some(1), "bad input");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("curves[2]"), "names the third curve: {err}");
    assert_eq!(
        std::fs::read_to_string(&out).expect("read"),
        "old",
        "untouched"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).expect("list").count(),
        1,
        "no temporary file left"
    );
}

#[test]
fn tiny_knots_and_subnormal_weights_are_cut_like_the_circle() {
    let dir = tempfile::tempdir().expect("tempdir");
    for name in [
        "hostile/hostile_tiny_knots.json",
        "hostile/hostile_subnormal_weights.json",
    ] {
        let out = dir.path().join("out.json");
        let o = kerf(&[
            "discretize",
            path(&fixture(name)),
            "-t",
            "0.001",
            "--json",
            "-o",
            path(&out),
        ]);
        assert!(
            o.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let summary: serde_json::Value =
            serde_json::from_slice(&o.stdout).expect("one JSON summary");
        let ratio = summary["segments_over_n_star"].as_f64().expect("ratio");
        assert!(
            ratio > 1.0 && ratio < 1.06,
            "{name}: segments / N* = {ratio}"
        );
        let check = Command::new(env!("CARGO_BIN_EXE_kerf"))
            .args(["check", path(&fixture(name)), path(&out)])
            .output()
            .expect("kerf check runs");
        assert!(
            check.status.success(),
            "{name}: independent check: {}{}",
            String::from_utf8_lossy(&check.stdout),
            String::from_utf8_lossy(&check.stderr)
        );
    }
    let o = kerf(&[
        "validate",
        path(&fixture("hostile/hostile_tiny_knots.json")),
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("[0, 1e-50]"), "readable domain: {text}");
}

#[test]
fn validate_and_run_end_on_the_small_hole_far_from_the_origin() {
    let o = kerf(&[
        "validate",
        path(&fixture("hostile/hostile_small_far_circle.json")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("0.314"),
        "length pi * 0.1 mm"
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let o = kerf(&[
        "run",
        path(&fixture("hostile/hostile_small_far_circle.json")),
        "-m",
        path(&fixture("machines/ac_head.json")),
        "-t",
        "0.001",
        "--out",
        path(dir.path()),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
