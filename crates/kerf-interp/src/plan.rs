//! The feed along the path: a time-optimal plan on the path the machine follows, within every
//! axis' velocity, acceleration and (when given) jerk limit in every interpolation cycle.
//!
//! 1. The smooth path (module `smooth`) cuts the program into *runs* at true corners (tangent turns of more
//!    than 5 degrees, rapid moves, pure rotations, path changes) and lays a C2 spline through
//!    the poses of each run: the path the machine follows, smooth between corners. With jerk
//!    limits the tip follows the spline's moving mean over a window within
//!    [`PlanOptions::blend_tolerance_mm`], which ramps every curvature jump (a clothoid-like
//!    blend); the rotary axes never leave their ranges (soft-range coordinates). A rapid is a
//!    run of its own, straight in the machine's axes, as its `G0` runs and its traverse was
//!    checked.
//! 2. Along a run the machine axes are `q(s)` of the run's path parameter `s` (the tip's arc
//!    length, or the rotary travel in mm equivalents where larger); with `x = (ds/dt)^2`
//!    and `u = d2s/dt2` every axis must satisfy `-A_k <= q'_k(s) u + q''_k(s) x <= A_k` and
//!    `|q'_k| sqrt(x) <= V_k`, the tip `|tip'| sqrt(x) <= F` (the programmed feed), the chord
//!    between two set-points on a curve within `chord_tolerance`. The module `topp` solves the
//!    time-optimal `x(s)` on a grid (the phase-plane formulation, rest to rest), using each
//!    axis' whole acceleration: no fixed shares.
//! 3. With jerk limits the run's `s(t)` is passed through a moving average of width
//!    `tau = JERK_FILTER_WIDTH max_k A_k / J_k` (an S-curve: the path jerk is the difference of
//!    two accelerations over `tau`), after the maximum velocity curve was lowered to its minimum
//!    over the filter's reach (measured with the speed of the unfiltered optimum) so that the
//!    averaged speed stays under it; the run takes `tau` longer. Where the profile accelerates
//!    and at once brakes (a triangle), its peak is capped to a plateau of one filter width, so
//!    that no window of the filter sees the whole reversal of the acceleration (which would
//!    take 160 % of the jerk).
//! 4. The set-points are the plan sampled every cycle `T`. The plan is then **verified the way a
//!    test would**: velocities `(q_i - q_{i-1}) / T`, accelerations
//!    `(q_{i+1} - 2 q_i + q_{i-1}) / T^2` and jerks `(q_{i+1} - 3 q_i + 3 q_{i-1} - q_{i-2}) / T^3`
//!    of every axis in every cycle, at rest before the first and after the last set-point. Where
//!    a cycle exceeds a limit (the grid misses a peak between its points), the caps of the grid
//!    points around that cycle are lowered by the excess and only those runs are planned again,
//!    at most [`PlanOptions::max_refinements`] times.
//!
//! The derivations are in `docs/interpolation.md`.

mod assemble;
mod deviation;
mod link;
mod motion;
mod profile;
mod verify;

pub use link::{link_paths, link_paths_through, link_paths_with_retract};
pub use motion::{Cycles, Motion, PathStats, PlanWork};

use assemble::assemble;
use profile::{run_feeds, run_grid, time_run, Timed};
use verify::verify;

use kerf_kinematics::Axes;

use crate::block::{Block, Geometry};
use crate::error::{positive, InterpError, Result};
use crate::model::AxisModel;
use crate::smooth::{runs, PathOptions, Run};

/// Share of each acceleration limit the grid plans with (the rest covers the grid error
/// between grid points; the verification checks every cycle against the whole limit).
pub const ACCELERATION_MARGIN: f64 = 0.99;
/// Share of each jerk limit the curvature term `q''' v^3` alone may take (the whole: on a
/// circle at constant speed it is the only term).
pub const JERK_STATIC_SHARE: f64 = 1.0;
/// Share of each jerk limit the term `3 q'' v a` (acceleration along a curve) may take: it caps
/// the path acceleration where the path curves at speed.
pub const JERK_CROSS_SHARE: f64 = 0.5;
/// Width of the jerk filter in jerk times `A_k / J_k`: at 1.25 a ramp of the path acceleration
/// from 0 to `A` takes 80 % of the jerk limit, the rest left to the curvature terms; a direct
/// reversal from `+A` to `-A` would take 160 %, and the verification lowers the accelerations
/// of those few cycles (measured on the fixtures: 1.25 gives shorter plans than 1 or 2).
pub const JERK_FILTER_WIDTH: f64 = 1.25;
/// The path parameter counts a block's rotary travel once turning it at the rotary axis' limit
/// would take this many times longer than the tip's travel at the slowest linear axis' limit
/// (see `smooth::block_param_length`): a tool turning about a nearly still tip. At 1 (any block
/// whose rotation takes longer than its tip travel) the 10,000-pose wave of the plan bench
/// needed 6 refinements and planned 5 % longer; at 3 and 5 it is planned as before, and the
/// pole repro of `tests/crawl.rs` in 2.4 and 2.5 s instead of 2.35 s.
pub(crate) const ROTATION_DOMINANCE: f64 = 5.0;
/// Every 4 refinements a window the verification still finds over a limit is slowed by this
/// factor more per round (on `x` and the accelerations), so that the budget of refinements
/// reaches any slow-down a motion can be followed at: 60 rounds multiply a window's caps by at
/// most `0.98^60 * 0.9^420`, about `1e-20`.
pub(crate) const REPAIR_ESCALATION: f64 = 0.9;

/// The corner rule of a technology: within `length_mm` of the path parameter on either side of
/// a point where the tip's direction turns by more than `min_turn_deg`, a cut runs at no more
/// than `feed_factor` of its feed (the power, following the speed, comes down with it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerSlowdown {
    /// The least turn of the tip's direction that makes a corner, degrees, in (0, 180).
    pub min_turn_deg: f64,
    /// How far on each side of the corner the slowdown reaches, mm of the path parameter
    /// (the tip's travel where it dominates), > 0.
    pub length_mm: f64,
    /// The share of the feed there, in (0, 1].
    pub feed_factor: f64,
}

/// The path parameters along `run` of the points where the tip turns by more than
/// `min_turn_deg` between two cutting blocks of its path (turns in place between them skipped),
/// including those in the path's neighbouring runs up to `reach` mm of tip travel beyond the
/// run's ends (runs end where the motion has a corner of its own; a corner just past one still
/// slows the run's end), there at parameters below 0 or past the run's length. Each block's
/// direction near its ends comes from [`Block::pose_at`] 0.01 mm (or its length) in.
fn corners(blocks: &[Block], run: &Run, min_turn_deg: f64, reach: f64) -> Vec<f64> {
    let cos_max = min_turn_deg.to_radians().cos();
    let path = blocks[run.first].path;
    let same = |k: usize| blocks.get(k).is_some_and(|b| !b.rapid && b.path == path);
    // The blocks within `reach` of tip travel before and after the run, with the parameter of
    // each block's start.
    let mut lo = run.first;
    let mut before = 0.0;
    while lo > 0 && same(lo - 1) && before <= reach {
        lo -= 1;
        before += blocks[lo].length();
    }
    let mut hi = run.last;
    let mut after = 0.0;
    while same(hi + 1) && after <= reach {
        hi += 1;
        after += blocks[hi].length();
    }
    let mut param = -before;
    let mut out = Vec::new();
    let mut last_dir: Option<nalgebra::Vector3<f64>> = None;
    for (k, b) in blocks.iter().enumerate().take(hi + 1).skip(lo) {
        let start = if (run.first..=run.last).contains(&k) {
            run.starts[k - run.first]
        } else if k > run.last {
            run.len() + (param - run.len()).max(0.0)
        } else {
            param
        };
        param = if (run.first..=run.last).contains(&k) {
            run.starts[k + 1 - run.first]
        } else {
            start + b.length()
        };
        if matches!(b.geometry, Geometry::Turn { .. }) || b.length() <= 0.0 {
            continue;
        }
        let h = b.length().min(0.01);
        let start_dir = b.pose_at(h).0 - b.start_tip();
        if let Some(d) = last_dir {
            let (n1, n2) = (d.norm(), start_dir.norm());
            if n1 > 0.0 && n2 > 0.0 && d.dot(&start_dir) / (n1 * n2) < cos_max {
                out.push(start);
            }
        }
        last_dir = Some(b.end_tip() - b.pose_at(b.length() - h).0);
    }
    out.dedup();
    out
}

/// Options of [`plan`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PlanOptions {
    /// Programmed cutting feed, mm/min (the tip's speed along the path). Must be > 0; no
    /// default (given to [`PlanOptions::new`]).
    pub feed_mm_per_min: f64,
    /// Interpolation cycle `T`, seconds. Must be > 0; no default (given to [`PlanOptions::new`]).
    pub cycle_s: f64,
    /// Largest chord error between two set-points on a curve, mm (paper 000 eq 17-18): caps
    /// the feed on small radii. Default 0.001.
    pub chord_tolerance_mm: f64,
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
    pub grid_step_mm: f64,
    /// Work budget: most grid points of the whole program; longer programs get a coarser grid
    /// (the verification still holds every cycle to the limits). Default 5 million.
    pub max_grid_points: usize,
    /// With jerk limits: how far the set-points' tip may leave the smooth path (the tip spline)
    /// to blend a curvature jump, mm (the tolerance budget's `controller_blending` term, default
    /// [`crate::DEFAULT_BLEND_TOLERANCE`]). The tip follows the spline's mean over a
    /// window of at most `2 sqrt(6 e / max |p''|)`, which ramps every curvature change over the
    /// window (a clothoid-like transition) within `e`. 0 for none; not used without jerk limits
    /// (a curvature jump is an acceleration jump, which they allow) or with
    /// [`PlanOptions::block_ends_on_cycles`] (whose block ends are exact).
    pub blend_tolerance_mm: f64,
    /// The share of the programmed feed each path cuts at (indexed like the blocks' `path`;
    /// a small hole's feed factor from the technology's small-hole rule), each in (0, 1]; 1
    /// where missing. Default none.
    pub feed_factors: Vec<f64>,
    /// Slow the tip at sharp corners of the cuts (a technology's corner rule). Default `None`.
    pub corner_slowdown: Option<CornerSlowdown>,
    /// Test hook: the share of the velocity, acceleration and jerk limits the grid plans with
    /// (default 1). Above 1 the first plan breaks the limits on purpose, so that the tests can
    /// watch the verification repair it; the verification always checks the true limits.
    #[doc(hidden)]
    pub planned_limit_scale: f64,
}

impl PlanOptions {
    /// Sets [`feed_mm_per_min`](Self::feed_mm_per_min): programmed cutting feed, mm/min (the tip's speed along the path).
    pub fn with_feed_mm_per_min(mut self, feed_mm_per_min: f64) -> Self {
        self.feed_mm_per_min = feed_mm_per_min;
        self
    }

    /// Sets [`corner_slowdown`](Self::corner_slowdown): the corner rule.
    pub fn with_corner_slowdown(mut self, rule: Option<CornerSlowdown>) -> Self {
        self.corner_slowdown = rule;
        self
    }

    /// Sets [`feed_factors`](Self::feed_factors): each path's share of the programmed feed.
    pub fn with_feed_factors(mut self, feed_factors: Vec<f64>) -> Self {
        self.feed_factors = feed_factors;
        self
    }

    /// Sets [`cycle_s`](Self::cycle_s): interpolation cycle `T`, seconds.
    pub fn with_cycle_s(mut self, cycle_s: f64) -> Self {
        self.cycle_s = cycle_s;
        self
    }

    /// Sets [`chord_tolerance_mm`](Self::chord_tolerance_mm): largest chord error between two
    /// set-points on a curve, mm (paper 000 eq 17-18).
    pub fn with_chord_tolerance_mm(mut self, chord_tolerance_mm: f64) -> Self {
        self.chord_tolerance_mm = chord_tolerance_mm;
        self
    }

    /// Sets [`max_cycles`](Self::max_cycles): refuse programs of more cycles than this.
    pub fn with_max_cycles(mut self, max_cycles: usize) -> Self {
        self.max_cycles = max_cycles;
        self
    }

    /// Sets [`max_refinements`](Self::max_refinements): most re-plans after a verification
    /// finds a cycle over a limit.
    pub fn with_max_refinements(mut self, max_refinements: usize) -> Self {
        self.max_refinements = max_refinements;
        self
    }

    /// Sets [`block_ends_on_cycles`](Self::block_ends_on_cycles): land every block's end
    /// exactly on a cycle, as paper 000's block-by-block interpolator does (default false).
    pub fn with_block_ends_on_cycles(mut self, block_ends_on_cycles: bool) -> Self {
        self.block_ends_on_cycles = block_ends_on_cycles;
        self
    }

    /// Sets [`grid_step_mm`](Self::grid_step_mm): largest spacing of the planning grid along the
    /// path, mm (degrees on a turn).
    pub fn with_grid_step_mm(mut self, grid_step_mm: f64) -> Self {
        self.grid_step_mm = grid_step_mm;
        self
    }

    /// Sets [`max_grid_points`](Self::max_grid_points): work budget.
    pub fn with_max_grid_points(mut self, max_grid_points: usize) -> Self {
        self.max_grid_points = max_grid_points;
        self
    }

    /// Sets [`blend_tolerance_mm`](Self::blend_tolerance_mm): with jerk limits.
    pub fn with_blend_tolerance_mm(mut self, blend_tolerance_mm: f64) -> Self {
        self.blend_tolerance_mm = blend_tolerance_mm;
        self
    }

    /// Options with this feed (mm/min) and cycle (s), defaults otherwise.
    pub fn new(feed_mm_per_min: f64, cycle_s: f64) -> Self {
        Self {
            feed_mm_per_min,
            cycle_s,
            chord_tolerance_mm: 0.001,
            max_cycles: 50_000_000,
            max_refinements: 60,
            block_ends_on_cycles: false,
            grid_step_mm: 0.5,
            max_grid_points: 5_000_000,
            blend_tolerance_mm: crate::DEFAULT_BLEND_TOLERANCE,
            feed_factors: Vec::new(),
            corner_slowdown: None,
            planned_limit_scale: 1.0,
        }
    }

    fn validate(&self) -> Result<()> {
        positive("feed_mm_per_min", self.feed_mm_per_min)?;
        positive("cycle_s", self.cycle_s)?;
        positive("chord_tolerance_mm", self.chord_tolerance_mm)?;
        positive("grid_step_mm", self.grid_step_mm)?;
        positive("planned_limit_scale", self.planned_limit_scale)?;
        crate::error::unit_factors("feed_factors", &self.feed_factors)?;
        if let Some(c) = &self.corner_slowdown {
            crate::error::unit_factors("corner_slowdown.feed_factor", &[c.feed_factor])?;
            if !(c.min_turn_deg.is_finite() && c.min_turn_deg > 0.0 && c.min_turn_deg < 180.0) {
                return Err(InterpError::BadParameter {
                    name: "corner_slowdown.min_turn_deg",
                    value: c.min_turn_deg,
                    reason: "must lie in (0, 180) degrees",
                });
            }
            positive("corner_slowdown.length_mm", c.length_mm)?;
        }
        if !(self.blend_tolerance_mm >= 0.0 && self.blend_tolerance_mm.is_finite()) {
            return Err(InterpError::BadParameter {
                name: "blend_tolerance_mm",
                value: self.blend_tolerance_mm,
                reason: "must be finite and >= 0",
            });
        }
        Ok(())
    }
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
    plan_owned(model, blocks.to_vec(), opts)
}

/// [`plan`] on blocks the caller gives up: they move into the [`Motion`] instead of being
/// copied (what [`crate::interpolate`] and [`crate::interpolate_through`] do, so that a
/// program's blocks are held once).
///
/// Memory: the planner holds the blocks, the runs' splines and the timed profile of every run
/// (5 numbers a grid point, which the [`Motion`] keeps for its set-points), one [`Motion`] at a
/// time; a run's grid constraints (15 numbers a grid point) only while that run is timed (a
/// refinement rebuilds the grid of each run it touches), and what the refinements lowered only
/// at the grid points they reached.
///
/// # Errors
/// As [`plan`].
pub fn plan_owned<M: AxisModel + ?Sized>(
    model: &M,
    mut blocks: Vec<Block>,
    opts: &PlanOptions,
) -> Result<Motion> {
    opts.validate()?;
    let limits = model.limits();
    limits.validate()?;
    for (bi, b) in blocks.iter().enumerate() {
        let finite = b.length().is_finite()
            && [b.start_axes, b.mid_axes, b.end_axes]
                .iter()
                .all(Axes::is_finite);
        if !finite {
            return Err(InterpError::NonFinite { index: bi });
        }
    }
    blocks.retain(|b| b.length() > 0.0);
    // Held to the end of the program's life: no room to spare.
    blocks.shrink_to_fit();
    let names = model.axis_names().map(str::to_string);
    // A degree of a rotary axis counts for `1 / ROTATION_DOMINANCE` of what the slowest
    // linear axis moves while that axis turns a degree at its limit.
    let v_lin = limits.max_velocity[..3]
        .iter()
        .fold(f64::INFINITY, |m, &v| m.min(v));
    let path = PathOptions {
        rotary_mm_per_deg: [
            v_lin / limits.max_velocity[3] / ROTATION_DOMINANCE,
            v_lin / limits.max_velocity[4] / ROTATION_DOMINANCE,
        ],
        rotary_ranges: [limits.range[3], limits.range[4]],
        blend_tolerance: if limits.max_jerk.is_some() && !opts.block_ends_on_cycles {
            opts.blend_tolerance_mm
        } else {
            0.0
        },
    };
    // Before any work: a lower bound of the program's time, each block no faster than its tip
    // travel at the feed (cutting blocks) and each axis' travel at its velocity limit.
    let feed_mm_s = opts.feed_mm_per_min / 60.0;
    let least: f64 = blocks
        .iter()
        .map(|b| {
            let turn = matches!(b.geometry, Geometry::Turn { .. });
            let tip = if b.rapid || turn {
                0.0
            } else {
                b.length() / feed_mm_s
            };
            (0..5)
                .map(|k| (b.end_axes[k] - b.start_axes[k]).abs() / limits.max_velocity[k])
                .fold(tip, f64::max)
        })
        .sum();
    if least / opts.cycle_s > opts.max_cycles as f64 {
        return Err(InterpError::TooManyCycles {
            cycles: least / opts.cycle_s,
            limit: opts.max_cycles,
        });
    }
    let mut runs = runs(&blocks, &path);
    for run in &mut runs {
        run.feed_factor = blocks[run.first..=run.last]
            .iter()
            .filter_map(|b| opts.feed_factors.get(b.path).copied())
            .fold(1.0, f64::min);
        if let (Some(rule), true) = (&opts.corner_slowdown, run.cutting) {
            run.corners = (
                corners(&blocks, run, rule.min_turn_deg, rule.length_mm),
                rule.length_mm,
                rule.feed_factor,
            );
        }
    }
    let total_len: f64 = runs.iter().map(Run::len).sum();
    // The work budget: a coarser grid for very long programs.
    let step = opts
        .grid_step_mm
        .max(2.0 * total_len / opts.max_grid_points.max(1000) as f64);
    // No filter where the jerk limit cannot bind at this cycle: an axis' acceleration changes
    // by at most `2 A_k` from one cycle to the next, a jerk of `2 A_k / T`, within `J_k` when
    // `2 A_k / J_k <= T`. (A filter of width `~A / J` far below one cycle only degenerated: a
    // jerk of 1e14 mm/s^3 planned the dome for 1.3e6 s.)
    // The acceleration a jerk-limited axis can reach at all: from `-V` to `V` at jerk `J`,
    // `a^2 / J <= 2 V`, so `a <= sqrt(2 J V)`. A larger `max_acceleration` is no limit, and
    // taken as one it would set the filter's width (`A / J`: 1e300 mm/s^2 gave 1e294 s).
    let acc: [f64; 5] = std::array::from_fn(|k| {
        opts.planned_limit_scale
            * match limits.max_jerk {
                Some(j) => {
                    limits.max_acceleration[k].min((2.0 * j[k] * limits.max_velocity[k]).sqrt())
                }
                None => limits.max_acceleration[k],
            }
    });
    let tau = limits.max_jerk.map_or(0.0, |j| {
        let binds = (0..5).any(|k| 2.0 * acc[k] / j[k] > opts.cycle_s);
        if !binds {
            return 0.0;
        }
        (0..5)
            .map(|k| JERK_FILTER_WIDTH * acc[k] / j[k])
            .fold(0.0, f64::max)
    });
    let feed = opts.feed_mm_per_min / 60.0;
    // Each run's grid, its timed profile and its blocks' `F` words. The grid's constraints
    // (15 numbers a grid point, three times the profile) are dropped once the run is timed: a
    // refinement rebuilds the grid of each run it touches (`run_grid` is a function of the run
    // and the options alone, so the rebuilt grid is the same to the bit) and applies the caps
    // the refinements lowered, which are kept by grid point for the few points they reached.
    let mut timed: Vec<Timed> = Vec::with_capacity(runs.len());
    let mut block_feeds = vec![0.0; blocks.len()];
    let mut grid_points = 0;
    let mut work = PlanWork::default();
    for run in &runs {
        let (s, g) = run_grid(model, run, step, opts);
        grid_points += s.len();
        let tm = time_run(s, &g, acc, limits.max_jerk, tau);
        run_feeds(
            run,
            &g,
            &tm,
            feed * run.feed_factor,
            &mut block_feeds[run.first..=run.last],
        );
        timed.push(tm);
    }
    // By run, sorted by grid point: the cap on `x` the refinements set there (infinite: none)
    // and the factor on the accelerations.
    let mut lowered: Vec<Vec<Lowered>> = vec![Vec::new(); runs.len()];
    let mut refinements = 0;
    loop {
        // Block times, feeds and statistics only when needed (the block clock) or final.
        let full = opts.block_ends_on_cycles;
        let motion = assemble(
            blocks,
            runs,
            timed,
            &block_feeds,
            grid_points,
            opts,
            &names,
            refinements,
            full,
        )?;
        let (worst, range_error) = verify(&motion, model);
        work.verified_cycles += motion.cycles() + 1;
        work.refinements = refinements;
        if worst.is_empty() {
            let motion = if full {
                motion
            } else {
                let Motion {
                    blocks,
                    runs,
                    timed,
                    ..
                } = motion;
                assemble(
                    blocks,
                    runs,
                    timed,
                    &block_feeds,
                    grid_points,
                    opts,
                    &names,
                    refinements,
                    true,
                )?
            };
            if let Some(e) = range_error {
                return Err(e);
            }
            let mut motion = motion;
            work.grid_points += grid_points;
            motion.work = work;
            return Ok(motion);
        }
        if refinements >= opts.max_refinements {
            let v = &worst[0];
            let (block, _) = motion.locate(v.time);
            return Err(InterpError::LimitsNotMet {
                axis: names[v.axis].clone(),
                what: ["velocity", "acceleration", "jerk"][v.kind],
                cycle: v.cycle,
                time_s: v.time,
                block,
                path: motion.blocks.get(block).map_or(0, |b| b.path),
                value: v.value,
                limit: v.limit,
                refinements,
            });
        }
        // Lower the caps of the grid points whose motion the bad cycle sees (the cycle's
        // stencil and, when filtered, the filter's reach), by the excess and a 2 % margin:
        // `(grid point, factor on x, factor on the accelerations)` by run, for the runs touched.
        let mut factors: Vec<Vec<(usize, f64, f64)>> = vec![Vec::new(); motion.runs.len()];
        // Rounds that did not clear a window slow it harder: the factor shrinks by
        // `REPAIR_ESCALATION` every 4 rounds, so within the budget of rounds any slow-down a
        // motion can be followed at is reached (and no rounding can hold a window at a fixed
        // excess: the check allows for the set-points' rounding, `verify::ROUNDING_ULPS`).
        let boost = REPAIR_ESCALATION.powi((refinements / 4) as i32);
        for v in &worst {
            // Per kind over its limit: 2 % under the excess; a kind not over it: no factor.
            let f = |r: f64| {
                if r > 0.0 {
                    0.98 * boost / r.max(1.0)
                } else {
                    1.0
                }
            };
            let [fv, fa, fj] = v.ratios.map(f);
            let (fx, fa) = ((fv * fv).min(fa).min(fj.powf(1.0 / 3.0)), fa.min(fj));
            let (mut lo, mut hi) = (
                v.window[0] - 3.0 * opts.cycle_s,
                v.window[1] + 3.0 * opts.cycle_s,
            );
            if opts.block_ends_on_cycles {
                // The speed jumps where two blocks slowed by different factors meet: lower the
                // whole blocks around the cycle.
                let (b, _) = motion.locate(v.time);
                let bt = &motion.block_times;
                lo = lo.min(bt[b.saturating_sub(1)][0]);
                hi = hi.max(bt[(b + 1).min(bt.len() - 1)][1]);
            }
            // The runs the window touches (the run holding `lo` and those starting up to `hi`).
            let r_lo = motion
                .starts
                .partition_point(|&t| t <= lo)
                .saturating_sub(1);
            let r_hi = motion.starts.partition_point(|&t| t <= hi);
            for r in r_lo..r_hi {
                let tm = &motion.timed[r];
                let (r0, r1) = (motion.starts[r], motion.starts[r] + tm.duration);
                if r1 < lo || r0 > hi {
                    continue;
                }
                let n = tm.t.len();
                let (a, b) = (lo - r0 - tm.tau, hi - r0);
                let i0 = tm.t.partition_point(|&t| t < a).saturating_sub(1);
                let i1 = (tm.t.partition_point(|&t| t <= b) + 1).min(n);
                if i0 < i1 {
                    factors[r].extend((i0..i1).map(|i| (i, fx, fa)));
                } else {
                    // Touched, nothing lowered: planned again all the same.
                    factors[r].push((usize::MAX, 1.0, 1.0));
                }
            }
        }
        Motion {
            blocks,
            runs,
            timed,
            ..
        } = motion;
        for (r, mut f) in factors.into_iter().enumerate() {
            if f.is_empty() {
                continue;
            }
            // The smallest factors of each grid point.
            f.sort_by_key(|e| e.0);
            f.dedup_by(|b, a| {
                if a.0 == b.0 {
                    a.1 = a.1.min(b.1);
                    a.2 = a.2.min(b.2);
                    true
                } else {
                    false
                }
            });
            // Relative to the profile as planned, so that every refinement changes it.
            // (The largest x of the point and its neighbours: the rest at a run's end is no
            // cap.)
            let x = &timed[r].x;
            let n = x.len();
            let near = |i: usize| x[i.saturating_sub(1)].max(x[i]).max(x[(i + 1).min(n - 1)]);
            lowered[r] = merge_lowered(&lowered[r], &f, near);
            let run = &runs[r];
            let (_, mut g) = run_grid(model, run, step, opts);
            for l in &lowered[r] {
                g.cap[l.point] = g.cap[l.point].min(l.cap);
                g.mult_a[l.point] = l.mult_a;
            }
            let s = std::mem::take(&mut timed[r].s);
            work.grid_points += s.len();
            timed[r] = time_run(s, &g, acc, limits.max_jerk, tau);
            if !(run.cutting && run.moves_tip) {
                // A cutting run's `F` words come from the limits alone: unchanged.
                run_feeds(
                    run,
                    &g,
                    &timed[r],
                    feed * run.feed_factor,
                    &mut block_feeds[run.first..=run.last],
                );
            }
        }
        refinements += 1;
    }
}

/// What the refinements set at one grid point of a run: a cap on `x` (infinite: none) and the
/// factor on the accelerations.
#[derive(Debug, Clone, Copy)]
struct Lowered {
    point: usize,
    cap: f64,
    mult_a: f64,
}

/// `old` (sorted by grid point) with this refinement's factors `new` (sorted, one per grid
/// point; a point past the grid touches nothing): the cap at a point becomes the smaller of
/// its cap and `near(point)` times the factor on `x` where that factor is below 1, and its
/// factor on the accelerations is multiplied by the new one, as the whole-grid refinement
/// did point by point.
fn merge_lowered(
    old: &[Lowered],
    new: &[(usize, f64, f64)],
    near: impl Fn(usize) -> f64,
) -> Vec<Lowered> {
    let mut out = Vec::with_capacity(old.len() + new.len());
    let mut a = 0;
    for &(point, fx, fa) in new.iter().take_while(|e| e.0 != usize::MAX) {
        while a < old.len() && old[a].point < point {
            out.push(old[a]);
            a += 1;
        }
        let mut l = if a < old.len() && old[a].point == point {
            a += 1;
            old[a - 1]
        } else {
            Lowered {
                point,
                cap: f64::INFINITY,
                mult_a: 1.0,
            }
        };
        if fx < 1.0 {
            l.cap = l.cap.min(near(point) * fx);
        }
        l.mult_a *= fa;
        out.push(l);
    }
    out.extend_from_slice(&old[a..]);
    out
}
