//! The documented range of every option of a job ([`crate::JobOptions`]) and of the motion
//! stage ([`crate::MotionOptions`]), in one place: [`crate::JobOptions::validate`] and
//! [`crate::MotionOptions::validate`] refuse a value outside it with [`Error::BadOption`]
//! before any work, and the `kerf` command line checks its options against the same ranges
//! (a usage error, exit 2). A value outside these ranges is never a real job: above them it
//! used to be accepted and then misbehave quietly (a clearance of 2e4 mm left every traverse
//! unchecked, a wall width of metres turns a flat sheet into a "wall").
//!
//! | range | value | options |
//! |---|---|---|
//! | [`TOLERANCE_MM`] | `0 < x <= 10` mm | the chord tolerance, the on-surface, linearization, arc-fit and set-point chord tolerances |
//! | [`BLEND_TOLERANCE_MM`] | `0 < x <= 10` mm | the controller's blending tolerance (the G-code writer needs it > 0) |
//! | [`SEGMENT_LENGTH_MM`] | `0 < x <= 1e4` mm | the longest and shortest segment (the longest may also be infinite: no limit) |
//! | [`FEED_MM_PER_MIN`] | `0 < x <= 1e6` mm/min | the programmed feed (16.7 m/s: above any laser cutting machine) |
//! | [`CYCLE_S`] | `1e-5 <= x <= 0.1` s | the interpolation cycle (10 microseconds to 100 milliseconds: every real interpolator) |
//! | [`RETRACT_MM`] | `0 <= x <= 1000` mm | the retract between contours |
//! | [`CLEARANCE_MM`] | `0 < x <= 1000` mm | the traverses' clearance from the part (the command line's 0 turns the checks off) |
//! | [`LEAD_MM`] | `0 <= x <= 1000` mm | the lead-in's line and radius, the overcut and the exit |
//! | [`WALL_MM`] | `0 <= x <= 100` mm | the widest wall cut along itself (the thickest sheet a laser cuts is tens of mm; a metre would take a sheet's face for a wall) |
//! | [`MICRO_JOINT_MM`] | `0 < x <= 10` mm | a micro-joint's length |
//! | [`MICRO_JOINT_SPACING_MM`] | `1 <= x <= 1e5` mm | the path between micro-joints (more than their length) |
//! | [`KERF_WIDTH_MM`] | `0 < x <= 20` mm | the kerf width (a fibre laser's is 0.1-0.3 mm, a plasma's a few mm) |
//!
//! Angles keep the ranges of their stage's own options (the normal step below 180 degrees,
//! the crease angle in `[0, 180]` degrees, the rotary step and the turn > 0) and the command
//! line's (`0 < x <= 180` degrees, the pole tolerance `0 < x <= 0.1` rad).

use std::fmt;

use crate::error::{Error, Result};

/// The range an option's value must lie in: finite, between `min` and `max`, each end
/// included or not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptionRange {
    /// The lower end.
    pub min: f64,
    /// Whether `min` itself is allowed.
    pub min_included: bool,
    /// The upper end (finite).
    pub max: f64,
    /// Whether `max` itself is allowed.
    pub max_included: bool,
    /// The unit written after each number (`mm`, `s`, `mm/min`, `degrees`, `rad`).
    pub unit: &'static str,
    /// Why the range is what it is, said after the value in a refusal (may be empty).
    pub why: &'static str,
}

impl OptionRange {
    /// Whether `value` lies in the range (NaN and infinities never do).
    pub fn contains(&self, value: f64) -> bool {
        let above = if self.min_included {
            value >= self.min
        } else {
            value > self.min
        };
        let below = if self.max_included {
            value <= self.max
        } else {
            value < self.max
        };
        value.is_finite() && above && below
    }

    /// What a value outside the range is told: `must be > 0 mm and <= 10 mm (got 20)`,
    /// `must be between 1e-5 s and 0.1 s (got 1e9; ...)`.
    pub fn refusal(&self, value: f64) -> String {
        let why = if self.why.is_empty() {
            String::new()
        } else {
            format!("; {}", self.why)
        };
        format!("must be {self} (got {}{why})", number(value))
    }

    /// `value` if it lies in the range, else [`Error::BadOption`] naming the option `name`.
    ///
    /// # Errors
    /// [`Error::BadOption`] for a value outside the range.
    pub fn check(&self, name: &'static str, value: f64) -> Result<f64> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(Error::BadOption {
                name,
                value,
                requirement: self.refusal(value),
            })
        }
    }
}

impl fmt::Display for OptionRange {
    /// `> 0 mm and <= 10 mm`, or `between 1e-5 s and 0.1 s` when both ends are included.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let u = |v: f64| {
            if self.unit.is_empty() {
                number(v)
            } else {
                format!("{} {}", number(v), self.unit)
            }
        };
        if self.min_included && self.max_included {
            write!(f, "between {} and {}", u(self.min), u(self.max))
        } else {
            let lo = if self.min_included { ">=" } else { ">" };
            let hi = if self.max_included { "<=" } else { "<" };
            write!(f, "{lo} {} and {hi} {}", u(self.min), u(self.max))
        }
    }
}

/// A number as a person reads it: `1e4`, `1e-5`, `0.1`, `1000`.
pub fn number(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() >= 1e4 || v.abs() < 1e-3) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

const fn range(
    min: f64,
    min_included: bool,
    max: f64,
    unit: &'static str,
    why: &'static str,
) -> OptionRange {
    OptionRange {
        min,
        min_included,
        max,
        max_included: true,
        unit,
        why,
    }
}

/// Tolerances: the chord tolerance, the on-surface tolerance of the normals, the
/// linearization tolerance of the kinematics, the arc-fit and the set-point chord tolerance.
/// A tolerance of 10 mm is far coarser than any cut; above it a value is a unit mistake.
pub const TOLERANCE_MM: OptionRange = range(0.0, false, 10.0, "mm", "");

/// The controller's blending tolerance, a term of the tolerance budget (> 0: the G-code
/// writer programs it, and LinuxCNC reads `G64 P0` as no tolerance at all).
pub const BLEND_TOLERANCE_MM: OptionRange = range(0.0, false, 10.0, "mm", "");

/// The longest and the shortest segment of the discretizer (10 m: longer than any machine's
/// travel).
pub const SEGMENT_LENGTH_MM: OptionRange = range(0.0, false, 1e4, "mm", "");

/// The programmed feed.
pub const FEED_MM_PER_MIN: OptionRange = range(
    0.0,
    false,
    1e6,
    "mm/min",
    "16.7 m/s, above any laser cutting machine",
);

/// The interpolation cycle (`1e9` would collapse the path into one step).
pub const CYCLE_S: OptionRange = range(
    1e-5,
    true,
    0.1,
    "s",
    "10 microseconds to 100 milliseconds, the range of real interpolators",
);

/// The retract along the tool axis between contours (a metre: above any machine's head
/// travel; 0 = one straight rapid).
pub const RETRACT_MM: OptionRange = range(0.0, true, 1000.0, "mm", "");

/// The clearance the checked traverses keep from the part. Its retract is 1.5 times it, and
/// the traverse checks' own limit for that is 1e4 mm (`kerf_process::TraverseOptions`).
pub const CLEARANCE_MM: OptionRange = range(0.0, false, 1000.0, "mm", "");

/// The lengths of the leads: the lead-in's line and arc radius, the overcut, the exit.
pub const LEAD_MM: OptionRange = range(0.0, true, 1000.0, "mm", "");

/// A micro-joint's length: the beam off over at most 10 mm of the path.
pub const MICRO_JOINT_MM: OptionRange = range(
    0.0,
    false,
    10.0,
    "mm",
    "a micro-joint holds a part by a few tenths of a millimetre of uncut sheet",
);

/// The path between micro-joints.
pub const MICRO_JOINT_SPACING_MM: OptionRange = range(1.0, true, 1e5, "mm", "");

/// The widest wall cut along itself (0: off).
pub const WALL_MM: OptionRange = range(
    0.0,
    true,
    100.0,
    "mm",
    "a wall through the sheet is as wide as the sheet is thick",
);

/// The kerf width the path is offset by (half of it toward the scrap), the same range as the
/// machine file's `process.kerf_width_mm`.
pub const KERF_WIDTH_MM: OptionRange = range(
    0.0,
    false,
    kerf_kinematics::MAX_KERF_WIDTH_MM,
    "mm",
    "a fibre laser's kerf is 0.1-0.3 mm, a plasma's a few mm",
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_say_their_ends_and_refuse_what_lies_outside() {
        assert_eq!(
            TOLERANCE_MM.to_string(),
            "> 0 mm and <= 10 mm",
            "open low end"
        );
        assert_eq!(CYCLE_S.to_string(), "between 1e-5 s and 0.1 s", "closed");
        assert_eq!(
            CLEARANCE_MM.refusal(2e4),
            "must be > 0 mm and <= 1000 mm (got 2e4)",
            "refusal"
        );
        for (r, inside, outside) in [
            (TOLERANCE_MM, [1e-9, 10.0], [0.0, 10.000001]),
            (BLEND_TOLERANCE_MM, [1e-9, 10.0], [0.0, 11.0]),
            (FEED_MM_PER_MIN, [1.0, 1e6], [0.0, 1e6 + 1.0]),
            (CYCLE_S, [1e-5, 0.1], [9e-6, 0.2]),
            (RETRACT_MM, [0.0, 1000.0], [-0.1, 1e5]),
            (CLEARANCE_MM, [1e-6, 1000.0], [0.0, 2e4]),
            (LEAD_MM, [0.0, 1000.0], [-1.0, 1001.0]),
            (WALL_MM, [0.0, 100.0], [-1.0, 1000.0]),
            (KERF_WIDTH_MM, [1e-3, 20.0], [0.0, 20.5]),
            (SEGMENT_LENGTH_MM, [1e-3, 1e4], [0.0, 1e300]),
        ] {
            for v in inside {
                assert!(r.contains(v), "{r}: {v} inside");
            }
            for v in outside.into_iter().chain([f64::NAN, f64::INFINITY]) {
                assert!(!r.contains(v), "{r}: {v} outside");
            }
        }
        let e = FEED_MM_PER_MIN
            .check("feed_mm_per_min", 2e6)
            .expect_err("too fast");
        assert_eq!(
            e.to_string(),
            "option feed_mm_per_min: must be > 0 mm/min and <= 1e6 mm/min (got 2e6; 16.7 m/s, \
             above any laser cutting machine)",
            "message"
        );
    }
}
