//! The non-linearity error of five-axis motion (paper 002) and the poses inserted against it.
//!
//! Between two points the controller interpolates the *axes* linearly. The tool tip then
//! follows `forward(lerp(q_a, q_b, s))`, not the straight segment from `P_a` to `P_b` that the
//! toolpath means: with a 200 mm pivot, 5 degrees of tilt over one segment bulge the tip
//! `200 (1 - cos 2.5 deg) = 0.190 mm` off the line. [`linearization_error`] measures the
//! largest distance of the tip from the segment; [`crate::solve_path`] inserts poses
//! ([`interpolate`]) until it is at most `linearization_tolerance_mm` on every segment.
//!
//! The measure is an estimate (dense sampling refined by golden-section search), not a
//! certified bound: a bulge narrower than the sample spacing could be missed. The sampling is
//! scaled with the rotary move so that it resolves the smooth, single-humped deviation of the
//! short segments that remain after insertion.
//!
//! **Error budget.** The tip's distance from the true curve is at most the chord error of the
//! discretizer (`tolerance` of `kerf.toolpath/1`, certified) plus the linearization error
//! (estimated, `<= linearization_tolerance_mm`): a user asking for 0.01 mm of chord error and the
//! default 0.005 mm of linearization tolerance should expect up to 0.015 mm. The interpolator's
//! own chord error, if any, adds to that.

use kerf_nurbs::distance_to_segment;
use nalgebra::Vector3;

use crate::kinematics::Kinematics;
use crate::pose::{Axes, Pose};
use crate::rotation::angle_between;

/// The largest deviation of the tool tip from the straight segment during a linear axis move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviation {
    /// The largest distance (mm) of the tip from the segment between the two tip points.
    pub distance: f64,
    /// Where along the move it occurs, as the fraction `s` in `[0, 1]` of the axis
    /// interpolation.
    pub at: f64,
}

/// The number of samples for a move: 16, plus one per degree of rotary step, at most 512.
fn samples_for(step: f64) -> usize {
    if step.is_finite() {
        (16.0 + step.ceil()).min(512.0) as usize
    } else {
        512
    }
}

/// The non-linearity error of the linear axis move from `a` to `b`: the largest distance of
/// `forward(lerp(a, b, s)).position` from the segment between `forward(a).position` and
/// `forward(b).position`, over `s` in `[0, 1]`.
///
/// Sampled at `16 + ceil(rotary step in degrees)` (at most 512) evenly spaced `s`, then
/// refined by golden-section search around the largest sample. An estimate (see the module
/// documentation).
pub fn linearization_error(kinematics: &dyn Kinematics, a: &Axes, b: &Axes) -> Deviation {
    let pa = kinematics.forward(a).position;
    let pb = kinematics.forward(b).position;
    let dist = |s: f64| distance_to_segment(&kinematics.forward(&a.lerp(b, s)).position, &pa, &pb);
    let n = samples_for(a.rotary_step(b));
    let (mut best, mut best_s) = (0.0, 0.0);
    let mut best_i = 0;
    for i in 1..n {
        let s = i as f64 / n as f64;
        let d = dist(s);
        if d > best {
            (best, best_s, best_i) = (d, s, i);
        }
    }
    if best_i == 0 {
        // No sample moved off the line (a pure translation, or nothing moves).
        return Deviation {
            distance: 0.0,
            at: 0.0,
        };
    }
    // Golden-section search for the maximum on the bracket around the best sample.
    let (mut lo, mut hi) = (
        (best_i - 1) as f64 / n as f64,
        (best_i + 1) as f64 / n as f64,
    );
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    let mut x1 = hi - INV_PHI * (hi - lo);
    let mut x2 = lo + INV_PHI * (hi - lo);
    let (mut f1, mut f2) = (dist(x1), dist(x2));
    for _ in 0..40 {
        if f1 > f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - INV_PHI * (hi - lo);
            f1 = dist(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + INV_PHI * (hi - lo);
            f2 = dist(x2);
        }
        if hi - lo < 1e-10 {
            break;
        }
    }
    for (d, s) in [(f1, x1), (f2, x2)] {
        if d > best {
            (best, best_s) = (d, s);
        }
    }
    Deviation {
        distance: best,
        at: best_s,
    }
}

/// Great-circle (spherical linear) interpolation of the unit vectors `a` and `b`, `s` in
/// `[0, 1]`; the result is unit. For antipodal vectors the great circle is not unique: kerf
/// turns about the axis most nearly perpendicular to both, deterministically.
pub fn slerp(a: &Vector3<f64>, b: &Vector3<f64>, s: f64) -> Vector3<f64> {
    let omega = angle_between(a, b);
    if omega < 1e-12 {
        let v = a + s * (b - a);
        return v.try_normalize(0.0).unwrap_or(*a);
    }
    // The unit vector perpendicular to a in the plane of a and b, toward b.
    let perp = (b - a * a.dot(b))
        .try_normalize(1e-300)
        .filter(|_| omega < std::f64::consts::PI - 1e-9)
        .unwrap_or_else(|| {
            // Antipodal: any perpendicular; take the one from the smallest component.
            let i = a.iamin();
            let mut e = Vector3::zeros();
            e[i] = 1.0;
            (e - a * a[i]).normalize()
        });
    let (sin, cos) = (s * omega).sin_cos();
    (a * cos + perp * sin).normalize()
}

/// The pose a fraction `s` of the way from `a` to `b`: position on the straight segment,
/// tool axis by [`slerp`]. ([`crate::solve_path`] puts the position on the curve instead when
/// it has one.)
pub fn interpolate(a: &Pose, b: &Pose, s: f64) -> Pose {
    Pose {
        position: a.position + s * (b.position - a.position),
        axis: slerp(&a.axis, &b.axis, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slerp_is_on_the_great_circle_at_constant_speed() {
        let a = Vector3::new(1.0, 0.0, 0.0);
        let b = Vector3::new(0.0, 1.0, 0.0);
        let m = slerp(&a, &b, 1.0 / 3.0);
        let (s, c) = 30f64.to_radians().sin_cos();
        assert!((m - Vector3::new(c, s, 0.0)).norm() < 1e-15, "{m}");
        assert!((slerp(&a, &b, 0.0) - a).norm() < 1e-15, "start");
        assert!((slerp(&a, &b, 1.0) - b).norm() < 1e-15, "end");
        let anti = slerp(&a, &(-a), 0.5);
        assert!((anti.norm() - 1.0).abs() < 1e-15, "antipodal stays unit");
        assert!(
            anti.dot(&a).abs() < 1e-15,
            "antipodal midpoint is perpendicular"
        );
    }
}
