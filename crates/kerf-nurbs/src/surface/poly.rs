//! Bivariate polynomials in tensor-product Bernstein form over the unit square: the algebra
//! the offset certificate ([`super::offset`]) runs on (products, derivatives, degree
//! elevation) and the bound it rests on: a ratio of two such polynomials of one degree, the
//! denominator's coefficients all positive, lies between the least and the largest ratio of
//! their coefficients ([`Poly::ratio_range`]).

use crate::basis::binomial;

/// `sum c[i (n + 1) + j] B_i^m(u) B_j^n(v)` on `[0, 1]^2`.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Poly {
    m: usize,
    n: usize,
    c: Vec<f64>,
}

/// A vector of three polynomials (x, y, z).
pub(super) type Poly3 = [Poly; 3];

impl Poly {
    /// The polynomial of degree `(m, n)` with coefficients `c` (row-major over u).
    pub(super) fn new(m: usize, n: usize, c: Vec<f64>) -> Self {
        debug_assert_eq!(c.len(), (m + 1) * (n + 1), "coefficient count");
        Self { m, n, c }
    }

    /// The coefficients, row-major over u.
    pub(super) fn coefficients(&self) -> &[f64] {
        &self.c
    }

    /// `(degree in u, degree in v)`.
    pub(super) fn degree(&self) -> (usize, usize) {
        (self.m, self.n)
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.c[i * (self.n + 1) + j]
    }

    /// `d/du` (degree `m - 1`; the zero polynomial of degree 0 in u where `m` is 0).
    pub(super) fn du(&self) -> Self {
        if self.m == 0 {
            return Self::new(0, self.n, vec![0.0; self.n + 1]);
        }
        let (m, n) = (self.m, self.n);
        let mut c = Vec::with_capacity(m * (n + 1));
        for i in 0..m {
            for j in 0..=n {
                c.push(m as f64 * (self.at(i + 1, j) - self.at(i, j)));
            }
        }
        Self::new(m - 1, n, c)
    }

    /// `d/dv`.
    pub(super) fn dv(&self) -> Self {
        if self.n == 0 {
            return Self::new(self.m, 0, vec![0.0; self.m + 1]);
        }
        let (m, n) = (self.m, self.n);
        let mut c = Vec::with_capacity((m + 1) * n);
        for i in 0..=m {
            for j in 0..n {
                c.push(n as f64 * (self.at(i, j + 1) - self.at(i, j)));
            }
        }
        Self::new(m, n - 1, c)
    }

    /// The product, of degree `(m1 + m2, n1 + n2)`: `B_i^a B_k^b = C(a,i) C(b,k) / C(a+b,i+k)
    /// B_{i+k}^{a+b}` in each direction.
    pub(super) fn mul(&self, o: &Self) -> Self {
        let (m, n) = (self.m + o.m, self.n + o.n);
        let mut c = vec![0.0; (m + 1) * (n + 1)];
        let bu: Vec<f64> = (0..=self.m).map(|i| binomial(self.m, i)).collect();
        let bv: Vec<f64> = (0..=self.n).map(|j| binomial(self.n, j)).collect();
        let ou: Vec<f64> = (0..=o.m).map(|i| binomial(o.m, i)).collect();
        let ov: Vec<f64> = (0..=o.n).map(|j| binomial(o.n, j)).collect();
        // The products' scaled coefficients first, the common divisors once at the end.
        for i in 0..=self.m {
            for j in 0..=self.n {
                let a = self.at(i, j) * bu[i] * bv[j];
                if a == 0.0 {
                    continue;
                }
                for k in 0..=o.m {
                    let row = (i + k) * (n + 1) + j;
                    for l in 0..=o.n {
                        c[row + l] += a * o.at(k, l) * ou[k] * ov[l];
                    }
                }
            }
        }
        for r in 0..=m {
            let du = binomial(m, r);
            for s in 0..=n {
                c[r * (n + 1) + s] /= du * binomial(n, s);
            }
        }
        Self::new(m, n, c)
    }

    /// The same polynomial written at the higher degree `(m, n)`.
    pub(super) fn elevate(&self, m: usize, n: usize) -> Self {
        debug_assert!(m >= self.m && n >= self.n, "elevation lowers no degree");
        if (m, n) == (self.m, self.n) {
            return self.clone();
        }
        // Multiplying by the constant 1 written at degree (m - m0, n - n0).
        let one = Self::new(
            m - self.m,
            n - self.n,
            vec![1.0; (m - self.m + 1) * (n - self.n + 1)],
        );
        self.mul(&one)
    }

    /// `self + k o` (the lower degree raised to the higher).
    pub(super) fn add_scaled(&self, o: &Self, k: f64) -> Self {
        let (m, n) = (self.m.max(o.m), self.n.max(o.n));
        let (a, b) = (self.elevate(m, n), o.elevate(m, n));
        let c = a.c.iter().zip(&b.c).map(|(x, y)| x + k * y).collect();
        Self::new(m, n, c)
    }

    /// The value at `(u, v)` in `[0, 1]^2`, by de Casteljau's algorithm in each direction.
    pub(super) fn eval(&self, u: f64, v: f64) -> f64 {
        let mut rows = Vec::with_capacity(self.m + 1);
        for i in 0..=self.m {
            rows.push(casteljau(
                &self.c[i * (self.n + 1)..(i + 1) * (self.n + 1)],
                v,
            ));
        }
        casteljau(&rows, u)
    }

    /// The range `(least, largest)` of the coefficient ratios `self_k / den_k` at a common
    /// degree, which holds `self / den` over the whole square: `self / den = sum (c_k / d_k)
    /// (d_k B_k / sum d_l B_l)`, a convex combination where every `d_k > 0`. `None` where a
    /// coefficient of `den` is not positive (or a ratio is not finite).
    pub(super) fn ratio_range(&self, den: &Self) -> Option<(f64, f64)> {
        let (m, n) = (self.m.max(den.m), self.n.max(den.n));
        let (a, b) = (self.elevate(m, n), den.elevate(m, n));
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for (x, d) in a.c.iter().zip(&b.c) {
            // NaN is refused too.
            if d.is_nan() || *d <= 0.0 {
                return None;
            }
            let r = x / d;
            if !r.is_finite() {
                return None;
            }
            lo = lo.min(r);
            hi = hi.max(r);
        }
        Some((lo, hi))
    }

    /// The least coefficient: a lower bound of the polynomial on the square.
    pub(super) fn min_coefficient(&self) -> f64 {
        self.c.iter().copied().fold(f64::INFINITY, f64::min)
    }
}

fn casteljau(c: &[f64], t: f64) -> f64 {
    let mut b = c.to_vec();
    for r in 1..b.len() {
        for k in 0..b.len() - r {
            b[k] = b[k] * (1.0 - t) + b[k + 1] * t;
        }
    }
    b[0]
}

/// `a . b`.
pub(super) fn dot(a: &Poly3, b: &Poly3) -> Poly {
    a[0].mul(&b[0])
        .add_scaled(&a[1].mul(&b[1]), 1.0)
        .add_scaled(&a[2].mul(&b[2]), 1.0)
}

/// `a x b`.
pub(super) fn cross(a: &Poly3, b: &Poly3) -> Poly3 {
    [
        a[1].mul(&b[2]).add_scaled(&a[2].mul(&b[1]), -1.0),
        a[2].mul(&b[0]).add_scaled(&a[0].mul(&b[2]), -1.0),
        a[0].mul(&b[1]).add_scaled(&a[1].mul(&b[0]), -1.0),
    ]
}

/// `k a`, a polynomial times each of three.
pub(super) fn scale3(k: &Poly, a: &Poly3) -> Poly3 {
    [k.mul(&a[0]), k.mul(&a[1]), k.mul(&a[2])]
}

/// `a + s b`.
pub(super) fn add3(a: &Poly3, b: &Poly3, s: f64) -> Poly3 {
    [
        a[0].add_scaled(&b[0], s),
        a[1].add_scaled(&b[1], s),
        a[2].add_scaled(&b[2], s),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f(u, v) = (1 + u)(2 - v) + u^2 v`, written at degree (2, 1) from its values.
    fn sample() -> Poly {
        // Bernstein coefficients of 1 + u at degree 2: 1, 1.5, 2; of u^2: 0, 0, 1.
        // 2 - v at degree 1: 2, 1; v: 0, 1.
        let a = [1.0, 1.5, 2.0];
        let b = [0.0, 0.0, 1.0];
        let mut c = Vec::new();
        for i in 0..3 {
            c.push(a[i] * 2.0 + b[i] * 0.0);
            c.push(a[i] * 1.0 + b[i] * 1.0);
        }
        Poly::new(2, 1, c)
    }

    fn f(u: f64, v: f64) -> f64 {
        (1.0 + u) * (2.0 - v) + u * u * v
    }

    #[test]
    fn products_derivatives_and_elevation_agree_with_the_closed_form() {
        let p = sample();
        let q = p.mul(&p).elevate(5, 3);
        let (pu, pv) = (p.du(), p.dv());
        for k in 0..=8 {
            for l in 0..=8 {
                let (u, v) = (k as f64 / 8.0, l as f64 / 8.0);
                assert!(
                    (p.eval(u, v) - f(u, v)).abs() < 1e-14,
                    "value at ({u}, {v})"
                );
                assert!(
                    (q.eval(u, v) - f(u, v).powi(2)).abs() < 1e-13,
                    "square at ({u}, {v})"
                );
                let fu = (2.0 - v) + 2.0 * u * v;
                let fv = -(1.0 + u) + u * u;
                assert!((pu.eval(u, v) - fu).abs() < 1e-14, "d/du at ({u}, {v})");
                assert!((pv.eval(u, v) - fv).abs() < 1e-14, "d/dv at ({u}, {v})");
            }
        }
    }

    #[test]
    fn the_coefficient_ratios_hold_the_ratio_everywhere() {
        let num = sample().mul(&sample().du());
        let den = sample().mul(&sample());
        let (lo, hi) = num.ratio_range(&den).expect("a positive denominator");
        let mut seen = (f64::INFINITY, f64::NEG_INFINITY);
        for k in 0..=64 {
            for l in 0..=64 {
                let (u, v) = (k as f64 / 64.0, l as f64 / 64.0);
                let r = num.eval(u, v) / den.eval(u, v);
                assert!(
                    r >= lo - 1e-14 && r <= hi + 1e-14,
                    "ratio {r} outside [{lo}, {hi}]"
                );
                seen = (seen.0.min(r), seen.1.max(r));
            }
        }
        // And the range is not vacuous: it is within 40 % of the sampled range's width.
        assert!(
            hi - lo < 1.4 * (seen.1 - seen.0) + 1e-12,
            "range [{lo}, {hi}] vs sampled [{}, {}]",
            seen.0,
            seen.1
        );
        let negative = Poly::new(0, 0, vec![-1.0]);
        assert!(
            num.ratio_range(&negative).is_none(),
            "a non-positive denominator is refused"
        );
    }
}
