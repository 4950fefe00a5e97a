//! Discretizes every curve of a `kerf.curves/1` file on one thread and prints the segments,
//! `segments / N*` (the walk's estimate), the evaluations per segment (counted: the
//! dev-dependencies build `kerf-nurbs` with `eval-counter`) and the thread CPU time. A quick
//! measure of the walk's work while changing it; the benchmark of record is
//! `benches/discretize_vs_occt.py` (the counter costs a little time here).
//!
//! Run: `cargo run --release -p kerf-discretize --example file_work -- FILE TOLERANCE`

use kerf_discretize::{discretize, Options};

fn thread_cpu_seconds() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

fn main() {
    let mut args = std::env::args().skip(1);
    let (Some(file), Some(tol)) = (args.next(), args.next().and_then(|s| s.parse::<f64>().ok()))
    else {
        eprintln!("usage: file_work FILE TOLERANCE");
        std::process::exit(2);
    };
    let doc = kerf_format::curves::load(&file).unwrap_or_else(|e| {
        eprintln!("file_work: {e}");
        std::process::exit(1);
    });
    let opts = Options::with_tolerance(tol);
    let c0 = thread_cpu_seconds();
    let (mut segments, mut nstar, mut worst) = (0usize, 0.0f64, 0.0f64);
    let (_, evals) = kerf_nurbs::counted(|| {
        for r in &doc.curves {
            let d = discretize(&r.curve, &opts).unwrap_or_else(|e| {
                eprintln!("file_work: curve {:?}: {e}", r.id);
                std::process::exit(1);
            });
            segments += d.segments();
            nstar += d.n_star(tol);
            worst = worst.max(d.max_chord_error());
        }
    });
    let seconds = thread_cpu_seconds() - c0;
    let per = evals.map_or(f64::NAN, |e| e as f64 / segments as f64);
    println!(
        "{} curves, tol {tol}: {segments} segments, {:.4} N*, {per:.2} evaluations/segment, \
         max bound {worst:e}, {seconds:.3} s thread CPU",
        doc.curves.len(),
        segments as f64 / nstar
    );
}
