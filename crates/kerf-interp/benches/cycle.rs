//! Per-cycle cost of the interpolator: what a controller computes every cycle.
//!
//! - `program`: one set-point of a planned 5-axis program (locate the run, the path parameter
//!   from the time-optimal profile, tip and rotary axes on the run's splines, paper 000 eq 16
//!   for the linear axes).
//! - `program-arcs-machine-file`: the same on `fixtures/machines/ac_head.json` through
//!   kerf-kinematics (`MachineModel`).
//! - `recurrence`: one step of paper 001's recursive spline in 5 coordinates (three-term form
//!   and Reinsch form), and of forward differences of a cubic, for comparison.
//!
//! Throughput is in cycles, so criterion reports the time per cycle.
//! Run: `cargo bench -p kerf-interp --features research --bench cycle -- --warm-up-time 1 --measurement-time 2`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kerf_interp::{fit_blocks, plan, solve_stations, FitOptions, PaperAcHead, PlanOptions};
use kerf_interp::{CubicHermite, NewBasisSegment, Recurrence};
use nalgebra::{Point3, Vector3};

fn program(c: &mut Criterion) {
    let m = PaperAcHead::paper_000();
    // A 3D wave with a varying tool axis: 2001 cutting points over about 400 mm.
    let tips: Vec<Point3<f64>> = (0..=2000)
        .map(|i| {
            let t = i as f64 * 0.2;
            Point3::new(t, 30.0 * (t / 25.0).sin(), 10.0 * (t / 40.0).cos())
        })
        .collect();
    let axes: Vec<Vector3<f64>> = tips
        .iter()
        .map(|p| Vector3::new(0.3 * (p.x / 60.0).sin(), 0.2, 1.0).normalize())
        .collect();
    let st = solve_stations(&m, &tips, Some(&axes), None, None).expect("reachable");
    let mut group = c.benchmark_group("cycle");
    for (name, arcs) in [("program-arcs", true), ("program-lines", false)] {
        let blocks = fit_blocks(
            &m,
            &st,
            None,
            0,
            &FitOptions::default()
                .with_arcs(arcs)
                .with_tolerance_mm(0.005),
        )
        .expect("fit");
        let motion = plan(&m, &blocks, &PlanOptions::new(10000.0, 0.001)).expect("plan");
        group.throughput(Throughput::Elements(motion.cycles() as u64 + 1));
        group.bench_function(name, |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for q in motion.iter(&m) {
                    acc += q[0] + q[4];
                }
                black_box(acc)
            })
        });
    }
    // The same program on the ac-head machine file through kerf-kinematics.
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/machines/ac_head.json"
    );
    let mm = kerf_interp::MachineModel::new(kerf_kinematics::Machine::read(file).expect("machine"))
        .expect("limits");
    let blocks = fit_blocks(
        &mm,
        &st,
        None,
        0,
        &FitOptions::default().with_tolerance_mm(0.005),
    )
    .expect("fit");
    let motion = plan(&mm, &blocks, &PlanOptions::new(10000.0, 0.001)).expect("plan");
    group.throughput(Throughput::Elements(motion.cycles() as u64 + 1));
    group.bench_function("program-arcs-machine-file", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for q in motion.iter(&mm) {
                acc += q[0] + q[4];
            }
            black_box(acc)
        })
    });
    let q0 = [1200.0, -800.0, 300.0, 10.0, 45.0];
    let q1 = [3900.0, 1500.0, -200.0, 35.0, 120.0];
    let d0 = [2500.0, 2600.0, -300.0, 20.0, 60.0];
    let d1 = [2900.0, 1900.0, -800.0, 30.0, 90.0];
    let nb = NewBasisSegment::hermite(q0, q1, d0, d1);
    let cu = CubicHermite::hermite(q0, q1, d0, d1);
    let n = 5000;
    group.throughput(Throughput::Elements(n as u64 + 1));
    for kind in [Recurrence::ThreeTerm, Recurrence::Reinsch] {
        group.bench_with_input(
            BenchmarkId::new("recurrence", format!("{kind:?}")),
            &kind,
            |b, &kind| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for v in nb.steps(n, kind) {
                        acc += v[0] + v[4];
                    }
                    black_box(acc)
                })
            },
        );
    }
    group.bench_function("forward-differences", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for v in cu.forward_differences(n) {
                acc += v[0] + v[4];
            }
            black_box(acc)
        })
    });
    group.finish();
}

criterion_group!(benches, program);
criterion_main!(benches);
