//! The chord error of arc interpolation and the feed limit it imposes (paper 000 eq 17-19).
//!
//! Each cycle the tip moves along the chord between two set-points on the arc; with step `dl`
//! on radius `R` the chord's sagitta is `delta = R - sqrt(R^2 - dl^2 / 4)` (eq 17), so
//! `delta <= delta_max` iff `dl <= 2 sqrt(delta_max (2 R - delta_max))` (eq 18), and with
//! `dl = F T`: `F <= 2 sqrt(delta_max (2 R - delta_max)) / T`. For `T = 8 ms` and
//! `delta_max = 1 um` that is `F <= sqrt(225000 (2 R - 0.001))` mm/min with `R` in mm: eq 19,
//! whose printed `2R - 1` mixes micrometres and millimetres.

/// Sagitta of a chord of length `step` on a circle of radius `radius` (eq 17); `radius` for a
/// chord longer than the diameter. Both in mm.
pub fn chord_error(radius: f64, step: f64) -> f64 {
    let h = radius * radius - step * step / 4.0;
    if h <= 0.0 {
        radius
    } else {
        radius - h.sqrt()
    }
}

/// Longest step on radius `radius` whose chord error is at most `delta` (eq 18); the diameter
/// when `delta >= radius`. NaN for NaN input.
pub fn max_step(radius: f64, delta: f64) -> f64 {
    if delta >= radius {
        return 2.0 * radius;
    }
    2.0 * (delta * (2.0 * radius - delta)).sqrt()
}

/// Largest feed (mm/min) on radius `radius` (mm) with chord error at most `delta` (mm) per
/// cycle of `cycle` seconds: `60 max_step / cycle`.
pub fn max_feed(radius: f64, delta: f64, cycle: f64) -> f64 {
    60.0 * max_step(radius, delta) / cycle
}

/// Paper 000 eq 19 with its unit slip corrected: `sqrt(225000 (2 R - 0.001))` mm/min, the
/// feed limit for `T = 8 ms`, `delta = 1 um`, `R` in mm. Equal to
/// `max_feed(radius, 0.001, 0.008)`. Research code (feature `research`).
#[cfg(feature = "research")]
pub fn paper_eq19(radius: f64) -> f64 {
    (225000.0 * (2.0 * radius - 0.001)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn step_and_error_are_inverse() {
        for r in [0.01, 0.5, 3.0, 100.0, 5000.0] {
            for d in [1e-6, 1e-4, 1e-3] {
                let dl = max_step(r, d);
                let e = chord_error(r, dl);
                assert!(
                    (e - d.min(r)).abs() <= 1e-9 * r.max(1.0),
                    "r {r} d {d}: {e}"
                );
            }
        }
        assert_eq!(
            max_step(1.0, 2.0),
            2.0,
            "tolerance above the radius: the diameter"
        );
        assert_eq!(chord_error(1.0, 3.0), 1.0, "chord longer than the diameter");
    }
}
