//! Helpers shared by the traverse tests.

#![allow(dead_code)] // each test file uses its own subset

use kerf_process::Pose;
use nalgebra::Point3;

/// The smallest of `distance` over a dense sampling of a route: the tip's polyline through the
/// waypoints every 0.05 mm (of tip travel plus the nozzle end's sweep where the axis turns),
/// and at each tip position the nozzle along the normalised interpolated axis at
/// `nozzle_samples + 1` points.
pub(crate) fn dense_min(
    way: &[Pose],
    nozzle: f64,
    nozzle_samples: u32,
    distance: &dyn Fn(&Point3<f64>) -> f64,
) -> f64 {
    let mut least = f64::INFINITY;
    for w in way.windows(2) {
        let (a, b) = (w[0].position, w[1].position);
        let (na, nb) = (w[0].axis, w[1].axis);
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
