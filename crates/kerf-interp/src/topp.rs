//! Time-optimal path parameterization (TOPP) on a grid: the phase-plane formulation solved
//! by reachability, as TOPP-RA does, in closed form for one path parameter.
//!
//! Along a path `q(s)`, with `x = (ds/dt)^2` and `u = d2s/dt2` (so `dx/ds = 2 u`), the axis
//! accelerations are `q'(s) u + q''(s) x`. At each grid point `s_i` every axis gives
//! `-A_k <= q'_k u + q''_k x <= A_k`; velocities, the programmed feed and the chord and jerk
//! caps give `x <= c_i`. With `u` constant on `[s_i, s_{i+1}]`, `x_{i+1} = x_i + 2 D_i u_i`.
//!
//! The *maximum velocity curve* `xmax_i` is the largest `x <= c_i` for which some `u` satisfies
//! every axis at once (each lower bound on `u` below each upper bound). The backward pass gives
//! the controllable sets `[0, K_i]`: `K_N = 0` (rest at the end) and `K_i` the largest
//! `x <= xmax_i` whose hardest braking still reaches `K_{i+1}`, i.e. `x + 2 D_i lo_i(x) <= K_{i+1}`
//! with `lo_i` the largest lower bound, linear per axis. The forward pass starts at rest and takes
//! the largest `u` that stays within the limits and inside `[0, K_{i+1}]`: the time-optimal
//! profile on the grid (bang-bang in `u`, on the maximum velocity curve where it binds).
//! The derivation is in `docs/interpolation.md`.

/// Below this `|q'_k|` (mm or degrees per unit of `s`) an axis does not constrain `u`; its
/// curvature term alone must stay within the limit.
const FLAT: f64 = 1e-9;

/// The constraints of one grid point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Point {
    /// `q'(s)` of each axis.
    pub d1: [f64; 5],
    /// `q''(s)` of each axis.
    pub d2: [f64; 5],
    /// The acceleration limit of each axis (already scaled by any margin).
    pub acc: [f64; 5],
    /// Static cap on `x` (velocity, feed, chord, jerk, refinements).
    pub cap: f64,
    /// Cap on the path acceleration `|u|` (the jerk budget of the curvature term
    /// `3 q'' v u`); infinite for none.
    pub path_acc: f64,
}

/// Bounds `alpha + beta x` on `u`, one per constraining axis (and the path acceleration).
type Linear = [(f64, f64); 6];

/// Lower and upper bounds on `u` as `alpha + beta x`, one pair per constraining axis, their
/// count, and the static cap on `x` from the axes that do not constrain `u`.
#[inline]
fn bounds(p: &Point) -> (Linear, Linear, usize, f64) {
    let mut lo = [(0.0, 0.0); 6];
    let mut hi = [(0.0, 0.0); 6];
    let mut n = 0;
    if p.path_acc.is_finite() {
        lo[0] = (-p.path_acc, 0.0);
        hi[0] = (p.path_acc, 0.0);
        n = 1;
    }
    let mut cap = p.cap;
    for k in 0..5 {
        let (a, b, lim) = (p.d1[k], p.d2[k], p.acc[k]);
        if a.abs() <= FLAT {
            if b != 0.0 {
                cap = cap.min(lim / b.abs());
            }
            continue;
        }
        lo[n] = (-lim / a.abs(), -b / a);
        hi[n] = (lim / a.abs(), -b / a);
        n += 1;
    }
    (lo, hi, n, cap)
}

/// The maximum velocity curve at one grid point: the largest admissible `x`.
pub(crate) fn xmax(p: &Point) -> f64 {
    let (lo, hi, n, mut cap) = bounds(p);
    for &(al, bl) in &lo[..n] {
        for &(ah, bh) in &hi[..n] {
            let slope = bl - bh;
            if slope > 0.0 {
                cap = cap.min((ah - al) / slope);
            }
        }
    }
    cap.max(0.0)
}

/// The range of `u` at `(p, x)`.
#[inline]
fn u_range(p: &Point, x: f64) -> (f64, f64) {
    let (lo, hi, n, _) = bounds(p);
    if n == 0 {
        return (f64::NEG_INFINITY, f64::INFINITY);
    }
    let l = lo[..n]
        .iter()
        .map(|(a, b)| a + b * x)
        .fold(f64::NEG_INFINITY, f64::max);
    let h = hi[..n]
        .iter()
        .map(|(a, b)| a + b * x)
        .fold(f64::INFINITY, f64::min);
    (l, h)
}

/// The time-optimal `x_i` at the grid `s` (rest at both ends) and the controls `u_i` of each
/// interval. `pts[i]` holds the constraints at `s[i]`; at least two points.
pub(crate) fn solve(s: &[f64], pts: &[Point]) -> (Vec<f64>, Vec<f64>) {
    let n = s.len();
    let mv: Vec<f64> = pts.iter().map(xmax).collect();
    // Backward: controllable sets [0, k_i].
    let mut k = vec![0.0; n];
    for i in (0..n - 1).rev() {
        let d = s[i + 1] - s[i];
        let (lo, _, m, _) = bounds(&pts[i]);
        let mut ki = mv[i];
        for &(a, b) in &lo[..m] {
            let c = 1.0 + 2.0 * d * b;
            if c > 0.0 {
                ki = ki.min((k[i + 1] - 2.0 * d * a) / c);
            }
        }
        k[i] = ki.max(0.0);
    }
    k[0] = 0.0;
    // Forward: from rest, the largest admissible control that stays controllable.
    let mut x = vec![0.0; n];
    let mut u = vec![0.0; n - 1];
    for i in 0..n - 1 {
        let d = s[i + 1] - s[i];
        let (_, hi) = u_range(&pts[i], x[i]);
        let want = (k[i + 1] - x[i]) / (2.0 * d);
        let ui = hi.min(want);
        let next = (x[i] + 2.0 * d * ui).clamp(0.0, k[i + 1]);
        u[i] = (next - x[i]) / (2.0 * d);
        x[i + 1] = next;
    }
    (x, u)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_line_gives_the_trapezoid() {
        // One axis along s, A = 2, v cap 3: rest to rest over 10 is the exact trapezoid
        // (accelerate 2.25, cruise 5.5, brake 2.25) because x is linear in s under constant u.
        let s: Vec<f64> = (0..=1000).map(|i| i as f64 * 0.01).collect();
        let p = Point {
            d1: [1.0, 0.0, 0.0, 0.0, 0.0],
            d2: [0.0; 5],
            acc: [2.0; 5],
            cap: 9.0,
            path_acc: f64::INFINITY,
        };
        let (x, u) = solve(&s, &vec![p; s.len()]);
        for (i, &si) in s.iter().enumerate() {
            let want = (2.0 * 2.0 * si).min(9.0).min(2.0 * 2.0 * (10.0 - si));
            assert!((x[i] - want).abs() < 1e-9, "x at {si}: {} vs {want}", x[i]);
        }
        assert!(u.iter().all(|v| v.abs() <= 2.0 + 1e-12), "within the limit");
    }

    #[test]
    fn curvature_alone_caps_the_speed() {
        // q' = (0, 0), q'' = (1, 0): x <= A / |q''|.
        let p = Point {
            d1: [0.0; 5],
            d2: [1.0, 0.0, 0.0, 0.0, 0.0],
            acc: [4.0; 5],
            cap: f64::INFINITY,
            path_acc: f64::INFINITY,
        };
        assert_eq!(xmax(&p), 4.0);
        // A circle of radius R at angle 0: q' = (0, 1), q'' = (-1/R, 0); x <= A R.
        let r = 5.0;
        let p = Point {
            d1: [0.0, 1.0, 0.0, 0.0, 0.0],
            d2: [-1.0 / r, 0.0, 0.0, 0.0, 0.0],
            acc: [6.0; 5],
            cap: f64::INFINITY,
            path_acc: f64::INFINITY,
        };
        assert!((xmax(&p) - 30.0).abs() < 1e-12);
    }
}
