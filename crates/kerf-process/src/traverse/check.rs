//! The certificate of a straight move: sphere tracing along the tip and the nozzle.

use nalgebra::{Point3, Vector3};

use super::Obstacles;
use crate::Pose;

/// Why a stretch of a traverse is not clear: the first offending sample.
#[derive(Debug, Clone, Copy)]
pub(super) struct Blocked {
    pub(super) at: Point3<f64>,
    pub(super) distance: f64,
    /// True if the work budget ran out before the stretch was decided (then `at` and
    /// `distance` are the closest sample so far, which keeps the need plus the margin).
    pub(super) exhausted: bool,
    /// Where along the move (interpolation parameter, 0 to 1) and along the nozzle (mm from
    /// the tip) the sample was taken.
    pub(super) f: f64,
    pub(super) s: f64,
}

impl Blocked {
    /// A blockage at `at`, `distance` from the part, not tied to a move's parameters.
    pub(super) fn at(at: Point3<f64>, distance: f64) -> Self {
        Self {
            at,
            distance,
            exhausted: false,
            f: 0.0,
            s: 0.0,
        }
    }

    /// True if the stretch failed only within the margin: the offending sample keeps the
    /// need (it is not closer than the clearance), so a finer margin may prove the stretch.
    pub(super) fn within_margin(&self, need: f64) -> bool {
        !self.exhausted && self.distance >= need
    }
}

/// A counted work budget: how many more distance samples the checks may take. Every sample
/// of [`Trace::certify`] spends one, so no loop outlives it, whatever rounding does to the steps.
#[derive(Debug, Clone, Copy)]
pub(super) struct Work {
    pub(super) left: usize,
}

impl Work {
    /// A budget of `samples` distance samples.
    pub(super) fn new(samples: usize) -> Self {
        Self { left: samples }
    }
}

/// Samples one straight move may take with the coarse margin (a guard against hostile input:
/// a 1,000 mm move along a surface just outside the margin takes about 2.5e5).
pub(super) const MOVE_SAMPLES: usize = 1 << 21;

/// The finest margin [`Trace::prove`] goes down to, as a fraction of the need: a stretch whose
/// closest sample comes within this of the need stays unproven.
pub(super) const FINEST_MARGIN: f64 = 1.0 / 4096.0;

/// The least `cos(theta / 2)` the swept surface's speed takes (`theta` the angle between the
/// move's tool axes): beyond a turn of about 174 degrees the speed is that of a 174-degree turn,
/// which is less than the interpolated axis' true speed near the middle of the move.
const LEAST_HALF_COS: f64 = 0.05;

/// One straight move `a -> b` of the tip and the nozzle (`nozzle` mm from the tip along the
/// tool axis, which turns as the normalised linear interpolation of `a`'s and `b`'s), to be
/// kept `need` from the surfaces of `obs`.
pub(super) struct Trace<'a> {
    obs: &'a Obstacles,
    pa: Point3<f64>,
    pb: Point3<f64>,
    na: Vector3<f64>,
    nb: Vector3<f64>,
    need: f64,
    nozzle: f64,
    /// How fast a point of the swept surface moves with the interpolation parameter, at most.
    speed: f64,
}

impl<'a> Trace<'a> {
    /// The move `a -> b` with its nozzle, kept `need` from `obs`.
    pub(super) fn new(obs: &'a Obstacles, a: &Pose, b: &Pose, need: f64, nozzle: f64) -> Self {
        let (pa, pb) = (a.position, b.position);
        let (na, nb) = (a.axis.normalize(), b.axis.normalize());
        let half_cos = (0.5 * (1.0 + na.dot(&nb)))
            .max(0.0)
            .sqrt()
            .max(LEAST_HALF_COS);
        let speed = (pb - pa).norm() + nozzle * (nb - na).norm() / half_cos;
        Self {
            obs,
            pa,
            pb,
            na,
            nb,
            need,
            nozzle,
            speed,
        }
    }

    /// The point of the swept surface at interpolation parameter `f` and nozzle offset `s`.
    pub(super) fn point(&self, f: f64, s: f64) -> Point3<f64> {
        let n = (self.na * (1.0 - f) + self.nb * f)
            .try_normalize(1e-12)
            .unwrap_or(if f < 0.5 { self.na } else { self.nb });
        self.pa + (self.pb - self.pa) * f + n * s
    }

    /// How fast a point of the swept surface moves with the interpolation parameter, at most
    /// (mm per unit of it).
    pub(super) fn speed(&self) -> f64 {
        self.speed
    }

    /// How far along the move (interpolation parameter) [`Trace::speed`] bounds the speed of
    /// every point of the swept surface, so that [`Trace::certify`] passes the move only if
    /// every point of [`Trace::point`]'s surface up to there keeps the need: 1 where the tool
    /// axis turns by less than about 173 degrees; for a larger turn, up to where the
    /// interpolated axis, whose length `|m(f)|` falls to `cos(theta / 2)` at the middle,
    /// is still `1.2` times the speed's least half-cosine long (a larger turn is traced with
    /// the speed of a 174-degree one, and the axis `m / |m|` turns at `|n_b - n_a| / |m|`, so
    /// near the middle the trace steps over parts of the nozzle's sweep). The samples before
    /// `f` all lie in `[0, f]`, where the bound holds, so the trace's argument covers it.
    pub(super) fn covered_until(&self) -> f64 {
        let h = 1.2 * LEAST_HALF_COS;
        let c = self.na.dot(&self.nb);
        // |m(f)|^2 = 1 - 2 f (1 - f) (1 - c), falling on [0, 1/2].
        let r = (1.0 - h * h) / (2.0 * (1.0 - c));
        if !(r.is_finite() && (0.0..0.25).contains(&r)) {
            return 1.0;
        }
        0.5 * (1.0 - (1.0 - 4.0 * r).sqrt())
    }

    /// Certifies the move: every point of the tip's segment and of the nozzle keeps at least
    /// `need` from the surfaces. Returns the smallest distance measured, or the first point
    /// closer than `need + floor`, or the closest sample so far when `work` runs out (each
    /// sample spends one).
    ///
    /// Sphere tracing with the 1-Lipschitz distance: along the nozzle at offset `s` with
    /// distance `e`, the next sample is `(e - need) / 2` further, so over each stretch the
    /// distance is at least `(e + need) / 2`, and the whole nozzle at this tip position at
    /// least `m`, the smallest of those. A point of the swept surface at interpolation
    /// parameter `f + df` lies within `df (|b - a| + nozzle |n_b - n_a| / cos(theta / 2))` of
    /// the one at `f` (the normalised interpolation turns at most that fast, `theta` the angle
    /// between the axes), so the tip advances by `df` with that distance equal to `m - need`.
    pub(super) fn certify(&self, floor: f64, work: &mut Work) -> std::result::Result<f64, Blocked> {
        let need = self.need;
        let limit = need + 2.0 * floor.max(need / 4.0) + 0.25 * self.nozzle;
        let mut least = f64::INFINITY;
        let mut closest = (self.pa, 0.0, 0.0);
        let mut f = 0.0_f64;
        loop {
            // The nozzle at this tip position.
            let mut m = f64::INFINITY;
            let mut s = 0.0_f64;
            loop {
                let q = self.point(f, s);
                let e = self.obs.distance_below(&q, limit);
                if e < least {
                    least = e;
                    closest = (q, f, s);
                }
                if e < need + floor {
                    return Err(Blocked {
                        at: q,
                        distance: e,
                        exhausted: false,
                        f,
                        s,
                    });
                }
                if work.left == 0 {
                    // Undecided: the closest sample so far.
                    return Err(Blocked {
                        at: closest.0,
                        distance: least,
                        exhausted: true,
                        f: closest.1,
                        s: closest.2,
                    });
                }
                work.left -= 1;
                let ds = 0.5 * (e - need);
                m = m.min(e - ds);
                if s >= self.nozzle {
                    break;
                }
                s = (s + ds).min(self.nozzle);
            }
            if f >= 1.0 || self.speed == 0.0 {
                return Ok(least);
            }
            f = (f + (m - need) / self.speed).min(1.0);
        }
    }

    /// Sphere tracing slows down as it nears a point closer than the need (the steps are
    /// half the excess), so a move that runs into the part ends on a sample just outside the
    /// margin, like one that keeps the need by a hair. Where [`Trace::certify`] stopped within
    /// the margin (at `stall`), this looks for a *witness* ahead of the stall: samples of the
    /// swept surface `delta` further along the move and along the nozzle, `delta` doubling
    /// from the stall's excess over the need (at least [`FINEST_MARGIN`] of the need: the
    /// distance is 1-Lipschitz, so nothing nearer can be closer than the need) to twice the
    /// need (each spending one of `work`). A sample closer than the need is a measured
    /// violation: the move is blocked, whatever the margin. Returns the closest sample of the
    /// first doubling that holds one, or `None` if none is found.
    pub(super) fn witness(&self, stall: &Blocked, work: &mut Work) -> Option<Blocked> {
        let need = self.need;
        let limit = need.abs() + 1.0;
        let mut found: Option<Blocked> = None;
        let mut delta = (stall.distance - need).max(need.abs() * FINEST_MARGIN + 1e-9);
        while delta <= 2.0 * need.abs() + 1e-9 {
            let df = if self.speed > 0.0 {
                delta / self.speed
            } else {
                0.0
            };
            for (f, s) in [
                (stall.f + df, stall.s),
                (stall.f, stall.s + delta),
                (stall.f, stall.s - delta),
                (stall.f + df, stall.s + delta),
                (stall.f + df, stall.s - delta),
            ] {
                if work.left == 0 {
                    return found;
                }
                work.left -= 1;
                let (f, s) = (f.clamp(0.0, 1.0), s.clamp(0.0, self.nozzle.max(0.0)));
                let q = self.point(f, s);
                let e = self.obs.distance_below(&q, limit);
                if e < need && found.is_none_or(|w| e < w.distance) {
                    found = Some(Blocked {
                        at: q,
                        distance: e,
                        exhausted: false,
                        f,
                        s,
                    });
                }
            }
            if found.is_some() {
                return found;
            }
            delta *= 2.0;
        }
        found
    }

    /// [`Trace::certify`], and where it stopped within the margin, a [`Trace::witness`]
    /// closer than the need (then that is the blockage).
    pub(super) fn certify_or_witness(
        &self,
        floor: f64,
        work: &mut Work,
    ) -> std::result::Result<f64, Blocked> {
        self.certify(floor, work).map_err(|bad| {
            if bad.within_margin(self.need) {
                self.witness(&bad, work).unwrap_or(bad)
            } else {
                bad
            }
        })
    }

    /// [`Trace::certify_or_witness`] with the margin `floor`, and where the move fails only
    /// within that margin (its offending sample keeps the need and no witness closer than the
    /// need was found ahead), again with the margin halved below that sample's excess
    /// (`(distance - need) / 2`), down to [`FINEST_MARGIN`] of the need, all within `work`.
    /// The claim stays the need: a sample closer than it blocks at once.
    pub(super) fn prove(&self, floor: f64, work: &mut Work) -> std::result::Result<f64, Blocked> {
        let finest = self.need.abs() * FINEST_MARGIN + 1e-9;
        let mut floor = floor;
        loop {
            match self.certify_or_witness(floor, work) {
                Err(bad) if bad.within_margin(self.need) && floor > finest => {
                    floor = (0.5 * (bad.distance - self.need))
                        .min(0.5 * floor)
                        .max(finest);
                }
                done => return done,
            }
        }
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
/// Each stretch is traced with a margin of a hundredth of `need_mm` first; where the trace
/// stops within it (its sample keeps `need_mm`), samples ahead of the stop look for one closer
/// than `need_mm` (a measured violation), and without one the stretch is traced again with
/// finer margins, down to 1/4096 of the need, within a counted budget of samples.
///
/// # Errors
/// `Err((point, distance))` for the first point closer than `need_mm` plus the margin it was
/// last traced with (a distance below `need_mm` is a measured violation; one above it was
/// not decided within the finest margin or the budget).
pub fn check_move(
    obs: &Obstacles,
    samples: &[Pose],
    need_mm: f64,
    nozzle_mm: f64,
) -> std::result::Result<f64, (Point3<f64>, f64)> {
    let floor = need_mm.abs() / 100.0 + 1e-6;
    let mut least = f64::INFINITY;
    let mut work = Work::new(MOVE_SAMPLES.max(256 * samples.len()));
    for w in samples.windows(2) {
        least = least.min(
            Trace::new(obs, &w[0], &w[1], need_mm, nozzle_mm)
                .prove(floor, &mut work)
                .map_err(|b| (b.at, b.distance))?,
        );
    }
    Ok(least)
}
