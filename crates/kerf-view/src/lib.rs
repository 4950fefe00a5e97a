//! An interactive 3D view of a kerf run as one self-contained HTML file (`view.html`).
//!
//! A [`Scene`] holds what is shown, as plain data in the workpiece frame of each set-up: the
//! part's surfaces as triangles, every cut's tip path, the beam direction at its points, the
//! pierce points in cutting order, the traverses between the cuts, a timeline of the planned
//! motion (the tip and the tool axis every few interpolation cycles, each sample's speed as a
//! share of the programmed feed) and the head's solids; the run's warnings beside it.
//! [`html`] turns it into one file that opens from the disk with no network: the page embeds
//! three.js (MIT, `vendor/three.bundle.min.js`, built by `scripts/vendor_three.sh`), the scene
//! as JSON and the viewer's script (`src/view.js`).
//!
//! The page shows the surfaces shaded, the paths coloured by planned speed (red where the
//! machine crawls, green at the programmed feed), traverses dashed, lead-ins and lead-outs in
//! their own colours, numbered pierces, beam directions as short lines toward the head, a
//! marker at each warning that names a point (every warning listed beside the view, each
//! clickable), and a time slider with a play button that moves the head along the planned
//! motion, with the time, the speed and the tip shown.
//!
//! For tests the page exposes `window.kerfView` (`counts`, `setTime(setup, t)`, `errors`) and,
//! when opened with a fragment `#t=<seconds>` (optionally `&setup=<k>`), writes the counts, the
//! head's tip and axis at that time and any script errors as JSON into `<pre id="kerf-test">`,
//! so that a headless browser's `--dump-dom` can read them back.

use serde::Serialize;

/// The three.js bundle (three r187 with `OrbitControls`, minified into one script that sets the
/// global `THREE`), made by `scripts/vendor_three.sh` from the npm package.
const THREE: &str = include_str!("../vendor/three.bundle.min.js");

/// The viewer's own script.
const VIEW_JS: &str = include_str!("view.js");

/// The most timeline samples of one set-up: a longer motion is sampled every few cycles
/// (the page interpolates linearly between samples, which it states).
pub const MAX_TIMELINE_SAMPLES: usize = 10_000;

/// The most triangles of all surfaces together: beyond it the surfaces' grids are coarsened.
pub const MAX_TRIANGLES: usize = 200_000;

/// What the view shows.
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct Scene {
    /// The title (the input file).
    pub title: String,
    /// The machine's name.
    pub machine: String,
    /// The programmed cutting feed, mm/min: the speed colours are shares of it.
    pub feed_mm_per_min: f64,
    /// The machine's axis names (`X Y Z A C`, or `B` for the tilt), as the set-points name them.
    pub axis_names: Vec<String>,
    /// The head's solids from the nozzle tip up: `[length, bottom diameter, top diameter]`
    /// in mm each.
    pub head: Vec<[f64; 3]>,
    /// How far the nozzle tip stands above the tool tip along the axis, mm (the machine's
    /// `process.standoff_mm`).
    pub head_standoff_mm: f64,
    /// The run's warnings, in order.
    pub warnings: Vec<Warning>,
    /// The set-ups, in cutting order.
    pub setups: Vec<Setup>,
}

/// One warning of the run, with the first point its text names, if any (drawn as a marker
/// where the scene has one set-up: the text does not say in which set-up's frame it is).
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct Warning {
    /// The text as the run printed it.
    pub text: String,
    /// The first point `(x, y, z)` the text names.
    pub point: Option<[f64; 3]>,
}

impl Warning {
    /// A warning of `text`, its point the first `(x, y, z)` in it.
    pub fn new(text: &str) -> Self {
        Self {
            text: text.to_string(),
            point: first_point(text),
        }
    }
}

/// One set-up: the part clamped once, in its workpiece frame.
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct Setup {
    /// Its program's file name.
    pub program: String,
    /// The part's surfaces.
    pub surfaces: Vec<SurfaceMesh>,
    /// The cuts in cutting order.
    pub cuts: Vec<Cut>,
    /// The traverses between the cuts, as tip polylines (flat `x, y, z, ...`).
    pub traverses: Vec<Vec<f32>>,
    /// The planned motion.
    pub timeline: Timeline,
}

/// A surface as triangles.
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct SurfaceMesh {
    /// Its id.
    pub id: String,
    /// Vertex positions, flat `x, y, z, ...`, mm.
    pub positions: Vec<f32>,
    /// Triangles, three vertex indices each.
    pub indices: Vec<u32>,
}

/// One cut: its tip path (lead-in, contour, lead-out), its beam directions and its pierce.
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct Cut {
    /// The path's id.
    pub id: String,
    /// The tip path, flat `x, y, z, ...`, mm.
    pub points: Vec<f32>,
    /// Beam directions (unit, toward the head) at some of the points: `x, y, z, i, j, k`
    /// each.
    pub beams: Vec<f32>,
    /// The pierce point (the rapid's end above the cut's start).
    pub pierce: [f32; 3],
    /// The length of its lead-in at the start of `points`, mm (0 without).
    pub lead_in_mm: f32,
    /// The length of its lead-out at the end of `points`, mm (0 without).
    pub lead_out_mm: f32,
}

/// The planned motion of a set-up, sampled.
#[derive(Debug, Clone, Default, Serialize)]
#[non_exhaustive]
pub struct Timeline {
    /// Its duration, seconds.
    pub duration_s: f64,
    /// The time between two samples, seconds (a whole number of interpolation cycles).
    pub step_s: f64,
    /// The interpolation cycle, seconds.
    pub cycle_s: f64,
    /// One sample per step from 0: `x, y, z` (tip), `i, j, k` (tool axis), the tip's speed as
    /// a share of the programmed feed, 1 on a traverse (0 while cutting), and the five machine
    /// axes of the set-point (mm and degrees, [`Scene::axis_names`]): 13 numbers each.
    pub samples: Vec<f32>,
}

/// Numbers per timeline sample.
pub const SAMPLE_LEN: usize = 13;

/// The page of `scene`: one HTML file with three.js, the scene and the viewer inside.
pub fn html(scene: &Scene) -> String {
    // Straight to text: through a `Value` every f32 would be written with an f64's digits.
    let data = serde_json::to_string(scene).unwrap_or_else(|_| "{}".to_string());
    page(data, &scene.title)
}

/// The page of a scene given as JSON (as [`read_scene`] reads it back from a page): how `kerf
/// view` refreshes a page with this version's viewer and the report's warnings.
pub fn html_value(scene: &serde_json::Value) -> String {
    let data = serde_json::to_string(scene).unwrap_or_else(|_| "{}".to_string());
    page(data, scene["title"].as_str().unwrap_or(""))
}

/// The page of the scene's JSON text `data`.
fn page(data: String, title: &str) -> String {
    // Inside <script> only `</script` or `<!--` could end or change it: every `<` of the
    // data (warnings and ids come from input files) is written as its JSON escape.
    let data = data.replace('<', "\\u003c");
    let title = escape_html(title);
    let mut s = String::with_capacity(THREE.len() + VIEW_JS.len() + data.len() + 4096);
    s.push_str("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>kerf: ");
    s.push_str(&title);
    s.push_str("</title>\n<style>");
    s.push_str(CSS);
    s.push_str("</style></head><body>\n");
    s.push_str(BODY);
    s.push_str("\n<script id=\"kerf-scene\" type=\"application/json\">");
    s.push_str(&data);
    s.push_str("</script>\n<script>");
    s.push_str(&THREE.replace("</script", "<\\/script"));
    s.push_str("</script>\n<script>");
    s.push_str(VIEW_JS);
    s.push_str("</script>\n</body></html>\n");
    s
}

/// The scene a page of [`html`] holds, as JSON.
///
/// # Errors
/// A message saying what is missing when `page` holds no scene (not a page of kerf's view)
/// or its scene is not JSON.
pub fn read_scene(page: &str) -> Result<serde_json::Value, String> {
    let open = "<script id=\"kerf-scene\" type=\"application/json\">";
    let start = page
        .find(open)
        .ok_or("no kerf scene in the page (not a view.html of kerf run)")?
        + open.len();
    let end = start
        + page[start..]
            .find("</script>")
            .ok_or("the page's kerf scene is not closed")?;
    let v: serde_json::Value = serde_json::from_str(&page[start..end])
        .map_err(|e| format!("the page's kerf scene is not JSON: {e}"))?;
    if !v["setups"].is_array() {
        return Err("the page's kerf scene has no set-ups".to_string());
    }
    Ok(v)
}

/// `text` safe inside HTML text.
fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

/// The first `(x, y, z)` of three numbers in `text`.
fn first_point(text: &str) -> Option<[f64; 3]> {
    let mut rest = text;
    while let Some(open) = rest.find('(') {
        let after = &rest[open + 1..];
        if let Some(close) = after.find(')') {
            let parts: Vec<f64> = after[..close]
                .split(',')
                .filter_map(|p| p.trim().parse().ok())
                .collect();
            if parts.len() == 3
                && after[..close].split(',').count() == 3
                && parts.iter().all(|v| v.is_finite())
            {
                return Some([parts[0], parts[1], parts[2]]);
            }
        }
        rest = after;
    }
    None
}

const CSS: &str = "html,body{margin:0;height:100%;font:13px sans-serif;background:#1e2228;color:#dde}\
#view{position:absolute;left:0;top:0;right:320px;bottom:64px}\
#side{position:absolute;right:0;top:0;width:320px;bottom:64px;overflow:auto;background:#262b33;padding:8px;box-sizing:border-box}\
#bar{position:absolute;left:0;right:0;bottom:0;height:64px;background:#2d333c;padding:6px 10px;box-sizing:border-box}\
#bar input[type=range]{width:60%;vertical-align:middle}\
#side h3{margin:6px 0 4px;font-size:13px}#side li{cursor:pointer;margin:3px 0}#side li.sel{color:#fc6}\
#legend span{display:inline-block;width:14px;height:10px;margin-right:4px}\
#kerf-test{display:none}.lbl{position:absolute;color:#fff;font:11px sans-serif;pointer-events:none;text-shadow:0 0 3px #000}";

const BODY: &str = "<div id=\"view\"></div>\
<div id=\"side\"><div id=\"title\"></div>\
<div>set-up <select id=\"setup\"></select></div>\
<div id=\"legend\"><span style=\"background:#e33\"></span>crawling <span style=\"background:#ec3\"></span>half feed <span style=\"background:#3c5\"></span>at feed <span style=\"background:#48f\"></span>traverse</div>\
<h3>counts</h3><div id=\"counts\"></div>\
<h3>warnings</h3><ol id=\"warnings\"></ol><div id=\"warning-text\"></div></div>\
<div id=\"bar\"><button id=\"play\">play</button> <input id=\"time\" type=\"range\" min=\"0\" max=\"1\" step=\"any\" value=\"0\"> <span id=\"readout\"></span></div>\
<pre id=\"kerf-test\"></pre>";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_name_their_first_point() {
        let w =
            Warning::new("traverse 3 (before \"hole\"): at (1.5, -2, 3e1) the head is 2 mm off");
        assert_eq!(w.point, Some([1.5, -2.0, 30.0]));
        assert_eq!(Warning::new("no point (here) or (1, 2)").point, None);
    }

    #[test]
    fn text_from_the_input_cannot_close_the_script() {
        let scene = Scene {
            title: "<b>part</b>".into(),
            warnings: vec![Warning::new("id </script><script>alert(1)</script>")],
            ..Scene::default()
        };
        let page = html(&scene);
        assert_eq!(
            page.matches("</script>").count(),
            3,
            "the three scripts' ends only"
        );
        assert!(page.contains("kerf: &lt;b&gt;part&lt;/b&gt;</title>"));
        // The data reads back as it was.
        let start = page.find("type=\"application/json\">").expect("data") + 24;
        let end = start + page[start..].find("</script>").expect("end");
        let v: serde_json::Value = serde_json::from_str(&page[start..end]).expect("JSON");
        assert_eq!(
            v["warnings"][0]["text"],
            "id </script><script>alert(1)</script>"
        );
        // And as the reader reads it, to the same page.
        let back = read_scene(&page).expect("scene");
        assert_eq!(back, v);
        assert_eq!(read_scene(&html_value(&back)).expect("again"), back);
        assert!(read_scene("<html></html>").is_err());
    }
}
