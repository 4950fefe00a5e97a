//! Planning cost: `plan()` on a 10,000-pose path (fit excluded), the target being well
//! under a second on one core.
//!
//! - `lines`: one line per pose (the generic dialect's fit), acceleration-limited;
//! - `arcs`: fitted arcs (the Sinumerik fit), acceleration-limited;
//! - `lines-jerk`: one line per pose with the machine file's jerk limits.
//!
//! On `fixtures/machines/ac_head.json` through kerf-kinematics, at 20 m/min, 1 ms cycle.
//! Run: `cargo bench -p kerf-interp --bench plan -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use kerf_interp::{fit_blocks, plan, solve_stations, FitOptions, MachineModel, PlanOptions};
use nalgebra::{Point3, Vector3};

fn planning(c: &mut Criterion) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/machines/ac_head.json"
    );
    let machine = kerf_kinematics::Machine::read(path).expect("machine");
    let jerk = MachineModel::new(machine.clone()).expect("model");
    let plain = MachineModel::new(machine.with_max_jerk(None).expect("valid")).expect("model");
    // A 3D wave with a varying tool axis: 10,000 poses 0.2 mm apart (2 m).
    let tips: Vec<Point3<f64>> = (0..10_000)
        .map(|i| {
            let t = i as f64 * 0.2;
            Point3::new(t - 1000.0, 30.0 * (t / 25.0).sin(), 10.0 * (t / 40.0).cos())
        })
        .collect();
    let axes: Vec<Vector3<f64>> = tips
        .iter()
        .map(|p| Vector3::new(0.3 * (p.x / 60.0).sin(), 0.2, 1.0).normalize())
        .collect();
    let st = solve_stations(&plain, &tips, Some(&axes), None, None).expect("reachable");
    let fit = |arcs: bool| {
        fit_blocks(
            &plain,
            &st,
            None,
            0,
            &FitOptions::default()
                .with_arcs(arcs)
                .with_merge_lines(arcs)
                .with_tolerance_mm(0.005),
        )
        .expect("fit")
    };
    let (lines, arcs) = (fit(false), fit(true));
    let opts = PlanOptions::new(20000.0, 0.001);
    let mut group = c.benchmark_group("plan-10000-poses");
    group.sample_size(10);
    for (name, model, blocks) in [
        ("lines", &plain, &lines),
        ("arcs", &plain, &arcs),
        ("lines-jerk", &jerk, &lines),
    ] {
        let m = plan(model, blocks, &opts).expect("plan");
        eprintln!(
            "{name}: {} blocks, {} runs, {} grid points, {} refinements, {:.3} s planned",
            blocks.len(),
            m.runs(),
            m.grid_points(),
            m.refinements(),
            m.duration()
        );
        group.bench_function(name, |b| {
            b.iter(|| black_box(plan(model, blocks, &opts).expect("plan").duration()))
        });
    }
    group.finish();
}

criterion_group!(benches, planning);
criterion_main!(benches);
