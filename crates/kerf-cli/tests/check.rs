//! `kerf check` end to end: a toolpath from `kerf discretize` passes; corrupted copies of it
//! (a point removed from a curved path, a C0 corner removed, a point moved off its curve,
//! params reversed) fail with exit status 1 and the violation named.

use std::path::Path;
use std::process::Output;

use serde_json::Value;
mod common;
use common::{fixture, kerf};

/// `kerf discretize fixtures/mixed.json -t 0.01` into `dir`, read back as JSON.
fn discretized(dir: &Path) -> Value {
    let out = dir.join("mixed.toolpath.json");
    let run = kerf()
        .arg("discretize")
        .arg(fixture("mixed.json"))
        .args(["-t", "0.01", "-q", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(out).unwrap()).unwrap()
}

/// Writes `doc` and runs `kerf check mixed.json <it> [extra]`.
fn check(dir: &Path, doc: &Value, extra: &[&str]) -> Output {
    let path = dir.join("candidate.json");
    std::fs::write(&path, serde_json::to_string_pretty(doc).unwrap()).unwrap();
    kerf()
        .arg("check")
        .arg(fixture("mixed.json"))
        .arg(&path)
        .args(extra)
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The index of the path with `id`.
fn path_index(doc: &Value, id: &str) -> usize {
    doc["paths"]
        .as_array()
        .unwrap()
        .iter()
        .position(|p| p["id"] == id)
        .unwrap()
}

/// Removes point `k` (and its param) of path `i`; drops `point_count`, now stale.
fn remove_point(doc: &mut Value, i: usize, k: usize) {
    let p = &mut doc["paths"][i];
    p.as_object_mut().unwrap().remove("point_count");
    p["points"].as_array_mut().unwrap().remove(k);
    p["params"].as_array_mut().unwrap().remove(k);
}

#[test]
fn a_correct_toolpath_passes() {
    let dir = tempfile::tempdir().unwrap();
    let doc = discretized(dir.path());
    let o = check(dir.path(), &doc, &[]);
    assert!(o.status.success(), "{}{}", stdout(&o), stderr(&o));
    let out = stdout(&o);
    // Every segment of the file is measured (the count follows the discretizer's band).
    let segments: usize = doc["paths"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["points"].as_array().unwrap().len() - 1)
        .sum();
    assert!(
        out.contains(&format!("4 paths, {segments} segments measured")),
        "{out}"
    );
    assert!(
        out.contains("passed: every segment's chord error <= 0.01 mm"),
        "{out}"
    );
    for id in ["v-corner", "straight", "freeform-quintic", "slot-on-plane"] {
        assert!(out.contains(id), "{id} in the table: {out}");
    }
    assert!(out.contains(">= measured: ok"), "claims checked: {out}");

    let o = check(dir.path(), &doc, &["--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["passed"], true, "{report}");
    assert_eq!(report["paths"].as_array().unwrap().len(), 4, "{report}");
    let worst = report["max_chord_error"].as_f64().unwrap();
    assert!(worst > 0.009 && worst <= 0.01, "{worst}");
    let quintic = &report["paths"][2];
    assert_eq!(quintic["claim_holds"], true, "{quintic}");
    assert!(
        quintic["worst"]["segment"].is_u64(),
        "worst segment given: {quintic}"
    );
}

#[test]
fn a_point_removed_from_a_curved_path_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = discretized(dir.path());
    let i = path_index(&doc, "freeform-quintic");
    let k = 30;
    remove_point(&mut doc, i, k);
    let o = check(dir.path(), &doc, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let out = stdout(&o);
    let line = out
        .lines()
        .find(|l| {
            l.contains(&format!(
                "paths[{i}] (\"freeform-quintic\"): segment {} (t ",
                k - 1
            ))
        })
        .unwrap_or_else(|| panic!("the merged segment is listed: {out}"));
    assert!(line.contains("mm > tolerance 0.01 mm"), "{line}");
    assert!(
        out.contains("UNDERSTATED"),
        "the old claim no longer holds: {out}"
    );
    assert!(
        stderr(&o).contains("candidate.json: 2 violations (listed above)"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_removed_c0_corner_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = discretized(dir.path());
    let i = path_index(&doc, "v-corner");
    let k = doc["paths"][i]["params"]
        .as_array()
        .unwrap()
        .iter()
        .position(|t| t.as_f64() == Some(0.5))
        .expect("the corner is a cutting point");
    remove_point(&mut doc, i, k);
    let o = check(dir.path(), &doc, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let out = stdout(&o);
    assert!(
        out.contains(&format!(
            "paths[{i}] (\"v-corner\"): C0 corner at t = 0.5 is not a cutting point (segment {} spans it)",
            k - 1
        )),
        "{out}"
    );
    assert!(
        out.contains(&format!("paths[{i}] (\"v-corner\"): segment {} (t ", k - 1))
            && out.contains("(largest at t = 0.5)"),
        "the chord cuts the corner: {out}"
    );
}

#[test]
fn a_point_moved_off_the_curve_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = discretized(dir.path());
    let i = path_index(&doc, "slot-on-plane");
    let z = doc["paths"][i]["points"][7][2].as_f64().unwrap();
    doc["paths"][i]["points"][7][2] = (z + 0.002).into();
    let o = check(dir.path(), &doc, &["--json"]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let report: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(report["passed"], false, "{report}");
    let v = &report["violations"][0];
    assert_eq!(v["kind"], "point_off_curve", "{v}");
    assert_eq!(v["path"], i, "{v}");
    assert_eq!(v["index"], 7, "{v}");
    let d = v["distance"].as_f64().unwrap();
    assert!((d - 0.002).abs() < 1e-9, "{d}");
    assert!(
        v["message"].as_str().unwrap().starts_with(&format!(
            "paths[{i}] (\"slot-on-plane\"): points[7]: 2.000e-3 mm from the curve"
        )),
        "{v}"
    );
}

#[test]
fn reversed_params_are_caught() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = discretized(dir.path());
    let i = path_index(&doc, "freeform-quintic");
    doc["paths"][i]["params"].as_array_mut().unwrap().reverse();
    let o = check(dir.path(), &doc, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let out = stdout(&o);
    assert!(
        out.contains(&format!(
            "paths[{i}] (\"freeform-quintic\"): params[1]: params must increase strictly"
        )),
        "{out}"
    );
    assert!(
        out.contains("params[0]: 1 is not the start of the curve's domain (0)"),
        "{out}"
    );
    assert!(
        out.contains("last param: 0 is not the end of the curve's domain (1)"),
        "{out}"
    );
    assert!(
        out.contains("from the curve's point at its param"),
        "points off: {out}"
    );
    assert!(
        out.contains("(--json lists them all)"),
        "a long list is cut: {out}"
    );
}

#[test]
fn normals_ids_and_unreadable_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = discretized(dir.path());
    // Normals: unit ones pass, a short one is named.
    for p in doc["paths"].as_array_mut().unwrap() {
        for q in p["points"].as_array_mut().unwrap() {
            q.as_array_mut()
                .unwrap()
                .extend([0.0.into(), 0.6.into(), 0.8.into()]);
        }
    }
    let o = check(dir.path(), &doc, &[]);
    assert!(o.status.success(), "unit normals pass: {}", stdout(&o));
    doc["paths"][1]["points"][1][5] = 0.7.into();
    doc["paths"].as_array_mut().unwrap().swap(2, 3);
    let o = check(dir.path(), &doc, &[]);
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    let out = stdout(&o);
    assert!(
        out.contains("paths[1] (\"straight\"): points[1]: normal has length"),
        "{out}"
    );
    assert!(
        out.contains("paths[2] (\"slot-on-plane\"): out of order: the curve at this index is \"freeform-quintic\""),
        "{out}"
    );

    // Not JSON, and the wrong kind of document: an error, not a report.
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, "{\"format\": ").unwrap();
    let o = kerf()
        .arg("check")
        .arg(fixture("mixed.json"))
        .arg(&bad)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stderr(&o).starts_with("error: ")
            && stderr(&o).contains("bad.json: invalid JSON at line 1"),
        "{}",
        stderr(&o)
    );
    let o = kerf()
        .arg("check")
        .arg(fixture("mixed.json"))
        .arg(fixture("mixed.json"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stdout(&o));
    assert!(
        stderr(&o).contains("format: expected \"kerf.toolpath/1\", found \"kerf.curves/1\""),
        "{}",
        stderr(&o)
    );
}

#[test]
fn reads_the_toolpath_from_standard_input() {
    let dir = tempfile::tempdir().unwrap();
    let doc = discretized(dir.path());
    let mut child = kerf()
        .arg("check")
        .arg(fixture("mixed.json"))
        .arg("-")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Write;
        let mut stdin = child.stdin.take().unwrap();
        stdin.write_all(doc.to_string().as_bytes()).unwrap();
    }
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stdout(&o));
    assert!(stdout(&o).starts_with("- against "), "{}", stdout(&o));
}
