//! The optional `process` object of `kerf.machine/1`: read, refused with the JSON path when
//! bad, written back by `to_json`.

use kerf_kinematics::{Machine, Process};

fn machine(process: &str) -> String {
    format!(
        r#"{{"format": "kerf.machine/1", "name": "m",
  "kinematics": {{ "type": "ac-head", "r_a": 180.0, "r_c": 95.0 }},
  "limits": {{ "X": [-1500, 1500], "Y": [-800, 800], "Z": [-100, 600], "A": [-135, 135], "C": null }},
  "max_velocity": {{ "X": 60000, "Y": 60000, "Z": 30000, "A": 36000, "C": 36000 }},
  "max_acceleration": {{ "X": 10000, "Y": 10000, "Z": 8000, "A": 20000, "C": 20000 }}{process}}}"#
    )
}

#[test]
fn absent_process_is_empty_and_a_full_one_reads_back() {
    let m = Machine::from_str(&machine("")).expect("no process");
    assert!(m.process.is_empty());
    let m = Machine::from_str(&machine(
        r#", "process": { "beam_on": ["M64 P0", "G4 P0.01"], "beam_off": ["M65 P0"], "pierce_dwell_s": 0.2, "pierce_standoff": 1.5, "kerf_width_mm": 0.15, "standoff_mm": 0.8, "technology": "tables/fiber.json" }"#,
    ))
    .expect("full process");
    assert_eq!(
        m.process,
        Process {
            beam_on: Some(vec!["M64 P0".into(), "G4 P0.01".into()]),
            beam_off: Some(vec!["M65 P0".into()]),
            pierce_dwell_s: Some(0.2),
            pierce_standoff: Some(1.5),
            kerf_width_mm: Some(0.15),
            standoff_mm: Some(0.8),
            technology: Some("tables/fiber.json".into()),
        }
    );
    let back = Machine::from_str(&m.to_json()).expect("to_json reads back");
    assert_eq!(back.process, m.process, "to_json keeps the process");
    let partial =
        Machine::from_str(&machine(r#", "process": { "pierce_dwell_s": 0 }"#)).expect("one key");
    assert_eq!(partial.process.pierce_dwell_s, Some(0.0));
    assert_eq!(partial.process.beam_on, None, "absent key stays absent");
    for (w, want) in [
        ("0", "process.kerf_width_mm: must lie in (0, 20] (got 0)"),
        ("25", "process.kerf_width_mm: must lie in (0, 20] (got 25)"),
        (
            "\"0.2\"",
            "process.kerf_width_mm: expected a number, found a string",
        ),
    ] {
        let e = Machine::from_str(&machine(&format!(
            r#", "process": {{ "kerf_width_mm": {w} }}"#
        )))
        .expect_err("kerf width out of range");
        assert!(e.to_string().contains(want), "{e}");
    }
}

#[test]
fn real_process_codes_are_accepted() {
    // Beam codes of LinuxCNC (digital outputs, spindle-as-laser with power), Sinumerik
    // (system variables) and vendor M-codes with parameters.
    for line in [
        "M64 P0",
        "M62 P2",
        "M3 S900",
        "M3S2000",
        "M7",
        "M10 P1 Q2",
        "M66 E0",
        "G4 P0.5",
        "G4 F0.5",
        "$A_OUT[1]=1",
        "$A_DBB[0]=255 M100",
    ] {
        assert_eq!(
            kerf_kinematics::process_line_defect(line),
            None,
            "{line:?} is a process line"
        );
        let process = format!(r#", "process": {{"beam_on": [{line:?}]}}"#);
        Machine::from_str(&machine(&process)).expect(line);
    }
}

#[test]
fn bad_process_values_are_named_errors() {
    let cases = [
        (r#"{"pierce_dwell_s": -1}"#, "process.pierce_dwell_s: must lie in [0, 60] (got -1)"),
        (r#"{"pierce_standoff": -0.5}"#, "process.pierce_standoff: must lie in [0, 100] (got -0.5)"),
        (r#"{"pierce_dwell_s": "long"}"#, "process.pierce_dwell_s: expected a number, found a string"),
        (r#"{"beam_on": []}"#, "process.beam_on: must list at least one program line"),
        (r#"{"beam_on": ["M64 P0", " "]}"#, "process.beam_on[1]: must not be empty"),
        (r#"{"beam_off": "M65 P0"}"#, "process.beam_off: expected a list of program lines, found a string"),
        (r#"{"beam_off": [5]}"#, "process.beam_off[0]: expected a string, found a number"),
        (r#"{"beam_on": ["M64 P0\nG0 X1400"]}"#, "process.beam_on[0]: must be one printable ASCII program line without comments (found '\\n')"),
        (r#"{"beam_on": ["M3 (on)"]}"#, "process.beam_on[0]: must be one printable ASCII program line without comments (found '(')"),
        (r#"{"beam_on": ["M3"], "dwell": 1}"#, "process.dwell: unknown key (known: beam_on, beam_off, pierce_dwell_s, pierce_standoff, kerf_width_mm, standoff_mm, technology)"),
        (r#"["M3"]"#, "process: expected an object, found an array"),
        // The review's machine files: no motion, program end, o-word or tape mark can ride
        // in on a process line, and no absurd pierce.
        (r#"{"beam_on": ["G0 X1400 Y700 Z-90"]}"#, "process.beam_on[0]: G0 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r#"{"beam_on": ["M30"]}"#, "process.beam_on[0]: M30 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r#"{"beam_off": ["M5", "M2"]}"#, "process.beam_off[1]: M2 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r#"{"beam_on": ["%"]}"#, "process.beam_on[0]: \"%\": expected words of a letter and a number"),
        (r#"{"beam_on": ["o100 call"]}"#, "process.beam_on[0]: O100 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r#"{"beam_on": ["M3 S1000 F20"]}"#, "process.beam_on[0]: F20 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r##"{"beam_on": ["#1=5"]}"##, "process.beam_on[0]: \"#1=5\": expected words of a letter and a number"),
        (r#"{"beam_on": ["$A_OUT[1]=1 X5"]}"#, "process.beam_on[0]: X5 may not be a process word: it moves the machine, sets a feed or a tool, or changes the program's flow"),
        (r#"{"beam_on": ["$A_OUT[1]"]}"#, "process.beam_on[0]: \"$A_OUT[1]\" is not a system-variable assignment $NAME[INDEX]=NUMBER"),
        (r#"{"pierce_standoff": 1e300}"#, "process.pierce_standoff: must lie in [0, 100] (got 1e300)"),
        (r#"{"pierce_dwell_s": 1e300}"#, "process.pierce_dwell_s: must lie in [0, 60] (got 1e300)"),
    ];
    for (process, want) in cases {
        let e =
            Machine::from_str(&machine(&format!(r#", "process": {process}"#))).expect_err(process);
        assert_eq!(e.to_string(), want, "{process}");
    }
}

/// Issue 35: a 5 MB beam code was accepted and written into every cut. Each line is at most
/// `MAX_PROCESS_LINE_CHARS` (LinuxCNC's longest line), each list at most `MAX_PROCESS_LINES`;
/// the refusal names the key and the count, never quotes the line.
#[test]
fn process_codes_have_a_length_limit() {
    use kerf_kinematics::{MAX_PROCESS_LINES, MAX_PROCESS_LINE_CHARS};
    assert_eq!(
        (MAX_PROCESS_LINE_CHARS, MAX_PROCESS_LINES),
        (255, 64),
        "limits"
    );
    // The longest allowed line: an M word with a long parameter list is still a process line.
    let longest = format!("M64 P{}", "0".repeat(MAX_PROCESS_LINE_CHARS - 5));
    assert_eq!(longest.len(), MAX_PROCESS_LINE_CHARS, "at the limit");
    Machine::from_str(&machine(&format!(
        r#", "process": {{"beam_on": [{longest:?}]}}"#
    )))
    .expect("a line of 255 characters");
    let huge = format!("M64 P{}", "0".repeat(5_000_000 - 5));
    let cases = [
        (
            format!(r#"{{"beam_on": [{huge:?}]}}"#),
            "process.beam_on[0]: 5000000 characters, at most 255".to_owned(),
        ),
        (
            format!(r#"{{"beam_off": ["M65 P0", "{longest}0"]}}"#),
            "process.beam_off[1]: 256 characters, at most 255".to_owned(),
        ),
        (
            format!(
                r#"{{"beam_on": [{}]}}"#,
                vec![r#""M64 P0""#; 100_000].join(",")
            ),
            "process.beam_on: 100000 lines, at most 64".to_owned(),
        ),
    ];
    for (process, want) in cases {
        let e = Machine::from_str(&machine(&format!(r#", "process": {process}"#)))
            .expect_err("too long");
        assert_eq!(e.to_string(), want, "message");
    }
    // A process built in code is held to the same limits (`Process::validate`, which the
    // G-code writer runs too).
    let p = Process {
        beam_off: Some(vec!["M5".to_owned(); MAX_PROCESS_LINES + 1]),
        ..Process::default()
    };
    let e = p.validate().expect_err("65 lines");
    assert_eq!(
        e.to_string(),
        "process.beam_off: 65 lines, at most 64",
        "built in code"
    );
}

/// The optional `head`: solids from the nozzle tip up, read strictly, written back.
#[test]
fn a_head_reads_back_and_bad_heads_are_refused_by_path() {
    let m = Machine::from_str(&machine(
        r#", "head": { "solids": [ { "type": "cone", "length": 20, "tip_diameter": 2, "cone_angle_deg": 30 }, { "type": "cylinder", "length": 100, "diameter": 80 } ] }"#,
    ))
    .expect("head");
    let h = m.head.as_ref().expect("a head");
    // A 30-degree cone widens by 2 tan(15 deg) per mm of length.
    let top = 2.0 + 2.0 * 20.0 * 15f64.to_radians().tan();
    assert!((h.solids[0].top_diameter_mm - top).abs() < 1e-12, "{h:?}");
    assert_eq!(h.length_mm(), 120.0);
    assert_eq!(h.max_radius_mm(), 40.0);
    assert_eq!(
        h.radius_at(20.0),
        Some(40.0),
        "the larger radius where solids meet"
    );
    let back = Machine::from_str(&m.to_json()).expect("to_json reads back");
    assert_eq!(back.head, m.head, "to_json keeps the head");
    for (head, want) in [
        (r#"[]"#, "head: expected an object, found an array"),
        (r#"{"solids": []}"#, "head.solids: must list at least one solid"),
        (r#"{"solid": []}"#, "head.solid: unknown key (known: solids)"),
        (
            r#"{"solids": [{"type": "cone", "length": 20, "tip_diameter": 2, "top_diameter": 9, "cone_angle_deg": 30}]}"#,
            "head.solids[0]: a cone takes top_diameter or cone_angle_deg, not both",
        ),
        (
            r#"{"solids": [{"type": "cylinder", "length": 20, "diameter": 9, "tip_diameter": 2}]}"#,
            "head.solids[0].tip_diameter: not a key of a cylinder",
        ),
        (
            r#"{"solids": [{"type": "cylinder", "length": -1, "diameter": 9}]}"#,
            "head.solids[0]: length must lie in (0, 5000] mm (got -1)",
        ),
        (
            r#"{"solids": [{"type": "cylinder", "length": 10}]}"#,
            "head.solids[0].diameter: missing",
        ),
        (
            r#"{"solids": [{"type": "sphere", "length": 10}]}"#,
            "head.solids[0].type: unknown type \"sphere\" (known: cone, cylinder)",
        ),
        (
            r#"{"solids": [{"type": "cylinder", "length": 10, "diameter": 5, "colour": 1}]}"#,
            "head.solids[0].colour: unknown key (known: type, length, diameter, tip_diameter, top_diameter, cone_angle_deg)",
        ),
    ] {
        let e = Machine::from_str(&machine(&format!(r#", "head": {head}"#))).expect_err(want);
        assert_eq!(e.to_string(), want);
    }
    let many = format!(
        r#", "head": {{"solids": [{}]}}"#,
        vec![r#"{"type": "cylinder", "length": 1, "diameter": 5}"#; 17].join(", ")
    );
    let e = Machine::from_str(&machine(&many)).expect_err("17 solids");
    assert_eq!(e.to_string(), "head.solids: 17 solids, at most 16");
}
