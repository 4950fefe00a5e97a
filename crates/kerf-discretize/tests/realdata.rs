//! Real parts (sheet-metal bends, a propeller with degree-11 edges and C0 knots) at 0.01 and
//! 0.001 mm, every segment checked by the independent brute force.

mod common;

use std::path::Path;

use kerf_discretize::{discretize, minimum_count, Options};

fn run(file: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/realdata")
        .join(file);
    let doc = kerf_format::curves::load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert!(!doc.curves.is_empty(), "{file} has curves");
    for tol in [0.01, 0.001] {
        let (mut segs, mut nstar) = (0usize, 0.0);
        for rec in &doc.curves {
            let d = discretize(&rec.curve, &Options::with_tolerance(tol))
                .unwrap_or_else(|e| panic!("{file} {}: {e}", rec.id));
            common::check(&rec.curve, &d, tol);
            segs += d.segments();
            nstar += minimum_count(&rec.curve, tol);
        }
        eprintln!("{file} tol {tol}: {segs} segments, N* {nstar:.1}");
    }
}

#[test]
fn sheet_metal_bends() {
    run("nori_sheetmetal.json");
}

#[test]
fn propeller_edges() {
    run("occt_propeller.json");
}
