//! The classic methods paper 004 compares against, each made to meet the same certified
//! guarantee: equal parameter steps and equal chord lengths with the smallest count that
//! certifies. (The third, "equal error", is the parameter-bisection mode of the walker.)

use nalgebra::Point3;

use crate::bound::{Certifier, Scratch};
use crate::error::{DiscretizeError, Result};
use crate::options::Options;
use crate::sphere::first_crossing;
use crate::Discretization;

/// Points of one trial: parameters, points, worst upper bound and worst lower bound.
type Trial = (Vec<f64>, Vec<Point3<f64>>, f64, f64);

/// The points of one trial, certified as they are made: a trial stops at its first failing
/// segment, so a hopeless count costs one segment, not a full allocation (a circle that cannot
/// be cut used to allocate the whole of `max_points` before failing).
struct Builder<'c, 'a> {
    cert: &'c Certifier<'a>,
    opts: &'c Options,
    scratch: &'c mut Scratch,
    trial: Trial,
}

impl<'c, 'a> Builder<'c, 'a> {
    fn new(
        cert: &'c Certifier<'a>,
        opts: &'c Options,
        scratch: &'c mut Scratch,
        t: f64,
        p: Point3<f64>,
    ) -> Self {
        Self {
            cert,
            opts,
            scratch,
            trial: (vec![t], vec![p], 0.0, 0.0),
        }
    }

    /// Appends `(t, p)` if the segment from the last point certifies; `None` otherwise.
    fn push(&mut self, t: f64, p: Point3<f64>) -> Option<()> {
        let (params, points, up, lo) = &mut self.trial;
        let (t0, p0) = (*params.last()?, *points.last()?);
        if (p - p0).norm() > self.opts.max_segment_length_mm {
            return None;
        }
        let tol = self.opts.tolerance_mm;
        let b = self
            .cert
            .chord_error(self.scratch, t0, t, &p0, &p, tol, 0.0);
        if b.upper > tol {
            return None;
        }
        *up = up.max(b.upper);
        *lo = lo.max(b.lower);
        params.push(t);
        points.push(p);
        Some(())
    }
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
            // Even the largest count allowed fails: the classic method needs more points than
            // max_points here (a curve it can cut at all is cut with fewer).
            let _ = (t0, tol);
            return Err(DiscretizeError::TooManyPoints {
                limit,
                estimate: limit as f64,
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
    cert: &Certifier<'_>,
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
    let curve = cert.curve();
    let mut scratch = Scratch::default();
    let trial = smallest(
        start,
        opts.max_points,
        |n| {
            let mut tr = Builder::new(cert, opts, &mut scratch, a, pa);
            for i in 1..=n {
                if i == n {
                    tr.push(b, pb)?;
                } else {
                    let t = a + (b - a) * i as f64 / n as f64;
                    tr.push(t, curve.point(t))?;
                }
            }
            Some(tr.trial)
        },
        a,
        opts.tolerance_mm,
    )?;
    append(out, trial);
    Ok(())
}

/// Equal chord lengths on `[a, b]`: a walk with a fixed reference-sphere radius `L / n`, with the
/// smallest `n` whose segments all certify (the last chord may be shorter).
pub(crate) fn equal_chord(
    cert: &Certifier<'_>,
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
    let curve = cert.curve();
    let length = curve.arc_length_between(a, b);
    let mut scratch = Scratch::default();
    let trial = smallest(
        start,
        opts.max_points,
        |n| {
            let r = length / n as f64;
            let mut tr = Builder::new(cert, opts, &mut scratch, a, pa);
            let mut dt = (b - a) / n as f64;
            let (mut t0, mut p0) = (a, pa);
            let mut count = 0usize;
            while t0 < b {
                count += 1;
                if count > 4 * n + 8 {
                    return None;
                }
                let hit = first_crossing(cert, &p0, r, t0, (b, pb), 8.0 * dt);
                if hit.t <= t0 {
                    return None;
                }
                dt = hit.t - t0;
                let p = if hit.t >= b { pb } else { hit.p };
                tr.push(hit.t.min(b), p)?;
                (t0, p0) = (hit.t, p);
            }
            Some(tr.trial)
        },
        a,
        opts.tolerance_mm,
    )?;
    append(out, trial);
    Ok(())
}
