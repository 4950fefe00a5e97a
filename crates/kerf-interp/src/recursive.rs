//! The recursive interpolator of paper 001: a spline whose basis terms obey a three-term
//! recurrence, evaluated every cycle with a handful of additions and multiplications.
//!
//! **The new basis.** Each blending function of a segment `t in [0, 1]` is
//!
//! ```text
//! h(t) = A + B t + C cos(w t) + D sin(w t) + E cos(2 w t) + F sin(2 w t),   w = pi / 2,
//! ```
//!
//! with its six coefficients chosen so that `h`, `h'` and `h''` at `t = 0` and `t = 1` equal
//! those of the cubic Hermite function it replaces (`h1 = 1 - 3t^2 + 2t^3`, ...). So a segment
//! `R(t) = h1 Q0 + h2 Q1 + h3 Q0' + h4 Q1'` meets the Hermite end conditions (positions and
//! tangents at both ends) and also the cubic's second derivatives there: a chain of segments
//! built on the slopes of a C2 cubic spline is C2 (the paper's "second-order continuity").
//! [`new_basis_coefficients`] reproduces the paper's table (eq 6 and the solution after it) to
//! its six printed digits.
//!
//! **The recurrence.** `cos(w (t + dt))` and `sin(w (t + dt))` both satisfy
//! `u(t + dt) = 2 cos(w dt) u(t) - u(t - dt)`, so the sum `u1(t) = C cos(w t) + D sin(w t)`
//! does too (and `u2` with `2 w`); with the linear part `A + B t` evaluated directly, a step
//! costs per axis two multiplications and a few additions ([`Recurrence::ThreeTerm`], the
//! paper's form). [`Recurrence::Reinsch`] runs the same recurrence in Reinsch's difference form
//! `d <- d - 4 sin^2(w dt / 2) u; u <- u + d`, which is algebraically the same sequence but
//! does not amplify round-off by `1 / sin(w dt)`. `docs/interpolation.md` has the error
//! analysis and the measured table (`cargo run --release -p kerf-interp --example recursion`).
//!
//! For comparison, [`CubicHermite::forward_differences`] steps the cubic Hermite segment by
//! plain forward differences, whose round-off grows with the cube of the step count.

use std::sync::OnceLock;

use kerf_kinematics::Axes;

use crate::block::{Station, MIN_TRAVEL};
use crate::error::{positive, InterpError, Result};
use crate::model::AxisModel;

/// `w`, the basic angular frequency of the new basis, radians per unit of `t`.
pub const OMEGA: f64 = std::f64::consts::FRAC_PI_2;

/// Coefficients `[A, B, C, D, E, F]` of the four blending functions `h1..h4` in the basis
/// `1, t, cos(w t), sin(w t), cos(2 w t), sin(2 w t)`, `w = pi/2`: the solutions of the 6x6
/// systems of paper 001 eq 6 (matching value, first and second derivative of the cubic Hermite
/// functions at both ends). Solved once, in double precision.
pub fn new_basis_coefficients() -> &'static [[f64; 6]; 4] {
    static COEFFS: OnceLock<[[f64; 6]; 4]> = OnceLock::new();
    COEFFS.get_or_init(|| {
        let w = OMEGA;
        let row = |t: f64, d: usize| -> [f64; 6] {
            let (s1, c1) = (w * t).sin_cos();
            let (s2, c2) = (2.0 * w * t).sin_cos();
            match d {
                0 => [1.0, t, c1, s1, c2, s2],
                1 => [0.0, 1.0, -w * s1, w * c1, -2.0 * w * s2, 2.0 * w * c2],
                _ => [
                    0.0,
                    0.0,
                    -w * w * c1,
                    -w * w * s1,
                    -4.0 * w * w * c2,
                    -4.0 * w * w * s2,
                ],
            }
        };
        let m = [
            row(0.0, 0),
            row(1.0, 0),
            row(0.0, 1),
            row(1.0, 1),
            row(0.0, 2),
            row(1.0, 2),
        ];
        // Values, slopes and second derivatives of the cubic Hermite functions at 0 and 1.
        let rhs: [[f64; 6]; 4] = [
            [1.0, 0.0, 0.0, 0.0, -6.0, 6.0],
            [0.0, 1.0, 0.0, 0.0, 6.0, -6.0],
            [0.0, 0.0, 1.0, 0.0, -4.0, 2.0],
            [0.0, 0.0, 0.0, 1.0, -2.0, 4.0],
        ];
        rhs.map(|b| solve6(m, b))
    })
}

/// Gaussian elimination with partial pivoting on a 6x6 system (well conditioned here).
fn solve6(mut m: [[f64; 6]; 6], mut b: [f64; 6]) -> [f64; 6] {
    for c in 0..6 {
        let p = (c..6)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap_or(c);
        m.swap(c, p);
        b.swap(c, p);
        for r in c + 1..6 {
            let f = m[r][c] / m[c][c];
            for k in c..6 {
                m[r][k] -= f * m[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 6];
    for r in (0..6).rev() {
        let s: f64 = (r + 1..6).map(|k| m[r][k] * x[k]).sum();
        x[r] = (b[r] - s) / m[r][r];
    }
    x
}

/// How [`NewBasisSegment::steps`] advances the trigonometric terms.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Recurrence {
    /// `u_{k+1} = 2 cos(w dt) u_k - u_{k-1}`: paper 001's form.
    ThreeTerm,
    /// The same sequence as `d_{k+1} = d_k - 4 sin^2(w dt / 2) u_k`, `u_{k+1} = u_k + d_{k+1}`.
    Reinsch,
}

/// One segment of the new-basis spline in `D` coordinates (five for `[x, y, z, tilt, C]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewBasisSegment<const D: usize> {
    /// `A` terms (constant).
    pub a: [f64; D],
    /// `B` terms (times `t`).
    pub b: [f64; D],
    /// Coefficients of `cos(w t)`.
    pub c1: [f64; D],
    /// Coefficients of `sin(w t)`.
    pub s1: [f64; D],
    /// Coefficients of `cos(2 w t)`.
    pub c2: [f64; D],
    /// Coefficients of `sin(2 w t)`.
    pub s2: [f64; D],
}

impl<const D: usize> NewBasisSegment<D> {
    /// The segment with end points `q0`, `q1` and end tangents `d0`, `d1` (derivatives with
    /// respect to `t in [0, 1]`): paper 001 eq 4.
    pub fn hermite(q0: [f64; D], q1: [f64; D], d0: [f64; D], d1: [f64; D]) -> Self {
        let h = new_basis_coefficients();
        let comb = |j: usize| -> [f64; D] {
            std::array::from_fn(|k| {
                h[0][j] * q0[k] + h[1][j] * q1[k] + h[2][j] * d0[k] + h[3][j] * d1[k]
            })
        };
        Self {
            a: comb(0),
            b: comb(1),
            c1: comb(2),
            s1: comb(3),
            c2: comb(4),
            s2: comb(5),
        }
    }

    /// Direct evaluation at `t`.
    pub fn eval(&self, t: f64) -> [f64; D] {
        let (sn1, cs1) = (OMEGA * t).sin_cos();
        let (sn2, cs2) = (2.0 * OMEGA * t).sin_cos();
        std::array::from_fn(|k| {
            self.a[k]
                + self.b[k] * t
                + self.c1[k] * cs1
                + self.s1[k] * sn1
                + self.c2[k] * cs2
                + self.s2[k] * sn2
        })
    }

    /// Derivative `dR/dt` at `t`.
    pub fn derivative(&self, t: f64) -> [f64; D] {
        let w = OMEGA;
        let (sn1, cs1) = (w * t).sin_cos();
        let (sn2, cs2) = (2.0 * w * t).sin_cos();
        std::array::from_fn(|k| {
            self.b[k]
                + w * (self.s1[k] * cs1 - self.c1[k] * sn1)
                + 2.0 * w * (self.s2[k] * cs2 - self.c2[k] * sn2)
        })
    }

    /// Second derivative at `t`.
    pub fn second_derivative(&self, t: f64) -> [f64; D] {
        let w = OMEGA;
        let (sn1, cs1) = (w * t).sin_cos();
        let (sn2, cs2) = (2.0 * w * t).sin_cos();
        std::array::from_fn(|k| {
            -w * w * (self.c1[k] * cs1 + self.s1[k] * sn1)
                - 4.0 * w * w * (self.c2[k] * cs2 + self.s2[k] * sn2)
        })
    }

    /// The values at `t = k / n`, `k = 0..=n`, by the recurrence (raw: the last value is the
    /// recurrence's, not snapped to the end point, so that its error can be measured).
    pub fn steps(&self, n: usize, kind: Recurrence) -> RecurrenceSteps<D> {
        let n = n.max(1);
        let theta1 = OMEGA / n as f64;
        let theta2 = 2.0 * OMEGA / n as f64;
        // u at k = 0 and k = -1 (three-term), or the difference d_0 = u_0 - u_{-1} (Reinsch).
        let init = |c: &[f64; D], s: &[f64; D], th: f64| -> ([f64; D], [f64; D]) {
            let (sn, cs) = th.sin_cos();
            let half = (0.5 * th).sin();
            match kind {
                Recurrence::ThreeTerm => (*c, std::array::from_fn(|k| c[k] * cs - s[k] * sn)),
                Recurrence::Reinsch => (
                    *c,
                    std::array::from_fn(|k| 2.0 * half * half * c[k] + sn * s[k]),
                ),
            }
        };
        let (u1, w1) = init(&self.c1, &self.s1, theta1);
        let (u2, w2) = init(&self.c2, &self.s2, theta2);
        let coef = |th: f64| match kind {
            Recurrence::ThreeTerm => 2.0 * th.cos(),
            Recurrence::Reinsch => {
                let h = (0.5 * th).sin();
                4.0 * h * h
            }
        };
        RecurrenceSteps {
            a: self.a,
            b: self.b,
            kind,
            k1: coef(theta1),
            k2: coef(theta2),
            u1,
            w1,
            u2,
            w2,
            i: 0,
            n,
        }
    }
}

/// Iterator of [`NewBasisSegment::steps`].
#[derive(Debug, Clone)]
pub struct RecurrenceSteps<const D: usize> {
    a: [f64; D],
    b: [f64; D],
    kind: Recurrence,
    k1: f64,
    k2: f64,
    u1: [f64; D],
    /// Previous value (three-term) or last difference (Reinsch).
    w1: [f64; D],
    u2: [f64; D],
    w2: [f64; D],
    i: usize,
    n: usize,
}

impl<const D: usize> Iterator for RecurrenceSteps<D> {
    type Item = [f64; D];

    #[inline]
    fn next(&mut self) -> Option<[f64; D]> {
        if self.i > self.n {
            return None;
        }
        if self.i > 0 {
            for k in 0..D {
                match self.kind {
                    Recurrence::ThreeTerm => {
                        let n1 = self.k1 * self.u1[k] - self.w1[k];
                        self.w1[k] = self.u1[k];
                        self.u1[k] = n1;
                        let n2 = self.k2 * self.u2[k] - self.w2[k];
                        self.w2[k] = self.u2[k];
                        self.u2[k] = n2;
                    }
                    Recurrence::Reinsch => {
                        self.w1[k] -= self.k1 * self.u1[k];
                        self.u1[k] += self.w1[k];
                        self.w2[k] -= self.k2 * self.u2[k];
                        self.u2[k] += self.w2[k];
                    }
                }
            }
        }
        let t = self.i as f64 / self.n as f64;
        self.i += 1;
        Some(std::array::from_fn(|k| {
            self.a[k] + self.b[k] * t + self.u1[k] + self.u2[k]
        }))
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = (self.n + 1).saturating_sub(self.i);
        (left, Some(left))
    }
}

/// A cubic Hermite segment `p0 + p1 t + p2 t^2 + p3 t^3`, `t in [0, 1]`: the classic
/// interpolator the new basis replaces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CubicHermite<const D: usize> {
    /// Power-basis coefficients `[p0, p1, p2, p3]`.
    pub p: [[f64; D]; 4],
}

impl<const D: usize> CubicHermite<D> {
    /// The cubic with end points `q0`, `q1` and end tangents `d0`, `d1` (paper 001 eq 1).
    pub fn hermite(q0: [f64; D], q1: [f64; D], d0: [f64; D], d1: [f64; D]) -> Self {
        Self {
            p: [
                q0,
                d0,
                std::array::from_fn(|k| -3.0 * q0[k] + 3.0 * q1[k] - 2.0 * d0[k] - d1[k]),
                std::array::from_fn(|k| 2.0 * q0[k] - 2.0 * q1[k] + d0[k] + d1[k]),
            ],
        }
    }

    /// Direct (Horner) evaluation at `t`.
    pub fn eval(&self, t: f64) -> [f64; D] {
        std::array::from_fn(|k| {
            ((self.p[3][k] * t + self.p[2][k]) * t + self.p[1][k]) * t + self.p[0][k]
        })
    }

    /// The values at `t = k / n`, `k = 0..=n`, by forward differences (three additions per
    /// coordinate and step).
    pub fn forward_differences(&self, n: usize) -> ForwardDifferences<D> {
        let h = 1.0 / n.max(1) as f64;
        let (h2, h3) = (h * h, h * h * h);
        let p = &self.p;
        ForwardDifferences {
            x: p[0],
            d1: std::array::from_fn(|k| p[1][k] * h + p[2][k] * h2 + p[3][k] * h3),
            d2: std::array::from_fn(|k| 2.0 * p[2][k] * h2 + 6.0 * p[3][k] * h3),
            d3: std::array::from_fn(|k| 6.0 * p[3][k] * h3),
            i: 0,
            n: n.max(1),
        }
    }
}

/// Iterator of [`CubicHermite::forward_differences`].
#[derive(Debug, Clone)]
pub struct ForwardDifferences<const D: usize> {
    x: [f64; D],
    d1: [f64; D],
    d2: [f64; D],
    d3: [f64; D],
    i: usize,
    n: usize,
}

impl<const D: usize> Iterator for ForwardDifferences<D> {
    type Item = [f64; D];

    #[inline]
    fn next(&mut self) -> Option<[f64; D]> {
        if self.i > self.n {
            return None;
        }
        let out = self.x;
        for k in 0..D {
            self.x[k] += self.d1[k];
            self.d1[k] += self.d2[k];
            self.d2[k] += self.d3[k];
        }
        self.i += 1;
        Some(out)
    }
}

/// Largest deviation over all steps `k = 0..=n` between a stepped sequence and the direct
/// evaluation at `t = k / n`, measured as the Euclidean norm of the first `min(D, 3)`
/// coordinates (the tool tip, mm).
pub fn max_deviation<const D: usize>(
    steps: impl Iterator<Item = [f64; D]>,
    n: usize,
    direct: impl Fn(f64) -> [f64; D],
) -> f64 {
    let n = n.max(1);
    let mut worst = 0.0f64;
    for (k, v) in steps.enumerate() {
        let e = direct(k as f64 / n as f64);
        let d: f64 = (0..D.min(3))
            .map(|j| (v[j] - e[j]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    worst
}

/// Slopes of the natural C2 cubic spline through `points` on the knots `u` (chord lengths):
/// the tridiagonal system `h_i m_{i-1} + 2 (h_{i-1} + h_i) m_i + h_{i-1} m_{i+1} =
/// 3 (h_i delta_{i-1} + h_{i-1} delta_i)` with `2 m_0 + m_1 = 3 delta_0` and
/// `m_{n-1} + 2 m_n = 3 delta_{n-1}` at the ends, solved by the Thomas algorithm.
fn spline_slopes(points: &[[f64; 5]], h: &[f64]) -> Vec<[f64; 5]> {
    let n = points.len();
    let delta: Vec<[f64; 5]> = (0..n - 1)
        .map(|i| std::array::from_fn(|k| (points[i + 1][k] - points[i][k]) / h[i]))
        .collect();
    let mut sub = vec![0.0; n];
    let mut diag = vec![0.0; n];
    let mut sup = vec![0.0; n];
    let mut rhs = vec![[0.0; 5]; n];
    diag[0] = 2.0;
    sup[0] = 1.0;
    rhs[0] = delta[0].map(|d| 3.0 * d);
    for i in 1..n - 1 {
        sub[i] = h[i];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        sup[i] = h[i - 1];
        rhs[i] = std::array::from_fn(|k| 3.0 * (h[i] * delta[i - 1][k] + h[i - 1] * delta[i][k]));
    }
    sub[n - 1] = 1.0;
    diag[n - 1] = 2.0;
    rhs[n - 1] = delta[n - 2].map(|d| 3.0 * d);
    for i in 1..n {
        let f = sub[i] / diag[i - 1];
        diag[i] -= f * sup[i - 1];
        let prev = rhs[i - 1];
        for k in 0..5 {
            rhs[i][k] -= f * prev[k];
        }
    }
    let mut m = vec![[0.0; 5]; n];
    m[n - 1] = rhs[n - 1].map(|r| r / diag[n - 1]);
    for i in (0..n - 1).rev() {
        m[i] = std::array::from_fn(|k| (rhs[i][k] - sup[i] * m[i + 1][k]) / diag[i]);
    }
    m
}

/// The new-basis spline through the stations, `[x, y, z, tilt, C]` per point: a C2 cubic
/// spline's slopes (natural ends, chord-length knots) as the Hermite tangents of each
/// segment, so the chain is C2.
///
/// # Errors
/// [`InterpError::TooFewPoints`] below two stations; [`InterpError::BadParameter`] when two
/// neighbouring tips coincide (chord-length knots need distinct points);
/// [`InterpError::NonFinite`].
pub fn spline_through(stations: &[Station]) -> Result<Vec<(NewBasisSegment<5>, f64)>> {
    if stations.len() < 2 {
        return Err(InterpError::TooFewPoints {
            got: stations.len(),
            need: 2,
        });
    }
    let pts: Vec<[f64; 5]> = stations
        .iter()
        .map(|s| [s.tip.x, s.tip.y, s.tip.z, s.axes.tilt, s.axes.c])
        .collect();
    for (i, p) in pts.iter().enumerate() {
        if !p.iter().all(|v| v.is_finite()) {
            return Err(InterpError::NonFinite { index: i });
        }
    }
    let h: Vec<f64> = stations
        .windows(2)
        .map(|w| (w[1].tip - w[0].tip).norm())
        .collect();
    if let Some(&bad) = h.iter().find(|&&d| d.is_nan() || d <= MIN_TRAVEL) {
        return Err(InterpError::BadParameter {
            name: "spline points",
            value: bad,
            reason: "neighbouring tips must be distinct",
        });
    }
    let m = spline_slopes(&pts, &h);
    Ok((0..pts.len() - 1)
        .map(|i| {
            let d0 = m[i].map(|v| v * h[i]);
            let d1 = m[i + 1].map(|v| v * h[i]);
            (NewBasisSegment::hermite(pts[i], pts[i + 1], d0, d1), h[i])
        })
        .collect())
}

/// Set-points of the recursive spline mode: the spline of [`spline_through`], each segment
/// stepped in `n = ceil(chord / (F T))` equal steps of `t` by the recurrence `kind`, every
/// value `[x, y, z, tilt, C]` through [`AxisModel::linear_axes`]. Every segment's last step
/// lands exactly on its station's axes.
///
/// This is paper 001's fixed-step scheme: the nominal feed `F` holds on average over a
/// segment (the parametric speed varies within it), and there is no look-ahead against the
/// axis limits; use the block program and [`crate::plan()`] for that.
///
/// # Errors
/// As [`spline_through`], plus [`InterpError::BadParameter`] for a feed or cycle that is not
/// finite and > 0 and [`InterpError::TooManyCycles`] beyond 100 million cycles.
pub fn spline_setpoints<M: AxisModel + ?Sized>(
    model: &M,
    stations: &[Station],
    feed: f64,
    cycle: f64,
    kind: Recurrence,
) -> Result<Vec<Axes>> {
    let dl = positive("feed", feed)? / 60.0 * positive("cycle", cycle)?;
    let segments = spline_through(stations)?;
    let total: f64 = segments.iter().map(|(_, h)| (h / dl).ceil()).sum();
    if total.is_nan() || total > 1e8 {
        return Err(InterpError::TooManyCycles {
            cycles: total,
            limit: 100_000_000,
        });
    }
    let mut out = Vec::with_capacity(total as usize + 1);
    out.push(stations[0].axes);
    for (i, (seg, h)) in segments.iter().enumerate() {
        let n = ((h / dl).ceil() as usize).max(1);
        for v in seg.steps(n, kind).skip(1).take(n - 1) {
            let xyz = model.linear_axes(&nalgebra::Point3::new(v[0], v[1], v[2]), v[3], v[4]);
            out.push(Axes::new(xyz[0], xyz[1], xyz[2], v[3], v[4]));
        }
        out.push(stations[i + 1].axes);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_matches_the_cubic_hermite_ends() {
        let q0 = [1.0, -2.0];
        let q1 = [4.0, 3.0];
        let d0 = [2.0, 0.5];
        let d1 = [-1.0, 5.0];
        let nb = NewBasisSegment::hermite(q0, q1, d0, d1);
        let cu = CubicHermite::hermite(q0, q1, d0, d1);
        let cd2 = |t: f64| -> [f64; 2] {
            std::array::from_fn(|k| 2.0 * cu.p[2][k] + 6.0 * cu.p[3][k] * t)
        };
        for t in [0.0, 1.0] {
            let (a, b) = (nb.eval(t), cu.eval(t));
            let (da, db) = (nb.derivative(t), [d0, d1][t as usize]);
            let (sa, sb) = (nb.second_derivative(t), cd2(t));
            for k in 0..2 {
                assert!((a[k] - b[k]).abs() < 1e-12, "value at {t}");
                assert!((da[k] - db[k]).abs() < 1e-12, "slope at {t}");
                assert!((sa[k] - sb[k]).abs() < 1e-12, "second derivative at {t}");
            }
        }
    }

    #[test]
    fn recurrences_follow_direct_evaluation() {
        let nb = NewBasisSegment::hermite(
            [0.0; 3],
            [10.0, 5.0, 1.0],
            [12.0, 0.0, 0.0],
            [0.0, 9.0, 1.0],
        );
        for kind in [Recurrence::ThreeTerm, Recurrence::Reinsch] {
            let e = max_deviation(nb.steps(100, kind), 100, |t| nb.eval(t));
            assert!(e < 1e-12, "{kind:?}: {e}");
        }
        let cu = CubicHermite::hermite(
            [0.0; 3],
            [10.0, 5.0, 1.0],
            [12.0, 0.0, 0.0],
            [0.0, 9.0, 1.0],
        );
        let e = max_deviation(cu.forward_differences(100), 100, |t| cu.eval(t));
        assert!(e < 1e-12, "forward differences: {e}");
    }
}
