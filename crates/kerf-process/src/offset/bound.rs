//! The offset's own chord term on a flat contour, proven from the tangent's cone
//! (docs/process.md, "Kerf compensation", "The certificate").
//!
//! On a segment `[t0, t1]` of a plane curve `C` with chord `C0 C1` (direction `u`), if every
//! tangent of the segment lies within the angle `alpha < 90 deg` of `u` and the curvature stays
//! below `1 / r`, every point of the offset `Q = C + r d` (with `d` the unit normal of the curve
//! in the plane, toward one side) lies within `e + r (1 - cos alpha)` of the chord `Q0 Q1`,
//! where `e` bounds the distance from `C` to its chord `C0 C1`. `alpha` comes from the rational
//! derivative's numerator `N = A' w - A w'` (`C' = N / w^2`, `w^2 > 0`), a polynomial whose
//! Bezier coefficients, of degree `2p - 1`, are computed exactly from each piece's homogeneous
//! control points: every `C'(t)` is a non-negative combination of them, and a cone of
//! half-angle below 90 degrees is convex, so the largest angle between a coefficient and `u`
//! bounds every tangent's. (The discretizer's turn bound works from the control polygon's
//! edges; the offset needs the numerator's coefficients for the curvature bound as well.)

use kerf_nurbs::{binomial, NurbsCurve};
use nalgebra::{Vector3, Vector4};

/// What the numerator's coefficients prove about the tangents of a segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cone {
    /// The largest angle (radians) between `u` and any tangent of the segment.
    pub(crate) alpha: f64,
    /// An upper bound of the curvature (1/mm) anywhere on the segment.
    pub(crate) kappa_max: f64,
    /// `+1` where the curve is proven to turn left about the axis everywhere on the segment
    /// (`(C' x C'') . a > 0`), `-1` where it turns right everywhere, `0` where unproven.
    pub(crate) turn: f64,
}

/// The cone of the tangents of `curve` on `[t0, t1]` about `u` (unit), with a bound of the
/// curvature, both proven; `None` when some tangent may point 90 degrees or more away from
/// `u` (the segment must then be split).
///
/// The curvature is `k = |N x N_s| w^2 / |N|^3` (the derivatives taken in a piece's own
/// parameter `s`, `C_s = N / w^2`, `C_ss = (N_s w - 2 N w_s) / w^3`), so
/// `k <= |N_s| w^2 / |N|^2 <= max|N_s| max(w)^2 / min(N . u)^2`: every `N(s)` is a convex
/// combination of the coefficients, `N . u >= min_k N_k . u`, and `N_s` is `2p - 1` times a
/// combination of the coefficients' differences.
///
/// The sign of the turn comes from `(N x N_s) . a` (`C_s x C_ss = N x N_s / w^4`), a polynomial
/// of degree `4p - 3` whose Bezier coefficients are products of `N`'s and `N_s`'s.
pub(crate) fn tangent_cone(
    curve: &NurbsCurve,
    t0: f64,
    t1: f64,
    u: &Vector3<f64>,
    axis: &Vector3<f64>,
) -> Option<Cone> {
    let mut max_angle = 0.0_f64;
    let mut kappa = 0.0_f64;
    let mut ok = true;
    let mut turn: Option<f64> = None;
    curve.for_each_bezier_piece(t0, t1, |b| {
        if !ok {
            return;
        }
        let coeffs = numerator(b.homogeneous());
        let mut n_min = f64::INFINITY;
        for (n, err) in &coeffs {
            let len = n.norm();
            let c = n.dot(u);
            // The coefficient's rounding `err` turns it by at most `err / (len - err)`.
            if !exceeds(len, 2.0 * err) || !exceeds(c, *err) {
                ok = false;
                return;
            }
            let angle = (c / len).clamp(-1.0, 1.0).acos() + 2.0 * err / len + 1e-15;
            max_angle = max_angle.max(angle);
            n_min = n_min.min(c - err);
        }
        let m = coeffs.len().saturating_sub(1) as f64;
        let d_max = coeffs
            .windows(2)
            .map(|w| m * ((w[1].0 - w[0].0).norm() + w[0].1 + w[1].1))
            .fold(0.0, f64::max);
        let w_max = b.homogeneous().iter().map(|c| c.w).fold(0.0, f64::max);
        let k = d_max * w_max * w_max / (n_min * n_min) * (1.0 + 1e-12);
        kappa = kappa.max(if k.is_finite() { k } else { f64::INFINITY });
        let t = turn_sign(&coeffs, axis);
        turn = Some(match turn {
            None => t,
            Some(prev) if prev == t => t,
            Some(_) => 0.0,
        });
    });
    (ok && max_angle.is_finite()).then_some(Cone {
        alpha: max_angle,
        kappa_max: kappa,
        turn: turn.unwrap_or(0.0),
    })
}

/// `+1` if every Bezier coefficient of `(N x N_s) . a` is positive beyond its rounding, `-1`
/// if every one is negative, else `0`.
fn turn_sign(n: &[(Vector3<f64>, f64)], axis: &Vector3<f64>) -> f64 {
    let m = n.len().saturating_sub(1);
    if m == 0 {
        return 0.0;
    }
    // N_s = m sum_j B_j^{m-1} (N_{j+1} - N_j).
    let ns: Vec<(Vector3<f64>, f64)> = n
        .windows(2)
        .map(|w| ((w[1].0 - w[0].0) * m as f64, m as f64 * (w[0].1 + w[1].1)))
        .collect();
    let deg = 2 * m - 1;
    let mut sign = 0.0;
    for k in 0..=deg {
        let denom = binomial(deg, k);
        let mut v = 0.0;
        let mut size = 0.0;
        for i in k.saturating_sub(m - 1)..=k.min(m) {
            let j = k - i;
            let c = binomial(m, i) * binomial(m - 1, j) / denom;
            v += c * n[i].0.cross(&ns[j].0).dot(axis);
            size += c
                * ((n[i].0.norm() + n[i].1) * (ns[j].0.norm() + ns[j].1)
                    - n[i].0.norm() * ns[j].0.norm());
            size += c * 8.0 * f64::EPSILON * n[i].0.norm() * ns[j].0.norm();
        }
        let s = if v > size {
            1.0
        } else if v < -size {
            -1.0
        } else {
            return 0.0;
        };
        if sign != 0.0 && s != sign {
            return 0.0;
        }
        sign = s;
    }
    sign
}

/// The Bezier coefficients (degree `2p - 1`) of `N = A' w - A w'` for one rational Bezier
/// piece in homogeneous form (`A` the first three coordinates, `w` the fourth), each with a
/// bound of its rounding error. `N` does not change when the curve is translated
/// (`A -> A - w o` leaves `A' w - A w'` as it is), so the piece is first moved to its first
/// control point: the products then have the size of the piece, not of its coordinates.
pub(super) fn numerator(cpw: &[Vector4<f64>]) -> Vec<(Vector3<f64>, f64)> {
    let p = cpw.len() - 1;
    if p == 0 {
        return Vec::new();
    }
    let o = cpw[0].xyz() / cpw[0].w;
    let w = |j: usize| cpw[j].w;
    let a = |j: usize| cpw[j].xyz() - o * cpw[j].w;
    // A' and w' as degree p - 1 Bezier coefficients.
    let da: Vec<Vector3<f64>> = (0..p).map(|j| (a(j + 1) - a(j)) * p as f64).collect();
    let dw: Vec<f64> = (0..p).map(|j| (w(j + 1) - w(j)) * p as f64).collect();
    let m = 2 * p - 1;
    let mut out = vec![(Vector3::zeros(), 0.0); m + 1];
    for (k, (o, err)) in out.iter_mut().enumerate() {
        let denom = binomial(m, k);
        // Product of a degree p - 1 and a degree p Bezier polynomial: sum over i + j = k.
        let mut size = 0.0;
        for i in k.saturating_sub(p)..=k.min(p - 1) {
            let j = k - i;
            let c = binomial(p - 1, i) * binomial(p, j) / denom;
            *o += (da[i] * w(j) - a(j) * dw[i]) * c;
            size += c * (da[i].norm() * w(j).abs() + a(j).norm() * dw[i].abs());
        }
        // Each term is a few roundings of relative size EPSILON, and so are the inputs
        // (the translation, the differences): a generous 16 p of them.
        *err = 16.0 * (p as f64 + 1.0) * f64::EPSILON * size;
    }
    out
}

/// The offset's own term of the bound: `r (1 - cos alpha)`, computed as `2 r sin^2(alpha / 2)`
/// (no cancellation); infinity from 90 degrees on, where it does not hold.
pub(crate) fn offset_term(r: f64, alpha: f64) -> f64 {
    if !exceeds(std::f64::consts::FRAC_PI_2, alpha) {
        return f64::INFINITY;
    }
    2.0 * r * (alpha / 2.0).sin().powi(2) * (1.0 + 4.0 * f64::EPSILON)
}

/// `a > b`, false where either is NaN (so that `!exceeds` refuses NaN).
pub(crate) fn exceeds(a: f64, b: f64) -> bool {
    a > b
}
