//! `kerf run`'s plot shows the laser process: in the top view one pierce marker per cut
//! (`report.json`'s pierce count), numbered 1..n in the order the axes file cuts them, each
//! marker at that cut's first lead-in point; lead-ins drawn; traverses dashed, one per gap.

mod common;

use common::{read_json, run_auto};

#[test]
fn the_plot_numbers_the_pierces_in_cutting_order() {
    for curves in ["sheet_metal_holes.json", "door_trim.json"] {
        let dir = run_auto(curves, "ac_head.json");
        let report = read_json(&dir.path().join("report.json"));
        let pierces = report["process"]["pierces"].as_u64().expect("pierces") as usize;
        let gaps = report["traverses"]["count"].as_u64().expect("count") as usize;
        let svg = std::fs::read_to_string(dir.path().join("plot.svg")).expect("plot");
        let a = svg.find("id=\"view-top\"").expect("top view");
        let top = &svg[a..a + svg[a..].find("id=\"view-iso\"").expect("iso view")];
        assert_eq!(top.matches("class=\"pierce\"").count(), pierces, "{curves}");
        assert_eq!(top.matches("class=\"traverse\"").count(), gaps, "{curves}");
        assert!(top.matches("class=\"lead-in\"").count() >= 1, "{curves}");
        let numbers: Vec<usize> = top
            .match_indices("class=\"order\">")
            .map(|(i, m)| {
                let s = &top[i + m.len()..];
                s[..s.find('<').unwrap()].parse().unwrap()
            })
            .collect();
        assert_eq!(numbers, (1..=pierces).collect::<Vec<_>>(), "{curves}");
        let orders: Vec<usize> = top
            .match_indices("data-order=\"")
            .map(|(i, m)| {
                let s = &top[i + m.len()..];
                s[..s.find('"').unwrap()].parse().unwrap()
            })
            .collect();
        assert_eq!(orders, (1..=pierces).collect::<Vec<_>>(), "{curves}");
        // The cutting order of the plot is the axes file's: path k's id is cut k's.
        let axes = read_json(&dir.path().join("axes.json"));
        assert_eq!(axes["paths"].as_array().unwrap().len(), pierces, "{curves}");
    }
}
