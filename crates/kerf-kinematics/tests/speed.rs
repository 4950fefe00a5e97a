//! Rough throughput figures (not a benchmark; the criterion benches live elsewhere). Ignored by
//! default; run with `cargo test -p kerf-kinematics --release --test speed -- --ignored
//! --nocapture`.

mod common;

use std::hint::black_box;
use std::time::Instant;

use common::{fixture, polar};
use kerf_kinematics::{solve_path, PathInput, PathOptions, Pose};
use nalgebra::Point3;

#[test]
#[ignore = "timing, run by hand in release"]
fn throughput() {
    for file in [
        "ac_head.json",
        "fork_head.json",
        "table_table.json",
        "head_table.json",
    ] {
        let mut machine = fixture(file);
        machine.limits = [None; 5]; // the helix turns C through 2000 degrees
        let kin = machine.kinematics.as_ref();
        let poses: Vec<Pose> = (0..1000)
            .map(|k| {
                let t = k as f64 * 0.01;
                Pose {
                    position: Point3::new(t.cos() * 50.0, t.sin() * 50.0, t),
                    axis: polar(0.2 + 0.5 * t.sin().abs(), 3.0 * t),
                }
            })
            .collect();
        let rounds = 2000;
        let start = Instant::now();
        let mut acc = 0.0;
        for _ in 0..rounds {
            for p in &poses {
                let [a, b] = kin.inverse(black_box(p));
                acc += a.x + b.c;
            }
        }
        let inv = (rounds * poses.len()) as f64 / start.elapsed().as_secs_f64();
        let start = Instant::now();
        for _ in 0..rounds {
            for p in &poses {
                acc += kin.forward(&kin.inverse(black_box(p))[0]).position.x;
            }
        }
        let fwd_inv = (rounds * poses.len()) as f64 / start.elapsed().as_secs_f64();
        // A 10 000-point helix with the tool tilting outward, default options.
        let helix: Vec<Pose> = (0..10_000)
            .map(|k| {
                let th = (k as f64 * 0.2).to_radians();
                Pose {
                    position: Point3::new(300.0 * th.cos(), 300.0 * th.sin(), 0.01 * k as f64),
                    axis: polar((30.0 + 10.0 * (5.0 * th).sin()).to_radians(), th),
                }
            })
            .collect();
        let start = Instant::now();
        let path = solve_path(
            &machine,
            &PathInput {
                id: "helix",
                poses: &helix,
                curve: None,
            },
            &PathOptions::default(),
        )
        .unwrap();
        let solve = helix.len() as f64 / start.elapsed().as_secs_f64();
        println!(
            "{file}: inverse (both solutions) {:.1} M/s, inverse+forward {:.1} M/s, solve_path {:.0} k cutting points/s ({} inserted) [{acc:.0}]",
            inv / 1e6,
            fwd_inv / 1e6,
            solve / 1e3,
            path.inserted
        );
    }
}
