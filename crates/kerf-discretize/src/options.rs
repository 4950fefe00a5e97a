//! Discretizer options.

use crate::error::{DiscretizeError, Result};

/// How cutting points are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Strategy {
    /// The reference-sphere method of paper 004, with a certified chord error (the default).
    #[default]
    ReferenceSphere,
    /// Classic: the same number of equal parameter steps on every C0 piece, the smallest
    /// count whose segments all certify.
    EqualParameter,
    /// Classic: equal arc-length steps on every C0 piece, the smallest count whose segments
    /// all certify.
    EqualChordLength,
    /// Classic "equal error": from each point, the longest parameter step whose certified
    /// chord error is within the band, found by bisection on the parameter (no curvature
    /// start, no sphere).
    EqualError,
}

/// Options of the discretizer. Lengths in the units of the curve (mm), angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// The chord tolerance `E_max`: every segment's chord error is at most this. Must be > 0.
    pub tolerance: f64,
    /// The lower edge of the band as a fraction of the tolerance: `E_min = band * tolerance`.
    /// A step whose estimated chord error lies in `[E_min, E_max]` is accepted at once; a
    /// shorter one is lengthened. In `(0, 1)`; default 0.97 (measured: see
    /// `docs/discretization.md`).
    pub band: f64,
    /// The longest chord allowed (machines limit block length). `f64::INFINITY` for none.
    pub max_segment_length: f64,
    /// The sphere radius is never proposed below this length; the tolerance still wins where
    /// it needs shorter segments, and the last segment before a C0 break or the end may be
    /// shorter. Default 0.
    pub min_segment_length: f64,
    /// The largest turn of the tangent between the two ends of a segment, in radians.
    /// `f64::INFINITY` (the default) for none.
    pub max_turn: f64,
    /// Which method to use.
    pub strategy: Strategy,
    /// Refuse curves that would need more points than this (protects against a tolerance
    /// typed in the wrong unit). Default 50,000,000.
    pub max_points: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            tolerance: 0.01,
            band: 0.97,
            max_segment_length: f64::INFINITY,
            min_segment_length: 0.0,
            max_turn: f64::INFINITY,
            strategy: Strategy::ReferenceSphere,
            max_points: 50_000_000,
        }
    }
}

impl Options {
    /// Default options with the given tolerance.
    pub fn with_tolerance(tolerance: f64) -> Self {
        Self {
            tolerance,
            ..Self::default()
        }
    }

    /// Checks every option.
    ///
    /// # Errors
    /// [`DiscretizeError::BadOption`] naming the first bad option.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(DiscretizeError::BadOption {
                name,
                value,
                reason,
            })
        };
        if !(self.tolerance.is_finite() && self.tolerance > 0.0) {
            return bad("tolerance", self.tolerance, "must be finite and > 0");
        }
        if !(self.band > 0.0 && self.band < 1.0) {
            return bad("band", self.band, "must lie strictly between 0 and 1");
        }
        if self.max_segment_length.is_nan() || self.max_segment_length <= 0.0 {
            return bad("max_segment_length", self.max_segment_length, "must be > 0");
        }
        if !(self.min_segment_length.is_finite() && self.min_segment_length >= 0.0) {
            return bad(
                "min_segment_length",
                self.min_segment_length,
                "must be finite and >= 0",
            );
        }
        if self.min_segment_length > self.max_segment_length {
            return bad(
                "min_segment_length",
                self.min_segment_length,
                "must not exceed max_segment_length",
            );
        }
        if self.max_turn.is_nan() || self.max_turn <= 0.0 {
            return bad("max_turn", self.max_turn, "must be > 0 (radians)");
        }
        Ok(())
    }
}
