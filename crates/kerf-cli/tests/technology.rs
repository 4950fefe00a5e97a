//! `kerf run --technology FILE --material NAME [--thickness MM]`: the entry sets the feed, the
//! pierce, the standoff and the kerf width, and is named in the program and the report; bad
//! tables and unknown materials are refused by file and JSON path with nothing written.

mod common;
use common::fixture;
use common::run_flat as run;

#[test]
fn the_entry_sets_feed_pierce_and_kerf_and_is_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = fixture("technology/fiber_3kw_example.json");
    let table = table.to_str().expect("path");
    let out = dir.path().join("out");
    let r = run(
        &[
            "--technology",
            table,
            "--material",
            "Mild Steel",
            "--thickness",
            "2",
        ],
        &out,
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let program = std::fs::read_to_string(out.join("program.nc")).expect("program");
    assert!(
        program.contains("; technology: mild steel 2 mm O2: feed 4500 mm/min"),
        "{}",
        &program[..600.min(program.len())]
    );
    // The entry's pierce time is the dwell; its kerf is offset; its feed is planned.
    assert!(program.contains("G4 P0.2\n"), "pierce dwell 0.2 s");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("report"))
            .expect("json");
    assert_eq!(report["technology"]["entry"], "mild steel 2 mm O2");
    assert_eq!(report["compensation"]["kerf_width_mm"], 0.15);
    assert_eq!(report["compensation"]["source"], "technology entry");
    assert_eq!(report["interpolation"]["feed_mm_per_min"], 4500.0);
    // --feed wins over the entry's.
    let out2 = dir.path().join("out2");
    let r = run(
        &[
            "--technology",
            table,
            "--material",
            "mild steel",
            "--thickness",
            "2",
            "--feed",
            "3000",
        ],
        &out2,
    );
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let program = std::fs::read_to_string(out2.join("program.nc")).expect("program");
    assert!(
        program.contains("feed 4500 mm/min"),
        "the entry is still named"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out2.join("report.json")).expect("report"))
            .expect("json");
    assert_eq!(report["interpolation"]["feed_mm_per_min"], 3000.0);
}

#[test]
fn unknown_materials_and_bad_tables_are_refused_by_name_with_nothing_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = fixture("technology/fiber_3kw_example.json");
    let table = table.to_str().expect("path");
    let out = dir.path().join("out");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["--technology".into(), table.into(), "--material".into(), "copper".into()],
            "technology: no entry for material \"copper\" (known: mild steel 1 mm, mild steel 2 mm",
        ),
        (
            vec!["--technology".into(), table.into(), "--material".into(), "stainless".into()],
            "material \"stainless\" has several entries: give the thickness",
        ),
        (
            vec![
                "--technology".into(),
                table.into(),
                "--material".into(),
                "aluminium".into(),
                "--thickness".into(),
                "4".into(),
            ],
            "no entry for material \"aluminium\" at 4 mm (known: aluminium 1 mm, aluminium 2 mm, aluminium 3 mm)",
        ),
    ];
    let bad = dir.path().join("bad.json");
    let tables = [
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 120}]}"#,
            "entries[0].power_percent: must lie in (0, 100] (got 120)",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 50, "speed": 3}]}"#,
            "entries[0]",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 50, "pierce": {"time_s": -1, "power_percent": 50, "height_mm": 2}}]}"#,
            "entries[0].pierce.time_s: must lie in [0, 60] (got -1)",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 50}, {"material": "X", "thickness_mm": 1, "feed_mm_per_min": 900, "power_percent": 50}]}"#,
            "entries[1]: X 1 mm is also entries[0]",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 50, "power_min_percent": 60}]}"#,
            "entries[0].power_min_percent: must lie in [0, 50] (got 60)",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": [{"material": "x", "thickness_mm": 1, "feed_mm_per_min": 1000, "power_percent": 50, "micro_joints": {"length_mm": 5, "spacing_mm": 4}}]}"#,
            "entries[0].micro_joints.length_mm: must be less than the spacing (4 mm, got 5)",
        ),
        (
            r#"{"format": "kerf.technology/1", "entries": []}"#,
            "entries: 0 entries, expected 1 to 4096",
        ),
        (r#"{"format": "kerf.machine/1"}"#, "format: unknown format"),
    ];
    for (args, want) in &cases {
        let r = run(&args.iter().map(String::as_str).collect::<Vec<_>>(), &out);
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success() && err.contains(want), "{args:?}: {err}");
        assert!(
            err.contains("fiber_3kw_example.json"),
            "names the file: {err}"
        );
        assert!(!out.exists(), "nothing written");
    }
    for (text, want) in tables {
        std::fs::write(&bad, text).expect("write");
        let r = run(
            &[
                "--technology",
                bad.to_str().expect("path"),
                "--material",
                "x",
            ],
            &out,
        );
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(!r.status.success() && err.contains(want), "{text}: {err}");
        assert!(err.contains("bad.json"), "names the file: {err}");
        assert!(!out.exists(), "nothing written");
    }
}

/// The machine file's `process.technology` (relative to the machine file) is the table
/// `--material` picks from when no `--technology` is given; `--material` with no table at all
/// is a usage error.
#[test]
fn the_machine_files_table_is_used_when_no_technology_is_given() {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::copy(
        fixture("technology/fiber_3kw_example.json"),
        dir.path().join("table.json"),
    )
    .expect("copy");
    let mut machine: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(fixture("machines/gantry_ac.json")).expect("read"),
    )
    .expect("json");
    machine["process"]["technology"] = "table.json".into();
    let machine_path = dir.path().join("machine.json");
    std::fs::write(&machine_path, machine.to_string()).expect("write");
    let out = dir.path().join("out");
    let r = common::kerf()
        .args(["run"])
        .arg(fixture("sheet_metal_holes.json"))
        .arg("-m")
        .arg(&machine_path)
        .args(["--material", "stainless", "--thickness", "3", "-q", "-o"])
        .arg(&out)
        .output()
        .expect("kerf runs");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let report = common::read_json(&out.join("report.json"));
    assert_eq!(report["technology"]["entry"], "stainless 3 mm N2");
    assert_eq!(report["interpolation"]["feed_mm_per_min"], 4000.0);
    // No table anywhere: --material is a usage error, nothing written.
    let out2 = dir.path().join("out2");
    let r = run(&["--material", "stainless"], &out2);
    assert_eq!(
        r.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(String::from_utf8_lossy(&r.stderr).contains("--material needs a technology table"));
    assert!(!out2.exists());
    // A table key that is not a file name is refused by its JSON path.
    machine["process"]["technology"] = 3.into();
    std::fs::write(&machine_path, machine.to_string()).expect("write");
    let r = common::kerf()
        .args(["run"])
        .arg(fixture("sheet_metal_holes.json"))
        .arg("-m")
        .arg(&machine_path)
        .args(["-q", "-o"])
        .arg(dir.path().join("out3"))
        .output()
        .expect("kerf runs");
    assert_eq!(r.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&r.stderr).contains("process.technology: expected a file name"),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
}
