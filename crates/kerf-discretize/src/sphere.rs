//! Intersection of the reference sphere with the curve (paper 004, eq 6).

use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

/// Relative accuracy of the intersection radius. The exact crossing is not needed: the step is
/// certified for whatever parameter is returned, so a loose tolerance saves evaluations.
pub(crate) const RADIUS_TOL: f64 = 1e-4;

/// Where the sphere search ended.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Hit {
    /// Parameter of the point.
    pub t: f64,
    /// The point `C(t)`.
    pub p: Point3<f64>,
}

/// Finds the first parameter in `(lo, hi]` where `|C(t) - centre|` reaches `radius`, given
/// `|C(lo) - centre| < radius`.
///
/// When `hi_outside` is true, `|C(hi) - centre| > radius` is known and the root is bracketed;
/// otherwise the curve is marched from `lo` by steps that, to first order, cannot cross the
/// sphere (`dt = (radius - d) / |C'|`, as in sphere tracing), never longer than `max_dt`. If the
/// sphere is not reached before `hi`, returns `hi` itself.
#[allow(clippy::too_many_arguments)]
pub(crate) fn first_crossing(
    curve: &NurbsCurve,
    centre: &Point3<f64>,
    radius: f64,
    lo: f64,
    hi: f64,
    hi_outside: bool,
    p_hi: Option<Point3<f64>>,
    max_dt: f64,
) -> Hit {
    if hi_outside {
        return solve(curve, centre, radius, lo, hi);
    }
    let mut t = lo;
    for _ in 0..96 {
        let (c, d1) = curve.eval_d1(t);
        let d = (c - centre).norm();
        if d >= radius {
            // Crossed during the last step: the root lies in [previous t, t].
            return if d <= radius * (1.0 + RADIUS_TOL) {
                Hit { t, p: c }
            } else {
                solve(curve, centre, radius, lo, t)
            };
        }
        let gap = radius - d;
        if gap <= radius * RADIUS_TOL && t > lo {
            return Hit { t, p: c };
        }
        let speed = d1.norm();
        let mut dt = if speed > 0.0 { gap / speed } else { max_dt };
        dt = dt.min(max_dt);
        if t + dt >= hi {
            let p = p_hi.unwrap_or_else(|| curve.point(hi));
            if (p - centre).norm() < radius {
                return Hit { t: hi, p };
            }
            return solve(curve, centre, radius, t, hi);
        }
        // Keep `lo` as the last parameter known to be inside the sphere.
        let next = t + dt;
        if next <= t {
            break;
        }
        t = next;
    }
    let (c, _) = curve.eval_d1(t);
    Hit { t, p: c }
}

/// Newton's method on `|C(t) - centre|^2 - radius^2` safeguarded by bisection in `[lo, hi]`,
/// where the function is negative at `lo` and positive at `hi`.
fn solve(curve: &NurbsCurve, centre: &Point3<f64>, radius: f64, mut lo: f64, mut hi: f64) -> Hit {
    let r2 = radius * radius;
    let mut t = 0.5 * (lo + hi);
    let mut best = None;
    for _ in 0..80 {
        let (c, d1) = curve.eval_d1(t);
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
        let (c, _) = curve.eval_d1(hi);
        Hit { t: hi, p: c }
    })
}
