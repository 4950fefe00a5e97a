//! Set-ups: groups of contours placed separately when the part does not fit in one.

use nalgebra::Vector3;

use super::directions::up_directions;
use super::work::Work;
use super::{auto_place, place_paths, search, validate, AutoPlaceOptions, Placement};
use crate::error::{KinematicsError, Result};
use crate::machine::Machine;
use crate::pose::Pose;
/// One set-up: contours cut with the part clamped in one placement.
#[derive(Debug, Clone, PartialEq)]
pub struct Setup {
    /// The indices of the paths cut in this set-up, in input order.
    pub paths: Vec<usize>,
    /// The placement of the part for these paths.
    pub placement: Placement,
    /// The smallest distance of any of its poses to a linear limit, mm.
    pub clearance_mm: f64,
}

/// The set-ups [`auto_setups`] chose: one when the whole part fits in one placement.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupPlan {
    /// The set-ups, in cutting order.
    pub setups: Vec<Setup>,
    /// For each path, true if its tool axes were turned to the other side of the sheet.
    pub flipped: Vec<bool>,
    /// How many orientations were tried in all.
    pub rotations_tried: usize,
    /// How many paths were solved in all (with the linear axes free, and against the real
    /// limits): each path once per orientation and side, however many groups and levels of
    /// splitting try it (see `docs/kinematics.md`, "Set-ups").
    pub paths_solved: usize,
}

impl SetupPlan {
    /// The set-up that cuts path `path`.
    pub fn setup_of(&self, path: usize) -> usize {
        self.setups
            .iter()
            .position(|s| s.paths.contains(&path))
            .unwrap_or(0)
    }

    /// The placement of path `path`.
    pub fn placement_of(&self, path: usize) -> Placement {
        self.setups
            .get(self.setup_of(path))
            .map_or(Placement::IDENTITY, |s| s.placement)
    }

    /// The placed poses of every path (each with its set-up's placement, flips applied).
    pub fn apply(&self, paths: &[Vec<Pose>]) -> Vec<Vec<Pose>> {
        paths
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let placed = place_paths(
                    &self.placement_of(i),
                    &[self.flipped.get(i).copied().unwrap_or(false)],
                    std::slice::from_ref(p),
                );
                placed.into_iter().next().unwrap_or_default()
            })
            .collect()
    }
}

/// Places the part in as few set-ups as it takes: the whole part in one placement if any fits
/// ([`auto_place`]); else the contours are grouped by the orientation that serves them (greedily:
/// the up direction that brings the most remaining contours within the tilt range takes them),
/// and a group that does not fit the travel in one placement is halved at the median of its
/// contours' centres along its longest extent, recursively, down to single contours.
///
/// # Errors
/// [`KinematicsError::NoPlacement`] for a single contour that fits in no placement (naming the
/// contour, the axis and the shortfall), and the errors of [`auto_place`].
pub fn auto_setups(
    machine: &Machine,
    paths: &[(&str, &[Pose])],
    options: &AutoPlaceOptions,
) -> Result<SetupPlan> {
    validate(options)?;
    let mut plan = SetupPlan {
        setups: Vec::new(),
        flipped: vec![false; paths.len()],
        rotations_tried: 0,
        paths_solved: 0,
    };
    let work = Work::new(machine, paths, options);
    let all: Vec<usize> = (0..paths.len()).collect();
    let placed = place_group(&work, &all, &mut plan)?;
    if !placed && paths.len() <= 1 {
        // The whole part's error.
        auto_place(machine, paths, options)?;
    } else if !placed {
        for group in orientation_groups(&work) {
            bisect(&work, &group, &mut plan)?;
        }
    }
    plan.paths_solved = work.solved.load(std::sync::atomic::Ordering::Relaxed);
    Ok(plan)
}

/// Places `group` as one set-up if it fits (true), else false; other errors pass through.
/// Only whether it fits matters here, so candidates are refused on the cheap bound of the
/// linear travel before they are solved.
pub(super) fn place_group(work: &Work<'_>, group: &[usize], plan: &mut SetupPlan) -> Result<bool> {
    match search(work, group, true) {
        Ok(found) => {
            plan.rotations_tried += found.rotations_tried;
            for (k, &i) in group.iter().enumerate() {
                plan.flipped[i] = found.flipped[k];
            }
            plan.setups.push(Setup {
                paths: group.to_vec(),
                placement: found.placement,
                clearance_mm: found.clearance_mm,
            });
            Ok(true)
        }
        Err(KinematicsError::NoPlacement {
            rotations_tried, ..
        }) => {
            plan.rotations_tried += rotations_tried;
            Ok(false)
        }
        Err(e) => Err(e),
    }
}

/// Places `group`, halving it spatially until every piece fits (see [`auto_setups`]).
pub(super) fn bisect(work: &Work<'_>, group: &[usize], plan: &mut SetupPlan) -> Result<()> {
    if place_group(work, group, plan)? {
        return Ok(());
    }
    let paths = work.paths;
    if group.len() == 1 {
        // The reason, for this contour alone (exact: solved without the cheap bound).
        auto_place(work.machine, &[paths[group[0]]], work.options)?;
        return Ok(());
    }
    let centre = |i: usize| {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for q in paths[i].1 {
            lo = lo.inf(&q.position.coords);
            hi = hi.sup(&q.position.coords);
        }
        0.5 * (lo + hi)
    };
    let centres: Vec<Vector3<f64>> = group.iter().map(|&i| centre(i)).collect();
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for c in &centres {
        lo = lo.inf(c);
        hi = hi.sup(c);
    }
    let axis = (hi - lo).imax();
    let mut order: Vec<usize> = (0..group.len()).collect();
    order.sort_by(|&a, &b| {
        centres[a][axis]
            .total_cmp(&centres[b][axis])
            .then(a.cmp(&b))
    });
    let half = group.len() / 2;
    let mut first: Vec<usize> = order[..half].iter().map(|&k| group[k]).collect();
    let mut second: Vec<usize> = order[half..].iter().map(|&k| group[k]).collect();
    first.sort_unstable();
    second.sort_unstable();
    bisect(work, &first, plan)?;
    bisect(work, &second, plan)
}

/// Groups of paths that one orientation serves: greedily, the lattice direction that brings the
/// most of the remaining paths within the tilt range (ties: the one nearest the modelled up
/// direction) takes them. Paths no direction serves come last, one group each (their
/// placement then fails with the reason).
pub(super) fn orientation_groups(work: &Work<'_>) -> Vec<Vec<usize>> {
    let lattice = up_directions();
    let all: Vec<usize> = (0..work.paths.len()).collect();
    let fits = work.reach(&all);
    let mut left: Vec<usize> = all.clone();
    let mut out = Vec::new();
    while !left.is_empty() {
        let mut best: Option<(usize, usize, f64)> = None;
        for (d, dir) in lattice.iter().enumerate() {
            let n = left.iter().filter(|&&i| fits[i][d]).count();
            let angle = dir.angle(&Vector3::z());
            if n > 0 && best.is_none_or(|(bn, _, ba)| n > bn || (n == bn && angle < ba - 1e-12)) {
                best = Some((n, d, angle));
            }
        }
        match best {
            Some((_, d, _)) => {
                let (take, rest): (Vec<usize>, Vec<usize>) =
                    left.iter().partition(|&&i| fits[i][d]);
                out.push(take);
                left = rest;
            }
            None => {
                out.extend(left.iter().map(|&i| vec![i]));
                left.clear();
            }
        }
    }
    out
}
