//! The head along the cuts: every cut of a set-up checked against the part it lies on
//! ([`kerf_process::check_cut_along`], counting the rotary axes' linear interpolation); where
//! the head comes too close, the tool axis is tilted within the tilt tolerance, away from the
//! surface in the way, and the path solved again (`docs/process.md`, "The head along the
//! cuts").

use kerf_kinematics::{
    solve_path, tilt_within_cones, Cone, Head, Machine, PathInput, PathOptions, Pose, SolvedPath,
};
use kerf_process::{check_cut, check_cut_along, CutClearance, HeadCheckOptions, Obstacles};
use nalgebra::{Point3, Vector3};

use crate::report::{HeadPath, HeadReport, HeadStretch, HeadTilt};

/// How near a surface's boundary must come to another for the two to be one part, mm (CAD
/// edges meet within hundredths of a millimetre).
pub(crate) const PART_JOIN_TOLERANCE_MM: f64 = 0.05;

/// What a refusal for the head says the user can do (the options by their library names; the
/// command line adds its flags).
pub(crate) const WAYS_OUT: &str = "; accept_head_collisions takes it with a warning, cut_clearance_mm sets another clearance or turns the check off";

/// Rounds of tilting and checking again a path may take.
const MAX_ROUNDS: usize = 4;

/// Steps of the tilt search within the tolerance (the smallest clearing tilt is taken).
const TILT_STEPS: usize = 8;

/// The largest tilt the refusal's "would clear" search tries, degrees.
const MAX_NEEDED_TILT_DEG: f64 = 60.0;

/// What the check and the avoidance did to the cuts of one set-up.
#[derive(Debug, Default)]
pub(crate) struct HeadOutcome {
    /// One report entry per path.
    pub report: Vec<HeadPath>,
    /// Collisions accepted as warnings.
    pub warnings: Vec<String>,
    /// The tip zone the check left out, mm.
    pub tip_zone_mm: Option<f64>,
    /// A refusal (the first path that could not be cleared), unless accepted.
    pub refusal: Option<kerf_process::ProcessError>,
    /// Per cut checked (its index) with anything to mark, where the picture marks it.
    pub marks: Vec<(usize, HeadMarks)>,
}

/// Where the picture marks what the head check did to one cut: ranges `[first, last]` of its
/// cutting points (indices into the cut's poses: lead-in, contour, lead-out).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct HeadMarks {
    /// Runs of cutting points whose tool axis was tilted to clear the head.
    pub(crate) tilted: Vec<[usize; 2]>,
    /// Stretches where the head came within the clearance (accepted as warnings), widened to
    /// the cutting points around them.
    pub(crate) close: Vec<[usize; 2]>,
}

impl HeadMarks {
    /// The marks of a cut whose cutting points `tilted` says were tilted, with the close
    /// stretches of `c` (indices into the solved poses, whose `source` gives the cutting point
    /// each stands on).
    fn of(s: &SolvedPath, c: &CutClearance, tilted: &[bool]) -> Self {
        let mut runs = Vec::new();
        let mut k = 0;
        while k < tilted.len() {
            if tilted[k] {
                let start = k;
                while k + 1 < tilted.len() && tilted[k + 1] {
                    k += 1;
                }
                runs.push([start, k]);
            }
            k += 1;
        }
        let last = tilted.len().saturating_sub(1);
        let close = c
            .close
            .iter()
            .map(|st| {
                let [a, b] = st.poses.map(|i| i.min(s.source.len().saturating_sub(1)));
                let lo = s.source[..=a].iter().rev().find_map(|x| *x).unwrap_or(0);
                let hi = s.source[b..].iter().find_map(|x| *x).unwrap_or(last);
                [lo.min(last), hi.min(last)]
            })
            .collect();
        Self {
            tilted: runs,
            close,
        }
    }

    /// True if there is nothing to mark.
    pub(crate) fn is_empty(&self) -> bool {
        self.tilted.is_empty() && self.close.is_empty()
    }
}

/// The tool axis tilted by `alpha` (radians) from `n` toward the unit `d` (at right angles to
/// `n`).
fn tilted(n: &Vector3<f64>, d: &Vector3<f64>, alpha: f64) -> Vector3<f64> {
    (n * alpha.cos() + d * alpha.sin()).normalize()
}

/// The direction at right angles to `n` pointing away from `w` seen from `p` (any
/// perpendicular where `w` lies on the axis line).
fn away(n: &Vector3<f64>, p: &Point3<f64>, w: &Point3<f64>) -> Vector3<f64> {
    let v = w - p;
    let d = -(v - n * n.dot(&v));
    if d.norm() > 1e-9 {
        d.normalize()
    } else {
        n.cross(&Vector3::x())
            .try_normalize(1e-9)
            .unwrap_or_else(|| n.cross(&Vector3::y()).normalize())
    }
}

/// The margin a tilt must clear beyond the clearance, mm: room for the taut strings between
/// the tilted cutting points and for the check of the tilted path, which proves a distance
/// near its requirement only with fine cells.
const TILT_MARGIN_MM: f64 = 0.5;

/// The most distance queries one placement of the head may take while searching a tilt.
const PLACEMENT_QUERIES: usize = 100_000;

/// The direction at right angles to `n` in which the head point `w` moves away from the part
/// fastest: the gradient of the distance to the part at `w` (central differences over
/// 0.01 mm), less its part along `n`; `None` where that is too small to tell.
fn escape(obs: &Obstacles, n: &Vector3<f64>, w: &Point3<f64>) -> Option<Vector3<f64>> {
    let e = 0.01;
    let g = Vector3::from_fn(|i, _| {
        let mut dv = Vector3::zeros();
        dv[i] = e;
        (obs.distance(&(w + dv)) - obs.distance(&(w - dv))) / (2.0 * e)
    });
    let t = g - n * n.dot(&g);
    (t.iter().all(|v| v.is_finite()) && t.norm() > 0.1).then(|| t.normalize())
}

/// The head standing once at `(p, axis)` with `opts`, its queries (at most
/// [`PLACEMENT_QUERIES`]) taken from `budget`.
fn place_once(
    obs: &Obstacles,
    head: &Head,
    opts: &HeadCheckOptions,
    p: Point3<f64>,
    axis: Vector3<f64>,
    budget: &mut usize,
) -> CutClearance {
    let opts = opts.with_max_queries(PLACEMENT_QUERIES.min(*budget));
    let c = check_cut(obs, head, &[Pose { position: p, axis }], &opts);
    *budget = budget.saturating_sub(c.queries);
    c
}

/// True if the head standing at `(p, axis)` keeps the clearance plus [`TILT_MARGIN_MM`] (a
/// single placement; none of the budget left: false).
fn clears(
    obs: &Obstacles,
    head: &Head,
    opts: &HeadCheckOptions,
    p: Point3<f64>,
    axis: Vector3<f64>,
    budget: &mut usize,
) -> bool {
    let opts = opts.with_clearance_mm(opts.clearance_mm + TILT_MARGIN_MM);
    let c = place_once(obs, head, &opts, p, axis, budget);
    c.proven && c.close.is_empty()
}

/// A head point that a placement at `(p, axis)` witnesses within the clearance, if any.
fn witness(
    obs: &Obstacles,
    head: &Head,
    opts: &HeadCheckOptions,
    p: Point3<f64>,
    axis: Vector3<f64>,
    budget: &mut usize,
) -> Option<Point3<f64>> {
    let c = place_once(obs, head, opts, p, axis, budget);
    c.close.first().map(|st| st.point)
}

/// The input pose indices a range of solved poses covers (inserted poses belong to the
/// stretch between their neighbours).
fn input_range(s: &SolvedPath, [a, b]: [usize; 2]) -> [usize; 2] {
    let lo = (0..=a.min(s.source.len() - 1))
        .rev()
        .find_map(|j| s.source[j])
        .unwrap_or(0);
    let hi = (b.min(s.source.len() - 1)..s.source.len())
        .find_map(|j| s.source[j])
        .unwrap_or(lo);
    [lo, hi.max(lo)]
}

/// Checks the cuts `ks` of one set-up (their solved paths in `solved`, the poses with their
/// normals in `inputs`, cut `k` against `obstacles(k)`) and tilts the tool axis within the tilt tolerance where the head comes
/// too close; a path that cannot be cleared is a refusal (or a warning when `accept`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_and_clear(
    machine: &Machine,
    obstacles: impl Fn(usize) -> Obstacles,
    head: &Head,
    hopts: &HeadCheckOptions,
    popts: &PathOptions,
    inputs: &[PathInput<'_>],
    ks: &[usize],
    solved: &mut [SolvedPath],
    accept: bool,
) -> HeadOutcome {
    let mut out = HeadOutcome::default();
    let theta =
        popts.tilt_tolerance_deg.max(0.0).to_radians() * kerf_kinematics::TILT_WORKING_FRACTION;
    for &k in ks {
        // After a refusal the run stops: the other cuts are not checked.
        if out.refusal.is_some() {
            break;
        }
        let own = obstacles(k);
        let obs = &own;
        // One work budget for the cut: the checks and the tilt search.
        let mut budget = hopts.max_queries;
        let mut c = check_cut_along(
            obs,
            head,
            &solved[k].poses,
            &rotary_curvature(&solved[k]),
            hopts,
        );
        budget = budget.saturating_sub(c.queries);
        out.tip_zone_mm = Some(c.tip_zone_mm);
        let normals = inputs[k].poses;
        // Required tilt and its direction per input pose.
        let mut need: Vec<Option<(f64, Vector3<f64>)>> = vec![None; normals.len()];
        // The tilts of the last path solved (what the report states).
        let mut applied: Vec<Option<(f64, Vector3<f64>)>> = need.clone();
        let mut rounds = 0;
        let mut unclearable: Vec<String> = Vec::new();
        while !c.close.is_empty() && theta > 0.0 && rounds < MAX_ROUNDS && unclearable.is_empty() {
            rounds += 1;
            let found = find_tilts(
                &Tilting {
                    obs,
                    head,
                    hopts,
                    popts,
                    theta,
                },
                &solved[k],
                normals,
                &c.close,
                &mut need,
                &mut budget,
            );
            if let Err(why) = found {
                unclearable.push(why);
                break;
            }
            match solve_tilted(machine, &inputs[k], &need, popts) {
                Ok(s) => {
                    solved[k] = s;
                    applied = need.clone();
                }
                Err(why) => {
                    unclearable.push(why);
                    break;
                }
            }
            let left = hopts.with_max_queries(budget);
            c = check_cut_along(
                obs,
                head,
                &solved[k].poses,
                &rotary_curvature(&solved[k]),
                &left,
            );
            budget = budget.saturating_sub(c.queries);
        }
        let tilted_poses = applied.iter().filter(|n| n.is_some()).count();
        let max_tilt_deg = applied
            .iter()
            .flatten()
            .map(|(a, _)| a.to_degrees())
            .fold(0.0, f64::max);
        let entry = report_entry(&solved[k], &c, rounds, tilted_poses, max_tilt_deg);
        let tilted: Vec<bool> = applied.iter().map(Option::is_some).collect();
        let marks = HeadMarks::of(&solved[k], &c, &tilted);
        if !marks.is_empty() {
            out.marks.push((k, marks));
        }
        if c.close.is_empty() && c.proven {
            out.report.push(entry);
            continue;
        }
        let mut reasons = describe(&solved[k], &c, hopts.clearance_mm);
        if theta == 0.0 {
            reasons.extend(worst_needed_tilt(
                obs,
                head,
                hopts,
                &solved[k],
                normals,
                &c.close,
                &mut budget,
            ));
        }
        reasons.extend(unclearable);
        let e = kerf_process::ProcessError::HeadTooClose {
            id: solved[k].id.clone(),
            reason: reasons.join("; "),
        };
        out.report.push(entry);
        if accept {
            out.warnings
                .push(format!("{e} (accepted: accept_head_collisions)"));
        } else if out.refusal.is_none() {
            out.refusal = Some(kerf_process::ProcessError::HeadTooClose {
                id: solved[k].id.clone(),
                reason: format!("{}{WAYS_OUT}", reasons.join("; ")),
            });
        }
    }
    out
}

/// Without a tilt tolerance: what tilt would clear the worst of the `close` stretches of `s`
/// at its middle cutting point (of `normals`), in words.
fn worst_needed_tilt(
    obs: &Obstacles,
    head: &Head,
    hopts: &HeadCheckOptions,
    s: &SolvedPath,
    normals: &[Pose],
    close: &[kerf_process::CloseStretch],
    budget: &mut usize,
) -> Option<String> {
    let st = close
        .iter()
        .min_by(|a, b| a.distance_mm.total_cmp(&b.distance_mm))?;
    let [lo, hi] = input_range(s, st.poses);
    let i = (lo + hi) / 2;
    Some(needed_tilt(
        obs,
        head,
        hopts,
        &normals[i],
        i,
        st,
        0.0,
        budget,
    ))
}

/// What the tilt search of one cut works with.
struct Tilting<'a> {
    obs: &'a Obstacles,
    head: &'a Head,
    hopts: &'a HeadCheckOptions,
    popts: &'a PathOptions,
    /// The largest tilt the search tries, radians (the working share of the tolerance).
    theta: f64,
}

/// The tilt that clears every cutting point of the `close` stretches of `s` (the cut's
/// `normals`), raised in [`TILT_STEPS`] steps of `theta` from what `need` already holds, away
/// from the surface its own head meets (else the stretch's witness), into `need`.
///
/// # Errors
/// Where no tilt within the tolerance clears a point: the tilt that would, in words.
fn find_tilts(
    t: &Tilting<'_>,
    s: &SolvedPath,
    normals: &[Pose],
    close: &[kerf_process::CloseStretch],
    need: &mut [Option<(f64, Vector3<f64>)>],
    budget: &mut usize,
) -> Result<(), String> {
    let (obs, head, hopts, theta) = (t.obs, t.head, t.hopts, t.theta);
    for st in close {
        let [lo, hi] = input_range(s, st.poses);
        for i in lo..=hi {
            let p = normals[i].position;
            let n = normals[i].axis;
            // Away from what this cutting point's own head meets (upright on its normal),
            // else from the stretch's witness.
            let w = witness(obs, head, hopts, p, n, budget).unwrap_or(st.point);
            let d = escape(obs, &n, &w).unwrap_or_else(|| away(&n, &p, &w));
            let start = need[i].map_or(0, |(a, _)| {
                ((a / theta) * TILT_STEPS as f64).round() as usize
            });
            let found = (start + 1..=TILT_STEPS)
                .map(|j| theta * j as f64 / TILT_STEPS as f64)
                .find(|&a| clears(obs, head, hopts, p, tilted(&n, &d, a), budget));
            match found {
                Some(a) => need[i] = Some((a, d)),
                None => {
                    return Err(needed_tilt(
                        obs,
                        head,
                        hopts,
                        &normals[i],
                        i,
                        st,
                        t.popts.tilt_tolerance_deg,
                        budget,
                    ))
                }
            }
        }
    }
    Ok(())
}

/// The cut `input` solved again with its tool axes chosen within the cones: a pose that
/// `need`s a tilt holds its clearing axis, the others their tolerance (the path options'
/// own tilt tolerance then 0: the axes are given).
///
/// # Errors
/// The solver's refusal, in words.
fn solve_tilted(
    machine: &Machine,
    input: &PathInput<'_>,
    need: &[Option<(f64, Vector3<f64>)>],
    popts: &PathOptions,
) -> Result<SolvedPath, String> {
    let normals = input.poses;
    let cones: Vec<Cone> = normals
        .iter()
        .zip(need)
        .map(|(pose, req)| match req {
            Some((a, d)) => Cone {
                axis: tilted(&pose.axis, d, *a),
                half_angle_deg: 0.0,
            },
            None => Cone {
                axis: pose.axis,
                half_angle_deg: popts.tilt_tolerance_deg,
            },
        })
        .collect();
    let choice = tilt_within_cones(normals, &cones, popts.tilt_tolerance_deg);
    let poses: Vec<Pose> = normals
        .iter()
        .zip(&choice.axes)
        .map(|(p, a)| Pose {
            position: p.position,
            axis: *a,
        })
        .collect();
    let tilted_input = PathInput {
        id: input.id,
        poses: &poses,
        curve: input.curve,
    };
    let fixed = (*popts).with_tilt_tolerance_deg(0.0);
    let mut s = solve_path(machine, &tilted_input, &fixed)
        .map_err(|e| format!("the tilted path cannot be solved: {e}"))?;
    s.tilt = Some(choice.report);
    Ok(s)
}

/// The tilt away from the surface in the way that would clear cutting point `i` (`pose`, its
/// normal), in words, for a refusal.
#[allow(clippy::too_many_arguments)]
fn needed_tilt(
    obs: &Obstacles,
    head: &Head,
    hopts: &HeadCheckOptions,
    pose: &Pose,
    i: usize,
    st: &kerf_process::CloseStretch,
    tolerance_deg: f64,
    budget: &mut usize,
) -> String {
    let d = escape(obs, &pose.axis, &st.point)
        .unwrap_or_else(|| away(&pose.axis, &pose.position, &st.point));
    let surface = st.surface.as_deref().unwrap_or("?");
    // A placement left unproven (the work budget spent, a placement's own cap, an unusable
    // head zone) is not a tilt that fails to clear: the first reason is quoted.
    let mut unproven: Option<String> = None;
    let more = (1..)
        .map(|j| j as f64 * 2.5)
        .take_while(|a| *a <= MAX_NEEDED_TILT_DEG)
        .find(|a| {
            let margin = hopts.with_clearance_mm(hopts.clearance_mm + TILT_MARGIN_MM);
            let axis = tilted(&pose.axis, &d, a.to_radians());
            let c = place_once(obs, head, &margin, pose.position, axis, budget);
            if !c.proven && unproven.is_none() {
                unproven = Some(c.unproven.clone().unwrap_or_else(|| "unproven".to_string()));
            }
            c.proven && c.close.is_empty()
        });
    let usable = kerf_kinematics::MAX_TILT_TOLERANCE_DEG * kerf_kinematics::TILT_WORKING_FRACTION;
    match more {
        Some(a) if a > usable => format!(
            "at cutting point {i} a tilt of {a:.1} deg away from surface {surface} would clear it, beyond the largest tilt tolerance ({} deg): another placement or a smaller head",
            kerf_kinematics::MAX_TILT_TOLERANCE_DEG
        ),
        Some(a) => format!(
            "at cutting point {i} a tilt of {a:.1} deg away from surface {surface} would clear it (tilt tolerance {tolerance_deg} deg; a tilt_tolerance_deg of {} allows it)",
            (a / kerf_kinematics::TILT_WORKING_FRACTION).ceil()
        ),
        None if unproven.is_some() => format!(
            "at cutting point {i} no tilt away from surface {surface} was proven to clear it: {} (the head check's budget is {} distance queries)",
            unproven.unwrap_or_default(),
            hopts.max_queries
        ),
        None => format!(
            "at cutting point {i} no tilt up to {MAX_NEEDED_TILT_DEG} deg away from surface {surface} clears it"
        ),
    }
}

/// The close stretches of a path in words.
fn describe(s: &SolvedPath, c: &CutClearance, clearance: f64) -> Vec<String> {
    let length = |a: usize, b: usize| -> f64 {
        s.poses[a..=b]
            .windows(2)
            .map(|w| (w[1].position - w[0].position).norm())
            .sum::<f64>()
            + 0.0
    };
    let mut reasons: Vec<String> = c
        .close
        .iter()
        .map(|st| {
            format!(
                "poses {}..{} ({:.1} mm from the cut's start, {:.1} mm long): a head point {:.1} mm above the nozzle tip within {:.3} mm of surface {} (clearance {clearance} mm)",
                st.poses[0],
                st.poses[1],
                length(0, st.poses[0]),
                st.length_mm,
                st.at_height_mm,
                st.distance_mm,
                st.surface.as_deref().unwrap_or("?"),
            )
        })
        .collect();
    if !c.proven {
        reasons.push(format!(
            "not proven clear: {}",
            c.unproven.as_deref().unwrap_or("the check did not finish")
        ));
    }
    reasons
}

/// One path's entry of the report's `head.paths`.
fn report_entry(
    s: &SolvedPath,
    c: &CutClearance,
    rounds: usize,
    tilted_poses: usize,
    max_tilt_deg: f64,
) -> HeadPath {
    HeadPath {
        path: s.id.clone(),
        min_distance_mm: c.min_distance_mm.is_finite().then_some(c.min_distance_mm),
        at_pose: c.at_pose,
        close: c
            .close
            .iter()
            .map(|st| HeadStretch {
                poses: st.poses,
                length_mm: st.length_mm,
                distance_mm: st.distance_mm,
                at_height_mm: st.at_height_mm,
                surface: st.surface.clone(),
            })
            .collect(),
        proven: c.proven,
        tilted: HeadTilt {
            rounds,
            cutting_points: tilted_poses,
            max_tilt_deg,
        },
        samples: c.samples,
        queries: c.queries,
    }
}

/// The report's `head` object: the check's settings and its figures per path.
pub(crate) fn head_report(
    clearance: Option<f64>,
    machine: &Machine,
    tip_zone: Option<f64>,
    paths: Vec<HeadPath>,
) -> HeadReport {
    let Some(clearance) = clearance else {
        return HeadReport {
            checked: false,
            clearance_mm: None,
            head: None,
            head_source: None,
            standoff_mm: None,
            tip_zone_mm: None,
            paths: None,
            note: "cuts not checked against the head (the head check is off: cut_clearance_mm None, `--cut-clearance off`)".into(),
        };
    };
    HeadReport {
        checked: true,
        clearance_mm: Some(clearance),
        head: Some(machine.head.clone().unwrap_or_else(Head::laser_default)),
        head_source: Some(
            if machine.head.is_some() { "machine file" } else { "default laser head" }.into(),
        ),
        standoff_mm: Some(
            machine
                .process
                .standoff_mm
                .unwrap_or(kerf_kinematics::DEFAULT_STANDOFF_MM),
        ),
        tip_zone_mm: Some(tip_zone),
        paths: Some(paths),
        note: "min_distance_mm: a proven lower bound of the distance from the head above the tip zone (the nozzle's lowest tip_zone_mm, meant to be near the cut) to the part the cut lies on (the surfaces its curve names and those joined to them; every surface of the file for a curve that names none) over the cut's poses and the motion between them; close: stretches where a head point was found within the clearance; tilted: cutting points whose tool axis was tilted (within the tilt tolerance, away from the surface in the way) to clear it".into(),
    }
}

/// A bound on the tool axis' second derivative on each move between the poses of `s`
/// ([`kerf_process::axis_curvature`] from the tilt and C steps): the machine moves its rotary
/// axes linearly between the poses, which takes the tool axis off the great circle the head
/// check's samples follow ([`kerf_process::check_cut_along`]).
fn rotary_curvature(s: &kerf_kinematics::SolvedPath) -> Vec<f64> {
    s.axes
        .windows(2)
        .map(|w| {
            kerf_process::axis_curvature(
                w[0].tilt.to_radians(),
                (w[1].tilt - w[0].tilt).to_radians(),
                (w[1].c - w[0].c).to_radians(),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The pipeline's bound on the tool axis' second derivative, from the solved axes in
    /// degrees, against the machines' own forward kinematics: on every move of a tilted
    /// cone of poses (C turning all round, the tilt changing), the axis of the linear joint
    /// move sampled densely never leaves the great circle by more than the departure the
    /// bound gives, and the bound is not wildly larger (a degree read as a radian would be
    /// 57 times too large, the other way round 57 times too small).
    #[test]
    fn the_rotary_curvature_bounds_each_machines_linear_moves() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/machines/");
        for name in ["ac_head", "fork_head", "table_table"] {
            let machine = Machine::read(format!("{dir}{name}.json")).expect("machine");
            let poses: Vec<Pose> = (0..=24)
                .map(|k| {
                    let u = std::f64::consts::TAU * k as f64 / 24.0;
                    let tilt = (12.0 + 8.0 * (2.0 * u).sin()).to_radians();
                    Pose {
                        position: Point3::new(30.0 * u.cos(), 30.0 * u.sin(), 0.0),
                        axis: Vector3::new(tilt.sin() * u.cos(), tilt.sin() * u.sin(), tilt.cos()),
                    }
                })
                .collect();
            let input = kerf_kinematics::PathInput {
                id: "cone",
                poses: &poses,
                curve: None,
            };
            let solved = kerf_kinematics::solve_path(
                &machine,
                &input,
                &kerf_kinematics::PathOptions::default(),
            )
            .unwrap_or_else(|e| panic!("{name}: {e}"));
            let bounds = rotary_curvature(&solved);
            assert_eq!(bounds.len(), solved.axes.len() - 1);
            let mut worst_ratio: f64 = 0.0;
            for (k, w) in solved.axes.windows(2).enumerate() {
                let (p, q) = (solved.poses[k].axis, solved.poses[k + 1].axis);
                let angle = p.angle(&q);
                let rot = nalgebra::UnitQuaternion::rotation_between(&p, &q)
                    .unwrap_or_else(nalgebra::UnitQuaternion::identity);
                let mut worst: f64 = 0.0;
                for j in 0..=200 {
                    let s = j as f64 / 200.0;
                    let mut a = w[0];
                    a.tilt += (w[1].tilt - w[0].tilt) * s;
                    a.c += (w[1].c - w[0].c) * s;
                    let axis = machine.kinematics.forward(&a).axis;
                    let great = nalgebra::UnitQuaternion::identity().slerp(&rot, s) * p;
                    worst = worst.max(axis.angle(&great));
                }
                let bound = kerf_process::rotary_departure_rad(bounds[k], angle);
                assert!(
                    worst <= bound + 2e-6,
                    "{name}: move {k}: departure {worst} rad above the bound {bound}"
                );
                if worst > 1e-5 {
                    worst_ratio = worst_ratio.max(bound / worst);
                }
            }
            assert!(
                worst_ratio < 20.0,
                "{name}: bound / departure {worst_ratio}"
            );
        }
    }

    /// A refusal whose search for a clearing tilt ran out of work says so, instead of
    /// claiming that no tilt up to 60 degrees clears the head.
    #[test]
    fn a_spent_budget_is_not_reported_as_no_clearing_tilt() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/head_wall.json");
        let file = kerf_format::curves::load(path).expect("fixture");
        let obs = Obstacles::from_all_surfaces(&file, |p| *p).expect("obstacles");
        let head = kerf_kinematics::Head::laser_default();
        let pose = Pose {
            position: Point3::origin(),
            axis: Vector3::z(),
        };
        let st = kerf_process::CloseStretch {
            poses: [0, 0],
            length_mm: 0.0,
            distance_mm: 0.5,
            at_height_mm: 50.0,
            surface: Some("wall".to_string()),
            point: Point3::new(40.0, 0.0, 50.0),
        };
        let hopts = HeadCheckOptions::default();
        let mut spent = 0;
        let s = needed_tilt(&obs, &head, &hopts, &pose, 7, &st, 0.0, &mut spent);
        assert!(
            s.contains("at cutting point 7 no tilt away from surface wall was proven to clear it")
                && s.contains("distance queries ran out"),
            "{s}"
        );
    }
}
