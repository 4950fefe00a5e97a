//! Helpers shared by the `kerf` binary's tests: the binary, the fixtures, and readers of
//! `kerf run`'s output files.

#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// The built `kerf` binary.
pub(crate) fn kerf() -> Command {
    Command::new(env!("CARGO_BIN_EXE_kerf"))
}

/// A file under `fixtures/`.
pub(crate) fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

/// A JSON file, parsed.
pub(crate) fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("read")).expect("JSON")
}

/// A JSON array of number arrays (points, poses, positions); empty if absent.
pub(crate) fn rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array()
        .map(|a| {
            a.iter()
                .map(|r| {
                    r.as_array()
                        .expect("row")
                        .iter()
                        .map(|x| x.as_f64().expect("number"))
                        .collect()
                })
                .collect()
        })
        .unwrap_or_default()
}

/// `kerf run CURVES --machine MACHINE --place auto --out DIR -q` on shipped fixtures (the
/// machine under `fixtures/machines/`), asserted to succeed; the directory holds its outputs.
pub(crate) fn run_auto(curves: &str, machine: &str) -> tempfile::TempDir {
    run_auto_with(curves, machine, &[])
}

/// [`run_auto`] with more arguments.
pub(crate) fn run_auto_with(curves: &str, machine: &str, more: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temporary directory");
    let out = kerf()
        .arg("run")
        .arg(fixture(curves))
        .arg("--machine")
        .arg(fixture("machines").join(machine))
        .args(["--place", "auto", "--out"])
        .arg(dir.path())
        .arg("-q")
        .args(more)
        .output()
        .expect("run kerf");
    assert!(
        out.status.success(),
        "kerf run {curves} on {machine}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    dir
}

/// `kerf run sheet_metal_holes.json -m gantry_ac.json -o OUT -q EXTRA...` (not placed): the
/// flat part's run, its outcome.
pub(crate) fn run_flat(extra: &[&str], out: &Path) -> std::process::Output {
    kerf()
        .args(["run"])
        .arg(fixture("sheet_metal_holes.json"))
        .arg("-m")
        .arg(fixture("machines/gantry_ac.json"))
        .arg("-o")
        .arg(out)
        .arg("-q")
        .args(extra)
        .output()
        .expect("kerf runs")
}
