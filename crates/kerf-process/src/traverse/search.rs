//! Where no route shape clears: a search for a path around the part, the head turned to one
//! tool axis for the travel (upright, or the pierce's or the exit's), on a lattice of tip
//! positions whose spacing is an eighth of the clearance, within a counted work budget.
//!
//! Along the lattice's third axis lies the travel's tool axis, so the nozzle over a lattice
//! point covers the lattice points above it: one distance per lattice point serves every
//! nozzle that passes it. A lattice point's *slack* is a lower bound of how much more than the
//! need (the clearance and a 32nd of it) the tip and the nozzle keep there: the smallest
//! distance of the lattice points along the nozzle (spaced `g`, the nozzle's length rounded up
//! to whole steps) less `g / 2`, less the need (the distance is 1-Lipschitz, so every point of
//! the nozzle is within `g / 2` of a sample). A straight move between two points with slacks
//! `s_p` and `s_q` keeps the need where `s_p + s_q >= |p - q|` (a point `t` along it keeps
//! `max(s_p - t, s_q - (|p - q| - t)) >= 0` more than the need, as the nozzle there is
//! `t` from the one at `p`): the lattice's moves, and the joins to the retract points, are
//! proven so; the path found is then shortened by straight moves checked like every other
//! travel (`Trace`), and the route is checked as any other (`docs/process.md`).
//!
//! The search runs from both ends at once (weighted A*: cost so far plus twice the straight
//! distance to the nearest end on the other side, the side with the smaller frontier first),
//! and stops where the two meet. Every distance query and every expansion spends one unit of
//! the work budget, so the search ends within it whatever the geometry.

use std::collections::{BinaryHeap, HashMap};
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::{Point3, Vector3};

use super::check::{Trace, Work};
use super::{Obstacles, TraverseOptions};
use crate::Pose;

/// A lattice point: integer coordinates along the lattice's three axes.
type Cell = (i32, i32, i32);

/// A fast hash of lattice points (the standard one is made for untrusted keys; these are not).
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.mix(u64::from(b));
        }
    }

    fn write_i32(&mut self, i: i32) {
        self.mix(u64::from(i as u32));
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl CellHasher {
    fn mix(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

type CellMap<V> = HashMap<Cell, V, BuildHasherDefault<CellHasher>>;

/// How far apart the lattice points are, as a fraction of the clearance.
const SPACING: f64 = 1.0 / 4.0;

/// How many samples along the nozzle per lattice step (the nozzle is sampled every eighth of
/// the clearance).
const NOZZLE_SAMPLES: i32 = 2;

/// What the lattice keeps beyond the clearance, as a fraction of it: more than the margin of
/// the checks (a 64th), so that the straight moves made of the path pass them.
const EXTRA: f64 = 1.0 / 32.0;

/// The weight of the heuristic (the straight distance to the other side's nearest end).
const WEIGHT: f64 = 2.0;

/// The lattice of tip positions with the travel's tool axis `m` along its third axis.
struct Lattice<'a> {
    obs: &'a Obstacles,
    origin: Point3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
    m: Vector3<f64>,
    g: f64,
    need: f64,
    nozzle: f64,
    /// The nozzle's length in lattice steps (rounded up).
    column: i32,
    /// Samples along the nozzle per lattice step.
    sub: i32,
    /// Distances are exact below this (enough for a slack of two steps); above it a lower
    /// bound at least this.
    cap: f64,
    dist: CellMap<f64>,
    slack: CellMap<f64>,
}

impl<'a> Lattice<'a> {
    fn at(&self, k: Cell) -> Point3<f64> {
        self.origin
            + self.e1 * (f64::from(k.0) * self.g)
            + self.e2 * (f64::from(k.1) * self.g)
            + self.m * (f64::from(k.2) * self.g)
    }

    /// The lattice cell containing `p` (its lowest corner).
    fn cell_of(&self, p: &Point3<f64>) -> Option<Cell> {
        let d = p - self.origin;
        let c = |v: f64| {
            let f = (v / self.g).floor();
            (f.abs() < 1e9).then_some(f as i32)
        };
        Some((c(d.dot(&self.e1))?, c(d.dot(&self.e2))?, c(d.dot(&self.m))?))
    }

    /// The distance at the column point `k` (its third coordinate in steps of `g / sub`).
    fn point_distance(&mut self, k: Cell, work: &mut Work) -> Option<f64> {
        if let Some(d) = self.dist.get(&k) {
            return Some(*d);
        }
        if work.left == 0 {
            return None;
        }
        work.left -= 1;
        let p = self.origin
            + self.e1 * (f64::from(k.0) * self.g)
            + self.e2 * (f64::from(k.1) * self.g)
            + self.m * (f64::from(k.2) * self.g / f64::from(self.sub));
        let d = self.obs.distance_below(&p, self.cap);
        self.dist.insert(k, d);
        Some(d)
    }

    /// The slack of the lattice point `k` (negative where the nozzle there is not clear).
    fn slack(&mut self, k: Cell, work: &mut Work) -> Option<f64> {
        if let Some(s) = self.slack.get(&k) {
            return Some(*s);
        }
        let h = self.g / f64::from(self.sub);
        let mut least = f64::INFINITY;
        for t in 0..=self.column * self.sub {
            least = least.min(self.point_distance((k.0, k.1, k.2 * self.sub + t), work)?);
            if least < self.need + 0.5 * h {
                break;
            }
        }
        let s = least - 0.5 * h - self.need;
        self.slack.insert(k, s);
        Some(s)
    }

    /// The slack of an arbitrary tip position `p` with the axis `m` (its nozzle sampled every
    /// quarter step).
    fn slack_at(&self, p: &Point3<f64>, work: &mut Work) -> Option<f64> {
        let k = ((self.nozzle / (0.25 * self.g)).ceil() as usize).max(1);
        let h = self.nozzle / k as f64;
        let mut least = f64::INFINITY;
        for j in 0..=k {
            if work.left == 0 {
                return None;
            }
            work.left -= 1;
            least = least.min(
                self.obs
                    .distance_below(&(p + self.m * (h * j as f64)), self.cap),
            );
        }
        Some(least - 0.5 * h - self.need)
    }
}

/// One end of the search: a retract point (the tip there with the travel's axis).
#[derive(Debug, Clone, Copy)]
struct End {
    at: Point3<f64>,
    /// The length of the axial move to it, mm.
    cost: f64,
    slack: f64,
}

/// Where a lattice point was reached from.
#[derive(Debug, Clone, Copy)]
enum From {
    End(usize),
    Cell(Cell),
}

/// An entry of the frontier: the estimate first (smallest first), then the cost so far.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    f: f64,
    g: f64,
    k: Cell,
}

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then(other.g.total_cmp(&self.g))
            .then(other.k.cmp(&self.k))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

/// One side of the search.
#[derive(Default)]
struct Side {
    open: BinaryHeap<Entry>,
    best: CellMap<(f64, From)>,
}

impl Side {
    /// The chain of lattice points from `k` back to its end, and that end.
    fn chain(&self, k: Cell) -> (Vec<Cell>, usize) {
        let mut out = vec![k];
        let mut cur = k;
        // Each step goes to a strictly cheaper point, so the chain ends; bounded anyway.
        for _ in 0..self.best.len() + 1 {
            match self.best.get(&cur).map(|b| b.1) {
                Some(From::Cell(p)) => {
                    out.push(p);
                    cur = p;
                }
                Some(From::End(e)) => return (out, e),
                None => break,
            }
        }
        (out, 0)
    }
}

/// The lattice path between an end on each side: `(source, target, points)`, the points from
/// the source's side to the target's, both ends' own points not included.
type Found = (usize, usize, Vec<Point3<f64>>);

fn bidirectional(
    lat: &mut Lattice<'_>,
    sources: &[End],
    targets: &[End],
    work: &mut Work,
) -> Option<Found> {
    let ends = [sources, targets];
    let heuristic = |side: usize, p: &Point3<f64>| {
        ends[1 - side]
            .iter()
            .map(|e| (e.at - p).norm() + e.cost)
            .fold(f64::INFINITY, f64::min)
    };
    let mut sides = [Side::default(), Side::default()];
    // Join each end to the corners of its lattice cell that the bubble rule allows.
    for side in 0..2 {
        for (i, e) in ends[side].iter().enumerate() {
            let base = lat.cell_of(&e.at)?;
            for corner in 0..8 {
                let k = (
                    base.0 + (corner & 1),
                    base.1 + ((corner >> 1) & 1),
                    base.2 + ((corner >> 2) & 1),
                );
                let sk = lat.slack(k, work)?;
                let len = (lat.at(k) - e.at).norm();
                if sk <= 0.0 || sk + e.slack < len {
                    continue;
                }
                let g = e.cost + len;
                if sides[side].best.get(&k).is_none_or(|b| g < b.0) {
                    if sides[1 - side].best.contains_key(&k) {
                        sides[side].best.insert(k, (g, From::End(i)));
                        return Some(meet(lat, &sides, k));
                    }
                    sides[side].best.insert(k, (g, From::End(i)));
                    let f = g + WEIGHT * heuristic(side, &lat.at(k));
                    sides[side].open.push(Entry { f, g, k });
                }
            }
        }
    }
    loop {
        // A side whose frontier is empty has reached every lattice point it can (the moves
        // are symmetric); had that held a point of the other side, they would have met.
        if sides[0].open.is_empty() || sides[1].open.is_empty() {
            return None;
        }
        let side = usize::from(sides[1].open.len() < sides[0].open.len());
        let Entry { g, k, .. } = sides[side].open.pop()?;
        if sides[side].best.get(&k).is_some_and(|b| b.0 < g) {
            continue; // a stale entry
        }
        if work.left == 0 {
            return None;
        }
        work.left -= 1;
        let sk = lat.slack(k, work)?;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if (dx, dy, dz) == (0, 0, 0) {
                        continue;
                    }
                    let q = (k.0 + dx, k.1 + dy, k.2 + dz);
                    let len = lat.g * f64::from(dx * dx + dy * dy + dz * dz).sqrt();
                    let gq = g + len;
                    if sides[side].best.get(&q).is_some_and(|b| b.0 <= gq) {
                        continue;
                    }
                    let sq = lat.slack(q, work)?;
                    if sq <= 0.0 || sq + sk < len {
                        continue;
                    }
                    sides[side].best.insert(q, (gq, From::Cell(k)));
                    if sides[1 - side].best.contains_key(&q) {
                        return Some(meet(lat, &sides, q));
                    }
                    let f = gq + WEIGHT * heuristic(side, &lat.at(q));
                    sides[side].open.push(Entry { f, g: gq, k: q });
                }
            }
        }
    }
}

/// The path through the lattice point `k` where the two sides met.
fn meet(lat: &Lattice<'_>, sides: &[Side; 2], k: Cell) -> Found {
    let (mut a, source) = sides[0].chain(k);
    a.reverse();
    let (b, target) = sides[1].chain(k);
    let points = a
        .iter()
        .chain(b.iter().skip(1))
        .map(|&c| lat.at(c))
        .collect();
    (source, target, points)
}

/// The tool axes a turn from `a` to `b` at one point passes: `b` alone where the turn is at
/// most a right angle, else the great circle's middle first (for opposite axes, the middle
/// nearest `up`), so that no move of a route turns the axis by more than a right angle.
pub(super) fn turn_axes(
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    up: &Vector3<f64>,
) -> Vec<Vector3<f64>> {
    if a.dot(b) >= 0.0 {
        return vec![*b];
    }
    let mid = (a + b).try_normalize(1e-6).unwrap_or_else(|| {
        (up - a * a.dot(up)).try_normalize(1e-6).unwrap_or_else(|| {
            let i = a.iamin();
            let mut e = Vector3::zeros();
            e[i] = 1.0;
            (e - a * a[i]).normalize()
        })
    });
    vec![mid, *b]
}

/// One end of a gap for the search: the exit (or the pierce) with its tool axis, and the
/// retract points on that axis whose axial moves are clear.
pub(super) struct GapEnd<'a> {
    pub(super) at: &'a Pose,
    pub(super) retracts: &'a [Pose],
}

/// A route from `a` (the exit) to `b` (the pierce) around the part with the head turned to
/// the tool axis `m` for the travel: from one of the exit's retract points the head turns to
/// `m` where that turn keeps the clearance, runs along the lattice path found, turns to the
/// pierce's axis over one of its retract points and approaches. `None` if no path is found
/// within `work` (each distance query, expansion and sample of the shortening spends one).
pub(super) fn route(
    obs: &Obstacles,
    a: &GapEnd<'_>,
    b: &GapEnd<'_>,
    m: &Vector3<f64>,
    opts: &TraverseOptions,
    work: &mut Work,
) -> Option<Vec<Pose>> {
    let (from, to, ends_a, ends_b) = (a.at, b.at, a.retracts, b.retracts);
    let c = opts.clearance_mm;
    let m = m.try_normalize(1e-12)?;
    let up = opts.up.normalize();
    let (na, nb) = (from.axis.normalize(), to.axis.normalize());
    let first = ends_a.first()?;
    let e1 = if m.x.abs() < 0.9 {
        Vector3::x().cross(&m).normalize()
    } else {
        Vector3::y().cross(&m).normalize()
    };
    let g = c * SPACING;
    // A nozzle of more than a thousand lattice steps (a tiny clearance with a long nozzle)
    // would make each lattice point's column too long to walk: no search.
    if opts.nozzle_mm / g > 1024.0 {
        return None;
    }
    let mut lat = Lattice {
        obs,
        origin: first.position,
        e1,
        e2: m.cross(&e1),
        m,
        g,
        need: c * (1.0 + EXTRA),
        nozzle: opts.nozzle_mm,
        column: (opts.nozzle_mm / g).ceil() as i32,
        sub: NOZZLE_SAMPLES,
        // A slack of two steps joins a point to any free neighbour (at most `g sqrt 3` away):
        // beyond that, distances need not be exact.
        cap: c * (1.0 + EXTRA) + 0.5 * g / f64::from(NOZZLE_SAMPLES) + 2.0 * g,
        dist: CellMap::default(),
        slack: CellMap::default(),
    };
    let floor = opts.margin();
    // The ends the head can turn to `m` at, with the turn's tool axes.
    let mut turns: [Vec<Vec<Vector3<f64>>>; 2] = [Vec::new(), Vec::new()];
    let mut ends: [Vec<End>; 2] = [Vec::new(), Vec::new()];
    for (side, (list, axis, base)) in [(ends_a, na, from), (ends_b, nb, to)]
        .into_iter()
        .enumerate()
    {
        for p in list {
            let at = p.position;
            let (start, goal) = if side == 0 { (axis, m) } else { (m, axis) };
            let mut axes = vec![start];
            axes.extend(turn_axes(&start, &goal, &up));
            let clear = axes.windows(2).all(|w| {
                w[0] == w[1]
                    || Trace::new(
                        obs,
                        &Pose::at(at, w[0]),
                        &Pose::at(at, w[1]),
                        c,
                        opts.nozzle_mm,
                    )
                    .certify(floor, work)
                    .is_ok()
            });
            if !clear {
                continue;
            }
            let slack = lat.slack_at(&at, work)?;
            if slack <= 0.0 {
                continue;
            }
            ends[side].push(End {
                at,
                cost: (at - base.position).norm(),
                slack,
            });
            turns[side].push(axes);
        }
    }
    if ends[0].is_empty() || ends[1].is_empty() {
        return None;
    }
    let (source, target, inner) = bidirectional(&mut lat, &ends[0], &ends[1], work)?;
    // The path with its ends, shortened: from each point, the farthest one (halving the
    // stretch) that a straight move reaches with the travel's check.
    let mut pts = vec![ends[0][source].at];
    pts.extend(inner);
    pts.push(ends[1][target].at);
    let mut kept = vec![pts[0]];
    let mut i = 0;
    while i + 1 < pts.len() {
        let mut j = pts.len() - 1;
        while j > i + 1 {
            let ok = Trace::new(
                obs,
                &Pose::at(pts[i], m),
                &Pose::at(pts[j], m),
                c,
                opts.nozzle_mm,
            )
            .certify(floor, work)
            .is_ok();
            if ok {
                break;
            }
            if work.left == 0 {
                return None;
            }
            j = i + (j - i) / 2;
        }
        kept.push(pts[j]);
        i = j;
    }
    // The route: the retract point with the exit's axis, the turn to `m`, the path, the turn to
    // the pierce's axis over the approach.
    let mut way: Vec<Pose> = turns[0][source]
        .iter()
        .map(|&n| Pose::at(kept[0], n))
        .collect();
    way.extend(kept[1..kept.len() - 1].iter().map(|&p| Pose::at(p, m)));
    way.extend(
        turns[1][target]
            .iter()
            .map(|&n| Pose::at(kept[kept.len() - 1], n)),
    );
    way.dedup();
    Some(way)
}
