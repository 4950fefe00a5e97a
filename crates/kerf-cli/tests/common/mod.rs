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

/// The words of an NC block: each address (its leading letters: `X`, `TX`, `G`) with the
/// number after it (a sign allowed: `X+1.5`); words without a number (`FMAX`, `LN`) are left
/// out.
pub(crate) fn nc_words(line: &str) -> Vec<(String, f64)> {
    line.split_whitespace()
        .filter_map(|w| {
            let split = w.find(|c: char| !c.is_ascii_alphabetic())?;
            let (address, number) = w.split_at(split);
            Some((address.to_string(), number.parse().ok()?))
        })
        .collect()
}

/// The number of the word with address `address` in an NC block.
pub(crate) fn nc_word(line: &str, address: &str) -> Option<f64> {
    nc_words(line)
        .into_iter()
        .find(|(a, _)| a == address)
        .map(|(_, v)| v)
}

/// The cutting lines of a program (the lines `is_move` accepts between the beam-on line `on`
/// and the beam-off line `off`), each cut after a mark (`None`).
pub(crate) fn cut_lines(
    p: &str,
    on: &str,
    off: &str,
    is_move: impl Fn(&str) -> bool,
) -> Vec<Option<String>> {
    let mut cut = false;
    let mut out = Vec::new();
    for l in p.lines() {
        if l == on {
            cut = true;
            out.push(None);
        } else if l == off {
            cut = false;
        } else if cut && is_move(l) {
            out.push(Some(l.to_string()));
        }
    }
    out
}

/// A cutting move of a tool-tip program read back: the tip, the tool direction or the rotary
/// axes, and `F` (mm/min of the tip).
pub(crate) struct TipMove {
    pub(crate) tip: [f64; 3],
    pub(crate) direction: Option<[f64; 3]>,
    pub(crate) rotary: Option<[f64; 2]>,
    pub(crate) feed: f64,
}

impl TipMove {
    /// The move of the block `l`: `X Y Z`, the direction's three addresses or the rotary
    /// axes' two (one of them given), `F`.
    pub(crate) fn read(l: &str, direction: Option<[&str; 3]>, rotary: Option<[&str; 2]>) -> Self {
        let w = |a: &str| nc_word(l, a).unwrap_or_else(|| panic!("{a} in {l}"));
        Self {
            tip: [w("X"), w("Y"), w("Z")],
            direction: direction.map(|d| d.map(w)),
            rotary: rotary.map(|r| r.map(w)),
            feed: w("F"),
        }
    }
}

/// The program `kerf run` writes for `curves` on `machine` in `dialect`, with the `extra`
/// arguments; the run must succeed.
pub(crate) fn run_program(curves: &Path, machine: &Path, dialect: &str, extra: &[&str]) -> String {
    let dir = tempfile::tempdir().expect("tmp");
    let r = kerf()
        .args(["run"])
        .arg(curves)
        .arg("-m")
        .arg(machine)
        .args(extra)
        .args(["--dialect", dialect, "-q", "-o"])
        .arg(dir.path())
        .output()
        .expect("kerf runs");
    assert!(
        r.status.success(),
        "{dialect}: {}",
        String::from_utf8_lossy(&r.stderr)
    );
    std::fs::read_to_string(dir.path().join("program.nc")).expect("program")
}

/// How closely a tool-tip program must read back as the joint-space program.
pub(crate) struct ReadBack {
    /// The tip, mm.
    pub(crate) tip_mm: f64,
    /// The tool direction (unit vectors' difference).
    pub(crate) direction: f64,
    /// The rotary words against the joints, degrees.
    pub(crate) rotary_deg: f64,
}

/// The round trip of a tool-tip dialect (issue 30): its cutting moves (`None` at each cut's
/// start) against the same job's joint-space LinuxCNC program `joint`, line by line: the tip
/// and the tool direction against the joint line through kerf's forward kinematics, rotary
/// words equal to the joints', and `F` the tip's travel over the joint line's planned time
/// (`60 / F` in `G93`). Returns the largest tip and direction differences.
pub(crate) fn read_back_against_joints(
    m: &kerf_kinematics::Machine,
    moves: &[Option<TipMove>],
    joint: &str,
    within: &ReadBack,
) -> (f64, f64) {
    use kerf_kinematics::Axes;
    let names = m.axis_names();
    let j = cut_lines(joint, "M64 P0", "M65 P0", |l| l.starts_with("G1 "));
    assert!(moves.len() > 100, "{} cutting lines", moves.len());
    assert_eq!(moves.len(), j.len(), "one line per joint-space line");
    let mut prev: Option<[f64; 3]> = None;
    let mut worst = (0.0f64, 0.0f64);
    for (mv, lj) in moves.iter().zip(&j) {
        let (Some(mv), Some(lj)) = (mv, lj) else {
            assert!(mv.is_none() && lj.is_none(), "the cuts line up");
            prev = None;
            continue;
        };
        let q: [f64; 5] = std::array::from_fn(|k| nc_word(lj, names[k]).expect("a joint word"));
        let pose = m.kinematics.forward(&Axes::from_array(q));
        let dp = (0..3)
            .map(|k| (mv.tip[k] - pose.position[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        let axis = match (mv.direction, mv.rotary) {
            (Some(d), _) => d,
            (None, Some([t, c])) => {
                assert!(
                    (t - q[3]).abs() < within.rotary_deg && (c - q[4]).abs() < within.rotary_deg,
                    "{t} {c} vs {lj}"
                );
                let u = m
                    .kinematics
                    .forward(&Axes::from_array([0.0, 0.0, 0.0, t, c]))
                    .axis;
                [u.x, u.y, u.z]
            }
            (None, None) => panic!("a move with neither a direction nor rotary axes"),
        };
        let da = (0..3)
            .map(|k| (axis[k] - pose.axis[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = (worst.0.max(dp), worst.1.max(da));
        if let Some(pt) = prev {
            let travel = (0..3)
                .map(|k| (mv.tip[k] - pt[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            let time_s = 60.0 / nc_word(lj, "F").expect("F");
            if travel > 1e-3 {
                let want = travel / time_s * 60.0;
                assert!(
                    (mv.feed - want).abs() <= 2e-5 * mv.feed + 1e-3 * 60.0 / time_s + 1e-3,
                    "{lj}: F {} vs {want}",
                    mv.feed
                );
            }
        }
        prev = Some(mv.tip);
    }
    assert!(worst.0 < within.tip_mm, "tip {} mm off", worst.0);
    assert!(worst.1 < within.direction, "direction {} off", worst.1);
    worst
}
