//! Guards of the command line: value parsers that turn an option out of range into a usage
//! error (exit 2, from clap, naming the option, the value and the range), and the refusal to
//! write an output over an input.
//!
//! The ranges, in one place: those of the options a job or the motion stage takes are
//! `kerf_pipeline::ranges` (which `JobOptions::validate` and `MotionOptions::validate` apply to
//! library callers too); the others are the command line's own, below. Every numeric option
//! has a finite upper end: a value above it is never a real job, and used to be accepted and
//! then misbehave quietly (issue 35: `--clearance 2e4` left every traverse unchecked).
//!
//! | kind | range | options |
//! |---|---|---|
//! | tolerance | `0 < x <= 10` mm | `--tolerance`, `--on-surface-tolerance`, `--linearization-tolerance`, `--fit-tolerance`, `--chord-tolerance` |
//! | blending | `0 < x <= 10` mm | `--blend-tolerance` |
//! | segment | `0 < x <= 1e4` mm | `--max-segment-length`, `--min-segment-length` |
//! | retract | `0 <= x <= 1000` mm | `--retract` |
//! | clearance | `0 <= x <= 1000` mm (0: unchecked traverses) | `--clearance` |
//! | lead | `0 <= x <= 1000` mm, each of the pair | `--lead-in LINE,RADIUS`, `--lead-out OVERCUT,EXIT` |
//! | wall | `0 <= x <= 100` mm | `--max-wall` |
//! | feed | `0 < x <= 1e6` mm/min | `--feed` |
//! | cycle | `1e-5 <= x <= 0.1` s | `--cycle` (10 microseconds to 100 milliseconds: every real interpolator; `1e9` would collapse the path into one step) |
//! | fraction | `0 < x < 1` | `--band` |
//! | angle | `0 < x <= 180` degrees | `--max-turn`, `--crease-angle`, `--max-rotary-step` |
//! | normal step | `0 < x < 180` degrees | `--max-normal-step` (the normals stage needs a step below a half turn) |
//! | small angle | `0 < x <= 0.1` rad | `--pole-tolerance` |
//! | tilt | `0 <= x <= 10` degrees (`kerf_kinematics::MAX_TILT_TOLERANCE_DEG`; 0: the exact normal) | `--tilt-tolerance` |
//! | STEP gaps | `0 <= x <= 10` mm | `--close-gaps` (0: close none) |
//! | STEP faces | `0 < x <= 10` mm | `--face-tolerance` |
//! | samples | `2 <= n <= 10,000` (`kerf_check::MAX_SAMPLES`) | `kerf check --samples` (the work is samples x spans x segments: 1,000,000 took 47 s on a 700-segment toolpath) |
//! | points | `2 <= n <= 1e9` | `--max-points`, `--max-total-points` |
//! | placement | each value finite, `abs <= 1e7` | `--place X,Y,Z[,RX,RY,RZ]` (`kerf_kinematics::Placement::parse`) |

use std::path::Path;

use kerf_pipeline::ranges::{self, OptionRange};

use crate::error::CliError;

/// `s` as a number within `range` (NaN and infinities never are); `-0` reads as 0.
fn within(s: &str, range: OptionRange) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if range.contains(v) {
        Ok(v + 0.0)
    } else {
        Err(range.refusal(v))
    }
}

/// A range of the command line's own, with no note.
const fn own(
    min: f64,
    min_included: bool,
    max: f64,
    max_included: bool,
    unit: &'static str,
) -> OptionRange {
    OptionRange {
        min,
        min_included,
        max,
        max_included,
        unit,
        why: "",
    }
}

/// `--clearance`: the job's range, and 0 for unchecked traverses.
pub(crate) const CLEARANCE_MM: OptionRange = OptionRange {
    min_included: true,
    ..ranges::CLEARANCE_MM
};
/// `--band`.
const FRACTION: OptionRange = own(0.0, false, 1.0, false, "");
/// `--max-turn`, `--crease-angle`, `--max-rotary-step`.
const ANGLE_DEG: OptionRange = own(0.0, false, 180.0, true, "degrees");
/// `--max-normal-step`: the normals stage needs a step below a half turn.
const NORMAL_STEP_DEG: OptionRange = own(0.0, false, 180.0, false, "degrees");
/// `--tilt-tolerance`: 0 is the exact normal; the upper end is the kinematics' own.
const TILT_DEG: OptionRange = own(
    0.0,
    true,
    kerf_kinematics::MAX_TILT_TOLERANCE_DEG,
    true,
    "degrees",
);
/// `--pole-tolerance`: a tolerance, not a tilt (5 degrees is 0.087 rad).
const POLE_DEG: OptionRange = own(0.0, false, 5.0, true, "degrees");
/// `--close-gaps` of a STEP import: a gap of more than 10 mm between two segments is no
/// modelling slack but an opening.
pub(crate) const CLOSE_GAPS_MM: OptionRange = own(0.0, true, 10.0, true, "mm");
/// `--face-tolerance` of a STEP import.
pub(crate) const FACE_TOLERANCE_MM: OptionRange = own(0.0, false, 10.0, true, "mm");

/// A tolerance in mm ([`ranges::TOLERANCE_MM`]).
pub(crate) fn tolerance_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::TOLERANCE_MM)
}

/// The controller's blending tolerance in mm ([`ranges::BLEND_TOLERANCE_MM`]).
pub(crate) fn blend_tolerance_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::BLEND_TOLERANCE_MM)
}

/// A segment length in mm ([`ranges::SEGMENT_LENGTH_MM`]).
pub(crate) fn segment_length_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::SEGMENT_LENGTH_MM)
}

/// The retract in mm ([`ranges::RETRACT_MM`]).
pub(crate) fn retract_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::RETRACT_MM)
}

/// The traverses' clearance in mm ([`CLEARANCE_MM`]).
pub(crate) fn clearance_mm(s: &str) -> Result<f64, String> {
    within(s, CLEARANCE_MM)
}

/// `--cut-clearance`: `off` (the head is not checked) or a clearance in mm within the job's
/// range ([`ranges::CLEARANCE_MM`], above 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CutClearance(pub(crate) Option<f64>);

/// Parses `--cut-clearance`: `off`, or mm within [`ranges::CLEARANCE_MM`].
pub(crate) fn cut_clearance(s: &str) -> Result<CutClearance, String> {
    if s.trim().eq_ignore_ascii_case("off") {
        Ok(CutClearance(None))
    } else {
        within(s, ranges::CLEARANCE_MM).map(|v| CutClearance(Some(v)))
    }
}

/// The widest wall cut along itself, mm ([`ranges::WALL_MM`]).
pub(crate) fn wall_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::WALL_MM)
}

/// A sheet thickness in mm: finite, above 0 and at most 100 (the technology entries' range).
pub(crate) fn positive_mm(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("expected a number of mm, got {s:?}"))?;
    if v.is_finite() && v > 0.0 && v <= 100.0 {
        Ok(v)
    } else {
        Err(format!("must lie in (0, 100] mm (got {s})"))
    }
}

/// A kerf width in [`ranges::KERF_WIDTH_MM`].
pub(crate) fn kerf_width_mm(s: &str) -> Result<f64, String> {
    within(s, ranges::KERF_WIDTH_MM)
}

/// `A,B`: two lengths of a lead in mm, each in [`ranges::LEAD_MM`], named `names`.
fn lead_pair(text: &str, names: [&str; 2]) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts.as_slice() else {
        return Err(format!(
            "expected two values {},{} in mm, got {text:?}",
            names[0], names[1]
        ));
    };
    let one = |name: &str, v: &str| within(v, ranges::LEAD_MM).map_err(|e| format!("{name}: {e}"));
    Ok((one(names[0], a)?, one(names[1], b)?))
}

/// `--lead-in LINE,RADIUS`.
pub(crate) fn lead_in(text: &str) -> Result<(f64, f64), String> {
    lead_pair(text, ["LINE", "RADIUS"])
}

/// `--lead-out OVERCUT,EXIT`.
pub(crate) fn lead_out(text: &str) -> Result<(f64, f64), String> {
    lead_pair(text, ["OVERCUT", "EXIT"])
}

/// `--micro-joints LENGTH,SPACING` ([`ranges::MICRO_JOINT_MM`],
/// [`ranges::MICRO_JOINT_SPACING_MM`], the length below the spacing).
pub(crate) fn micro_joints(text: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [a, b] = parts.as_slice() else {
        return Err(format!(
            "expected two values LENGTH,SPACING in mm, got {text:?}"
        ));
    };
    let length = within(a, ranges::MICRO_JOINT_MM).map_err(|e| format!("LENGTH: {e}"))?;
    let spacing = within(b, ranges::MICRO_JOINT_SPACING_MM).map_err(|e| format!("SPACING: {e}"))?;
    if length >= spacing {
        return Err(format!(
            "LENGTH ({length} mm) must be less than SPACING ({spacing} mm)"
        ));
    }
    Ok((length, spacing))
}

/// A fraction strictly between 0 and 1.
pub(crate) fn fraction(s: &str) -> Result<f64, String> {
    within(s, FRACTION)
}

/// An angle in degrees: 0 < x <= 180.
pub(crate) fn angle_deg(s: &str) -> Result<f64, String> {
    within(s, ANGLE_DEG)
}

/// The tilt tolerance, degrees ([`TILT_DEG`]).
pub(crate) fn tilt_deg(s: &str) -> Result<f64, String> {
    within(s, TILT_DEG)
}

/// The largest angle between neighbouring normals, degrees: 0 < x < 180.
pub(crate) fn normal_step_deg(s: &str) -> Result<f64, String> {
    within(s, NORMAL_STEP_DEG)
}

/// A small angle in degrees: 0 < x <= 5.
pub(crate) fn small_angle_deg(s: &str) -> Result<f64, String> {
    within(s, POLE_DEG)
}

/// A feed in mm/min ([`ranges::FEED_MM_PER_MIN`]).
pub(crate) fn feed_mm_per_min(s: &str) -> Result<f64, String> {
    within(s, ranges::FEED_MM_PER_MIN)
}

/// An interpolation cycle in seconds ([`ranges::CYCLE_S`]).
pub(crate) fn cycle_s(s: &str) -> Result<f64, String> {
    within(s, ranges::CYCLE_S)
}

/// `--close-gaps` of a STEP import, mm ([`CLOSE_GAPS_MM`]).
pub(crate) fn close_gaps_mm(s: &str) -> Result<f64, String> {
    within(s, CLOSE_GAPS_MM)
}

/// `--face-tolerance` of a STEP import, mm ([`FACE_TOLERANCE_MM`]).
pub(crate) fn face_tolerance_mm(s: &str) -> Result<f64, String> {
    within(s, FACE_TOLERANCE_MM)
}

/// A sample count for `kerf check`: 2 to [`kerf_check::MAX_SAMPLES`].
pub(crate) fn samples(s: &str) -> Result<usize, String> {
    let v: usize = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a whole number"))?;
    let max = kerf_check::MAX_SAMPLES;
    if !(2..=max).contains(&v) {
        return Err(format!(
            "must be between 2 and {max} (got {v}; the work grows with samples x spans x segments, and the refinement of the local maxima needs no more)"
        ));
    }
    Ok(v)
}

/// Refuses to write `output` (named by the option `option`) if it is the same file as one of
/// `inputs` (same device and inode: through links, `./` and `..` too): the input would be
/// destroyed before, or while, it is read. A usage error (exit 2).
pub(crate) fn refuse_overwrite(
    option: &str,
    output: &Path,
    inputs: &[&Path],
) -> Result<(), CliError> {
    for input in inputs {
        if kerf_io::same_file(output, input) {
            return Err(CliError::Usage(format!(
                "{option} {} is the input file {}; writing it would destroy the input \
                 (choose another output)",
                output.display(),
                input.display()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsers_accept_their_range_and_refuse_the_rest() {
        assert_eq!(tolerance_mm("0.01"), Ok(0.01), "tolerance");
        for bad in ["0", "-1", "nan", "inf", "1e400", "x", "", "10.5", "1e300"] {
            assert!(tolerance_mm(bad).is_err(), "tolerance {bad:?}");
        }
        assert_eq!(retract_mm("0"), Ok(0.0), "zero retract");
        assert_eq!(retract_mm("-0"), Ok(0.0), "-0 reads as 0");
        assert!(retract_mm("-0.1").is_err(), "negative retract");
        assert!(
            fraction("1").is_err() && fraction("0").is_err(),
            "open interval"
        );
        assert_eq!(fraction("0.9"), Ok(0.9), "band");
        assert_eq!(angle_deg("180"), Ok(180.0), "half turn");
        assert!(
            angle_deg("181").is_err() && angle_deg("0").is_err(),
            "angle range"
        );
        assert!(
            normal_step_deg("180").is_err(),
            "the normal step is below a half turn"
        );
        assert_eq!(normal_step_deg("179.9"), Ok(179.9), "normal step");
        assert!(small_angle_deg("6").is_err(), "pole tolerance");
        assert_eq!(cycle_s("0.001"), Ok(0.001), "1 ms");
        assert_eq!(cycle_s("1e-5"), Ok(1e-5), "lower end");
        let e = cycle_s("1e9").expect_err("a cycle of 30 years");
        assert!(e.contains("between 1e-5 s and 0.1 s"), "{e}");
        assert!(
            feed_mm_per_min("0").is_err() && feed_mm_per_min("1e7").is_err(),
            "feed"
        );
        // Issue 35: every length has an upper end, stated with the value.
        assert_eq!(clearance_mm("0"), Ok(0.0), "0: unchecked traverses");
        assert_eq!(clearance_mm("1000"), Ok(1000.0), "the largest clearance");
        assert_eq!(
            clearance_mm("2e4"),
            Err("must be between 0 mm and 1000 mm (got 2e4)".to_owned()),
            "clearance"
        );
        assert!(retract_mm("1e5").is_err(), "retract");
        assert!(wall_mm("100").is_ok() && wall_mm("1000").is_err(), "wall");
        assert!(
            segment_length_mm("1e4").is_ok() && segment_length_mm("1e300").is_err(),
            "segment"
        );
        assert!(
            blend_tolerance_mm("0.001").is_ok()
                && blend_tolerance_mm("0").is_err()
                && blend_tolerance_mm("-1").is_err()
                && blend_tolerance_mm("nan").is_err()
                && blend_tolerance_mm("1e300").is_err(),
            "blend"
        );
        assert_eq!(lead_in("2,1"), Ok((2.0, 1.0)), "lead-in");
        assert_eq!(
            lead_out("0.5,2000"),
            Err("EXIT: must be between 0 mm and 1000 mm (got 2000)".to_owned()),
            "lead-out"
        );
        assert!(
            lead_in("2").is_err() && lead_in("2,-1").is_err(),
            "lead shape"
        );
        assert_eq!(close_gaps_mm("0"), Ok(0.0), "close no gap");
        for bad in ["-1", "nan", "inf", "11"] {
            assert!(close_gaps_mm(bad).is_err(), "close gaps {bad}");
            assert!(face_tolerance_mm(bad).is_err(), "face tolerance {bad}");
        }
        assert!(face_tolerance_mm("0").is_err(), "a face tolerance is > 0");
        assert_eq!(samples("64"), Ok(64), "samples");
        // The review's --samples 1000000 took 47 s on a 700-segment toolpath.
        assert_eq!(samples("10000"), Ok(10_000), "the largest");
        let e = samples("1000000").expect_err("above MAX_SAMPLES");
        assert!(e.contains("between 2 and 10000"), "{e}");
        assert!(
            samples("1").is_err() && samples("-3").is_err(),
            "samples range"
        );
    }

    #[test]
    fn an_output_over_an_input_is_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let input = dir.path().join("part.json");
        std::fs::write(&input, "{}").expect("write");
        let other = dir.path().join("sub").join("..").join("part.json");
        std::fs::create_dir(dir.path().join("sub")).expect("mkdir");
        let e =
            refuse_overwrite("-o", &other, &[Path::new("m.json"), &input]).expect_err("same file");
        assert!(matches!(e, CliError::Usage(_)), "usage error");
        assert!(e.to_string().contains("would destroy the input"), "{e}");
        refuse_overwrite("-o", &dir.path().join("new.json"), &[&input]).expect("new file");
        refuse_overwrite("-o", Path::new("-"), &[&input]).expect("stdout");
    }
}
