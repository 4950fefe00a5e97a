//! `kerf run` on every shipped fixture: the report's process figures (pierces, cut length,
//! traverse length against file order, estimated time) recomputed from the written axes file,
//! the traverses checked against the part and written into the axes file, and the program
//! header stating the placement.

mod common;

use common::{read_json, run_auto, run_auto_with};
use serde_json::Value;

fn dist(a: &Value, b: &Value) -> f64 {
    (0..3)
        .map(|k| (a[k].as_f64().unwrap() - b[k].as_f64().unwrap()).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn poly_len(poses: &[Value]) -> f64 {
    poses.windows(2).map(|w| dist(&w[0], &w[1])).sum()
}

#[test]
fn every_fixture_reports_pierces_lengths_saved_traverse_and_time() {
    let cases = [
        ("sheet_metal_holes.json", "ac_head.json"),
        ("door_trim.json", "ac_head.json"),
        ("dome.json", "ac_head.json"),
        ("tube_saddle.json", "ac_head.json"),
        ("tube_saddle_stl.json", "ac_head.json"),
        ("mixed.json", "ac_head.json"),
        ("mesh_surfaces.json", "ac_head.json"),
        ("circle.json", "ac_head.json"),
        ("quarter_arc.json", "ac_head.json"),
    ];
    for (curves, machine) in cases {
        // `mixed`'s curves run under its tilted plane: the head meets it (the head check has
        // its own tests); the traverses are what is asserted here.
        let dir = if curves == "mixed.json" {
            run_auto_with(curves, machine, &["--cut-clearance", "off"])
        } else {
            run_auto(curves, machine)
        };
        let report = read_json(&dir.path().join("report.json"));
        let axes = read_json(&dir.path().join("axes.json"));
        let paths = axes["paths"].as_array().expect("paths");
        let p = &report["process"];
        assert_eq!(
            p["pierces"].as_u64(),
            Some(paths.len() as u64),
            "{curves}: pierces"
        );
        // Cut length: the contours' polylines as written (the kinematics' inserted points
        // lie on the curve, so the written polyline is at most a little longer).
        let cut: f64 = paths
            .iter()
            .map(|q| poly_len(q["poses"].as_array().expect("poses")))
            .sum();
        let said = p["cut_length_mm"].as_f64().expect("cut length");
        assert!(
            said > 0.0 && (cut - said).abs() <= 1e-3 * said + 0.05,
            "{curves}: cut {said} against {cut}"
        );
        // Traverse: from each cut's last pose to the next cut's first (pierce) pose, within
        // each set-up (distances do not change under the placement).
        let setups = report["placement"]["setups"]
            .as_array()
            .map_or(1, Vec::len)
            .max(1);
        let first = |q: &Value| -> Value {
            q.get("lead_in")
                .and_then(|l| l["poses"].as_array())
                .and_then(|v| v.first())
                .cloned()
                .unwrap_or_else(|| q["poses"][0].clone())
        };
        let last = |q: &Value| -> Value {
            q.get("lead_out")
                .and_then(|l| l["poses"].as_array())
                .and_then(|v| v.last())
                .cloned()
                .unwrap_or_else(|| q["poses"].as_array().unwrap().last().unwrap().clone())
        };
        let traverse = p["traverse_mm"].as_f64().expect("traverse");
        let file_order = p["file_order_traverse_mm"].as_f64().expect("file order");
        let saved = p["traverse_saved_mm"].as_f64().expect("saved");
        assert!(
            (file_order - traverse - saved).abs() < 1e-9,
            "{curves}: saved = file order - traverse"
        );
        assert!(
            traverse <= file_order + 1e-9,
            "{curves}: the order is no longer than file order"
        );
        if setups == 1 {
            let again: f64 = paths
                .windows(2)
                .map(|w| dist(&last(&w[0]), &first(&w[1])))
                .sum();
            assert!(
                (again - traverse).abs() < 1e-6 * (1.0 + traverse),
                "{curves}: traverse {traverse} against {again} from axes.json"
            );
        }
        // Estimated time: at least the cut at the programmed feed.
        let feed = report["interpolation"]["feed_mm_per_min"]
            .as_f64()
            .expect("feed");
        let time = report["interpolation"]["duration_s"]
            .as_f64()
            .expect("time");
        assert!(
            time >= cut / feed * 60.0 * 0.999,
            "{curves}: {time} s for {cut} mm at {feed}"
        );
        // Traverses: checked, one per gap within a set-up, in the axes file, clear.
        let t = &report["traverses"];
        assert_eq!(t["checked"], Value::Bool(true), "{curves}: checked");
        let gaps = paths.len().saturating_sub(setups);
        assert_eq!(
            t["count"].as_u64(),
            Some(gaps as u64),
            "{curves}: one traverse per gap"
        );
        let unchecked = t["unchecked"].as_array().map_or(0, Vec::len);
        let written = paths.iter().filter(|q| q.get("traverse").is_some()).count();
        assert_eq!(
            written + unchecked,
            gaps,
            "{curves}: traverse moves in axes.json"
        );
        if let Some(d) = t["min_distance_mm"].as_f64() {
            assert!(d >= 5.0, "{curves}: min distance {d}");
        }
        // The program states the placement.
        let program = std::fs::read_to_string(dir.path().join(if setups == 1 {
            "program.nc"
        } else {
            "program-1.nc"
        }))
        .expect("program");
        assert!(
            program.contains("placement [part to workpiece]: translation"),
            "{curves}: header"
        );
    }
}
