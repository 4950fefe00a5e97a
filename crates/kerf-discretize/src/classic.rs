//! The classic methods paper 004 compares against, each made to meet the same certified
//! guarantee: equal parameter steps and equal chord lengths with the smallest count that
//! certifies. (The third, "equal error", is the parameter-bisection mode of the walker.)

use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

use crate::bound::{chord_error_with, Scratch};
use crate::error::{DiscretizeError, Result};
use crate::options::Options;
use crate::sphere::{first_crossing, End, Start};
use crate::Discretization;

/// Points of one trial: parameters, points, worst upper bound and worst lower bound.
type Trial = (Vec<f64>, Vec<Point3<f64>>, f64, f64);

/// Certifies consecutive segments; `None` at the first failure.
fn certify_all(
    curve: &NurbsCurve,
    opts: &Options,
    scratch: &mut Scratch,
    params: Vec<f64>,
    points: Vec<Point3<f64>>,
) -> Option<Trial> {
    let tol = opts.tolerance;
    let (mut up, mut lo) = (0.0f64, 0.0f64);
    for i in 1..params.len() {
        if (points[i] - points[i - 1]).norm() > opts.max_segment_length {
            return None;
        }
        let b = chord_error_with(
            scratch,
            curve,
            params[i - 1],
            params[i],
            &points[i - 1],
            &points[i],
            tol,
            0.0,
        );
        if b.upper > tol {
            return None;
        }
        up = up.max(b.upper);
        lo = lo.max(b.lower);
    }
    Some((params, points, up, lo))
}

/// Searches the smallest `n` for which `make(n)` certifies: doubling, then bisection.
fn smallest(
    start: usize,
    limit: usize,
    mut make: impl FnMut(usize) -> Option<Trial>,
    t0: f64,
    tol: f64,
) -> Result<Trial> {
    let mut n = start.max(1);
    let mut fail = 0usize;
    let pass = loop {
        if let Some(tr) = make(n) {
            break (n, tr);
        }
        fail = n;
        if n >= limit {
            return Err(DiscretizeError::ToleranceBelowPrecision {
                t: t0,
                tolerance: tol,
            });
        }
        n = (n * 2).min(limit);
    };
    let (mut hi, mut best) = pass;
    // If the start passed at once, look below it too.
    let mut lo = if fail == 0 { 0 } else { fail };
    if fail == 0 {
        let mut m = hi;
        while m > 1 {
            m /= 2;
            match make(m) {
                Some(tr) => {
                    hi = m;
                    best = tr;
                }
                None => {
                    lo = m;
                    break;
                }
            }
        }
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        match make(mid) {
            Some(tr) => {
                hi = mid;
                best = tr;
            }
            None => lo = mid,
        }
    }
    Ok(best)
}

fn append(out: &mut Discretization, trial: Trial) {
    let (params, points, up, lo) = trial;
    out.params.extend_from_slice(&params[1..]);
    out.points.extend_from_slice(&points[1..]);
    out.max_chord_error = out.max_chord_error.max(up);
    out.estimated_chord_error = out.estimated_chord_error.max(lo);
}

/// One C0 piece `[a, b]` with its end points and the count to start the search from.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    pub a: f64,
    pub b: f64,
    pub pa: Point3<f64>,
    pub pb: Point3<f64>,
    pub start: usize,
}

/// Equal parameter steps on `[a, b]`: the smallest count that certifies.
pub(crate) fn equal_parameter(
    curve: &NurbsCurve,
    opts: &Options,
    piece: Piece,
    out: &mut Discretization,
) -> Result<()> {
    let Piece {
        a,
        b,
        pa,
        pb,
        start,
    } = piece;
    let mut scratch = Scratch::default();
    let trial = smallest(
        start,
        opts.max_points,
        |n| {
            let params: Vec<f64> = (0..=n)
                .map(|i| {
                    if i == n {
                        b
                    } else {
                        a + (b - a) * i as f64 / n as f64
                    }
                })
                .collect();
            let points = params
                .iter()
                .enumerate()
                .map(|(i, &t)| match i {
                    0 => pa,
                    _ if i == n => pb,
                    _ => curve.point(t),
                })
                .collect();
            certify_all(curve, opts, &mut scratch, params, points)
        },
        a,
        opts.tolerance,
    )?;
    append(out, trial);
    Ok(())
}

/// Equal chord lengths on `[a, b]`: a walk with a fixed reference-sphere radius `L / n`, with the
/// smallest `n` whose segments all certify (the last chord may be shorter).
pub(crate) fn equal_chord(
    curve: &NurbsCurve,
    opts: &Options,
    piece: Piece,
    out: &mut Discretization,
) -> Result<()> {
    let Piece {
        a,
        b,
        pa,
        pb,
        start,
    } = piece;
    let length = curve.arc_length_between(a, b);
    let mut scratch = Scratch::default();
    let trial = smallest(
        start,
        opts.max_points,
        |n| {
            let r = length / n as f64;
            let mut params = vec![a];
            let mut points = vec![pa];
            let mut dt = (b - a) / n as f64;
            while *params.last().expect("non-empty") < b {
                if params.len() > 4 * n + 8 {
                    return None;
                }
                let t0 = *params.last().expect("non-empty");
                let p0 = *points.last().expect("non-empty");
                let start = Start {
                    t: t0,
                    d: 0.0,
                    speed: None,
                };
                let end = End::PieceEnd { t: b, p: pb };
                let hit = first_crossing(curve, &p0, r, start, end, 8.0 * dt);
                if hit.t <= t0 {
                    return None;
                }
                dt = hit.t - t0;
                params.push(hit.t);
                points.push(if hit.t >= b { pb } else { hit.p });
            }
            certify_all(curve, opts, &mut scratch, params, points)
        },
        a,
        opts.tolerance,
    )?;
    append(out, trial);
    Ok(())
}
