//! Discretizer throughput: cutting points per second over a tolerance sweep, on seeded random
//! cubic and quintic curves, single thread and rayon batch.
//!
//! Run: `cargo bench --bench discretize`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kerf::discretize::{discretize, discretize_all, Options};
use kerf::nurbs::NurbsCurve;
use nalgebra::Point3;

fn smooth_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    let mut s = seed;
    let mut rnd = move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let n = degree + 1 + 8;
            let pts: Vec<Point3<f64>> = (0..n)
                .map(|i| Point3::new(20.0 * i as f64 + 10.0 * rnd(), 60.0 * rnd(), 20.0 * rnd()))
                .collect();
            let mut knots = vec![0.0; degree + 1];
            let inner = n - degree - 1;
            knots.extend((1..=inner).map(|i| i as f64 / (inner + 1) as f64));
            knots.extend(vec![1.0; degree + 1]);
            NurbsCurve::new(degree, knots, pts, None)
        })
        .collect()
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
                .map(|c| discretize(c, &opts).expect("discretizes").points.len())
                .sum();
            group.throughput(Throughput::Elements(points as u64));
            group.bench_with_input(BenchmarkId::new("single", tol), &opts, |b, o| {
                b.iter(|| {
                    curves
                        .iter()
                        .map(|c| discretize(c, o).expect("discretizes").points.len())
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
                .map(|d| d.expect("discretizes").points.len())
                .sum();
            group.throughput(Throughput::Elements(points as u64));
            group.bench_with_input(BenchmarkId::new("single", tol), &opts, |b, o| {
                b.iter(|| {
                    curves
                        .iter()
                        .map(|c| discretize(c, o).expect("discretizes").points.len())
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
