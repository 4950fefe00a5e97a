//! The three G-code dialects read back: headers, the framing of every cut (pierce point on the
//! tool axis, beam on, dwell, descent, cut, beam off), no beam during rapids, the feed words'
//! meaning, hostile ids confined to comments, bad process codes refused.

mod common;

use common::{circle, stations};
use kerf_interp::{
    gcode_motion, interpolate, AxisModel, ChordTerm, Dialect, FitOptions, GcodeOptions,
    InterpError, Motion, PaperAcHead, PlanOptions, ProgramPath,
};
use kerf_kinematics::{Axes, Process};
use nalgebra::{Point3, Vector3};

const DIALECTS: [Dialect; 3] = [Dialect::Generic, Dialect::Sinumerik, Dialect::Linuxcnc];

/// Two closed contours, the second with a tilted tool, linked by rapids with a 10 mm retract.
fn program(m: &PaperAcHead, dialect: Dialect) -> Motion {
    let a = stations(m, &circle(20.0, 0.0, 0.0, 0.0), 0.005, |_| Vector3::z());
    let b = stations(m, &circle(15.0, 80.0, 10.0, 5.0), 0.005, |p| {
        Vector3::new((p.x - 80.0) / 60.0, (p.y - 10.0) / 60.0, 1.0).normalize()
    });
    let paths = vec![
        ProgramPath {
            id: "a".into(),
            stations: a,
            curve: None,
        },
        ProgramPath {
            id: "b".into(),
            stations: b,
            curve: None,
        },
    ];
    let fit = FitOptions::with_tolerance(0.005)
        .with_arcs(!dialect.raw_axes())
        .with_merge_lines(!dialect.raw_axes())
        .with_retract_mm(10.0);
    interpolate(m, &paths, &fit, &PlanOptions::new(6000.0, 0.001)).expect("plan")
}

/// The code of a line without its comment (`;` to the end, or `( ... )`).
fn code(line: &str) -> String {
    let mut out = String::new();
    let mut depth = 0;
    for c in line.chars() {
        match c {
            '(' => depth += 1,
            ')' if depth > 0 => depth -= 1,
            ';' if depth == 0 => break,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out.trim().to_string()
}

/// `X1.5` / `A3=0.2` words of a code line.
fn word(code: &str, key: &str) -> Option<f64> {
    code.split_whitespace().find_map(|w| {
        let v = w.strip_prefix(key)?;
        let v = v.strip_prefix('=').unwrap_or(v);
        if v.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '.') {
            v.parse().ok()
        } else {
            None
        }
    })
}

fn u_of(m: &PaperAcHead, q: &Axes) -> Vector3<f64> {
    // u = Rz(C) Rx(A) ez, written out (formats.md), not the model's own function.
    let (a, c) = (q[3].to_radians(), q[4].to_radians());
    Vector3::new(a.sin() * c.sin(), -a.sin() * c.cos(), a.cos()) + 0.0 * m.tool_axis(0.0, 0.0)
}

fn tip_of(m: &PaperAcHead, q: &Axes) -> Point3<f64> {
    // Paper 000 eq 16 solved for the tip.
    let u = u_of(m, q);
    let c = q[4].to_radians();
    Point3::new(
        q[0] - m.r_a * u.x + m.r_c * c.cos(),
        q[1] - m.r_a * u.y + m.r_c * c.sin(),
        q[2] - m.r_a * u.z,
    )
}

#[test]
fn every_cut_is_framed_and_no_beam_during_rapids() {
    let m = PaperAcHead::paper_000();
    for dialect in DIALECTS {
        let motion = program(&m, dialect);
        let opts = GcodeOptions::new(dialect, 6000.0);
        let text = gcode_motion(&m, &motion, &["a".into(), "b".into()], &opts).expect("gcode");
        let p = dialect.default_process();
        let (on, off) = (p.beam_on[0].as_str(), p.beam_off[0].as_str());
        let lines: Vec<String> = text.lines().map(code).filter(|l| !l.is_empty()).collect();
        let mut beam = false;
        let mut cuts = 0;
        let mut last_rapid: Option<String> = None;
        let mut i = 0;
        while i < lines.len() {
            let l = &lines[i];
            if l == on {
                assert!(!beam, "{dialect:?}: beam on twice");
                beam = true;
                cuts += 1;
                // Dwell right after, then the descent as a feed move.
                let dwell = &lines[i + 1];
                assert!(
                    dwell.starts_with("G4 "),
                    "{dialect:?}: dwell after beam on: {dwell}"
                );
                let secs = word(
                    dwell,
                    if dialect == Dialect::Sinumerik {
                        "F"
                    } else {
                        "P"
                    },
                );
                assert_eq!(secs, Some(0.2), "{dialect:?}: default dwell");
                let pierce = last_rapid.clone().expect("a rapid to the pierce point");
                let descent = lines[i + 2..]
                    .iter()
                    .find(|l| l.starts_with("G1 "))
                    .expect("descent");
                let dist = if dialect == Dialect::Sinumerik {
                    let at = |l: &str| {
                        Point3::new(
                            word(l, "X").unwrap(),
                            word(l, "Y").unwrap(),
                            word(l, "Z").unwrap(),
                        )
                    };
                    let u = Vector3::new(
                        word(descent, "A3").unwrap(),
                        word(descent, "B3").unwrap(),
                        word(descent, "C3").unwrap(),
                    );
                    let d = at(&pierce) - at(descent);
                    assert!(
                        (d - u * d.norm()).norm() < 1e-5,
                        "{dialect:?}: pierce on the tool axis"
                    );
                    d.norm()
                } else {
                    let q = |l: &str| {
                        Axes::from_array(["X", "Y", "Z", "A", "C"].map(|k| word(l, k).unwrap()))
                    };
                    let (qp, qd) = (q(&pierce), q(descent));
                    assert_eq!(
                        (qp[3], qp[4]),
                        (qd[3], qd[4]),
                        "{dialect:?}: rotary axes stand"
                    );
                    let d = tip_of(&m, &qp) - tip_of(&m, &qd);
                    let u = u_of(&m, &qd);
                    assert!(
                        (d - u * d.norm()).norm() < 1e-5,
                        "{dialect:?}: pierce on the tool axis, {d:?} vs {u:?}"
                    );
                    d.norm()
                };
                assert!((dist - 1.5).abs() < 1e-5, "{dialect:?}: standoff {dist}");
            } else if l == off {
                beam = false;
            } else if l.starts_with("G0 ") {
                assert!(!beam, "{dialect:?}: rapid with the beam on: {l}");
                last_rapid = Some(l.clone());
            } else if l.starts_with("G1 ") || l.starts_with("CIP ") {
                assert!(beam, "{dialect:?}: feed move with the beam off: {l}");
                if dialect == Dialect::Linuxcnc {
                    assert!(
                        word(l, "F").is_some_and(|f| f > 0.0),
                        "G93: F on every block: {l}"
                    );
                }
            }
            i += 1;
        }
        assert!(!beam, "{dialect:?}: beam off at the end");
        assert_eq!(cuts, 2, "{dialect:?}: one pierce per cut");
        assert_eq!(
            text.matches(&format!("\n{off}\n")).count(),
            3,
            "{dialect:?}: beam off in the preamble and after each cut"
        );
        let end = if dialect == Dialect::Linuxcnc {
            "M2\n"
        } else {
            "M30\n"
        };
        assert!(text.ends_with(end), "{dialect:?}: ends with {end:?}");
        assert!(
            !text.contains('\r') && !text.contains(" \n"),
            "{dialect:?}: clean line ends"
        );
    }
}

#[test]
fn headers_state_units_feed_budget_machine_and_process() {
    let m = PaperAcHead::paper_000();
    for dialect in DIALECTS {
        let motion = program(&m, dialect);
        let opts = GcodeOptions::new(dialect, 6000.0)
            .with_linearization_tolerance_mm(Some(0.005))
            .with_fit_tolerance_mm(0.01)
            .with_chord_term(ChordTerm::Certified(0.01))
            .with_source(Some("part.json".into()));
        let text = gcode_motion(&m, &motion, &[], &opts).expect("gcode");
        // Without being told where the chord term comes from, the program states none, and a
        // claim is stated as one.
        let line = |o: &GcodeOptions| -> String {
            gcode_motion(&m, &motion, &[], o)
                .expect("gcode")
                .lines()
                .filter(|l| l.contains("tolerance budget"))
                .collect::<Vec<_>>()
                .join("\n")
        };
        let unknown = line(&opts.clone().with_chord_term(ChordTerm::Unknown));
        assert!(
            unknown.contains("chord unknown + ")
                && unknown.contains(if dialect.raw_axes() {
                    "= 0.011"
                } else {
                    "= 0.021"
                }),
            "{dialect:?}: {unknown}"
        );
        let claimed = line(&opts.clone().with_chord_term(ChordTerm::Claimed(0.01)));
        assert!(
            claimed.contains("chord 0.01 + ") && claimed.contains("claim, not verified"),
            "{dialect:?}: {claimed}"
        );
        let head: String = text.lines().take(16).collect::<Vec<_>>().join("\n");
        // Arcs and merged lines (tool-tip control) add their fit to the chord: they lie
        // within the fit tolerance of the polyline, which lies within the chord error of the
        // curve.
        let budget = if dialect.raw_axes() {
            "tolerance budget mm: chord 0.01 + linearization 0.005 + interpolation_chord 0.001 + controller_blending 0.005 = 0.021"
        } else {
            "tolerance budget mm: chord 0.01 + fit 0.01 + linearization 0.005 + interpolation_chord 0.001 + controller_blending 0.005 = 0.031"
        };
        // The whole line: the sum without its binary rounding noise.
        assert!(
            head.lines()
                .any(|l| l.trim_end_matches(')').ends_with(budget)),
            "{dialect:?}: budget line {budget:?}:\n{head}"
        );
        // The total the report states is the same decimal, not the binary sum's noise.
        let total = if dialect.raw_axes() { 0.021 } else { 0.031 };
        assert_eq!(opts.budget_total(), total, "{dialect:?}: budget total");
        for want in [
            "machine: paper-000 laser head",
            "source: part.json",
            "units: mm",
            "process: beam on",
        ] {
            assert!(
                head.contains(want),
                "{dialect:?}: header has {want:?}:\n{head}"
            );
        }
        let feed = match dialect {
            Dialect::Linuxcnc => "feed: G93 inverse time",
            Dialect::Generic => "NOT of the tool tip",
            Dialect::Sinumerik => "F in mm/min of the tool tip [TRAORI]",
            // linuxcnc-tcp needs a kerf.machine/1 machine: crates/kerf-cli/tests/linuxcnc_tcp.rs.
            other => unreachable!("{other:?} is not in DIALECTS"),
        };
        assert!(
            head.contains(feed),
            "{dialect:?}: feed semantics {feed:?}:\n{head}"
        );
        assert!(
            text.contains("path 0") && text.contains("path 1"),
            "missing ids named by number"
        );
        match dialect {
            Dialect::Linuxcnc => {
                assert!(
                    text.contains("G17 G21 G40 G49 G54 G80 G90"),
                    "safe preamble"
                );
                assert!(
                    text.contains("\nG93\n")
                        && text.contains("\nG64 P0.005 Q0\n")
                        && text.contains("\nG61\n")
                );
            }
            Dialect::Sinumerik => {
                for w in ["\nG54\n", "\nSOFT\n", "\nG642\n", "\nTRAORI\n", "CTOL="] {
                    assert!(text.contains(w), "Sinumerik frame has {w:?}");
                }
            }
            Dialect::Generic => assert!(text.contains("G90 G94")),
            other => unreachable!("{other:?} is not in DIALECTS"),
        }
    }
}

/// The time the controller takes by the feed words' own rule equals the plan's: G93 (1/F min
/// per block), the RS274/NGC G94 rule on the machine axes (generic), the tip (Sinumerik).
#[test]
fn feed_words_reproduce_the_planned_block_times() {
    let m = PaperAcHead::paper_000();
    for dialect in DIALECTS {
        let motion = program(&m, dialect);
        let opts = GcodeOptions::new(dialect, 6000.0).with_process(Process {
            pierce_standoff: Some(0.0),
            pierce_dwell_s: Some(0.0),
            ..Process::default()
        });
        let text = gcode_motion(&m, &motion, &[], &opts).expect("gcode");
        let planned: f64 = (0..motion.blocks().len())
            .filter(|&b| !motion.blocks()[b].rapid)
            .map(|b| motion.block_duration(b))
            .sum();
        let mut t = 0.0;
        let mut prev: Option<[f64; 6]> = None;
        let mut f = f64::NAN;
        for l in text.lines().map(code) {
            let keys: &[&str] = if dialect == Dialect::Sinumerik {
                &["X", "Y", "Z", "A3", "B3", "C3"]
            } else {
                &["X", "Y", "Z", "A", "C"]
            };
            let is_move = l.starts_with("G0") || l.starts_with("G1 ") || l.starts_with("CIP ");
            if !is_move {
                continue;
            }
            let mut q = prev.unwrap_or([0.0; 6]);
            for (k, key) in keys.iter().enumerate() {
                if let Some(v) = word(&l, key) {
                    q[k] = v;
                }
            }
            if let Some(v) = word(&l, "F") {
                f = v;
            }
            if let (Some(p), false) = (prev, l.starts_with("G0 ")) {
                let lin =
                    ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt();
                t += match dialect {
                    Dialect::Linuxcnc => 60.0 / f,
                    Dialect::Generic => {
                        let rot = ((q[3] - p[3]).powi(2) + (q[4] - p[4]).powi(2)).sqrt();
                        (if lin > 0.0 { lin } else { rot }) / f * 60.0
                    }
                    // Lines only here (the tip's chord); arcs are checked by length below.
                    Dialect::Sinumerik => 0.0,
                    other => unreachable!("{other:?} is not in DIALECTS"),
                };
            }
            prev = Some(q);
        }
        if dialect == Dialect::Sinumerik {
            continue;
        }
        assert!(
            (t - planned).abs() <= 2e-4 * planned,
            "{dialect:?}: program time {t} s vs planned {planned} s"
        );
    }
}

#[test]
fn hostile_ids_and_names_never_make_a_block() {
    let m = PaperAcHead {
        name: "evil\nG0 X1400 Y700 Z-90 A0 C0\nM30 (".into(),
        ..PaperAcHead::paper_000()
    };
    let hostile: Vec<String> = [
        "hole\nG0 X1400 Y700 Z-90 A0 C0\nM30",
        ")G0X1(",
        "x\rM2\r\n",
        "sep\u{2028}G0 X5\u{2029}M30",
        "nul\0M30",
        "nel\u{85}M30\u{b}\u{c}",
        ";M2",
        "(MSG,boom)",
        &"long".repeat(200),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let tame: Vec<String> = vec!["a".into(), "b".into()];
    for dialect in DIALECTS {
        let motion = program(&m, dialect);
        for pair in hostile.chunks(2) {
            let ids: Vec<String> = pair.to_vec();
            let opts =
                GcodeOptions::new(dialect, 6000.0).with_source(Some(format!("{}.json", pair[0])));
            let bad = gcode_motion(&m, &motion, &ids, &opts).expect("gcode");
            let tame_opts =
                GcodeOptions::new(dialect, 6000.0).with_source(Some("part.json".into()));
            let good = gcode_motion(&m, &motion, &tame, &tame_opts).expect("gcode");
            let codes = |t: &str| -> Vec<String> {
                t.lines().map(code).filter(|c| !c.is_empty()).collect()
            };
            assert_eq!(
                codes(&bad),
                codes(&good),
                "{dialect:?}: the same blocks whatever the ids {ids:?}"
            );
            assert_eq!(
                bad.lines().count(),
                good.lines().count(),
                "{dialect:?}: no extra line"
            );
            for l in bad.lines() {
                assert!(
                    l.len() <= 255,
                    "{dialect:?}: line too long for LinuxCNC: {}",
                    l.len()
                );
                assert!(
                    l.bytes().all(|b| (0x20..0x7f).contains(&b)),
                    "{dialect:?}: only printable ASCII: {l:?}"
                );
                if dialect == Dialect::Linuxcnc && l.starts_with('(') {
                    assert!(
                        l.ends_with(')') && l[1..l.len() - 1].find(['(', ')']).is_none(),
                        "one flat comment: {l}"
                    );
                }
            }
        }
    }
}

#[test]
fn bad_process_codes_are_named_errors() {
    let m = PaperAcHead::paper_000();
    let motion = program(&m, Dialect::Linuxcnc);
    for (p, want) in [
        (Process { pierce_dwell_s: Some(-1.0), ..Process::default() }, "process.pierce_dwell_s: must lie in [0, 60] (got -1)"),
        (Process { pierce_standoff: Some(f64::NAN), ..Process::default() }, "process.pierce_standoff: must lie in [0, 100] (got NaN)"),
        (Process { beam_on: Some(vec![]), ..Process::default() }, "process.beam_on: must list at least one program line"),
        (Process { beam_off: Some(vec!["M65 P0\nG0 X0".into()]), ..Process::default() }, "process.beam_off[0]: must be one printable ASCII program line without comments (found '\\n')"),
    ] {
        let opts = GcodeOptions::new(Dialect::Linuxcnc, 6000.0).with_process(p);
        let e = gcode_motion(&m, &motion, &[], &opts).expect_err(want);
        assert_eq!(e.to_string(), want);
    }
    // Given codes are written as given, in place of the defaults.
    let opts = GcodeOptions::new(Dialect::Linuxcnc, 6000.0).with_process(Process {
        beam_on: Some(vec!["M62 P2".into(), "M3 S900".into()]),
        beam_off: Some(vec!["M5".into()]),
        pierce_dwell_s: Some(0.5),
        pierce_standoff: Some(0.0),
        kerf_width_mm: None,
        standoff_mm: None,
        technology: None,
    });
    let text = gcode_motion(&m, &motion, &[], &opts).expect("gcode");
    // The synchronized M62 lights the pierce as the immediate M64 (else the dwell runs dark).
    assert_eq!(
        text.matches("\nM64 P2\nM3 S900\nG4 P0.5\n").count(),
        2,
        "beam on, dwell per cut"
    );
    assert!(
        !text.contains("M64 P0") && !text.contains("M65"),
        "no default codes"
    );
}

#[test]
fn a_pierce_point_outside_an_axis_range_is_refused() {
    // The planned blocks stay within the ranges; the pierce standoff above each cut's start
    // is added by the writer. With Z's range ending 1 mm above the highest cut start, a
    // 1.5 mm standoff leaves it (the review's machine wrote Z680 on a Z range ending at 600)
    // and a 0.5 mm one does not.
    let m = PaperAcHead::paper_000();
    for dialect in DIALECTS {
        let motion = program(&m, dialect);
        let blocks = motion.blocks();
        let top = (0..blocks.len())
            .filter(|&k| !blocks[k].rapid && (k == 0 || blocks[k - 1].rapid))
            .map(|k| blocks[k].start_axes[2])
            .fold(f64::NEG_INFINITY, f64::max);
        let mut low = m.clone();
        low.limits.range[2] = Some([-100.0, top + 1.0]);
        let with = |standoff: f64| {
            GcodeOptions::new(dialect, 6000.0).with_process(Process {
                pierce_standoff: Some(standoff),
                ..Process::default()
            })
        };
        let e = gcode_motion(&low, &motion, &[], &with(1.5)).expect_err("pierce above the range");
        assert!(
            matches!(&e, InterpError::PierceOutOfRange { axis, value, .. } if axis == "Z" && *value > top + 1.0),
            "{dialect:?}: {e}"
        );
        gcode_motion(&low, &motion, &[], &with(0.5)).expect("pierce within the range");
    }
}
