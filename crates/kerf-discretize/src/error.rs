//! The error type of the discretizer.

use kerf_nurbs::Readable;
use thiserror::Error;

/// What can go wrong when discretizing a curve.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum DiscretizeError {
    /// An option is out of range (NaN, infinite where a finite value is needed, negative, or
    /// inconsistent with another option). Fix: see the option's documentation in
    /// [`crate::Options`].
    #[error("option {name}: {reason} (got {})", Readable(*.value))]
    BadOption {
        /// The option's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The curve jumps at a knot of multiplicity `degree + 1`: a cut contour must be
    /// continuous. Fix: split the curve into two curves at that parameter.
    #[error("curve is discontinuous at t = {} (gap {:.3e} mm); split it into two curves there", Readable(*.t), .gap)]
    Discontinuous {
        /// Parameter of the jump.
        t: f64,
        /// Distance between the left and right limits.
        gap: f64,
    },
    /// No step, however short, met the tolerance at `t`: the tolerance is below what double
    /// precision can resolve at the curve's coordinates. Fix: raise the tolerance or move the
    /// part closer to the origin.
    #[error("tolerance {} mm cannot be met at t = {}: below the floating-point resolution of the curve's coordinates", Readable(*.tolerance), Readable(*.t))]
    ToleranceBelowPrecision {
        /// Parameter where the walk got stuck.
        t: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// The rounding margin the certificate must add (from the magnitudes of the curve's
    /// control points about its local origin, and one ulp of its coordinates for the rounded
    /// cutting points; known before the walk) is more than half the tolerance, so the tolerance
    /// cannot be certified. Fix: raise the tolerance above twice the margin, or, for a part
    /// far from the origin whose knot spans are long, split it into shorter curves.
    #[error("tolerance {} mm is below what double precision can certify for this curve: the rounding margin of its coordinates is {:.3e} mm; use a tolerance of at least {:.3e} mm", Readable(*.tolerance), .margin, 2.0 * .margin)]
    ToleranceBelowMargin {
        /// The tolerance.
        tolerance: f64,
        /// The largest rounding margin of a segment, plus the output resolution.
        margin: f64,
    },
    /// No step after `t` could be represented: the next parameter value after `t` in double
    /// precision is already too far (the knot values are huge compared with the domain, or
    /// the domain is a handful of ulps long). Fix: reparametrise the curve (e.g. knots from 0
    /// to 1).
    #[error("no cutting point can follow t = {}: the parameter's floating-point resolution is too coarse there; reparametrise the curve (knots from 0 to 1)", Readable(*.t))]
    ParameterResolution {
        /// Parameter where the walk got stuck.
        t: f64,
    },
    /// No step after `t`, however short, keeps the tangent's turn within `max_turn`: the
    /// tangent turns abruptly there (a corner or cusp inside a knot span). Fix: raise
    /// [`crate::Options::max_turn_deg`], or split the curve at the corner so that it becomes a C0
    /// break.
    #[error("the tangent turns by more than max_turn = {max_turn_deg:.3} degrees at t = {} however short the segment (a corner inside a knot span); raise max_turn_deg or split the curve there", Readable(*.t))]
    TurnUnreachable {
        /// Parameter where the walk got stuck.
        t: f64,
        /// The limit, degrees.
        max_turn_deg: f64,
    },
    /// The discretization would exceed [`crate::Options::max_points`]. Fix: raise the
    /// tolerance, or raise the limit if the count is really wanted.
    #[error("more than {limit} cutting points would be needed (estimated {}); raise the tolerance, or the limit (Options::max_points)", Readable(.estimate.round()))]
    TooManyPoints {
        /// The limit.
        limit: usize,
        /// The estimated count.
        estimate: f64,
    },
    /// [`crate::Discretization::certify`] was given parameters that it cannot certify. Fix:
    /// discretize the curve with [`crate::discretize`] instead, or correct the parameters.
    #[error("cutting parameter or segment {index} cannot be certified: {reason} (bound {})", Readable(*.bound))]
    NotCertified {
        /// Index of the parameter (or of the segment, which starts at that parameter).
        index: usize,
        /// What is wrong.
        reason: &'static str,
        /// The certified bound reached (mm), or the parameter of a missing C0 break, or NaN.
        bound: f64,
    },
    /// [`crate::discretize_all`] did not walk this curve because the tolerance cannot be
    /// certified on another curve of the batch (known before any walk). Fix: raise the
    /// tolerance for the curve `index`, or discretize it apart.
    #[error("not discretized: the tolerance cannot be certified on curve {index} of the batch, so no curve was walked")]
    NotWalked {
        /// The first curve of the batch whose tolerance is below its rounding margin.
        index: usize,
    },
}

/// `Result` with [`DiscretizeError`].
pub type Result<T> = std::result::Result<T, DiscretizeError>;
