//! The routes of a traverse (straight, lifted, over the safe plane), checked shortest first.

use nalgebra::Point3;

use super::check::{Blocked, Trace, Work, MOVE_SAMPLES};
use super::obstacles::top_along;
use super::{Obstacles, TraverseOptions};
use crate::{Pose, ProcessError, Result};

/// How a traverse runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Route {
    /// Retract, one straight travel, approach.
    Straight,
    /// Retract, rise along the up direction to the safe plane above every surface, travel in
    /// it, descend, approach.
    SafePlane,
    /// Retract, rise along the up direction to a clearance above the surfaces whose boxes
    /// come near the travel (seen along the up direction), travel, descend, approach: lower
    /// than the safe plane, so often within the axis limits where that is not.
    Lifted,
    /// Retract, turn the head to one tool axis (upright, the pierce's or the exit's) where
    /// that turn keeps the clearance, follow a path found by a search around the part, turn
    /// to the pierce's axis, approach: where no other route clears (an overhang, a pocket the
    /// head leaves by another way than it came).
    Searched,
}

impl Route {
    /// `"straight"`, `"safe_plane"`, `"lifted"` or `"searched"`.
    pub fn name(self) -> &'static str {
        match self {
            Route::Straight => "straight",
            Route::SafePlane => "safe_plane",
            Route::Lifted => "lifted",
            Route::Searched => "searched",
        }
    }
}

/// A planned traverse from the end of one cut to the pierce of the next.
#[derive(Debug, Clone, PartialEq)]
pub struct Traverse {
    /// The waypoints with tool axes, workpiece frame, from the retract point above the exit
    /// to the point above the pierce; the head reaches the first along the exit's tool axis
    /// and leaves the last along the pierce's tool axis. Between waypoints it moves straight,
    /// the tool axis turning from one waypoint's to the next's.
    pub waypoints: Vec<Pose>,
    /// The route taken.
    pub route: Route,
    /// The smallest surface distance found over the travel's samples (tip and nozzle), mm;
    /// the travel is certified to stay at least the clearance away.
    pub min_distance_mm: f64,
    /// The length of the tip's path from the exit to the pierce: retract, travel, approach,
    /// mm.
    pub length_mm: f64,
}

fn path_length(points: &[Point3<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Plans the traverse from `from` (where the last cut ended: tip and tool axis, workpiece
/// frame) to `to` (the next pierce point and its tool axis).
///
/// The head backs off along `from`'s axis by the retract (doubled, up to 16 times the larger of
/// clearance and retract, where a route from there is not clear), and the straight travel to
/// the point as far above `to` is checked; where it is blocked, the travel rises along
/// [`TraverseOptions::up`] to the safe plane a clearance and a sample step above every
/// surface's bounding box, crosses in it and comes down. Along the retract and the approach,
/// from 3/4 of the clearance up the tip keeps half the clearance (their lower ends touch the
/// part by design); along the travel the tip and the nozzle keep the full clearance.
///
/// Each move is sphere-traced with a margin of a 64th of the clearance; where it stops within
/// that margin, a sample closer than the clearance is looked for ahead of the stop (a measured
/// violation); if no route clears, the routes that stopped within the margin with no such
/// sample are traced again with finer margins, within a counted budget of samples
/// (`docs/process.md`, "The margin and the witness").
///
/// # Errors
/// [`ProcessError::BadOption`] for bad options, [`ProcessError::BadContour`] for non-finite
/// poses, [`ProcessError::TraverseBlocked`] if no route is clear (e.g. a tool axis pointing
/// into a pocket the head cannot back out of).
pub fn plan_traverse(
    obs: &Obstacles,
    from: &Pose,
    to: &Pose,
    opts: &TraverseOptions,
) -> Result<Traverse> {
    plan_traverse_within(obs, from, to, opts, &|_| true)
}

/// [`plan_traverse`] among the routes whose waypoints `reachable` accepts (e.g. within the
/// machine's axis limits); the others are not tried.
///
/// # Errors
/// As [`plan_traverse`].
pub fn plan_traverse_within(
    obs: &Obstacles,
    from: &Pose,
    to: &Pose,
    opts: &TraverseOptions,
    reachable: &dyn Fn(&[Pose]) -> bool,
) -> Result<Traverse> {
    plan_traverse_accepting(obs, from, to, opts, reachable, &mut |_| Ok(()), true).map(|(t, ())| t)
}

/// A straight move's two poses, bit for bit: the key under which its coarse outcome is kept.
type MoveKey = [u64; 12];

/// The coarse outcomes of the moves of one gap's routes, by their poses.
type MoveOutcomes = std::collections::HashMap<MoveKey, std::result::Result<f64, Blocked>>;

fn move_key(a: &Pose, b: &Pose) -> MoveKey {
    let (a, b) = (a.to_array(), b.to_array());
    std::array::from_fn(|k| if k < 6 { a[k] } else { b[k - 6] }.to_bits())
}

/// What the coarse pass made of one route.
#[derive(Debug, Clone, Copy)]
enum Coarse {
    /// Outside the machine's axis limits (not checked).
    Unreachable,
    /// Clear, but refused by the caller's check, at this point; `true` where the split that
    /// would clear the machine's own move leaves the axis limits.
    Refused(Blocked, bool),
    /// Its check failed so.
    Failed(Blocked),
    /// A point of it was measured closer than the clearance: its check cannot pass, and is
    /// put off until its outcome is needed.
    Deferred,
    /// An axial move to one of its retract points is not clear: the route does not exist.
    Absent,
}

/// True if the route through `way` cannot pass the travel's check: one of its moves already
/// failed it (`traced`), or a point of one of them is measured closer than the clearance
/// (`probe`; the first and the last move first, where the routes of the real files fail).
fn fails_for_sure(
    traced: &MoveOutcomes,
    probe: &mut super::probe::Probe<'_>,
    way: &[Pose],
) -> bool {
    let moves = way.len().saturating_sub(1);
    let known = |i: usize| traced.get(&move_key(&way[i], &way[i + 1]));
    if (0..moves).any(|i| matches!(known(i), Some(Err(_)))) {
        return true;
    }
    let order = [0, moves.saturating_sub(1)]
        .into_iter()
        .chain(1..moves.saturating_sub(1));
    let mut seen = Vec::with_capacity(moves);
    for i in order.take(moves) {
        if seen.contains(&i) || known(i).is_some() {
            continue;
        }
        seen.push(i);
        if probe.violated(&way[i], &way[i + 1]) {
            return true;
        }
    }
    false
}

/// Samples the finer margins may take over one gap's routes, after the coarse pass found
/// none clear.
const FINE_SAMPLES: usize = 1 << 22;

/// The share of [`FINE_SAMPLES`] the finer margins get before the search around the part:
/// routes that hug the part can spend the whole budget and clear none where the search finds
/// a path cheaply (the propeller on `head_table`: ten such routes took all 4.2 M samples and
/// 4.4 M exact distances; the search then found a path with 3,648).
const FINE_FIRST: usize = 1 << 18;

/// The work the search around the part may spend on one gap where no route shape clears
/// (distance queries, expansions and samples, `search::route`).
const SEARCH_WORK: usize = 1 << 19;

/// How the routes of one gap failed.
#[derive(Debug, Default)]
struct Tally {
    /// Outside the machine's axis limits.
    unreachable: usize,
    /// Clear, but refused by the caller's check (the machine's rapid swing).
    refused: usize,
    /// Of those, the routes whose swing a split would clear but whose split points leave the
    /// axis limits.
    refused_limits: usize,
    /// A sample measured closer than the clearance.
    closer: usize,
    /// Not proven: within the finest margin, or the work budget ran out.
    undecided: usize,
    /// The blockage of the route that came nearest to clearing (its offending sample farthest
    /// from the part).
    nearest: Option<Blocked>,
}

impl Tally {
    fn note(&mut self, b: Blocked) {
        if self.nearest.is_none_or(|n| b.distance > n.distance) {
            self.nearest = Some(b);
        }
    }

    /// A route whose check failed at `e`: measured closer than `need`, or not proven.
    fn failed(&mut self, e: Blocked, need: f64) {
        if e.distance < need && !e.exhausted {
            self.closer += 1;
        } else {
            self.undecided += 1;
        }
        self.note(e);
    }

    /// Hands the clear route `t` to `accept`: its result, or `None` counted as refused.
    fn offer<T>(
        &mut self,
        t: Traverse,
        accept: &mut dyn FnMut(&Traverse) -> std::result::Result<T, Refusal>,
    ) -> Option<(Traverse, T)> {
        match accept(&t) {
            Ok(v) => Some((t, v)),
            Err(r) => {
                self.refuse(Blocked::at(r.at, r.distance), r.outside_limits);
                None
            }
        }
    }

    /// A clear route the caller's check refused at `b` (`outside_limits`: its split would
    /// leave the axis limits).
    fn refuse(&mut self, b: Blocked, outside_limits: bool) {
        self.refused += 1;
        if outside_limits {
            self.refused_limits += 1;
        }
        self.note(b);
    }
}

/// The clear route of `route`'s shape through `waypoints` (`length_mm` long), keeping
/// `least` mm from the part.
fn traverse_of(length_mm: f64, route: Route, waypoints: &[Pose], least: f64) -> Traverse {
    Traverse {
        length_mm,
        waypoints: waypoints.to_vec(),
        route,
        min_distance_mm: least,
    }
}

/// Why a route was refused by the caller's own check (e.g. the machine's rapid swing).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Refusal {
    /// The first offending point.
    pub(crate) at: Point3<f64>,
    /// Its distance from the part, mm.
    pub(crate) distance: f64,
    /// True where the move could be cleared by splitting it but the split points leave the
    /// machine's axis limits.
    pub(crate) outside_limits: bool,
}

/// The retract heights a traverse tries at each end, doubling from the retract: every route
/// (searched ones included) leaves and reaches the part through a retract point at one of
/// them.
pub(crate) fn retract_heights(opts: &TraverseOptions) -> [f64; 5] {
    std::array::from_fn(|k| opts.retract_mm * f64::from(1u32 << k))
}

/// An axial move's check: the retract point reached, or why it is blocked.
type AxialOutcome = std::result::Result<Pose, Blocked>;

/// [`plan_traverse_within`], where a route that is clear is also handed to `accept` (e.g.
/// the check of the machine's own rapid moves); the first route both accept is returned with
/// `accept`'s result, the next shortest tried otherwise.
///
/// With `explain` false the caller does not want the reason where no route clears (it tries
/// again with fewer surfaces): the error then says so instead of counting the routes, and
/// the routes put off for a point measured closer than the clearance are not traced for it.
/// Which route is found, if any, does not depend on `explain`.
pub(crate) fn plan_traverse_accepting<T>(
    obs: &Obstacles,
    from: &Pose,
    to: &Pose,
    opts: &TraverseOptions,
    reachable: &dyn Fn(&[Pose]) -> bool,
    accept: &mut dyn FnMut(&Traverse) -> std::result::Result<T, Refusal>,
    explain: bool,
) -> Result<(Traverse, T)> {
    opts.validate()?;
    for (name, p) in [("from", from), ("to", to)] {
        let axis_ok = p.axis.norm() > 1e-9;
        if !p.is_finite() || !axis_ok {
            return Err(ProcessError::BadContour {
                id: format!("traverse {name}"),
                reason: "a non-finite pose or a zero tool axis".into(),
            });
        }
    }
    let c = opts.clearance_mm;
    let h = opts.step();
    let floor = opts.margin();
    let up = opts.up.normalize();
    let unit = |p: &Pose| {
        let n = p.axis.normalize();
        Pose::at(p.position, n)
    };
    let (from, to) = (unit(from), unit(to));
    // The retract (and the approach) along the tool axis: from 3/4 of the clearance to the
    // retract height, the tip and the nozzle (which slides along the same line, up to the
    // height plus its length) keep half the clearance; raised where they do not. (The head
    // at the retract point, where the travel starts, keeps the full clearance: the travel's
    // check.)
    let axial = |p: &Pose, height: f64| -> std::result::Result<Pose, Blocked> {
        let (q, n) = (p.position, p.axis);
        let low = Pose::at(q + n * (0.75 * c), n);
        let high = Pose::at(q + n * height, n);
        // The tip and the nozzle sweep the one line from `low` to the height plus the
        // nozzle: traced as the tip's.
        let top = Pose::at(q + n * (height + opts.nozzle_mm), n);
        Trace::new(obs, &low, &top, 0.5 * c, 0.0).prove(floor, &mut Work::new(MOVE_SAMPLES))?;
        Ok(high)
    };
    let length_of = |way: &[Pose]| {
        let mut pts = vec![from.position];
        pts.extend(way.iter().map(|p| p.position));
        pts.push(to.position);
        path_length(&pts)
    };
    // The travel between the waypoints, tip and nozzle keeping the clearance: with the
    // coarse margin (each move within its own budget), or with `Trace::prove`'s finer margins
    // within the gap's budget `fine`. A coarse move's outcome depends on nothing but its two
    // poses (the obstacles, the clearance, the nozzle and the margin are the gap's, the budget
    // its own), and the routes of a gap share many moves (every safe-plane route from one
    // retract point rises along the same move; half the moves checked on the real files are
    // repeats): each is traced once per gap.
    let traced: std::cell::RefCell<MoveOutcomes> = Default::default();
    let tip_ends = |w: &[Pose], fine: Option<&mut Work>| -> std::result::Result<f64, Blocked> {
        let mut least = f64::INFINITY;
        let mut fine = fine;
        for s in w.windows(2) {
            let trace = Trace::new(obs, &s[0], &s[1], c, opts.nozzle_mm);
            least = least.min(match fine.as_deref_mut() {
                None => {
                    let key = move_key(&s[0], &s[1]);
                    let known = traced.borrow().get(&key).copied();
                    let outcome = known.unwrap_or_else(|| {
                        trace.certify_or_witness(floor, &mut Work::new(MOVE_SAMPLES))
                    });
                    traced.borrow_mut().insert(key, outcome);
                    outcome?
                }
                Some(work) => trace.prove(floor, work)?,
            });
        }
        Ok(least)
    };
    let blocked_err = |b: Blocked, why: String| {
        ProcessError::TraverseBlocked(Box::new(crate::Blockage {
            from: from.position.into(),
            to: to.position.into(),
            at: [b.at.x, b.at.y, b.at.z],
            distance_mm: b.distance,
            clearance_mm: c,
            why,
        }))
    };
    // The error of a gap whose reason the caller does not want (it tries again with fewer
    // surfaces): the routes put off are not traced for it.
    let unexplained = |b: Blocked| {
        blocked_err(
            b,
            "no route clears (the routes were not all traced: the reason was not asked for)".into(),
        )
    };
    // The retract heights tried at each end (doubling), those whose axial move is clear.
    let heights = retract_heights(opts);
    // The axial moves, each checked once and only where needed: a route is taken only if
    // both its retract points' axial moves are clear, but a route put off (below) needs
    // neither, and where a route is taken the higher retract points are seldom reached.
    // Every end's axial moves are checked before the routes are counted or searched.
    let axial_done: std::cell::RefCell<[[Option<AxialOutcome>; 5]; 2]> = Default::default();
    let axial_at = |side: usize, k: usize| -> std::result::Result<Pose, Blocked> {
        if let Some(known) = axial_done.borrow()[side][k] {
            return known;
        }
        let outcome = axial(if side == 0 { &from } else { &to }, heights[k]);
        axial_done.borrow_mut()[side][k] = Some(outcome);
        outcome
    };
    // The retract point at height `k` of an end, whether or not its axial move is clear.
    let retract_point = |p: &Pose, k: usize| {
        let (q, n) = (p.position, p.axis);
        Pose::at(q + n * heights[k], n)
    };
    // Every route: straight between any two retract points, lifted along `up` over the
    // surfaces near the travel, or over the safe plane above every surface; checked shortest
    // first. Built for every pair of retract heights; a route whose retract points' axial
    // moves are not both clear does not exist (sorting is stable, so the order of the others
    // is that of the routes built from the clear retract points alone).
    let mut routes: Vec<(f64, Route, Vec<Pose>)> = Vec::new();
    let mut route_ends: Vec<(usize, usize)> = Vec::new();
    let lift_to = |level: f64| {
        move |p: &Pose| {
            let q = p.position;
            let rise = (level - q.coords.dot(&up)).max(0.0);
            Pose::at(q + up * rise, p.axis)
        }
    };
    let global_top = obs
        .bounding_box()
        .map(|(lo, hi)| top_along(&lo, &hi, &up) + c + 2.0 * h);
    for ka in 0..heights.len() {
        let a = &retract_point(&from, ka);
        for kb in 0..heights.len() {
            let b = &retract_point(&to, kb);
            let straight = vec![*a, *b];
            routes.push((length_of(&straight), Route::Straight, straight));
            route_ends.push((ka, kb));
            let (pa, pb) = (a.position, b.position);
            // Each lift at a clearance and two steps above the boxes' top, and a clearance
            // higher (where a tilted nozzle reaches down past the first).
            let local = obs.local_top(&pa, &pb, &up, 2.0 * c + opts.nozzle_mm + 4.0 * h);
            for extra in [0.0, c + 2.0 * h] {
                if let Some(level) = local {
                    let lift = lift_to(level + c + 2.0 * h + extra);
                    let way = vec![*a, lift(a), lift(b), *b];
                    routes.push((length_of(&way), Route::Lifted, way));
                    route_ends.push((ka, kb));
                }
                if let Some(level) = global_top {
                    let lift = lift_to(level + extra);
                    let plane = vec![*a, lift(a), lift(b), *b];
                    routes.push((length_of(&plane), Route::SafePlane, plane));
                    route_ends.push((ka, kb));
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..routes.len()).collect();
    order.sort_by(|&x, &y| routes[x].0.total_cmp(&routes[y].0));
    let mut sorted: Vec<Option<(f64, Route, Vec<Pose>)>> = routes.into_iter().map(Some).collect();
    let mut routes: Vec<(f64, Route, Vec<Pose>)> = Vec::with_capacity(order.len());
    let mut ends_of: Vec<(usize, usize)> = Vec::with_capacity(order.len());
    for &k in &order {
        routes.extend(sorted[k].take());
        ends_of.push(route_ends[k]);
    }
    // True if both retract points' axial moves of route `k` are clear (checking them).
    let exists = |k: usize| {
        let (ka, kb) = ends_of[k];
        axial_at(0, ka).is_ok() && axial_at(1, kb).is_ok()
    };
    // Known not to exist: an axial move of it already failed.
    let gone = |k: usize| {
        let (ka, kb) = ends_of[k];
        let done = axial_done.borrow();
        matches!(done[0][ka], Some(Err(_))) || matches!(done[1][kb], Some(Err(_)))
    };
    // First every route with the coarse margin, shortest first; then, if none clears, the
    // routes that failed only within the margin again with finer margins (`prove`), within
    // the gap's budget of samples.
    //
    // A route on which a point closer than the clearance is measured first (`Probe`) cannot
    // pass its check: its trace is put off. Where a later route is taken, it is never needed;
    // otherwise the routes put off are traced then, and every route's outcome is counted in
    // the order of the routes, as if each had been traced in turn (a route put off that did
    // clear would be offered then, before any other: none of the routes after it was taken).
    let mut probe = super::probe::Probe::new(obs, c, opts.nozzle_mm);
    let mut outcomes: Vec<Coarse> = Vec::with_capacity(routes.len());
    for (k, (length_mm, route, waypoints)) in routes.iter().enumerate() {
        if gone(k) {
            outcomes.push(Coarse::Absent);
            continue;
        }
        if !reachable(waypoints) {
            outcomes.push(Coarse::Unreachable);
            continue;
        }
        if fails_for_sure(&traced.borrow(), &mut probe, waypoints) {
            outcomes.push(Coarse::Deferred);
            continue;
        }
        if !exists(k) {
            outcomes.push(Coarse::Absent);
            continue;
        }
        let checked = tip_ends(waypoints, None);
        match checked {
            Ok(least) => {
                let t = traverse_of(*length_mm, *route, waypoints, least);
                match accept(&t) {
                    Ok(v) => return Ok((t, v)),
                    Err(r) => {
                        outcomes.push(Coarse::Refused(
                            Blocked::at(r.at, r.distance),
                            r.outside_limits,
                        ));
                    }
                }
            }
            Err(e) => {
                probe.learn(e.at, e.distance);
                outcomes.push(Coarse::Failed(e));
            }
        }
    }
    // No route clears with the coarse margin. Every end's axial moves now, as they were
    // checked before any route: where all of one end's fail, that is the gap's error.
    let top = heights[heights.len() - 1];
    let mut retracts: [Vec<Pose>; 2] = [Vec::new(), Vec::new()];
    for (side, what) in [
        (0, "the retract along the tool axis from the exit"),
        (1, "the approach along the tool axis to the pierce"),
    ] {
        let mut last = None;
        for k in 0..heights.len() {
            match axial_at(side, k) {
                Ok(q) => retracts[side].push(q),
                Err(e) => last = Some(e),
            }
        }
        if let (true, Some(b)) = (retracts[side].is_empty(), last) {
            return Err(blocked_err(
                b,
                format!(
                    "{what} is blocked at every height from {:.1} to {top:.1} mm",
                    heights[0]
                ),
            ));
        }
    }
    let [ends_a, ends_b] = retracts;
    // The routes that exist, with what the coarse pass made of them.
    let (routes, outcomes): (Vec<_>, Vec<_>) = routes
        .into_iter()
        .zip(outcomes)
        .enumerate()
        .filter(|(k, _)| exists(*k))
        .map(|(_, r)| r)
        .unzip();
    // No route clears with the coarse margin. The finer margins need the routes that failed
    // only within it, in order, and the error counts every route: both need the routes put
    // off, unless this gap's error is not wanted and no route traced failed within the margin
    // (then the finer margins could only re-trace routes that cannot pass).
    let mut tally = Tally::default();
    // The routes that failed only within the coarse margin, with that failure.
    let mut marginal: Vec<(usize, Blocked)> = Vec::new();
    let resolve = explain
        || outcomes
            .iter()
            .any(|o| matches!(o, Coarse::Failed(e) if e.within_margin(c)));
    if resolve {
        for (k, outcome) in outcomes.into_iter().enumerate() {
            let outcome = match outcome {
                Coarse::Deferred => {
                    let (length_mm, route, waypoints) = &routes[k];
                    match tip_ends(waypoints, None) {
                        Ok(least) => {
                            let t = traverse_of(*length_mm, *route, waypoints, least);
                            match accept(&t) {
                                Ok(v) => return Ok((t, v)),
                                Err(r) => {
                                    Coarse::Refused(Blocked::at(r.at, r.distance), r.outside_limits)
                                }
                            }
                        }
                        Err(e) => Coarse::Failed(e),
                    }
                }
                other => other,
            };
            match outcome {
                Coarse::Unreachable => tally.unreachable += 1,
                Coarse::Refused(b, outside_limits) => tally.refuse(b, outside_limits),
                Coarse::Failed(e) if e.within_margin(c) => marginal.push((k, e)),
                Coarse::Failed(e) => tally.failed(e, c),
                Coarse::Deferred | Coarse::Absent => unreachable!("traced or left out above"),
            }
        }
    }
    // The finer margins over `list` within `fine`: a route that clears and is accepted ends
    // the gap; one that ran out of the budget is handed back when `hand_back` (to wait for
    // the search around the part), else undecided at its coarse failure.
    type Waiting = Vec<(usize, Blocked)>;
    let fine_pass = |list: Waiting,
                     fine: &mut Work,
                     tally: &mut Tally,
                     accept: &mut dyn FnMut(&Traverse) -> std::result::Result<T, Refusal>,
                     hand_back: bool|
     -> std::result::Result<(Traverse, T), Waiting> {
        let mut waiting = Vec::new();
        for (k, b) in list {
            let (length_mm, route, waypoints) = &routes[k];
            if fine.left == 0 {
                if hand_back {
                    waiting.push((k, b));
                } else {
                    // No budget left to re-trace it: undecided at its coarse failure.
                    tally.undecided += 1;
                    tally.note(b);
                }
                continue;
            }
            match tip_ends(waypoints, Some(&mut *fine)) {
                Ok(least) => {
                    let t = traverse_of(*length_mm, *route, waypoints, least);
                    if let Some(done) = tally.offer(t, accept) {
                        return Ok(done);
                    }
                }
                Err(e) if hand_back && e.exhausted && fine.left == 0 => waiting.push((k, b)),
                Err(e) => tally.failed(e, c),
            }
        }
        Err(waiting)
    };
    // First within a share of the budget ([`FINE_FIRST`]); the routes that ran out of it wait
    // for the search around the part and get the rest only if that finds no path.
    let mut fine = Work::new(FINE_FIRST);
    let waiting = match fine_pass(
        std::mem::take(&mut marginal),
        &mut fine,
        &mut tally,
        accept,
        true,
    ) {
        Ok(done) => return Ok(done),
        Err(waiting) => waiting,
    };
    let mut fine = Work::new(FINE_SAMPLES - FINE_FIRST);
    // Where the search finds no path: the waiting routes with the rest of the budget.
    let mut resume =
        |tally: &mut Tally,
         accept: &mut dyn FnMut(&Traverse) -> std::result::Result<T, Refusal>,
         waiting: Waiting| { fine_pass(waiting, &mut fine, tally, accept, false).ok() };
    // How the routes of the given shapes failed, in words.
    let tally_text = |tally: &Tally, n: usize| {
        if tally.unreachable == n {
            format!("none of the {n} routes lies within the machine's axis limits")
        } else {
            format!(
                "{} of {n} routes come too close ({} measured closer than the clearance, {} not proven within a margin of {:.4} mm or the work budget), {} of them only in the machine's rapid swing{}, {} leave the axis limits",
                n - tally.unreachable,
                tally.closer,
                tally.undecided,
                c * super::check::FINEST_MARGIN,
                tally.refused,
                if tally.refused_limits > 0 {
                    format!(
                        " ({} where the split that would clear it leaves the axis limits)",
                        tally.refused_limits
                    )
                } else {
                    String::new()
                },
                tally.unreachable
            )
        }
    };
    // No route shape clears. First, is one possible at all? Every route leaves the exit and
    // reaches the pierce along their tool axes (`proof::line_blocked`).
    for (p, what) in [
        (&to, "the approach to the pierce"),
        (&from, "the retract from the exit"),
    ] {
        if let Some((b, why)) = super::proof::line_blocked(obs, p, opts, what) {
            // No route can clear: the waiting ones neither.
            for &(_, w) in &waiting {
                tally.undecided += 1;
                tally.note(w);
            }
            if !explain {
                return Err(unexplained(b));
            }
            let shapes = tally_text(&tally, routes.len());
            return Err(blocked_err(
                b,
                format!("{why}; of the route shapes tried, {shapes}"),
            ));
        }
    }
    // Then a search around the part with the head turned to one tool axis for the travel:
    // upright, the pierce's, the exit's (each once), sharing one work budget.
    let mut axes: Vec<nalgebra::Vector3<f64>> = Vec::new();
    for m in [up, to.axis, from.axis] {
        if axes.iter().all(|a| (a - m).norm() > 1e-9) {
            axes.push(m);
        }
    }
    let mut search = Work::new(if opts.search { SEARCH_WORK } else { 0 });
    let mut searched = 0;
    for (i, m) in axes.iter().enumerate() {
        if !opts.search {
            break;
        }
        let mut share = Work::new(search.left / (axes.len() - i));
        let before = share.left;
        let found = super::search::route(
            obs,
            &super::search::GapEnd {
                at: &from,
                retracts: &ends_a,
            },
            &super::search::GapEnd {
                at: &to,
                retracts: &ends_b,
            },
            m,
            opts,
            &mut share,
        );
        search.left -= before - share.left;
        let Some(waypoints) = found else { continue };
        searched += 1;
        if !reachable(&waypoints) {
            tally.unreachable += 1;
            continue;
        }
        match tip_ends(&waypoints, None) {
            Ok(least) => {
                let t = Traverse {
                    length_mm: length_of(&waypoints),
                    waypoints,
                    route: Route::Searched,
                    min_distance_mm: least,
                };
                if let Some(done) = tally.offer(t, accept) {
                    return Ok(done);
                }
            }
            Err(e) => tally.failed(e, c),
        }
    }
    if let Some(done) = resume(&mut tally, accept, waiting) {
        return Ok(done);
    }
    if !explain {
        return Err(unexplained(Blocked::at(from.position, 0.0)));
    }
    let n = routes.len() + searched;
    let search_note = if opts.search {
        format!(
            "; the search around the part (the head turned upright, to the pierce's or to the exit's tool axis) found {searched} path{} in {} of its {SEARCH_WORK} work units",
            if searched == 1 { "" } else { "s" },
            SEARCH_WORK - search.left
        )
    } else {
        String::new()
    };
    let why = tally_text(&tally, n) + &search_note;
    let b = tally.nearest.unwrap_or(Blocked::at(from.position, 0.0));
    Err(blocked_err(b, why))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every route clear of an empty part, every one refused by the caller: the gap's error
    /// counts them as the machine's swing, and says how many of those only a split outside
    /// the axis limits would clear.
    fn refused_everywhere(outside_limits: bool) -> String {
        let obs = Obstacles::new();
        let from = Pose::new(0.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let to = Pose::new(50.0, 0.0, 0.0, 0.0, 0.0, 1.0);
        let mut offered = 0;
        let e = plan_traverse_accepting(
            &obs,
            &from,
            &to,
            &TraverseOptions::default(),
            &|_: &[Pose]| true,
            &mut |t: &Traverse| -> std::result::Result<(), Refusal> {
                offered += 1;
                let w = t.waypoints[t.waypoints.len() / 2];
                Err(Refusal {
                    at: w.position,
                    distance: 1.0,
                    outside_limits,
                })
            },
            true,
        )
        .expect_err("every route refused");
        assert!(offered > 0, "routes were offered");
        let text = e.to_string();
        assert!(
            text.contains(&format!(
                ", {offered} of them only in the machine's rapid swing"
            )),
            "{offered} offered: {text}"
        );
        text
    }

    #[test]
    fn routes_whose_split_leaves_the_limits_are_told_apart() {
        let within = refused_everywhere(false);
        assert!(!within.contains("leaves the axis limits"), "{within}");
        let outside = refused_everywhere(true);
        // Every route refused so: the count is every route offered.
        let offered = outside
            .split(" of them only in the machine's rapid swing")
            .next()
            .and_then(|s| s.rsplit(", ").next())
            .expect("the swing count");
        assert!(
            outside.contains(&format!(
                "({offered} where the split that would clear it leaves the axis limits)"
            )),
            "{outside}"
        );
    }
}
