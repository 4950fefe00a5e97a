//! B-spline basis functions and their derivatives (The NURBS Book A2.2 and A2.3).
//!
//! Both functions work on fixed-size stack arrays sized by [`MAX_ORDER`], so evaluation never
//! allocates.

use crate::MAX_ORDER;

/// The `degree + 1` non-zero basis functions `N[span - degree + j, degree](u)`, `j = 0..=degree`,
/// written to `out[..=degree]` (The NURBS Book A2.2).
///
/// `span` must satisfy `knots[span] < knots[span + 1]`, as [`crate::knots::find_span`] returns.
#[inline]
pub fn basis_funs(span: usize, u: f64, degree: usize, knots: &[f64], out: &mut [f64; MAX_ORDER]) {
    basis_funs_m(span, u, degree, knots, out);
}

/// [`basis_funs`] with scratch arrays of `M >= degree + 1` entries. Evaluation picks a small `M`
/// for the common low degrees so that no time goes into clearing unused stack space.
#[inline]
pub fn basis_funs_m<const M: usize>(
    span: usize,
    u: f64,
    degree: usize,
    knots: &[f64],
    out: &mut [f64; M],
) {
    let mut left = [0.0; M];
    let mut right = [0.0; M];
    out[0] = 1.0;
    for j in 1..=degree {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = out[r] / (right[r + 1] + left[j - r]);
            out[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        out[j] = saved;
    }
}

/// Basis functions and their derivatives up to order `n` (The NURBS Book A2.3):
/// `ders[k][j]` is the `k`-th derivative of `N[span - degree + j, degree](u)`.
/// Orders above the degree are zero; only `ders[..=min(n, degree)]` is written.
pub fn ders_basis_funs(
    span: usize,
    u: f64,
    degree: usize,
    n: usize,
    knots: &[f64],
    ders: &mut [[f64; MAX_ORDER]],
) {
    ders_basis_funs_m(span, u, degree, n, knots, ders);
}

/// [`ders_basis_funs`] with scratch arrays of `M >= degree + 1` entries.
#[inline]
pub fn ders_basis_funs_m<const M: usize>(
    span: usize,
    u: f64,
    degree: usize,
    n: usize,
    knots: &[f64],
    ders: &mut [[f64; M]],
) {
    let p = degree;
    let n = n.min(p);
    let mut ndu = [[0.0; M]; M];
    let mut left = [0.0; M];
    let mut right = [0.0; M];
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            // Lower triangle: knot differences.
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            // Upper triangle: basis functions.
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    for j in 0..=p {
        ders[0][j] = ndu[j][p];
    }
    let mut a = [[0.0; M]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0usize, 1usize);
        a[0][0] = 1.0;
        for k in 1..=n {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                let rk = rk as usize;
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk];
                d = a[s2][0] * ndu[rk][pk];
            }
            let j1: usize = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2: usize = if r as isize - 1 <= pk as isize {
                k - 1
            } else {
                p - r
            };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k][r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut factor = p as f64;
    for k in 1..=n {
        for j in 0..=p {
            ders[k][j] *= factor;
        }
        factor *= (p - k) as f64;
    }
}

/// Binomial coefficient `C(n, k)` as `f64` (exact for the small arguments used here: every
/// partial product `C(n, i)` is an integer below 2^53). A `const fn`, so that tables of it are
/// built at compile time (the surface evaluator's Leibniz-rule table).
#[inline]
pub const fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        return 0.0;
    }
    let k = if k < n - k { k } else { n - k };
    let mut c = 1.0;
    let mut i = 0;
    while i < k {
        c = c * (n - i) as f64 / (i + 1) as f64;
        i += 1;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::knots::find_span;

    #[test]
    fn partition_of_unity_and_non_negative() {
        let knots = [0.0, 0.0, 0.0, 0.0, 0.2, 0.2, 0.5, 0.9, 1.0, 1.0, 1.0, 1.0];
        let n_points = knots.len() - 4;
        for i in 0..=1000 {
            let u = i as f64 / 1000.0;
            let span = find_span(3, &knots, n_points, u);
            let mut n = [0.0; MAX_ORDER];
            basis_funs(span, u, 3, &knots, &mut n);
            let sum: f64 = n[..4].iter().sum();
            assert!((sum - 1.0).abs() < 1e-14, "sum of basis at {u} is {sum}");
            assert!(n[..4].iter().all(|&b| b >= 0.0), "negative basis at {u}");
            let mut d = [[0.0; MAX_ORDER]; 4];
            ders_basis_funs(span, u, 3, 3, &knots, &mut d);
            for j in 0..4 {
                assert!(
                    (d[0][j] - n[j]).abs() < 1e-15,
                    "A2.2 and A2.3 disagree at {u}"
                );
            }
            for (k, row) in d.iter().enumerate().skip(1) {
                let s: f64 = row[..4].iter().sum();
                assert!(
                    s.abs() < 1e-9,
                    "derivative {k} of the partition of unity is {s}"
                );
            }
        }
    }

    #[test]
    fn binomials() {
        assert_eq!(binomial(5, 2), 10.0, "C(5,2)");
        assert_eq!(binomial(7, 0), 1.0, "C(7,0)");
        assert_eq!(binomial(3, 4), 0.0, "C(3,4)");
    }
}
