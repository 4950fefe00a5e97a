//! Times the discretization alone (no reading, no writing) of every curve of a `kerf.curves/1`
//! file, on one thread, in CPU time of that thread; prints one JSON line. Used by
//! `benches/discretize_vs_occt.py` (issue 15) next to the whole `kerf discretize` process and
//! Open CASCADE's `GCPnts_TangentialDeflection`.
//!
//! Run: `cargo run --release --example discretize_time -- FILE TOLERANCE [REPS [BAND]]`
//!
//! The figure is the fastest of `REPS` (default 3) passes over the whole file. The CPU time of
//! the thread is read from `/proc/thread-self/schedstat` (nanoseconds on a CPU), so other
//! processes on a loaded machine do not inflate it; where that file is missing, wall time is
//! used and the output says so.

use std::time::Instant;

use kerf::discretize::{discretize, minimum_count, Options};

/// CPU time of the calling thread in seconds, if the kernel exposes it.
fn thread_cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(file), Some(tol)) = (args.next(), args.next().and_then(|s| s.parse::<f64>().ok()))
    else {
        eprintln!("usage: discretize_time FILE TOLERANCE [REPS]");
        std::process::exit(2);
    };
    let reps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(3).max(1);
    let defaults = Options::with_tolerance(tol);
    let band: f64 = args
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(defaults.band);
    let doc = match kerf::format::curves::load(&file) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("discretize_time: {e}");
            std::process::exit(1);
        }
    };
    let opts = defaults.with_band(band);
    let cpu = thread_cpu_seconds().is_some();
    let now = || thread_cpu_seconds().unwrap_or(0.0);
    let wall = Instant::now();
    let mut best = f64::INFINITY;
    let mut best_wall = f64::INFINITY;
    let mut points = 0usize;
    let mut segments = 0usize;
    let mut worst = 0.0f64;
    for _ in 0..reps {
        let (c0, w0) = (now(), wall.elapsed().as_secs_f64());
        points = 0;
        segments = 0;
        for r in &doc.curves {
            match discretize(&r.curve, &opts) {
                Ok(d) => {
                    points += d.points().len();
                    segments += d.segments();
                    worst = worst.max(d.max_chord_error());
                }
                Err(e) => {
                    eprintln!("discretize_time: curve {:?}: {e}", r.id);
                    std::process::exit(1);
                }
            }
        }
        best = best.min(now() - c0);
        best_wall = best_wall.min(wall.elapsed().as_secs_f64() - w0);
    }
    let c0 = now();
    let nstar: f64 = doc
        .curves
        .iter()
        .map(|r| minimum_count(&r.curve, tol))
        .sum();
    let nstar_seconds = now() - c0;
    println!(
        "{{\"file\": {file:?}, \"tolerance\": {tol}, \"band\": {band}, \"curves\": {}, \"points\": {points}, \
         \"segments\": {segments}, \"max_chord_error\": {worst}, \"seconds\": {}, \
         \"clock\": \"{}\", \"wall_seconds\": {best_wall}, \"reps\": {reps}, \
         \"n_star\": {nstar}, \"n_star_quadrature_seconds\": {nstar_seconds}}}",
        doc.curves.len(),
        if cpu { best } else { best_wall },
        if cpu { "thread cpu" } else { "wall" },
    );
}
