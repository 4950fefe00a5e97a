//! The feed along the path: a look-ahead plan that keeps every axis within its velocity and
//! acceleration limits, in every interpolation cycle, and stops at the end.
//!
//! The program is a chain of *pieces*: the blocks, with each arc split at its intermediate
//! point where the rotary axes change slope. Along a piece the machine axes are functions
//! `q(s)` of the path parameter `s` (tip arc length), so with path speed `v = ds/dt` and path
//! acceleration `a`:
//!
//! ```text
//! dq/dt = q'(s) v,    d2q/dt2 = q''(s) v^2 + q'(s) a.
//! ```
//!
//! Per piece, `max |q'_k|` and `max |q''_k|` are measured on samples of the piece, and the
//! acceleration budget of each axis is split: `F_TANGENT` of it for the path acceleration,
//! `F_CURVATURE` for the curvature term and `F_JUNCTION` for the velocity jump at a corner
//! between pieces (where `q'` jumps by `dq'`, a cycle sees the change `|dq'| v`, i.e. an
//! acceleration `|dq'| v / T`). That gives per piece a speed cap
//! `min(F, chord cap, vmax_k / |q'_k|, sqrt(F_CURVATURE amax_k / |q''_k|))`, an acceleration
//! cap `F_TANGENT amax_k / |q'_k|`, and per junction the cap `F_JUNCTION amax_k T / |dq'_k|`.
//! The look-ahead is the classic two-pass plan on `v^2` (backward from the stop at the end,
//! forward from rest at the start), then a trapezoid (accelerate, cruise, decelerate) per piece.
//!
//! The set-points are the plan sampled every `T` seconds. Finally the plan is **verified the
//! way a test would**: velocities `(q_i - q_{i-1}) / T` and accelerations
//! `(q_{i+1} - 2 q_i + q_{i-1}) / T^2` of every axis in every cycle, at rest before the first
//! and after the last set-point. Where a cycle exceeds a limit (sampling missed a peak, or
//! several corners fall into one cycle), the caps of the pieces around it are lowered and the
//! plan is redone, until every cycle is within the limits.

use crate::block::{Block, Geometry};
use crate::chord::max_step;
use crate::error::{positive, InterpError, Result};
use crate::fit::BlockCounts;
use crate::model::AxisModel;

/// Share of each axis' acceleration limit given to the path acceleration.
pub const F_TANGENT: f64 = 0.4;
/// Share of each axis' acceleration limit given to the curvature of the axis path.
pub const F_CURVATURE: f64 = 0.3;
/// Share of each axis' acceleration limit given to the velocity jump at a corner.
pub const F_JUNCTION: f64 = 0.25;

/// Options of [`plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlanOptions {
    /// Programmed cutting feed, mm/min (the tip's speed along the path). Must be > 0.
    pub feed: f64,
    /// Interpolation cycle `T`, seconds. Must be > 0.
    pub cycle: f64,
    /// Largest chord error between two set-points on an arc, mm (paper 000 eq 17-18): caps
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
    /// lowers the caps until those jumps are within the acceleration limits), so it costs
    /// cycle time on programs of many short blocks. With false the set-points sample one
    /// continuous motion; block ends fall between cycles, the program's end is still exact.
    pub block_ends_on_cycles: bool,
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
        }
    }

    fn validate(&self) -> Result<()> {
        positive("feed", self.feed)?;
        positive("cycle", self.cycle)?;
        positive("chord_tolerance", self.chord_tolerance)?;
        Ok(())
    }
}

/// A part of a block with smooth axis motion.
#[derive(Debug, Clone)]
struct Piece {
    block: usize,
    s0: f64,
    len: f64,
    vcap: f64,
    acap: f64,
    /// `dq/ds` at the start and the end.
    d1_start: [f64; 5],
    d1_end: [f64; 5],
}

/// Trapezoidal profile of one piece.
#[derive(Debug, Clone, Copy, Default)]
struct Profile {
    v0: f64,
    vp: f64,
    acc: f64,
    ta: f64,
    tc: f64,
    td: f64,
    da: f64,
    dc: f64,
    len: f64,
}

impl Profile {
    fn duration(&self) -> f64 {
        self.ta + self.tc + self.td
    }

    #[inline]
    fn distance(&self, t: f64) -> f64 {
        let s = if t < self.ta {
            self.v0 * t + 0.5 * self.acc * t * t
        } else if t < self.ta + self.tc {
            self.da + self.vp * (t - self.ta)
        } else if t < self.ta + self.tc + self.td {
            let u = t - self.ta - self.tc;
            self.da + self.dc + self.vp * u - 0.5 * self.acc * u * u
        } else {
            self.len
        };
        s.clamp(0.0, self.len)
    }
}

/// A planned program: blocks, their feed profile, and the set-points it gives.
#[derive(Debug, Clone)]
pub struct Motion {
    blocks: Vec<Block>,
    pieces: Vec<Piece>,
    profiles: Vec<Profile>,
    /// Start time of each piece.
    starts: Vec<f64>,
    duration: f64,
    cycle: f64,
    refinements: usize,
    axis_names: [String; 5],
    peak_speed: Vec<f64>,
    /// With [`PlanOptions::block_ends_on_cycles`]: when each block runs.
    clock: Option<Vec<BlockClock>>,
    total_cycles: usize,
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

    /// How many times the verification lowered caps and planned again.
    pub fn refinements(&self) -> usize {
        self.refinements
    }

    /// Axis names (CSV header).
    pub fn axis_names(&self) -> [&str; 5] {
        std::array::from_fn(|k| self.axis_names[k].as_str())
    }

    /// The highest planned tip speed within block `b`, mm/min (what a G-code `F` word for that
    /// block would say); 0 for an index out of range.
    pub fn block_feed(&self, b: usize) -> f64 {
        self.peak_speed.get(b).copied().unwrap_or(0.0) * 60.0
    }

    /// The planned time of block `b` from its start to its end, seconds: what an inverse-time
    /// (`G93`) feed word must say for the controller to follow this plan
    /// (`F = 60 / block_duration` in 1/min); 0 for an index out of range.
    pub fn block_duration(&self, b: usize) -> f64 {
        self.pieces
            .iter()
            .zip(&self.profiles)
            .filter(|(p, _)| p.block == b)
            .map(|(_, pr)| pr.duration())
            .sum()
    }

    /// [`Motion::block_feed`] of every block, for the `F` words of [`crate::gcode`].
    pub fn block_feeds(&self) -> Vec<f64> {
        (0..self.blocks.len()).map(|b| self.block_feed(b)).collect()
    }

    /// The block index and path parameter at time `t` (seconds from the start) of the planned
    /// motion (with [`PlanOptions::block_ends_on_cycles`], before each block is slowed to whole
    /// cycles).
    pub fn locate(&self, t: f64) -> (usize, f64) {
        let p = self.starts.partition_point(|&s| s <= t).saturating_sub(1);
        self.locate_from(p, t).1
    }

    #[inline]
    fn locate_from(&self, mut p: usize, t: f64) -> (usize, (usize, f64)) {
        if self.pieces.is_empty() {
            return (0, (0, 0.0));
        }
        while p + 1 < self.pieces.len() && t >= self.starts[p + 1] {
            p += 1;
        }
        let piece = &self.pieces[p];
        let s = piece.s0 + self.profiles[p].distance(t - self.starts[p]);
        (p, (piece.block, s))
    }

    /// The set-points, one per cycle, computed by [`Motion::iter`].
    pub fn setpoints<M: AxisModel + ?Sized>(&self, model: &M) -> Vec<[f64; 5]> {
        let mut out = Vec::with_capacity(self.cycles() + 1);
        out.extend(self.iter(model));
        out
    }

    /// The set-points one cycle at a time, as a controller computes them: cycle `i` is the
    /// plan at `t = i T`, its position computed from its block's start and the path parameter
    /// (never by summing increments). The last set-point is exactly the program's end.
    pub fn iter<'a, M: AxisModel + ?Sized>(&'a self, model: &'a M) -> Cycles<'a, M> {
        Cycles {
            motion: self,
            model,
            i: 0,
            n: self.cycles(),
            piece: 0,
            block: 0,
        }
    }
}

/// Iterator over the set-points of a [`Motion`], one per cycle.
#[derive(Debug)]
pub struct Cycles<'a, M: ?Sized> {
    motion: &'a Motion,
    model: &'a M,
    i: usize,
    n: usize,
    piece: usize,
    block: usize,
}

impl<M: AxisModel + ?Sized> Cycles<'_, M> {
    /// The set-point of the next cycle and the index of its piece (internal).
    #[inline]
    fn next_with_piece(&mut self) -> Option<([f64; 5], usize)> {
        if self.i > self.n || self.motion.blocks.is_empty() {
            return None;
        }
        let m = self.motion;
        let q = if self.i == self.n {
            self.piece = m.pieces.len().saturating_sub(1);
            m.blocks[m.blocks.len() - 1].end_axes
        } else {
            let t = match &m.clock {
                Some(clock) => {
                    while self.block + 1 < clock.len() && self.i >= clock[self.block + 1].first {
                        self.block += 1;
                    }
                    let c = &clock[self.block];
                    c.start + (self.i - c.first) as f64 / c.n as f64 * c.duration
                }
                None => self.i as f64 * m.cycle,
            };
            let (p, (b, s)) = m.locate_from(self.piece, t);
            self.piece = p;
            m.blocks[b].axes_at(self.model, s)
        };
        self.i += 1;
        Some((q, self.piece))
    }
}

impl<M: AxisModel + ?Sized> Iterator for Cycles<'_, M> {
    type Item = [f64; 5];

    #[inline]
    fn next(&mut self) -> Option<[f64; 5]> {
        self.next_with_piece().map(|(q, _)| q)
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
    let mut pieces = Vec::new();
    for (bi, b) in blocks.iter().enumerate() {
        if !b.length().is_finite() {
            return Err(InterpError::NonFinite { index: bi });
        }
        let mid = b.mid_length();
        if b.is_arc() && mid > 0.0 && mid < b.length() {
            pieces.push(make_piece(model, b, bi, 0.0, mid, opts));
            pieces.push(make_piece(model, b, bi, mid, b.length(), opts));
        } else {
            pieces.push(make_piece(model, b, bi, 0.0, b.length(), opts));
        }
    }
    let jcap: Vec<f64> = pieces
        .windows(2)
        .map(|w| {
            let mut cap = f64::INFINITY;
            for k in 0..5 {
                let jump = (w[0].d1_end[k] - w[1].d1_start[k]).abs();
                if jump > 0.0 {
                    cap = cap.min(F_JUNCTION * limits.max_acceleration[k] * opts.cycle / jump);
                }
            }
            cap
        })
        .collect();
    let mut mult = vec![1.0; pieces.len()];
    let mut mult_a = vec![1.0; pieces.len()];
    let mut refinements = 0;
    loop {
        let profiles = lookahead(&pieces, &jcap, &mult, &mult_a);
        let mut starts = Vec::with_capacity(pieces.len());
        let mut t = 0.0;
        for p in &profiles {
            starts.push(t);
            t += p.duration();
        }
        let cycles = t / opts.cycle;
        if cycles.is_nan() || cycles > opts.max_cycles as f64 {
            return Err(InterpError::TooManyCycles {
                cycles,
                limit: opts.max_cycles,
            });
        }
        let mut total_cycles = (cycles - 1e-9).ceil().max(0.0) as usize;
        let mut duration = t;
        let clock = opts.block_ends_on_cycles.then(|| {
            let mut clock: Vec<BlockClock> = Vec::with_capacity(blocks.len());
            let mut first = 0;
            for (p, piece) in pieces.iter().enumerate() {
                let d = profiles[p].duration();
                match clock.last_mut() {
                    Some(c) if pieces[p - 1].block == piece.block => c.duration += d,
                    _ => clock.push(BlockClock {
                        first: 0,
                        n: 0,
                        start: starts[p],
                        duration: d,
                    }),
                }
            }
            for c in &mut clock {
                c.first = first;
                c.n = ((c.duration / opts.cycle - 1e-9).ceil() as usize).max(1);
                first += c.n;
            }
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
        let mut peak_speed = vec![0.0f64; blocks.len()];
        for (p, pr) in pieces.iter().zip(&profiles) {
            peak_speed[p.block] = peak_speed[p.block].max(pr.vp);
        }
        let motion = Motion {
            blocks: blocks.clone(),
            pieces: pieces.clone(),
            profiles,
            starts,
            duration,
            cycle: opts.cycle,
            refinements,
            axis_names: names.clone(),
            peak_speed,
            clock,
            total_cycles,
        };
        let worst = verify(&motion, model);
        if worst.is_empty() {
            check_ranges(&motion, model)?;
            return Ok(motion);
        }
        if refinements >= opts.max_refinements {
            let v = &worst[0];
            return Err(InterpError::LimitsNotMet {
                axis: names[v.axis].clone(),
                what: if v.acceleration {
                    "acceleration"
                } else {
                    "velocity"
                },
                cycle: v.cycle,
                value: v.value,
                limit: v.limit,
            });
        }
        // Lower the caps of the pieces around each bad cycle, once per piece, by the worst
        // ratio seen there (and a 5 % margin).
        let mut ratio_v = vec![1.0f64; pieces.len()];
        let mut ratio_a = vec![1.0f64; pieces.len()];
        for v in &worst {
            let ratio = v.value / v.limit;
            for p in v.pieces[0]..=v.pieces[1] {
                ratio_v[p] = ratio_v[p].max(ratio);
                if v.acceleration {
                    ratio_a[p] = ratio_a[p].max(ratio);
                }
            }
        }
        for p in 0..pieces.len() {
            if ratio_v[p] > 1.0 - 1e-6 {
                mult[p] *= 0.95 / ratio_v[p].max(1.0);
            }
            if ratio_a[p] > 1.0 - 1e-6 {
                mult_a[p] *= 0.95 / ratio_a[p].max(1.0);
            }
        }
        refinements += 1;
    }
}

/// Caps of one piece from samples of its axis path.
fn make_piece<M: AxisModel + ?Sized>(
    model: &M,
    b: &Block,
    block: usize,
    s0: f64,
    s1: f64,
    opts: &PlanOptions,
) -> Piece {
    let lim = model.limits();
    let len = s1 - s0;
    let q0 = b.axes_at(model, s0);
    let q1 = b.axes_at(model, s1);
    let rot = (q1[3] - q0[3]).abs().max((q1[4] - q0[4]).abs());
    let sweep = match &b.geometry {
        Geometry::Arc(a) => len / a.radius,
        _ => 0.0,
    };
    // Samples: at least 4, one per 0.25 mm, per 2 degrees of sweep or of rotary travel.
    let m = ((len / 0.25)
        .max(sweep.to_degrees() / 2.0)
        .max(rot / 2.0)
        .ceil() as usize)
        .clamp(4, 256);
    let h = len / m as f64;
    let q: Vec<[f64; 5]> = (0..=m)
        .map(|i| {
            let s = if i == m { s1 } else { s0 + i as f64 * h };
            // Inside the piece, evaluate from its own side of an arc's mid point.
            b.axes_at(model, s)
        })
        .collect();
    let mut d1 = [0.0f64; 5];
    let mut d2 = [0.0f64; 5];
    for i in 0..m {
        for k in 0..5 {
            d1[k] = d1[k].max(((q[i + 1][k] - q[i][k]) / h).abs());
            if i + 1 < m {
                d2[k] = d2[k].max(((q[i + 2][k] - 2.0 * q[i + 1][k] + q[i][k]) / (h * h)).abs());
            }
        }
    }
    // One-sided derivatives at the ends, for the corner jumps.
    let he = (len * 1e-4).max(1e-9).min(len);
    let qa = b.axes_at(model, s0 + he);
    let qb = b.axes_at(model, s1 - he);
    let d1_start = std::array::from_fn(|k| (qa[k] - q0[k]) / he);
    let d1_end = std::array::from_fn(|k| (q1[k] - qb[k]) / he);
    let mut vcap = if b.rapid || matches!(b.geometry, Geometry::Turn { .. }) {
        f64::INFINITY
    } else {
        opts.feed / 60.0
    };
    if let Geometry::Arc(a) = &b.geometry {
        vcap = vcap.min(max_step(a.radius, opts.chord_tolerance) / opts.cycle);
    }
    let mut acap = f64::INFINITY;
    for k in 0..5 {
        let dk = d1[k].max(d1_start[k].abs()).max(d1_end[k].abs()) * 1.02;
        if dk > 0.0 {
            vcap = vcap.min(lim.max_velocity[k] / dk);
            acap = acap.min(F_TANGENT * lim.max_acceleration[k] / dk);
        }
        if d2[k] > 0.0 {
            vcap = vcap.min((F_CURVATURE * lim.max_acceleration[k] / (d2[k] * 1.05)).sqrt());
        }
    }
    // A piece that moves no axis (cannot happen with a positive length on a real machine):
    // keep the numbers finite.
    if !vcap.is_finite() {
        vcap = 1e9;
    }
    if !acap.is_finite() {
        acap = 1e12;
    }
    Piece {
        block,
        s0,
        len,
        vcap,
        acap,
        d1_start,
        d1_end,
    }
}

/// The two-pass look-ahead and the trapezoid of each piece.
fn lookahead(pieces: &[Piece], jcap: &[f64], mult: &[f64], mult_a: &[f64]) -> Vec<Profile> {
    let n = pieces.len();
    if n == 0 {
        return Vec::new();
    }
    let vmax: Vec<f64> = (0..n).map(|p| pieces[p].vcap * mult[p]).collect();
    let acc: Vec<f64> = (0..n).map(|p| pieces[p].acap * mult_a[p]).collect();
    // ve[p]: speed at the end of piece p; the junction p | p+1.
    let mut ve = vec![0.0; n];
    for p in 0..n - 1 {
        ve[p] = vmax[p]
            .min(vmax[p + 1])
            .min(jcap[p] * mult[p].min(mult[p + 1]));
    }
    ve[n - 1] = 0.0;
    // Backward: each piece must be able to brake to its end speed.
    for p in (1..n).rev() {
        let reach = (ve[p] * ve[p] + 2.0 * acc[p] * pieces[p].len).sqrt();
        ve[p - 1] = ve[p - 1].min(reach);
    }
    // Forward: from rest.
    let mut v0 = 0.0;
    let mut out = Vec::with_capacity(n);
    for p in 0..n {
        let (a, len) = (acc[p], pieces[p].len);
        let v1 = ve[p].min((v0 * v0 + 2.0 * a * len).sqrt());
        let peak = ((2.0 * a * len + v0 * v0 + v1 * v1) / 2.0).sqrt();
        let vp = vmax[p].min(peak).max(v0).max(v1);
        let da = ((vp * vp - v0 * v0) / (2.0 * a)).max(0.0);
        let dd = ((vp * vp - v1 * v1) / (2.0 * a)).max(0.0);
        let dc = (len - da - dd).max(0.0);
        let tc = if vp > 0.0 { dc / vp } else { 0.0 };
        out.push(Profile {
            v0,
            vp,

            acc: a,
            ta: (vp - v0) / a,
            tc,
            td: (vp - v1) / a,
            da,
            dc,
            len,
        });
        v0 = v1;
    }
    out
}

/// A cycle over a limit.
#[derive(Debug, Clone)]
struct Violation {
    cycle: usize,
    axis: usize,
    acceleration: bool,
    value: f64,
    limit: f64,
    pieces: [usize; 2],
}

/// Every cycle over a limit, worst first (at most one per cycle).
fn verify<M: AxisModel + ?Sized>(motion: &Motion, model: &M) -> Vec<Violation> {
    let lim = model.limits();
    let t = motion.cycle;
    let mut out = Vec::new();
    let slack = 1.0 - 1e-6;
    // Rows i - 2 .. i + 1 streamed from the iterator, so memory does not grow with the
    // program; rows before the first and after the last are the first and the last (rest).
    let mut it = motion.iter(model);
    let n = it.size_hint().0;
    let Some(first) = it.next_with_piece() else {
        return out;
    };
    let (mut r2, mut r1, mut r0) = (first, first, first);
    let mut r3 = it.next_with_piece().unwrap_or(r0);
    for i in 0..=n {
        let (qm, q0, qp) = (r1.0, r0.0, r3.0);
        let mut worst: Option<Violation> = None;
        for k in 0..5 {
            let v = ((q0[k] - qm[k]) / t).abs();
            let a = ((qp[k] - 2.0 * q0[k] + qm[k]) / (t * t)).abs();
            for (value, limit, acceleration) in [
                (v, lim.max_velocity[k], false),
                (a, lim.max_acceleration[k], true),
            ] {
                if value > limit * slack
                    && worst
                        .as_ref()
                        .is_none_or(|w| value / limit > w.value / w.limit)
                {
                    worst = Some(Violation {
                        cycle: i,
                        axis: k,
                        acceleration,
                        value,
                        limit,
                        pieces: [r2.1, r3.1],
                    });
                }
            }
        }
        out.extend(worst);
        (r2, r1, r0) = (r1, r0, r3);
        r3 = it.next_with_piece().unwrap_or(r0);
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
