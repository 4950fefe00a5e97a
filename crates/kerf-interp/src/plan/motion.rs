//! A planned program ([`Motion`]) and its set-points one cycle at a time ([`Cycles`]).

use kerf_kinematics::Axes;

use super::profile::Timed;
use crate::block::Block;
use crate::fit::BlockCounts;
use crate::model::AxisModel;
use crate::smooth::Run;

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

/// The work of one plan, counted (see [`Motion::work`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct PlanWork {
    /// Grid points the time-optimal solver worked on, summed over the first plan and every
    /// re-plan of a run after a refinement.
    pub grid_points: usize,
    /// Set-points computed by the verifications (each verification computes every cycle of the
    /// program once).
    pub verified_cycles: usize,
    /// Refinements (re-plans after a verification found a cycle over a limit).
    pub refinements: usize,
}

/// A planned program: blocks, their feed profile, and the set-points it gives.
#[derive(Debug, Clone)]
pub struct Motion {
    pub(super) blocks: Vec<Block>,
    pub(super) runs: Vec<Run>,
    pub(super) timed: Vec<Timed>,
    /// Start time of each run in the program.
    pub(super) starts: Vec<f64>,
    pub(super) duration: f64,
    pub(super) cycle: f64,
    pub(super) refinements: usize,
    pub(super) grid_points: usize,
    /// The planner's work, counted (set once the plan is verified).
    pub(super) work: PlanWork,
    pub(super) axis_names: [String; 5],
    /// Start and end time of each block.
    pub(super) block_times: Vec<[f64; 2]>,
    /// F word of each block, mm/s.
    pub(super) feeds: Vec<f64>,
    /// With [`PlanOptions::block_ends_on_cycles`](super::PlanOptions::block_ends_on_cycles): when each block runs.
    pub(super) clock: Option<Vec<BlockClock>>,
    pub(super) total_cycles: usize,
    pub(super) stats: Vec<PathStats>,
}

/// The cycles of one block when block ends land on cycles: cycles `first..first + n`, mapped
/// linearly onto the block's planned time `start..start + duration`.
#[derive(Debug, Clone, Copy)]
pub(super) struct BlockClock {
    pub(super) first: usize,
    pub(super) n: usize,
    pub(super) start: f64,
    pub(super) duration: f64,
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

    /// What planning this motion cost, counted: grid points over every plan and re-plan, and
    /// set-points computed by the verifications. Bounded by the program, not by how the
    /// rounding falls: the tests hold these counts, never a time.
    pub fn work(&self) -> PlanWork {
        self.work
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
    /// motion (with [`PlanOptions::block_ends_on_cycles`](super::PlanOptions::block_ends_on_cycles), before each block is slowed to whole
    /// cycles).
    pub fn locate(&self, t: f64) -> (usize, f64) {
        if self.runs.is_empty() {
            return (0, 0.0);
        }
        let r = self.starts.partition_point(|&s| s <= t).saturating_sub(1);
        let s = self.timed[r].s_at(t - self.starts[r]);
        self.runs[r].block_at(s)
    }

    /// The largest distance of the tip, over every set-point, from the smooth path before the
    /// blend of curvature changes ([`PlanOptions::blend_tolerance_mm`](super::PlanOptions)), mm:
    /// measured on the set-points' own path parameters, so it is what the blend really cost;
    /// at most the blend tolerance, 0 without jerk limits.
    pub fn blend_deviation(&self) -> f64 {
        if !self.runs.iter().any(Run::blended) {
            return 0.0;
        }
        let mut worst = 0.0f64;
        let mut r = 0;
        for i in 0..=self.total_cycles {
            let t = i as f64 * self.cycle;
            while r + 1 < self.runs.len() && t >= self.starts[r + 1] {
                r += 1;
            }
            let s = self.timed[r].s_at(t - self.starts[r]);
            let run = &self.runs[r];
            if run.blended() {
                let (tip, _) = run.pose(s);
                worst = worst.max((tip - run.spline_tip(s)).norm());
            }
        }
        worst
    }

    /// The set-points, one per cycle, computed by [`Motion::iter`].
    pub fn setpoints<M: AxisModel + ?Sized>(&self, model: &M) -> Vec<Axes> {
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
    pub(super) fn cycle_time(&self, i: usize, run: &mut usize, block: &mut usize) -> Timepoint {
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
    pub(super) fn axes_at_time<M: AxisModel + ?Sized>(
        &self,
        model: &M,
        t: f64,
        run: &mut usize,
    ) -> Axes {
        while *run + 1 < self.runs.len() && t >= self.starts[*run + 1] {
            *run += 1;
        }
        let r = *run;
        let s = self.timed[r].s_at(t - self.starts[r]);
        self.runs[r].axes_at(model, &self.blocks, s)
    }
}

pub(super) enum Timepoint {
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
    pub(super) fn next_full(&mut self) -> Option<(Axes, f64, usize)> {
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
    type Item = Axes;

    #[inline]
    fn next(&mut self) -> Option<Axes> {
        self.next_full().map(|(q, _, _)| q)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.n + 1).saturating_sub(self.i);
        (left, Some(left))
    }
}
