//! Helpers shared by the traverse tests.

#![allow(dead_code)] // each test file uses its own subset

use kerf_process::PoseArray;
use nalgebra::{Point3, Vector3};

/// The smallest of `distance` over a dense sampling of a route: the tip's polyline through the
/// waypoints every 0.05 mm (of tip travel plus the nozzle end's sweep where the axis turns),
/// and at each tip position the nozzle along the normalised interpolated axis at
/// `nozzle_samples + 1` points.
pub(crate) fn dense_min(
    way: &[PoseArray],
    nozzle: f64,
    nozzle_samples: u32,
    distance: &dyn Fn(&Point3<f64>) -> f64,
) -> f64 {
    let mut least = f64::INFINITY;
    for w in way.windows(2) {
        let (a, b) = (
            Point3::new(w[0][0], w[0][1], w[0][2]),
            Point3::new(w[1][0], w[1][1], w[1][2]),
        );
        let (na, nb) = (
            Vector3::new(w[0][3], w[0][4], w[0][5]),
            Vector3::new(w[1][3], w[1][4], w[1][5]),
        );
        let turn = (nb - na).norm() * nozzle;
        let k = (((b - a).norm() + turn) / 0.05).ceil().max(1.0) as usize;
        for j in 0..=k {
            let f = j as f64 / k as f64;
            let p = a + (b - a) * f;
            let n = (na * (1.0 - f) + nb * f).normalize();
            for s in 0..=nozzle_samples {
                let q = p + n * (nozzle * f64::from(s) / f64::from(nozzle_samples));
                least = least.min(distance(&q));
            }
        }
    }
    least
}
