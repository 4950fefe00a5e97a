//! The theoretical minimum count of chords, `N* = integral sqrt(k(s) / (8 tol)) ds`.
//!
//! A chord of length `L` on a circle of curvature `k` has sagitta `k L^2 / 8` to leading order,
//! so a chord with sagitta `tol` spans `L = sqrt(8 tol / k)` and the number of chords per unit
//! length is `sqrt(k / (8 tol))`. Integrating along the curve gives the asymptotic minimum
//! (`docs/discretization.md` derives it).

use kerf_nurbs::curvature_of;
use kerf_nurbs::integrate;
use kerf_nurbs::{NurbsCurve, Quadrature};
use nalgebra::Vector3;

fn integrand(curve: &NurbsCurve, t: f64) -> f64 {
    let (_, d1, d2) = curve.eval_d2(t);
    let v = curvature_of(&d1, &d2).sqrt() * d1.norm();
    // Where the speed is zero or overflows, the integrand is a removable (or integrable)
    // singularity: never let a NaN poison the sum.
    if v.is_finite() {
        v
    } else {
        0.0
    }
}

/// Relative accuracy asked of `N*`.
pub const NSTAR_RELATIVE_ACCURACY: f64 = 1e-7;

/// Absolute accuracy asked of `N*`, in chords: a thousandth of a chord is far below anything a
/// count can show, and rounding noise in the curvature of nearly straight or degenerate curves
/// (whose `N*` is near 0) can make a relative accuracy unreachable.
pub const NSTAR_ABSOLUTE_ACCURACY: f64 = 1e-3;

/// Panel splits per knot span for `N*` (40 evaluations each).
pub const NSTAR_SPLITS_PER_SPAN: usize = 32;

/// `integral sqrt(k) ds` over the curve, to a relative accuracy of about 1e-7, or an absolute
/// accuracy of `absolute` (in `sqrt(mm)`), whichever is reached first, within
/// [`NSTAR_SPLITS_PER_SPAN`] panel splits per knot span.
pub fn sqrt_curvature_quadrature(curve: &NurbsCurve, absolute: f64) -> Quadrature {
    let pieces: Vec<(f64, f64)> = curve.spans().iter().map(|&(_, a, b)| (a, b)).collect();
    integrate(
        |t| integrand(curve, t),
        None,
        &pieces,
        NSTAR_RELATIVE_ACCURACY,
        absolute,
        NSTAR_SPLITS_PER_SPAN * pieces.len(),
    )
}

/// `integral sqrt(k) ds` over the curve, to a relative accuracy of about 1e-7 (or `1e-9
/// sqrt(size)` absolute, for curves whose integral is near 0), within a work budget linear in
/// the number of knot spans (see [`sqrt_curvature_quadrature`]).
pub fn sqrt_curvature_integral(curve: &NurbsCurve) -> f64 {
    sqrt_curvature_quadrature(curve, 1e-9 * curve.size().sqrt()).value
}

/// [`minimum_count`] with its error estimate and work: relative accuracy
/// [`NSTAR_RELATIVE_ACCURACY`] or [`NSTAR_ABSOLUTE_ACCURACY`] chords, whichever is reached
/// first, within [`NSTAR_SPLITS_PER_SPAN`] splits per knot span; `converged` is false if the
/// budget ran out first (the value is then the best estimate, `error` its estimated error).
pub fn minimum_count_quadrature(curve: &NurbsCurve, tol: f64) -> Quadrature {
    let s = (8.0 * tol).sqrt();
    let q = sqrt_curvature_quadrature(curve, NSTAR_ABSOLUTE_ACCURACY * s);
    Quadrature {
        value: q.value / s,
        error: q.error / s,
        ..q
    }
}

/// The asymptotic minimum number of chords `N* = integral sqrt(k / (8 tol)) ds` that keep every
/// chord's sagitta within `tol`, to a relative accuracy of 1e-7 or a thousandth of a chord,
/// within a work budget linear in the number of knot spans ([`minimum_count_quadrature`]).
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
    minimum_count_quadrature(curve, tol).value
}

/// A cheap estimate of the total turning of the tangent, `integral k ds` (radians; the 2-point
/// Gauss rule per knot span), used to refuse a `max_turn` that would need absurdly many points
/// before any work. Turns concentrated at a point (a corner inside a span) are not seen.
pub fn estimate_turning(curve: &NurbsCurve) -> f64 {
    let x = 1.0 / 3f64.sqrt();
    let f = |t: f64| {
        let (_, d1, d2) = curve.eval_d2(t);
        let v = curvature_of(&d1, &d2) * d1.norm();
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    curve
        .spans()
        .iter()
        .map(|&(_, a, b)| {
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            h * (f(m - h * x) + f(m + h * x))
        })
        .sum()
}

/// A cheap estimate of [`minimum_count`] (the 2-point Gauss rule per knot span), used to size
/// the output and to refuse absurd requests before any work. It only needs the order of
/// magnitude; a finer rule would cost more evaluations than the walk itself at coarse
/// tolerances.
pub fn estimate_count(curve: &NurbsCurve, tol: f64) -> f64 {
    estimate_count_with(curve, tol, |_, t| {
        let (_, d1, d2) = curve.eval_d2(t);
        (d1, d2)
    })
}

/// [`estimate_count`] with the first two derivatives at `t` in knot span `span` from `d12`
/// (the discretizer passes its span-local evaluator for the curve's degree, several times
/// cheaper than the basis functions).
pub(crate) fn estimate_count_with(
    curve: &NurbsCurve,
    tol: f64,
    d12: impl Fn(usize, f64) -> (Vector3<f64>, Vector3<f64>),
) -> f64 {
    let x = 1.0 / 3f64.sqrt();
    let f = |span: usize, t: f64| {
        let (d1, d2) = d12(span, t);
        let v = curvature_of(&d1, &d2).sqrt() * d1.norm();
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    let knots = curve.knots();
    (curve.degree()..curve.len())
        .filter(|&i| knots[i] < knots[i + 1])
        .map(|i| {
            let (a, b) = (knots[i], knots[i + 1]);
            let (m, h) = (0.5 * (a + b), 0.5 * (b - a));
            h * (f(i, m - h * x) + f(i, m + h * x))
        })
        .sum::<f64>()
        / (8.0 * tol).sqrt()
}
