//! Cutting points on NURBS curves with a certified chord error.
//!
//! The reference-sphere method of paper 004 (Wang et al., Chinese J. Lasers 2010): from each
//! cutting point, the osculating circle predicts the sphere radius whose chord has the target
//! sagitta; the sphere centred at the point meets the curve at the candidate next point; the
//! radius is then bisected until the chord error lies in the band `[E_min, E_max]`. kerf
//! replaces the paper's `dL/dt = 0` error estimate by a *certified* upper bound (convex hull of
//! the rational Bezier pieces, refined by subdivision), so every segment's chord error is
//! proven `<= tolerance`. The proof is in `docs/discretization.md`.
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
//! assert!(d.max_chord_error <= 0.01, "certified");
//! assert_eq!(d.params[0], 0.0, "starts at the domain start");
//! assert_eq!(*d.params.last().unwrap(), 1.0, "ends at the domain end");
//! # Ok::<(), kerf_discretize::DiscretizeError>(())
//! ```

mod bound;
mod classic;
mod error;
mod minimum;
mod options;
mod sphere;
mod walk;

pub use bound::{chord_error, Bound, Certifier, Scratch, MARGIN_FACTOR, MAX_SUBDIVISION_DEPTH};
pub use error::{DiscretizeError, Result};
pub use minimum::{
    estimate_count, estimate_turning, minimum_count, minimum_count_quadrature,
    sqrt_curvature_integral, sqrt_curvature_quadrature, NSTAR_ABSOLUTE_ACCURACY,
    NSTAR_RELATIVE_ACCURACY, NSTAR_SPLITS_PER_SPAN,
};
pub use options::{Options, Strategy};

use kerf_nurbs::NurbsCurve;
use nalgebra::Point3;
use rayon::prelude::*;

/// The cutting points of one curve.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Discretization {
    /// Curve parameter of each cutting point; strictly increasing, first and last are the ends
    /// of the domain.
    pub params: Vec<f64>,
    /// The cutting points `C(params[n])`.
    pub points: Vec<Point3<f64>>,
    /// Certified upper bound of the chord error over every segment (`<= tolerance`).
    pub max_chord_error: f64,
    /// The largest chord error actually observed (a lower bound of the true maximum).
    pub estimated_chord_error: f64,
    /// The C0 break parameters that were forced as cutting points.
    pub c0_breaks: Vec<f64>,
}

impl Discretization {
    /// Number of segments (points - 1).
    pub fn segments(&self) -> usize {
        self.points.len().saturating_sub(1)
    }
}

/// The ends of the C0 pieces: the domain ends and every C0 break in between. Fails if the
/// curve jumps by more than half the tolerance at a knot of multiplicity `degree + 1`
/// (smaller gaps are covered by the certified bound of the segment that ends there).
///
/// # Errors
/// [`DiscretizeError::Discontinuous`].
pub fn piece_ends(curve: &NurbsCurve, tolerance: f64) -> Result<Vec<f64>> {
    let (a, b) = curve.domain();
    let breaks = curve.c0_breaks();
    let p = curve.degree();
    for &u in &breaks {
        if kerf_nurbs::multiplicity(curve.knots(), u) > p {
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
    let mut ends = piece_ends(curve, opts.tolerance)?;
    ends.retain(|&t| t > a && t < b);
    ends.insert(0, a);
    ends.push(b);
    // Everything that can refuse the request is decided here, before any walk: the rounding
    // margin (known from the control points), then the size of the output.
    let cert = Certifier::new(curve);
    let margin = cert.max_margin() + cert.output_resolution();
    if margin.is_nan() || margin > 0.5 * opts.tolerance {
        return Err(DiscretizeError::ToleranceBelowMargin {
            tolerance: opts.tolerance,
            margin,
        });
    }
    let estimate = estimate_count(curve, opts.tolerance);
    let by_length = if opts.max_segment_length.is_finite() {
        curve.size() / opts.max_segment_length
    } else {
        0.0
    };
    let by_turn = if opts.max_turn.is_finite() {
        minimum::estimate_turning(curve) / opts.max_turn
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
        c0_breaks: ends[1..ends.len() - 1].to_vec(),
        ..Default::default()
    };
    let mut pa = curve.point(ends[0]);
    out.params.push(ends[0]);
    out.points.push(pa);
    let mut walker = walk::Walker {
        curve,
        opts,
        scratch: Default::default(),
        param_only: opts.strategy == Strategy::EqualError,
        emin: opts.band * (opts.tolerance - margin),
        cert,
    };
    for w in ends.windows(2) {
        let (a, b) = (w[0], w[1]);
        let pb = curve.point(b);
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
    Ok(out)
}

/// Discretizes many curves in parallel (rayon); results in input order, identical to calling
/// [`discretize`] on each curve in turn.
pub fn discretize_all(curves: &[NurbsCurve], opts: &Options) -> Vec<Result<Discretization>> {
    curves.par_iter().map(|c| discretize(c, opts)).collect()
}
