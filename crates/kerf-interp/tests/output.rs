//! CSV and G-code: the header and rows of formats.md, and programs that parse back (with a
//! simple line parser written here) to the positions they were made from.

mod common;

use std::collections::HashMap;

use common::{circle, freeform, stations};
use kerf_interp::{
    csv_string, fit_blocks, gcode, plan, write_csv, write_gcode, AxisModel, Dialect, FitOptions,
    GcodeOptions, Geometry, PaperAcHead, PlanOptions, EXIT_RETRACT_MIN_MM,
};
use kerf_kinematics::Axes;
use nalgebra::Vector3;

/// Words of one G-code line: `G1 X1.5 A3=0.2` -> {"G": 1, "X": 1.5, "A3": 0.2}; comments
/// (`;` to the end) dropped.
fn words(line: &str) -> (String, HashMap<String, f64>) {
    let code = line.split(';').next().unwrap_or("").trim();
    let mut it = code.split_whitespace();
    let head = it.next().unwrap_or("").to_string();
    let mut map = HashMap::new();
    for w in it {
        let (k, v) = match w.split_once('=') {
            Some((k, v)) => (k.to_string(), v),
            None => {
                let i = w
                    .find(|c: char| c == '-' || c == '.' || c.is_ascii_digit())
                    .unwrap_or(w.len());
                (w[..i].to_string(), &w[i..])
            }
        };
        map.insert(
            k,
            v.parse::<f64>()
                .unwrap_or_else(|_| panic!("number in {line:?}")),
        );
    }
    (head, map)
}

/// Fit options for one line block per pose step (no arcs, no merged lines).
fn lines_only() -> FitOptions {
    FitOptions::default()
        .with_arcs(false)
        .with_merge_lines(false)
}

#[test]
fn csv_header_and_rows() {
    let m = PaperAcHead::paper_000();
    let st = stations(&m, &circle(10.0, 0.0, 0.0, 0.0), 0.001, |_| Vector3::z());
    let blocks = fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit");
    let motion = plan(&m, &blocks, &PlanOptions::new(3000.0, 0.004)).expect("plan");
    let rows = motion.setpoints(&m);
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("out.csv");
    write_csv(&path, m.axis_names(), 0.004, &rows).expect("write");
    let text = std::fs::read_to_string(&path).expect("read");
    assert_eq!(
        text,
        csv_string(m.axis_names(), 0.004, &rows),
        "file = string"
    );
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,X,Y,Z,A,C"), "header of formats.md");
    let parsed: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().expect("number")).collect())
        .collect();
    assert_eq!(parsed.len(), rows.len(), "one row per cycle");
    for (i, (p, q)) in parsed.iter().zip(&rows).enumerate() {
        assert_eq!(p.len(), 6, "six columns");
        assert!((p[0] - i as f64 * 0.004).abs() < 1e-9, "t of row {i}");
        for k in 0..5 {
            assert_eq!(p[k + 1], q[k], "row {i} axis {k} reads back exactly");
        }
    }
    // No temporary file left behind.
    assert_eq!(
        std::fs::read_dir(dir.path()).expect("dir").count(),
        1,
        "only the CSV"
    );
    // A directory that does not exist is an error, not a panic.
    let e = write_csv(
        dir.path().join("no/such/dir.csv"),
        m.axis_names(),
        0.004,
        &rows,
    );
    assert!(
        matches!(e, Err(kerf_interp::InterpError::Io { .. })),
        "{e:?}"
    );
}

#[test]
fn generic_gcode_parses_back_to_the_machine_axes() {
    let m = PaperAcHead::paper_000();
    let c = freeform();
    let st = stations(&m, &c, 0.001, |p| {
        Vector3::new(0.3 * (p.x / 50.0).sin(), 0.2, 1.0).normalize()
    });
    let curve = |t: f64| c.point(t);
    // Generic programs give raw machine axes: one line per pose, no arcs, no merged lines.
    let arcs = fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::default()).expect("fit");
    let opts = GcodeOptions::new(Dialect::Generic, 6000.0);
    let refused = gcode(&m, &arcs, &["door-trim-1".to_string()], None, &opts);
    assert!(
        matches!(
            refused,
            Err(kerf_interp::InterpError::UncheckedBlock { .. })
        ),
        "arcs or merged lines in a generic program are refused: {refused:?}"
    );
    let lines_only = lines_only();
    let blocks = fit_blocks(&m, &st, Some(&curve), 0, &lines_only).expect("fit");
    assert_eq!(blocks.len(), st.len() - 1, "one block per pose step");
    let text = gcode(&m, &blocks, &["door-trim-1".to_string()], None, &opts).expect("gcode");
    assert!(
        text.contains("; curve door-trim-1"),
        "comment names the source curve"
    );
    assert!(
        text.contains("; machine: paper-000 laser head"),
        "header names the machine"
    );
    assert!(text.contains("units: mm"), "header states units");
    assert!(
        text.contains("tolerance budget mm: chord unknown"),
        "header states the budget, and no chord term it was not told"
    );
    let mut moves: Vec<HashMap<String, f64>> = text
        .lines()
        .map(words)
        .filter(|(h, _)| h == "G0" || h == "G1")
        .map(|(_, w)| w)
        .collect();
    // The program ends with a move after the last beam-off: the retract along the tool axis,
    // at least 1 mm, so that a beam-off synchronized with motion takes effect.
    let exit = moves.pop().expect("moves");
    let last = blocks.last().expect("blocks");
    let u = m.tool_axis(last.end_axes[3], last.end_axes[4]);
    let up = last.end_tip()
        + u * EXIT_RETRACT_MIN_MM.max(Dialect::Generic.default_process().pierce_standoff);
    let lin = m.linear_axes(&up, last.end_axes[3], last.end_axes[4]);
    for (k, v) in ["X", "Y", "Z"].iter().zip(lin) {
        assert!(
            (exit[*k] - v).abs() <= 5e-7,
            "exit retract {k}: {} vs {v}",
            exit[*k]
        );
    }
    assert!(
        text.rfind("G0 X").expect("G0") > text.rfind("M5").expect("beam off"),
        "the retract follows the last beam-off"
    );
    let q = |w: &HashMap<String, f64>| Axes::from_array(["X", "Y", "Z", "A", "C"].map(|k| w[k]));
    // G0 to the pierce point, then the descent to the start.
    assert_eq!(
        q(&moves[1]),
        blocks[0].start_axes.map(|v| (v * 1e6).round() / 1e6),
        "descent to the start"
    );
    // Every block end appears, in order; arcs add chord points lying on the arc.
    let mut it = moves.iter().skip(2);
    for b in &blocks {
        let mut found = false;
        for w in it.by_ref() {
            let got = q(w);
            if (0..5).all(|k| (got[k] - b.end_axes[k]).abs() <= 5e-7) {
                found = true;
                break;
            }
            assert!(b.is_arc(), "only arcs have intermediate G1 points");
        }
        assert!(found, "block end {:?} in the program", b.end_axes);
    }
    // F is the machine axes' X Y Z feed (RS274/NGC G94) that makes each block take its
    // time at 6000 mm/min of the tip: the X Y Z times of the cut add up to tip length / feed.
    let mut t = 0.0;
    for w in moves.windows(2).skip(1) {
        let d = ((w[1]["X"] - w[0]["X"]).powi(2)
            + (w[1]["Y"] - w[0]["Y"]).powi(2)
            + (w[1]["Z"] - w[0]["Z"]).powi(2))
        .sqrt();
        t += d / w[1]["F"] * 60.0;
    }
    let tip: f64 = blocks.iter().map(|b| b.length()).sum();
    assert!(
        (t - tip / 100.0).abs() <= 1e-4 * t,
        "time {t} s vs tip length / feed {} s",
        tip / 100.0
    );
    assert!(text.trim_end().ends_with("M30"), "program end");
}

#[test]
fn sinumerik_gcode_parses_back_to_tips_orientations_and_arcs() {
    let m = PaperAcHead::paper_000();
    let c = circle(40.0, 10.0, -5.0, 3.0);
    let st = stations(&m, &c, 0.001, |p| {
        Vector3::new((p.x - 10.0) / 120.0, (p.y + 5.0) / 120.0, 1.0).normalize()
    });
    let curve = |t: f64| c.point(t);
    let blocks = fit_blocks(&m, &st, Some(&curve), 0, &FitOptions::default()).expect("fit");
    let motion = plan(&m, &blocks, &PlanOptions::new(5000.0, 0.001)).expect("plan");
    let feeds = motion.block_feeds();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ring.mpf");
    let opts = GcodeOptions::new(Dialect::Sinumerik, 5000.0);
    write_gcode(
        &path,
        &m,
        &blocks,
        &["ring".to_string()],
        Some(&feeds),
        &opts,
    )
    .expect("write");
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(text.contains("TRAORI"), "orientation transformation on");
    assert!(text.contains("TRAFOOF"), "and off");
    let moves: Vec<(String, HashMap<String, f64>)> = text
        .lines()
        .map(words)
        .filter(|(h, _)| h == "G0" || h == "G1" || h == "CIP")
        .collect();
    assert_eq!(
        moves.len(),
        blocks.len() + 3,
        "a move to the pierce point, the descent, one line per block and the exit retract"
    );
    let (head, exit) = moves.last().expect("moves");
    let last = blocks.last().expect("blocks");
    assert_eq!(head, "G0", "the program ends with a retract");
    assert!(
        (exit["Z"]
            - last.end_tip().z
            - last.end_tool_axis.z
                * EXIT_RETRACT_MIN_MM.max(Dialect::Generic.default_process().pierce_standoff))
        .abs()
            <= 5e-7,
        "the retract runs along the tool axis"
    );
    for (b, (head, w)) in blocks.iter().zip(&moves[2..]) {
        let tip = b.end_tip();
        for (k, v) in [
            ("X", tip.x),
            ("Y", tip.y),
            ("Z", tip.z),
            ("A3", b.end_tool_axis.x),
            ("B3", b.end_tool_axis.y),
            ("C3", b.end_tool_axis.z),
        ] {
            assert!((w[k] - v).abs() <= 5e-7, "{k}: {} vs {v}", w[k]);
        }
        if let Geometry::Arc(a) = &b.geometry {
            assert_eq!(head, "CIP", "arc as CIP");
            for (k, v) in [("I1", a.mid.x), ("J1", a.mid.y), ("K1", a.mid.z)] {
                assert!((w[k] - v).abs() <= 5e-7, "{k}: {} vs {v}", w[k]);
            }
        } else {
            assert_eq!(head, "G1", "line");
        }
    }
    // F is modal: the first block's, or the descent's if equal.
    let f = *moves[2].1.get("F").unwrap_or(&moves[1].1["F"]);
    assert!(
        f > 0.0 && f <= 5000.0 + 0.05,
        "planned feed within the programmed one: {f}"
    );
}

/// A Sinumerik rapid under `TRAORI` (`RTLION`) moves the tip straight between its `G0` ends;
/// kerf's traverse is a straight move of the machine's axes. A rapid that turns C by half a
/// turn is split until the middle of every piece (the machine's axes halfway, through the
/// model) lies within `RAPID_TCP_TOLERANCE_MM` of the piece's straight tip line, and the
/// pieces' ends carry the tool axis of those axes.
#[test]
fn sinumerik_rapids_follow_the_machines_straight_moves() {
    let m = PaperAcHead::paper_000();
    // An open curve whose tool axis turns along it (so the cut ends on other rotary axes than
    // it pierced with: the rapid after it must start from the cut's end), then a ring tilted
    // the other way.
    let c1 = freeform();
    let c2 = circle(20.0, 60.0, 0.0, 0.0);
    let out = |p: &nalgebra::Point3<f64>| Vector3::new(0.4, 0.004 * p.x, 1.0).normalize();
    let back = |_: &nalgebra::Point3<f64>| Vector3::new(-0.4, 0.0, 1.0).normalize();
    let f1 = |t: f64| c1.point(t);
    let f2 = |t: f64| c2.point(t);
    let paths = [
        kerf_interp::ProgramPath {
            id: "a".into(),
            stations: stations(&m, &c1, 0.01, out),
            curve: Some(&f1),
        },
        kerf_interp::ProgramPath {
            id: "b".into(),
            stations: stations(&m, &c2, 0.01, back),
            curve: Some(&f2),
        },
    ];
    let blocks = kerf_interp::fit_program(&m, &paths, &FitOptions::default()).expect("fit");
    let motion = plan(&m, &blocks, &PlanOptions::new(5000.0, 0.001)).expect("plan");
    let text = gcode(
        &m,
        &blocks,
        &["a".to_string(), "b".to_string()],
        Some(&motion.block_feeds()),
        &GcodeOptions::new(Dialect::Sinumerik, 5000.0),
    )
    .expect("program");
    assert!(
        text.lines().any(|l| l.trim() == "RTLION"),
        "G0 along the tip's line"
    );
    let moves: Vec<(String, HashMap<String, f64>)> = text
        .lines()
        .map(words)
        .filter(|(h, _)| h == "G0" || h == "G1" || h == "CIP")
        .collect();
    // The machine's axes of each written line, the inverse taken nearest the line before.
    let mut prev: Option<Axes> = None;
    let mut axes = Vec::new();
    for (_, w) in &moves {
        let tip = nalgebra::Point3::new(w["X"], w["Y"], w["Z"]);
        let u = Vector3::new(w["A3"], w["B3"], w["C3"]).normalize();
        let q = m.inverse(&tip, &u, prev.as_ref()).expect("reachable");
        prev = Some(q);
        axes.push((tip, q));
    }
    let mut pieces = 0;
    let mut worst = 0.0f64;
    for k in 1..moves.len() {
        if moves[k].0 != "G0" {
            continue;
        }
        let ((ta, qa), (tb, qb)) = (axes[k - 1], axes[k]);
        if (qa[4] - qb[4]).abs() > 1e-6 {
            pieces += 1;
        }
        let mid = qa.lerp(&qb, 0.5);
        let d = (m.tip(&mid) - nalgebra::center(&ta, &tb)).norm();
        worst = worst.max(d);
    }
    assert!(
        pieces >= 18,
        "the half turn of C split into pieces: {pieces}"
    );
    assert!(
        worst <= kerf_interp::RAPID_TCP_TOLERANCE_MM + 1e-5,
        "a piece's middle {worst} mm off the machine's straight move"
    );
}

/// Two paths where the second starts exactly where the first ends, at the same axes (a circle
/// and a smaller one touching it from inside at (10, 0)), with no traverse between them: each is
/// its own cut, beam off after the first, a pierce before the second, not one cut run on.
#[test]
fn a_path_that_starts_where_the_last_one_ended_is_pierced_again() {
    let m = PaperAcHead::paper_000();
    let lines_only = lines_only();
    let mut blocks = Vec::new();
    for (path, c) in [circle(10.0, 0.0, 0.0, 0.0), circle(5.0, 5.0, 0.0, 0.0)]
        .iter()
        .enumerate()
    {
        let st = stations(&m, c, 0.001, |_| Vector3::z());
        blocks.extend(fit_blocks(&m, &st, None, path, &lines_only).expect("fit"));
    }
    let first_end = blocks
        .iter()
        .rfind(|b| b.path == 0)
        .expect("path 0")
        .end_axes;
    let second_start = blocks
        .iter()
        .find(|b| b.path == 1)
        .expect("path 1")
        .start_axes;
    assert!(
        (0..5).all(|k| (first_end[k] - second_start[k]).abs() < 1e-9),
        "the second path starts at the first one's end: {first_end:?} {second_start:?}"
    );
    let ids = ["outer".to_string(), "inner".to_string()];
    let opts = GcodeOptions::new(Dialect::Generic, 6000.0);
    let text = gcode(&m, &blocks, &ids, None, &opts).expect("gcode");
    let code_lines: Vec<&str> = text
        .lines()
        .map(|l| l.split(';').next().unwrap_or("").trim())
        .collect();
    // The program opens with a beam off (the safe state); the cuts follow.
    let opened = code_lines
        .iter()
        .position(|l| *l == "M3")
        .expect("a beam on");
    let on = code_lines.iter().filter(|l| **l == "M3").count();
    let off = code_lines[opened..].iter().filter(|l| **l == "M5").count();
    assert_eq!((on, off), (2, 2), "one beam on and off per path:\n{text}");
    // The second cut's beam-on comes after the first cut's beam-off.
    let first_off = opened
        + code_lines[opened..]
            .iter()
            .position(|l| *l == "M5")
            .expect("off");
    let second_on = code_lines
        .iter()
        .enumerate()
        .filter(|(_, l)| **l == "M3")
        .nth(1)
        .expect("second on")
        .0;
    assert!(first_off < second_on, "off before the second pierce");
}

/// The controllers select their kerf compensation on a straight move: a compensated cut whose
/// first block is an arc (a circle fitted with arcs, no lead-in) is refused by name in the
/// Sinumerik dialect (LinuxCNC's raw-axis dialect writes no arcs at all and refuses the block
/// before); the same cut fitted with lines only is written, with its compensation.
#[test]
fn controller_compensation_refuses_an_arc_as_the_entry_move() {
    let m = PaperAcHead::paper_000();
    let st = stations(&m, &circle(10.0, 0.0, 0.0, 0.0), 0.001, |_| Vector3::z());
    let arcs = fit_blocks(&m, &st, None, 0, &FitOptions::default()).expect("fit");
    assert!(
        matches!(arcs[0].geometry, Geometry::Arc(_)),
        "the circle's first block is an arc"
    );
    let c = kerf_interp::CutterCompensation {
        left: true,
        kerf_width_mm: 0.2,
    };
    let ids = ["hole-7".to_string()];
    let opts =
        GcodeOptions::new(Dialect::Sinumerik, 3000.0).with_cutter_compensation(vec![Some(c)]);
    match gcode(&m, &arcs, &ids, None, &opts) {
        Err(kerf_interp::InterpError::CompensationOnArc { path }) => {
            assert_eq!(path, "hole-7", "the refusal names the path")
        }
        other => panic!("an arc entry must be refused, got {other:?}"),
    }
    let linuxcnc =
        GcodeOptions::new(Dialect::Linuxcnc, 3000.0).with_cutter_compensation(vec![Some(c)]);
    assert!(
        matches!(
            gcode(&m, &arcs, &ids, None, &linuxcnc),
            Err(kerf_interp::InterpError::UncheckedBlock { .. })
        ),
        "LinuxCNC's raw-axis dialect refuses arcs"
    );
    let lines = FitOptions::default().with_arcs(false);
    let blocks = fit_blocks(&m, &st, None, 0, &lines).expect("fit");
    let text = gcode(&m, &blocks, &ids, None, &opts).expect("lines are written");
    assert!(
        text.lines().any(|l| l.contains("G41")) && text.contains("OFFN=0.1"),
        "compensated with G41 and OFFN = kerf / 2"
    );
}

/// A path that starts where the last one ended is pierced again, so its pierce point is held to
/// the axis ranges too: two lines, the second starting 5 mm higher where the first ends; with
/// Z's range ending 1 mm above the second's start, a 1.5 mm standoff is refused for path 1
/// (the first path's pierce, 5 mm lower, is within it), and a 0.5 mm one is written.
#[test]
fn the_pierce_of_a_path_without_a_traverse_before_it_is_range_checked() {
    use nalgebra::Point3;
    let m = PaperAcHead::paper_000();
    let lines_only = lines_only();
    let (a, b, c) = (
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(10.0, 0.0, 5.0),
        Point3::new(20.0, 0.0, 5.0),
    );
    let mut blocks = Vec::new();
    for (path, (p, q)) in [(a, b), (b, c)].into_iter().enumerate() {
        let line = kerf_nurbs::NurbsCurve::line(p, q).expect("line");
        let st = stations(&m, &line, 0.001, |_| Vector3::z());
        blocks.extend(fit_blocks(&m, &st, None, path, &lines_only).expect("fit"));
    }
    let second = blocks.iter().position(|b| b.path == 1).expect("path 1");
    assert!(kerf_interp::starts_cut(&blocks, second) && kerf_interp::starts_cut(&blocks, 0));
    assert_eq!(
        (0..blocks.len())
            .filter(|&k| kerf_interp::starts_cut(&blocks, k))
            .count(),
        2
    );
    let top = blocks[second].start_axes[2];
    let mut low = m.clone();
    low.limits.range[2] = Some([-1000.0, top + 1.0]);
    let with = |standoff: f64| {
        GcodeOptions::new(Dialect::Generic, 6000.0).with_process(kerf_kinematics::Process {
            pierce_standoff: Some(standoff),
            ..kerf_kinematics::Process::default()
        })
    };
    match gcode(&low, &blocks, &[], None, &with(1.5)) {
        Err(kerf_interp::InterpError::PierceOutOfRange { path, axis, .. }) => {
            assert_eq!((path, axis.as_str()), (1, "Z"), "the second path's pierce")
        }
        other => panic!("the second pierce is above Z's range: {other:?}"),
    }
    gcode(&low, &blocks, &[], None, &with(0.5)).expect("within the range");
}
