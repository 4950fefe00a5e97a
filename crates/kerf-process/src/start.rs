//! Where a closed cut starts, before the normals: a start pinned by the curve's `start` key,
//! or, on a polygon whose every cutting point is a corner, the middle of its longest edge,
//! made a cutting point of the discretization so that the cut can begin there.

use kerf_discretize::Discretization;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

use crate::LeadOptions;

/// The turn of the polyline at each distinct point of a closed polyline (radians).
fn turns(points: &[Point3<f64>]) -> Vec<f64> {
    let m = points.len() - 1;
    (0..m)
        .map(|i| {
            let a = points[(i + m - 1) % m];
            let b = points[i];
            let c = points[(i + 1) % m];
            let angle = (b - a).angle(&(c - b));
            if angle.is_finite() {
                angle
            } else {
                0.0
            }
        })
        .collect()
}

/// Prepares the start of a closed curve's cut and returns its parameter (a cutting point of
/// `disc` after the call), or `None` to let the plan choose among its candidates (an open
/// curve, or a closed one with stretches away from corners and no pinned start).
///
/// - `pinned` (the `start` key, inside the domain; the end of the domain means its start): the
///   cutting point there, inserted if it is not one already;
/// - otherwise, if every cutting point lies within two points of a corner (a turn above
///   [`LeadOptions::corner_deg`], e.g. a polygon of straight edges with no point between its
///   vertices), the middle of the longest edge, inserted, so that the cut starts on a straight
///   stretch instead of at a corner.
///
/// An inserted point is on the curve; only the two new chords are certified
/// ([`Discretization::with_point`], at `tolerance_mm`, the chord tolerance the discretization
/// was made with), and they must stay within the discretization's certified bound; then the
/// result replaces `disc`. Otherwise nothing is inserted and the nearest cutting point by
/// parameter is used.
pub fn prepare_start(
    curve: &NurbsCurve,
    disc: &mut Discretization,
    pinned: Option<f64>,
    opts: &LeadOptions,
    tolerance_mm: f64,
) -> Option<f64> {
    let (params, points) = (disc.params(), disc.points());
    let n = points.len();
    if n < 4 || n != params.len() {
        return None;
    }
    if (points[0] - points[n - 1]).norm() > opts.closed_tolerance_mm {
        return None;
    }
    let (t0, t1) = curve.domain();
    let want = match pinned {
        Some(t) if t.is_finite() => {
            if t >= t1 {
                t0
            } else {
                t.max(t0)
            }
        }
        Some(_) => return None,
        None => {
            let turn = turns(points);
            let m = n - 1;
            let corner = opts.corner_deg.to_radians();
            let near = |i: usize| {
                (0..=2).any(|d| turn[(i + d) % m] > corner || turn[(i + m - d) % m] > corner)
            };
            if !(0..m).all(near) {
                return None;
            }
            let longest = (0..m)
                .max_by(|&a, &b| {
                    let la = (points[a + 1] - points[a]).norm();
                    let lb = (points[b + 1] - points[b]).norm();
                    la.total_cmp(&lb).then(b.cmp(&a))
                })
                .unwrap_or(0);
            0.5 * (params[longest] + params[longest + 1])
        }
    };
    // Already a cutting point?
    if let Some(i) = params.iter().position(|&p| p == want) {
        return Some(params[if i == n - 1 { 0 } else { i }]);
    }
    let i = params.partition_point(|&p| p < want); // params[i - 1] < want < params[i]
    if i == 0 || i >= n {
        return None;
    }
    let (ta, tb) = (params[i - 1], params[i]);
    let nearest = {
        let j = if want - ta <= tb - want { i - 1 } else { i };
        params[if j == n - 1 { 0 } else { j }]
    };
    // Only the two new chords are certified; within the discretization's certified bound, or
    // the nearer existing cutting point is used.
    match disc.with_point(curve, want, tolerance_mm) {
        Ok(with_start) if with_start.max_chord_error() <= disc.max_chord_error() => {
            *disc = with_start;
            Some(want)
        }
        _ => Some(nearest),
    }
}

/// The index of the cutting point with parameter `t` in `params` (exact, else the nearest).
pub fn index_of_param(params: &[f64], t: f64) -> usize {
    params
        .iter()
        .enumerate()
        .min_by(|a, b| {
            (a.1 - t)
                .abs()
                .total_cmp(&(b.1 - t).abs())
                .then(a.0.cmp(&b.0))
        })
        .map_or(0, |(i, _)| i)
}
