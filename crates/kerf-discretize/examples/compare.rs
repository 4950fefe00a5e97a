//! Reproduces the comparison of paper 004 on kerf's fixtures: points and time per strategy, per
//! curve (small fixtures) and per file (real parts). Every strategy carries the same certified
//! guarantee; the table shows what each costs in points. Times are the best of 5 runs.
//!
//! Run: `cargo run --release -p kerf-discretize --example compare -- 0.01`

use std::path::Path;
use std::time::Instant;

use kerf_discretize::{discretize, minimum_count, Options, Strategy};

const STRATEGIES: [(Strategy, &str); 4] = [
    (Strategy::ReferenceSphere, "reference sphere"),
    (Strategy::EqualError, "equal error"),
    (Strategy::EqualChordLength, "equal chord"),
    (Strategy::EqualParameter, "equal parameter"),
];

fn main() {
    let tol: f64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.01);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let files = [
        ("mixed.json", true),
        ("circle.json", true),
        ("realdata/nori_sheetmetal.json", false),
        ("realdata/occt_propeller.json", false),
    ];
    println!("tolerance {tol} mm; points (time) per strategy; N* = theoretical minimum segments\n");
    println!(
        "| file | curve | N* | reference sphere | equal error | equal chord | equal parameter |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (file, per_curve) in files {
        let doc = kerf_format::curves::load(root.join(file)).expect("fixture loads");
        let mut totals = [(0usize, 0.0f64); 4];
        let mut nstar_total = 0.0;
        for rec in &doc.curves {
            let nstar = minimum_count(&rec.curve, tol);
            nstar_total += nstar;
            let mut cells = Vec::new();
            for (i, (s, _)) in STRATEGIES.iter().enumerate() {
                let opts = Options::with_tolerance(tol).with_strategy(*s);
                // Best of 5 runs: the first run of a curve pays for cold caches.
                let mut secs = f64::INFINITY;
                let mut d = None;
                for _ in 0..5 {
                    let start = Instant::now();
                    d = Some(discretize(&rec.curve, &opts).expect("discretizes"));
                    secs = secs.min(start.elapsed().as_secs_f64());
                }
                let d = d.expect("ran");
                totals[i].0 += d.points().len();
                totals[i].1 += secs;
                cells.push(format!("{} ({:.0} us)", d.points().len(), secs * 1e6));
            }
            if per_curve {
                println!(
                    "| {file} | {} | {nstar:.1} | {} |",
                    rec.id,
                    cells.join(" | ")
                );
            }
        }
        let cells: Vec<String> = totals
            .iter()
            .map(|(n, s)| format!("{n} ({:.1} ms)", s * 1e3))
            .collect();
        println!(
            "| {file} | all {} curves | {nstar_total:.1} | {} |",
            doc.curves.len(),
            cells.join(" | ")
        );
    }
}
