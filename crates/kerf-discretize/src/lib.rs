//! Cutting points on NURBS curves with a certified chord error.
//!
//! After the reference-sphere method of paper 004 (Wang et al., Chinese J. Lasers 2010), which
//! predicts each chord from the osculating circle, intersects the sphere of that radius with
//! the curve and bisects the radius until the chord error lies in the band `[E_min, E_max]`:
//! kerf predicts the parameter step from the arc's Taylor cubic at the point, certifies it, and
//! corrects it from the certificate's own numbers, usually at once. The paper's `dL/dt = 0`
//! error estimate is replaced by a *certified* upper bound (a closed-form interpolation bound
//! inside a knot span, else the convex hull of the rational Bezier pieces refined by
//! subdivision), so every segment's chord error is proven `<= tolerance`. The proof is in
//! `docs/discretization.md`.
//!
//! ```
//! use kerf_discretize::{discretize, Options};
//! use kerf_nurbs::NurbsCurve;
//! use nalgebra::Point3;
//!
//! let h = std::f64::consts::FRAC_1_SQRT_2;
//! let quarter = NurbsCurve::new(
//!     2,
//!     vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
//!     vec![Point3::new(50.0, 0.0, 0.0), Point3::new(50.0, 50.0, 0.0), Point3::new(0.0, 50.0, 0.0)],
//!     Some(vec![1.0, h, 1.0]),
//! );
//! let d = discretize(&quarter, &Options::with_tolerance(0.01))?;
//! assert!(d.max_chord_error() <= 0.01, "certified");
//! assert_eq!(d.params()[0], 0.0, "starts at the domain start");
//! assert_eq!(*d.params().last().unwrap(), 1.0, "ends at the domain end");
//! # Ok::<(), kerf_discretize::DiscretizeError>(())
//! ```

mod batch;
mod bound;
mod classic;
mod error;
mod minimum;
mod options;
mod sphere;
mod walk;

pub use batch::{Batch, BatchError, BatchRefusal};
pub use bound::{chord_error, Bound, Certifier, Scratch, MARGIN_FACTOR, MAX_SUBDIVISION_DEPTH};
pub use error::{DiscretizeError, Result};
pub use minimum::{
    estimate_count, estimate_turning, minimum_count, minimum_count_quadrature,
    sqrt_curvature_integral, sqrt_curvature_quadrature, NSTAR_ABSOLUTE_ACCURACY,
    NSTAR_RELATIVE_ACCURACY, NSTAR_SPLITS_PER_SPAN,
};
pub use options::{Options, Strategy};

use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

/// The cutting points of one curve, with the certificate of their chord error.
///
/// The fields are private: a `Discretization` is made only by the discretizer
/// ([`discretize`], [`discretize_range`]), or by [`Discretization::certify`], which proves the
/// bound of every segment of given parameters itself. So [`Discretization::max_chord_error`] is
/// always a certified bound, and later stages (the normals' `orient`) can rely on it. Points read
/// back from a toolpath file are a claim, not a certificate: check them with `kerf-check`, or
/// turn them into a `Discretization` with [`Discretization::certify`]. There is deliberately no
/// `Default` (an empty value would carry a certificate no walk produced):
///
/// ```compile_fail
/// let forged = kerf_discretize::Discretization::default();
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Discretization {
    params: Vec<f64>,
    points: Vec<Point3<f64>>,
    max_chord_error: f64,
    estimated_chord_error: f64,
    c0_breaks: Vec<f64>,
    /// `integral sqrt(k) |C'| dt` over the range by the trapezoid rule on the cutting points.
    sqrt_curvature: f64,
}

impl Discretization {
    /// Number of segments (points - 1).
    pub fn segments(&self) -> usize {
        self.points.len().saturating_sub(1)
    }

    /// Curve parameter of each cutting point; strictly increasing, first and last are the ends
    /// of the discretized range.
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// The cutting points `C(params[n])`, evaluated on the curve.
    pub fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    /// Certified upper bound (mm) of the chord error over every segment, rounding margin
    /// included; `<=` the tolerance asked for.
    pub fn max_chord_error(&self) -> f64 {
        self.max_chord_error
    }

    /// The largest chord error actually observed (mm): a curve point's distance from its
    /// chord, so a lower bound of the true maximum.
    pub fn estimated_chord_error(&self) -> f64 {
        self.estimated_chord_error
    }

    /// The C0 break parameters strictly inside the range, each of which is a cutting point.
    pub fn c0_breaks(&self) -> &[f64] {
        &self.c0_breaks
    }

    /// The theoretical minimum number of segments `N* = integral sqrt(k / (8 tol)) ds` for the
    /// tolerance asked (`docs/discretization.md`), estimated at no extra cost from what the
    /// walk evaluated: the trapezoid rule on `sqrt(k) |C'|` at the cutting points (the walk
    /// computes the curvature at every point to predict its next step). The nodes are the
    /// cutting points themselves, about `N*` of them, so on smooth curves this agrees with the
    /// adaptive quadrature of [`minimum_count`] to a small fraction of a chord per C0 piece (the
    /// last segment of each piece uses the value at its start). It is an estimate, not a
    /// bound; [`minimum_count`] is the accurate (and far costlier) figure.
    pub fn n_star(&self, tolerance: f64) -> f64 {
        self.sqrt_curvature / (8.0 * tolerance).sqrt()
    }

    /// The parameters and the points, moved out (no copy).
    pub fn into_parts(self) -> (Vec<f64>, Vec<Point3<f64>>) {
        (self.params, self.points)
    }

    /// Certifies given cutting parameters of `curve` (for instance read back from a toolpath
    /// file): checks that they are strictly increasing from one end of the domain to the other
    /// and contain every C0 break, evaluates the points on the curve, and proves the chord
    /// error of every segment `<= tolerance` with the same bound as the discretizer
    /// (`docs/discretization.md`). The result is then as trustworthy as one from
    /// [`discretize`].
    ///
    /// # Errors
    /// [`DiscretizeError::BadOption`] for a tolerance that is not finite and positive,
    /// [`DiscretizeError::ToleranceBelowMargin`] as in [`discretize`],
    /// [`DiscretizeError::NotCertified`] naming the first parameter or segment that fails.
    pub fn certify(curve: &NurbsCurve, params: &[f64], tolerance: f64) -> Result<Self> {
        Options::with_tolerance(tolerance).validate()?;
        let cert = Certifier::new(curve);
        margin_refusal(tolerance, cert.max_margin() + cert.output_resolution())?;
        let fail = |index: usize, reason: &'static str, bound: f64| {
            Err(DiscretizeError::NotCertified {
                index,
                reason,
                bound,
            })
        };
        let (a, b) = curve.domain();
        if params.len() < 2 {
            return fail(0, "at least two parameters are needed", f64::NAN);
        }
        if params[0] != a || params[params.len() - 1] != b {
            return fail(
                0,
                "the parameters must start and end at the domain's ends",
                f64::NAN,
            );
        }
        if let Some(i) = params
            .windows(2)
            .position(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less))
        {
            return fail(i + 1, "parameters must be strictly increasing", f64::NAN);
        }
        let c0_breaks = piece_ends(curve, tolerance)?;
        let c0_breaks = c0_breaks[1..c0_breaks.len() - 1].to_vec();
        if let Some(&t) = c0_breaks
            .iter()
            .find(|t| params.binary_search_by(|p| p.total_cmp(t)).is_err())
        {
            return fail(0, "a C0 break is not a cutting point", t);
        }
        let points: Vec<Point3<f64>> = params.iter().map(|&t| cert.point(t)).collect();
        let mut scratch = bound::Scratch::default();
        let (mut upper, mut lower) = (0.0f64, 0.0f64);
        for i in 0..params.len() - 1 {
            let bd = cert.chord_error(
                &mut scratch,
                params[i],
                params[i + 1],
                &points[i],
                &points[i + 1],
                tolerance,
                tolerance,
            );
            if bd.upper.is_nan() || bd.upper > tolerance {
                return fail(i, "the segment's chord error cannot be certified", bd.upper);
            }
            upper = upper.max(bd.upper);
            lower = lower.max(bd.lower);
        }
        let sqrt_curvature = trapezoid_sqrt_curvature(curve, params);
        Ok(Self {
            params: params.to_vec(),
            points,
            max_chord_error: upper,
            estimated_chord_error: lower,
            c0_breaks,
            sqrt_curvature,
        })
    }
}

impl Discretization {
    /// This discretization of `curve` with one more cutting point, at `t` strictly between two
    /// cutting points (for instance where a cut must start): only the two new segments are
    /// certified, with the bound of [`Discretization::certify`] at `tolerance` (the tolerance
    /// the discretization was made with); every other segment keeps its certificate. The
    /// certified maximum becomes the larger of the old one and the new segments' (a bound,
    /// possibly above the true maximum when the replaced segment held it); the observed
    /// maximum, which must stay a lower bound of the true one, becomes the new segments' (the
    /// replaced segment may have held the old one).
    ///
    /// # Errors
    /// As [`Discretization::certify`] for the tolerance; [`DiscretizeError::NotCertified`] if
    /// `t` is not strictly between two cutting points (or `curve` is not the one discretized:
    /// its domain differs) or a new segment cannot be certified.
    pub fn with_point(&self, curve: &NurbsCurve, t: f64, tolerance: f64) -> Result<Self> {
        Options::with_tolerance(tolerance).validate()?;
        let cert = Certifier::new(curve);
        margin_refusal(tolerance, cert.max_margin() + cert.output_resolution())?;
        let n = self.params.len();
        let i = self.params.partition_point(|&p| p < t);
        let (a, b) = curve.domain();
        let inside = i > 0 && i < n && self.params[i - 1] < t && t < self.params[i];
        if !inside || self.params[0] != a || self.params[n - 1] != b {
            return Err(DiscretizeError::NotCertified {
                index: i,
                reason: "the new parameter must lie strictly between two cutting points",
                bound: t,
            });
        }
        let p = cert.point(t);
        let mut scratch = bound::Scratch::default();
        let (t0, t1) = (self.params[i - 1], self.params[i]);
        let left = cert.chord_error(
            &mut scratch,
            t0,
            t,
            &self.points[i - 1],
            &p,
            tolerance,
            tolerance,
        );
        let right = cert.chord_error(
            &mut scratch,
            t,
            t1,
            &p,
            &self.points[i],
            tolerance,
            tolerance,
        );
        for (k, bd) in [(i - 1, left), (i, right)] {
            if bd.upper.is_nan() || bd.upper > tolerance {
                return Err(DiscretizeError::NotCertified {
                    index: k,
                    reason: "the segment's chord error cannot be certified",
                    bound: bd.upper,
                });
            }
        }
        let mut params = self.params.clone();
        let mut points = self.points.clone();
        params.insert(i, t);
        points.insert(i, p);
        let value = |u: f64| {
            let d = curve.eval_d3(u);
            Scaled::new(&d[1], &d[2], &d[3]).sqrt_curvature_speed()
        };
        let (v0, v, v1) = (value(t0), value(t), value(t1));
        let at = |u: f64| (u, curve.span(u));
        let sqrt_curvature = self.sqrt_curvature - trapezoid_step(curve, at(t0), at(t1), v0, v1)
            + trapezoid_step(curve, at(t0), at(t), v0, v)
            + trapezoid_step(curve, at(t), at(t1), v, v1);
        let new_lower = left.lower.max(right.lower);
        Ok(Self {
            params,
            points,
            max_chord_error: self.max_chord_error.max(left.upper).max(right.upper),
            estimated_chord_error: new_lower,
            c0_breaks: self.c0_breaks.clone(),
            sqrt_curvature,
        })
    }
}

/// The first three derivatives at a point, scaled to a parameter that moves about as fast as
/// the arc length: with `s = |C'|`, `v = C' / s`, `a = C'' / s^2`, `j = C''' / s^3` (the
/// derivatives with respect to `x = s (t - t0)`). Whatever the scale of the knots (a range of
/// `1e-50` gives `|C'| ~ 1e52`, `|C''| ~ 1e104`, and `C' x C''` would overflow), these are of the
/// size of the geometry: the step model and `N*` work on them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scaled {
    pub s: f64,
    pub v: Vector3<f64>,
    pub a: Vector3<f64>,
    pub j: Vector3<f64>,
}

impl Scaled {
    /// From the first three derivatives with respect to the curve's parameter.
    #[inline(always)]
    pub(crate) fn new(d1: &Vector3<f64>, d2: &Vector3<f64>, d3: &Vector3<f64>) -> Self {
        let s = d1.norm();
        let inv = 1.0 / s;
        Self {
            s,
            v: d1 * inv,
            a: d2 * inv * inv,
            j: d3 * inv * inv * inv,
        }
    }

    /// `f = sqrt(k) |C'|` and its derivative `df/dt`. The curvature is `k = |v x a|`, so
    /// `f = s sqrt(|b|)` with `b = v x a`, and (`db/dx = v x j` up to terms along `b`'s own
    /// scaling) `df/dt = (f s / 2) ((b . c) / |b|^2 - v . a)` with `c = v x j`.
    /// `f` is 0 where it is not finite (a removable or integrable singularity of the
    /// integrand); `df/dt` is NaN where it is not finite (`k = 0`, where `sqrt(k)` has no
    /// derivative).
    #[inline(always)]
    pub(crate) fn sqrt_curvature_speed(&self) -> (f64, f64) {
        let b = self.v.cross(&self.a);
        let bb = b.norm_squared();
        let f = bb.sqrt().sqrt() * self.s;
        let df = 0.5 * f * self.s * (b.dot(&self.v.cross(&self.j)) / bb - self.v.dot(&self.a));
        let f = if f.is_finite() { f } else { 0.0 };
        let df = if df.is_finite() { df } else { f64::NAN };
        (f, df)
    }
}

/// The corrected trapezoid rule for `integral sqrt(k) |C'| dt` on the nodes `params` (one
/// evaluation per node), for the strategies that do not evaluate the curvature at their points.
fn trapezoid_sqrt_curvature(curve: &NurbsCurve, params: &[f64]) -> f64 {
    let mut sum = 0.0;
    let mut prev = None;
    for &t in params {
        let d = curve.eval_d3(t);
        let v = Scaled::new(&d[1], &d[2], &d[3]).sqrt_curvature_speed();
        if let Some((tp, vp)) = prev {
            sum += trapezoid_step(curve, (tp, curve.span(tp)), (t, curve.span(t)), vp, v);
        }
        prev = Some((t, v));
    }
    sum
}

/// One step of the quadrature of `integral f dt`, `f = sqrt(k) |C'|`, on `[t0, t1]` from the
/// values and derivatives `(f, f')` at its ends: the corrected trapezoid rule
/// `h (f0 + f1) / 2 + h^2 (f0' - f1') / 12` (exact for cubics; the plain rule overestimates
/// `N*` by up to 0.9 % at 0.01 mm, where the steps are long). Where a derivative is not finite
/// (`k = 0`) or the correction exceeds a quarter of the step, the plain rule is used. The
/// curvature may jump at a knot (degree 2, or repeated knots), so a step that crosses knots
/// uses each end's value up to the nearest knot on its side (and the mean in between): the
/// error is then of the order of the integrand's variation within a span, not of its jump.
/// `span` and `span1` are the knot spans of `t0` and `t1` (`NurbsCurve::span`).
#[inline(always)]
pub(crate) fn trapezoid_step(
    curve: &NurbsCurve,
    (t0, span): (f64, usize),
    (t1, span1): (f64, usize),
    (f0, g0): (f64, f64),
    (f1, g1): (f64, f64),
) -> f64 {
    let knots = curve.knots();
    let first = knots[span + 1];
    if first >= t1 || span + 1 >= curve.len() {
        let h = t1 - t0;
        let plain = 0.5 * (f0 + f1) * h;
        let corr = h * h * (g0 - g1) / 12.0;
        return if corr.is_finite() && corr.abs() <= 0.25 * plain.abs() {
            plain + corr
        } else {
            plain
        };
    }
    let last = knots[span1].max(first);
    if last >= t1 {
        return f0 * (first - t0) + f1 * (t1 - first);
    }
    f0 * (first - t0) + 0.5 * (f0 + f1) * (last - first) + f1 * (t1 - last)
}

/// Refuses a tolerance that cannot be certified on `curve`, from its control points alone
/// (one pass, no Bezier form, no walk): a tolerance that is not finite and positive, or one
/// below twice the certificate's rounding margin plus the output resolution
/// ([`Certifier::max_margin`], [`Certifier::output_resolution`]). [`discretize`] makes the
/// same check before its walk; a caller that discretizes many curves and stops at the first
/// failure should check every curve first, so that a curve late in the file that cannot be
/// certified is refused before the walks of the curves before it.
///
/// # Errors
/// [`DiscretizeError::BadOption`] (named `tolerance_mm`), [`DiscretizeError::ToleranceBelowMargin`].
pub fn check_tolerance(curve: &NurbsCurve, tolerance: f64) -> Result<()> {
    Options::with_tolerance(tolerance).validate()?;
    let m = bound::Margins::of(curve, &kerf_nurbs::LocalCurve::new(curve));
    margin_refusal(tolerance, m.max_margin + m.output_resolution)
}

/// The refusal of a tolerance below twice the `margin` (max margin plus output resolution).
fn margin_refusal(tolerance: f64, margin: f64) -> Result<()> {
    if margin.is_nan() || margin > 0.5 * tolerance {
        return Err(DiscretizeError::ToleranceBelowMargin { tolerance, margin });
    }
    Ok(())
}

/// The ends of the C0 pieces: the domain ends and every C0 break in between. Fails if the
/// curve jumps by more than half the tolerance at a knot of multiplicity `degree + 1`
/// (smaller gaps are covered by the certified bound of the segment that ends there).
///
/// # Errors
/// [`DiscretizeError::Discontinuous`].
pub fn piece_ends(curve: &NurbsCurve, tolerance: f64) -> Result<Vec<f64>> {
    let (a, b) = curve.domain();
    let p = curve.degree();
    // One pass over the knots gives every break with its multiplicity (a scan per break was
    // quadratic on a polyline with a break at each of its 200,000 knots).
    let knots = kerf_nurbs::interior_knots(p, curve.knots(), curve.len());
    let mut breaks = Vec::with_capacity(knots.len());
    for (u, m) in knots.into_iter().filter(|&(_, m)| m >= p) {
        breaks.push(u);
        if m > p {
            let span = curve.span(u);
            // The span ending at u, to its left.
            let left_span = (p..span)
                .rev()
                .find(|&i| curve.knots()[i] < curve.knots()[i + 1]);
            if let Some(ls) = left_span {
                let lo = curve.knots()[ls];
                let left = curve.bezier_in_span(ls, lo, u);
                let end = left.homogeneous()[p];
                let l = Point3::from(end.xyz() / end.w);
                let gap = (l - curve.point(u)).norm();
                if gap > 0.5 * tolerance {
                    return Err(DiscretizeError::Discontinuous { t: u, gap });
                }
            }
        }
    }
    let mut ends = Vec::with_capacity(breaks.len() + 2);
    ends.push(a);
    ends.extend(breaks);
    ends.push(b);
    Ok(ends)
}

/// Discretizes one curve.
///
/// # Errors
/// [`DiscretizeError::BadOption`] for invalid options, [`DiscretizeError::Discontinuous`] for a
/// curve that jumps, [`DiscretizeError::TooManyPoints`] when the estimate exceeds
/// [`Options::max_points`], and [`DiscretizeError::ToleranceBelowPrecision`] when the tolerance
/// cannot be resolved in double precision.
pub fn discretize(curve: &NurbsCurve, opts: &Options) -> Result<Discretization> {
    let (a, b) = curve.domain();
    discretize_range(curve, a, b, opts)
}

/// Discretizes the part `[a, b]` of the curve's domain (`a < b`, both inside the domain), with
/// the same guarantees as [`discretize`]: the first and last parameters are `a` and `b`, and the
/// C0 breaks strictly inside are cutting points. Later stages use it to refine a stretch of an
/// existing discretization.
///
/// # Errors
/// As [`discretize`], and [`DiscretizeError::BadOption`] (named `range`) if `[a, b]` is empty or
/// outside the domain.
pub fn discretize_range(
    curve: &NurbsCurve,
    a: f64,
    b: f64,
    opts: &Options,
) -> Result<Discretization> {
    opts.validate()?;
    let (da, db) = curve.domain();
    if !(a >= da && b <= db && a < b) {
        return Err(DiscretizeError::BadOption {
            name: "range",
            value: a,
            reason: "must satisfy domain start <= a < b <= domain end",
        });
    }
    let mut ends = piece_ends(curve, opts.tolerance_mm)?;
    ends.retain(|&t| t > a && t < b);
    ends.insert(0, a);
    ends.push(b);
    // Everything that can refuse the request is decided here, before any walk: the rounding
    // margin (known from the control points), then the size of the output.
    let cert = Certifier::new(curve);
    let margin = cert.max_margin() + cert.output_resolution();
    margin_refusal(opts.tolerance_mm, margin)?;
    macro_rules! estimate {
        ($p:literal, $m:expr) => {
            minimum::estimate_count_with(curve, opts.tolerance_mm, |span, t| {
                let e = cert.eval::<$p, $m, 2>(span, t);
                (e.d[0], e.d[1])
            })
        };
    }
    let estimate = bound::by_degree!(curve.degree(), estimate);
    let by_length = if opts.max_segment_length_mm.is_finite() {
        curve.size() / opts.max_segment_length_mm
    } else {
        0.0
    };
    let by_turn = if opts.max_turn_deg.is_finite() {
        minimum::estimate_turning(curve) / opts.max_turn_deg.to_radians()
    } else {
        0.0
    };
    let expected = estimate.max(by_length).max(by_turn) + ends.len() as f64;
    if expected.is_nan() || expected > opts.max_points as f64 {
        return Err(DiscretizeError::TooManyPoints {
            limit: opts.max_points,
            estimate: expected,
        });
    }
    let cap = ((expected * 1.2) as usize + 8).min(opts.max_points + 1);
    let mut out = Discretization {
        params: Vec::with_capacity(cap),
        points: Vec::with_capacity(cap),
        max_chord_error: 0.0,
        estimated_chord_error: 0.0,
        c0_breaks: ends[1..ends.len() - 1].to_vec(),
        sqrt_curvature: 0.0,
    };
    let mut pa = cert.point(ends[0]);
    out.params.push(ends[0]);
    out.points.push(pa);
    let mut walker = walk::Walker {
        curve,
        opts,
        scratch: Default::default(),
        param_only: opts.strategy == Strategy::EqualError,
        emin: opts.band * (opts.tolerance_mm - margin),
        cert,
        sqrt_curvature: 0.0,
    };
    for w in ends.windows(2) {
        let (a, b) = (w[0], w[1]);
        let pb = walker.cert.point(b);
        match opts.strategy {
            Strategy::ReferenceSphere | Strategy::EqualError => walker.piece(a, b, pb, &mut out)?,
            Strategy::EqualParameter | Strategy::EqualChordLength => {
                let start = (estimate * (b - a) / (ends[ends.len() - 1] - ends[0])).ceil() as usize;
                let piece = classic::Piece {
                    a,
                    b,
                    pa,
                    pb,
                    start,
                };
                if opts.strategy == Strategy::EqualParameter {
                    classic::equal_parameter(&walker.cert, opts, piece, &mut out)?;
                } else {
                    classic::equal_chord(&walker.cert, opts, piece, &mut out)?;
                }
            }
        }
        pa = pb;
        if out.points.len() > opts.max_points {
            return Err(DiscretizeError::TooManyPoints {
                limit: opts.max_points,
                estimate: out.points.len() as f64,
            });
        }
    }
    out.sqrt_curvature = match opts.strategy {
        Strategy::ReferenceSphere | Strategy::EqualError => walker.sqrt_curvature,
        Strategy::EqualParameter | Strategy::EqualChordLength => {
            trapezoid_sqrt_curvature(curve, &out.params)
        }
    };
    Ok(out)
}

/// Discretizes many curves in parallel (rayon); results in input order, identical to calling
/// [`discretize`] on each curve in turn when every curve's tolerance can be certified. One
/// [`Batch`] of the curves, every result kept.
///
/// Refusals known from the options and the control points come first, before any walk: if the
/// options are invalid every result is that error, and if the tolerance is below the rounding
/// margin of some curves ([`check_tolerance`]) no curve is walked: those curves' results are
/// [`DiscretizeError::ToleranceBelowMargin`] and every other result is
/// [`DiscretizeError::NotWalked`] naming the first refused curve (a batch at a tolerance that
/// cannot hold for all of it is refused at once, not after the walks of the others).
pub fn discretize_all(curves: &[NurbsCurve], opts: &Options) -> Vec<Result<Discretization>> {
    let batch = match Batch::new(curves, |c| c, opts) {
        Ok(batch) => batch,
        Err(BatchRefusal::Options(e)) => return curves.iter().map(|_| Err(e.clone())).collect(),
        Err(BatchRefusal::Curve { index, .. }) => {
            // Every curve's own refusal (control points only), the others not walked.
            return curves
                .par_iter()
                .map(|c| {
                    check_tolerance(c, opts.tolerance_mm)
                        .and(Err(DiscretizeError::NotWalked { index }))
                })
                .collect();
        }
    };
    let mut results = Vec::with_capacity(curves.len());
    let ran = batch.each(&|_, _| {}, |_, r| {
        results.push(r);
        Ok::<(), std::convert::Infallible>(())
    });
    match ran {
        Ok(()) => {}
        // Not reached: the batch has no total limit and the sink does not fail.
        Err(BatchError::TooManyPoints { limit, reached, .. }) => {
            results.resize_with(curves.len(), || {
                Err(DiscretizeError::TooManyPoints {
                    limit,
                    estimate: reached,
                })
            });
        }
        Err(BatchError::Sink { source, .. }) => match source {},
    }
    results
}
