//! A proof that no traverse can leave an exit or reach a pierce: every route retracts along
//! the exit's tool axis and approaches along the pierce's, sliding the nozzle along that
//! line, and starts or ends its travel on it; where no height on the line admits both, no
//! route shape, searched or not, can help.

use nalgebra::{Point3, Vector3};

use super::check::Blocked;
use super::{Obstacles, TraverseOptions};
use crate::Pose;

/// Most samples the proof takes along one line (beyond them it gives up: no proof).
const LINE_SAMPLES: usize = 1 << 16;

/// A proof that the tool axis line at `p` (the exit or the pierce, with its tool axis) admits
/// no traverse: for every height `h` from the retract (`opts.retract_mm`) up, either the axial
/// move to `h` (which sweeps the line from 3/4 of the clearance to `h` plus the nozzle) passes
/// closer than half the clearance to the part, or the head at `h` (the tip and the nozzle
/// there, the travel's first or last pose) comes closer than the clearance. Both are shown by
/// measured samples: one sample `s_b` along the line closer than half the clearance blocks
/// every `h >= s_b - nozzle`; a sample `s` at distance `d` below the clearance makes every
/// line point within `c - d` of it closer than the clearance (1-Lipschitz), which fails
/// every head whose nozzle reaches that stretch. `None` where these do not cover every
/// height (then a route may exist).
///
/// Returns the blocking sample (the nearest witness below half the clearance) and the
/// reason in words. `what` names the line ("the retract from the exit", "the approach to the
/// pierce").
pub(super) fn line_blocked(
    obs: &Obstacles,
    p: &Pose,
    opts: &TraverseOptions,
    what: &str,
) -> Option<(Blocked, String)> {
    let c = opts.clearance_mm;
    let noz = opts.nozzle_mm;
    let q = p.position;
    let n = p.axis.try_normalize(1e-12)?;
    let lo = 0.75 * c;
    let r = opts.retract_mm;
    // Beyond the surfaces' box (grown by the clearance) every point keeps the clearance: the
    // line is sampled up to there.
    let (blo, bhi) = obs.bounding_box()?;
    let far = leave_box(
        &q,
        &n,
        &(blo - Vector3::repeat(c)),
        &(bhi + Vector3::repeat(c)),
    )?;
    let step = c / 16.0;
    let count = ((far.max(lo) - lo) / step).ceil() as usize + 1;
    if count > LINE_SAMPLES {
        return None;
    }
    let at = |s: f64| q + n * s;
    // The first sample closer than half the clearance (blocks the axial moves that reach it),
    // and the stretches closer than the clearance.
    let mut block: Option<(f64, f64)> = None;
    let mut stretches: Vec<(f64, f64, f64, f64)> = Vec::new(); // (from, to, s, d)
    for i in 0..count {
        let s = lo + step * i as f64;
        let d = obs.distance_below(&at(s), c);
        if d < c {
            stretches.push((s - (c - d), s + (c - d), s, d));
        }
        if d < 0.5 * c {
            block = Some((s, d));
            break;
        }
    }
    let (sb, db) = block?;
    // Every height from r to sb - nozzle must have a stretch its nozzle reaches: the head at
    // h covers [h, h + nozzle], which meets the open stretch (a, b) for h in (a - nozzle, b).
    let end = sb - noz;
    let mut covered = r;
    let mut nearest: Option<(f64, f64)> = None;
    for &(a, b, s, d) in &stretches {
        if covered >= end {
            break;
        }
        if a - noz < covered && b > covered {
            covered = b;
            if nearest.is_none_or(|(_, dn)| d < dn) {
                nearest = Some((s, d));
            }
        }
    }
    if covered < end {
        return None;
    }
    let why = match nearest {
        Some((s, d)) => format!(
            "proven, no route can exist: {what} along the tool axis is blocked at every retract height from {r:.1} mm: the axial move up to {end:.1} mm or higher sweeps the point {sb:.2} mm along the axis, {db:.3} mm from the part (half the clearance is {:.2} mm), and the head at any lower height has its nozzle within the clearance (the nearest such sample {s:.2} mm along the axis, {d:.3} mm from the part)",
            0.5 * c
        ),
        None => format!(
            "proven, no route can exist: {what} along the tool axis is blocked at every retract height from {r:.1} mm: the axial move sweeps the point {sb:.2} mm along the axis, {db:.3} mm from the part (half the clearance is {:.2} mm)",
            0.5 * c
        ),
    };
    Some((Blocked::at(at(sb), db), why))
}

/// How far along the ray `q + s n` (s >= 0) it leaves the box `lo hi` for good (0 if it never
/// enters it), or `None` for a non-finite ray.
fn leave_box(q: &Point3<f64>, n: &Vector3<f64>, lo: &Point3<f64>, hi: &Point3<f64>) -> Option<f64> {
    let mut t_enter = 0.0_f64;
    let mut t_leave = f64::INFINITY;
    for k in 0..3 {
        if n[k].abs() < 1e-15 {
            if q[k] < lo[k] || q[k] > hi[k] {
                return Some(0.0);
            }
            continue;
        }
        let (a, b) = ((lo[k] - q[k]) / n[k], (hi[k] - q[k]) / n[k]);
        t_enter = t_enter.max(a.min(b));
        t_leave = t_leave.min(a.max(b));
    }
    if !t_leave.is_finite() {
        return None;
    }
    Some(if t_leave < t_enter {
        0.0
    } else {
        t_leave.max(0.0)
    })
}
