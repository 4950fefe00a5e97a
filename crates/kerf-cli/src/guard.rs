//! Guards of the command line: value parsers that turn an option out of range into a usage
//! error (exit 2, from clap, naming the option), and the refusal to write an output over an
//! input.
//!
//! The ranges, in one place:
//!
//! | kind | range | options |
//! |---|---|---|
//! | length | finite, > 0 mm | `--tolerance`, `--max-segment-length`, `--min-segment-length`, `--on-surface-tolerance`, `--linearization-tolerance`, `--fit-tolerance`, `--chord-tolerance` |
//! | distance | finite, >= 0 mm | `--retract` |
//! | fraction | 0 < x < 1 | `--band` |
//! | angle | 0 < x <= 180 degrees | `--max-turn`, `--max-normal-step`, `--crease-angle`, `--max-rotary-step` |
//! | small angle | 0 < x <= 0.1 rad | `--pole-tolerance` |
//! | feed | 0 < x <= 1,000,000 mm/min | `--feed` |
//! | cycle | 1e-5 s <= x <= 0.1 s | `--cycle` (10 microseconds to 100 milliseconds: every real interpolator; `1e9` would collapse the path into one step) |
//! | samples | 2 <= n <= 10,000 (`kerf_check::MAX_SAMPLES`) | `kerf check --samples` (the work is samples x spans x segments: 1,000,000 took 47 s on a 700-segment toolpath) |

use std::path::Path;

use crate::error::CliError;

fn number(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if !v.is_finite() {
        return Err(format!("{s} is not a finite number"));
    }
    Ok(v)
}

/// A length in mm: finite and > 0.
pub(crate) fn length_mm(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v <= 0.0 {
        return Err(format!("must be > 0 mm (got {v})"));
    }
    Ok(v)
}

/// A distance in mm: finite and >= 0.
pub(crate) fn distance_mm(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if v < 0.0 {
        return Err(format!("must be >= 0 mm (got {v})"));
    }
    Ok(v + 0.0)
}

/// A fraction strictly between 0 and 1.
pub(crate) fn fraction(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v < 1.0) {
        return Err(format!("must be between 0 and 1, both excluded (got {v})"));
    }
    Ok(v)
}

/// An angle in degrees: 0 < x <= 180.
pub(crate) fn angle_deg(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v <= 180.0) {
        return Err(format!("must be > 0 and <= 180 degrees (got {v})"));
    }
    Ok(v)
}

/// A small angle in radians: 0 < x <= 0.1.
pub(crate) fn small_angle_rad(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v <= 0.1) {
        return Err(format!(
            "must be > 0 and <= 0.1 rad (5.7 degrees) (got {v})"
        ));
    }
    Ok(v)
}

/// The largest programmed feed, mm/min (16.7 m/s: above any laser cutting machine).
pub(crate) const MAX_FEED_MM_PER_MIN: f64 = 1e6;

/// A feed in mm/min: 0 < x <= [`MAX_FEED_MM_PER_MIN`].
pub(crate) fn feed_mm_per_min(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    if !(v > 0.0 && v <= MAX_FEED_MM_PER_MIN) {
        return Err(format!(
            "must be > 0 and <= {MAX_FEED_MM_PER_MIN:e} mm/min (got {v})"
        ));
    }
    Ok(v)
}

/// The shortest and longest interpolation cycle, s.
pub(crate) const CYCLE_RANGE_S: (f64, f64) = (1e-5, 0.1);

/// An interpolation cycle in seconds, within [`CYCLE_RANGE_S`].
pub(crate) fn cycle_s(s: &str) -> Result<f64, String> {
    let v = number(s)?;
    let (lo, hi) = CYCLE_RANGE_S;
    if !(lo..=hi).contains(&v) {
        return Err(format!(
            "must be between {lo:e} s and {hi} s (10 microseconds to 100 milliseconds, the \
             range of real interpolators; got {v} s)"
        ));
    }
    Ok(v)
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
        assert_eq!(length_mm("0.01"), Ok(0.01), "length");
        for bad in ["0", "-1", "nan", "inf", "1e400", "x", ""] {
            assert!(length_mm(bad).is_err(), "length {bad:?}");
        }
        assert_eq!(distance_mm("0"), Ok(0.0), "zero retract");
        assert!(distance_mm("-0.1").is_err(), "negative retract");
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
        assert!(small_angle_rad("0.2").is_err(), "pole tolerance");
        assert_eq!(cycle_s("0.001"), Ok(0.001), "1 ms");
        assert_eq!(cycle_s("1e-5"), Ok(1e-5), "lower end");
        let e = cycle_s("1e9").expect_err("a cycle of 30 years");
        assert!(e.contains("between 1e-5 s and 0.1 s"), "{e}");
        assert!(
            feed_mm_per_min("0").is_err() && feed_mm_per_min("1e7").is_err(),
            "feed"
        );
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
