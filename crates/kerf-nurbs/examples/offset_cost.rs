//! What the offset of a free-form surface costs and how tight its proven bound is, for
//! docs/step.md and docs/performance.md:
//!
//! ```sh
//! cargo run --release -p kerf-nurbs --example offset_cost
//! ```
//!
//! A bicubic height field (the one of `tests/offset.rs`) offset by 3 mm within 1e-4 mm: cells,
//! the proven bounds and the largest distance and angle a 241 x 241 sampling finds against
//! `S + d n` at the same parameters; then the time per certified cell by degree (polynomial
//! and rational single patches, wall clock on a possibly shared machine) beside a cold closest
//! point on the same surface.

use std::time::Instant;

use kerf_nurbs::{NurbsSurface, SurfaceOffsetOptions};
use nalgebra::Point3;

fn main() {
    let z = [
        [0.0, 12.0, -6.0, 3.0],
        [8.0, -4.0, 15.0, 0.0],
        [-5.0, 10.0, 2.0, 9.0],
        [4.0, -8.0, 6.0, -2.0],
    ];
    let net: Vec<Vec<Point3<f64>>> = (0..4)
        .map(|i| {
            (0..4)
                .map(|j| Point3::new(100.0 * i as f64 / 3.0, 80.0 * j as f64 / 3.0, z[i][j]))
                .collect()
        })
        .collect();
    let k = || vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let s = NurbsSurface::try_new(3, 3, k(), k(), net, None).expect("patch");
    let o = s
        .offset(3.0, &SurfaceOffsetOptions::new(1e-4))
        .expect("certified");
    let (mut worst, mut worst_angle) = (0.0_f64, 0.0_f64);
    for i in 0..=240 {
        for j in 0..=240 {
            let (u, v) = (i as f64 / 240.0, j as f64 / 240.0);
            let (p, su, sv) = s.eval_d1(u, v);
            let n = su.cross(&sv).normalize();
            worst = worst.max((o.surface.point(u, v) - (p + n * 3.0)).norm());
            let a = o.surface.normal(u, v).expect("regular");
            worst_angle = worst_angle.max(a.cross(&n).norm().atan2(a.dot(&n)));
        }
    }
    println!(
        "height field, d = 3 mm, tolerance 1e-4 mm: {} cells ({} certified), bound {:.3e} mm (sampled {:.3e}, ratio {:.2}), normals {:.3e} rad (sampled {:.3e})",
        o.cells,
        o.cells_certified,
        o.position_bound_mm,
        worst,
        o.position_bound_mm / worst,
        o.normal_bound_rad,
        worst_angle
    );
    for (deg, rational) in [
        (3usize, false),
        (5, false),
        (7, false),
        (3, true),
        (5, true),
    ] {
        let n = deg + 1;
        let mut k = vec![0.0; n];
        k.extend(vec![1.0; n]);
        let net: Vec<Vec<Point3<f64>>> = (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        Point3::new(
                            20.0 * i as f64,
                            20.0 * j as f64,
                            ((i * 7 + j * 3) % 5) as f64 * 2.0,
                        )
                    })
                    .collect()
            })
            .collect();
        let w: Option<Vec<Vec<f64>>> = rational.then(|| {
            (0..n)
                .map(|i| (0..n).map(|j| 1.0 + 0.2 * ((i + j) % 3) as f64).collect())
                .collect()
        });
        let s = NurbsSurface::try_new(deg, deg, k.clone(), k, net, w).expect("patch");
        let t = Instant::now();
        let mut far = 0.0;
        for i in 0..2000 {
            let q = Point3::new(
                20.0 * deg as f64 * (i as f64 / 2000.0),
                30.0,
                5.0 + (i % 7) as f64,
            );
            far += s.closest_point(&q, None).distance;
        }
        let projection = t.elapsed().as_secs_f64() / 2000.0;
        let t = Instant::now();
        let o = s
            .offset(
                1.0,
                &SurfaceOffsetOptions::new(1e-4).with_max_work(1_000_000),
            )
            .expect("certified");
        let spent = t.elapsed().as_secs_f64();
        println!(
            "degree {deg}{}: {} cells certified (work {}), {:.2} ms a cell; a cold closest point {:.3} ms (checksum {far:.1})",
            if rational { " rational" } else { "" },
            o.cells_certified,
            o.work,
            1e3 * spent / o.cells_certified as f64,
            1e3 * projection
        );
    }
}
