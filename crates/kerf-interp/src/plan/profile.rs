//! The planning grid of one run (its constraints, held while the run is timed) and the timed
//! profile planned on it: the time-optimal `x(s)`, the time of every grid point, and the jerk
//! filter.

use super::{PlanOptions, ACCELERATION_MARGIN, JERK_CROSS_SHARE, JERK_STATIC_SHARE};
use crate::model::AxisModel;
use crate::smooth::Run;
use crate::topp;

/// The constraints of one run at its grid points (the grid's `s` itself is [`Timed::s`]):
/// 15 numbers a grid point (120 bytes, three times the profile), so the planner holds a run's
/// grid only while it times the run (a refinement rebuilds it).
#[derive(Debug, Clone)]
pub(super) struct RunGrid {
    pub(super) d1: Vec<[f64; 5]>,
    pub(super) d2: Vec<[f64; 5]>,
    /// `|tip'(s)|`.
    pub(super) tip_speed: Vec<f64>,
    /// The cap on `x`: the static cap (velocity, feed, chord, jerk), lowered by refinements.
    pub(super) cap: Vec<f64>,
    /// The maximum velocity curve of the limits alone (no refinement): what the `F` words of
    /// a cutting run say.
    pub(super) static_mv: Vec<f64>,
    /// Factors on the accelerations, set by refinements.
    pub(super) mult_a: Vec<f64>,
}

/// The timed profile of one run: `x`, `u` and the time of each grid point, and the integral of
/// `s dt` for the jerk filter.
#[derive(Debug, Clone)]
pub(super) struct Timed {
    pub(super) s: Vec<f64>,
    pub(super) x: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) t: Vec<f64>,
    /// The integral of `s dt` up to each grid point in two parts (a compensated sum: the value
    /// is `area + area_lo`, to about `eps^2` of it), so that the jerk filter's difference of two
    /// integrals over one window is not lost in their rounding (see [`Timed::s_at`]).
    pub(super) area: Vec<f64>,
    pub(super) area_lo: Vec<f64>,
    /// Filter width, s (0: acceleration-limited).
    pub(super) tau: f64,
    /// Run time, s (the grid's time plus `tau`).
    pub(super) duration: f64,
}

impl Timed {
    pub(super) fn len(&self) -> f64 {
        self.s[self.s.len() - 1]
    }

    /// The interval holding time `t` (`0 <= t < t_N`).
    #[inline]
    pub(super) fn interval(&self, t: f64) -> usize {
        self.t
            .partition_point(|&v| v <= t)
            .clamp(1, self.t.len() - 1)
            - 1
    }

    /// `s` at time `t` of the unfiltered profile.
    #[inline]
    pub(super) fn s_raw(&self, t: f64) -> f64 {
        let n = self.t.len() - 1;
        if t <= 0.0 {
            return 0.0;
        }
        if t >= self.t[n] {
            return self.len();
        }
        let i = self.interval(t);
        let h = t - self.t[i];
        (self.s[i] + self.x[i].sqrt() * h + 0.5 * self.u[i] * h * h).clamp(self.s[i], self.s[i + 1])
    }

    /// `integral of s dt` from 0 to `t` of the unfiltered profile (`s = len` after the end), as
    /// `(big, small)`: the prefix sum at a grid point and the rest (its compensation and the
    /// integral from that grid point to `t`), both exact to rounding of their own size.
    #[inline]
    pub(super) fn area_at(&self, t: f64) -> (f64, f64) {
        let n = self.t.len() - 1;
        if t <= 0.0 {
            return (0.0, 0.0);
        }
        if t >= self.t[n] {
            return (self.area[n], self.area_lo[n] + self.len() * (t - self.t[n]));
        }
        let i = self.interval(t);
        let h = t - self.t[i];
        (
            self.area[i],
            self.area_lo[i] + h * (self.s[i] + h * (0.5 * self.x[i].sqrt() + h * self.u[i] / 6.0)),
        )
    }

    /// `s` at time `t` of the run (filtered when jerk-limited).
    #[inline]
    pub(super) fn s_at(&self, t: f64) -> f64 {
        if t >= self.duration {
            return self.len();
        }
        if self.tau > 0.0 {
            // The two prefix sums are within a window's integral of each other, so their
            // difference is exact (Sterbenz) or nearly; subtracted as one number they lost
            // `eps |area|` (1e-11 mm s on a 200 s run, a jerk of 1e6 mm/s^3 at a 10 us cycle).
            let ((a1, b1), (a0, b0)) = (self.area_at(t), self.area_at(t - self.tau));
            (((a1 - a0) + (b1 - b0)) / self.tau).clamp(0.0, self.len())
        } else {
            self.s_raw(t)
        }
    }

    /// `ds/dt` at time `t`.
    pub(super) fn speed_at(&self, t: f64) -> f64 {
        if t <= 0.0 || t >= self.duration {
            return 0.0;
        }
        if self.tau > 0.0 {
            (self.s_raw(t) - self.s_raw(t - self.tau)) / self.tau
        } else {
            let i = self.interval(t);
            (self.x[i].sqrt() + self.u[i] * (t - self.t[i])).max(0.0)
        }
    }

    /// The earliest time at which `s_at(t) >= s`: exact from the grid when unfiltered (block
    /// starts are grid points), else by bisection in `[t_raw(s), t_raw(s) + tau]` (the average
    /// of `s` over `[t - tau, t]` lies between `s(t - tau)` and `s(t)`).
    pub(super) fn time_of(&self, s: f64) -> f64 {
        if s <= 0.0 {
            return 0.0;
        }
        if s >= self.len() {
            return self.duration;
        }
        let i = self.s.partition_point(|&v| v < s).min(self.s.len() - 1);
        let raw = if self.s[i] == s || i == 0 {
            self.t[i]
        } else {
            // Inside interval i - 1: solve s_i + v tau + u tau^2 / 2 = s by bisection too.
            bisect(self.t[i - 1], self.t[i], 50, 0.0, |tau| {
                self.s_raw(tau) >= s
            })
            .1
        };
        if self.tau <= 0.0 {
            return raw;
        }
        let hi = (raw + self.tau).min(self.duration);
        bisect(raw, hi, 50, 1e-13 * self.duration, |tau| {
            self.s_at(tau) >= s
        })
        .1
    }
}

/// The bracket `(lo, hi)` in `[lo, hi]` of where a monotone `reached` turns true (false at
/// `lo`'s side, true at `hi`'s), by at most `halvings` halvings, stopping once it is `width`
/// wide or less. (A bracket of width 0 no longer changes, so `width` 0 is all the halvings.)
fn bisect(
    mut lo: f64,
    mut hi: f64,
    halvings: usize,
    width: f64,
    reached: impl Fn(f64) -> bool,
) -> (f64, f64) {
    for _ in 0..halvings {
        let mid = 0.5 * (lo + hi);
        if reached(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
        if hi - lo <= width {
            break;
        }
    }
    (lo, hi)
}

/// The grid of one run: nodes subdivided to at most `step`, at least two intervals each, and
/// at every grid point `q'`, `q''` (and `q'''` for the jerk cap) by central differences of the
/// machine axes along the smooth path, with the static caps on `x`: the grid's `s` and its
/// constraints.
pub(super) fn run_grid<M: AxisModel + ?Sized>(
    model: &M,
    run: &Run,
    step: f64,
    opts: &PlanOptions,
) -> (Vec<f64>, RunGrid) {
    let lim = model.limits();
    let mut s = Vec::new();
    for w in run.nodes.windows(2) {
        let h = w[1] - w[0];
        if h <= 0.0 {
            continue;
        }
        let m = ((h / step).ceil() as usize).max(2);
        for k in 0..m {
            s.push(w[0] + h * k as f64 / m as f64);
        }
    }
    s.push(run.len());
    let h = 1e-3f64.min(run.len() * 1e-3);
    let derivs = |si: f64| {
        let q = |d: f64| run.axes_raw(model, si + d);
        let (qm2, qm1, q0, qp1, qp2) = (q(-2.0 * h), q(-h), q(0.0), q(h), q(2.0 * h));
        let a: [f64; 5] = std::array::from_fn(|k| (qp1[k] - qm1[k]) / (2.0 * h));
        let b: [f64; 5] = std::array::from_fn(|k| (qp1[k] - 2.0 * q0[k] + qm1[k]) / (h * h));
        let c: [f64; 5] = std::array::from_fn(|k| {
            (qp2[k] - 2.0 * qp1[k] + 2.0 * qm1[k] - qm2[k]) / (2.0 * h * h * h)
        });
        (a, b, c)
    };
    let mut first: Vec<_> = s.iter().map(|&si| derivs(si)).collect();
    // Where the axes' speeds per unit of s (in units of their limits) change by more than 2 %
    // between grid points, refine: the constraints hold at grid points only.
    let norm = |a: &[f64; 5]| -> [f64; 5] { std::array::from_fn(|k| a[k] / lim.max_velocity[k]) };
    let mut fine_s = Vec::with_capacity(s.len());
    let mut fine_d = Vec::with_capacity(s.len());
    for i in 0..s.len() {
        fine_s.push(s[i]);
        fine_d.push(first[i]);
        if i + 1 == s.len() {
            break;
        }
        let (p, q) = (norm(&first[i].0), norm(&first[i + 1].0));
        let scale = (0..5)
            .map(|k| p[k].abs().max(q[k].abs()))
            .fold(0.0, f64::max);
        let change = (0..5).map(|k| (p[k] - q[k]).abs()).fold(0.0, f64::max);
        if scale > 0.0 && change > 0.02 * scale {
            let m = ((change / (0.02 * scale)).ceil() as usize).min(64);
            for k in 1..m {
                let sk = s[i] + (s[i + 1] - s[i]) * k as f64 / m as f64;
                fine_s.push(sk);
                fine_d.push(derivs(sk));
            }
        }
    }
    first.clear();
    let mut s = fine_s;
    // Kept in the run's profile for the program's life: no room to spare.
    s.shrink_to_fit();
    let n = s.len();
    let mut d1 = Vec::with_capacity(n);
    let mut d2 = Vec::with_capacity(n);
    let mut tip_speed = Vec::with_capacity(n);
    let mut cap = Vec::with_capacity(n);
    let mut static_mv = Vec::with_capacity(n);
    let feed = opts.feed_mm_per_min / 60.0 * run.feed_factor;
    for (&si, &(a, b, c)) in s.iter().zip(&fine_d) {
        let (t1, t2) = run.tip_derivatives(si);
        // A rapid's splines are the machine's axes (`Run::joint`): its tip speed (what its
        // reported peak is made of) by a central difference of the tip through the model.
        let speed = if run.joint {
            let h = 1e-3_f64.min(0.25 * run.len());
            let at = |v: f64| model.tip(&run.axes_raw(model, v));
            (at(si + h) - at(si - h)).norm() / (2.0 * h)
        } else {
            t1.norm()
        };
        let mut x = f64::INFINITY;
        let scale = opts.planned_limit_scale;
        for k in 0..5 {
            if a[k] != 0.0 {
                x = x.min((scale * lim.max_velocity[k] * 0.999 / a[k].abs()).powi(2));
            }
            if let Some(j) = lim.max_jerk {
                if c[k] != 0.0 {
                    x = x.min((scale * JERK_STATIC_SHARE * j[k] / c[k].abs()).powf(2.0 / 3.0));
                }
            }
        }
        if run.moves_tip && speed > 0.0 {
            if run.cutting {
                x = x.min((feed * run.corner_factor(si) / speed).powi(2));
            }
            let kappa = t1.cross(&t2).norm() / speed.powi(3);
            if kappa > 1e-12 {
                let step = (8.0 * opts.chord_tolerance_mm / kappa).sqrt();
                x = x.min((step / opts.cycle_s / speed).powi(2));
            }
        }
        let x = x.min(1e18);
        static_mv.push(topp::xmax(&topp::Point {
            d1: a,
            d2: b,
            acc: lim.max_acceleration.map(|v| v * ACCELERATION_MARGIN),
            cap: x,
            path_acc: f64::INFINITY,
        }));
        d1.push(a);
        d2.push(b);
        tip_speed.push(speed);
        cap.push(x);
    }
    let grid = RunGrid {
        static_mv,
        mult_a: vec![1.0; n],
        d1,
        d2,
        tip_speed,
        cap,
    };
    (s, grid)
}

/// Plans one run on its grid `s` with the constraints `g` (rest to rest) and times it (the
/// profile keeps `s`).
pub(super) fn time_run(
    s: Vec<f64>,
    g: &RunGrid,
    acc: [f64; 5],
    jerk: Option<[f64; 5]>,
    tau: f64,
) -> Timed {
    let n = s.len();
    let mut pts: Vec<topp::Point> = (0..n)
        .map(|i| {
            let cap = g.cap[i];
            let mut path_acc = f64::INFINITY;
            if let Some(j) = jerk {
                let v = cap.sqrt();
                for k in 0..5 {
                    // `|q''|` of the axis: the jerk budget of the path acceleration.
                    let c = 3.0 * g.d2[i][k].abs() * v;
                    if c > 0.0 {
                        path_acc = path_acc.min(JERK_CROSS_SHARE * j[k] / c);
                    }
                }
            }
            topp::Point {
                d1: g.d1[i],
                d2: g.d2[i],
                acc: acc.map(|a| a * ACCELERATION_MARGIN * g.mult_a[i]),
                cap,
                path_acc,
            }
        })
        .collect();
    let mv: Vec<f64> = pts.iter().map(topp::xmax).collect();
    if tau > 0.0 {
        // The moving average sees positions about v tau / 2 either side: lower the maximum
        // velocity curve to its minimum over that reach, the reach measured with the speed of
        // the unfiltered optimum (an upper bound of the final speed, so the reach is not too
        // short; measured with the maximum velocity curve instead, a fast straight would drag
        // the slow junction it leads to far back along itself).
        // The reach's ends by bisection and the minimum from a range-minimum table: a loop
        // over the reach was quadratic where the grid is dense (seconds on a run of 1e-6 mm
        // blocks at a fast feed).
        let (first, _) = topp::solve(&s, &pts);
        let table = RangeMin::new(&mv);
        let mut mv = mv;
        for i in 0..n {
            let w = FILTER_REACH * first[i].sqrt() * tau;
            let lo = s[..i].partition_point(|&v| s[i] - v > w);
            let hi = i + s[i + 1..].partition_point(|&v| v - s[i] <= w);
            mv[i] = table.min(lo, hi);
        }
        for (p, m) in pts.iter_mut().zip(&mv) {
            p.cap = p.cap.min(*m);
        }
    }
    let (mut x, mut u) = topp::solve(&s, &pts);
    if let (Some(j), true) = (jerk, tau > 0.0) {
        // Reversals of the path acceleration (a triangular speed profile: accelerating, then
        // at once braking) get a plateau of at least `tau` at their peak, so that the filter
        // never sees the whole reversal in one window (see `reversal_caps`).
        let caps = reversal_caps(&s, g, &x, &u, j, tau);
        if !caps.is_empty() {
            for (i, c) in caps {
                pts[i].cap = pts[i].cap.min(c);
            }
            (x, u) = topp::solve(&s, &pts);
        }
    }
    let mut t = Vec::with_capacity(n);
    let mut tt = 0.0;
    for i in 0..n {
        t.push(tt);
        if i + 1 < n {
            let d = s[i + 1] - s[i];
            let den = x[i].sqrt() + x[i + 1].sqrt();
            tt += if den > 0.0 {
                2.0 * d / den
            } else {
                f64::INFINITY
            };
        }
    }
    // The integral of `s dt`, each interval over the duration the time grid gives it
    // (`t_{i+1} - t_i`, exact by Sterbenz, not the `dt` that was added: at 200 s the two
    // differ by 4e-14 s, which times `s` = 1e4 mm made the filtered position jump by 4e-8 mm at
    // every grid point, a third difference of 1e7 mm/s^3 at a 10 us cycle), summed with
    // Knuth's two-sum so that `area + area_lo` carries it to about `eps^2`.
    let mut area = Vec::with_capacity(n);
    let mut area_lo = Vec::with_capacity(n);
    let (mut aa, mut lo) = (0.0, 0.0);
    for i in 0..n {
        area.push(aa);
        area_lo.push(lo);
        if i + 1 < n {
            let dt = t[i + 1] - t[i];
            let add = dt * (s[i] + dt * (0.5 * x[i].sqrt() + dt * u[i] / 6.0));
            let sum = aa + add;
            let back = sum - aa;
            lo += (aa - (sum - back)) + (add - back);
            aa = sum;
        }
    }
    Timed {
        s,
        duration: tt + tau,
        x,
        u,
        t,
        area,
        area_lo,
        tau,
    }
}

/// The `F` words of the blocks of `run` (`out[j]` for block `run.first + j`), before the stretches
/// below the programmed feed share their lowest ([`super::assemble::modal_feeds`]): for a
/// cutting block the programmed feed `feed` (mm/s) if the limits allow it somewhere in the
/// block, else the lowest tip speed they allow along it; for any other block its planned peak
/// tip speed. Computed when the run is timed, while its grid is at hand.
pub(super) fn run_feeds(run: &Run, g: &RunGrid, tm: &Timed, feed: f64, out: &mut [f64]) {
    let s = &tm.s;
    for b in run.first..=run.last {
        let j = b - run.first;
        let (s0, s1) = (run.starts[j], run.starts[j + 1]);
        let i0 = s.partition_point(|&v| v < s0);
        let i1 = s.partition_point(|&v| v <= s1).max(i0 + 1).min(s.len());
        let range = i0.min(s.len() - 1)..i1;
        out[j] = if run.cutting && run.moves_tip {
            let speeds = range.map(|i| g.static_mv[i].sqrt() * g.tip_speed[i]);
            let (low, best) =
                speeds.fold((f64::INFINITY, 0.0f64), |(l, h), v| (l.min(v), h.max(v)));
            if best >= feed * 0.999 {
                feed
            } else {
                low
            }
        } else {
            range
                .map(|i| tm.x[i].sqrt() * g.tip_speed[i])
                .fold(0.0, f64::max)
        };
    }
}

/// Caps on `x` that turn every sharp reversal of the path acceleration into a plateau of at
/// least `tau` (`PLATEAU_MARGIN` more), as `(grid point, cap)` pairs.
///
/// The jerk filter is a moving average of width `tau`: its path jerk is
/// `(u(t) - u(t - tau)) / tau` with `u` the unfiltered path acceleration. Where the
/// acceleration-limited optimum accelerates at `+A` and at once brakes at `-A` (a triangle: a
/// straight between two slow junctions), that is `2 A / tau`, 160 % of the jerk at the
/// shipped width; the verification then lowered the accelerations over the whole straight
/// (the slot's peak went from 520 to 420 mm/s). A plateau of duration `tau` at the peak,
/// `x <= x_c`, takes the reversal in two steps of `A` each in separate windows, within the
/// jerk, at the cost of a lower peak: the largest `x_c` whose plateau (the grid points with
/// `x >= x_c`, where the capped profile has `u = 0`) lasts `tau` at speed `sqrt(x_c)`, found by
/// bisection (the plateau's length only shrinks as `x_c` grows). The time lost is about
/// `tau / 2` per reversal; the time-optimal jerk-limited reversal takes `2 A / J = 1.6 tau`
/// against the filter's `2 tau`.
///
/// A reversal is flagged when the acceleration falls by more than the jerk allows in one
/// window, `J_path tau` with `J_path = min_k J_k / |q'_k|` at the peak, within less than `tau`
/// from the last accelerating to the first braking interval. Valleys need nothing here: they lie
/// on minima of the maximum velocity curve, which the filter's reach already flattened.
fn reversal_caps(
    s: &[f64],
    g: &RunGrid,
    x: &[f64],
    u: &[f64],
    jerk: [f64; 5],
    tau: f64,
) -> Vec<(usize, f64)> {
    let n = x.len();
    let dt = |i: usize| {
        let den = x[i].sqrt() + x[i + 1].sqrt();
        if den > 0.0 {
            2.0 * (s[i + 1] - s[i]) / den
        } else {
            f64::INFINITY
        }
    };
    let umax = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if umax <= 0.0 {
        return Vec::new();
    }
    let tol = 1e-6 * umax;
    let mut caps = Vec::new();
    let mut i = 0;
    while i + 1 < n {
        // Interval i accelerates; find the next interval that does not.
        if u[i] <= tol {
            i += 1;
            continue;
        }
        let mut a = i;
        while a + 1 < n - 1 && u[a + 1] > tol {
            a += 1;
        }
        // Grid point a + 1 ends the acceleration; the first braking interval after it.
        let mut b = a + 1;
        let mut gap = 0.0;
        while b < n - 1 && u[b] >= -tol {
            gap += dt(b);
            b += 1;
        }
        if b >= n - 1 || gap >= tau {
            i = b.max(a + 1);
            continue;
        }
        let peak = a + 1;
        let jp = (0..5)
            .filter(|&k| g.d1[peak][k].abs() > 1e-9)
            .map(|k| jerk[k] / g.d1[peak][k].abs())
            .fold(f64::INFINITY, f64::min);
        if u[a] - u[b] <= jp * tau {
            i = b;
            continue;
        }
        // The plateau of a cap c: the grid points around the peak with x >= c.
        let top = (a + 1..=b).fold(a + 1, |m, k| if x[k] > x[m] { k } else { m });
        let plateau = |c: f64| {
            let mut lo = top;
            while lo > 0 && x[lo - 1] >= c {
                lo -= 1;
            }
            let mut hi = top;
            while hi + 1 < n && x[hi + 1] >= c {
                hi += 1;
            }
            (lo, hi)
        };
        let lasts = |c: f64| {
            let (lo, hi) = plateau(c);
            c > 0.0 && (s[hi] - s[lo]) >= PLATEAU_MARGIN * tau * c.sqrt()
        };
        if lasts(x[top]) {
            i = b;
            continue;
        }
        // The largest cap that still lasts.
        let (lo_c, _) = bisect(0.0, x[top], 60, 0.0, |c| !lasts(c));
        if lo_c > 0.0 {
            let (p0, p1) = plateau(lo_c);
            caps.extend((p0..=p1).map(|k| (k, lo_c)));
        }
        i = b;
    }
    caps
}

/// How far either side the filtered speed at a point sees the unfiltered one, in `v tau`: the
/// moving average over `[t - tau, t]` is at about `s(t - tau / 2)` and averages the speeds of
/// `s +- v tau / 2`; 10 % more covers the speed's change over the window (measured on the
/// fixtures: 0.6 cost the 40 x 10 slot 1.3 % more at 40 m/min, 0.5 let the jerk over at its
/// junctions, and the refinement that corrected it cost more than 0.55 did).
pub(super) const FILTER_REACH: f64 = 0.55;
/// The plateau at a reversal lasts this many filter widths (grid error margin).
const PLATEAU_MARGIN: f64 = 1.05;

/// Minima of any index range of a sequence in `O(1)` after `O(n log n)` set-up: row `k` holds
/// the minimum of each window of `2^k` values, and a range is covered by two such windows.
struct RangeMin {
    rows: Vec<Vec<f64>>,
}

impl RangeMin {
    fn new(v: &[f64]) -> Self {
        let mut rows = vec![v.to_vec()];
        let mut width = 1;
        while 2 * width <= v.len() {
            let prev = &rows[rows.len() - 1];
            let next: Vec<f64> = (0..=v.len() - 2 * width)
                .map(|i| prev[i].min(prev[i + width]))
                .collect();
            rows.push(next);
            width *= 2;
        }
        Self { rows }
    }

    /// The minimum of `v[lo..=hi]` (`lo <= hi < v.len()`).
    fn min(&self, lo: usize, hi: usize) -> f64 {
        let k = (usize::BITS - 1 - (hi - lo + 1).leading_zeros()) as usize;
        self.rows[k][lo].min(self.rows[k][hi + 1 - (1 << k)])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_filtered_position_keeps_its_precision_on_a_long_run() {
        // A 20 m straight at 50 mm/s (400 s): the filter's `s` is the difference of two integrals
        // of about 1e6 mm s over a window of 12.5 ms. Subtracted as one number each, or summed
        // over `dt`s that the time grid rounds differently, their rounding made the filtered
        // position jump by 4e-8 mm at grid points: third differences of 1.5e7 mm/s^3 at a 10 us
        // cycle (measured). Now they stay at the rounding of `s` itself (one ulp of 1e4 mm,
        // 1.8e-12 mm, is 1.5e4 mm/s^3 in a third difference at 10 us; measured 1.3e4).
        let len = 20_000.0;
        let n = 40_001;
        let s: Vec<f64> = (0..n).map(|i| len * i as f64 / (n - 1) as f64).collect();
        let g = RunGrid {
            d1: vec![[1.0, 0.0, 0.0, 0.0, 0.0]; n],
            d2: vec![[0.0; 5]; n],
            tip_speed: vec![1.0; n],
            cap: vec![2500.0; n],
            static_mv: vec![2500.0; n],
            mult_a: vec![1.0; n],
        };
        let tau = 0.0125;
        let tm = time_run(s, &g, [5000.0; 5], Some([1e6; 5]), tau);
        let t = 1e-5;
        let mid = 0.5 * tm.duration;
        let mut worst = 0.0f64;
        for i in 0..1000 {
            let at = |k: f64| tm.s_at(mid + (i as f64 + k) * t);
            let j = (at(1.0) - 3.0 * at(0.0) + 3.0 * at(-1.0) - at(-2.0)) / (t * t * t);
            worst = worst.max(j.abs());
        }
        println!("cruise third difference {worst:e} mm/s^3 at t = {mid} s");
        assert!(worst < 1e5, "{worst:e}");
    }

    #[test]
    fn range_minima_match_a_scan() {
        // Every range of a sequence with repeats and no order, against a plain scan.
        let v: Vec<f64> = (0..77).map(|i| ((i * 37 % 23) as f64).sin()).collect();
        let table = super::RangeMin::new(&v);
        for lo in 0..v.len() {
            for hi in lo..v.len() {
                let want = v[lo..=hi].iter().copied().fold(f64::INFINITY, f64::min);
                assert_eq!(table.min(lo, hi), want, "{lo}..={hi}");
            }
        }
    }
}
