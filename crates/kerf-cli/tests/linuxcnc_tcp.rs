//! The `linuxcnc-tcp` dialect (issue 30) against LinuxCNC 2.9's own tool-tip kinematics,
//! `xyzac-trt-kins` and `5axiskins`, written here from their published formulas
//! (`src/emc/kinematics/trtfuncs.c`, `xyzacKinematicsForward`/`Inverse`; `5axiskins.c`), not
//! from kerf's code: kerf's table-table with `conventional: false` and its B fork head with
//! `tilt_sign` -1 are those modules; a tool-tip program put through the module's inverse is the
//! joint-space program kerf writes for the same job, line by line; the feed is the tip's at
//! kerf's planned time; the rapids follow kerf's joint-space traverses within
//! `RAPID_TCP_TOLERANCE_MM`; other machines are refused by name. The
//! controller's execution is checked in tests/linuxcnc/check.py.

mod common;
use common::{fixture, kerf};

use kerf_kinematics::{Axes, Machine};
use nalgebra::{Point3, Rotation3, Vector3};

/// `fixtures/machines/xyzac_trt.json`'s HAL pins: x/y/z-rot-point, y-offset, z-offset.
const ROT: [f64; 3] = [3.0, -2.0, 0.0];
const DY: f64 = 5.0;
const DZ: f64 = 80.0;

/// xyzacKinematicsForward: joints -> world (tool tip in the table frame).
fn lcnc_forward(j: &[f64; 5]) -> [f64; 3] {
    let (a, c) = (j[3].to_radians(), j[4].to_radians());
    let (xr, yr, zr) = (ROT[0], ROT[1], ROT[2]);
    let (dy, dz) = (DY, DZ);
    [
        c.cos() * (j[0] - xr)
            + c.sin() * a.cos() * (j[1] - dy - yr)
            + c.sin() * a.sin() * (j[2] - dz - zr)
            + c.sin() * dy
            + xr,
        -c.sin() * (j[0] - xr)
            + c.cos() * a.cos() * (j[1] - dy - yr)
            + c.cos() * a.sin() * (j[2] - dz - zr)
            + c.cos() * dy
            + yr,
        -a.sin() * (j[1] - dy - yr) + a.cos() * (j[2] - dz - zr) + dz + zr,
    ]
}

/// xyzacKinematicsInverse: world (tip X Y Z, A, C) -> joints.
fn lcnc_inverse(w: &[f64; 5]) -> [f64; 5] {
    let (a, c) = (w[3].to_radians(), w[4].to_radians());
    let (xr, yr, zr) = (ROT[0], ROT[1], ROT[2]);
    let (dy, dz) = (DY, DZ);
    let (x, y, z) = (w[0] - xr, w[1] - yr, w[2] - zr);
    [
        c.cos() * x - c.sin() * y + xr,
        c.sin() * a.cos() * x + c.cos() * a.cos() * y - a.sin() * z - a.cos() * dy
            + a.sin() * dz
            + dy
            + yr,
        c.sin() * a.sin() * x + c.cos() * a.sin() * y + a.cos() * z - a.sin() * dy - a.cos() * dz
            + dz
            + zr,
        w[3],
        w[4],
    ]
}

/// `fixtures/machines/bc_head_5axiskins.json`'s `5axiskins.pivot-length`.
const PIVOT: f64 = 210.0;

/// 5axiskins' forward kinematics (`src/emc/kinematics/5axiskins.c`, the W joint at 0):
/// `world = J + (0, 0, L) + s2r(L, C, 180 - B)`, `s2r(r, t, p) = r (sin p cos t, sin p sin t,
/// cos p)`.
fn five_forward(j: &[f64; 5]) -> [f64; 3] {
    let (t, p) = (j[4].to_radians(), (180.0 - j[3]).to_radians());
    [
        j[0] + PIVOT * p.sin() * t.cos(),
        j[1] + PIVOT * p.sin() * t.sin(),
        j[2] + PIVOT + PIVOT * p.cos(),
    ]
}

/// 5axiskins' inverse kinematics: `J = world - (0, 0, L) - s2r(L, C, 180 - B)`.
fn five_inverse(w: &[f64; 5]) -> [f64; 5] {
    let (t, p) = (w[4].to_radians(), (180.0 - w[3]).to_radians());
    [
        w[0] - PIVOT * p.sin() * t.cos(),
        w[1] - PIVOT * p.sin() * t.sin(),
        w[2] - PIVOT - PIVOT * p.cos(),
        w[3],
        w[4],
    ]
}

/// A LinuxCNC tool-tip module with the shipped machine that matches it and the fixture its
/// program is tested on.
struct Module {
    machine: &'static str,
    fixture: &'static str,
    tilt: char,
    forward: fn(&[f64; 5]) -> [f64; 3],
    inverse: fn(&[f64; 5]) -> [f64; 5],
    header: &'static [&'static str],
}

const TRT: Module = Module {
    machine: "machines/xyzac_trt.json",
    fixture: "dome.json",
    tilt: 'A',
    forward: lcnc_forward,
    inverse: lcnc_inverse,
    header: &[
        "(kinematics: LinuxCNC [KINS] KINEMATICS = xyzac-trt-kins, [TRAJ] COORDINATES = XYZAC",
        "(kinematics: setp xyzac-trt-kins.x-rot-point 3)",
        "(kinematics: setp xyzac-trt-kins.y-rot-point -2)",
        "(kinematics: setp xyzac-trt-kins.y-offset 5)",
        "(kinematics: setp xyzac-trt-kins.z-offset 80)",
        "(kinematics: setp xyzac-trt-kins.tool-offset 0)",
    ],
};

const FIVE_AXIS: Module = Module {
    machine: "machines/bc_head_5axiskins.json",
    fixture: "tube_saddle.json",
    tilt: 'B',
    forward: five_forward,
    inverse: five_inverse,
    header: &[
        "(kinematics: LinuxCNC [KINS] KINEMATICS = 5axiskins, [TRAJ] COORDINATES = XYZBCW",
        "(kinematics: setp 5axiskins.pivot-length 210)",
    ],
};

fn machine() -> Machine {
    Machine::read(fixture("machines/xyzac_trt.json")).expect("machine")
}

#[test]
fn kerfs_table_table_with_conventional_false_is_linuxcncs_xyzac_trt() {
    let m = machine();
    let mut worst = 0.0f64;
    for i in 0..7 {
        for k in 0..9 {
            let j = [
                -120.0 + 37.0 * i as f64,
                55.0 - 19.0 * k as f64,
                -30.0 + 11.0 * (i + k) as f64,
                -10.0 + 17.5 * i as f64,
                -400.0 + 97.0 * k as f64,
            ];
            let pose = m.kinematics.forward(&Axes::from_array(j));
            let w = lcnc_forward(&j);
            worst = worst.max((pose.position - Point3::from(w)).norm());
            // The tool is along the machine's +z; in the table frame the same rotations turn
            // it: Rz(-C) Rx(-A) ez.
            let u = Rotation3::from_axis_angle(&Vector3::z_axis(), -j[4].to_radians())
                * Rotation3::from_axis_angle(&Vector3::x_axis(), -j[3].to_radians())
                * Vector3::z();
            assert!(
                (pose.axis - u).norm() < 1e-12,
                "{j:?}: axis {} vs {u}",
                pose.axis
            );
            let back = lcnc_inverse(&[w[0], w[1], w[2], j[3], j[4]]);
            for n in 0..5 {
                assert!((back[n] - j[n]).abs() < 1e-9, "{j:?}: inverse {back:?}");
            }
        }
    }
    assert!(worst < 1e-9, "kerf vs LinuxCNC forward: {worst} mm");
}

#[test]
fn kerfs_fork_head_with_tilt_sign_minus_one_is_linuxcncs_5axiskins() {
    let m = Machine::read(fixture(FIVE_AXIS.machine)).expect("machine");
    for i in 0..9 {
        for k in 0..9 {
            let j = [
                -700.0 + 173.0 * i as f64,
                310.0 - 61.0 * k as f64,
                -40.0 + 23.0 * (i + k) as f64,
                -120.0 + 29.0 * i as f64,
                -400.0 + 97.0 * k as f64,
            ];
            let pose = m.kinematics.forward(&Axes::from_array(j));
            let w = five_forward(&j);
            assert!(
                (pose.position - Point3::from(w)).norm() < 1e-9,
                "{j:?}: kerf {} vs 5axiskins {w:?}",
                pose.position
            );
            // The tool axis runs from the tip to LinuxCNC's pivot, J + (0, 0, L).
            let pivot = Point3::new(j[0], j[1], j[2] + PIVOT);
            let u = (pivot - Point3::from(w)) / PIVOT;
            assert!(
                (pose.axis - u).norm() < 1e-12,
                "{j:?}: axis {} vs {u}",
                pose.axis
            );
            let back = five_inverse(&[w[0], w[1], w[2], j[3], j[4]]);
            for n in 0..5 {
                assert!((back[n] - j[n]).abs() < 1e-9, "{j:?}: inverse {back:?}");
            }
        }
    }
}

/// The number after `letter` in a block (`X-1.5` -> -1.5).
fn word(line: &str, letter: char) -> Option<f64> {
    line.split_whitespace()
        .find(|w| w.starts_with(letter) && w[1..].parse::<f64>().is_ok())
        .map(|w| w[1..].parse().expect("number"))
}

fn words5(line: &str, tilt: char) -> [f64; 5] {
    ['X', 'Y', 'Z', tilt, 'C'].map(|l| word(line, l).unwrap_or_else(|| panic!("{l} in {line}")))
}

fn run(dialect: &str, machine: &str, out: &std::path::Path) -> std::process::Output {
    run_fixture("dome.json", dialect, machine, out)
}

fn run_fixture(
    curves: &str,
    dialect: &str,
    machine: &str,
    out: &std::path::Path,
) -> std::process::Output {
    kerf()
        .args(["run"])
        .arg(fixture(curves))
        .arg("-m")
        .arg(fixture(machine))
        .args(["--dialect", dialect, "-q", "-o"])
        .arg(out)
        .output()
        .expect("kerf runs")
}

fn program(m: &Module, dialect: &str) -> String {
    let dir = tempfile::tempdir().expect("tmp");
    let r = run_fixture(m.fixture, dialect, m.machine, dir.path());
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    std::fs::read_to_string(dir.path().join("program.nc")).expect("program")
}

#[test]
fn a_tool_tip_program_through_linuxcncs_inverse_is_kerfs_joint_program() {
    for m in [TRT, FIVE_AXIS] {
        tool_tip_program_is_the_joint_program(&m);
    }
}

fn tool_tip_program_is_the_joint_program(m: &Module) {
    let tcp = program(m, "linuxcnc-tcp");
    let joint = program(m, "linuxcnc");
    // The header names the module and its pins with the machine file's numbers.
    for l in m.header {
        assert!(tcp.contains(l), "{}: header line {l}", m.machine);
    }
    assert!(
        tcp.contains("\nG94\n") || tcp.contains("G90 G94\n"),
        "G94 feed"
    );
    assert!(!tcp.contains("G93"), "no inverse time");
    // The cutting lines, in order, of both programs (the G1s between beam-on and beam-off).
    let cut_lines = |p: &str| -> Vec<String> {
        let mut on = false;
        let mut out = Vec::new();
        for l in p.lines() {
            match l {
                "M64 P0" => {
                    on = true;
                    out.push(String::new());
                }
                "M65 P0" => on = false,
                _ if on && l.starts_with("G1 ") => out.push(l.to_string()),
                _ => {}
            }
        }
        out
    };
    let (t, j) = (cut_lines(&tcp), cut_lines(&joint));
    assert!(
        t.len() > 500,
        "{} cutting lines (and a mark per cut)",
        t.len()
    );
    assert_eq!(t.len(), j.len(), "one tool-tip line per joint line");
    let mut worst = 0.0f64;
    let mut prev: Option<([f64; 5], [f64; 5])> = None;
    for (lt, lj) in t.iter().zip(&j) {
        if lt.is_empty() {
            // A new cut: its descent starts from the pierce point.
            assert!(lj.is_empty(), "the cuts line up");
            prev = None;
            continue;
        }
        let w = words5(lt, m.tilt);
        let q = words5(lj, m.tilt);
        let from_lcnc = (m.inverse)(&w);
        for n in 0..5 {
            worst = worst.max((from_lcnc[n] - q[n]).abs());
        }
        // F: mm/min of the tip at the block's planned time (the joint line's 60 / F).
        if let Some((pw, _)) = prev {
            let tip =
                ((w[0] - pw[0]).powi(2) + (w[1] - pw[1]).powi(2) + (w[2] - pw[2]).powi(2)).sqrt();
            let time_s = 60.0 / word(lj, 'F').expect("F");
            if tip > 1e-3 {
                let f = word(lt, 'F').expect("F");
                assert!(
                    (f - tip / time_s * 60.0).abs() <= 2e-5 * f + 1e-3 * 60.0 / time_s,
                    "{lt}: F {f} vs {} mm/min",
                    tip / time_s * 60.0
                );
            }
        }
        prev = Some((w, q));
    }
    // Six decimals of an angle (5e-7 deg) over a ~400 mm lever: 4e-6 mm.
    assert!(
        worst < 2e-5,
        "joints from LinuxCNC's inverse vs kerf's: {worst}"
    );
}

#[test]
fn tool_tip_rapids_follow_kerfs_joint_space_traverses() {
    for m in [TRT, FIVE_AXIS] {
        tool_tip_rapids_follow_the_traverses(&m);
    }
}

fn tool_tip_rapids_follow_the_traverses(m: &Module) {
    let tcp = program(m, "linuxcnc-tcp");
    let joint = program(m, "linuxcnc");
    let rapids = |p: &str| -> Vec<[f64; 5]> {
        p.lines()
            .filter(|l| l.starts_with("G0 "))
            .map(|l| words5(l, m.tilt))
            .collect()
    };
    let (t, j) = (rapids(&tcp), rapids(&joint));
    assert!(
        t.len() > j.len(),
        "the tool-tip rapids are split ({} vs {})",
        t.len(),
        j.len()
    );
    // Every joint-space G0 target is the end of a tool-tip G0 (through LinuxCNC's inverse).
    for q in &j {
        assert!(
            t.iter().any(|w| {
                let back = (m.inverse)(w);
                (0..5).all(|n| (back[n] - q[n]).abs() < 2e-5)
            }),
            "joint-space G0 target {q:?} missing"
        );
    }
    // Between a G0's start (the last move's end) and its end LinuxCNC moves the tip straight;
    // kerf's traverse is linear in the joints: their middles within the tolerance, for every
    // G0 piece (the first from where the cut before it ended).
    let mut worst = 0.0f64;
    let mut pieces = 0;
    let lines: Vec<&str> = tcp
        .lines()
        .filter(|l| l.starts_with("G0 ") || l.starts_with("G1 "))
        .collect();
    for w in lines.windows(2) {
        if !w[1].starts_with("G0 ") {
            continue;
        }
        pieces += 1;
        let (a, b) = (words5(w[0], m.tilt), words5(w[1], m.tilt));
        let (ja, jb) = ((m.inverse)(&a), (m.inverse)(&b));
        let jm: [f64; 5] = std::array::from_fn(|n| 0.5 * (ja[n] + jb[n]));
        let on_traverse = (m.forward)(&jm);
        let chord_mid = [0, 1, 2].map(|n| 0.5 * (a[n] + b[n]));
        let d = (0..3)
            .map(|n| (on_traverse[n] - chord_mid[n]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    assert!(pieces > 0, "some rapid is split");
    assert!(
        worst <= kerf_interp::RAPID_TCP_TOLERANCE_MM + 1e-5,
        "a G0's middle {worst} mm off the joint-space traverse"
    );
}

#[test]
fn machines_linuxcnc_has_no_tool_tip_kinematics_for_are_refused_by_name() {
    for (machine, says) in [
        (
            "machines/ac_head.json",
            "dialect linuxcnc-tcp: the machine's kinematics are ac-head",
        ),
        (
            "machines/table_table.json",
            "dialect linuxcnc-tcp: kinematics.conventional is true",
        ),
        (
            "machines/fork_head.json",
            "dialect linuxcnc-tcp: fork-head for LinuxCNC's 5axiskins: kinematics.tilt_sign is +1",
        ),
    ] {
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().join("out");
        let r = run("linuxcnc-tcp", machine, &out);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{machine}: {err}");
        assert!(err.contains(says), "{machine}: {err}");
        assert!(!out.join("program.nc").exists(), "{machine}: no program");
    }
    // The tool length belongs to the controller.
    let mut m = machine();
    let tt =
        kerf_kinematics::TableTable::try_new(Vector3::new(3.0, -2.0, 0.0), 5.0, 80.0, 10.0, false)
            .expect("table-table");
    m.kinematics = std::sync::Arc::new(tt);
    let e = kerf_interp::linuxcnc_kinematics(&m)
        .unwrap_err()
        .to_string();
    assert!(e.contains("kinematics.tool_offset is 10"), "{e}");
    // A fork head turning B the 5axiskins way whose pivot is not straight above the joints'
    // point, or whose nozzle sits beside the axis, is not 5axiskins either.
    let mut m = machine();
    for (d, lateral, says) in [
        (
            [0.0, 35.0, -120.0],
            [0.0, 0.0],
            "kinematics.d is [0.0, 35.0, -120.0]",
        ),
        (
            [0.0, 0.0, 210.0],
            [2.0, 0.0],
            "kinematics.tool_lateral is [2.0, 0.0]",
        ),
    ] {
        let head = kerf_kinematics::ForkHead::try_new(
            kerf_kinematics::ForkTilt::B,
            210.0,
            Vector3::from(d),
            lateral,
        )
        .and_then(|h| h.with_tilt_sign(-1.0))
        .expect("fork head");
        m.kinematics = std::sync::Arc::new(head);
        let e = kerf_interp::linuxcnc_kinematics(&m)
            .unwrap_err()
            .to_string();
        assert!(e.contains(says), "{e}");
    }
    let k = kerf_interp::linuxcnc_kinematics(&machine()).expect("xyzac-trt");
    assert_eq!(k.module, "xyzac-trt-kins");
    assert_eq!(
        k.setp_lines()[..3],
        [
            "setp xyzac-trt-kins.x-rot-point 3",
            "setp xyzac-trt-kins.y-rot-point -2",
            "setp xyzac-trt-kins.z-rot-point 0"
        ]
    );
    // The controller's kerf compensation is LinuxCNC's joint-space dialect's (and
    // Sinumerik's), not the tool-tip dialect's.
    let dir = tempfile::tempdir().expect("tmp");
    let r = kerf()
        .args(["run"])
        .arg(fixture("sheet_metal_holes.json"))
        .arg("-m")
        .arg(fixture("machines/xyzac_trt.json"))
        .args([
            "--dialect",
            "linuxcnc-tcp",
            "--kerf-width",
            "0.2",
            "--kerf-in-control",
            "-q",
            "-o",
        ])
        .arg(dir.path().join("out"))
        .output()
        .expect("kerf runs");
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        !r.status.success() && err.contains("not linuxcnc-tcp"),
        "{err}"
    );
}

#[test]
fn tool_tip_power_coefficients_give_the_tip_speed_from_linuxcncs_joints() {
    // With a technology the program sets the same rotary coefficients as the joint-space
    // dialect (the HAL of docs/process.md computes the tip speed from the joints, which under
    // tool-tip kinematics are LinuxCNC's): replayed at both ends of every cutting piece against
    // the tip's rate from LinuxCNC's forward kinematics along the joints' motion, within the
    // 3 % of tests/power.rs.
    let dir = tempfile::tempdir().expect("tmp");
    let r = kerf()
        .args(["run"])
        .arg(fixture("dome.json"))
        .arg("-m")
        .arg(fixture("machines/xyzac_trt.json"))
        .arg("--technology")
        .arg(fixture("technology/fiber_3kw_example.json"))
        .args(["--material", "stainless", "--thickness", "2"])
        .args(["--dialect", "linuxcnc-tcp", "-q", "-o"])
        .arg(dir.path())
        .output()
        .expect("kerf runs");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let program = std::fs::read_to_string(dir.path().join("program.nc")).expect("program");
    let (checked, rotating, _) = common::replay_power_coefficients(
        &program,
        |l| (l.starts_with("G0 ") || l.starts_with("G1 ")).then(|| lcnc_inverse(&words5(l, 'A'))),
        |end, d| {
            let h = 1e-4;
            let at =
                |s: f64| -> [f64; 3] { lcnc_forward(&std::array::from_fn(|k| end[k] + s * d[k])) };
            let (a, b) = (at(h), at(-h));
            (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt() / (2.0 * h)
        },
        0.031,
    );
    assert!(
        rotating > 50,
        "{rotating} rotating pieces: the dome turns the table"
    );
    assert!(checked > 2 * rotating, "{checked} ends checked");
}
