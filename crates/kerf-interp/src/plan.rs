//! The feed along the path: a time-optimal plan on the path the machine follows, within every
//! axis' velocity, acceleration and (when given) jerk limit in every interpolation cycle.
//!
//! 1. The smooth path (module `smooth`) cuts the program into *runs* at true corners (tangent turns of more
//!    than 5 degrees, rapid moves, pure rotations, path changes) and lays a C2 spline through
//!    the poses of each run: the path the machine follows, smooth between corners.
//! 2. Along a run the machine axes are `q(s)` of the tip's arc length `s`; with `x = (ds/dt)^2`
//!    and `u = d2s/dt2` every axis must satisfy `-A_k <= q'_k(s) u + q''_k(s) x <= A_k` and
//!    `|q'_k| sqrt(x) <= V_k`, the tip `|tip'| sqrt(x) <= F` (the programmed feed), the chord
//!    between two set-points on a curve within `chord_tolerance`. The module `topp` solves the
//!    time-optimal `x(s)` on a grid (the phase-plane formulation, rest to rest), using each
//!    axis' whole acceleration: no fixed shares.
//! 3. With jerk limits the run's `s(t)` is passed through a moving average of width
//!    `tau = max_k A_k / J_k` (an S-curve: the path jerk is the difference of two accelerations
//!    over `tau`), after the maximum velocity curve was lowered to its minimum over the filter's
//!    reach so that the averaged speed stays under it; the run takes `tau` longer.
//! 4. The set-points are the plan sampled every cycle `T`. The plan is then **verified the way a
//!    test would**: velocities `(q_i - q_{i-1}) / T`, accelerations
//!    `(q_{i+1} - 2 q_i + q_{i-1}) / T^2` and jerks `(q_{i+1} - 3 q_i + 3 q_{i-1} - q_{i-2}) / T^3`
//!    of every axis in every cycle, at rest before the first and after the last set-point. Where
//!    a cycle exceeds a limit (the grid misses a peak between its points), the caps of the grid
//!    points around that cycle are lowered by the excess and only those runs are planned again,
//!    at most [`PlanOptions::max_refinements`] times.
//!
//! The derivations are in `docs/interpolation.md`.

use crate::block::Block;
use crate::error::{positive, InterpError, Result};
use crate::fit::BlockCounts;
use crate::model::AxisModel;
use crate::smooth::{runs, Run};
use crate::topp;

/// Share of each acceleration limit the grid plans with (the rest covers the grid error
/// between grid points; the verification checks every cycle against the whole limit).
pub const ACCELERATION_MARGIN: f64 = 0.99;
/// Share of each jerk limit the curvature term `q''' v^3` alone may take.
pub const JERK_STATIC_SHARE: f64 = 0.5;
/// Share of each jerk limit the term `3 q'' v a` (acceleration along a curve) may take: it caps
/// the path acceleration where the path curves at speed.
pub const JERK_CROSS_SHARE: f64 = 1.0;

/// Options of [`plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Programmed cutting feed, mm/min (the tip's speed along the path). Must be > 0.
    pub feed: f64,
    /// Interpolation cycle `T`, seconds. Must be > 0.
    pub cycle: f64,
    /// Largest chord error between two set-points on a curve, mm (paper 000 eq 17-18): caps
    /// the feed on small radii. Default 0.001.
    pub chord_tolerance: f64,
    /// Refuse programs of more cycles than this. Default 50 million.
    pub max_cycles: usize,
    /// Most re-plans after a verification finds a cycle over a limit. Default 60.
    pub max_refinements: usize,
    /// Land every block's end exactly on a cycle, as paper 000's block-by-block interpolator
    /// does (default false). Each block then takes a whole number of cycles, at least one: its
    /// planned profile is slowed to fill them. That caps the speed on a block of length `L`
    /// at `L / T` and makes the speed jump slightly where two blocks meet (the verification
    /// lowers the caps until those jumps are within the limits), so it costs cycle time on
    /// programs of many short blocks. With false the set-points sample one continuous motion;
    /// block ends fall between cycles, the program's end is still exact.
    pub block_ends_on_cycles: bool,
    /// Largest spacing of the planning grid along the path, mm (degrees on a turn); the grid
    /// also has at least two intervals between neighbouring spline nodes. Default 0.5.
    pub grid_step: f64,
    /// Work budget: most grid points of the whole program; longer programs get a coarser grid
    /// (the verification still holds every cycle to the limits). Default 5 million.
    pub max_grid_points: usize,
}

impl PlanOptions {
    /// Options with this feed (mm/min) and cycle (s), defaults otherwise.
    pub fn new(feed: f64, cycle: f64) -> Self {
        Self {
            feed,
            cycle,
            chord_tolerance: 0.001,
            max_cycles: 50_000_000,
            max_refinements: 60,
            block_ends_on_cycles: false,
            grid_step: 0.5,
            max_grid_points: 5_000_000,
        }
    }

    fn validate(&self) -> Result<()> {
        positive("feed", self.feed)?;
        positive("cycle", self.cycle)?;
        positive("chord_tolerance", self.chord_tolerance)?;
        positive("grid_step", self.grid_step)?;
        Ok(())
    }
}

/// The grid of one run and its constraints, computed once.
#[derive(Debug, Clone)]
struct RunGrid {
    s: Vec<f64>,
    d1: Vec<[f64; 5]>,
    d2: Vec<[f64; 5]>,
    /// `|tip'(s)|`.
    tip_speed: Vec<f64>,
    /// The static cap on `x` (velocity, feed, chord, jerk).
    cap: Vec<f64>,
    /// `|q''|` of each axis (for the jerk budget of the path acceleration).
    d2_abs_max: Vec<[f64; 5]>,
    /// The maximum velocity curve of the limits alone (no refinement): what the `F` words say.
    static_mv: Vec<f64>,
    /// Caps on `x` set by refinements, and factors on the accelerations.
    xlim: Vec<f64>,
    mult_a: Vec<f64>,
}

/// The timed profile of one run: `x`, `u` and the time of each grid point, and the integral of
/// `s dt` for the jerk filter.
#[derive(Debug, Clone)]
struct Timed {
    s: Vec<f64>,
    x: Vec<f64>,
    u: Vec<f64>,
    t: Vec<f64>,
    area: Vec<f64>,
    /// Filter width, s (0: acceleration-limited).
    tau: f64,
    /// Run time, s (the grid's time plus `tau`).
    duration: f64,
}

impl Timed {
    fn len(&self) -> f64 {
        self.s[self.s.len() - 1]
    }

    /// The interval holding time `t` (`0 <= t < t_N`).
    #[inline]
    fn interval(&self, t: f64) -> usize {
        self.t
            .partition_point(|&v| v <= t)
            .clamp(1, self.t.len() - 1)
            - 1
    }

    /// `s` at time `t` of the unfiltered profile.
    #[inline]
    fn s_raw(&self, t: f64) -> f64 {
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

    /// `integral of s dt` from 0 to `t` of the unfiltered profile (`s = len` after the end).
    #[inline]
    fn area_at(&self, t: f64) -> f64 {
        let n = self.t.len() - 1;
        if t <= 0.0 {
            return 0.0;
        }
        if t >= self.t[n] {
            return self.area[n] + self.len() * (t - self.t[n]);
        }
        let i = self.interval(t);
        let h = t - self.t[i];
        self.area[i] + h * (self.s[i] + h * (0.5 * self.x[i].sqrt() + h * self.u[i] / 6.0))
    }

    /// `s` at time `t` of the run (filtered when jerk-limited).
    #[inline]
    fn s_at(&self, t: f64) -> f64 {
        if t >= self.duration {
            return self.len();
        }
        if self.tau > 0.0 {
            ((self.area_at(t) - self.area_at(t - self.tau)) / self.tau).clamp(0.0, self.len())
        } else {
            self.s_raw(t)
        }
    }

    /// `ds/dt` at time `t`.
    fn speed_at(&self, t: f64) -> f64 {
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
    fn time_of(&self, s: f64) -> f64 {
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
            let (mut lo, mut hi) = (self.t[i - 1], self.t[i]);
            for _ in 0..50 {
                let mid = 0.5 * (lo + hi);
                if self.s_raw(mid) >= s {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            hi
        };
        if self.tau <= 0.0 {
            return raw;
        }
        let (mut lo, mut hi) = (raw, (raw + self.tau).min(self.duration));
        for _ in 0..50 {
            let mid = 0.5 * (lo + hi);
            if self.s_at(mid) >= s {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo <= 1e-13 * self.duration {
                break;
            }
        }
        hi
    }
}

/// Planned time and feed figures of one path of the program (see [`Motion::path_stats`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PathStats {
    /// Index of the path in the program.
    pub path: usize,
    /// Planned time of the path's blocks, including the rapid moves that lead to it, s.
    pub duration: f64,
    /// Planned time of its cutting blocks, s.
    pub cutting_time: f64,
    /// Tip travel of its cutting blocks, mm.
    pub cutting_length: f64,
    /// Time the tip moves at the programmed feed (within 0.1 %), s.
    pub time_at_feed: f64,
    /// Tip travel at the programmed feed, mm.
    pub length_at_feed: f64,
}

/// A planned program: blocks, their feed profile, and the set-points it gives.
#[derive(Debug, Clone)]
pub struct Motion {
    blocks: Vec<Block>,
    runs: Vec<Run>,
    timed: Vec<Timed>,
    /// Start time of each run in the program.
    starts: Vec<f64>,
    duration: f64,
    cycle: f64,
    refinements: usize,
    grid_points: usize,
    axis_names: [String; 5],
    /// Start and end time of each block.
    block_times: Vec<[f64; 2]>,
    /// F word of each block, mm/s.
    feeds: Vec<f64>,
    /// With [`PlanOptions::block_ends_on_cycles`]: when each block runs.
    clock: Option<Vec<BlockClock>>,
    total_cycles: usize,
    stats: Vec<PathStats>,
}

/// The cycles of one block when block ends land on cycles: cycles `first..first + n`, mapped
/// linearly onto the block's planned time `start..start + duration`.
#[derive(Debug, Clone, Copy)]
struct BlockClock {
    first: usize,
    n: usize,
    start: f64,
    duration: f64,
}

impl Motion {
    /// The blocks, in order.
    pub fn blocks(&self) -> &[Block] {
        &self.blocks
    }

    /// Lines, arcs and turns among the cutting blocks.
    pub fn counts(&self) -> BlockCounts {
        BlockCounts::of(&self.blocks)
    }

    /// Planned motion time from rest to rest, seconds (with block ends on cycles, the whole
    /// cycles the blocks take).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Interpolation cycle, seconds.
    pub fn cycle(&self) -> f64 {
        self.cycle
    }

    /// Number of cycles: the set-points are cycles `0..=cycles()`, the last one at rest on the
    /// program's end. The program's cycle time is `cycles() * cycle()` seconds.
    pub fn cycles(&self) -> usize {
        self.total_cycles
    }

    /// How many times the verification lowered caps and planned again (the planner's work
    /// beyond the first plan: each refinement re-plans the affected runs and re-verifies).
    pub fn refinements(&self) -> usize {
        self.refinements
    }

    /// Grid points the time-optimal planner worked on (the first plan; a measure of work).
    pub fn grid_points(&self) -> usize {
        self.grid_points
    }

    /// How many runs (smooth stretches between true corners, rapid moves and turns) the plan
    /// has: the machine is at rest between two runs and nowhere else.
    pub fn runs(&self) -> usize {
        self.runs.len()
    }

    /// Axis names (CSV header).
    pub fn axis_names(&self) -> [&str; 5] {
        std::array::from_fn(|k| self.axis_names[k].as_str())
    }

    /// The `F` word of block `b`, mm/min: for a cutting block the programmed feed wherever the
    /// machine can follow it somewhere in the block (so that a smooth contour keeps one modal
    /// feed), else the tip speed the limits allow all along the block, every stretch of such
    /// blocks sharing the lowest (one modal `F` the machine can hold all along); for a rapid
    /// move its planned peak speed. 0 for an index out of range.
    pub fn block_feed(&self, b: usize) -> f64 {
        self.feeds.get(b).copied().unwrap_or(0.0) * 60.0
    }

    /// The planned time of block `b` from its start to its end, seconds: what an inverse-time
    /// (`G93`) feed word must say for the controller to follow this plan
    /// (`F = 60 / block_duration` in 1/min); 0 for an index out of range.
    pub fn block_duration(&self, b: usize) -> f64 {
        self.block_times.get(b).map_or(0.0, |[a, e]| e - a)
    }

    /// [`Motion::block_feed`] of every block, for the `F` words of [`crate::gcode`].
    pub fn block_feeds(&self) -> Vec<f64> {
        (0..self.blocks.len()).map(|b| self.block_feed(b)).collect()
    }

    /// Planned time and the share at the programmed feed of every path, in program order.
    pub fn path_stats(&self) -> &[PathStats] {
        &self.stats
    }

    /// Share of the cutting time spent at the programmed feed (within 0.1 %), 0 to 1; 0 for a
    /// program without cutting blocks.
    pub fn time_share_at_feed(&self) -> f64 {
        let (a, t) = self.stats.iter().fold((0.0, 0.0), |(a, t), p| {
            (a + p.time_at_feed, t + p.cutting_time)
        });
        if t > 0.0 {
            a / t
        } else {
            0.0
        }
    }

    /// The block index and path parameter at time `t` (seconds from the start) of the planned
    /// motion (with [`PlanOptions::block_ends_on_cycles`], before each block is slowed to whole
    /// cycles).
    pub fn locate(&self, t: f64) -> (usize, f64) {
        if self.runs.is_empty() {
            return (0, 0.0);
        }
        let r = self.starts.partition_point(|&s| s <= t).saturating_sub(1);
        let s = self.timed[r].s_at(t - self.starts[r]);
        self.runs[r].block_at(s)
    }

    /// The set-points, one per cycle, computed by [`Motion::iter`].
    pub fn setpoints<M: AxisModel + ?Sized>(&self, model: &M) -> Vec<[f64; 5]> {
        let mut out = Vec::with_capacity(self.cycles() + 1);
        out.extend(self.iter(model));
        out
    }

    /// The set-points one cycle at a time, as a controller computes them: cycle `i` is the
    /// plan at `t = i T`, its position computed on the run's smooth path from the path
    /// parameter (never by summing increments). The first and the last set-point are exactly
    /// the program's start and end, and the machine is exactly on a station at every rest.
    pub fn iter<'a, M: AxisModel + ?Sized>(&'a self, model: &'a M) -> Cycles<'a, M> {
        Cycles {
            motion: self,
            model,
            i: 0,
            n: self.cycles(),
            run: 0,
            block: 0,
        }
    }

    /// The program time of cycle `i` (block-clock aware) and the run it falls in.
    fn cycle_time(&self, i: usize, run: &mut usize, block: &mut usize) -> Timepoint {
        if let Some(clock) = &self.clock {
            while *block + 1 < clock.len() && i >= clock[*block + 1].first {
                *block += 1;
            }
            let c = &clock[*block];
            if i == c.first {
                return Timepoint::BlockStart(*block, c.start);
            }
            let t = c.start + (i - c.first) as f64 / c.n as f64 * c.duration;
            // Stay inside the block's own time so that rounding cannot carry a set-point into
            // the next block.
            let end = self.block_times[*block][1];
            return Timepoint::At(t.min(end));
        }
        let _ = run;
        Timepoint::At(i as f64 * self.cycle)
    }

    #[inline]
    fn axes_at_time<M: AxisModel + ?Sized>(&self, model: &M, t: f64, run: &mut usize) -> [f64; 5] {
        while *run + 1 < self.runs.len() && t >= self.starts[*run + 1] {
            *run += 1;
        }
        let r = *run;
        let s = self.timed[r].s_at(t - self.starts[r]);
        self.runs[r].axes_at(model, &self.blocks, s)
    }
}

enum Timepoint {
    At(f64),
    BlockStart(usize, f64),
}

/// Iterator over the set-points of a [`Motion`], one per cycle.
#[derive(Debug)]
pub struct Cycles<'a, M: ?Sized> {
    motion: &'a Motion,
    model: &'a M,
    i: usize,
    n: usize,
    run: usize,
    block: usize,
}

impl<M: AxisModel + ?Sized> Cycles<'_, M> {
    /// The set-point of the next cycle, its time and its run (internal).
    #[inline]
    fn next_full(&mut self) -> Option<([f64; 5], f64, usize)> {
        if self.i > self.n || self.motion.blocks.is_empty() {
            return None;
        }
        let m = self.motion;
        let (q, t) = if self.i == self.n {
            self.run = m.runs.len() - 1;
            (m.blocks[m.blocks.len() - 1].end_axes, m.duration)
        } else {
            match m.cycle_time(self.i, &mut self.run, &mut self.block) {
                Timepoint::BlockStart(b, t) => {
                    while self.run + 1 < m.runs.len() && b > m.runs[self.run].last {
                        self.run += 1;
                    }
                    (m.blocks[b].start_axes, t)
                }
                Timepoint::At(t) => (m.axes_at_time(self.model, t, &mut self.run), t),
            }
        };
        self.i += 1;
        Some((q, t, self.run))
    }
}

impl<M: AxisModel + ?Sized> Iterator for Cycles<'_, M> {
    type Item = [f64; 5];

    #[inline]
    fn next(&mut self) -> Option<[f64; 5]> {
        self.next_full().map(|(q, _, _)| q)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.n + 1).saturating_sub(self.i);
        (left, Some(left))
    }
}

/// Joins the blocks of several paths into one program: between the end of one path and the
/// start of the next, a rapid (laser-off) line, planned at the axes' own limits.
pub fn link_paths(paths: Vec<Vec<Block>>) -> Vec<Block> {
    let mut out: Vec<Block> = Vec::new();
    for blocks in paths {
        let Some(first) = blocks.first() else {
            continue;
        };
        if let Some(last) = out.last() {
            if last.end_axes != first.start_axes {
                let a = crate::block::Station {
                    tip: last.end_tip(),
                    axis: last.end_tool_axis,
                    param: None,
                    axes: last.end_axes,
                };
                let b = crate::block::Station {
                    tip: first.start_tip(),
                    axis: first.end_tool_axis,
                    param: None,
                    axes: first.start_axes,
                };
                let mut rapid = Block::line(&a, &b);
                rapid.rapid = true;
                rapid.path = first.path;
                rapid.stations = [0, 0];
                out.push(rapid);
            }
        }
        out.extend(blocks);
    }
    out
}

/// Like [`link_paths`], but each rapid move backs off `retract` mm along the tool axis from
/// the end of one path (rotary axes standing), traverses to `retract` mm above the next path's
/// start along its tool axis, and approaches it along that axis, so the nozzle leaves and
/// meets the part along the beam instead of crossing it at cutting height. The traverse between
/// the two retract points is one straight move of the machine axes (the rotary axes turn during
/// it): it clears the part only if the retract distance is large enough for the part's shape;
/// nothing here checks the traverse against the part. With `retract <= 0` it is one straight rapid
/// (as [`link_paths`], but arriving with the next path's start orientation).
pub fn link_paths_with_retract<M: AxisModel + ?Sized>(
    model: &M,
    paths: Vec<Vec<Block>>,
    retract: f64,
) -> Vec<Block> {
    // Without a retract: one straight rapid, with the tool axes of the model at both ends
    // (the next path's start orientation, not its first block's end).
    let retract = if retract.is_nan() {
        0.0
    } else {
        retract.max(0.0)
    };
    let station = |tip: nalgebra::Point3<f64>, axes: [f64; 5]| {
        let axis = model.tool_axis(axes[3], axes[4]);
        let lin = model.linear_axes(&tip, axes[3], axes[4]);
        crate::block::Station {
            tip,
            axis,
            param: None,
            axes: [lin[0], lin[1], lin[2], axes[3], axes[4]],
        }
    };
    let mut out: Vec<Block> = Vec::new();
    for blocks in paths {
        let Some(first) = blocks.first() else {
            continue;
        };
        if let Some(last) = out.last() {
            if last.end_axes != first.start_axes {
                let end = station(last.end_tip(), last.end_axes);
                let start = station(first.start_tip(), first.start_axes);
                let up = station(end.tip + end.axis * retract, end.axes);
                let over = station(start.tip + start.axis * retract, start.axes);
                let moves = if retract > 0.0 {
                    vec![(&end, &up), (&up, &over), (&over, &start)]
                } else {
                    vec![(&end, &start)]
                };
                for (a, b) in moves {
                    let mut rapid = Block::line(a, b);
                    rapid.rapid = true;
                    rapid.path = first.path;
                    rapid.stations = [0, 0];
                    out.push(rapid);
                }
            }
        }
        out.extend(blocks);
    }
    out
}

/// Like [`link_paths_with_retract`], but the rapid moves between path `k` and path `k + 1` run
/// through the given waypoints `traverses[k]` (tip, tool axis and axes `[X, Y, Z, tilt, C]`
/// of each, e.g. a traverse checked against the part by `kerf-process`): from the end of
/// path `k` to the first waypoint, from one waypoint to the next, and from the last to the
/// start of path `k + 1`, each one rapid line. A gap without waypoints (a missing or empty
/// entry) falls back to the retract of [`link_paths_with_retract`].
pub fn link_paths_through<M: AxisModel + ?Sized>(
    model: &M,
    paths: Vec<Vec<Block>>,
    traverses: &[Vec<crate::block::Station>],
    retract: f64,
) -> Vec<Block> {
    let mut out: Vec<Block> = Vec::new();
    let mut k = 0usize;
    for blocks in paths {
        let Some(first) = blocks.first() else {
            continue;
        };
        if let Some(last) = out.last() {
            let way = traverses.get(k).filter(|w| !w.is_empty());
            k += 1;
            match way {
                Some(way) => {
                    let end = crate::block::Station {
                        tip: last.end_tip(),
                        axis: last.end_tool_axis,
                        param: None,
                        axes: last.end_axes,
                    };
                    let start = crate::block::Station {
                        tip: first.start_tip(),
                        axis: model.tool_axis(first.start_axes[3], first.start_axes[4]),
                        param: None,
                        axes: first.start_axes,
                    };
                    let mut stops = vec![end];
                    stops.extend(
                        way.iter()
                            .map(|s| crate::block::Station { param: None, ..*s }),
                    );
                    stops.push(start);
                    for w in stops.windows(2) {
                        let mut rapid = Block::line(&w[0], &w[1]);
                        rapid.rapid = true;
                        rapid.path = first.path;
                        rapid.stations = [0, 0];
                        out.push(rapid);
                    }
                }
                None => {
                    let mut linked =
                        link_paths_with_retract(model, vec![vec![*last], vec![*first]], retract);
                    linked.pop();
                    linked.remove(0);
                    out.extend(linked);
                }
            }
        }
        out.extend(blocks);
    }
    out
}

/// Plans the feed along `blocks` (one program, run from rest to rest) within the machine's
/// limits; see the module documentation.
///
/// # Errors
/// [`InterpError::BadParameter`] for invalid options or machine limits,
/// [`InterpError::TooManyCycles`], [`InterpError::LimitsNotMet`] if the refinements run out,
/// and [`InterpError::OutOfRange`] when a set-point leaves an axis range.
pub fn plan<M: AxisModel + ?Sized>(
    model: &M,
    blocks: &[Block],
    opts: &PlanOptions,
) -> Result<Motion> {
    opts.validate()?;
    let limits = model.limits();
    limits.validate()?;
    for (bi, b) in blocks.iter().enumerate() {
        let finite = b.length().is_finite()
            && [b.start_axes, b.mid_axes, b.end_axes]
                .iter()
                .flatten()
                .all(|v| v.is_finite());
        if !finite {
            return Err(InterpError::NonFinite { index: bi });
        }
    }
    let blocks: Vec<Block> = blocks
        .iter()
        .filter(|b| b.length() > 0.0)
        .copied()
        .collect();
    let names = model.axis_names().map(str::to_string);
    let runs = runs(&blocks);
    let total_len: f64 = runs.iter().map(Run::len).sum();
    // The work budget: a coarser grid for very long programs.
    let step = opts
        .grid_step
        .max(2.0 * total_len / opts.max_grid_points.max(1000) as f64);
    let tau = limits.max_jerk.map_or(0.0, |j| {
        (0..5)
            .map(|k| limits.max_acceleration[k] / j[k])
            .fold(0.0, f64::max)
    });
    let mut grids: Vec<RunGrid> = runs
        .iter()
        .map(|r| run_grid(model, r, step, opts))
        .collect();
    let mut timed: Vec<Timed> = grids
        .iter()
        .map(|g| time_run(g, limits.max_acceleration, limits.max_jerk, tau))
        .collect();
    let mut refinements = 0;
    loop {
        // Block times, feeds and statistics only when needed (the block clock) or final.
        let full = opts.block_ends_on_cycles;
        let motion = assemble(
            &blocks,
            &runs,
            &grids,
            timed.clone(),
            opts,
            &names,
            refinements,
            full,
        )?;
        let worst = verify(&motion, model);
        if worst.is_empty() {
            let motion = if full {
                motion
            } else {
                assemble(
                    &blocks,
                    &runs,
                    &grids,
                    timed,
                    opts,
                    &names,
                    refinements,
                    true,
                )?
            };
            check_ranges(&motion, model)?;
            return Ok(motion);
        }
        if refinements >= opts.max_refinements {
            let v = &worst[0];
            return Err(InterpError::LimitsNotMet {
                axis: names[v.axis].clone(),
                what: ["velocity", "acceleration", "jerk"][v.kind],
                cycle: v.cycle,
                value: v.value,
                limit: v.limit,
            });
        }
        // Lower the caps of the grid points whose motion the bad cycle sees (the cycle's
        // stencil and, when filtered, the filter's reach), by the excess and a 2 % margin.
        let mut touched = vec![false; runs.len()];
        let mut fxs: Vec<Vec<f64>> = grids.iter().map(|g| vec![1.0; g.s.len()]).collect();
        let mut fas = fxs.clone();
        for v in &worst {
            let f = 0.98 / (v.value / v.limit).max(1.0);
            let (fx, fa) = match v.kind {
                0 => (f * f, 1.0),
                1 => (f, f),
                _ => (f.powf(1.0 / 3.0), f),
            };
            let (mut lo, mut hi) = (v.time - 3.0 * opts.cycle, v.time + 3.0 * opts.cycle);
            if opts.block_ends_on_cycles {
                // The speed jumps where two blocks slowed by different factors meet: lower the
                // whole blocks around the cycle.
                let (b, _) = motion.locate(v.time);
                let bt = &motion.block_times;
                lo = lo.min(bt[b.saturating_sub(1)][0]);
                hi = hi.max(bt[(b + 1).min(bt.len() - 1)][1]);
            }
            for (r, tm) in timed.iter().enumerate() {
                let (r0, r1) = (motion.starts[r], motion.starts[r] + tm.duration);
                if r1 < lo || r0 > hi {
                    continue;
                }
                touched[r] = true;
                let (a, b) = (lo - r0 - tm.tau, hi - r0);
                let n = tm.t.len();
                let i0 = tm.t.partition_point(|&t| t < a).saturating_sub(1);
                let i1 = (tm.t.partition_point(|&t| t <= b) + 1).min(n);
                for i in i0..i1 {
                    fxs[r][i] = fxs[r][i].min(fx);
                    fas[r][i] = fas[r][i].min(fa);
                }
            }
        }
        for (r, t) in touched.iter().enumerate() {
            if *t {
                // Relative to the profile as planned, so that every refinement changes it.
                // (The largest x of the point and its neighbours: the rest at a run's end is no
                // cap.)
                let g = &mut grids[r];
                let x = &timed[r].x;
                let n = x.len();
                for i in 0..n {
                    if fxs[r][i] < 1.0 {
                        let near = x[i.saturating_sub(1)].max(x[i]).max(x[(i + 1).min(n - 1)]);
                        g.xlim[i] = g.xlim[i].min(near * fxs[r][i]);
                    }
                    g.mult_a[i] *= fas[r][i];
                }
                timed[r] = time_run(&grids[r], limits.max_acceleration, limits.max_jerk, tau);
            }
        }
        refinements += 1;
    }
}

/// The grid of one run: nodes subdivided to at most `step`, at least two intervals each, and
/// at every grid point `q'`, `q''` (and `q'''` for the jerk cap) by central differences of the
/// machine axes along the smooth path, with the static caps on `x`.
fn run_grid<M: AxisModel + ?Sized>(model: &M, run: &Run, step: f64, opts: &PlanOptions) -> RunGrid {
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
    let s = fine_s;
    let n = s.len();
    let mut d1 = Vec::with_capacity(n);
    let mut d2 = Vec::with_capacity(n);
    let mut tip_speed = Vec::with_capacity(n);
    let mut cap = Vec::with_capacity(n);
    let mut static_mv = Vec::with_capacity(n);
    let feed = opts.feed / 60.0;
    for (&si, &(a, b, c)) in s.iter().zip(&fine_d) {
        let (t1, t2) = run.tip_derivatives(si);
        let speed = t1.norm();
        let mut x = f64::INFINITY;
        for k in 0..5 {
            if a[k] != 0.0 {
                x = x.min((lim.max_velocity[k] * 0.999 / a[k].abs()).powi(2));
            }
            if let Some(j) = lim.max_jerk {
                if c[k] != 0.0 {
                    x = x.min((JERK_STATIC_SHARE * j[k] / c[k].abs()).powf(2.0 / 3.0));
                }
            }
        }
        if run.moves_tip && speed > 0.0 {
            if run.cutting {
                x = x.min((feed / speed).powi(2));
            }
            let kappa = t1.cross(&t2).norm() / speed.powi(3);
            if kappa > 1e-12 {
                let step = (8.0 * opts.chord_tolerance / kappa).sqrt();
                x = x.min((step / opts.cycle / speed).powi(2));
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
    RunGrid {
        xlim: vec![f64::INFINITY; n],
        d2_abs_max: d2.iter().map(|b: &[f64; 5]| b.map(f64::abs)).collect(),
        static_mv,
        mult_a: vec![1.0; n],
        s,
        d1,
        d2,
        tip_speed,
        cap,
    }
}

/// Plans one run on its grid (rest to rest) and times it.
fn time_run(g: &RunGrid, acc: [f64; 5], jerk: Option<[f64; 5]>, tau: f64) -> Timed {
    let n = g.s.len();
    let mut pts: Vec<topp::Point> = (0..n)
        .map(|i| {
            let cap = g.cap[i].min(g.xlim[i]);
            let mut path_acc = f64::INFINITY;
            if let Some(j) = jerk {
                let v = cap.sqrt();
                for k in 0..5 {
                    let c = 3.0 * g.d2_abs_max[i][k] * v;
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
    let mut mv: Vec<f64> = pts.iter().map(topp::xmax).collect();
    if tau > 0.0 {
        // The moving average sees positions about v tau / 2 either side: lower the maximum
        // velocity curve to its minimum over that reach.
        let raw = mv.clone();
        for i in 0..n {
            let w = 0.6 * raw[i].sqrt() * tau;
            let mut low = raw[i];
            let mut j = i;
            while j > 0 && g.s[i] - g.s[j - 1] <= w {
                j -= 1;
                low = low.min(raw[j]);
            }
            let mut j = i;
            while j + 1 < n && g.s[j + 1] - g.s[i] <= w {
                j += 1;
                low = low.min(raw[j]);
            }
            mv[i] = low;
        }
        for (p, m) in pts.iter_mut().zip(&mv) {
            p.cap = p.cap.min(*m);
        }
    }
    let (x, u) = topp::solve(&g.s, &pts);
    let mut t = Vec::with_capacity(n);
    let mut area = Vec::with_capacity(n);
    let (mut tt, mut aa) = (0.0, 0.0);
    for i in 0..n {
        t.push(tt);
        area.push(aa);
        if i + 1 < n {
            let d = g.s[i + 1] - g.s[i];
            let den = x[i].sqrt() + x[i + 1].sqrt();
            let dt = if den > 0.0 {
                2.0 * d / den
            } else {
                f64::INFINITY
            };
            let v = x[i].sqrt();
            aa += dt * (g.s[i] + dt * (0.5 * v + dt * u[i] / 6.0));
            tt += dt;
        }
    }
    Timed {
        s: g.s.clone(),
        duration: tt + tau,
        x,
        u,
        t,
        area,
        tau,
    }
}

/// Puts the runs' profiles together into a program: start times, block times and feeds, the
/// block clock, statistics.
#[allow(clippy::too_many_arguments)]
fn assemble(
    blocks: &[Block],
    runs: &[Run],
    grids: &[RunGrid],
    timed: Vec<Timed>,
    opts: &PlanOptions,
    names: &[String; 5],
    refinements: usize,
    full: bool,
) -> Result<Motion> {
    let mut starts = Vec::with_capacity(runs.len());
    let mut total = 0.0;
    for tm in &timed {
        starts.push(total);
        total += tm.duration;
    }
    let cycles = total / opts.cycle;
    if cycles.is_nan() || cycles > opts.max_cycles as f64 {
        return Err(InterpError::TooManyCycles {
            cycles,
            limit: opts.max_cycles,
        });
    }
    let feed = opts.feed / 60.0;
    let mut block_times = vec![[0.0; 2]; blocks.len()];
    let mut feeds = vec![0.0; blocks.len()];
    let mut stats: Vec<PathStats> = Vec::new();
    for (r, run) in runs.iter().enumerate() {
        if !full {
            break;
        }
        let (tm, g) = (&timed[r], &grids[r]);
        for b in run.first..=run.last {
            let j = b - run.first;
            let (s0, s1) = (run.starts[j], run.starts[j + 1]);
            let t0 = if j == 0 { 0.0 } else { tm.time_of(s0) };
            let t1 = if b == run.last {
                tm.duration
            } else {
                tm.time_of(s1)
            };
            block_times[b] = [starts[r] + t0, starts[r] + t1];
            let i0 = g.s.partition_point(|&s| s < s0);
            let i1 = g.s.partition_point(|&s| s <= s1).max(i0 + 1).min(g.s.len());
            let range = i0.min(g.s.len() - 1)..i1;
            feeds[b] = if run.cutting && run.moves_tip {
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
        if run.cutting && run.moves_tip {
            modal_feeds(&mut feeds[run.first..=run.last], feed);
        }
        // Statistics of the path this run belongs to.
        let path = blocks[run.first].path;
        if stats.last().is_none_or(|p| p.path != path) {
            stats.push(PathStats {
                path,
                ..PathStats::default()
            });
        }
        let st = stats.last_mut().unwrap_or_else(|| unreachable!());
        st.duration += tm.duration;
        if run.cutting && run.moves_tip {
            st.cutting_time += tm.duration;
            st.cutting_length += run.len();
            // Sample the run at half a cycle.
            let dt = opts.cycle / 2.0;
            let steps = (tm.duration / dt).ceil() as usize;
            let dt = tm.duration / steps.max(1) as f64;
            for k in 0..steps {
                let t = (k as f64 + 0.5) * dt;
                let s = tm.s_at(t);
                let (t1, _) = run.tip_derivatives(s);
                let v = tm.speed_at(t) * t1.norm();
                if v >= feed * 0.999 {
                    st.time_at_feed += dt;
                    st.length_at_feed += v * dt;
                }
            }
            st.length_at_feed = st.length_at_feed.min(st.cutting_length);
        }
    }
    let mut total_cycles = (cycles - 1e-9).ceil().max(0.0) as usize;
    let mut duration = total;
    let clock = opts.block_ends_on_cycles.then(|| {
        let mut first = 0;
        let clock: Vec<BlockClock> = block_times
            .iter()
            .map(|[a, e]| {
                let d = e - a;
                let n = ((d / opts.cycle - 1e-9).ceil() as usize).max(1);
                let c = BlockClock {
                    first,
                    n,
                    start: *a,
                    duration: d,
                };
                first += n;
                c
            })
            .collect();
        total_cycles = first;
        duration = first as f64 * opts.cycle;
        clock
    });
    if total_cycles > opts.max_cycles {
        return Err(InterpError::TooManyCycles {
            cycles: total_cycles as f64,
            limit: opts.max_cycles,
        });
    }
    Ok(Motion {
        blocks: blocks.to_vec(),
        runs: runs.to_vec(),
        timed,
        starts,
        duration,
        cycle: opts.cycle,
        refinements,
        grid_points: grids.iter().map(|g| g.s.len()).sum(),
        axis_names: names.clone(),
        block_times,
        feeds,
        clock,
        total_cycles,
        stats,
    })
}

/// Every stretch of neighbouring blocks of one run below the programmed feed shares the lowest
/// of their feeds, so that a smooth stretch the machine cannot take at the programmed feed gets
/// one modal `F` word (the speed it can hold all along) instead of a new one per block.
fn modal_feeds(feeds: &mut [f64], programmed: f64) {
    let mut start = 0;
    while start < feeds.len() {
        if feeds[start] >= programmed {
            start += 1;
            continue;
        }
        let mut end = start;
        let mut lo = f64::INFINITY;
        while end < feeds.len() && feeds[end] < programmed {
            lo = lo.min(feeds[end]);
            end += 1;
        }
        for f in &mut feeds[start..end] {
            *f = lo;
        }
        start = end;
    }
}

/// A cycle over a limit.
#[derive(Debug, Clone)]
struct Violation {
    cycle: usize,
    /// Program time of the cycle.
    time: f64,
    axis: usize,
    /// 0 velocity, 1 acceleration, 2 jerk.
    kind: usize,
    value: f64,
    limit: f64,
}

/// Every cycle over a limit, worst first (at most one per cycle). Velocity at cycle `i` is
/// `(q_i - q_{i-1}) / T`, acceleration `(q_{i+1} - 2 q_i + q_{i-1}) / T^2`, jerk
/// `(q_{i+1} - 3 q_i + 3 q_{i-1} - q_{i-2}) / T^3`; rows before the first and after the last are
/// the first and the last (rest).
fn verify<M: AxisModel + ?Sized>(motion: &Motion, model: &M) -> Vec<Violation> {
    let lim = model.limits();
    let t = motion.cycle;
    let mut out = Vec::new();
    let slack = 1.0 - 1e-6;
    let mut it = motion.iter(model);
    let n = it.size_hint().0;
    let Some(first) = it.next_full() else {
        return out;
    };
    // Rows i - 2, i - 1, i, i + 1 streamed, so memory does not grow with the program.
    let (mut r2, mut r1, mut r0) = (first, first, first);
    let mut r3 = it.next_full().unwrap_or(r0);
    for i in 0..=n + 1 {
        let (qmm, qm, q0, qp) = (r2.0, r1.0, r0.0, r3.0);
        let mut worst: Option<Violation> = None;
        for k in 0..5 {
            let v = ((q0[k] - qm[k]) / t).abs();
            let a = ((qp[k] - 2.0 * q0[k] + qm[k]) / (t * t)).abs();
            let j = ((qp[k] - 3.0 * q0[k] + 3.0 * qm[k] - qmm[k]) / (t * t * t)).abs();
            let checks = [
                (v, lim.max_velocity[k], 0),
                (a, lim.max_acceleration[k], 1),
                (j, lim.max_jerk.map_or(f64::INFINITY, |m| m[k]), 2),
            ];
            for (value, limit, kind) in checks {
                if value > limit * slack
                    && worst
                        .as_ref()
                        .is_none_or(|w| value / limit > w.value / w.limit)
                {
                    worst = Some(Violation {
                        cycle: i.min(n.saturating_sub(1)),
                        time: r0.1,
                        axis: k,
                        kind,
                        value,
                        limit,
                    });
                }
            }
        }
        out.extend(worst);
        (r2, r1, r0) = (r1, r0, r3);
        r3 = it.next_full().unwrap_or(r0);
    }
    out.sort_by(|a, b| (b.value / b.limit).total_cmp(&(a.value / a.limit)));
    out
}

fn check_ranges<M: AxisModel + ?Sized>(motion: &Motion, model: &M) -> Result<()> {
    let lim = model.limits();
    for (i, q) in motion.iter(model).enumerate() {
        for k in 0..5 {
            if let Some([lo, hi]) = lim.range[k] {
                if !(q[k] >= lo - 1e-9 && q[k] <= hi + 1e-9) {
                    return Err(InterpError::OutOfRange {
                        cycle: i,
                        axis: model.axis_names()[k].to_string(),
                        value: q[k],
                        min: lo,
                        max: hi,
                    });
                }
            }
        }
    }
    Ok(())
}
