//! `kerf plot` end to end: the SVG is well-formed, has every view and chart, one marker per
//! cutting point per view, the machine axes with their limits when given, and is written
//! atomically.

use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;
mod common;
use common::{fixture, kerf};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs kerf with `args`, asserting success.
fn ok(args: &[&std::ffi::OsStr]) {
    let o = kerf().args(args).output().unwrap();
    assert!(o.status.success(), "kerf {args:?}: {}", stderr(&o));
}

/// A discretized mixed.json in `dir`, optionally with the normal (0, 0.6, 0.8) on every point
/// (made up: `kerf post` does not need them to be the surface's).
fn toolpath(dir: &Path, normals: bool) -> (PathBuf, usize) {
    let out = dir.join("mixed.toolpath.json");
    ok(&[
        "discretize".as_ref(),
        fixture("mixed.json").as_os_str(),
        "-q".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let mut points = 0;
    for p in doc["paths"].as_array_mut().unwrap() {
        for q in p["points"].as_array_mut().unwrap() {
            points += 1;
            if normals {
                q.as_array_mut()
                    .unwrap()
                    .extend([0.0.into(), 0.6.into(), 0.8.into()]);
            }
        }
    }
    std::fs::write(&out, doc.to_string()).unwrap();
    (out, points)
}

/// Balanced, properly nested tags with quoted attributes; the number of elements.
fn well_formed(s: &str) -> Result<usize, String> {
    let mut stack: Vec<&str> = Vec::new();
    let (mut count, mut i) = (0, 0);
    while let Some(open) = s[i..].find('<') {
        let start = i + open;
        let text = &s[i..start];
        for (k, _) in text.match_indices('&') {
            let name = &text[k + 1..k + 1 + text[k + 1..].find(';').ok_or("bad &")?];
            if !matches!(name, "amp" | "lt" | "gt" | "quot" | "apos") {
                return Err(format!("entity &{name};"));
            }
        }
        let end = start + s[start..].find('>').ok_or("unterminated tag")?;
        let tag = &s[start + 1..end];
        i = end + 1;
        if tag.starts_with('?') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            if stack.pop() != Some(name) {
                return Err(format!("</{name}> out of place"));
            }
            continue;
        }
        if tag.matches('"').count() % 2 != 0 || tag.contains("=\"\"\"") {
            return Err(format!("bad quoting in <{tag}>"));
        }
        count += 1;
        if !tag.ends_with('/') {
            stack.push(tag.split_whitespace().next().ok_or("empty tag")?);
        }
    }
    if stack.is_empty() {
        Ok(count)
    } else {
        Err(format!("unclosed {stack:?}"))
    }
}

/// The text of `svg` from `from` to the next `to`.
fn between<'a>(svg: &'a str, from: &str, to: &str) -> &'a str {
    let a = svg
        .find(from)
        .unwrap_or_else(|| panic!("{from} in the SVG"));
    let b = a + svg[a..]
        .find(to)
        .unwrap_or_else(|| panic!("{to} after {from}"));
    &svg[a..b]
}

#[test]
fn draws_views_and_the_chord_error_chart() {
    let dir = tempfile::tempdir().unwrap();
    let (tp, points) = toolpath(dir.path(), false);
    let svg_path = dir.path().join("plot.svg");
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .arg("-o")
        .arg(&svg_path)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(&format!("4 paths, {points} points")),
        "{}",
        stderr(&o)
    );
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    let elements = well_formed(&svg).unwrap();
    assert!(elements > points * 4, "{elements} elements");
    assert!(
        svg.starts_with("<?xml") && svg.contains("<svg xmlns=\"http://www.w3.org/2000/svg\""),
        "an SVG document"
    );
    for (id, title) in [
        ("view-top", "Top view (XY"),
        ("view-front", "Front view (XZ"),
        ("view-side", "Side view (YZ"),
        ("view-iso", "Isometric view"),
        ("chart-chord-error", "Chord error per segment"),
    ] {
        assert!(svg.contains(&format!("<g id=\"{id}\"")), "{id}");
        assert!(svg.contains(title), "{title}");
    }
    assert!(
        svg.contains("id=\"legend-error\"") && svg.contains("chord error / tolerance"),
        "colour legend"
    );
    assert!(!svg.contains("id=\"chart-axes\""), "no axes asked for");
    assert_eq!(
        svg.matches("class=\"pt\"").count(),
        4 * points,
        "every point in every view"
    );
    let top = between(&svg, "<g id=\"view-top\"", "<g id=\"view-iso\"");
    assert_eq!(
        top.matches("class=\"pt\"").count(),
        points,
        "every point in the top view"
    );
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(
        names.len(),
        2,
        "toolpath and plot, no temporary file: {names:?}"
    );
}

#[test]
fn draws_normals_and_machine_axes_with_limits() {
    let dir = tempfile::tempdir().unwrap();
    let (tp, points) = toolpath(dir.path(), true);
    let axes = dir.path().join("mixed.axes.json");
    let machine = fixture("machines/ac_head.json");
    ok(&[
        "post".as_ref(),
        tp.as_os_str(),
        "-m".as_ref(),
        machine.as_os_str(),
        "-q".as_ref(),
        "-o".as_ref(),
        axes.as_os_str(),
    ]);
    let svg_path = dir.path().join("plot.svg");
    ok(&[
        "plot".as_ref(),
        fixture("mixed.json").as_os_str(),
        tp.as_os_str(),
        "--axes".as_ref(),
        axes.as_os_str(),
        "--machine".as_ref(),
        machine.as_os_str(),
        "-o".as_ref(),
        svg_path.as_os_str(),
    ]);
    let svg = std::fs::read_to_string(&svg_path).unwrap();
    well_formed(&svg).unwrap();
    let top = between(&svg, "<g id=\"view-top\"", "<g id=\"view-iso\"");
    let normals = between(top, "class=\"normals\"", "</g>");
    assert_eq!(
        normals.matches("<line").count(),
        points,
        "few points: every tool axis"
    );
    assert_eq!(top.matches("class=\"pt\"").count(), points, "every point");
    let chart = between(&svg, "<g id=\"chart-axes\"", "</svg>");
    assert!(chart.contains("paper-000 laser head"), "machine named");
    for name in ["X / mm", "Y / mm", "Z / mm", "A / deg", "C / deg"] {
        assert!(chart.contains(name), "{name}");
    }
    assert!(chart.contains("class=\"limit\""), "limits dashed");
    assert!(
        chart.contains("continuous axis: no limits"),
        "C of the AC head"
    );

    // Another machine's limits do not apply.
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .arg("--axes")
        .arg(&axes)
        .arg("--machine")
        .arg(fixture("machines/fork_head.json"))
        .arg("-o")
        .arg(dir.path().join("other.svg"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the axes file is for machine paper-000 laser head"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("other.svg").exists(), "nothing written");
}

#[test]
fn errors_leave_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let (tp, _) = toolpath(dir.path(), false);
    // Curves that are not the toolpath's.
    let out = dir.path().join("x.svg");
    let o = kerf()
        .arg("plot")
        .arg(fixture("circle.json"))
        .arg(&tp)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("paths[0] (\"v-corner\"): no curve with this id in the curves file"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists(), "no picture");
    // An output directory that does not exist.
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .arg("-o")
        .arg(dir.path().join("missing/x.svg"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot write"), "{}", stderr(&o));
    // --machine needs --axes: a usage error.
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .arg("--machine")
        .arg(fixture("machines/ac_head.json"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "only the toolpath: {names:?}");
}

#[test]
fn draws_a_broken_toolpath_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let (tp, _) = toolpath(dir.path(), false);
    let mut doc: Value = serde_json::from_str(&std::fs::read_to_string(&tp).unwrap()).unwrap();
    // A point removed from the quintic, and a claim that says so (above the tolerance: the
    // strict reader refuses the file).
    let p = &mut doc["paths"][2];
    p.as_object_mut().unwrap().remove("point_count");
    p["points"].as_array_mut().unwrap().remove(30);
    p["params"].as_array_mut().unwrap().remove(30);
    p["max_chord_error"] = 0.05.into();
    std::fs::write(&tp, doc.to_string()).unwrap();
    let out = dir.path().join("broken.svg");
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).starts_with("warning: ") && stderr(&o).contains("drawing it anyway"),
        "{}",
        stderr(&o)
    );
    let svg = std::fs::read_to_string(&out).unwrap();
    well_formed(&svg).unwrap();
    let top = between(&svg, "<g id=\"view-top\"", "<g id=\"view-iso\"");
    assert!(
        top.contains("class=\"over\""),
        "the long segment drawn as above the tolerance"
    );
}

#[test]
fn writes_to_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let (tp, points) = toolpath(dir.path(), false);
    let o = kerf()
        .arg("plot")
        .arg(fixture("mixed.json"))
        .arg(&tp)
        .args(["-o", "-"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let svg = String::from_utf8(o.stdout).unwrap();
    well_formed(&svg).unwrap();
    assert_eq!(
        svg.matches("class=\"pt\"").count(),
        4 * points,
        "the whole picture"
    );
}
