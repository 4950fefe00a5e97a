//! Laser power that follows the tip's speed (issue 29), checked in the programs against
//! independent truth: the generic `S` words against the blocks' own speeds (the tip is the
//! linear axes on a flat part under a still head), LinuxCNC's rotary coefficients against the
//! tip speed from kerf's *forward* kinematics (the coefficients come from the inverse), and
//! the small-hole rule's feed and power in both dialects. The controller's execution is
//! checked in tests/linuxcnc/check.py.

mod common;
use common::{fixture, kerf};

use kerf_kinematics::{Axes, Machine};

fn run(curves: &str, machine: &str, extra: &[&str], out: &std::path::Path) -> String {
    let table = fixture("technology/fiber_3kw_example.json");
    let r = kerf()
        .args(["run"])
        .arg(fixture(curves))
        .arg("-m")
        .arg(fixture(machine))
        .arg("-o")
        .arg(out)
        .arg("-q")
        .arg("--technology")
        .arg(table)
        .args(extra)
        .output()
        .expect("kerf runs");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    std::fs::read_to_string(out.join("program.nc")).expect("program")
}

/// sheet_metal_holes on the gantry in `dialect` with mild steel 3 mm: 100 % at 3500 mm/min,
/// floor 20 %, pierce 60 %; holes up to 10 mm at 0.5 x feed and 0.7 x power (the fixture's
/// four 10 mm holes).
fn flat_part(dialect: &str, out: &std::path::Path) -> String {
    run(
        "sheet_metal_holes.json",
        "machines/gantry_ac.json",
        &[
            "--material",
            "mild steel",
            "--thickness",
            "3",
            "--dialect",
            dialect,
        ],
        out,
    )
}

/// The number after `letter` in a block (`X-1.5` -> -1.5).
fn word(line: &str, letter: char) -> Option<f64> {
    line.split_whitespace()
        .find(|w| w.starts_with(letter) && w[1..].parse::<f64>().is_ok())
        .map(|w| w[1..].parse().expect("number"))
}

fn axes(line: &str, names: [char; 5]) -> Option<[f64; 5]> {
    let v: Vec<f64> = names.iter().filter_map(|&n| word(line, n)).collect();
    (v.len() == 5).then(|| [v[0], v[1], v[2], v[3], v[4]])
}

/// One cut of a program: the lines between its beam-on and beam-off, with the id of its
/// curve.
fn cuts<'a>(program: &'a str, on: &str, off: &str) -> Vec<(String, Vec<&'a str>)> {
    let mut out = Vec::new();
    let mut id = String::new();
    let mut cur: Option<Vec<&str>> = None;
    for l in program.lines() {
        if let Some(rest) = l
            .strip_prefix("; curve ")
            .or_else(|| l.strip_prefix("(curve "))
        {
            id = rest.split(',').next().unwrap_or("").to_string();
        }
        if l == on {
            cur = Some(Vec::new());
        } else if l == off {
            if let Some(c) = cur.take() {
                out.push((id.clone(), c));
            }
        } else if let Some(c) = cur.as_mut() {
            c.push(l);
        }
    }
    out
}

#[test]
fn generic_s_words_follow_the_planned_speed_and_small_holes_run_at_their_factors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let program = flat_part("generic", &dir.path().join("out"));
    let report: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("out/report.json")).expect("report"),
    )
    .expect("json");
    let small: Vec<&str> = report["technology"]["small_holes"]
        .as_array()
        .expect("small_holes")
        .iter()
        .map(|v| v.as_str().expect("id"))
        .collect();
    let mut small_sorted = small.clone();
    small_sorted.sort();
    assert_eq!(
        small_sorted,
        ["hole-d10-1", "hole-d10-2", "hole-d10-3", "hole-d10-4"],
        "the 10 mm holes and nothing else"
    );
    let names = ['X', 'Y', 'Z', 'A', 'C'];
    let mut checked = 0;
    let cut_list = cuts(&program, "M3", "M5");
    assert_eq!(cut_list.len(), 8);
    for (id, lines) in &cut_list {
        let is_small = small.contains(&id.as_str());
        let (pf, ff) = if is_small { (0.7, 0.5) } else { (1.0, 1.0) };
        let mut s = None;
        let mut top = 0.0f64;
        let mut prev: Option<[f64; 5]> = None;
        for l in lines {
            if let Some(v) = word(l, 'S') {
                s = Some(v);
            }
            let Some(q) = axes(l, names) else { continue };
            if let (Some(p), Some(f), Some(s)) = (prev, word(l, 'F'), s) {
                // The head stands upright: the tip moves as X Y Z, F is its speed.
                assert_eq!((p[3], p[4]), (q[3], q[4]), "{id}: the head turned");
                let want = (pf * 100.0 * f / 3500.0).clamp(20.0, 100.0);
                assert!(
                    (s - want).abs() <= 0.006 * want + 1e-3,
                    "{id}: S{s} at F{f}, the rule gives {want}: {l}"
                );
                // The descent from the pierce height runs at the programmed feed.
                if p[2] == q[2] {
                    top = top.max(f);
                }
                checked += 1;
            }
            prev = Some(q);
        }
        // The planned speed of a small hole stays within its share of the feed, and reaches
        // it. (A block's F is its chord over its planned time on the smoothed path: up to
        // 1 % over the feed on a 10 mm hole, as tests/linuxcnc allows the executed tip.)
        if is_small {
            assert!(top <= 0.5 * 3500.0 * 1.01, "{id}: {top} mm/min");
        }
        assert!(top >= ff * 3500.0 * 0.98, "{id}: peak {top} mm/min");
    }
    assert!(checked > 600, "{checked} blocks checked");
    // The pierce runs at the pierce power, the program ends with the power at zero.
    assert!(
        program.contains("S60\nM3\n"),
        "pierce power before the beam"
    );
    assert!(
        program.trim_end().ends_with("S0\nM30"),
        "{}",
        &program[program.len() - 200..]
    );
}

/// The tip speed per unit of joint motion along the straight joint line from `q` in
/// direction `d`, from kerf's forward kinematics (central differences).
fn tip_rate(m: &Machine, q: &[f64; 5], d: &[f64; 5]) -> f64 {
    let h = 1e-5;
    let at = |s: f64| {
        let a: [f64; 5] = std::array::from_fn(|k| q[k] + s * d[k]);
        m.kinematics.forward(&Axes::from_array(a)).position
    };
    (at(h) - at(-h)).norm() / (2.0 * h)
}

/// LinuxCNC's coefficients, replayed as the HAL of docs/process.md computes the tip speed,
/// against the forward kinematics at both ends of every cutting block of a tilted fixture:
/// within the 2.5 % the writer's pieces promise at their ends plus the 0.5 % by which written
/// coefficients may go stale before they are written again (3 %, 0.1 % for the rounding).
fn linuxcnc_coefficients_give_the_tip_speed(curves: &str, machine: &str, extra: &[&str]) {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut args = vec![
        "--material",
        "stainless",
        "--thickness",
        "2",
        "--dialect",
        "linuxcnc",
    ];
    args.extend_from_slice(extra);
    let program = run(curves, machine, &args, &dir.path().join("out"));
    let m = Machine::read(fixture(machine)).expect("machine");
    let names = [
        'X',
        'Y',
        'Z',
        if program.contains(" B") { 'B' } else { 'A' },
        'C',
    ];
    let (checked, rotating, worst) = common::replay_power_coefficients(
        &program,
        |l| axes(l, names),
        |end, d| tip_rate(&m, end, d),
        0.031,
    );
    assert!(
        rotating > 50,
        "{rotating} rotating blocks: the fixture must turn the head"
    );
    assert!(checked > 2 * rotating, "{checked} ends checked");
    eprintln!("{curves} on {machine}: {checked} block ends, worst {worst:.4}");
}

#[test]
fn linuxcnc_coefficients_give_the_tip_speed_on_the_saddle() {
    linuxcnc_coefficients_give_the_tip_speed("tube_saddle.json", "machines/ac_head.json", &[]);
}

#[test]
fn linuxcnc_coefficients_give_the_tip_speed_through_the_pole() {
    linuxcnc_coefficients_give_the_tip_speed(
        "trim_panel.json",
        "machines/ac_head.json",
        &["--place", "auto", "--tilt-tolerance", "1"],
    );
}

#[test]
fn linuxcnc_coefficients_give_the_tip_speed_on_a_table_table_machine() {
    linuxcnc_coefficients_give_the_tip_speed(
        "tube_saddle.json",
        "machines/table_table.json",
        &["--place", "auto"],
    );
}

#[test]
fn linuxcnc_cuts_set_pierce_floor_and_scale_with_the_small_hole_factor() {
    let dir = tempfile::tempdir().expect("tempdir");
    let program = flat_part("linuxcnc", &dir.path().join("out"));
    let full = 100.0 / (3500.0 / 60.0);
    for (id, _) in cuts(&program, "M64 P0", "M65 P0") {
        let scale = if id.starts_with("hole-d10") {
            0.7 * full
        } else {
            full
        };
        // Pierce power (immediate) before the beam, floor and scale (synchronized) before the
        // descent.
        let at = program
            .find(&format!("(curve {id},"))
            .expect("curve comment");
        let rest = &program[at..];
        let cut = &rest[..rest.find("M65 P0").expect("beam off")];
        let expect = format!(
            "M68 E0 Q0\nM68 E1 Q60\nM64 P0\nG4 P0.4\nG64 P0.005 Q0\nM67 E1 Q20\nM67 E0 Q{scale:.5}\n"
        );
        assert!(
            cut.contains(&expect),
            "{id}: {expect:?} in\n{}",
            &cut[..400.min(cut.len())]
        );
    }
    // The flat part's head never turns: no rotary coefficient is ever needed.
    assert!(
        !program.contains("M67 E2"),
        "coefficients written on a flat part"
    );
    assert!(
        program.contains("M68 E7 Q0\nM2"),
        "outputs back to zero at the end"
    );
}

/// A technology's corner rule (`corner`: turns above 45 degrees, 2 mm each side, half the
/// feed): in the set-points, the tip within 1.5 mm of path of a sharp vertex of the program's
/// cuts never passes half the feed, while without the rule it passes faster there (the
/// gantry brakes within 0.8 mm). The vertices come from the program's own blocks.
#[test]
fn the_corner_rule_slows_the_cut_near_sharp_vertices() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = dir.path().join("table.json");
    let entry = |corner: &str| {
        format!(
            r#"{{"format": "kerf.technology/1", "entries": [{{"material": "steel", "thickness_mm": 2, "feed_mm_per_min": 6000, "power_percent": 80{corner}}}]}}"#
        )
    };
    let near_corners = |corner: &str, tag: &str| -> (f64, usize) {
        std::fs::write(&table, entry(corner)).expect("write");
        let out = dir.path().join(tag);
        let r = kerf()
            .args(["run"])
            .arg(fixture("sheet_metal_holes.json"))
            .arg("-m")
            .arg(fixture("machines/gantry_ac.json"))
            .args(["--dialect", "generic", "--technology"])
            .arg(&table)
            .args(["--material", "steel", "-q", "-o"])
            .arg(&out)
            .output()
            .expect("kerf runs");
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        // Sharp vertices of the cuts (machine X Y Z: the head stands upright, so they are
        // the tip's, shifted).
        let program = std::fs::read_to_string(out.join("program.nc")).expect("program");
        let mut vertices: Vec<[f64; 3]> = Vec::new();
        let (mut prev, mut dir_prev): (Option<[f64; 3]>, Option<[f64; 3]>) = (None, None);
        for l in program.lines() {
            let w: Vec<f64> = ['X', 'Y', 'Z'].iter().filter_map(|&n| word(l, n)).collect();
            if w.len() != 3 {
                continue;
            }
            let p = [w[0], w[1], w[2]];
            if l.starts_with("G0") {
                (prev, dir_prev) = (Some(p), None);
                continue;
            }
            if let Some(a) = prev {
                let d = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
                let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                if n > 0.0 && d[2] == 0.0 {
                    if let Some(e) = dir_prev {
                        let m = (e[0] * e[0] + e[1] * e[1]).sqrt();
                        if (d[0] * e[0] + d[1] * e[1]) / (n * m) < 45f64.to_radians().cos() {
                            vertices.push(a);
                        }
                    }
                    dir_prev = Some(d);
                } else if d[2] != 0.0 {
                    dir_prev = None;
                }
            }
            prev = Some(p);
        }
        assert!(vertices.len() >= 10, "{} sharp vertices", vertices.len());
        let csv = std::fs::read_to_string(out.join("setpoints.csv")).expect("csv");
        let rows: Vec<[f64; 3]> = csv
            .lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
                [v[1], v[2], v[3]]
            })
            .collect();
        // Along the path: each vertex at the set-point nearest it (the path passes through it;
        // elsewhere the same contour may pass within a millimetre, e.g. an overcut's exit
        // beside the contour's start), then every cutting sample within 1.5 mm of path.
        let mut along = vec![0.0];
        for w in rows.windows(2) {
            let d = ((w[1][0] - w[0][0]).powi(2)
                + (w[1][1] - w[0][1]).powi(2)
                + (w[1][2] - w[0][2]).powi(2))
            .sqrt();
            along.push(along[along.len() - 1] + d);
        }
        let mut top = 0.0f64;
        let mut samples = 0;
        for v in &vertices {
            let i = (0..rows.len())
                .min_by(|&a, &b| {
                    let d = |k: usize| (0..3).map(|j| (rows[k][j] - v[j]).powi(2)).sum::<f64>();
                    d(a).total_cmp(&d(b))
                })
                .expect("rows");
            for j in 1..rows.len() {
                if (along[j] - along[i]).abs() <= 1.5 && rows[j][2] == rows[j - 1][2] {
                    let d = ((rows[j][0] - rows[j - 1][0]).powi(2)
                        + (rows[j][1] - rows[j - 1][1]).powi(2))
                    .sqrt();
                    top = top.max(d / 0.001 * 60.0);
                    samples += 1;
                }
            }
        }
        (top, samples)
    };
    let (with_rule, n) = near_corners(
        r#", "corner": {"min_turn_deg": 45, "length_mm": 2, "feed_factor": 0.5}"#,
        "rule",
    );
    assert!(n > 100, "{n} samples near corners");
    assert!(
        with_rule <= 0.5 * 6000.0 * 1.02,
        "{with_rule} mm/min near a corner"
    );
    let (without, _) = near_corners("", "free");
    assert!(
        without > 0.6 * 6000.0,
        "{without} mm/min near a corner without the rule"
    );
}

/// The Sinumerik dialect writes Siemens' laser-power pattern (not executed here: no Sinumerik
/// oracle): one synchronized action on the path velocity, per cut the pierce power as a flat
/// polynomial and then the cut's slope `P_cut / v_cut` per mm/min with the floor, and the
/// action cancelled at the end.
#[test]
fn sinumerik_writes_the_synchronized_power_action() {
    let dir = tempfile::tempdir().expect("tempdir");
    let program = flat_part("sinumerik", &dir.path().join("out"));
    assert_eq!(
        program
            .matches("\nID=1 WHENEVER TRUE DO SYNFCT(1,$A_OUTA[1],$AC_VACTW)\n")
            .count(),
        1
    );
    let cuts = program.matches("\nM3\n").count();
    assert_eq!(cuts, 8);
    assert_eq!(
        program.matches("\nFCTDEF(1,60,60,60,0)\nM3\n").count(),
        cuts,
        "pierce power"
    );
    // 100 % at 3500 mm/min: 0.0285714 % per mm/min (six significant digits); the holes at
    // 0.7 of it.
    assert_eq!(
        program.matches("\nFCTDEF(1,20,100,0,0.0285714)\n").count(),
        4
    );
    assert_eq!(
        program.matches("\nFCTDEF(1,20,100,0,0.0200000)\n").count(),
        4
    );
    assert!(program.contains("CANCEL(1)\nTRAFOOF\nM30"));
}
