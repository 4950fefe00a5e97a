//! The runs' profiles put together into a program: start times, block times and `F` words,
//! the block clock, statistics.

use super::motion::{BlockClock, Motion, PathStats};
use super::profile::Timed;
use super::PlanOptions;
use crate::block::Block;
use crate::error::{InterpError, Result};
use crate::smooth::Run;

/// Puts the runs' profiles together into a program: start times, block times and feeds, the
/// block clock, statistics. The blocks, runs and profiles are moved into the [`Motion`], not
/// copied (a refinement takes them back out); `block_feeds` are the blocks' `F` words before
/// the modal stretches ([`super::profile::run_feeds`]), `grid_points` the size of the grid.
#[allow(clippy::too_many_arguments)]
pub(super) fn assemble(
    blocks: Vec<Block>,
    runs: Vec<Run>,
    timed: Vec<Timed>,
    block_feeds: &[f64],
    grid_points: usize,
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
    let cycles = total / opts.cycle_s;
    if cycles.is_nan() || cycles > opts.max_cycles as f64 {
        return Err(InterpError::TooManyCycles {
            cycles,
            limit: opts.max_cycles,
        });
    }
    let feed = opts.feed_mm_per_min / 60.0;
    let mut block_times = vec![[0.0; 2]; blocks.len()];
    let mut feeds = vec![0.0; blocks.len()];
    let mut stats: Vec<PathStats> = Vec::new();
    for (r, run) in runs.iter().enumerate() {
        if !full {
            break;
        }
        let tm = &timed[r];
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
        }
        feeds[run.first..=run.last].copy_from_slice(&block_feeds[run.first..=run.last]);
        if run.cutting && run.moves_tip {
            modal_feeds(&mut feeds[run.first..=run.last], feed * run.feed_factor);
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
            st.cutting_length += run.tip_len;
            // Sample the run at half a cycle, at most 64 samples a grid point (the profile is
            // one polynomial per grid interval): a 10 us cycle would otherwise sample a 189 s
            // circle 38 M times for a share.
            let dt = opts.cycle_s / 2.0;
            let steps = ((tm.duration / dt).ceil() as usize).min(64 * tm.s.len());
            let dt = tm.duration / steps.max(1) as f64;
            for k in 0..steps {
                let t = (k as f64 + 0.5) * dt;
                let s = tm.s_at(t);
                let (t1, _) = run.tip_derivatives(s);
                let v = tm.speed_at(t) * t1.norm();
                if v >= feed * run.feed_factor * 0.999 {
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
                let n = ((d / opts.cycle_s - 1e-9).ceil() as usize).max(1);
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
        duration = first as f64 * opts.cycle_s;
        clock
    });
    if total_cycles > opts.max_cycles {
        return Err(InterpError::TooManyCycles {
            cycles: total_cycles as f64,
            limit: opts.max_cycles,
        });
    }
    Ok(Motion {
        blocks,
        runs,
        timed,
        starts,
        duration,
        cycle: opts.cycle_s,
        refinements,
        grid_points,
        work: super::motion::PlanWork::default(),
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
pub(super) fn modal_feeds(feeds: &mut [f64], programmed: f64) {
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
