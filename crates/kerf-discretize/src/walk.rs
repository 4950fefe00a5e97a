//! The reference-sphere walk of paper 004 (and the parameter-bisection walk of the classic
//! "equal error" method), with every accepted segment certified by [`crate::bound`].

use kerf_nurbs::curvature_of;
use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

use crate::bound::{Bound, Certifier, Scratch};
use crate::error::{DiscretizeError, Result};
use crate::options::Options;
use crate::sphere::{first_crossing, End, Hit, Start};
use crate::Discretization;

/// Iterations of the radius search per cutting point before giving up.
const MAX_ITERS: usize = 80;
/// Consecutive failures with no good radius after which the search bisects the parameter
/// instead (guaranteed progress on pathological curves).
const PARAM_FALLBACK_AFTER: usize = 10;
/// The radius search stops when the bracket is this narrow (relative).
const BRACKET_TOL: f64 = 2e-3;

#[derive(Debug, Clone, Copy)]
struct Cand {
    r: f64,
    hit: Hit,
    bound: Bound,
}

/// Walks one C0 piece `[a, b]`; `out` already holds the point at `a`.
pub(crate) struct Walker<'a> {
    pub curve: &'a NurbsCurve,
    pub opts: &'a Options,
    pub scratch: Scratch,
    /// Start in parameter-bisection mode (the classic "equal error" method).
    pub param_only: bool,
    /// The curve prepared for certification.
    pub cert: Certifier<'a>,
    /// The band's lower edge `E_min`: `band * (tolerance - margin)`, so that the band stays
    /// reachable when the rounding margin is a visible part of the tolerance.
    pub emin: f64,
    /// `integral sqrt(k) |C'| dt` so far, by the trapezoid rule on the cutting points (the
    /// curvature at each point is evaluated anyway, to predict the step): `N*` for free.
    pub sqrt_curvature: f64,
}

/// Why the last trial of a point failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fail {
    Chord,
    Turn,
}

impl Walker<'_> {
    fn certify(&mut self, t0: f64, p0: &Point3<f64>, hit: &Hit) -> (Bound, Option<Fail>) {
        let tol = self.opts.tolerance_mm;
        let bound = self.cert.chord_error_hinted(
            &mut self.scratch,
            t0,
            hit.t,
            p0,
            &hit.p,
            hit.h,
            tol,
            self.emin,
        );
        if bound.upper > tol {
            return (bound, Some(Fail::Chord));
        }
        if (hit.p - p0).norm() > self.opts.max_segment_length_mm {
            return (bound, Some(Fail::Chord));
        }
        if self.opts.max_turn_rad.is_finite()
            && self.cert.turn_bound(t0, hit.t, self.opts.max_turn_rad) > self.opts.max_turn_rad
        {
            return (bound, Some(Fail::Turn));
        }
        (bound, None)
    }

    /// Discretizes `[a, b]`, appending every cutting point after `a` (the last one is `b`).
    pub(crate) fn piece(
        &mut self,
        a: f64,
        b: f64,
        pb: Point3<f64>,
        out: &mut Discretization,
    ) -> Result<()> {
        let tol = self.opts.tolerance_mm;
        let emin = self.emin;
        let hp = 0.5 * (emin + tol);
        let max_len = self.opts.max_segment_length_mm;
        let min_len = self.opts.min_segment_length_mm;
        let mut t0 = a;
        let mut p0 = *out.points.last().expect("start point pushed");
        // Ratio of the accepted radius to the curvature prediction at the previous point: the
        // walk learns the systematic error of the osculating-circle model (warm start).
        let mut bias = 1.0f64;
        let mut last_dt = (b - a) / 8.0;
        // sqrt(k) |C'| at the previous cutting point.
        let mut prev_f = None;
        while t0 < b {
            let d = self.cert.eval_d3(t0);
            let (d1, d2) = (d[1], d[2]);
            let k = curvature_of(&d1, &d2);
            let f0 = crate::sqrt_curvature_speed(&d);
            if let Some(fp) = prev_f {
                self.sqrt_curvature += crate::trapezoid_step(self.curve, t0 - last_dt, t0, fp, f0);
            }
            prev_f = Some(f0);
            let speed0 = d1.norm();
            let remaining = (pb - p0).norm();
            // Paper 004 eq 4-5: the chord of the osculating circle with sagitta H_p.
            let r_curv = if k > 0.0 {
                let r = 1.0 / k;
                if hp >= r {
                    2.0 * r
                } else {
                    2.0 * (hp * (2.0 * r - hp)).sqrt()
                }
            } else {
                f64::INFINITY
            };
            let mut r = if r_curv.is_finite() {
                r_curv * bias
            } else {
                // Straight here: try the rest of the piece (first-order length if it closes).
                remaining.max(d1.norm() * (b - t0)) * (1.0 + 1e-9)
            };
            r = r.min(max_len).max(min_len);
            if r.is_nan() || r <= 0.0 {
                r = max_len.min(f64::MAX);
            }
            let max_dt = (8.0 * last_dt).min(b - a);
            let mut good: Option<Cand> = None;
            let mut bad: Option<Cand> = None;
            let mut param_mode = self.param_only;
            let mut fails = 0usize;
            let mut last_fail = Fail::Chord;
            let mut stuck = false;
            let mut t_try = t0 + last_dt.min(b - t0);
            for _ in 0..MAX_ITERS {
                let hit = if param_mode {
                    if t_try >= b {
                        Hit {
                            t: b,
                            p: pb,
                            h: None,
                        }
                    } else {
                        let (p, h) = self.cert.point_h(t_try);
                        Hit {
                            t: t_try,
                            p,
                            h: Some(h),
                        }
                    }
                } else {
                    let start = good.map_or(
                        Start {
                            t: t0,
                            d: 0.0,
                            speed: Some(speed0),
                            derivs: Some([d[1], d[2], d[3]]),
                        },
                        |g| Start {
                            t: g.hit.t,
                            d: g.r,
                            speed: None,
                            derivs: None,
                        },
                    );
                    let end = match bad {
                        Some(bd) if bd.r > r => End::Outside {
                            t: bd.hit.t,
                            d: bd.r,
                        },
                        _ => End::PieceEnd { t: b, p: pb },
                    };
                    first_crossing(&self.cert, &p0, r, start, end, max_dt)
                };
                if hit.t <= t0 {
                    stuck = true;
                    break;
                }
                // Certify exactly the point that will be output for the piece end.
                let hit = if hit.t >= b {
                    Hit {
                        t: b,
                        p: pb,
                        h: None,
                    }
                } else {
                    hit
                };
                let (bound, fail) = self.certify(t0, &p0, &hit);
                let ok = fail.is_none();
                if let Some(f) = fail {
                    last_fail = f;
                }
                let cand = Cand {
                    r: (hit.p - p0).norm(),
                    hit,
                    bound,
                };
                if ok {
                    good = Some(cand);
                    fails = 0;
                    if hit.t >= b || bound.lower >= emin || cand.r >= max_len * (1.0 - 1e-12) {
                        break;
                    }
                } else {
                    bad = Some(cand);
                    fails += 1;
                    if good.is_none() && fails >= PARAM_FALLBACK_AFTER {
                        param_mode = true;
                    }
                }
                // Next trial.
                match (good, bad) {
                    (Some(g), None) => {
                        let f = if g.bound.lower > 0.0 {
                            (hp / g.bound.lower).sqrt().clamp(1.005, 4.0)
                        } else {
                            4.0
                        };
                        r = (g.r * f).min(max_len);
                        t_try = t0 + 2.0 * (g.hit.t - t0);
                    }
                    (None, Some(bd)) => {
                        let f = if bd.bound.lower > 0.0 {
                            (hp / bd.bound.lower).sqrt().clamp(0.05, 0.995)
                        } else {
                            0.5
                        };
                        r = (bd.r * f).max(if fails == 1 { min_len } else { 0.0 });
                        if r >= bd.r {
                            r = 0.5 * bd.r;
                        }
                        t_try = t0 + 0.5 * (bd.hit.t - t0);
                    }
                    (Some(g), Some(bd)) => {
                        let gap_t = bd.hit.t - g.hit.t;
                        if gap_t <= 1e-9 * (g.hit.t - t0) {
                            break;
                        }
                        if param_mode {
                            if gap_t <= BRACKET_TOL * (g.hit.t - t0) {
                                break;
                            }
                            t_try = 0.5 * (g.hit.t + bd.hit.t);
                        } else {
                            let gap = bd.r - g.r;
                            if gap <= BRACKET_TOL * g.r || gap <= crate::sphere::RADIUS_TOL * bd.r {
                                break;
                            }
                            // Power law e = c r^q through both ends of the bracket.
                            let (eg, eb) = (g.bound.lower, bd.bound.lower);
                            let model = if eg > 0.0 && eb > eg {
                                let q = (eb / eg).ln() / (bd.r / g.r).ln();
                                g.r * (hp / eg).powf(1.0 / q)
                            } else if eg > 0.0 {
                                g.r * (hp / eg).sqrt()
                            } else {
                                0.5 * (g.r + bd.r)
                            };
                            r = model.clamp(g.r + 0.1 * gap, bd.r - 0.1 * gap);
                        }
                    }
                    (None, None) => unreachable!("a trial was made"),
                }
            }
            let Some(g) = good else {
                return Err(if last_fail == Fail::Turn {
                    DiscretizeError::TurnUnreachable {
                        t: t0,
                        max_turn_deg: self.opts.max_turn_rad.to_degrees(),
                    }
                } else if stuck || next_float_gap(t0) * 4.0 >= b - t0 {
                    DiscretizeError::ParameterResolution { t: t0 }
                } else {
                    DiscretizeError::ToleranceBelowPrecision {
                        t: t0,
                        tolerance: tol,
                    }
                });
            };
            if r_curv.is_finite() && g.hit.t < b && g.bound.lower > 0.0 {
                // The radius that would have hit H_p exactly, relative to the prediction.
                bias = (g.r * (hp / g.bound.lower).sqrt() / r_curv).clamp(0.25, 4.0);
            }
            last_dt = g.hit.t - t0;
            out.max_chord_error = out.max_chord_error.max(g.bound.upper);
            out.estimated_chord_error = out.estimated_chord_error.max(g.bound.lower);
            let (t1, p1) = if g.hit.t >= b {
                (b, pb)
            } else {
                (g.hit.t, g.hit.p)
            };
            if t1 >= b {
                // The piece's last segment: the value at its start (the value at `b` would
                // cost an evaluation, and at a C0 break it belongs to the next piece).
                self.sqrt_curvature += f0.0 * (t1 - t0);
            }
            out.params.push(t1);
            out.points.push(p1);
            if out.points.len() > self.opts.max_points {
                return Err(DiscretizeError::TooManyPoints {
                    limit: self.opts.max_points,
                    estimate: out.points.len() as f64,
                });
            }
            t0 = t1;
            p0 = p1;
        }
        Ok(())
    }
}

/// The gap from `t` to the next larger double.
fn next_float_gap(t: f64) -> f64 {
    let next = f64::from_bits(if t >= 0.0 {
        t.to_bits() + 1
    } else {
        t.to_bits() - 1
    });
    (next - t).abs()
}
