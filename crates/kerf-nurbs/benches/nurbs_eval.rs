//! NURBS curve evaluation: kerf against curvo on the same curves.
//!
//! Three operations (the point; the point with first and second derivatives; curvature) on
//! seeded random rational curves of degree 2, 3 and 5 with 10 and 1,000 control points
//! (clamped uniform knots, weights in `[0.5, 2]`). Each iteration evaluates 1,024 seeded random
//! parameters, so the per-call cost (span search included) is what is measured; criterion
//! reports it per evaluation through `Throughput::Elements`. A fourth group evaluates points
//! along a sorted sweep, where curvo's `evaluator()` skips the span search.
//!
//! Both libraries get the same data: kerf through `NurbsCurve::try_new` with weights, curvo
//! through `NurbsCurve3D::try_new` with homogeneous control points `(w x, w y, w z, w)`
//! converted through arrays (curvo is built on its own nalgebra version). Before timing, the
//! two are checked to agree on every parameter, so both do the same work.
//!
//! Run: `cargo bench --bench nurbs_eval -- --warm-up-time 1 --measurement-time 2`, or
//! `KERF_EVAL_TABLE=300 cargo bench --bench nurbs_eval` for a markdown table of the fastest of
//! 300 alternating batches (robust on a loaded machine). `docs/performance.md` has the figures.

use std::hint::black_box;

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use curvo::prelude::NurbsCurve3D;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

/// Parameters evaluated per iteration.
const PARAMS: usize = 1024;

/// A 64-bit linear congruential generator (Knuth's MMIX constants) giving `f64` in `[0, 1)`.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One benchmark case: the same rational curve for both libraries and the parameters.
struct Case {
    label: String,
    degree: usize,
    points: usize,
    kerf: NurbsCurve,
    curvo: NurbsCurve3D<f64>,
    /// Seeded random parameters in the domain.
    params: Vec<f64>,
    /// The same, sorted (a forward sweep).
    sorted: Vec<f64>,
}

fn case(degree: usize, n: usize, seed: u64) -> Case {
    let mut rng = Lcg(seed);
    let points: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            [
                i as f64 + rng.next(),
                20.0 * rng.next() - 10.0,
                20.0 * rng.next() - 10.0,
            ]
        })
        .collect();
    let weights: Vec<f64> = (0..n).map(|_| 0.5 + 1.5 * rng.next()).collect();
    let spans = n - degree;
    let mut knots = vec![0.0; degree + 1];
    knots.extend((1..spans).map(|i| i as f64));
    knots.extend(vec![spans as f64; degree + 1]);
    let params: Vec<f64> = (0..PARAMS).map(|_| spans as f64 * rng.next()).collect();

    let kerf = NurbsCurve::try_new(
        degree,
        knots.clone(),
        points
            .iter()
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect(),
        Some(weights.clone()),
    )
    .expect("valid curve");
    let homogeneous = points
        .iter()
        .zip(&weights)
        .map(|(p, &w)| [p[0] * w, p[1] * w, p[2] * w, w].into())
        .collect();
    let curvo = NurbsCurve3D::try_new(degree, homogeneous, knots).expect("valid curvo curve");
    let mut sorted = params.clone();
    sorted.sort_by(f64::total_cmp);
    let case = Case {
        label: format!("p{degree}_n{n}"),
        degree,
        points: n,
        kerf,
        curvo,
        params,
        sorted,
    };
    check_agreement(&case);
    case
}

/// Both libraries evaluate the same curve: points, derivatives and curvature agree.
fn check_agreement(case: &Case) {
    let scale = case.kerf.size();
    for &t in &case.params {
        let p = case.kerf.point(t);
        let q = case.curvo.point_at(t);
        let dp = (p.x - q[0]).abs() + (p.y - q[1]).abs() + (p.z - q[2]).abs();
        assert!(dp <= 1e-12 * scale, "{}: points differ at {t}", case.label);
        let (_, d1, d2) = case.kerf.eval_d2(t);
        let e = case.curvo.rational_derivatives(t, 2);
        for (k, (dk, ek)) in [d1, d2].iter().zip(&e[1..]).enumerate() {
            let diff = (dk.x - ek[0]).abs() + (dk.y - ek[1]).abs() + (dk.z - ek[2]).abs();
            assert!(
                diff <= 1e-9 * (dk.norm() + scale),
                "{}: derivative {} differs at {t}",
                case.label,
                k + 1
            );
        }
        let k1 = case.kerf.curvature(t);
        let k2 = case.curvo.curvature_at(t).expect("regular").kappa();
        assert!(
            (k1 - k2).abs() <= 1e-9 * k1.max(1e-9),
            "{}: curvature differs at {t}",
            case.label
        );
    }
}

/// What one benchmark row evaluates.
#[derive(Clone, Copy)]
enum Op {
    /// `C(t)` at the random parameters.
    Point,
    /// `C, C', C''` at the random parameters.
    PointD2,
    /// Curvature at the random parameters.
    Curvature,
    /// `C(t)` along the sorted parameters (curvo: its span-caching `evaluator()`).
    Sweep,
}

impl Op {
    const ALL: [Op; 4] = [Op::Point, Op::PointD2, Op::Curvature, Op::Sweep];

    fn group(self) -> &'static str {
        match self {
            Op::Point => "point",
            Op::PointD2 => "point_d2",
            Op::Curvature => "curvature",
            Op::Sweep => "point_sweep",
        }
    }

    fn curvo_name(self) -> &'static str {
        match self {
            Op::Sweep => "curvo_evaluator",
            _ => "curvo",
        }
    }
}

/// One iteration of `op` with kerf: all `PARAMS` parameters. Each loop is a function of its
/// own (not inlined), for kerf and curvo alike, so that neither library's loop is laid out or
/// optimised differently because of the others.
fn run_kerf(op: Op, case: &Case) -> f64 {
    match op {
        Op::Point => kerf_point(&case.kerf, &case.params),
        Op::PointD2 => kerf_point_d2(&case.kerf, &case.params),
        Op::Curvature => kerf_curvature(&case.kerf, &case.params),
        Op::Sweep => kerf_point(&case.kerf, &case.sorted),
    }
}

/// One iteration of `op` with curvo: all `PARAMS` parameters.
fn run_curvo(op: Op, case: &Case) -> f64 {
    match op {
        Op::Point => curvo_point(&case.curvo, &case.params),
        Op::PointD2 => curvo_point_d2(&case.curvo, &case.params),
        Op::Curvature => curvo_curvature(&case.curvo, &case.params),
        Op::Sweep => curvo_sweep(&case.curvo, &case.sorted),
    }
}

#[inline(never)]
fn kerf_point(curve: &NurbsCurve, ts: &[f64]) -> f64 {
    let mut acc = 0.0;
    for &t in ts {
        let p = curve.point(black_box(t));
        acc += p.x + p.y + p.z;
    }
    acc
}

#[inline(never)]
fn kerf_point_d2(curve: &NurbsCurve, ts: &[f64]) -> f64 {
    // black_box on the whole result: summing a few components would let the compiler drop
    // the work for the others.
    for &t in ts {
        black_box(curve.eval_d2(black_box(t)));
    }
    0.0
}

#[inline(never)]
fn kerf_curvature(curve: &NurbsCurve, ts: &[f64]) -> f64 {
    let mut acc = 0.0;
    for &t in ts {
        acc += curve.curvature(black_box(t));
    }
    acc
}

#[inline(never)]
fn curvo_point(curve: &NurbsCurve3D<f64>, ts: &[f64]) -> f64 {
    let mut acc = 0.0;
    for &t in ts {
        let p = curve.point_at(black_box(t));
        acc += p[0] + p[1] + p[2];
    }
    acc
}

#[inline(never)]
fn curvo_point_d2(curve: &NurbsCurve3D<f64>, ts: &[f64]) -> f64 {
    for &t in ts {
        black_box(curve.rational_derivatives(black_box(t), 2));
    }
    0.0
}

#[inline(never)]
fn curvo_curvature(curve: &NurbsCurve3D<f64>, ts: &[f64]) -> f64 {
    let mut acc = 0.0;
    for &t in ts {
        acc += curve.curvature_at(black_box(t)).map_or(0.0, |k| k.kappa());
    }
    acc
}

#[inline(never)]
fn curvo_sweep(curve: &NurbsCurve3D<f64>, ts: &[f64]) -> f64 {
    let mut ev = curve.evaluator();
    let mut acc = 0.0;
    for &t in ts {
        let p = ev.point_at(black_box(t));
        acc += p[0] + p[1] + p[2];
    }
    acc
}

fn cases() -> Vec<Case> {
    [2usize, 3, 5]
        .into_iter()
        .flat_map(|p| [10usize, 1000].map(move |n| (p, n)))
        .enumerate()
        .map(|(i, (p, n))| case(p, n, 0x5eed_0000 + i as u64))
        .collect()
}

fn bench(c: &mut Criterion) {
    let cases = cases();
    for op in Op::ALL {
        let mut group = c.benchmark_group(op.group());
        group.throughput(Throughput::Elements(PARAMS as u64));
        for case in &cases {
            group.bench_with_input(BenchmarkId::new("kerf", &case.label), case, |b, case| {
                b.iter(|| run_kerf(op, case))
            });
            group.bench_with_input(
                BenchmarkId::new(op.curvo_name(), &case.label),
                case,
                |b, case| b.iter(|| run_curvo(op, case)),
            );
        }
        group.finish();
    }
}

/// `KERF_EVAL_TABLE=<batches>`: instead of criterion, time `batches` single iterations of
/// kerf and curvo alternately for every row and print the fastest and the median batch in
/// ns per evaluation as a markdown table. On a shared machine the fastest batch is the one
/// least disturbed by other processes, which makes the ratio reproducible where criterion's
/// means drift with the load.
fn table(batches: usize) {
    println!("| operation | degree | points | kerf ns/eval (min / median) | curvo ns/eval (min / median) | curvo / kerf (min) |");
    println!("|---|---|---|---|---|---|");
    let cases = cases();
    for op in Op::ALL {
        for case in &cases {
            let time = |f: &dyn Fn() -> f64| {
                let start = std::time::Instant::now();
                black_box(f());
                start.elapsed().as_nanos() as f64 / PARAMS as f64
            };
            let (mut k, mut c) = (Vec::new(), Vec::new());
            for _ in 0..batches {
                k.push(time(&|| run_kerf(op, case)));
                c.push(time(&|| run_curvo(op, case)));
            }
            k.sort_by(f64::total_cmp);
            c.sort_by(f64::total_cmp);
            println!(
                "| {} | {} | {} | {:.1} / {:.1} | {:.1} / {:.1} | {:.2} |",
                op.group(),
                case.degree,
                case.points,
                k[0],
                k[batches / 2],
                c[0],
                c[batches / 2],
                c[0] / k[0]
            );
        }
    }
}

criterion_group!(benches, bench);

fn main() {
    if let Some(batches) = std::env::var("KERF_EVAL_TABLE")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        table(batches.max(1));
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
