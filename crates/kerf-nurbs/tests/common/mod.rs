//! Shared proptest strategies and independent reference computations for the kerf-nurbs tests.
//!
//! The strategies produce *valid* random curves: degrees 1..=7, log-uniform weights in
//! `[0.05, 20]` (or all equal, for polynomial curves), random knot vectors whose multiplicities go
//! up to the degree, both clamped (end knots repeated `degree + 1` times) and unclamped (every
//! knot, the domain ends included, of multiplicity at most the degree), over random parameter
//! ranges.
//!
//! [`reference_point`] evaluates a curve by the Cox-de Boor recursion over the whole knot vector,
//! which shares no code and no algorithm with the crate's span-local evaluator.

// Each test file compiles this module on its own and uses only part of it.
#![allow(dead_code)]

use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

/// The raw data a random curve was built from.
#[derive(Debug, Clone)]
pub(crate) struct CurveData {
    /// Degree.
    pub(crate) degree: usize,
    /// Full knot vector.
    pub(crate) knots: Vec<f64>,
    /// Control points.
    pub(crate) points: Vec<Point3<f64>>,
    /// Weights (`None` for a polynomial curve).
    pub(crate) weights: Option<Vec<f64>>,
    /// Whether the knot vector is clamped.
    pub(crate) clamped: bool,
}

impl CurveData {
    /// The curve (the strategy only yields valid data).
    pub(crate) fn curve(&self) -> NurbsCurve {
        NurbsCurve::try_new(
            self.degree,
            self.knots.clone(),
            self.points.clone(),
            self.weights.clone(),
        )
        .expect("the strategy yields valid curves")
    }
}

/// Expands `(gap, multiplicity)` runs into `count` non-decreasing knots starting at `start`
/// (the first run sits at `start`; each further run is `gap * scale` after the previous one),
/// truncating the last run that does not fit.
fn expand_runs(runs: &[(f64, usize)], count: usize, start: f64, scale: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(count);
    let mut x = start;
    for (i, &(gap, mult)) in runs.iter().enumerate() {
        if i > 0 {
            x += gap * scale;
        }
        for _ in 0..mult {
            if out.len() == count {
                return out;
            }
            out.push(x);
        }
    }
    // Not enough runs: continue with simple knots.
    while out.len() < count {
        x += 0.5 * scale;
        out.push(x);
    }
    out
}

/// A random valid knot vector of `len` entries for `degree`, clamped or not.
pub(crate) fn knot_vector(
    degree: usize,
    len: usize,
    clamped: bool,
) -> impl Strategy<Value = Vec<f64>> {
    (
        -3.0..3.0f64,
        0.2..5.0f64,
        prop::collection::vec((0.05..1.0f64, 1..=degree), len),
    )
        .prop_map(move |(start, scale, runs)| {
            if clamped {
                // p + 1 copies of start, the interior runs (multiplicity <= p), p + 1 copies of
                // end; the first interior run sits one gap after start.
                let interior = len - 2 * (degree + 1);
                let first = start + runs[0].0 * scale;
                let inner = expand_runs(&runs[1..], interior, first, scale);
                let last = inner.last().copied().unwrap_or(start);
                let end = last + runs[0].0.max(0.3) * scale;
                let mut knots = vec![start; degree + 1];
                knots.extend(inner);
                knots.extend(std::iter::repeat_n(end, degree + 1));
                knots
            } else {
                expand_runs(&runs, len, start, scale)
            }
        })
}

/// Random weights: log-uniform in `[0.05, 20]`, or `None` (polynomial) one time in five.
pub(crate) fn weights(n: usize) -> impl Strategy<Value = Option<Vec<f64>>> {
    prop_oneof![
        1 => Just(None),
        4 => prop::collection::vec((0.05f64.ln()..20.0f64.ln()).prop_map(f64::exp), n).prop_map(Some),
    ]
}

/// Random control points in `[-10, 10]^3`.
pub(crate) fn points(n: usize) -> impl Strategy<Value = Vec<Point3<f64>>> {
    prop::collection::vec(
        (-10.0..10.0f64, -10.0..10.0f64, -10.0..10.0f64).prop_map(|(x, y, z)| Point3::new(x, y, z)),
        n,
    )
}

/// Random valid curve data with degree in `degrees`, `degree + 1 ..= degree + 1 + extra`
/// control points, clamped or unclamped.
pub(crate) fn curve_data_with(
    degrees: std::ops::RangeInclusive<usize>,
    extra: usize,
) -> impl Strategy<Value = CurveData> {
    (degrees, 0..=extra, any::<bool>())
        .prop_flat_map(|(degree, more, clamped)| {
            let n = degree + 1 + more;
            // A clamped vector needs at least 2 (p + 1) knots, which n + p + 1 always is.
            (
                Just(degree),
                knot_vector(degree, n + degree + 1, clamped),
                points(n),
                weights(n),
                Just(clamped),
            )
        })
        .prop_filter_map(
            "unclamped knots with an empty domain",
            |(degree, knots, points, weights, clamped)| {
                let data = CurveData {
                    degree,
                    knots,
                    points,
                    weights,
                    clamped,
                };
                NurbsCurve::try_new(
                    data.degree,
                    data.knots.clone(),
                    data.points.clone(),
                    data.weights.clone(),
                )
                .ok()
                .map(|_| data)
            },
        )
}

/// Random valid curve data: degrees 1..=7, up to 8 more control points than the minimum.
pub(crate) fn curve_data() -> impl Strategy<Value = CurveData> {
    curve_data_with(1..=7, 8)
}

/// Random valid curves: degrees 1..=7, up to 8 more control points than the minimum.
pub(crate) fn curve() -> impl Strategy<Value = NurbsCurve> {
    curve_data().prop_map(|d| d.curve())
}

/// The distinct knot values inside the closed domain `[a, b]`, the domain ends included.
pub(crate) fn breakpoints(c: &NurbsCurve) -> Vec<f64> {
    let (a, b) = c.domain();
    let mut out = vec![a];
    for &k in c.knots() {
        if k > a && k < b && out.last() != Some(&k) {
            out.push(k);
        }
    }
    out.push(b);
    out
}

/// The breakpoints `(lo, hi)` around `t` (lo <= t <= hi, hi > lo).
pub(crate) fn breakpoint_interval(c: &NurbsCurve, t: f64) -> (f64, f64) {
    let bp = breakpoints(c);
    for w in bp.windows(2) {
        if t >= w[0] && t <= w[1] {
            return (w[0], w[1]);
        }
    }
    (bp[0], bp[bp.len() - 1])
}

/// Distance from `t` to the nearest breakpoint (domain ends included).
pub(crate) fn distance_to_breakpoint(c: &NurbsCurve, t: f64) -> f64 {
    breakpoints(c)
        .iter()
        .map(|k| (t - k).abs())
        .fold(f64::INFINITY, f64::min)
}

/// `C(t)` by the Cox-de Boor recursion on the whole knot vector and the rational quotient
/// `sum N_i w_i P_i / sum N_i w_i` (independent of the crate's A2.2 evaluator). At the domain
/// end the last non-empty span is used (the limit from the left).
pub(crate) fn reference_point(c: &NurbsCurve, t: f64) -> Point3<f64> {
    let p = c.degree();
    let u = c.knots();
    let pts = c.control_points();
    let w = c.weights();
    let n = pts.len();
    let (a, b) = c.domain();
    let t = t.clamp(a, b);
    let mut span = p;
    for i in p..n {
        if u[i] < u[i + 1] && u[i] <= t && (t < u[i + 1] || t == b) {
            span = i;
        }
    }
    // N_{i,0} for i = 0..m-1.
    let m = u.len();
    let mut basis: Vec<f64> = (0..m - 1).map(|i| f64::from(u8::from(i == span))).collect();
    for k in 1..=p {
        let next: Vec<f64> = (0..m - 1 - k)
            .map(|i| {
                let mut v = 0.0;
                let d1 = u[i + k] - u[i];
                if d1 > 0.0 {
                    v += (t - u[i]) / d1 * basis[i];
                }
                let d2 = u[i + k + 1] - u[i + 1];
                if d2 > 0.0 {
                    v += (u[i + k + 1] - t) / d2 * basis[i + 1];
                }
                v
            })
            .collect();
        basis = next;
    }
    let mut num = Vector3::zeros();
    let mut den = 0.0;
    for i in 0..n {
        num += pts[i].coords * (basis[i] * w[i]);
        den += basis[i] * w[i];
    }
    Point3::from(num / den)
}

/// The largest distance between `f(t)` and `g(t)` over `samples + 1` evenly spaced parameters
/// of `[t0, t1]`.
pub(crate) fn max_deviation(
    t0: f64,
    t1: f64,
    samples: usize,
    f: impl Fn(f64) -> Point3<f64>,
    g: impl Fn(f64) -> Point3<f64>,
) -> f64 {
    (0..=samples)
        .map(|i| {
            let t = t0 + (t1 - t0) * i as f64 / samples as f64;
            (f(t) - g(t)).norm()
        })
        .fold(0.0, f64::max)
}
