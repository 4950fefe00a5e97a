//! Intersection of a sphere centred at a cutting point with the curve (paper 004, eq 6): the
//! classic equal-chord strategy's walk with a fixed radius.

use nalgebra::Point3;

use crate::bound::Certifier;

/// Relative accuracy of the intersection radius. The exact crossing is not needed: the step is
/// certified for whatever parameter is returned, so a loose tolerance saves evaluations.
pub(crate) const RADIUS_TOL: f64 = 5e-4;

/// Where the sphere search ended.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hit {
    /// Parameter of the point.
    pub t: f64,
    /// The point `C(t)`.
    pub p: Point3<f64>,
}

/// Finds the first parameter after `lo` where `|C(t) - centre|` reaches `radius` (`C(lo)` is
/// the centre), marching from `lo` by steps that, to first order, cannot cross the sphere
/// (`dt = (radius - d) / |C'|`, as in sphere tracing), never longer than `max_dt`, then by
/// safeguarded Newton once the crossing is bracketed. If the sphere is not reached before
/// `hi`, returns `hi` and its point `p_hi`.
pub(crate) fn first_crossing(
    cert: &Certifier<'_>,
    centre: &Point3<f64>,
    radius: f64,
    lo: f64,
    (hi, p_hi): (f64, Point3<f64>),
    max_dt: f64,
) -> Hit {
    let mut t = lo;
    let mut inside = lo;
    let mut known = None;
    for _ in 0..96 {
        let (d, speed) = match known.take() {
            Some(ds) => ds,
            None => {
                let (c, d1) = cert.eval_d1(t);
                let d = (c - centre).norm();
                if d >= radius {
                    // Crossed during the last step: the root lies in [inside, t].
                    return if d <= radius * (1.0 + RADIUS_TOL) {
                        Hit { t, p: c }
                    } else {
                        solve(cert, centre, radius, inside, t, 0.5 * (inside + t))
                    };
                }
                if radius - d <= radius * RADIUS_TOL {
                    return Hit { t, p: c };
                }
                inside = t;
                (d, d1.norm())
            }
        };
        let gap = radius - d;
        let dt = if speed > 0.0 { gap / speed } else { max_dt }.min(max_dt);
        if t + dt >= hi {
            if (p_hi - centre).norm() < radius {
                return Hit { t: hi, p: p_hi };
            }
            return solve(cert, centre, radius, t, hi, 0.5 * (t + hi));
        }
        let next = t + dt;
        if next <= t {
            break;
        }
        t = next;
    }
    let (c, _) = cert.eval_d1(t);
    Hit { t, p: c }
}

/// Newton's method on `|C(t) - centre|^2 - radius^2` safeguarded by bisection in `[lo, hi]`,
/// where the function is negative at `lo` and positive at `hi`.
fn solve(
    cert: &Certifier<'_>,
    centre: &Point3<f64>,
    radius: f64,
    mut lo: f64,
    mut hi: f64,
    guess: f64,
) -> Hit {
    let r2 = radius * radius;
    let mut t = if guess > lo && guess < hi {
        guess
    } else {
        0.5 * (lo + hi)
    };
    let mut best = None;
    for _ in 0..80 {
        let (c, d1) = cert.eval_d1(t);
        let v = c - centre;
        let f = v.norm_squared() - r2;
        if f.abs() <= 2.0 * RADIUS_TOL * r2 {
            return Hit { t, p: c };
        }
        if f < 0.0 {
            lo = t;
            best = Some(Hit { t, p: c });
        } else {
            hi = t;
        }
        let df = 2.0 * v.dot(&d1);
        let newton = if df != 0.0 { t - f / df } else { f64::NAN };
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if next == t || hi - lo <= f64::EPSILON * hi.abs().max(lo.abs()).max(1e-300) {
            break;
        }
        t = next;
    }
    best.unwrap_or_else(|| {
        let (c, _) = cert.eval_d1(hi);
        Hit { t: hi, p: c }
    })
}
