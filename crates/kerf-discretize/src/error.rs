//! The error type of the discretizer.

use thiserror::Error;

/// What can go wrong when discretizing a curve.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum DiscretizeError {
    /// An option is out of range (NaN, infinite where a finite value is needed, negative, or
    /// inconsistent with another option). Fix: see the option's documentation in
    /// [`crate::Options`].
    #[error("option {name}: {reason} (got {value})")]
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
    #[error("curve is discontinuous at t = {t} (gap {gap} mm); split it into two curves there")]
    Discontinuous {
        /// Parameter of the jump.
        t: f64,
        /// Distance between the left and right limits.
        gap: f64,
    },
    /// No step, however short, met the tolerance at `t`: the tolerance is below what double
    /// precision can resolve at the curve's coordinates. Fix: raise the tolerance or move the
    /// part closer to the origin.
    #[error("tolerance {tolerance} cannot be met at t = {t}: below the floating-point resolution of the curve's coordinates")]
    ToleranceBelowPrecision {
        /// Parameter where the walk got stuck.
        t: f64,
        /// The tolerance.
        tolerance: f64,
    },
    /// The discretization would exceed [`crate::Options::max_points`]. Fix: raise the
    /// tolerance, or raise the limit if the count is really wanted.
    #[error("more than {limit} cutting points would be needed (estimated {estimate:.0}); raise the tolerance or max_points")]
    TooManyPoints {
        /// The limit.
        limit: usize,
        /// The estimated count.
        estimate: f64,
    },
}

/// `Result` with [`DiscretizeError`].
pub type Result<T> = std::result::Result<T, DiscretizeError>;
