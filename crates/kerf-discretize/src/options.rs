//! Discretizer options.

use crate::error::{DiscretizeError, Result};

/// How cutting points are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Strategy {
    /// After the reference-sphere method of paper 004, with a certified chord error (the
    /// default): the step predicted from the arc's Taylor cubic, certified, corrected by the
    /// certificate's numbers (`docs/discretization.md`, "The walk").
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
#[non_exhaustive]
pub struct Options {
    /// The chord tolerance `E_max`: every segment's chord error is at most this, mm. Must be > 0;
    /// default 0.01 (start a chain with [`Options::with_tolerance`]).
    pub tolerance_mm: f64,
    /// The lower edge of the band as a fraction of the tolerance: `E_min = band * tolerance`.
    /// A step whose estimated chord error lies in `[E_min, E_max]` is accepted at once; a
    /// shorter one is lengthened. In `(0, 1)`; default 0.97 (measured: see
    /// `docs/discretization.md`).
    pub band: f64,
    /// The longest chord allowed (machines limit block length), mm. `f64::INFINITY` (the
    /// default) for none.
    pub max_segment_length_mm: f64,
    /// The sphere radius is never proposed below this length; the tolerance still wins where
    /// it needs shorter segments, and the last segment before a C0 break or the end may be
    /// shorter, mm. Default 0.
    pub min_segment_length_mm: f64,
    /// The largest turn of the tangent between the two ends of a segment, in degrees.
    /// `f64::INFINITY` (the default) for none.
    pub max_turn_deg: f64,
    /// Which method to use. Default [`Strategy::ReferenceSphere`].
    pub strategy: Strategy,
    /// Refuse curves that would need more points than this (protects against a tolerance
    /// typed in the wrong unit). Default 50,000,000.
    pub max_points: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            tolerance_mm: 0.01,
            band: 0.97,
            max_segment_length_mm: f64::INFINITY,
            min_segment_length_mm: 0.0,
            max_turn_deg: f64::INFINITY,
            strategy: Strategy::ReferenceSphere,
            max_points: 50_000_000,
        }
    }
}

impl Options {
    /// Sets [`band`](Self::band): the lower edge of the band as a fraction of the tolerance.
    pub fn with_band(mut self, band: f64) -> Self {
        self.band = band;
        self
    }

    /// Sets [`max_segment_length_mm`](Self::max_segment_length_mm): the longest chord allowed
    /// (machines limit block length).
    pub fn with_max_segment_length_mm(mut self, max_segment_length_mm: f64) -> Self {
        self.max_segment_length_mm = max_segment_length_mm;
        self
    }

    /// Sets [`min_segment_length_mm`](Self::min_segment_length_mm): the sphere radius is never
    /// proposed below this length.
    pub fn with_min_segment_length_mm(mut self, min_segment_length_mm: f64) -> Self {
        self.min_segment_length_mm = min_segment_length_mm;
        self
    }

    /// Sets [`max_turn_deg`](Self::max_turn_deg): the largest turn of the tangent between the two
    /// ends of a segment, in degrees.
    pub fn with_max_turn_deg(mut self, max_turn_deg: f64) -> Self {
        self.max_turn_deg = max_turn_deg;
        self
    }

    /// Sets [`strategy`](Self::strategy): which method to use.
    pub fn with_strategy(mut self, strategy: Strategy) -> Self {
        self.strategy = strategy;
        self
    }

    /// Sets [`max_points`](Self::max_points): refuse curves that would need more points
    /// than this (protects against a tolerance typed in the wrong unit).
    pub fn with_max_points(mut self, max_points: usize) -> Self {
        self.max_points = max_points;
        self
    }

    /// Default options with the given chord tolerance, mm (a constructor: the setter of an
    /// existing value is [`Options::with_tolerance_mm`]).
    pub fn with_tolerance(tolerance_mm: f64) -> Self {
        Self {
            tolerance_mm,
            ..Self::default()
        }
    }

    /// Sets [`tolerance_mm`](Self::tolerance_mm): the chord tolerance, mm.
    pub fn with_tolerance_mm(mut self, tolerance_mm: f64) -> Self {
        self.tolerance_mm = tolerance_mm;
        self
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
        if !(self.tolerance_mm.is_finite() && self.tolerance_mm > 0.0) {
            return bad("tolerance_mm", self.tolerance_mm, "must be finite and > 0");
        }
        if !(self.band > 0.0 && self.band < 1.0) {
            return bad("band", self.band, "must lie strictly between 0 and 1");
        }
        if self.max_segment_length_mm.is_nan() || self.max_segment_length_mm <= 0.0 {
            return bad(
                "max_segment_length_mm",
                self.max_segment_length_mm,
                "must be > 0",
            );
        }
        if !(self.min_segment_length_mm.is_finite() && self.min_segment_length_mm >= 0.0) {
            return bad(
                "min_segment_length_mm",
                self.min_segment_length_mm,
                "must be finite and >= 0",
            );
        }
        if self.min_segment_length_mm > self.max_segment_length_mm {
            return bad(
                "min_segment_length_mm",
                self.min_segment_length_mm,
                "must not exceed max_segment_length_mm",
            );
        }
        if self.max_turn_deg.is_nan() || self.max_turn_deg <= 0.0 {
            return bad("max_turn_deg", self.max_turn_deg, "must be > 0 (degrees)");
        }
        Ok(())
    }
}
