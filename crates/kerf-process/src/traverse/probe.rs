//! A quick look for a point of a route closer than the clearance before the route is traced:
//! a route on which one is measured cannot be certified, so its trace (the costly part of a
//! gap whose shorter routes run into the part) waits until its outcome is needed.
//!
//! The argument: [`Trace::certify`] passes a move only if every point of its swept surface
//! (tip and nozzle) keeps the need, by the 1-Lipschitz bound on its samples' distances. A
//! point `q` of that surface with a measured distance `e(q)` below the need less a small
//! tolerance (below) is therefore a point the certificate cannot cover: the move fails,
//! whatever its samples. Points are found two ways, both measured:
//!
//! - *known points*: every point measured closer than the need near the gap (by the probes
//!   below, or the blockage of a route already traced), with its distance `e(x)`; a point `q`
//!   of the move's swept surface with `|q - x| + e(x)` below the need is closer than the need
//!   (the distance is 1-Lipschitz: `d(q) <= d(x) + |q - x|`, and `e(x)` is the distance to a
//!   point of a surface, at least `d(x)`), without a query;
//! - *probes*: the swept surface sampled on a grid (at most the need apart along the move, as
//!   the trace measures the move's speed, and along the nozzle), coarse to fine, until one
//!   sample is closer than the need or the grid is done.
//!
//! Neither decides that a route clears: a route with no such point is traced as before.

use nalgebra::Point3;

use super::check::Trace;
use super::Obstacles;
use crate::Pose;

/// Below the need by at least this (mm): far above the rounding of positions and distances
/// (about 1e-12 mm at a metre), so the certificate's own rounding cannot pass such a point.
const TOLERANCE_MM: f64 = 1e-6;

/// Most probes of one move's grid (past them the move is traced without more looking).
const MOVE_PROBES: usize = 1 << 10;

/// The points measured closer than the need near one gap, and the probes of its routes.
pub(super) struct Probe<'a> {
    obs: &'a Obstacles,
    need: f64,
    nozzle: f64,
    /// Points measured closer than the need, with their distance.
    known: Vec<(Point3<f64>, f64)>,
}

impl<'a> Probe<'a> {
    /// The probe of moves of the tip and nozzle (`nozzle` mm long) that must keep `need` from
    /// `obs`.
    pub(super) fn new(obs: &'a Obstacles, need: f64, nozzle: f64) -> Self {
        Self {
            obs,
            need,
            nozzle,
            known: Vec::new(),
        }
    }

    /// Keeps `at`, measured `distance` from the part, if that is closer than the need.
    pub(super) fn learn(&mut self, at: Point3<f64>, distance: f64) {
        if distance < self.need - TOLERANCE_MM {
            self.known.push((at, distance));
        }
    }

    /// True if a point of the move `a -> b`'s swept surface is measured closer than the need
    /// (by a known point or a probe; each probe is one distance query). False says nothing.
    pub(super) fn violated(&mut self, a: &Pose, b: &Pose) -> bool {
        let trace = Trace::new(self.obs, a, b, self.need, self.nozzle);
        // Beyond this the trace's argument may not cover the surface (a turn of the axis by
        // nearly half a turn): no point is looked for there.
        let until = trace.covered_until();
        let limit = self.need - TOLERANCE_MM;
        // A known point near the swept surface: the surface point nearest to it along the tip's
        // segment and then the nozzle (any point of the surface gives a bound).
        let (pa, pb) = (trace.point(0.0, 0.0), trace.point(1.0, 0.0));
        let ab = pb - pa;
        for &(x, e) in &self.known {
            let f = if ab.norm_squared() > 0.0 {
                ((x - pa).dot(&ab) / ab.norm_squared()).clamp(0.0, until)
            } else {
                0.0
            };
            let tip = trace.point(f, 0.0);
            let axis = trace.point(f, 1.0) - tip;
            let s = (x - tip).dot(&axis).clamp(0.0, self.nozzle.max(0.0));
            if (trace.point(f, s) - x).norm() + e < limit {
                return true;
            }
        }
        // The grid, coarse to fine: along the move at most the need apart (the swept surface
        // moves at most `speed` per unit of the parameter), along the nozzle as much.
        let steps = |len: f64| -> usize {
            let n = (len / self.need.max(1e-9)).ceil();
            if n.is_finite() && n >= 1.0 {
                (n as usize).min(1 << 20).next_power_of_two()
            } else {
                1
            }
        };
        let (nf, ns) = (steps(until * trace.speed()), steps(self.nozzle));
        let mut probes = 0;
        for fi in coarse_to_fine(nf) {
            for si in coarse_to_fine(ns) {
                if probes == MOVE_PROBES {
                    return false;
                }
                probes += 1;
                let (f, s) = (
                    until * fi as f64 / nf as f64,
                    self.nozzle.max(0.0) * si as f64 / ns as f64,
                );
                let q = trace.point(f, s);
                let e = self.obs.distance_below(&q, self.need);
                if e < limit {
                    self.known.push((q, e));
                    return true;
                }
            }
        }
        false
    }
}

/// `0..=n` (`n` a power of two) coarse to fine: the ends, the middle, the quarters, ...
fn coarse_to_fine(n: usize) -> impl Iterator<Item = usize> {
    let levels = n.trailing_zeros();
    [0, n]
        .into_iter()
        .take(if n == 0 { 1 } else { 2 })
        .chain((1..=levels).flat_map(move |l| {
            let step = n >> l;
            (0..1usize << (l - 1)).map(move |k| step * (2 * k + 1))
        }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coarse_to_fine_visits_every_grid_point_once() {
        for n in [1usize, 2, 4, 8, 64] {
            let mut v: Vec<usize> = coarse_to_fine(n).collect();
            assert_eq!(v[..2], [0, n]);
            v.sort_unstable();
            assert_eq!(v, (0..=n).collect::<Vec<_>>(), "{n}");
        }
    }
}
