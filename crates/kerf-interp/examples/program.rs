//! Block counts and program cycle times on test curves: cutting points from kerf-discretize,
//! blocks from the arc fit (or one line per chord), the feed plan on paper 000's machine.
//!
//! Run: `cargo run --release -p kerf-interp --example program`

use kerf_discretize::{discretize, Options};
use kerf_interp::{
    fit_blocks, plan, solve_stations, BlockCounts, FitOptions, PaperAcHead, PlanOptions,
};
use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};

fn circle(r: f64) -> NurbsCurve {
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let sq = [
        (1., 0.),
        (1., 1.),
        (0., 1.),
        (-1., 1.),
        (-1., 0.),
        (-1., -1.),
        (0., -1.),
        (1., -1.),
        (1., 0.),
    ];
    let pts = sq
        .iter()
        .map(|(x, y)| Point3::new(r * x, r * y, 0.0))
        .collect();
    let w = (0..9).map(|i| if i % 2 == 0 { 1.0 } else { h }).collect();
    NurbsCurve::new(
        2,
        vec![0., 0., 0., 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1., 1., 1.],
        pts,
        Some(w),
    )
}

fn freeform() -> NurbsCurve {
    let pts = vec![
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(40.0, 60.0, 10.0),
        Point3::new(80.0, -30.0, 25.0),
        Point3::new(110.0, 40.0, 40.0),
        Point3::new(140.0, 90.0, 20.0),
        Point3::new(170.0, 20.0, 0.0),
        Point3::new(185.0, -20.0, 15.0),
        Point3::new(200.0, 10.0, 30.0),
    ];
    NurbsCurve::new(
        3,
        vec![0., 0., 0., 0., 0.2, 0.4, 0.55, 0.8, 1., 1., 1., 1.],
        pts,
        None,
    )
}

type AxisOf = fn(&Point3<f64>) -> Vector3<f64>;

fn main() {
    let m = PaperAcHead::paper_000();
    let up: AxisOf = |_| Vector3::z();
    let tilted: AxisOf =
        |p| Vector3::new(0.4 * (p.x / 40.0).sin(), 0.3 * (p.y / 25.0).cos(), 1.0).normalize();
    let cases: [(&str, NurbsCurve, AxisOf); 4] = [
        ("circle r50, tool vertical", circle(50.0), up),
        ("circle r5, tool vertical", circle(5.0), up),
        ("free-form 3D, tool vertical", freeform(), up),
        ("free-form 3D, tool axis varying", freeform(), tilted),
    ];
    let (feed, cycle, tol) = (15000.0, 0.001, 0.001);
    println!(
        "F = {feed} mm/min, T = {} ms, tolerance {tol} mm, machine: {}\n",
        cycle * 1000.0,
        m.name
    );
    println!("| path | points | blocks | cycles (continuous) | cycles (block ends on cycles) |");
    println!("|---|---:|---|---:|---:|");
    for (name, c, axis_of) in cases {
        let d = discretize(&c, &Options::with_tolerance(tol)).expect("discretize");
        let axes: Vec<Vector3<f64>> = d.points().iter().map(axis_of).collect();
        let st =
            solve_stations(&m, d.points(), Some(&axes), Some(d.params()), None).expect("reachable");
        let curve = |t: f64| c.point(t);
        let fits = [
            (
                "one line per chord",
                FitOptions::with_tolerance(tol)
                    .with_arcs(false)
                    .with_merge_lines(false),
            ),
            ("arc fit", FitOptions::with_tolerance(tol)),
        ];
        for (how, opts) in fits {
            let blocks = fit_blocks(&m, &st, Some(&curve), 0, &opts).expect("fit");
            let n = BlockCounts::of(&blocks);
            let cont = plan(&m, &blocks, &PlanOptions::new(feed, cycle)).expect("plan");
            let exact = plan(
                &m,
                &blocks,
                &PlanOptions::new(feed, cycle).with_block_ends_on_cycles(true),
            )
            .expect("plan");
            println!(
                "| {name} ({how}) | {} | {} lines, {} arcs | {} | {} |",
                st.len(),
                n.lines,
                n.arcs,
                cont.cycles(),
                exact.cycles()
            );
        }
    }
}
