//! Discretizer throughput: cutting points per second over a tolerance sweep, on seeded random
//! cubic and quintic curves, single thread and rayon batch.
//!
//! Run: `cargo bench --bench discretize`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kerf::discretize::{discretize, discretize_all, Options};
use kerf::nurbs::NurbsCurve;

fn smooth_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    kerf::nurbs::smooth_random_curves(degree, count, seed)
}

fn bench(c: &mut Criterion) {
    for degree in [3usize, 5] {
        let curves = smooth_curves(degree, 64, 42 + degree as u64);
        let mut group = c.benchmark_group(format!("discretize/degree{degree}"));
        group.sample_size(10);
        for tol in [0.1, 0.01, 0.001] {
            let opts = Options::with_tolerance(tol);
            let points: usize = curves
                .iter()
                .map(|c| discretize(c, &opts).expect("discretizes").points().len())
                .sum();
            group.throughput(Throughput::Elements(points as u64));
            group.bench_with_input(BenchmarkId::new("single", tol), &opts, |b, o| {
                b.iter(|| {
                    curves
                        .iter()
                        .map(|c| discretize(c, o).expect("discretizes").points().len())
                        .sum::<usize>()
                })
            });
            group.bench_with_input(BenchmarkId::new("rayon", tol), &opts, |b, o| {
                b.iter(|| discretize_all(&curves, o).len())
            });
        }
        group.finish();
    }
    // The real parts of fixtures/realdata, all curves as one batch.
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/realdata");
    for file in ["nori_sheetmetal.json", "occt_propeller.json"] {
        let doc = kerf::format::curves::load(root.join(file)).expect("fixture loads");
        let curves: Vec<NurbsCurve> = doc.curves.into_iter().map(|r| r.curve).collect();
        let mut group = c.benchmark_group(format!("discretize/{file}"));
        group.sample_size(10);
        for tol in [0.1, 0.01, 0.001] {
            let opts = Options::with_tolerance(tol);
            let points: usize = discretize_all(&curves, &opts)
                .into_iter()
                .map(|d| d.expect("discretizes").points().len())
                .sum();
            group.throughput(Throughput::Elements(points as u64));
            group.bench_with_input(BenchmarkId::new("single", tol), &opts, |b, o| {
                b.iter(|| {
                    curves
                        .iter()
                        .map(|c| discretize(c, o).expect("discretizes").points().len())
                        .sum::<usize>()
                })
            });
            group.bench_with_input(BenchmarkId::new("rayon", tol), &opts, |b, o| {
                b.iter(|| discretize_all(&curves, o).len())
            });
        }
        group.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
