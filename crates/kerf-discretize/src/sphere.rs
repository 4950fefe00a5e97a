//! Intersection of the reference sphere with the curve (paper 004, eq 6).

use nalgebra::{Point3, Vector3, Vector4};

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
    /// The knot span and the homogeneous point (local frame) it was evaluated from, if any:
    /// the certificate reuses it instead of evaluating `C(t)` again.
    pub h: Option<(usize, Vector4<f64>)>,
}

/// What is known at the low end of the search: the parameter, its distance from the centre
/// and (if known) the speed `|C'|` there.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Start {
    pub t: f64,
    pub d: f64,
    pub speed: Option<f64>,
    /// `C'`, `C''`, `C'''` at `t` when the centre is `C(t)` (the first search from a cutting
    /// point): the first step then comes from the arc's Taylor expansion instead of the
    /// first-order `radius / |C'|`.
    pub derivs: Option<[Vector3<f64>; 3]>,
}

/// The high end of the search.
#[derive(Debug, Clone, Copy)]
pub(crate) enum End {
    /// A parameter known to lie outside the sphere, with its distance from the centre.
    Outside { t: f64, d: f64 },
    /// The end of the piece and its point; the sphere may not reach it.
    PieceEnd { t: f64, p: Point3<f64> },
}

/// Finds the first parameter after `start.t` where `|C(t) - centre|` reaches `radius`, given
/// `start.d < radius`.
///
/// With [`End::Outside`] the root is bracketed and found by safeguarded Newton, starting from
/// the linear interpolation of the distance. With [`End::PieceEnd`] the curve is marched from
/// the start by steps that, to first order, cannot cross the sphere (`dt = (radius - d) / |C'|`,
/// as in sphere tracing), never longer than `max_dt`; if the sphere is not reached before the
/// piece end, the piece end itself is returned.
pub(crate) fn first_crossing(
    cert: &Certifier<'_>,
    centre: &Point3<f64>,
    radius: f64,
    start: Start,
    end: End,
    max_dt: f64,
) -> Hit {
    let lo = start.t;
    let (hi, p_hi) = match end {
        End::Outside { t, d } => {
            // Distance is close to linear in t over a short step: start from the interpolation.
            let f = ((radius - start.d) / (d - start.d)).clamp(0.0, 1.0);
            return solve(cert, centre, radius, lo, t, lo + f * (t - lo));
        }
        End::PieceEnd { t, p } => (t, p),
    };
    let mut t = lo;
    let mut inside = lo;
    let mut known = start.speed.map(|s| (start.d, s));
    if let (Some(dd), Some(speed)) = (start.derivs, start.speed) {
        // |C(t0 + x) - C(t0)|^2 = a2 x^2 + a3 x^3 + a4 x^4 + O(x^5): Newton on it from the
        // first-order step. The step is only a guess (the evaluation decides), kept within
        // 1.6 times the first-order one (an arc's length over its chord, up to a half turn),
        // so that it cannot jump far past the first crossing.
        let x1 = radius / speed;
        let a2 = dd[0].norm_squared();
        let a3 = dd[0].dot(&dd[1]);
        let a4 = 0.25 * dd[1].norm_squared() + dd[0].dot(&dd[2]) / 3.0;
        let r2 = radius * radius;
        let mut x = x1;
        for _ in 0..4 {
            let g = x * x * (a2 + x * (a3 + x * a4)) - r2;
            let dg = x * (2.0 * a2 + x * (3.0 * a3 + 4.0 * a4 * x));
            let next = x - g / dg;
            if !(next > 0.0 && next.is_finite()) {
                x = x1;
                break;
            }
            x = next;
        }
        if x.is_nan() || x > 1.6 * x1 {
            x = x1;
        }
        let x = x.min(max_dt);
        if x > 0.0 && lo + x < hi {
            let next = lo + x;
            let (c, d1, h) = cert.eval_d1_h(next);
            let d = (c - centre).norm();
            if (d - radius).abs() <= radius * RADIUS_TOL {
                return Hit {
                    t: next,
                    p: c,
                    h: Some(h),
                };
            }
            if d > radius {
                // Past the sphere: the root lies in [lo, next], near the linear interpolation.
                let f = ((radius - start.d) / (d - start.d)).clamp(0.0, 1.0);
                return solve(cert, centre, radius, lo, next, lo + f * x);
            }
            t = next;
            inside = next;
            known = Some((d, d1.norm()));
        }
    }
    for _ in 0..96 {
        let (d, speed) = match known.take() {
            Some(ds) => ds,
            None => {
                let (c, d1, h) = cert.eval_d1_h(t);
                let d = (c - centre).norm();
                if d >= radius {
                    // Crossed during the last step: the root lies in [inside, t].
                    return if d <= radius * (1.0 + RADIUS_TOL) {
                        Hit {
                            t,
                            p: c,
                            h: Some(h),
                        }
                    } else {
                        solve(cert, centre, radius, inside, t, 0.5 * (inside + t))
                    };
                }
                if radius - d <= radius * RADIUS_TOL {
                    return Hit {
                        t,
                        p: c,
                        h: Some(h),
                    };
                }
                inside = t;
                (d, d1.norm())
            }
        };
        let gap = radius - d;
        let dt = if speed > 0.0 { gap / speed } else { max_dt }.min(max_dt);
        if t + dt >= hi {
            if (p_hi - centre).norm() < radius {
                return Hit {
                    t: hi,
                    p: p_hi,
                    h: None,
                };
            }
            return solve(cert, centre, radius, t, hi, 0.5 * (t + hi));
        }
        let next = t + dt;
        if next <= t {
            break;
        }
        t = next;
    }
    let (c, _, h) = cert.eval_d1_h(t);
    Hit {
        t,
        p: c,
        h: Some(h),
    }
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
        let (c, d1, h) = cert.eval_d1_h(t);
        let v = c - centre;
        let f = v.norm_squared() - r2;
        if f.abs() <= 2.0 * RADIUS_TOL * r2 {
            return Hit {
                t,
                p: c,
                h: Some(h),
            };
        }
        if f < 0.0 {
            lo = t;
            best = Some(Hit {
                t,
                p: c,
                h: Some(h),
            });
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
        let (c, _, h) = cert.eval_d1_h(hi);
        Hit {
            t: hi,
            p: c,
            h: Some(h),
        }
    })
}
