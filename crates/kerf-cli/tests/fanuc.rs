//! The `fanuc` (`G43.4`, rotary axes) and `fanuc-ijk` (`G43.5`, tool direction) dialects
//! (issue 30): every block's syntax as Fanuc's tool center point control reads it, and a round
//! trip: the program read back (tip, tool direction, feed) against the same job's joint-space
//! program put through kerf's forward kinematics, line by line. No Fanuc control runs here: the
//! syntax is the manuals' block formats (`G43.4 H`, `G43.5 H`, `G05.1 Q1`/`Q0`, `G49`, `G04 X`
//! seconds, `%` and an `O` number), not an execution.

mod common;
use common::{cut_lines, fixture, kerf, read_back_against_joints, run_program, ReadBack, TipMove};

use kerf_kinematics::Machine;

fn program(curves: &str, machine: &str, dialect: &str) -> String {
    program_with(curves, machine, dialect, &[])
}

/// The program of `curves` on `machine` in `dialect`; the head check off (some fixtures meet
/// the head as drawn: `mixed`'s curves run under its tilted plane, the head fixtures need a
/// tilt; the syntax does not depend on it).
fn program_with(curves: &str, machine: &str, dialect: &str, extra: &[&str]) -> String {
    let mut args = vec!["--cut-clearance", "off"];
    args.extend_from_slice(extra);
    run_program(&fixture(curves), &fixture(machine), dialect, &args)
}

/// The words of a block: letter (with a `.`-suffix such as `G43.4` kept whole) and number.
fn words(line: &str) -> Vec<(char, f64)> {
    line.split_whitespace()
        .map(|w| {
            let mut c = w.chars();
            let letter = c.next().expect("a word");
            let value: f64 = c
                .as_str()
                .parse()
                .unwrap_or_else(|_| panic!("{w} in {line}: not a letter and a number"));
            (letter, value)
        })
        .collect()
}

fn word(line: &str, letter: char) -> Option<f64> {
    words(line)
        .into_iter()
        .find(|(l, _)| *l == letter)
        .map(|(_, v)| v)
}

/// Every line is one of the blocks a Fanuc TCP program of kerf may hold, in its order.
fn check_syntax(p: &str, ijk: bool, tilt: char) {
    let lines: Vec<&str> = p.lines().collect();
    assert_eq!(lines[0], "%", "tape start");
    assert!(
        lines[1].starts_with('O') && lines[1][1..].parse::<u32>().is_ok(),
        "program number: {}",
        lines[1]
    );
    assert_eq!(*lines.last().expect("lines"), "%", "tape end");
    let tcp = if ijk { "G43.5 H1" } else { "G43.4 H1" };
    let at = |l: &str| {
        lines
            .iter()
            .position(|x| *x == l)
            .unwrap_or_else(|| panic!("no {l} block"))
    };
    let (on, off, end) = (at(tcp), at("G49"), at("M30"));
    let is_move = |l: &&str| l.starts_with("G00 ") || l.starts_with("G01 ");
    let first_move = lines.iter().position(is_move).expect("moves");
    let last_move = lines.iter().rposition(is_move).expect("moves");
    assert!(
        on < first_move && last_move < off && off < at("G05.1 Q0") && at("G05.1 Q0") < end,
        "TCP on before the first move, G49 and G05.1 Q0 after the last, then M30"
    );
    assert!(at("G05.1 Q1") < on, "look-ahead on before TCP");
    // `%` ends the record on a Fanuc control: only the first and the last line.
    assert!(
        lines[1..lines.len() - 1].iter().all(|l| !l.contains('%')),
        "a % inside the program"
    );
    let position: Vec<char> = if ijk {
        vec!['X', 'Y', 'Z', 'I', 'J', 'K']
    } else {
        vec!['X', 'Y', 'Z', tilt, 'C']
    };
    for l in &lines[2..lines.len() - 1] {
        if l.starts_with('(') {
            assert!(
                l.ends_with(')') && !l[1..l.len() - 1].contains(['(', ')']),
                "comment {l}"
            );
            continue;
        }
        let fixed = [
            "G17 G21 G40 G49 G80 G90 G94",
            "G54",
            "G05.1 Q1",
            "G05.1 Q0",
            tcp,
            "G49",
            "M30",
            "M3",
            "M5",
        ];
        if fixed.contains(l) {
            continue;
        }
        let w = words(l);
        let letters: Vec<char> = w.iter().map(|(c, _)| *c).collect();
        match l.split_whitespace().next() {
            Some("G00") => assert_eq!(letters[1..], position[..], "{l}"),
            Some("G01") => {
                assert_eq!(letters[1..=position.len()], position[..], "{l}");
                assert_eq!(letters[position.len() + 1], 'F', "{l}");
                // The planned power where it changed (with a technology).
                assert!(
                    letters.len() == position.len() + 2
                        || (letters.len() == position.len() + 3
                            && letters[position.len() + 2] == 'S'),
                    "{l}"
                );
                assert!(w[position.len() + 1].1 > 0.0, "{l}: F > 0");
            }
            Some(w0) if w0.starts_with('S') => {
                assert!(
                    letters == ['S'] && (0.0..=100.0).contains(&w[0].1),
                    "{l}: power %"
                )
            }
            // Seconds with a decimal point (without one Fanuc reads milliseconds).
            Some("G04") => assert!(
                letters == ['G', 'X'] && w[1].1 > 0.0 && l.contains('.'),
                "{l}: seconds"
            ),
            _ => panic!("a block a Fanuc TCP program of kerf does not write: {l}"),
        }
        if ijk && is_move(l) {
            let n = (word(l, 'I').expect("I").powi(2)
                + word(l, 'J').expect("J").powi(2)
                + word(l, 'K').expect("K").powi(2))
            .sqrt();
            assert!((n - 1.0).abs() < 1e-5, "{l}: a unit direction");
        }
    }
}

fn round_trip(curves: &str, machine: &str, ijk: bool) {
    let m = Machine::read(fixture(machine)).expect("machine");
    let tilt = m.axis_names()[3].chars().next().expect("tilt");
    let dialect = if ijk { "fanuc-ijk" } else { "fanuc" };
    let fanuc = program(curves, machine, dialect);
    check_syntax(&fanuc, ijk, tilt);
    let joint = program(curves, machine, "linuxcnc");
    let tilt = tilt.to_string();
    let moves: Vec<Option<TipMove>> = cut_lines(&fanuc, "M3", "M5", |l| l.starts_with("G01 "))
        .into_iter()
        .map(|l| {
            l.map(|l| {
                TipMove::read(
                    &l,
                    ijk.then_some(["I", "J", "K"]),
                    (!ijk).then_some([&tilt, "C"]),
                )
            })
        })
        .collect();
    // Six printed decimals of the joints through a ~300 mm lever: a few um.
    let within = ReadBack {
        tip_mm: 2e-5,
        direction: 1e-5,
        rotary_deg: 2e-6,
    };
    read_back_against_joints(&m, &moves, &joint, &within);
}

#[test]
fn fanuc_programs_read_back_as_the_joint_program_through_the_kinematics() {
    round_trip("tube_saddle.json", "machines/ac_head.json", false);
    round_trip("tube_saddle.json", "machines/ac_head.json", true);
    round_trip("tube_saddle.json", "machines/fork_head.json", true);
    round_trip("dome.json", "machines/table_table.json", false);
}

#[test]
fn g43_5_with_ijk_is_refused_on_table_machines_by_name() {
    for machine in ["machines/table_table.json", "machines/head_table.json"] {
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().join("out");
        let r = kerf()
            .args(["run"])
            .arg(fixture("circle.json"))
            .arg("-m")
            .arg(fixture(machine))
            .args(["--dialect", "fanuc-ijk", "-q", "-o"])
            .arg(&out)
            .output()
            .expect("kerf runs");
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{machine}: {err}");
        assert!(
            err.contains("dialect fanuc-ijk: the machine is a")
                && err.contains("alarm PS5421")
                && err.contains("use the fanuc dialect (G43.4, rotary axes)"),
            "{machine}: {err}"
        );
        assert!(!out.exists(), "{machine}: nothing written");
    }
}

#[test]
fn every_shipped_fixture_gets_a_fanuc_program_of_valid_blocks() {
    // The gantry holds every fixture: each one in both forms.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut n = 0;
    for e in std::fs::read_dir(dir).expect("fixtures") {
        let path = e.expect("entry").path();
        if path.extension().and_then(|x| x.to_str()) != Some("json") {
            continue;
        }
        let name = path.file_name().and_then(|f| f.to_str()).expect("name");
        for ijk in [false, true] {
            let p = program(
                name,
                "machines/gantry_ac.json",
                if ijk { "fanuc-ijk" } else { "fanuc" },
            );
            check_syntax(&p, ijk, 'A');
        }
        n += 1;
    }
    assert!(n >= 15, "{n} fixtures");
    // With a technology: S per block where the planned power changes, the pierce's before the
    // beam, S0 at the end.
    let table = fixture("technology/fiber_3kw_example.json");
    let p = program_with(
        "dome.json",
        "machines/gantry_ac.json",
        "fanuc",
        &[
            "--technology",
            table.to_str().expect("path"),
            "--material",
            "stainless",
            "--thickness",
            "2",
        ],
    );
    check_syntax(&p, false, 'A');
    assert!(p.contains(" S") && p.contains("\nS0\n"), "power words");
}
