//! The walk of the default strategy (paper 004's reference sphere, its radius and crossing
//! predicted from the arc's Taylor expansion) and the parameter-bisection walk of the classic
//! "equal error" method, with every accepted segment certified by [`crate::bound`].

use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;

use crate::bound::{by_degree, Bound, Certifier, Eval, Question, Scratch};
use crate::error::{DiscretizeError, Result};
use crate::options::Options;
use crate::{Discretization, Scaled};

/// Trials per cutting point before giving up.
const MAX_ITERS: usize = 80;
/// Consecutive failures with no good step after which the search bisects the parameter
/// instead (guaranteed progress on pathological curves).
const PARAM_FALLBACK_AFTER: usize = 10;
/// The search between a good and a bad step stops when they are this close (relative).
const BRACKET_TOL: f64 = 2e-3;
/// A good step whose chord is within this fraction of `max_segment_length_mm` is accepted:
/// a longer one is refused, so the step cannot do better.
const LENGTH_TOL: f64 = 2e-3;

/// Why a trial failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fail {
    /// The chord error cannot be certified.
    Chord,
    /// The chord is longer than `max_segment_length_mm`.
    Length,
    /// The tangent turns more than `max_turn_deg`.
    Turn,
}

/// One trial: the step `h` in the parameter, the chord's length, the end's evaluation (for
/// the next step if accepted), the certificate and why it failed, if it did.
#[derive(Debug, Clone, Copy)]
struct Cand {
    t: f64,
    h: f64,
    /// What the search steers on: the certified upper bound (the lower bound where the
    /// upper is not finite).
    err: f64,
    r: f64,
    end: Option<Eval>,
    p: Point3<f64>,
    bound: Bound,
    fail: Option<Fail>,
}

/// The arc's Taylor expansion at a cutting point, `C(t0 + h) - C(t0) = v x + a x^2 / 2 +
/// j x^3 / 6 + O(x^4)` in the scaled step `x = s h` ([`Scaled`]: the model does not depend on
/// the knots' scale), kept as `s` and the six dot products of `v`, `a`, `j` (every quantity of
/// the model is a polynomial in the step over them). Its chord error for a step is the
/// interpolation certificate's closed form on the model (see [`Taylor::error`]); it is accurate
/// to a relative `O(h^2)`, where the osculating circle's (paper 004's radius) is only `O(h)`.
#[derive(Debug, Clone, Copy)]
struct Taylor {
    s: f64,
    vv: f64,
    va: f64,
    vj: f64,
    aa: f64,
    aj: f64,
    jj: f64,
}

impl Taylor {
    fn new(d: &Scaled) -> Self {
        let (v, a, j) = (&d.v, &d.a, &d.j);
        Self {
            s: d.s,
            vv: v.dot(v),
            va: v.dot(a),
            vj: v.dot(j),
            aa: a.dot(a),
            aj: a.dot(j),
            jj: j.dot(j),
        }
    }

    /// The model's chord error for the step `h`: the interpolation certificate's closed form
    /// on the model (a cubic, whose third derivative is known exactly),
    /// `max_x (1/4 - x^2) (4 n + cl x)` with `n` the middle point's distance from the chord and
    /// `cl` from the cubic term across the chord, so that the model predicts the certified
    /// bound the step will get, not only its middle point's distance (the error of a step
    /// dominated by its cubic term peaks off the middle). With `c = v + a x / 2 + j x^2 / 6`
    /// the chord over `x` and `m = a / 8 + j x / 16` the middle point's offset from the chord's
    /// middle over `x^2`, the parts across the chord are `|m|^2 - (m.c)^2 / |c|^2` and so on.
    /// Where `cl <= n` the maximum is `n + cl^2 / (256 n)` to a relative `3e-5`.
    #[inline(always)]
    fn error(&self, h: f64) -> f64 {
        const THIRD: f64 = 1.0 / 3.0;
        const SIXTH: f64 = 1.0 / 6.0;
        let Self {
            vv,
            va,
            vj,
            aa,
            aj,
            jj,
            ..
        } = *self;
        let x = h * self.s;
        let cc = vv + x * (va + x * (0.25 * aa + THIRD * vj + x * (SIXTH * aj + x * jj / 36.0)));
        let mc = 0.125 * va + x * (0.0625 * (aa + vj) + x * (aj * (5.0 / 96.0) + x * jj / 96.0));
        let jc = vj + x * (0.5 * aj + SIXTH * x * jj);
        let mm = aa / 64.0 + x * (aj / 64.0 + x * jj / 256.0);
        let mj = 0.125 * aj + 0.0625 * x * jj;
        let inv = 1.0 / cc;
        let x2 = x * x;
        let x3 = SIXTH * x2 * x;
        // |d|, |j_perp| x^3 / 6 and |d . j_perp| x^3 / 6, d the offset across the chord.
        let n = (mm - mc * mc * inv).max(0.0).sqrt() * x2;
        let cj2 = (jj - jc * jc * inv).max(0.0) * x3 * x3;
        let k = (mj - mc * jc * inv).abs() * x2 * x3;
        let inv_n = 1.0 / n;
        let cl = (k + 0.0625 * cj2) * inv_n;
        let cl = if cl * cl <= cj2 { cl } else { cj2.sqrt() };
        if cl <= n {
            return n + cl * cl * inv_n * (1.0 / 256.0);
        }
        let root = (64.0 * n * n + 3.0 * cl * cl).sqrt() + 8.0 * n;
        let x = if root > 0.0 { cl / (2.0 * root) } else { 0.0 };
        (0.25 - x * x) * (4.0 * n + cl * x)
    }

    /// The model's chord length for the step `h`.
    #[inline(always)]
    fn length(&self, h: f64) -> f64 {
        let x = h * self.s;
        let cc = self.vv
            + x * (self.va
                + x * (0.25 * self.aa + self.vj / 3.0 + x * (self.aj / 6.0 + x * self.jj / 36.0)));
        cc.max(0.0).sqrt() * x
    }

    /// The step whose model error is `target`, from `guess` (the last step, which had about
    /// the target error on a curve whose geometry changes slowly) by one fixed-point step
    /// `h <- h sqrt(target / e(h))` (the error grows like `h^2`, so the step leaves only the
    /// relative variation of `e / h^2` over the correction); without a guess, from the
    /// circle's estimate (the cubic term's where that dominates, at an inflection) by two.
    /// Infinite where the model has no error (straight).
    #[inline(always)]
    fn step_for(&self, target: f64, guess: f64) -> f64 {
        let (mut h, iterations) = if guess > 0.0 && guess.is_finite() {
            (guess, 1)
        } else {
            // |v x a| / |v| and |v x j| / |v|: the curvature's and the cubic term's scales.
            let ka = ((self.aa - self.va * self.va / self.vv).max(0.0)).sqrt();
            let mut x = (8.0 * target / ka).sqrt();
            // The cubic term alone would reach the target at x = cbrt(16 target / kj): only
            // where that is shorter (kj x^3 / 16 > target) does it matter.
            let kj = ((self.jj - self.vj * self.vj / self.vv).max(0.0)).sqrt();
            let cubic = kj * x * x * x;
            if cubic.is_nan() || cubic > 16.0 * target {
                let xj = (16.0 * target / kj).cbrt();
                if xj < x || !x.is_finite() {
                    x = xj;
                }
            }
            let h = x / self.s;
            if !(h.is_finite() && h > 0.0) {
                return f64::INFINITY;
            }
            (h, 2)
        };
        for _ in 0..iterations {
            let e = self.error(h);
            if !(e.is_finite() && e > 0.0) {
                break;
            }
            h *= (target / e).sqrt();
        }
        h
    }

    /// The step whose model chord is `length` (two fixed-point steps from `h`; the chord is
    /// nearly proportional to the step).
    #[inline(always)]
    fn step_for_length(&self, mut h: f64, length: f64) -> f64 {
        for _ in 0..2 {
            let l = self.length(h);
            if !(l > 0.0 && l.is_finite()) {
                break;
            }
            h *= length / l;
        }
        h
    }
}

/// Walks one C0 piece `[a, b]`; `out` already holds the point at `a`.
pub(crate) struct Walker<'a> {
    pub curve: &'a NurbsCurve,
    pub opts: &'a Options,
    pub scratch: Scratch,
    /// Bisect the parameter from the last step (the classic "equal error" method) instead of
    /// predicting the step from the Taylor model.
    pub param_only: bool,
    /// The curve prepared for certification.
    pub cert: Certifier<'a>,
    /// The band's lower edge `E_min`: `band * (tolerance - margin)`, so that the band stays
    /// reachable when the rounding margin is a visible part of the tolerance.
    pub emin: f64,
    /// `integral sqrt(k) |C'| dt` so far, by the trapezoid rule on the cutting points (the
    /// derivatives at each point are evaluated anyway, to predict the step): `N*` for free.
    pub sqrt_curvature: f64,
}

impl Walker<'_> {
    /// Discretizes `[a, b]`, appending every cutting point after `a` (the last one is `b`).
    ///
    /// On an x86-64 processor with AVX2 and FMA (x86-64-v3: every x86-64 processor since
    /// 2013-2015), the walk runs as code compiled for those instructions (the four lanes of a
    /// homogeneous point in one 256-bit register), found at run time: the same IEEE operations
    /// in the same order (Rust never fuses a multiply and an add on its own), so the same
    /// bits, about 25 % faster (`docs/performance.md`). Elsewhere it runs as compiled.
    pub(crate) fn piece(
        &mut self,
        a: f64,
        b: f64,
        pb: Point3<f64>,
        out: &mut Discretization,
    ) -> Result<()> {
        #[cfg(target_arch = "x86_64")]
        if x86_64_v3() && !generic_only() {
            // SAFETY: `piece_v3` only needs the target features that `x86_64_v3` has just
            // found on this processor.
            return unsafe { self.piece_v3(a, b, pb, out) };
        }
        self.piece_any(a, b, pb, out)
    }

    /// [`Walker::piece`] compiled for x86-64-v3's vector and bit instructions.
    ///
    /// # Safety
    /// The processor must have the features enabled here ([`x86_64_v3`]).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,bmi1,bmi2,lzcnt,movbe,popcnt,f16c")]
    unsafe fn piece_v3(
        &mut self,
        a: f64,
        b: f64,
        pb: Point3<f64>,
        out: &mut Discretization,
    ) -> Result<()> {
        self.piece_any(a, b, pb, out)
    }

    /// [`Walker::piece`] for the curve's degree, compiled for whatever the caller is.
    #[inline(always)]
    fn piece_any(
        &mut self,
        a: f64,
        b: f64,
        pb: Point3<f64>,
        out: &mut Discretization,
    ) -> Result<()> {
        macro_rules! go {
            ($p:literal, $m:expr) => {
                self.piece_of::<$p, $m>(a, b, pb, out)
            };
        }
        by_degree!(self.curve.degree(), go)
    }

    /// Certifies the segment from `start` to the trial end `(t1, p1, end)`.
    #[inline(always)]
    fn certify<const P: usize, const M: usize>(
        &mut self,
        start: &Eval,
        t1: f64,
        p1: &Point3<f64>,
        end: Option<&Eval>,
    ) -> (Bound, Option<Fail>) {
        let tol = self.opts.tolerance_mm;
        let bound = self.cert.chord_error_known::<P, M>(
            &mut self.scratch,
            (start.t, Some((start.span, start.u, start.h))),
            (t1, end.map(|e| (e.span, e.u, e.h))),
            &start.p,
            p1,
            Question {
                limit: tol,
                want_lower: self.emin,
                settle: true,
            },
        );
        if bound.upper > tol {
            return (bound, Some(Fail::Chord));
        }
        if (p1 - start.p).norm() > self.opts.max_segment_length_mm {
            return (bound, Some(Fail::Length));
        }
        let max_turn = self.opts.max_turn_deg.to_radians();
        if max_turn.is_finite() && self.cert.turn_bound(start.t, t1, max_turn) > max_turn {
            return (bound, Some(Fail::Turn));
        }
        (bound, None)
    }

    #[inline(always)]
    fn piece_of<const P: usize, const M: usize>(
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
        let mut cur = self
            .cert
            .eval::<P, M, 3>(self.cert.span_at(a, self.curve.degree()), a);
        cur.p = *out.points.last().expect("start point pushed");
        // The ratio of the measured chord error to the model's at the last accepted step: the
        // model's systematic error (the next terms of the expansion) changes slowly along the
        // curve, so the next prediction is corrected by it (warm start).
        let mut bias = 1.0f64;
        // Whether the last step was a full one (neither the piece's first nor cut short), so
        // that it is a good first guess of the next.
        let mut warm = false;
        let mut last_dt = (b - a) / 8.0;
        // The previous cutting point's parameter and span, and sqrt(k) |C'| and its
        // derivative there.
        let mut prev_f: Option<(f64, usize, (f64, f64))> = None;
        while cur.t < b {
            let t0 = cur.t;
            let d = &cur.d;
            let scaled = Scaled::new(&d[0], &d[1], &d[2]);
            let f0 = scaled.sqrt_curvature_speed();
            if let Some((tp, span, fp)) = prev_f {
                self.sqrt_curvature +=
                    crate::trapezoid_step(self.curve, (tp, span), (t0, cur.span), fp, f0);
            }
            prev_f = Some((t0, cur.span, f0));
            let model = Taylor::new(&scaled);
            let rest = b - t0;
            let mut first_h = None;
            let mut h = if self.param_only {
                last_dt
            } else {
                let mut h = model
                    .step_for(hp / bias, if warm { last_dt } else { 0.0 })
                    .min(8.0 * last_dt);
                if h.is_nan() || h <= 0.0 {
                    h = rest;
                }
                if h < rest && h < 8.0 * last_dt {
                    first_h = Some(h);
                }
                if h < rest && (max_len.is_finite() || min_len > 0.0) {
                    first_h = None;
                    let len = model.length(h);
                    if len > max_len * (1.0 - 0.5 * LENGTH_TOL) {
                        h = model.step_for_length(h, max_len * (1.0 - 0.5 * LENGTH_TOL));
                    } else if len < min_len {
                        h = model.step_for_length(h, min_len);
                    }
                }
                h
            }
            .min(rest);
            let mut good: Option<Cand> = None;
            let mut bad: Option<Cand> = None;
            let mut param_mode = self.param_only;
            let mut fails = 0usize;
            let mut last_fail = Fail::Chord;
            let mut stuck = false;
            let mut trials_made = 0;
            // The good trial before `good`, while the last two trials were both good: their
            // bounds measure the certificate's own growth with the step (see `secant_step`).
            let mut prev_good: Option<(f64, f64)>;
            for _ in 0..MAX_ITERS {
                trials_made += 1;
                let t1 = if h >= rest { b } else { t0 + h };
                if t1.is_nan() || t1 <= t0 {
                    stuck = true;
                    break;
                }
                // Certify exactly the point that will be output for the piece end.
                let (t1, p1, end) = if t1 >= b {
                    (b, pb, None)
                } else {
                    let span = self.cert.span_at(t1, cur.span);
                    let e = self.cert.eval::<P, M, 3>(span, t1);
                    (t1, e.p, Some(e))
                };
                let (bound, fail) = self.certify::<P, M>(&cur, t1, &p1, end.as_ref());
                let cand = Cand {
                    t: t1,
                    h: t1 - t0,
                    err: if bound.upper.is_finite() {
                        bound.upper
                    } else {
                        bound.lower
                    },
                    r: (p1 - cur.p).norm(),
                    end,
                    p: p1,
                    bound,
                    fail,
                };
                if let Some(f) = fail {
                    prev_good = None;
                    last_fail = f;
                    bad = Some(cand);
                    fails += 1;
                    if good.is_none() && fails >= PARAM_FALLBACK_AFTER {
                        param_mode = true;
                    }
                } else {
                    prev_good = good.filter(|_| fails == 0).map(|g| (g.h, g.err));
                    good = Some(cand);
                    fails = 0;
                    if t1 >= b || bound.upper >= emin || cand.r >= max_len * (1.0 - LENGTH_TOL) {
                        break;
                    }
                }
                // Next trial.
                h = match (good, bad) {
                    (Some(g), None) => {
                        if param_mode {
                            2.0 * g.h
                        } else {
                            let secant = prev_good.and_then(|pg| secant_step(pg, (g.h, g.err), hp));
                            let mut h = if let Some(h) = secant {
                                h.clamp(1.005 * g.h, 4.0 * g.h)
                            } else if g.err > 0.0 {
                                next_step(&model, g.h, g.err, hp).clamp(1.005 * g.h, 4.0 * g.h)
                            } else {
                                4.0 * g.h
                            };
                            if max_len.is_finite() {
                                let at_max = g.h * max_len * (1.0 - 0.5 * LENGTH_TOL) / g.r;
                                h = h.min(at_max.max(1.005 * g.h));
                            }
                            h
                        }
                    }
                    (None, Some(bd)) => {
                        let h = if param_mode {
                            0.5 * bd.h
                        } else {
                            match bd.fail {
                                Some(Fail::Length) => {
                                    bd.h * (max_len * (1.0 - 0.5 * LENGTH_TOL) / bd.r).min(0.995)
                                }
                                Some(Fail::Chord) if bd.err > 0.0 => {
                                    next_step(&model, bd.h, bd.err, hp)
                                        .clamp(0.05 * bd.h, 0.995 * bd.h)
                                }
                                _ => 0.5 * bd.h,
                            }
                        };
                        let h = if fails == 1 && !param_mode && min_len > 0.0 {
                            h.max(model.step_for_length(h, min_len))
                        } else {
                            h
                        };
                        if h >= bd.h {
                            0.5 * bd.h
                        } else {
                            h
                        }
                    }
                    (Some(g), Some(bd)) => {
                        let gap = bd.h - g.h;
                        if gap <= 1e-9 * g.h || gap <= BRACKET_TOL * g.h {
                            break;
                        }
                        if param_mode {
                            0.5 * (g.h + bd.h)
                        } else {
                            let (eg, eb) = (g.err, bd.err);
                            let secant = prev_good.and_then(|pg| secant_step(pg, (g.h, g.err), hp));
                            let next = match (bd.fail, secant) {
                                // The good end moved twice in a row: the bad end's bound is
                                // off the power law near the good end (a loose bound, the far
                                // side of a knot), and interpolating towards it would creep up
                                // in ever smaller steps (regula falsi's stagnation).
                                (Some(Fail::Chord), Some(h)) => h,
                                // Power law e = c h^q through both ends of the bracket.
                                (Some(Fail::Chord), _) if eg > 0.0 && eb > eg => {
                                    let q = (eb / eg).ln() / (bd.h / g.h).ln();
                                    g.h * (hp / eg).powf(1.0 / q)
                                }
                                (Some(Fail::Chord), _) if eg > 0.0 => g.h * (hp / eg).sqrt(),
                                // The chord's length is nearly linear in the step.
                                (Some(Fail::Length), _) if bd.r > g.r => {
                                    let target = max_len * (1.0 - 0.5 * LENGTH_TOL);
                                    g.h + gap * (target - g.r) / (bd.r - g.r)
                                }
                                _ => 0.5 * (g.h + bd.h),
                            };
                            if next.is_nan() {
                                0.5 * (g.h + bd.h)
                            } else {
                                next.clamp(g.h + 0.1 * gap, bd.h - 0.1 * gap)
                            }
                        }
                    }
                    (None, None) => unreachable!("a trial was made"),
                }
                .min(rest);
            }
            let Some(g) = good else {
                return Err(if last_fail == Fail::Turn {
                    DiscretizeError::TurnUnreachable {
                        t: t0,
                        max_turn_deg: self.opts.max_turn_deg,
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
            if !self.param_only && g.end.is_some() && g.err > 0.0 {
                // A first trial from the model: its prediction was the target (one fixed-point
                // step from a near guess leaves it within a fraction of a percent).
                let predicted = if first_h.is_some() && trials_made == 1 {
                    hp / bias
                } else {
                    model.error(g.h)
                };
                // A step across a knot measures the model against the next span's third
                // derivative, which the next step (mostly inside one span) does not meet.
                let crossed = g.t > self.curve.knots()[cur.span + 1];
                if predicted > 0.0 && !crossed {
                    bias = (g.err / predicted).clamp(0.25, 4.0);
                }
                warm = true;
            } else {
                warm = false;
            }
            last_dt = g.h;
            out.max_chord_error = out.max_chord_error.max(g.bound.upper);
            out.estimated_chord_error = out.estimated_chord_error.max(g.bound.lower);
            out.params.push(g.t);
            out.points.push(g.p);
            if out.points.len() > self.opts.max_points {
                return Err(DiscretizeError::TooManyPoints {
                    limit: self.opts.max_points,
                    estimate: out.points.len() as f64,
                });
            }
            match g.end {
                Some(e) => cur = e,
                None => {
                    // The piece's last segment: the value at its start (the value at `b` would
                    // cost an evaluation, and at a C0 break it belongs to the next piece).
                    self.sqrt_curvature += f0.0 * g.h;
                    break;
                }
            }
        }
        Ok(())
    }
}

/// The step where the power law `err = c h^q` through two good trials `(h, err)` (`a` the
/// shorter, both certified, `err` their steering values) reaches `target`, the exponent measured from them
/// and kept in `[1/2, 8]`: where the certificate's bound grows unlike the model's error (a
/// loose bound level, a knot inside the step), the bound's own growth is the better guide.
/// `None` where the bounds do not grow with the step.
#[inline(always)]
fn secant_step((ha, ea): (f64, f64), (hb, eb): (f64, f64), target: f64) -> Option<f64> {
    if !(ea > 0.0 && eb > ea && hb > ha) {
        return None;
    }
    let q = ((eb / ea).ln() / (hb / ha).ln()).clamp(0.5, 8.0);
    let h = hb * (target / eb).powf(1.0 / q);
    h.is_finite().then_some(h)
}

/// The next step after a one-sided trial of step `h` whose error came out `err`, for the
/// target `target`: the model's own step with its bias measured at `h`, kept between the
/// power laws `err ~ h^2` and `err ~ h^4` through the trial (where the model is poor, across a
/// knot, the trial's own scaling decides); NaN-free.
#[inline(always)]
fn next_step(model: &Taylor, h: f64, err: f64, target: f64) -> f64 {
    let r = target / err;
    let (q2, q4) = (h * r.sqrt(), h * r.sqrt().sqrt());
    let (lo, hi) = if r >= 1.0 { (q4, q2) } else { (q2, q4) };
    let predicted = model.error(h);
    let h = if predicted > 0.0 {
        model.step_for(target * predicted / err, h)
    } else {
        f64::NAN
    };
    if h.is_nan() {
        q2
    } else {
        h.clamp(lo, hi)
    }
}

/// Whether this thread's walks are held to the code compiled for any processor: only the test
/// that compares the two walks asks for it; outside the tests the walk always takes the fastest
/// code the processor runs.
#[inline(always)]
fn generic_only() -> bool {
    #[cfg(test)]
    {
        tests::generic_only()
    }
    #[cfg(not(test))]
    {
        false
    }
}

/// Whether this processor has what [`Walker::piece_v3`] is compiled for (checked once, then
/// cached by the standard library).
#[cfg(target_arch = "x86_64")]
#[inline]
fn x86_64_v3() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
        && std::arch::is_x86_feature_detected!("bmi1")
        && std::arch::is_x86_feature_detected!("bmi2")
        && std::arch::is_x86_feature_detected!("lzcnt")
        && std::arch::is_x86_feature_detected!("movbe")
        && std::arch::is_x86_feature_detected!("popcnt")
        && std::arch::is_x86_feature_detected!("f16c")
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

#[cfg(test)]
mod tests {
    use std::cell::Cell;

    use kerf_nurbs::NurbsCurve;
    use nalgebra::{Point3, Vector3};

    use crate::{discretize, Options};

    thread_local! {
        static GENERIC_ONLY: Cell<bool> = const { Cell::new(false) };
    }

    /// Whether this thread's walks are held to the code compiled for any processor.
    pub(super) fn generic_only() -> bool {
        GENERIC_ONLY.with(Cell::get)
    }

    /// The walk compiled for x86-64-v3 and the walk compiled for any x86-64 make the same
    /// cutting points to the bit, and the same certified bound (the proof of
    /// `docs/discretization.md` is about the IEEE operations, which target features do not
    /// change: Rust never fuses a multiply and an add it was not told to). On a processor
    /// without those features both runs take the generic walk and the test holds trivially,
    /// which it says.
    #[test]
    fn the_vector_walk_and_the_generic_walk_agree_to_the_bit() {
        let mut curves: Vec<NurbsCurve> = (1..=9)
            .flat_map(|d| kerf_nurbs::smooth_random_curves(d, 4, 1000 + d as u64))
            .collect();
        // Rational: the same curves with uneven weights, and an exact circle far from the
        // origin.
        for c in kerf_nurbs::smooth_random_curves(4, 3, 77) {
            let w: Vec<f64> = (0..c.len()).map(|i| 0.5 + (i % 3) as f64 * 0.75).collect();
            curves.push(NurbsCurve::new(
                c.degree(),
                c.knots().to_vec(),
                c.control_points(),
                Some(w),
            ));
        }
        curves.push(
            NurbsCurve::circle(
                Point3::new(1e4, -3e3, 250.0),
                Vector3::new(1.0, 2.0, 3.0),
                40.0,
            )
            .expect("circle"),
        );
        #[cfg(target_arch = "x86_64")]
        if !super::x86_64_v3() {
            eprintln!("this processor has no x86-64-v3: both walks are the generic one");
        }
        for tol in [0.01, 1e-4] {
            let opts = Options::with_tolerance(tol);
            for (i, c) in curves.iter().enumerate() {
                GENERIC_ONLY.with(|g| g.set(false));
                let fast = discretize(c, &opts).expect("walk");
                GENERIC_ONLY.with(|g| g.set(true));
                let generic = discretize(c, &opts).expect("walk");
                GENERIC_ONLY.with(|g| g.set(false));
                let bits = |d: &crate::Discretization| -> Vec<u64> {
                    d.params()
                        .iter()
                        .map(|t| t.to_bits())
                        .chain(
                            d.points()
                                .iter()
                                .flat_map(|p| p.iter().map(|x| x.to_bits())),
                        )
                        .chain([d.max_chord_error().to_bits()])
                        .collect()
                };
                assert!(fast.points().len() > 2, "curve {i}: a real walk");
                assert_eq!(bits(&fast), bits(&generic), "curve {i} at {tol} mm");
            }
        }
    }
}
