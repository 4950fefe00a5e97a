//! The machine's rapid moves through a traverse's waypoints, checked as the machine runs
//! them: a rapid (G0) moves every axis linearly from one waypoint to the next, so where the
//! rotary axes turn, the tip does not follow the straight line between the waypoints but
//! swings; each move is sampled through the forward kinematics and checked, and a move that
//! comes too close is split into shorter ones along the straight line until it clears.

use kerf_kinematics::{Axes, Head, Kinematics};
use nalgebra::{Point3, Vector3};

use crate::head::{
    axis_curvature, check_cut_along, CutClearance, HeadCheckOptions, SAMPLE_STEP_MM,
};
use crate::traverse::{check_move, Obstacles, Traverse, TraverseOptions};
use crate::{Pose, ProcessError, Result};

/// Most pieces one rapid move between two waypoints is split into.
const MAX_SPLIT: usize = 64;

/// The machine axes of a traverse's rapid moves.
#[derive(Debug, Clone, PartialEq)]
pub struct RapidMoves {
    /// The machine axes of every rapid waypoint, from the retract point to the point above
    /// the pierce (the cut's end and the next pierce not included).
    pub axes: Vec<Axes>,
    /// The tip and tool axis at each of those (workpiece frame).
    pub poses: Vec<Pose>,
    /// The smallest surface distance measured over the sampled machine moves, mm.
    pub min_distance_mm: f64,
    /// How many moves had to be split so that their swing clears the part.
    pub split_moves: usize,
    /// With a head model ([`TraverseHead`]): the least distance proven between the head and
    /// the part over the machine's moves it checks, mm; `None` without one, or where no route
    /// cleared the head (then [`head_too_close`](Self::head_too_close)).
    pub head_min_distance_mm: Option<f64>,
    /// With a head model: where the head came too close on the first route it refused, when
    /// no route the tip and nozzle line clear cleared the head too (or where it stands too
    /// close at one end whatever the route); the route is then the one the traverse's own
    /// check takes without the head, for the caller to refuse or accept.
    pub head_too_close: Option<HeadWitness>,
}

/// Where the head model comes closer to the part than the cutting clearance on a traverse
/// ([`RapidMoves::head_too_close`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HeadWitness {
    /// The head point witnessed too close, or, where the check was not proven, the tip at the
    /// pose nearest its least proven distance (workpiece frame).
    pub at: Point3<f64>,
    /// Its distance from the part, mm (an upper bound of the least distance there; negative:
    /// inside the part); `None` where the head was not proven clear within the work budget.
    pub distance_mm: Option<f64>,
    /// The surface nearest that point.
    pub surface: Option<String>,
    /// Why the head is not proven clear, where it is not ([`CutClearance::unproven`]).
    pub unproven: Option<String>,
}

impl std::fmt::Display for HeadWitness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let p = self.at;
        match self.distance_mm {
            Some(d) => write!(
                f,
                "within {d:.3} mm of the part at ({:.3}, {:.3}, {:.3})",
                p.x, p.y, p.z
            )?,
            None => write!(
                f,
                "not proven clear ({}) near ({:.3}, {:.3}, {:.3})",
                self.unproven
                    .as_deref()
                    .unwrap_or("the check did not finish"),
                p.x,
                p.y,
                p.z
            )?,
        }
        if let Some(id) = &self.surface {
            write!(f, ", surface {id}")?;
        }
        Ok(())
    }
}

/// The cutting head a traverse keeps clear of the part besides its tip and nozzle line
/// ([`plan_rapids`]): the head model standing on every sample of the machine's moves from the
/// cut's end to the next pierce, checked as the cuts are ([`check_cut_along`]): the retract
/// from the cut's end and the approach to the pierce with the cut's tip zone left out (the
/// nozzle is at the surface there), the travel between the retract points with the whole
/// head; against every surface of the parts the two cuts lie on.
#[derive(Debug, Clone, Copy)]
#[non_exhaustive]
pub struct TraverseHead<'a> {
    /// The head's solids.
    pub head: &'a Head,
    /// The clearance (the cutting clearance: the head keeps it while it cuts, so the moves
    /// next to a cut can keep no more), the standoff and the tilt of the tip zone.
    pub opts: HeadCheckOptions,
    /// Every surface of the set-up, placed.
    pub obstacles: &'a Obstacles,
    /// The part of each surface of `obstacles` ([`Obstacles::parts`]).
    pub parts: &'a [usize],
}

/// One machine move's head check: the least distance proven, or where the head came too
/// close.
type HeadMove = std::result::Result<f64, HeadWitness>;

/// A machine move's key in a gap's cache of head checks: its two axes (bits), whether with
/// the whole head, and which surfaces (those with the cuts' way's `first` or `all` left out).
type HeadMoveKey = ([[u64; 5]; 2], bool, usize);

/// The witness of a check that found the head too close or could not prove it clear
/// (`poses` the poses checked); `None` where it is proven clear.
fn witness(obs: &Obstacles, c: &CutClearance, poses: &[Pose]) -> Option<HeadWitness> {
    if let Some(s) = c.close.first() {
        return Some(HeadWitness {
            at: s.point,
            distance_mm: Some(s.distance_mm),
            surface: s.surface.clone(),
            unproven: None,
        });
    }
    (!c.proven).then(|| {
        let at = poses
            .get(c.at_pose)
            .or(poses.first())
            .map_or(Point3::origin(), |p| p.position);
        HeadWitness {
            at,
            distance_mm: None,
            surface: obs.nearest(&at).map(|(id, _)| id),
            unproven: c.unproven.clone(),
        }
    })
}

impl<'a> TraverseHead<'a> {
    /// The head `head` checked with `opts` against the surfaces of `obstacles` in the parts
    /// the gap's two cuts lie on (`parts` from [`Obstacles::parts`]).
    pub fn new(
        head: &'a Head,
        opts: HeadCheckOptions,
        obstacles: &'a Obstacles,
        parts: &'a [usize],
    ) -> Self {
        Self {
            head,
            opts,
            obstacles,
            parts,
        }
    }

    /// The surfaces one gap's head check keeps clear of: the parts its two cuts lie on,
    /// without those left out of its traverse check (`absent`: in the cuts' way).
    fn obstacles_of(&self, g: &Gap, absent: &[String]) -> Obstacles {
        let mut seeds = g.from_surfaces.clone();
        seeds.extend(g.to_surfaces.iter().cloned());
        self.obstacles.of_parts(self.parts, &seeds).without(absent)
    }

    /// The options of a check: stopping at the first witness, the whole head or not.
    fn options(&self, whole: bool) -> HeadCheckOptions {
        self.opts
            .with_stop_at_first_close(true)
            .with_whole_head(whole)
    }

    /// The head standing at `p` alone against `obs` (`whole`: down to the nozzle tip): `None`
    /// where it clears, else where it comes too close (or is not proven clear).
    fn stands_clear(&self, obs: &Obstacles, p: &Pose, whole: bool) -> Option<HeadWitness> {
        let one = [Pose::at(p.position, p.axis.normalize())];
        let c = check_cut_along(obs, self.head, &one, &[], &self.options(whole));
        witness(obs, &c, &one)
    }

    /// Where no route of gap `g` can clear the head against `obs` (the surfaces with the most
    /// a route is checked without left out): every route starts with the retract from the
    /// cut's end and ends with the approach to the pierce, each through a retract point at one
    /// of the retract heights; so where the head standing at a cut's end comes too close, or
    /// the whole head at every retract point of one end does, that witness. `None` where each
    /// end has a retract point the head clears.
    fn no_route_clears(
        &self,
        g: &Gap,
        obs: &Obstacles,
        opts: &TraverseOptions,
    ) -> Option<HeadWitness> {
        let heights = crate::traverse::retract_heights(opts);
        [g.from, g.to].iter().find_map(|end| {
            if let Some(w) = self.stands_clear(obs, end, false) {
                return Some(w);
            }
            let n = end.axis.normalize();
            let mut lowest = None;
            for h in heights {
                match self.stands_clear(obs, &Pose::at(end.position + n * h, n), true) {
                    None => return None,
                    Some(w) => {
                        lowest.get_or_insert(w);
                    }
                }
            }
            lowest
        })
    }

    /// The head along the joint-linear moves through `axes` (sampled every
    /// [`SAMPLE_STEP_MM`] of the tip, the rotary axes' departure from the great circle counted
    /// on each sample step), `whole` or with the tip zone left out: the least distance proven,
    /// or where it comes too close.
    fn along(&self, kin: &dyn Kinematics, obs: &Obstacles, axes: &[Axes], whole: bool) -> HeadMove {
        let mut poses: Vec<Pose> = Vec::new();
        let mut bends: Vec<f64> = Vec::new();
        if let [one] = axes {
            poses.push(kin.forward(one));
        }
        for w in axes.windows(2) {
            let samples = joint_samples(kin, &w[0], &w[1], SAMPLE_STEP_MM);
            let k = (samples.len() - 1) as f64;
            let (dt, dc) = ((w[1].tilt - w[0].tilt) / k, (w[1].c - w[0].c) / k);
            let skip = usize::from(!poses.is_empty());
            for (j, p) in samples.iter().enumerate().skip(skip) {
                if j > 0 {
                    let start = w[0].tilt + dt * (j - 1) as f64;
                    bends.push(axis_curvature(
                        start.to_radians(),
                        dt.to_radians(),
                        dc.to_radians(),
                    ));
                }
                poses.push(Pose::at(p.position, p.axis.normalize()));
            }
        }
        let c = check_cut_along(obs, self.head, &poses, &bends, &self.options(whole));
        match witness(obs, &c, &poses) {
            Some(w) => Err(w),
            None => Ok(c.min_distance_mm),
        }
    }

    /// The head along the machine's moves of `r` for gap `g` against `obs`, each move checked
    /// by `one_move` (the move's two axes, whether with the whole head; [`Self::along`] or a
    /// cache of it): the retract from the cut's end to the first waypoint and the approach
    /// from the last to the pierce with the tip zone left out, the moves of the travel between
    /// them with the whole head (the head standing at the two retract points first: a route
    /// from one it does not clear fails at once).
    fn check(
        &self,
        g: &Gap,
        obs: &Obstacles,
        r: &RapidMoves,
        one_move: &mut dyn FnMut([Axes; 2], bool) -> HeadMove,
    ) -> HeadMove {
        let (Some(first), Some(last)) = (r.axes.first(), r.axes.last()) else {
            return one_move([g.from_axes, g.to_axes], false);
        };
        for p in [r.poses.first(), r.poses.last()].into_iter().flatten() {
            if let Some(w) = self.stands_clear(obs, p, true) {
                return Err(w);
            }
        }
        let mut least = one_move([g.from_axes, *first], false)?;
        least = least.min(one_move([*last, g.to_axes], false)?);
        for w in r.axes.windows(2) {
            least = least.min(one_move([w[0], w[1]], true)?);
        }
        Ok(least)
    }
}

/// The axes that put the tip at `tip` with the rotary axes at `tilt`, `c` (degrees).
fn linear_at(kin: &dyn Kinematics, tip: &Point3<f64>, tilt: f64, c: f64) -> Axes {
    let axis = kin.forward(&Axes::new(0.0, 0.0, 0.0, tilt, c)).axis;
    let q = kin.inverse_with_c(
        &Pose {
            position: *tip,
            axis,
        },
        c,
    );
    Axes::new(q.x, q.y, q.z, tilt, c)
}

/// Where the tool axis is this close to the C axis (radians), C is free: a waypoint there keeps
/// the C of its neighbours instead of the inverse's arbitrary one.
const POLE_RAD: f64 = 1e-9;

/// The rotary axes `[tilt, C]` (degrees) of every waypoint of a traverse: the first waypoints,
/// as long as they keep the exit's tool axis, stand at `from`'s rotaries (the head backed off
/// along that axis), the last ones, as long as they keep the pierce's tool axis, at `to`'s (it
/// approaches along it); where every waypoint keeps one axis, the first half takes `from`'s and
/// the rest `to`'s. A waypoint with another tool axis (a head turned upright or to an
/// intermediate axis on the way) takes the inverse solution with the least rotary travel from
/// the waypoint before it (within `tilt`, the tilt axis' range, where one is), and where its axis
/// is along the C axis (C is then free) the C of the waypoint before it, except the last of
/// such a run, which takes the C of the waypoint after it: the moves into and out of the upright
/// run then turn the tilt alone, in the plane of the tool axes, as the traverse's check assumes.
pub(crate) fn waypoint_rotaries(
    kin: &dyn Kinematics,
    way: &[Pose],
    from: &Axes,
    to: &Axes,
    tilt: Option<(f64, f64)>,
) -> Vec<[f64; 2]> {
    let n = way.len();
    let axis = |i: usize| way[i].axis;
    let same = |a: Vector3<f64>, b: Vector3<f64>| (a - b).norm() <= 1e-12 * (1.0 + a.norm());
    let (rf, rt) = ([from.tilt, from.c], [to.tilt, to.c]);
    if n == 0 {
        return Vec::new();
    }
    // The waypoints 0..=p keep the first axis, s..n the last.
    let mut p = 0;
    while p + 1 < n && same(axis(p + 1), axis(0)) {
        p += 1;
    }
    let mut s = n - 1;
    while s > 0 && same(axis(s - 1), axis(n - 1)) {
        s -= 1;
    }
    if s <= p {
        return (0..n).map(|i| if i < n / 2 { rf } else { rt }).collect();
    }
    let mut rot: Vec<[f64; 2]> = (0..n).map(|i| if i <= p { rf } else { rt }).collect();
    let fits = |t: f64| tilt.is_none_or(|(lo, hi)| t >= lo && t <= hi);
    let mut pole = vec![false; n];
    for i in p + 1..s {
        let prev = rot[i - 1];
        let pose = Pose {
            position: way[i].position,
            axis: axis(i).normalize(),
        };
        if kin.pole_angle(&pose.axis) <= POLE_RAD {
            let q = kin.inverse_with_c(&pose, prev[1]);
            rot[i] = [kerf_kinematics::nearest_turn(q.tilt, prev[0]), prev[1]];
            pole[i] = true;
            continue;
        }
        let reference = Axes::new(0.0, 0.0, 0.0, prev[0], prev[1]);
        let candidates = kin.inverse(&pose);
        let q = kerf_kinematics::nearest_solution(candidates, &reference, |q| fits(q.tilt))
            .or_else(|| kerf_kinematics::nearest_solution(candidates, &reference, |_| true))
            .unwrap_or(candidates[0]);
        rot[i] = [q.tilt, q.c];
    }
    // The last waypoint of an upright run takes the C of the one after it.
    for i in p + 1..s {
        if pole[i] && !pole[i + 1] {
            rot[i][1] = rot[i + 1][1];
        }
    }
    rot
}

/// The poses of the joint-linear move `a -> b`, sampled so that the tip moves at most
/// `step` between samples (doubling the count until it does, at most 2^16 samples).
fn joint_samples(kin: &dyn Kinematics, a: &Axes, b: &Axes, step: f64) -> Vec<Pose> {
    let at = |f: f64| kin.forward(&a.lerp(b, f));
    let mut k = 8usize;
    loop {
        let poses: Vec<Pose> = (0..=k).map(|j| at(j as f64 / k as f64)).collect();
        let widest = poses
            .windows(2)
            .map(|w| {
                let (p, q) = (w[0].position, w[1].position);
                ((q.x - p.x).powi(2) + (q.y - p.y).powi(2) + (q.z - p.z).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        if widest <= step || k >= 1 << 16 {
            return poses;
        }
        k *= 2;
    }
}

/// The machine's rapid moves for `traverse`, from the axes where the last cut ended
/// (`end_axes`) to those where the next one starts (`start_axes`), `[X, Y, Z, tilt, C]`.
///
/// The rotary axes stand while the head backs off and rises (the waypoints with the exit's
/// tool axis keep `end_axes`' rotaries), and turn on the move to the first waypoint with the
/// next tool axis; the linear axes of each waypoint put the tip on it. Every move between
/// waypoints is then run as the machine runs a rapid, all axes linear, sampled through the
/// forward kinematics (the tip at most an eighth of the clearance between samples), and
/// checked like the traverse (tip and nozzle keep the clearance); a move that does not is
/// split into 2, 4, ... 64 moves along the straight line between its waypoints, the rotary
/// axes shared out evenly, until each clears.
///
/// # Errors
/// [`ProcessError::TraverseBlocked`] if a move still comes too close when split 64 times.
pub fn rapid_moves(
    kin: &dyn Kinematics,
    obs: &Obstacles,
    end_axes: Axes,
    start_axes: Axes,
    traverse: &Traverse,
    opts: &TraverseOptions,
) -> Result<RapidMoves> {
    rapid_moves_within(kin, obs, end_axes, start_axes, traverse, opts, None).map_err(|r| r.error)
}

/// Why the machine's own moves along a route are refused: the blockage, and whether the split
/// that would clear it leaves the axis limits.
struct MovesRefused {
    error: ProcessError,
    outside_limits: bool,
}

/// True when every limited axis of `q` lies inside its range, a thousandth of the range
/// from either end.
fn inside_limits(q: &Axes, limits: &[Option<(f64, f64)>; 5]) -> bool {
    q.to_array().iter().zip(limits).all(|(v, l)| {
        l.is_none_or(|(lo, hi)| {
            let m = 1e-3 * (hi - lo);
            *v >= lo + m && *v <= hi - m
        })
    })
}

/// [`rapid_moves`] within the machine's `limits`, where given: the waypoints' rotaries chosen
/// within the tilt axis' range (where a waypoint turns the head to another tool axis,
/// [`waypoint_rotaries`]), and a move split only at points inside every range (a split point
/// lies on the tip's straight line with the rotaries shared out, where the linear axes can
/// swing past both ends; the machine's own straight moves between in-range ends cannot).
fn rapid_moves_within(
    kin: &dyn Kinematics,
    obs: &Obstacles,
    end_axes: Axes,
    start_axes: Axes,
    traverse: &Traverse,
    opts: &TraverseOptions,
    limits: Option<&[Option<(f64, f64)>; 5]>,
) -> std::result::Result<RapidMoves, MovesRefused> {
    let tilt = limits.and_then(|l| l[3]);
    let c = opts.clearance_mm;
    let step = c / 8.0;
    let rot = waypoint_rotaries(kin, &traverse.waypoints, &end_axes, &start_axes, tilt);
    let waypoint_axes: Vec<Axes> = traverse
        .waypoints
        .iter()
        .zip(&rot)
        .map(|(w, r)| linear_at(kin, &w.position, r[0], r[1]))
        .collect();
    let mut axes = Vec::new();
    let mut least = f64::INFINITY;
    let mut split_moves = 0;
    for (i, w) in waypoint_axes.iter().enumerate() {
        if i == 0 {
            axes.push(*w);
            continue;
        }
        let a = waypoint_axes[i - 1];
        let b = *w;
        let mut pieces = 1;
        loop {
            // The pieces' ends: on the straight line between the waypoints' tips.
            let ta = kin.forward(&a).position;
            let tb = kin.forward(&b).position;
            // The axes at fraction `f` of the tip's straight line, the rotaries shared out.
            let split_at = |f: f64| {
                linear_at(
                    kin,
                    &(ta + (tb - ta) * f),
                    a.tilt + (b.tilt - a.tilt) * f,
                    a.c + (b.c - a.c) * f,
                )
            };
            let ends: Vec<Axes> = (0..=pieces)
                .map(|j| {
                    if j == 0 {
                        a
                    } else if j == pieces {
                        b
                    } else {
                        split_at(j as f64 / pieces as f64)
                    }
                })
                .collect();
            let mut worst: Option<(Point3<f64>, f64)> = None;
            let mut here = f64::INFINITY;
            for e in ends.windows(2) {
                let samples = joint_samples(kin, &e[0], &e[1], step);
                match check_move(obs, &samples, c, opts.nozzle_mm) {
                    Ok(d) => here = here.min(d),
                    Err(bad) => {
                        worst = Some(bad);
                        break;
                    }
                }
            }
            // The move still too close at `at` (`d` mm from the part), and why it stays so.
            let blocked = |at: Point3<f64>, d: f64, why: String| {
                ProcessError::TraverseBlocked(Box::new(crate::Blockage {
                    from: [ta.x, ta.y, ta.z],
                    to: [tb.x, tb.y, tb.z],
                    at: [at.x, at.y, at.z],
                    distance_mm: d,
                    clearance_mm: c,
                    why,
                }))
            };
            match worst {
                None => {
                    least = least.min(here);
                    if pieces > 1 {
                        split_moves += 1;
                    }
                    axes.extend_from_slice(&ends[1..]);
                    break;
                }
                Some((at, d)) if pieces >= MAX_SPLIT => {
                    let why = format!(
                        "the machine's rapid move swings too close even split {MAX_SPLIT} times"
                    );
                    return Err(MovesRefused {
                        outside_limits: false,
                        error: blocked(at, d, why),
                    });
                }
                Some((at, d)) => {
                    pieces *= 2;
                    // The points of the finer split, where the machine must reach them.
                    let outside = limits.is_some_and(|l| {
                        (1..pieces).any(|j| !inside_limits(&split_at(j as f64 / pieces as f64), l))
                    });
                    if outside {
                        let why = "the machine's rapid move swings too close, and the points that would split it leave the axis limits";
                        return Err(MovesRefused {
                            outside_limits: true,
                            error: blocked(at, d, why.into()),
                        });
                    }
                }
            }
        }
    }
    let poses = axes.iter().map(|a| kin.forward(a)).collect();
    Ok(RapidMoves {
        axes,
        poses,
        min_distance_mm: least,
        split_moves,
        head_min_distance_mm: None,
        head_too_close: None,
    })
}

/// One gap between two cuts: where the last ended and where the next starts, each as the tip
/// with its tool axis (workpiece frame) and the machine axes `[X, Y, Z, tilt, C]` there.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    /// The end of the last cut (its lead-out's end).
    pub from: Pose,
    /// The machine axes there.
    pub from_axes: Axes,
    /// The next pierce point.
    pub to: Pose,
    /// The machine axes there.
    pub to_axes: Axes,
    /// The last cutting point of the last cut on its contour (before the lead-out), mm.
    pub from_contour: Point3<f64>,
    /// The first cutting point of the next cut on its contour (after the lead-in), mm.
    pub to_contour: Point3<f64>,
    /// The surfaces the last cut's curve names (ids as in [`Obstacles::from_file`]).
    pub from_surfaces: Vec<String>,
    /// The surfaces the next cut's curve names.
    pub to_surfaces: Vec<String>,
}

/// The surfaces that the head meets at a gap's ends while it cuts or pierces there, and
/// which no traverse can therefore keep the clearance from: for each end (the last cut's
/// contour end and its exit, the next cut's pierce and its contour start), the line along the
/// tool axis there up to the retract plus the nozzle (the head is on the part of that line the
/// nozzle covers while it cuts or pierces, and backs off along it), and
///
/// - a surface the cut's curve does not name that comes within half the clearance of the line
///   from its foot: not there while that contour is cut (a file holding two workpieces in the
///   same place, as a tube joint's hole in the main tube and the end of the branch tube, lists
///   both, and each contour passes through the other workpiece) or in the way of the cut;
/// - a surface the curve names (its own carrying surface) that comes within half the
///   clearance of the line from three quarters of the clearance up: the surface curls back
///   over the head (a hole narrower than about the clearance whose tool axis is its wall's
///   normal, a tight bend's inside), so the cut's own nozzle meets it.
///
/// Ids as in [`Obstacles::from_file`], each once, in the order found.
pub fn in_the_cuts_way(obs: &Obstacles, g: &Gap, opts: &TraverseOptions) -> Vec<String> {
    cuts_way(obs, g, opts, true)
}

/// Of [`in_the_cuts_way`], only the surfaces a cut's curve names itself (its own surface
/// curling back over the head line from three quarters of the clearance up): where such a
/// surface is left out, that cut's own nozzle meets its surface.
pub fn own_surfaces_over_the_head(obs: &Obstacles, g: &Gap, opts: &TraverseOptions) -> Vec<String> {
    let c = opts.clearance_mm;
    let mut own: Vec<String> = Vec::new();
    let (exit, pierce) = (g.from.position, g.to.position);
    for (p, axis, named) in [
        (&g.from_contour, &g.from, &g.from_surfaces),
        (&exit, &g.from, &g.from_surfaces),
        (&g.to_contour, &g.to, &g.to_surfaces),
        (&pierce, &g.to, &g.to_surfaces),
    ] {
        let at = *p;
        let n = axis
            .axis
            .try_normalize(1e-12)
            .unwrap_or_else(nalgebra::Vector3::z);
        let top = at + n * (opts.retract_mm + opts.nozzle_mm);
        for id in obs.near_segment(&(at + n * (0.75 * c)), &top, 0.5 * c) {
            if named.contains(&id) && !own.contains(&id) {
                own.push(id);
            }
        }
    }
    own
}

/// [`in_the_cuts_way`]; with `all` false, only the surfaces the curves do not name on the
/// contour lines (what [`plan_rapids`] leaves out first).
fn cuts_way(obs: &Obstacles, g: &Gap, opts: &TraverseOptions, all: bool) -> Vec<String> {
    let c = opts.clearance_mm;
    let mut absent: Vec<String> = Vec::new();
    let (exit, pierce) = (g.from.position, g.to.position);
    let lines: Vec<(&Point3<f64>, &Pose, &Vec<String>)> = if all {
        vec![
            (&g.from_contour, &g.from, &g.from_surfaces),
            (&exit, &g.from, &g.from_surfaces),
            (&g.to_contour, &g.to, &g.to_surfaces),
            (&pierce, &g.to, &g.to_surfaces),
        ]
    } else {
        vec![
            (&g.from_contour, &g.from, &g.from_surfaces),
            (&g.to_contour, &g.to, &g.to_surfaces),
        ]
    };
    for (p, axis, named) in lines {
        let at = *p;
        let n = axis
            .axis
            .try_normalize(1e-12)
            .unwrap_or_else(nalgebra::Vector3::z);
        let top = at + n * (opts.retract_mm + opts.nozzle_mm);
        let mut add = |id: String| {
            if !absent.contains(&id) {
                absent.push(id);
            }
        };
        for id in obs.near_segment(&at, &top, 0.5 * c) {
            if !named.contains(&id) {
                add(id);
            }
        }
        if !all {
            continue;
        }
        let low = at + n * (0.75 * c);
        for id in obs.near_segment(&low, &top, 0.5 * c) {
            if named.contains(&id) {
                add(id);
            }
        }
    }
    absent
}

/// `e` (no route clears the tip and nozzle line) with where the head came too close too.
fn with_head_witness(e: ProcessError, w: &HeadWitness) -> ProcessError {
    match e {
        ProcessError::TraverseBlocked(mut b) => {
            b.why = format!("{}; the head model comes {w} as well", b.why);
            ProcessError::TraverseBlocked(b)
        }
        other => other,
    }
}

/// Plans and checks the traverse of every gap ([`crate::plan_traverse_within`] among the
/// routes whose waypoints lie within `limits`, `(min, max)` of `[X, Y, Z, tilt, C]` or `None`
/// for an unlimited axis, then [`rapid_moves`]), in order; one result per gap (a blocked gap does not stop the others:
/// the caller decides, e.g. to fall back to an unchecked traverse and say so).
///
/// Which surfaces are checked: all of `obs`, except, for one gap, those a cut's curve does not
/// name that come within half the clearance of the tool axis line at the last cut's contour
/// end or the next cut's contour start; only where no route clears then (and the head, if
/// any, refused none of those the tip and nozzle line clear), all those [`in_the_cuts_way`]
/// at its two ends. The ids left out are returned with the gap so that they can be reported.
/// Where the head clears no route, the gap is planned without it and
/// [`RapidMoves::head_too_close`] says where it came too close.
///
/// A route is taken only if its waypoints and the interpolated moves between them lie within
/// the limits and the machine's own rapid moves ([`rapid_moves`]) clear too, and, with `head`,
/// the head model along those moves ([`TraverseHead`]); otherwise the next shortest route is
/// tried.
///
/// Each result's error is as [`crate::plan_traverse`] and [`rapid_moves`].
pub fn plan_rapids(
    kin: &dyn Kinematics,
    limits: &[Option<(f64, f64)>; 5],
    obs: &Obstacles,
    gaps: &[Gap],
    opts: &TraverseOptions,
    head: Option<&TraverseHead<'_>>,
) -> Vec<Result<(Traverse, RapidMoves, Vec<String>)>> {
    use rayon::prelude::*;
    gaps.par_iter()
        .map(|g| {
            // First with the surfaces a cut's curve does not name on its contour lines left
            // out; only where no route clears then, with all those in the cuts' way.
            let first = cuts_way(obs, g, opts, false);
            // A route is tried only if the machine reaches its waypoints (with the rotary
            // axes as [`rapid_moves`] sets them): the machine runs each rapid straight in its
            // axes, inside the limits when its ends are (the points a split move adds are
            // checked where it is split, `rapid_moves_within`).
            let reachable = |way: &[Pose]| {
                let rots = waypoint_rotaries(kin, way, &g.from_axes, &g.to_axes, limits[3]);
                way.iter().zip(&rots).all(|(w, r)| {
                    let tip = w.position;
                    inside_limits(&linear_at(kin, &tip, r[0], r[1]), limits)
                })
            };
            // Where no route clears with `first` left out and more surfaces are in the cuts'
            // way, the reason is not reported (the gap is tried again without them).
            let all = cuts_way(obs, g, opts, true);
            // A route is taken only if the machine's own rapid moves along it clear too, and
            // the head along them (`with_head`); where the head refuses a route, the first
            // refusal is kept.
            let refused: std::cell::RefCell<Option<HeadWitness>> = Default::default();
            // The head's surfaces for the gap, with `first` and with `all` left out (built once:
            // every route the gap tries queries them).
            let head_obs = head.map(|h| [h.obstacles_of(g, &first), h.obstacles_of(g, &all)]);
            // Each machine move's head check, once per gap: the routes of a gap share their
            // retract and approach and many of their moves.
            let head_moves: std::cell::RefCell<std::collections::HashMap<HeadMoveKey, HeadMove>> =
                Default::default();
            let plan = |with_all: bool, explain: bool, with_head: bool| {
                let absent = if with_all { &all } else { &first };
                let here = obs.without(absent);
                crate::traverse::plan_traverse_accepting(
                    &here,
                    &g.from,
                    &g.to,
                    opts,
                    &reachable,
                    &mut |t| {
                        rapid_moves_within(
                            kin,
                            &here,
                            g.from_axes,
                            g.to_axes,
                            t,
                            opts,
                            Some(limits),
                        )
                        .map_err(|r| {
                            let (at, distance) = match r.error {
                                ProcessError::TraverseBlocked(b) => {
                                    (Point3::from(b.at), b.distance_mm)
                                }
                                _ => (g.from_contour, 0.0),
                            };
                            crate::traverse::Refusal {
                                at,
                                distance,
                                outside_limits: r.outside_limits,
                            }
                        })
                        .and_then(|mut r| {
                            let (Some(h), Some(ho), true) = (head, &head_obs, with_head) else {
                                return Ok(r);
                            };
                            let k = usize::from(with_all);
                            match h.check(g, &ho[k], &r, &mut |m: [Axes; 2], whole: bool| {
                                let key = (m.map(|a| a.to_array().map(f64::to_bits)), whole, k);
                                if let Some(known) = head_moves.borrow().get(&key) {
                                    return known.clone();
                                }
                                let outcome = h.along(kin, &ho[k], &m, whole);
                                head_moves.borrow_mut().insert(key, outcome.clone());
                                outcome
                            }) {
                                Ok(d) => {
                                    r.head_min_distance_mm = Some(d);
                                    Ok(r)
                                }
                                Err(w) => {
                                    let refusal = crate::traverse::Refusal {
                                        at: w.at,
                                        distance: w.distance_mm.unwrap_or(0.0),
                                        outside_limits: false,
                                    };
                                    // The first route the head refused: the one the nozzle
                                    // line's check alone takes, if no route clears the head.
                                    refused.borrow_mut().get_or_insert(w);
                                    Err(refusal)
                                }
                            }
                        })
                    },
                    explain,
                )
            };
            let planned = |with_head: bool| match plan(false, all.len() == first.len(), with_head) {
                Ok((t, r)) => Ok((t, r, first.clone())),
                Err(e) => {
                    // Where the head refused routes the tip and nozzle line clear, fewer
                    // surfaces are not tried for the head's sake: the fallback plans without
                    // it, from `first` again.
                    let head_refused = with_head && refused.borrow().is_some();
                    if all.len() == first.len() || head_refused {
                        return Err(e);
                    }
                    let (t, r) = plan(true, true, with_head)?;
                    Ok((t, r, all.clone()))
                }
            };
            // Where the head stands too close at a cut's end, or clears no retract point at one
            // end, no route can clear it: the gap is planned without it.
            let hopeless = head
                .zip(head_obs.as_ref())
                .and_then(|(h, ho)| h.no_route_clears(g, &ho[1], opts));
            let outcome = planned(head.is_some() && hopeless.is_none());
            match (outcome, hopeless, refused.take()) {
                // Planned without the head: with where it comes too close.
                (Ok((t, mut r, a)), Some(w), _) => {
                    r.head_too_close = Some(w);
                    Ok((t, r, a))
                }
                (Err(e), Some(w), _) => Err(with_head_witness(e, &w)),
                // With the head (if any): every route taken cleared it.
                (Ok(ok), None, _) => Ok(ok),
                (Err(e), None, None) => Err(e),
                // The head refused every route the tip and nozzle line clear: the route
                // without the head, with where the head came too close on the first.
                (Err(_), None, Some(w)) => match planned(false) {
                    Ok((t, mut r, a)) => {
                        r.head_too_close = Some(w);
                        Ok((t, r, a))
                    }
                    Err(e) => Err(with_head_witness(e, &w)),
                },
            }
        })
        .collect()
}
