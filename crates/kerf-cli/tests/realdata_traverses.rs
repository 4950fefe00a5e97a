//! The traverses of the real files (`kerf run --place auto` on the gantry): how many are
//! checked against the part, and the residue with its reasons asserted exactly, so that a
//! change that loses a route (or finds one) shows here. Every gap is either written as a
//! checked traverse into `axes.json` or listed as unchecked with the reason; every listed
//! own-surface exemption names a surface the neighbouring cut's curve names.

mod common;

use common::{fixture, read_json, run_auto};
use serde_json::Value;

fn run(curves: &str) -> (Value, Value, Value) {
    let dir = run_auto(curves, "gantry_ac.json");
    let curves_file = read_json(&fixture(curves));
    (
        read_json(&dir.path().join("report.json")),
        read_json(&dir.path().join("axes.json")),
        curves_file,
    )
}

#[test]
fn real_files_route_every_traverse_but_an_asserted_residue() {
    // (file, gaps, unchecked, own): the residue is gaps where every route shape tried
    // (straight, lifted over the nearby surfaces, over the safe plane, each at two heights and
    // with five retract heights at each end) is measured closer than the clearance somewhere
    // (a witness sample, not the tracing's margin: none is left unproven); `own` gaps
    // leave out a cut's own surface that curls over its head line (holes narrower than the
    // clearance cut with the wall's radial normal as tool axis). `turned`: contours cut from
    // the other side of the sheet because the nozzle's line meets the part from the given
    // side and not from the other; `both`: contours kept although their nozzle's line meets
    // the part from both sides (or the head cannot reach the clear side): most of the `own`
    // residue.
    for (curves, gaps, unchecked, own, turned, both) in [
        ("realdata/nori_sheetmetal.json", 74, 2, 9, 6, 13),
        ("realdata/occt_propeller.json", 46, 3, 1, 9, 13),
    ] {
        let (report, axes, file) = run(curves);
        let sides = report["placement"]["sides"].as_array().expect("sides");
        let reasons = |needle: &str| {
            sides
                .iter()
                .filter(|s| s["reason"].as_str().expect("reason").contains(needle))
                .collect::<Vec<_>>()
        };
        let by_head = reasons("from the other side at none");
        assert_eq!(by_head.len(), turned, "{curves}: {sides:#?}");
        let flipped = report["placement"]["flipped_paths"]
            .as_array()
            .expect("flipped");
        for s in &by_head {
            assert_eq!(s["side"], "other", "{s}");
            assert!(flipped.contains(&s["id"]), "{curves}: {s}");
        }
        let kept = reasons("both sides").len() + reasons("cannot reach the other side").len();
        assert_eq!(kept, both, "{curves}: {sides:#?}");
        let t = &report["traverses"];
        let clearance = t["clearance_mm"].as_f64().expect("clearance");
        assert_eq!(t["count"].as_u64(), Some(gaps), "{curves}: gaps");
        let listed = t["unchecked"].as_array().expect("unchecked");
        assert_eq!(listed.len(), unchecked, "{curves}: unchecked {listed:#?}");
        for u in listed {
            let why = u["reason"].as_str().expect("reason");
            assert!(
                why.contains("measured closer than the clearance, 0 not proven")
                    && why.contains(
                        "0 of them only in the machine's rapid swing, 0 leave the axis limits"
                    ),
                "{curves}: {why}"
            );
            // The named sample is closer than the clearance (a measured violation).
            let d: f64 = why
                .rsplit(") is ")
                .next()
                .and_then(|t| t.split(" mm").next())
                .and_then(|t| t.parse().ok())
                .expect("the distance in the reason");
            assert!(d < clearance, "{curves}: {why}");
        }
        assert_eq!(
            t["checked_count"].as_u64(),
            Some(gaps - unchecked as u64),
            "{curves}"
        );
        assert!(
            t["min_distance_mm"].as_f64().expect("min") >= clearance,
            "{curves}: a checked traverse closer than the clearance"
        );
        // Every gap of a set-up: a checked traverse in axes.json, or listed as unchecked.
        let paths = axes["paths"].as_array().expect("paths");
        let written = paths.iter().filter(|p| p.get("traverse").is_some()).count();
        assert_eq!(written as u64, gaps - unchecked as u64, "{curves}: written");
        for u in listed {
            let before = u["before"].as_str().expect("before");
            let p = paths
                .iter()
                .find(|p| p["id"] == before)
                .expect("the listed cut");
            assert!(p.get("traverse").is_none(), "{curves}: {before}");
        }
        // Own-surface exemptions name a surface of one of the two cuts.
        let surfaces_of = |id: &str| -> Vec<String> {
            let c = file["curves"]
                .as_array()
                .expect("curves")
                .iter()
                .find(|c| c["id"] == id)
                .expect("curve");
            let mut s: Vec<String> = c["surfaces"]
                .as_array()
                .map(|a| a.iter().map(|v| v.as_str().unwrap().to_string()).collect())
                .unwrap_or_default();
            if let Some(one) = c["surface"].as_str() {
                s.push(one.to_string());
            }
            s
        };
        let owns = t["own_surface_over_the_head"].as_array().expect("own");
        assert_eq!(owns.len(), own, "{curves}: {owns:#?}");
        for o in owns {
            let mut named = surfaces_of(o["after"].as_str().unwrap());
            named.extend(surfaces_of(o["before"].as_str().unwrap()));
            for s in o["surfaces"].as_array().unwrap() {
                assert!(named.contains(&s.as_str().unwrap().to_string()), "{o}");
            }
        }
    }
}
