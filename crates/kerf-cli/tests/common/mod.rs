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

/// LinuxCNC's power coefficients replayed as the HAL of docs/process.md computes the tip
/// speed (`|XYZ' + E2..4 tilt' + E5..7 C'|` per unit of joint motion), against `tip_rate(end,
/// d)` (the true tip speed per unit of joint motion at `end` along `d`) at both ends of every
/// cutting move of `program` (beam codes `M64 P0` / `M65 P0`): each within `tolerance`.
/// `joints` turns a move line into the machine's joints (`None`: not a move). Returns the ends
/// checked, the moves that turn a rotary axis, and the worst relative error.
pub(crate) fn replay_power_coefficients(
    program: &str,
    joints: impl Fn(&str) -> Option<[f64; 5]>,
    tip_rate: impl Fn(&[f64; 5], &[f64; 5]) -> f64,
    tolerance: f64,
) -> (usize, usize, f64) {
    let mut e = [0.0f64; 8];
    let mut prev: Option<[f64; 5]> = None;
    let (mut checked, mut rotating, mut worst) = (0, 0, 0.0f64);
    let mut in_cut = false;
    for l in program.lines() {
        if let Some(rest) = l.strip_prefix("M67 E").or_else(|| l.strip_prefix("M68 E")) {
            let (n, v) = rest.split_once(" Q").expect("M67 E<n> Q<v>");
            e[n.parse::<usize>().expect("n")] = v.parse().expect("value");
            continue;
        }
        match l {
            "M64 P0" => in_cut = true,
            "M65 P0" => in_cut = false,
            _ => {}
        }
        let Some(q) = joints(l) else { continue };
        if let (Some(p), true, true) = (prev, in_cut, l.starts_with("G1")) {
            let d: [f64; 5] = std::array::from_fn(|k| q[k] - p[k]);
            let hal = (0..3)
                .map(|j| (d[j] + e[2 + j] * d[3] + e[5 + j] * d[4]).powi(2))
                .sum::<f64>()
                .sqrt();
            for end in [p, q] {
                let exact = tip_rate(&end, &d);
                if exact < 1e-3 * d.iter().map(|v| v.abs()).sum::<f64>() {
                    continue; // a turn in place: the tip stands (at the floor either way)
                }
                let err = (hal - exact).abs() / exact;
                worst = worst.max(err);
                assert!(
                    err <= tolerance,
                    "HAL's tip speed {hal} vs {exact} ({err}) at {l}"
                );
                checked += 1;
            }
            if d[3] != 0.0 || d[4] != 0.0 {
                rotating += 1;
            }
        }
        prev = Some(q);
    }
    (checked, rotating, worst)
}
