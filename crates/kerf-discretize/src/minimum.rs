//! The theoretical minimum count of chords, `N* = integral sqrt(k(s) / (8 tol)) ds`.
//!
//! A chord of length `L` on a circle of curvature `k` has sagitta `k L^2 / 8` to leading order,
//! so a chord with sagitta `tol` spans `L = sqrt(8 tol / k)` and the number of chords per unit
//! length is `sqrt(k / (8 tol))`. Integrating along the curve gives the asymptotic minimum
//! (`docs/discretization.md` derives it).

use kerf_nurbs::arclength::{GL10_NODES as GL_X, GL10_WEIGHTS as GL_W};
use kerf_nurbs::curve::curvature_of;
use kerf_nurbs::NurbsCurve;

fn integrand(curve: &NurbsCurve, t: f64) -> f64 {
    let (_, d1, d2) = curve.eval_d2(t);
    curvature_of(&d1, &d2).sqrt() * d1.norm()
}

fn gauss(curve: &NurbsCurve, a: f64, b: f64) -> f64 {
    let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
    let mut s = 0.0;
    for i in 0..5 {
        s += GL_W[i] * (integrand(curve, m - h * GL_X[i]) + integrand(curve, m + h * GL_X[i]));
    }
    s * h
}

fn adaptive(curve: &NurbsCurve, a: f64, b: f64, whole: f64, tol: f64, depth: u32) -> f64 {
    let m = 0.5 * (a + b);
    let (l, r) = (gauss(curve, a, m), gauss(curve, m, b));
    if depth == 0 || (l + r - whole).abs() <= tol {
        return l + r;
    }
    adaptive(curve, a, m, l, 0.5 * tol, depth - 1) + adaptive(curve, m, b, r, 0.5 * tol, depth - 1)
}

/// `integral sqrt(k) ds` over the curve, to a relative accuracy of about 1e-6.
pub fn sqrt_curvature_integral(curve: &NurbsCurve) -> f64 {
    let spans = curve.spans();
    let rough: f64 = spans.iter().map(|&(_, a, b)| gauss(curve, a, b)).sum();
    let tol = 1e-7 * rough.max(1e-300);
    spans
        .iter()
        .map(|&(_, a, b)| {
            let w = gauss(curve, a, b);
            adaptive(curve, a, b, w, tol, 24)
        })
        .sum()
}

/// The asymptotic minimum number of chords `N* = integral sqrt(k / (8 tol)) ds` that keep every
/// chord's sagitta within `tol`.
///
/// ```
/// use kerf_nurbs::NurbsCurve;
/// use nalgebra::Point3;
/// let h = std::f64::consts::FRAC_1_SQRT_2;
/// let quarter = NurbsCurve::new(
///     2,
///     vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
///     vec![Point3::new(10.0, 0.0, 0.0), Point3::new(10.0, 10.0, 0.0), Point3::new(0.0, 10.0, 0.0)],
///     Some(vec![1.0, h, 1.0]),
/// );
/// // Quarter circle of radius 10: N* = (pi/2) * 10 * sqrt(0.1 / (8 * 0.01)).
/// let n = kerf_discretize::minimum_count(&quarter, 0.01);
/// let exact = std::f64::consts::FRAC_PI_2 * 10.0 * (0.1f64 / 0.08).sqrt();
/// assert!((n - exact).abs() < 1e-6 * exact, "N* of a quarter circle");
/// ```
pub fn minimum_count(curve: &NurbsCurve, tol: f64) -> f64 {
    sqrt_curvature_integral(curve) / (8.0 * tol).sqrt()
}

/// A cheap estimate of [`minimum_count`] (the 2-point Gauss rule per knot span), used to size
/// the output and to refuse absurd requests before any work. It only needs the order of
/// magnitude; a finer rule would cost more evaluations than the walk itself at coarse
/// tolerances.
pub fn estimate_count(curve: &NurbsCurve, tol: f64) -> f64 {
    let x = 1.0 / 3f64.sqrt();
    curve
        .spans()
        .iter()
        .map(|&(_, a, b)| {
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            h * (integrand(curve, m - h * x) + integrand(curve, m + h * x))
        })
        .sum::<f64>()
        / (8.0 * tol).sqrt()
}
