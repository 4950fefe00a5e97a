//! Pictures of kerf's stages as one self-contained SVG file.
//!
//! A [`Scene`] holds what is drawn, as plain data: each path's curve (densely sampled), its
//! cutting points, their normals if any, the chord error of each segment, and optionally the
//! machine axes over the points with the machine's limits ([`AxesChart`]). [`Scene::new`]
//! builds it from kerf's files; [`render`] turns it into SVG text:
//!
//! - four views of the geometry, to scale (same scale on both axes of a view): top (XY),
//!   front (XZ), side (YZ) with grids and axis ticks in mm, and an isometric view with an axis
//!   triad and a scale bar; segments are coloured by chord error / tolerance (viridis from 0
//!   to 1, red above the tolerance), the cutting points are circles, and tool axes (normals)
//!   are short blue lines toward the head;
//! - a chart of the chord error of every segment (all paths in file order) against the
//!   tolerance line;
//! - with axes, one chart row per machine axis over the point index, limits dashed (a limit
//!   more than one data span away from the data is written out rather than drawn, so that the
//!   motion stays readable).
//!
//! The SVG is plain text (no scripts, no external fonts or images) and opens in any browser.
//! Its groups have stable ids for tests and styling: `view-top`, `view-front`, `view-side`,
//! `view-iso`, `legend-error`, `chart-chord-error`, `chart-axes`; every cutting point is one
//! `<circle class="pt">` per view. With a [`ProcessPicture`], every view also holds a group
//! `class="process"`: each traverse a dashed `<polyline class="traverse">`, each lead-in a
//! `<polyline class="lead-in">`, each lead-out a `<polyline class="lead-out">`, each
//! micro-joint a `<polyline class="micro-joint">` (a bar wider than the path, from where the beam
//! goes off to where it comes on), each stretch the head check tilted a wide translucent amber
//! band `<polyline class="head-tilted">` and each where it found the head too close a wide
//! translucent red band `<polyline class="head-close">` over the path, each pierce a `<circle class="pierce" data-order="k">` and
//! beside it `<text class="order">k</text>`, `k` from 1 in cutting order.
//!
//! The picture's size is bounded whatever the input: beyond [`MAX_DRAWN_SEGMENTS`] segments,
//! [`MAX_DRAWN_PATHS`] paths or [`MAX_DRAWN_CURVE_SAMPLES`] curve samples or axis positions,
//! every `k`-th cutting point of each path is drawn (ends kept, each drawn segment carrying the
//! largest chord error of those it stands for), and a line under the title
//! (`<text id="decimated">`) says so; the head check's bands are then bounded too (the first
//! 200 in cutting order, about 5,000 points in all, each keeping its ends).
//!
//! The chord errors drawn are sampled estimates ([`sampled_chord_error`]), for display; the
//! independent measurement is `kerf check` (crate `kerf-check`).
//!
//! ```
//! use kerf_plot::{render, PathPicture, Scene};
//! use nalgebra::Point3;
//!
//! let line = |x: f64| Point3::new(x, 0.5 * x, 0.0);
//! let scene = Scene {
//!     title: "a line".into(),
//!     subtitle: String::new(),
//!     tolerance: 0.01,
//!     paths: vec![PathPicture {
//!         id: "line".into(),
//!         curve: vec![line(0.0), line(10.0)],
//!         points: vec![line(0.0), line(5.0), line(10.0)],
//!         normals: None,
//!         segment_errors: vec![0.0, 0.0],
//!     }],
//!     axes: None,
//!     process: None,
//! };
//! let svg = render(&scene);
//! assert!(svg.starts_with("<?xml"), "an XML document");
//! assert_eq!(svg.matches("class=\"pt\"").count(), 3 * 4, "3 points in 4 views");
//! ```

use std::io;
use std::path::Path;

mod charts;
mod decimate;
mod layout;
mod scale;
mod scene;
mod svg;
mod views;

pub use decimate::{MAX_DRAWN_CURVE_SAMPLES, MAX_DRAWN_PATHS, MAX_DRAWN_SEGMENTS};
pub use scene::{
    sample_curve, sampled_chord_error, AxesChart, CutPicture, PathPicture, ProcessPicture, Scene,
    SceneOptions,
};

use layout::Rect;
use views::View;

/// Why a picture cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A toolpath's path names no curve of the curves file. Fix: pass the curves file the
    /// toolpath was computed from.
    #[error("paths[{index}] ({id:?}): no curve with this id in the curves file")]
    UnknownCurve {
        /// Index of the path in the toolpath.
        index: usize,
        /// Its id.
        id: String,
    },
    /// The machine file is not the machine the axes file was computed for, so its limits do
    /// not apply. Fix: pass the machine file given to `kerf post`.
    #[error("the axes file is for machine {axes} but the machine file describes {machine}")]
    MachineMismatch {
        /// The axes file's machine.
        axes: String,
        /// The machine file's machine.
        machine: String,
    },
}

/// Page width in pixels.
const WIDTH: f64 = 1400.0;
/// Outer margin in pixels.
const MARGIN: f64 = 20.0;
/// Height of one view panel.
const VIEW_H: f64 = 450.0;

/// The picture of `scene` as SVG text (see the crate documentation for its content), at most
/// [`MAX_DRAWN_SEGMENTS`] segments of it.
pub fn render(scene: &Scene) -> String {
    let (scene, note) = decimate::bounded(scene);
    let scene = scene.as_ref();
    let half = (WIDTH - 3.0 * MARGIN) / 2.0;
    let views_y = 84.0;
    let legend_y = views_y + 2.0 * VIEW_H + MARGIN;
    let chord_y = legend_y + 78.0;
    let chord_h = 360.0;
    let axes_y = chord_y + chord_h + MARGIN;
    let height = match &scene.axes {
        Some(_) => axes_y + charts::axes_chart_height() + MARGIN,
        None => axes_y,
    };
    let style = format!(
        "text{{font-size:12px;fill:#222}}.h1{{font-size:22px;font-weight:bold}}\
         .h2{{font-size:15px;font-weight:bold}}.sub{{font-size:13px;fill:#555}}\
         .axis{{font-size:12px;font-weight:bold;fill:#333}}.tick{{font-size:11px}}\
         .note{{font-size:11px;fill:#666}}{}{}",
        views::STYLE,
        charts::STYLE
    );
    let mut doc = svg::Doc::new(WIDTH, height, &scene.title, &style);
    doc.open("id=\"header\"");
    doc.text(MARGIN, 36.0, &scene.title, "class=\"h1\"");
    doc.text(MARGIN, 60.0, &scene.subtitle, "class=\"sub\"");
    if let Some(note) = &note {
        doc.text(MARGIN, 77.0, note, "id=\"decimated\" class=\"note\"");
    }
    doc.close();
    let normal_len = views::normal_length(scene);
    let panel = |col: f64, row: f64| Rect {
        x: MARGIN + col * (half + MARGIN),
        y: views_y + row * (VIEW_H + 0.0),
        w: half,
        h: VIEW_H - 10.0,
    };
    for (view, col, row) in [
        (View::Top, 0.0, 0.0),
        (View::Iso, 1.0, 0.0),
        (View::Front, 0.0, 1.0),
        (View::Side, 1.0, 1.0),
    ] {
        views::draw_view(&mut doc, scene, view, panel(col, row), normal_len);
    }
    views::draw_legend(
        &mut doc,
        scene,
        Rect {
            x: MARGIN,
            y: legend_y - 10.0,
            w: WIDTH - 2.0 * MARGIN,
            h: 70.0,
        },
    );
    charts::draw_chord_chart(
        &mut doc,
        scene,
        Rect {
            x: MARGIN,
            y: chord_y,
            w: WIDTH - 2.0 * MARGIN,
            h: chord_h,
        },
    );
    if let Some(axes) = &scene.axes {
        charts::draw_axes_chart(
            &mut doc,
            axes,
            Rect {
                x: MARGIN,
                y: axes_y,
                w: WIDTH - 2.0 * MARGIN,
                h: charts::axes_chart_height(),
            },
        );
    }
    doc.finish()
}

/// Writes `svg` to `dest` through [`kerf_io::write_file`]: atomically (a temporary file in the
/// same directory, renamed over `dest` once complete, so that a failure never leaves a partial
/// picture) onto a new path or a regular file, written through to a device or FIFO; a
/// symbolic link's target is written. `-` writes to standard output.
///
/// # Errors
/// Any I/O error; `dest` is then untouched.
pub fn write_svg(dest: impl AsRef<Path>, svg: &str) -> io::Result<()> {
    kerf_io::write_file(dest.as_ref(), |w| w.write_all(svg.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Vector3};

    /// A minimal XML well-formedness check: balanced and properly nested tags, quoted and
    /// unique attributes, valid entities. Returns the number of elements.
    pub(crate) fn well_formed(s: &str) -> Result<usize, String> {
        fn entities(text: &str) -> Result<(), String> {
            for (i, _) in text.match_indices('&') {
                let rest = &text[i + 1..];
                let end = rest.find(';').ok_or("unterminated entity")?;
                let name = &rest[..end];
                let ok = matches!(name, "amp" | "lt" | "gt" | "quot" | "apos")
                    || name
                        .strip_prefix('#')
                        .is_some_and(|n| n.chars().all(|c| c.is_ascii_digit()));
                if !ok {
                    return Err(format!("bad entity &{name};"));
                }
            }
            Ok(())
        }
        let mut stack: Vec<&str> = Vec::new();
        let mut count = 0;
        let mut i = 0;
        let mut roots = 0;
        while let Some(open) = s[i..].find('<') {
            let start = i + open;
            entities(&s[i..start])?;
            let end = start + s[start..].find('>').ok_or("unterminated tag")?;
            let tag = &s[start + 1..end];
            i = end + 1;
            if let Some(pi) = tag.strip_prefix('?') {
                if !pi.ends_with('?') || start != 0 {
                    return Err(format!("bad processing instruction <{tag}>"));
                }
                continue;
            }
            if let Some(name) = tag.strip_prefix('/') {
                match stack.pop() {
                    Some(open) if open == name => continue,
                    other => return Err(format!("</{name}> closes {other:?}")),
                }
            }
            let self_closing = tag.ends_with('/');
            let body = tag.trim_end_matches('/');
            let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
            let name = &body[..name_end];
            if name.is_empty()
                || !name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == ':')
            {
                return Err(format!("bad element name in <{tag}>"));
            }
            // Attributes: name="value" pairs.
            let mut rest = body[name_end..].trim_start();
            let mut seen = Vec::new();
            while !rest.is_empty() {
                let eq = rest
                    .find('=')
                    .ok_or_else(|| format!("attribute without value in <{tag}>"))?;
                let attr = rest[..eq].trim();
                if seen.contains(&attr) {
                    return Err(format!("duplicate attribute {attr} in <{tag}>"));
                }
                seen.push(attr);
                let after = &rest[eq + 1..];
                let quoted = after
                    .strip_prefix('"')
                    .ok_or_else(|| format!("unquoted {attr} in <{tag}>"))?;
                let close = quoted.find('"').ok_or("unterminated attribute")?;
                let value = &quoted[..close];
                if value.contains('<') {
                    return Err(format!("< in attribute {attr}"));
                }
                entities(value)?;
                rest = quoted[close + 1..].trim_start();
            }
            if stack.is_empty() {
                roots += 1;
            }
            count += 1;
            if !self_closing {
                stack.push(name);
            }
        }
        entities(&s[i..])?;
        if !stack.is_empty() {
            return Err(format!("unclosed {stack:?}"));
        }
        if roots != 1 {
            return Err(format!("{roots} root elements"));
        }
        Ok(count)
    }

    fn arc_scene(normals: bool) -> Scene {
        let pt = |t: f64| Point3::new(30.0 * t.cos(), 30.0 * t.sin(), 5.0 * t);
        let points: Vec<_> = (0..=20).map(|k| pt(f64::from(k) * 0.1)).collect();
        Scene {
            title: "arc <&> test".into(),
            subtitle: "sub".into(),
            tolerance: 0.01,
            paths: vec![
                PathPicture {
                    id: "arc \"1\"".into(),
                    curve: (0..=400).map(|k| pt(f64::from(k) * 0.005)).collect(),
                    normals: normals.then(|| vec![Vector3::z(); points.len()]),
                    segment_errors: (0..20).map(|k| 0.0005 * f64::from(k)).collect(),
                    points,
                },
                PathPicture {
                    id: "line".into(),
                    curve: vec![Point3::new(0.0, -10.0, 0.0), Point3::new(40.0, -10.0, 0.0)],
                    points: vec![Point3::new(0.0, -10.0, 0.0), Point3::new(40.0, -10.0, 0.0)],
                    normals: normals.then(|| vec![Vector3::z(); 2]),
                    segment_errors: vec![0.0],
                },
            ],
            axes: None,
            process: None,
        }
    }

    fn between<'a>(svg: &'a str, from: &str, to: &str) -> &'a str {
        let a = svg.find(from).expect("start marker");
        let b = a + svg[a..].find(to).expect("end marker");
        &svg[a..b]
    }

    #[test]
    fn the_picture_is_well_formed_with_every_part() {
        let svg = render(&arc_scene(false));
        well_formed(&svg).unwrap();
        for id in [
            "view-top",
            "view-front",
            "view-side",
            "view-iso",
            "legend-error",
            "chart-chord-error",
        ] {
            assert!(svg.contains(&format!("id=\"{id}\"")), "{id} drawn");
        }
        assert!(!svg.contains("chart-axes"), "no axes chart without axes");
        assert!(
            svg.contains("<title>arc &lt;&amp;&gt; test</title>"),
            "title escaped"
        );
        assert!(svg.contains("Top view (XY"), "view titles");
        assert!(
            svg.contains(">x / mm<") && svg.contains(">z / mm<"),
            "axis labels with units"
        );
        assert!(svg.contains(">chord error / mm<"), "chart axis label");
        assert!(svg.contains("tolerance 0.01 mm"), "tolerance line labelled");
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "only finite numbers"
        );
        // One marker per cutting point in each view.
        assert_eq!(
            svg.matches("class=\"pt\"").count(),
            4 * 23,
            "23 points, 4 views"
        );
        let top = between(&svg, "id=\"view-top\"", "id=\"view-iso\"");
        assert_eq!(
            top.matches("class=\"pt\"").count(),
            23,
            "23 points in the top view"
        );
        // Every segment drawn in the chart.
        let chart = between(&svg, "id=\"chart-chord-error\"", "</svg>");
        assert_eq!(
            chart.matches("<circle").count(),
            21 + 1,
            "21 segments and a legend dot"
        );
        assert!(
            !svg.contains("class=\"normals\"><line"),
            "no normals without normals"
        );
    }

    #[test]
    fn normals_are_drawn_when_present() {
        let svg = render(&arc_scene(true));
        well_formed(&svg).unwrap();
        let top = between(&svg, "id=\"view-top\"", "id=\"view-iso\"");
        let normals = between(top, "class=\"normals\"", "</g>");
        assert_eq!(
            normals.matches("<line").count(),
            23,
            "few points: every normal"
        );
        assert!(svg.contains("tool axis (toward the head)"), "legend entry");
    }

    #[test]
    fn many_normals_are_thinned_keeping_the_ends() {
        let idx = views::normal_indices(1000, 1000);
        assert!(idx.len() <= 400 && idx.len() >= 390, "{}", idx.len());
        assert_eq!((idx[0], *idx.last().unwrap()), (0, 999), "ends kept");
        assert_eq!(
            views::normal_indices(5, 100_000),
            vec![0, 4],
            "at least the ends"
        );
        assert_eq!(views::normal_indices(1, 10), vec![0], "a single point");
        assert!(views::normal_indices(0, 10).is_empty(), "no points");
    }

    #[test]
    fn axes_are_charted_with_their_limits() {
        let mut scene = arc_scene(true);
        let positions: Vec<[f64; 5]> = (0..30)
            .map(|k| {
                let t = f64::from(k);
                [t, 2.0 * t, 280.0, 10.0 + t, -t * 3.0]
            })
            .collect();
        scene.axes = Some(AxesChart {
            machine: "test head".into(),
            names: ["X", "Y", "Z", "A", "C"].map(String::from),
            paths: vec![
                ("arc".into(), positions.clone()),
                ("line".into(), positions),
            ],
            limits: [
                Some((-1500.0, 1500.0)),
                Some((-10.0, 100.0)),
                Some((-100.0, 600.0)),
                Some((-135.0, 135.0)),
                None,
            ],
            limits_known: true,
        });
        let svg = render(&scene);
        well_formed(&svg).unwrap();
        let chart = between(&svg, "id=\"chart-axes\"", "</svg>");
        assert!(chart.contains("test head"), "machine named");
        for name in ["X / mm", "Y / mm", "Z / mm", "A / deg", "C / deg"] {
            assert!(chart.contains(name), "{name} row");
        }
        assert!(
            chart.contains("min -1500, max 1500 mm: off scale"),
            "far limits written out"
        );
        assert!(
            chart.contains(">max 100 mm<") && chart.contains(">min -10 mm<"),
            "near limits drawn"
        );
        assert!(chart.contains("continuous axis: no limits"), "C has none");
        assert!(
            chart.contains("min -100, max 600 mm: off scale"),
            "Z constant: its limits far"
        );
        assert!(chart.contains("min -135, max 135 deg: off scale"), "A");
        assert_eq!(
            chart.matches("class=\"limit\"").count(),
            1 + 2,
            "legend + the Y limits"
        );
    }

    #[test]
    fn segments_above_the_tolerance_stand_out() {
        let mut scene = arc_scene(false);
        scene.paths[0].segment_errors[4] = 0.5;
        scene.paths[0].segment_errors[5] = 0.012;
        let svg = render(&scene);
        well_formed(&svg).unwrap();
        let top = between(&svg, "id=\"view-top\"", "id=\"view-iso\"");
        assert_eq!(
            top.matches("class=\"over\"").count(),
            1,
            "one run of two segments"
        );
        let chart = between(&svg, "id=\"chart-chord-error\"", "</svg>");
        assert_eq!(
            chart.matches("class=\"off\"").count(),
            1,
            "the outlier on the top edge"
        );
        assert!(
            chart.contains("1 segment above the chart, largest 0.5 mm"),
            "and said so"
        );
        assert_eq!(
            chart.matches("<circle").count(),
            21 + 1 - 1,
            "the others as dots"
        );
    }

    #[test]
    fn degenerate_scenes_do_not_panic() {
        let empty = Scene {
            title: String::new(),
            subtitle: String::new(),
            tolerance: 0.01,
            paths: Vec::new(),
            axes: None,
            process: None,
        };
        let svg = render(&empty);
        well_formed(&svg).unwrap();
        assert!(
            svg.contains("no paths") && svg.contains("no segments"),
            "said so"
        );
        let mut odd = arc_scene(true);
        odd.paths[0].points[3] = Point3::new(f64::NAN, 0.0, f64::INFINITY);
        odd.paths[0].segment_errors[2] = f64::NAN;
        odd.paths[1].points = vec![Point3::origin()];
        odd.paths[1].segment_errors.clear();
        odd.tolerance = 0.0;
        let svg = render(&odd);
        well_formed(&svg).unwrap();
        assert!(
            !svg.contains("NaN") && !svg.contains("inf"),
            "only finite numbers"
        );
        // A single point, every view flat.
        let mut dot = arc_scene(false);
        dot.paths.truncate(1);
        dot.paths[0].curve = vec![Point3::new(1.0, 2.0, 3.0)];
        dot.paths[0].points = vec![Point3::new(1.0, 2.0, 3.0)];
        dot.paths[0].segment_errors.clear();
        well_formed(&render(&dot)).unwrap();
    }

    #[test]
    fn the_checker_rejects_broken_xml() {
        assert!(well_formed("<a><b></a></b>").is_err(), "crossed");
        assert!(well_formed("<a x=1/>").is_err(), "unquoted");
        assert!(well_formed("<a>&nope;</a>").is_err(), "entity");
        assert!(well_formed("<a></a><b/>").is_err(), "two roots");
        assert!(
            well_formed("<a x=\"1\" x=\"2\"/>").is_err(),
            "duplicate attribute"
        );
        assert_eq!(well_formed("<?xml v?><a><b/>t &amp; u</a>"), Ok(2), "fine");
    }

    #[test]
    fn writes_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("p.svg");
        write_svg(&dest, "<svg/>").unwrap();
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "<svg/>", "written");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "no temporary file left: {names:?}");
        let bad = dir.path().join("missing").join("p.svg");
        assert!(write_svg(&bad, "<svg/>").is_err(), "no such directory");
        assert!(!bad.exists(), "nothing written");
    }

    /// The review's 600-byte circle at `-t 1e-8`: 594,000 cutting points made a 233 MB
    /// `plot.svg`. The picture's size no longer grows with the points, and it says what it
    /// left out.
    #[test]
    fn a_huge_scene_is_drawn_within_a_bounded_size_and_says_so() {
        let size = |n: usize, paths: usize| {
            let pt = |k: usize| {
                let t = k as f64 / n as f64 * std::f64::consts::TAU;
                Point3::new(700.0 * t.cos(), 700.0 * t.sin(), 0.0)
            };
            let scene = Scene {
                title: "big".into(),
                subtitle: String::new(),
                tolerance: 0.01,
                paths: (0..paths)
                    .map(|i| PathPicture {
                        id: format!("p{i}"),
                        curve: (0..=n).map(pt).collect(),
                        points: (0..=n).map(pt).collect(),
                        normals: Some(vec![Vector3::z(); n + 1]),
                        segment_errors: vec![0.005; n],
                    })
                    .collect(),
                axes: Some(AxesChart {
                    machine: "m".into(),
                    names: ["X", "Y", "Z", "A", "C"].map(String::from),
                    paths: (0..paths)
                        .map(|i| (format!("p{i}"), vec![[0.0; 5]; n + 1]))
                        .collect(),
                    limits: [None; 5],
                    limits_known: false,
                }),
                // A head check's band the whole contour long: thinned with the path.
                process: Some(ProcessPicture {
                    cuts: (0..paths)
                        .map(|i| CutPicture {
                            id: format!("p{i}"),
                            pierce: pt(0),
                            lead_in: Vec::new(),
                            lead_out: Vec::new(),
                            micro_joints: Vec::new(),
                            head_tilted: vec![(0..=n).map(pt).collect()],
                            head_close: Vec::new(),
                        })
                        .collect(),
                    traverses: Vec::new(),
                }),
            };
            let svg = render(&scene);
            (svg.len(), svg.contains("id=\"decimated\""), svg)
        };
        let (small, noted, _) = size(1_000, 1);
        assert!(!noted, "a small scene is drawn whole");
        let (big, noted, svg) = size(600_000, 1);
        assert!(noted, "the picture says it is thinned");
        assert!(
            svg.contains("Drawn: 20000 of 600000 segments"),
            "the counts"
        );
        assert!(
            big < 12_000_000,
            "{big} bytes for 600,000 points ({small} for 1,000)"
        );
        let (many, noted, svg) = size(20, 10_000);
        assert!(
            noted && svg.contains("the first 2000 of 10000 paths"),
            "paths"
        );
        // The 2000 drawn cuts' pierce markers and numbers add about 1 MB over four views; the
        // first 200 head-check bands are drawn.
        assert!(many < 14_000_000, "{many} bytes for 10,000 paths");
        assert_eq!(
            svg.matches("class=\"head-tilted\"").count(),
            4 * 200,
            "the first 200 bands, in four views"
        );
        well_formed(&svg).expect("well-formed");
    }

    #[test]
    fn the_process_is_drawn_pierces_numbered_in_cutting_order() {
        let mut scene = arc_scene(true);
        // Cut "line" first, then the arc: pierces off both, a traverse between them.
        let p0 = Point3::new(-3.0, -12.0, 0.0);
        let p1 = Point3::new(28.0, 2.0, 0.0);
        scene.process = Some(ProcessPicture {
            cuts: vec![
                CutPicture {
                    id: "line".into(),
                    pierce: p0,
                    lead_in: vec![p0, Point3::new(0.0, -10.0, 0.0)],
                    lead_out: vec![Point3::new(40.0, -10.0, 0.0), Point3::new(42.0, -8.0, 0.0)],
                    micro_joints: vec![[
                        Point3::new(20.0, -10.0, 0.0),
                        Point3::new(20.5, -10.0, 0.0),
                    ]],
                    head_tilted: vec![
                        vec![Point3::new(5.0, -10.0, 0.0), Point3::new(9.0, -10.0, 0.0)],
                        // A single point is not a stretch: not drawn.
                        vec![Point3::new(12.0, -10.0, 0.0)],
                    ],
                    head_close: vec![vec![
                        Point3::new(30.0, -10.0, 0.0),
                        Point3::new(31.0, -10.0, 0.0),
                        Point3::new(32.0, -10.0, 0.0),
                    ]],
                },
                CutPicture {
                    id: "arc".into(),
                    pierce: p1,
                    lead_in: vec![p1, Point3::new(30.0, 0.0, 0.0)],
                    lead_out: Vec::new(),
                    micro_joints: Vec::new(),
                    head_tilted: Vec::new(),
                    head_close: Vec::new(),
                },
            ],
            traverses: vec![vec![Point3::new(42.0, -8.0, 0.0), p1]],
        });
        let svg = render(&scene);
        well_formed(&svg).unwrap();
        let top = between(&svg, "id=\"view-top\"", "id=\"view-iso\"");
        assert_eq!(
            top.matches("class=\"pierce\"").count(),
            2,
            "one marker a pierce"
        );
        for (class, count, why) in [
            ("traverse", 1, "one traverse"),
            ("lead-in", 2, "one a cut"),
            ("micro-joint", 1, "one bar a joint"),
            ("lead-out", 1, "none drawn when empty"),
            ("head-tilted", 1, "a single tilted point is not drawn"),
            ("head-close", 1, "one close stretch"),
        ] {
            let tag = format!("class=\"{class}\"");
            assert_eq!(top.matches(&tag).count(), count, "{class}: {why}");
        }
        // The numbers, in document order, are 1..n, each beside its own marker.
        let mut numbers = Vec::new();
        let mut rest = top;
        while let Some(i) = rest.find("class=\"pierce\" data-order=\"") {
            let tag_start = rest[..i].rfind("<circle").unwrap();
            let tag = &rest[tag_start..i];
            let attr = |name: &str| -> f64 {
                let a = tag.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
                tag[a..a + tag[a..].find('"').unwrap()].parse().unwrap()
            };
            let (cx, cy) = (attr("cx"), attr("cy"));
            let after = &rest[i..];
            let t = after.find("class=\"order\">").unwrap();
            let text_tag = &after[after[..t].rfind("<text").unwrap()..t];
            let tx: f64 = {
                let a = text_tag.find("x=\"").unwrap() + 3;
                text_tag[a..a + text_tag[a..].find('"').unwrap()]
                    .parse()
                    .unwrap()
            };
            let n: usize = after[t + 14..t + 14 + after[t + 14..].find('<').unwrap()]
                .parse()
                .unwrap();
            assert!((tx - cx - 4.5).abs() < 0.01, "number {n} beside its marker");
            assert!(cx.is_finite() && cy.is_finite());
            numbers.push(n);
            rest = &after[t..];
        }
        assert_eq!(numbers, vec![1, 2]);
        assert_eq!(
            svg.matches("class=\"pierce\"").count(),
            2 * 4,
            "in all 4 views"
        );
    }
}
