//! The certificate of a straight move: sphere tracing along the tip and the nozzle.

use nalgebra::Point3;

use super::Obstacles;
use crate::geometry::{normal, position};
use crate::PoseArray;

/// Why a stretch of a traverse is not clear: the first offending sample.
#[derive(Debug, Clone, Copy)]
pub(super) struct Blocked {
    pub(super) at: Point3<f64>,
    pub(super) distance: f64,
}

/// Certifies the straight move `a -> b` (the tool axis turning as the normalised linear
/// interpolation of `a`'s and `b`'s): every point of the tip's segment and of the nozzle (from
/// the tip `nozzle` mm along the axis) keeps at least `need` from the surfaces. Returns the
/// smallest distance measured, or the first point closer than `need + floor`.
///
/// Sphere tracing with the 1-Lipschitz distance: along the nozzle at offset `s` with distance
/// `e`, the next sample is `(e - need) / 2` further, so over each stretch the distance is at
/// least `(e + need) / 2`, and the whole nozzle at this tip position at least `m`, the smallest
/// of those. A point of the swept surface at interpolation parameter `f + df` lies within
/// `df (|b - a| + nozzle |n_b - n_a| / cos(theta / 2))` of the one at `f` (the normalised
/// interpolation turns at most that fast, `theta` the angle between the axes), so the tip
/// advances by `df` with that distance equal to `m - need`.
pub(super) fn certify(
    obs: &Obstacles,
    a: &PoseArray,
    b: &PoseArray,
    need: f64,
    nozzle: f64,
    floor: f64,
) -> std::result::Result<f64, Blocked> {
    let (pa, pb) = (position(a), position(b));
    let (na, nb) = (normal(a).normalize(), normal(b).normalize());
    let half_cos = (0.5 * (1.0 + na.dot(&nb))).max(0.0).sqrt().max(0.05);
    let speed = (pb - pa).norm() + nozzle * (nb - na).norm() / half_cos;
    let limit = need + 2.0 * floor.max(need / 4.0) + 0.25 * nozzle;
    let mut least = f64::INFINITY;
    let mut f = 0.0_f64;
    loop {
        let p = pa + (pb - pa) * f;
        let n = (na * (1.0 - f) + nb * f)
            .try_normalize(1e-12)
            .unwrap_or(if f < 0.5 { na } else { nb });
        // The nozzle at this tip position.
        let mut m = f64::INFINITY;
        let mut s = 0.0_f64;
        loop {
            let q = p + n * s;
            let e = obs.distance_below(&q, limit);
            least = least.min(e);
            if e < need + floor {
                return Err(Blocked { at: q, distance: e });
            }
            let ds = 0.5 * (e - need);
            m = m.min(e - ds);
            if s >= nozzle {
                break;
            }
            s = (s + ds).min(nozzle);
        }
        if f >= 1.0 || speed == 0.0 {
            return Ok(least);
        }
        f = (f + (m - need) / speed).min(1.0);
    }
}

/// Certifies a machine's move given as the poses of its tip and tool axis sampled along it
/// (e.g. the tip and axis of the machine axes interpolated between two solved waypoints,
/// closely spaced, workpiece frame): the tip and the nozzle (`nozzle_mm` along the axis) on
/// the straight moves between consecutive samples keep `need_mm` from the surfaces. Returns
/// the smallest distance measured.
///
/// The bound covers the polyline through the samples; the machine's own path between two
/// samples departs from it by the second order of their spacing, which the caller keeps small
/// (or adds to `need_mm`).
///
/// # Errors
/// `Err((point, distance))` for the first point closer than `need_mm` plus a hundredth of it.
pub fn check_move(
    obs: &Obstacles,
    samples: &[PoseArray],
    need_mm: f64,
    nozzle_mm: f64,
) -> std::result::Result<f64, (Point3<f64>, f64)> {
    let floor = need_mm.abs() / 100.0 + 1e-6;
    let mut least = f64::INFINITY;
    for w in samples.windows(2) {
        least = least.min(
            certify(obs, &w[0], &w[1], need_mm, nozzle_mm, floor)
                .map_err(|b| (b.at, b.distance))?,
        );
    }
    Ok(least)
}
