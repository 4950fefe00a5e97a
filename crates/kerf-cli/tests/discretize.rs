//! `kerf discretize` end to end: the binary on fixtures, its output read back and checked.

mod common;
use common::{fixture, kerf};

#[test]
fn writes_a_certified_toolpath_for_every_curve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mixed.toolpath.json");
    let status = kerf()
        .arg("discretize")
        .arg(fixture("mixed.json"))
        .args(["--tolerance", "0.005", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let stderr = String::from_utf8_lossy(&status.stderr);
    assert!(
        stderr.contains("4 curves"),
        "summary names the curves: {stderr}"
    );
    let tp = kerf_format::toolpath::load(&out).unwrap();
    let curves = kerf_format::curves::load(fixture("mixed.json")).unwrap();
    assert_eq!(tp.tolerance, 0.005, "tolerance recorded");
    assert_eq!(tp.paths.len(), curves.curves.len(), "one path per curve");
    for (p, c) in tp.paths.iter().zip(&curves.curves) {
        assert_eq!(p.id, c.id, "same ids, same order");
        assert!(
            p.max_chord_error <= 0.005,
            "{}: certified bound within tolerance",
            p.id
        );
        let (a, b) = c.curve.domain();
        assert_eq!(p.params[0], a, "{}: starts at the domain start", p.id);
        assert_eq!(
            *p.params.last().unwrap(),
            b,
            "{}: ends at the domain end",
            p.id
        );
        for (n, t) in p.params.iter().enumerate() {
            let q = c.curve.point(*t);
            assert!(
                (q - p.points.position(n)).norm() < 1e-9,
                "{}: point {n} on the curve",
                p.id
            );
        }
        for br in c.curve.c0_breaks() {
            assert!(p.params.contains(&br), "{}: C0 break {br} kept", p.id);
        }
    }
}

#[test]
fn stdout_output_and_json_summary() {
    let out = kerf()
        .arg("discretize")
        .arg(fixture("circle.json"))
        .args(["-t", "0.01", "-o", "-", "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "exit 0");
    let tp = kerf_format::toolpath::from_str(&String::from_utf8(out.stdout).unwrap()).unwrap();
    assert_eq!(tp.paths.len(), 1, "the circle");
    let summary: serde_json::Value = serde_json::from_slice(&out.stderr).unwrap();
    assert_eq!(summary["curves"], 1, "summary curves");
    assert!(summary["n_star"].as_f64().unwrap() > 100.0, "N* reported");
}

#[test]
fn bad_options_and_bad_input_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.json");
    // Option values out of range are usage errors (exit 2), bad input exit 1.
    for (args, file, needle, code) in [
        (vec!["-t", "0"], "mixed.json", "tolerance", 2),
        (vec!["-t", "nan"], "mixed.json", "tolerance", 2),
        (vec!["--band", "1.5"], "mixed.json", "band", 2),
        (vec![], "bad/decreasing_knots.json", "curves[1].knots[5]", 1),
        (vec![], "bad/negative_weight.json", "weight", 1),
        (vec![], "bad/malformed.json", "line", 1),
        (vec![], "no-such-file.json", "no-such-file.json", 1),
    ] {
        let o = kerf()
            .arg("discretize")
            .arg(fixture(file))
            .args(&args)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(
            o.status.code(),
            Some(code),
            "{file} {args:?}: exit {code}, stderr {stderr}"
        );
        assert!(
            stderr.contains(needle),
            "{file} {args:?}: message names {needle}: {stderr}"
        );
        assert!(!out.exists(), "{file} {args:?}: no output file left behind");
    }
}

#[test]
fn usage_errors_exit_2() {
    let o = kerf().args(["discretize", "--tolerance"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "missing value is a usage error");
}

/// Runs `kerf discretize` on a `kerf.curves/1` document with `args`; (exit code, stderr).
fn discretize_doc(doc: &str, args: &[&str]) -> (Option<i32>, String) {
    let (code, _, stderr) = discretize_doc_out(doc, args);
    (code, stderr)
}

/// [`discretize_doc`] with standard output: (exit code, stdout, stderr).
fn discretize_doc_out(doc: &str, args: &[&str]) -> (Option<i32>, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.json");
    std::fs::write(&input, doc).unwrap();
    let o = kerf()
        .arg("discretize")
        .arg(&input)
        .args(args)
        .arg("-o")
        .arg(dir.path().join("out.json"))
        .output()
        .unwrap();
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn a_tolerance_no_curve_can_hold_is_refused_before_any_walk() {
    // Review: door_trim at 1e-10 mm walked curves 0 and 1 for 110 s before refusing curve 2,
    // whose rounding margin is known from its control points. Curve 0 here fails only in its
    // walk (its estimate before the walk is 2 points, from a curvature too small to measure,
    // and the walk needs 20, over --max-points 10); curve 1 is 1e12 mm long (margin ~0.1 mm).
    // Checked before any walk, curve 1's refusal comes first.
    let first = r#"{"id": "huge-span", "degree": 2, "knots": [0, 0, 0, 1e-300, 1e300, 1e300, 1e300],
         "control_points": [[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]]}"#;
    let second = r#"{"id": "long", "degree": 2, "knots": [0, 0, 0, 1, 1, 1],
         "control_points": [[0, 0, 0], [1e12, 1, 0], [1e12, 1e12, 0]]}"#;
    let doc = |curves: &str| {
        format!(r#"{{"format": "kerf.curves/1", "units": "mm", "curves": [{curves}]}}"#)
    };
    let args = ["-t", "0.01", "--max-points", "10"];
    let (code, stderr) = discretize_doc(&doc(&format!("{first}, {second}")), &args);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("curves[1]") && stderr.contains("rounding margin"),
        "{stderr}"
    );
    // Alone, curve 0 is refused by its walk when it passes the limit (so the order above is
    // the check's doing).
    let (code, stderr) = discretize_doc(&doc(first), &args);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("curves[0]")
            && stderr.contains("more than 10 cutting points would be needed (estimated 11)"),
        "{stderr}"
    );
}

#[test]
fn summary_without_curvature_gives_no_ratio() {
    // Review: straight pieces have N* = 0 and the summary printed "segments / N* = NaN".
    let doc = r#"{"format": "kerf.curves/1", "units": "mm", "curves": [
        {"id": "zigzag", "degree": 1, "knots": [0, 0, 1, 2, 3, 3],
         "control_points": [[0, 0, 0], [1, 1, 0], [2, 0, 0], [3, 1, 0]]}]}"#;
    let (code, stderr) = discretize_doc(doc, &["-t", "0.01"]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(!stderr.contains("NaN"), "{stderr}");
    assert!(
        stderr.contains("N* 0.0 (no curvature measured, so no segments / N* ratio)"),
        "{stderr}"
    );
    let (code, stdout, stderr) = discretize_doc_out(doc, &["-t", "0.01", "--json"]);
    assert_eq!(code, Some(0), "{stderr}");
    let summary: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(summary["n_star"], 0.0);
    assert!(summary["segments_over_n_star"].is_null(), "{summary}");
    assert_eq!(summary["segments"], 3);
}

/// `n` cubic curves with 6 control points each, from a fixed linear congruential sequence;
/// curve `wiggly` (if any) is 100 times larger, so that it needs far more points.
fn many_curves(n: usize, wiggly: Option<usize>) -> String {
    let mut state: u64 = 0x2545_f491_4f6c_dd1d;
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let curves: Vec<String> = (0..n)
        .map(|k| {
            let scale = if Some(k) == wiggly { 1000.0 } else { 10.0 };
            let points: Vec<String> = (0..6)
                .map(|j| {
                    let (x, y, z) = (next(), next(), next());
                    format!(
                        "[{}, {}, {}]",
                        scale * (j as f64 + x),
                        scale * y,
                        scale * 0.2 * z
                    )
                })
                .collect();
            format!(
                r#"{{"id": "c{k}", "degree": 3, "knots": [0, 0, 0, 0, 0.3, 0.6, 1, 1, 1, 1],
                     "control_points": [{}]}}"#,
                points.join(", ")
            )
        })
        .collect();
    format!(
        r#"{{"format": "kerf.curves/1", "units": "mm", "curves": [{}]}}"#,
        curves.join(",\n")
    )
}

#[test]
fn a_file_of_several_groups_is_the_library_output_in_order_to_the_bit() {
    // The command discretizes groups of 256 curves in parallel and writes one group while it
    // discretizes the next: 700 curves are three groups, the last one short.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.json");
    let out = dir.path().join("out.json");
    std::fs::write(&input, many_curves(700, None)).unwrap();
    let o = kerf()
        .arg("discretize")
        .arg(&input)
        .args(["-t", "0.01", "-q", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let tp = kerf_format::toolpath::load(&out).unwrap();
    let curves = kerf_format::curves::load(&input).unwrap();
    assert_eq!(tp.paths.len(), 700);
    let opts = kerf_discretize::Options::with_tolerance(0.01);
    for (p, c) in tp.paths.iter().zip(&curves.curves) {
        assert_eq!(p.id, c.id, "input order");
        let d = kerf_discretize::discretize(&c.curve, &opts).unwrap();
        assert_eq!(p.params, d.params(), "{}: the library's params", p.id);
        for (n, q) in d.points().iter().enumerate() {
            assert_eq!(
                p.points.position(n),
                *q,
                "{}: point {n} as the library made it",
                p.id
            );
        }
        assert_eq!(p.max_chord_error, d.max_chord_error(), "{}", p.id);
    }
}

#[test]
fn a_curve_refused_in_a_later_group_names_itself_and_leaves_no_file() {
    // Curve 600 (third group) needs more points than --max-points allows; the groups before
    // it are written by then, and still nothing may be left behind.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.json");
    let out = dir.path().join("out.json");
    std::fs::write(&input, many_curves(700, Some(600))).unwrap();
    let o = kerf()
        .arg("discretize")
        .arg(&input)
        .args(["-t", "0.01", "--max-points", "100", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("curves[600]") && stderr.contains("\"c600\""),
        "{stderr}"
    );
    assert!(!out.exists(), "no half-written toolpath");
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 1, "only the input is left: {left:?}");
}
