//! Normals per second (NURBS sphere and a ~100k-triangle mesh) and inverse kinematics per
//! second (each machine type), with seeded inputs.
//!
//! Run: `cargo bench --bench normals_kinematics`

use std::f64::consts::PI;
use std::path::Path;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use kerf::kinematics::{solve_path, Machine, PathInput, PathOptions, Pose};
use kerf::normals::{Hint, MeshNormals, NormalSource, NurbsNormals};
use nalgebra::Point3;

/// Points on a latitude band of the sphere of radius `r` around the origin, in path order.
fn band_points(r: f64, n: usize) -> Vec<Point3<f64>> {
    (0..n)
        .map(|i| {
            let s = i as f64 / n as f64;
            let (lon, lat) = (2.0 * PI * s, 0.6 + 0.2 * (7.0 * PI * s).sin());
            Point3::new(
                r * lat.cos() * lon.cos(),
                r * lat.cos() * lon.sin(),
                r * lat.sin(),
            )
        })
        .collect()
}

/// A UV sphere mesh with `2 * m * (m / 2)` triangles (STL-like: outward winding).
fn sphere_mesh(r: f64, m: usize) -> (Vec<Point3<f64>>, Vec<[u32; 3]>) {
    let rings = m / 2;
    let mut v = Vec::new();
    for j in 0..=rings {
        let lat = -PI / 2.0 + PI * j as f64 / rings as f64;
        for i in 0..m {
            let lon = 2.0 * PI * i as f64 / m as f64;
            v.push(Point3::new(
                r * lat.cos() * lon.cos(),
                r * lat.cos() * lon.sin(),
                r * lat.sin(),
            ));
        }
    }
    let idx = |i: usize, j: usize| (j * m + i % m) as u32;
    let mut t = Vec::new();
    for j in 0..rings {
        for i in 0..m {
            t.push([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)]);
            t.push([idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]);
        }
    }
    (v, t)
}

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let dome = kerf::format::curves::load(root.join("dome.json")).expect("fixture loads");
    let kerf::format::SurfaceGeometry::Nurbs(sphere) = &dome.surfaces[0].geometry else {
        panic!("the dome is a NURBS sphere");
    };
    let nurbs = NurbsNormals::new(sphere.clone(), false);
    let pts = band_points(100.0, 2000);
    let mut g = c.benchmark_group("normals");
    g.sample_size(10);
    g.throughput(Throughput::Elements(pts.len() as u64));
    g.bench_function("nurbs_sphere_warm_path", |b| {
        b.iter(|| {
            let mut hint = Hint::None;
            let mut acc = 0.0;
            for p in &pts {
                let pr = nurbs.project(p, hint);
                hint = pr.hint;
                acc += pr.normal.map_or(0.0, |n| n.z);
            }
            acc
        })
    });
    let (v, t) = sphere_mesh(100.0, 316);
    let mesh = MeshNormals::new(v, t, 30.0, false).expect("mesh builds");
    g.bench_function(
        BenchmarkId::new("mesh_sphere", mesh.triangle_count()),
        |b| {
            b.iter(|| {
                pts.iter()
                    .map(|p| mesh.project(p, Hint::None).normal.map_or(0.0, |n| n.z))
                    .sum::<f64>()
            })
        },
    );
    g.finish();

    let poses: Vec<Pose> = band_points(1.0, 4096)
        .iter()
        .enumerate()
        .map(|(i, a)| Pose::new(i as f64 * 0.1, 5.0, 20.0, a.x, a.y, a.z))
        .collect();
    let mut g = c.benchmark_group("inverse_kinematics");
    g.throughput(Throughput::Elements(poses.len() as u64));
    for m in ["ac_head", "fork_head", "table_table", "head_table"] {
        let machine = Machine::read(root.join(format!("machines/{m}.json"))).expect("machine");
        let k = machine.kinematics.clone();
        g.bench_function(m, |b| {
            b.iter(|| poses.iter().map(|p| k.inverse(p)[0].c).sum::<f64>())
        });
    }
    g.finish();

    // Whole paths: a 10,000-point helix with the tool tilting outward, default options
    // (continuity, limits lifted, non-linearity insertion).
    let helix: Vec<Pose> = (0..10_000)
        .map(|k| {
            let th = (k as f64 * 0.2).to_radians();
            let tilt = (30.0 + 10.0 * (5.0 * th).sin()).to_radians();
            Pose::new(
                300.0 * th.cos(),
                300.0 * th.sin(),
                0.01 * k as f64,
                tilt.sin() * th.cos(),
                tilt.sin() * th.sin(),
                tilt.cos(),
            )
        })
        .collect();
    let mut g = c.benchmark_group("solve_path");
    g.sample_size(10);
    g.throughput(Throughput::Elements(helix.len() as u64));
    for m in ["ac_head", "fork_head", "table_table", "head_table"] {
        let mut machine = Machine::read(root.join(format!("machines/{m}.json"))).expect("machine");
        machine.limits = [None; 5];
        let input = PathInput {
            id: "helix",
            poses: &helix,
            curve: None,
        };
        g.bench_function(m, |b| {
            b.iter(|| {
                solve_path(&machine, &input, &PathOptions::default())
                    .expect("solves")
                    .inserted
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
