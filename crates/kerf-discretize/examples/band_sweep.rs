//! Measures point count (relative to N*) and speed of the reference-sphere walk for several
//! band settings, on seeded smooth random cubic and quintic curves. Used to choose the default
//! band (`docs/discretization.md`).
//!
//! Run: `cargo run --release -p kerf-discretize --example band_sweep`

use std::time::Instant;

use kerf_discretize::{discretize, minimum_count, Options};
use kerf_nurbs::NurbsCurve;

fn smooth_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    kerf_nurbs::smooth_random_curves(degree, count, seed)
}

fn main() {
    println!("| degree | tol | band | segments / N* | points/s (1 thread) |");
    println!("|---|---|---|---|---|");
    for degree in [3, 5] {
        let curves = smooth_curves(degree, 200, 99 + degree as u64);
        for tol in [0.01, 0.001] {
            let nstar: f64 = curves.iter().map(|c| minimum_count(c, tol)).sum();
            for band in [0.5, 0.7, 0.8, 0.9, 0.95, 0.98] {
                let opts = Options::with_tolerance(tol).with_band(band);
                let start = Instant::now();
                let mut segs = 0;
                let mut pts = 0;
                let reps = 5;
                for _ in 0..reps {
                    segs = 0;
                    for c in &curves {
                        let d = discretize(c, &opts).expect("discretizes");
                        segs += d.segments();
                        pts += d.points().len();
                    }
                }
                let rate = pts as f64 / start.elapsed().as_secs_f64();
                println!(
                    "| {degree} | {tol} | {band} | {:.4} | {:.2e} |",
                    segs as f64 / nstar,
                    rate
                );
            }
        }
    }
}
