//! A machine file's `process` object through the CLI: its codes reach the program as given,
//! and a bad one is a named error (exit 1) with no output written.

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(name)
}

fn machine_with(dir: &Path, process: &str) -> PathBuf {
    let text = std::fs::read_to_string(fixture("machines/ac_head.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["process"] = serde_json::from_str(process).unwrap();
    let p = dir.join("machine.json");
    std::fs::write(&p, v.to_string()).unwrap();
    p
}

#[test]
fn process_codes_reach_the_program() {
    let dir = tempfile::tempdir().unwrap();
    let m = machine_with(
        dir.path(),
        r#"{"beam_on": ["M62 P1", "G4 P0.05"], "beam_off": ["M63 P1"], "pierce_dwell_s": 0.5, "pierce_standoff": 2}"#,
    );
    for dialect in ["linuxcnc", "generic", "sinumerik"] {
        let out = dir.path().join(dialect);
        let o = Command::new(env!("CARGO_BIN_EXE_kerf"))
            .arg("run")
            .arg(fixture("dome.json"))
            .arg("-m")
            .arg(&m)
            .args(["--dialect", dialect, "-q", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("program.nc")).unwrap();
        let dwell = if dialect == "sinumerik" {
            "G4 F0.5"
        } else {
            "G4 P0.5"
        };
        // LinuxCNC lights the pierce with the immediate form of a synchronized code (M62
        // would wait for the next move: the dwell would run dark).
        let on = if dialect == "linuxcnc" {
            "M64 P1"
        } else {
            "M62 P1"
        };
        assert_eq!(
            text.matches(&format!("\n{on}\nG4 P0.05\n{dwell}\n"))
                .count(),
            2,
            "{dialect}: beam on as given, then the dwell, for both dome circles"
        );
        assert_eq!(
            text.matches("\nM63 P1\n").count(),
            3,
            "{dialect}: preamble + 2 cuts"
        );
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap())
                .unwrap();
        assert_eq!(report["program"]["pierce_standoff_mm"], 2.0);
        assert_eq!(report["program"]["cuts"], 2);
        let b = &report["tolerance_budget_mm"];
        // Every term, `fit` too where arcs and merged lines are written (Sinumerik).
        let sum = b
            .as_object()
            .expect("budget object")
            .iter()
            .filter(|(k, _)| *k != "total")
            .map(|(_, v)| v.as_f64().expect("a known term"))
            .sum::<f64>();
        assert_eq!(
            b.get("fit").is_some(),
            dialect == "sinumerik",
            "{dialect}: a fit term exactly where blocks are fitted"
        );
        assert!(
            (b["total"].as_f64().unwrap() - sum).abs() < 1e-12,
            "total is the sum"
        );
    }
}

#[test]
fn bad_process_is_a_named_error_and_writes_nothing() {
    for (process, want) in [
        (
            r#"{"pierce_dwell_s": -0.1}"#,
            "process.pierce_dwell_s: must lie in [0, 60] (got -0.1)",
        ),
        (
            r#"{"beam_on": [""]}"#,
            "process.beam_on[0]: must not be empty",
        ),
        (
            r#"{"beam_off": []}"#,
            "process.beam_off: must list at least one program line",
        ),
        (r#"{"standoff": 1}"#, "process.standoff: unknown key"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let m = machine_with(dir.path(), process);
        let out = dir.path().join("out");
        let o = Command::new(env!("CARGO_BIN_EXE_kerf"))
            .arg("run")
            .arg(fixture("dome.json"))
            .arg("-m")
            .arg(&m)
            .args(["--dialect", "linuxcnc", "-q", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{process}: exit 1, {err}");
        assert!(
            err.contains(want) && err.contains("machine.json"),
            "{process}: {err}"
        );
        assert!(!out.exists(), "{process}: no output directory");
        let nc = dir.path().join("p.nc");
        let o = Command::new(env!("CARGO_BIN_EXE_kerf"))
            .arg("gcode")
            .arg(fixture("quarter_arc.json"))
            .arg("-m")
            .arg(&m)
            .args(["--feed", "6000", "--dialect", "linuxcnc", "-o"])
            .arg(&nc)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "gcode {process}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains(want),
            "gcode {process}: the machine's error first: {err}"
        );
        assert!(!nc.exists(), "gcode {process}: no program");
    }
}
