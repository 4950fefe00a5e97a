//! `view.html` in a real browser (issue 33): headless Chromium (Debian's `chromium`, which
//! `.ci/run` installs; software WebGL through SwiftShader) opens the view of every fixture and
//! of the real parts from the disk: no script error, the scene's counts equal to `report.json`'s,
//! the head at a time of the slider on the set-point of that time in `setpoints.csv` (through
//! kerf's forward kinematics), and a screenshot that is not blank, kept as an artefact under
//! `target/view-screenshots/`.
//!
//! Skipped with a notice where Chromium is not installed, unless `KERF_REQUIRE_CHROMIUM` is set
//! (as `.ci/run` does after installing it): then a missing browser fails.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
use common::{fixture, kerf, read_json};
use kerf_kinematics::{Axes, Machine};
use serde_json::Value;

/// True where the browser runs; a notice (or, with `KERF_REQUIRE_CHROMIUM`, a failure) where
/// it does not.
fn browser() -> bool {
    let found = chromium_command().arg("--version").output().is_ok();
    if !found {
        assert!(
            std::env::var_os("KERF_REQUIRE_CHROMIUM").is_none(),
            "KERF_REQUIRE_CHROMIUM is set but chromium is not installed"
        );
        eprintln!("notice: chromium not installed; the browser test of view.html skipped");
    }
    found
}

/// The browser's command: `$KERF_CHROMIUM`, else `chromium` on the path.
fn chromium_command() -> Command {
    let bin = std::env::var("KERF_CHROMIUM").unwrap_or_else(|_| "chromium".to_string());
    Command::new(bin)
}

/// The browser, headless, with software WebGL.
fn chromium() -> Command {
    let mut c = chromium_command();
    c.args([
        "--headless",
        "--no-sandbox",
        "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader",
        "--virtual-time-budget=10000",
        "--window-size=1280,800",
    ]);
    c
}

fn url(page: &Path, fragment: &str) -> String {
    format!("file://{}#{fragment}", page.display())
}

/// What the page writes into `<pre id="kerf-test">` when opened at `fragment`.
fn browse(page: &Path, fragment: &str) -> Value {
    let out = chromium()
        .arg("--dump-dom")
        .arg(url(page, fragment))
        .output()
        .expect("chromium runs (Debian's chromium package: .ci/run installs it)");
    let dom = String::from_utf8_lossy(&out.stdout);
    let open = "<pre id=\"kerf-test\">";
    let start = dom
        .find(open)
        .unwrap_or_else(|| panic!("{}: no test output in the page", page.display()))
        + open.len();
    let end = start + dom[start..].find("</pre>").expect("closed");
    let text = dom[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// A screenshot of the page at `fragment`, into `png`: the share of pixels that differ from
/// the background and the number of distinct colours.
fn screenshot(page: &Path, fragment: &str, png: &Path) -> (f64, usize) {
    let out = chromium()
        .arg(format!("--screenshot={}", png.display()))
        .arg(url(page, fragment))
        .output()
        .expect("chromium runs");
    assert!(
        png.is_file(),
        "no screenshot: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let decoder = png::Decoder::new(std::fs::File::open(png).expect("png"));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("a frame");
    let px = info.color_type.samples();
    let bytes = &buf[..info.buffer_size()];
    let background = [0x1e, 0x22, 0x28];
    let mut colours = std::collections::HashSet::new();
    let mut other = 0usize;
    let n = bytes.len() / px;
    for p in bytes.chunks(px) {
        let rgb = [p[0], p[1], p[2]];
        colours.insert(rgb);
        if rgb != background {
            other += 1;
        }
    }
    (other as f64 / n as f64, colours.len())
}

/// `kerf run` of `input` on `machine` into a new directory.
fn run(input: &Path, machine: &str, more: &[&str]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tmp");
    let r = kerf()
        .arg("run")
        .arg(input)
        .arg("-m")
        .arg(fixture(machine))
        .args(more)
        .args(["-q", "-o"])
        .arg(dir.path())
        .output()
        .expect("kerf runs");
    assert!(
        r.status.success(),
        "{}: {}",
        input.display(),
        String::from_utf8_lossy(&r.stderr)
    );
    dir
}

/// The rows of a set-points CSV (`t, X, Y, Z, tilt, C`).
fn setpoints(path: &Path) -> Vec<[f64; 6]> {
    std::fs::read_to_string(path)
        .expect("setpoints")
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().expect("number")).collect();
            std::array::from_fn(|k| v[k])
        })
        .collect()
}

/// The page of `dir` against its report and its set-points: set-up 1 at a third of its
/// samples, and where there are several set-ups the last one too (switched in the page's
/// set-up list). Returns the largest distance of the head from its set-point's tip.
fn check_page(name: &str, dir: &Path, machine: &str) -> f64 {
    let report = read_json(&dir.join("report.json"));
    let setups = report["placement"]["setups"].as_array().map_or(1, Vec::len);
    let mut worst = check_setup(name, dir, machine, &report, 0, setups);
    if setups > 1 {
        worst = worst.max(check_setup(name, dir, machine, &report, setups - 1, setups));
    }
    worst
}

/// Set-up `k` (of `setups`) of the page of `dir` at a third of its samples.
fn check_setup(
    name: &str,
    dir: &Path,
    machine: &str,
    report: &Value,
    k: usize,
    setups: usize,
) -> f64 {
    let page = dir.join("view.html");
    let m = Machine::read(fixture(machine)).expect("machine");
    let rows = setpoints(&dir.join(if setups == 1 {
        "setpoints.csv".to_string()
    } else {
        format!("setpoints-{}.csv", k + 1)
    }));
    // The page's samples: every `stride` cycles (kerf_view::MAX_TIMELINE_SAMPLES at most).
    let stride = rows.len().div_ceil(kerf_view::MAX_TIMELINE_SAMPLES).max(1);
    let cycle = report["interpolation"]["cycle_s"].as_f64().expect("cycle");
    let i = (rows.len() - 1) / stride / 3 * stride;
    let t = i as f64 * cycle;
    let v = browse(&page, &format!("t={t}&setup={k}"));
    let name = format!("{name} set-up {}", k + 1);
    assert_eq!(v["errors"], serde_json::json!([]), "{name}: script errors");
    assert_eq!(
        v["at"]["setup"].as_u64(),
        Some(k as u64),
        "{name}: the set-up shown"
    );
    let c = &v["counts"];
    let cuts = report["program"]["cuts"].as_u64().expect("cuts");
    assert_eq!(c["paths"].as_u64(), Some(cuts), "{name}: cuts");
    // The pierce markers drawn against the process stage's own count.
    assert_eq!(
        c["pierces"], report["process"]["pierces"],
        "{name}: pierces"
    );
    assert_eq!(
        c["traverses"], report["traverses"]["count"],
        "{name}: traverses"
    );
    assert_eq!(
        c["warnings"].as_u64(),
        report["warnings"].as_array().map(|w| w.len() as u64),
        "{name}: warnings"
    );
    assert_eq!(
        c["setups"].as_u64(),
        report["placement"]["setups"]
            .as_array()
            .map(|s| s.len() as u64),
        "{name}: set-ups"
    );
    // The head on the set-point of that time.
    let q = rows[i];
    assert!((q[0] - t).abs() < 1e-6, "{name}: row {i} is at {}", q[0]);
    let pose = m
        .kinematics
        .forward(&Axes::from_array([q[1], q[2], q[3], q[4], q[5]]));
    let shown = v["at"]["t"].as_f64().expect("the slider's time");
    assert!(
        (shown - t).abs() < 1e-9,
        "{name}: the slider shows {shown}, not {t}"
    );
    let at = |key: &str, k: usize| v["at"][key][k].as_f64().expect("a number");
    let tip = (0..3)
        .map(|k| (at("tip", k) - pose.position[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let axis = (0..3)
        .map(|k| (at("axis", k) - pose.axis[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    // The machine axes shown are the set-point's (micrometres and millidegrees, f32).
    for k in 0..5 {
        let shown = v["at"]["axes"][k].as_f64().expect("an axis value");
        assert!(
            (shown - q[k + 1]).abs() <= 1e-3 + 1e-7 * q[k + 1].abs(),
            "{name}: axis {k} shown {shown}, set-point {}",
            q[k + 1]
        );
    }
    // The view holds micrometres (f32) and directions to 1e-4.
    assert!(
        tip < 2e-3,
        "{name}: the head is {tip} mm from the set-point at t = {t}"
    );
    assert!(
        axis < 2e-4,
        "{name}: the head's axis is {axis} off at t = {t}"
    );
    tip
}

fn screenshots_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/view-screenshots");
    std::fs::create_dir_all(&dir).expect("screenshot directory");
    dir
}

#[test]
fn every_fixture_view_opens_offline_with_the_reports_counts_and_the_head_on_its_set_point() {
    if !browser() {
        return;
    }
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).expect("fixtures") {
        let path = e.expect("entry").path();
        if path.extension().and_then(|x| x.to_str()) != Some("json") {
            continue;
        }
        let name = path.file_name().and_then(|f| f.to_str()).expect("name");
        // The gantry holds every fixture; where the head meets the part as drawn (`mixed`,
        // `trim_creases`, the head fixtures upright) the close stretches are accepted and
        // drawn.
        let machine = "machines/gantry_ac.json";
        let out = run(&path, machine, &["--accept-head-collisions"]);
        check_page(name, out.path(), machine);
        n += 1;
    }
    assert!(n >= 15, "{n} fixtures");
}

#[test]
fn real_parts_views_open_and_show_the_part() {
    if !browser() {
        return;
    }
    let shots = screenshots_dir();
    let mut parts: Vec<(String, PathBuf, Vec<&str>)> = vec![
        (
            "occt_propeller".into(),
            fixture("realdata/occt_propeller.json"),
            vec!["--place", "auto", "--cut-clearance", "off"],
        ),
        (
            "nori_sheetmetal".into(),
            fixture("realdata/nori_sheetmetal.json"),
            vec!["--place", "auto", "--cut-clearance", "off"],
        ),
    ];
    parts.push((
        "S06298".into(),
        fixture("realdata/step/S06298.stp"),
        vec!["--edges", "--place", "auto", "--accept-head-collisions"],
    ));
    for (name, input, more) in parts {
        let out = run(&input, "machines/gantry_ac.json", &more);
        check_page(&name, out.path(), "machines/gantry_ac.json");
        let png = shots.join(format!("{name}.png"));
        let (share, colours) = screenshot(&out.path().join("view.html"), "t=0", &png);
        // The part, its paths and the head cover a good part of the view in many shades.
        assert!(
            share > 0.05 && colours > 50,
            "{name}: {share} of the pixels drawn, {colours} colours ({})",
            png.display()
        );
        let size = std::fs::metadata(out.path().join("view.html"))
            .expect("page")
            .len();
        eprintln!("{name}: view.html {size} bytes, {:.0} % of the screenshot drawn, {colours} colours: {}", share * 100.0, png.display());
    }
}

#[test]
fn kerf_view_refreshes_a_page_with_the_reports_warnings() {
    let out = run(&fixture("circle.json"), "machines/gantry_ac.json", &[]);
    let page = out.path().join("view.html");
    let before = std::fs::read_to_string(&page).expect("page");
    // A warning added to the report after the run reaches the refreshed page.
    let report_path = out.path().join("report.json");
    let mut report = read_json(&report_path);
    report["warnings"] = serde_json::json!(["checked by hand at (1, 2, 3) </script>"]);
    std::fs::write(&report_path, report.to_string()).expect("report");
    let r = kerf()
        .arg("view")
        .arg(out.path())
        .output()
        .expect("kerf view");
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let after = std::fs::read_to_string(&page).expect("page");
    assert_ne!(before, after);
    let scene = kerf_view::read_scene(&after).expect("scene");
    assert_eq!(
        scene["warnings"][0]["point"],
        serde_json::json!([1.0, 2.0, 3.0])
    );
    if browser() {
        let v = browse(&page, "t=0.5");
        assert_eq!(v["errors"], serde_json::json!([]));
        assert_eq!(v["counts"]["warnings"], 1);
        assert_eq!(
            v["counts"]["warning_markers"], 1,
            "one set-up: its marker drawn"
        );
    }
    // A directory without a view: refused by name, nothing written.
    let empty = tempfile::tempdir().expect("tmp");
    let r = kerf()
        .arg("view")
        .arg(empty.path())
        .output()
        .expect("kerf view");
    assert_eq!(r.status.code(), Some(1));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("view.html") && err.contains("No such file"),
        "{err}"
    );
    assert!(!empty.path().join("view.html").exists());
}
