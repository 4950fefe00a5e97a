//! Rational B-spline curves.

use nalgebra::{Point3, Vector3, Vector4};

use crate::basis::{basis_funs_m, binomial, ders_basis_funs_m};
use crate::error::{NurbsError, Result};
use crate::knots;
use crate::MAX_ORDER;

/// A non-uniform rational B-spline curve in 3D.
///
/// Stored as degree, the full knot vector and homogeneous control points `(w x, w y, w z, w)`.
/// The parameter domain is `[knots[degree], knots[len - degree - 1]]`; clamped and unclamped
/// knot vectors are both legal. Construction validates everything (see [`NurbsCurve::try_new`]),
/// so evaluation never fails: parameters outside the domain are clamped to it.
#[derive(Debug, Clone, PartialEq)]
pub struct NurbsCurve {
    degree: usize,
    knots: Vec<f64>,
    cpw: Vec<Vector4<f64>>,
    rational: bool,
}

/// The Frenet frame at a point of a curve: unit tangent, principal normal and binormal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrenetFrame {
    /// Unit tangent `C' / |C'|`.
    pub tangent: Vector3<f64>,
    /// Unit principal normal, pointing to the centre of curvature.
    pub normal: Vector3<f64>,
    /// Unit binormal `tangent x normal`.
    pub binormal: Vector3<f64>,
}

impl NurbsCurve {
    /// Builds a curve from its degree, full knot vector, control points and optional weights
    /// (`None` = all 1), checking every value.
    ///
    /// # Errors
    /// One [`NurbsError`] variant per defect: degree 0 or above [`crate::MAX_DEGREE`], fewer than
    /// `degree + 1` points, wrong knot count, non-finite or decreasing knots, a knot repeated
    /// more than `degree + 1` times, an empty domain, non-finite control points, a weight count
    /// that differs from the point count, and weights that are not finite and > 0.
    pub fn try_new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Result<Self> {
        knots::validate(
            degree,
            &knots,
            points.len(),
            "degree",
            "knots",
            "control_points",
        )?;
        for (i, p) in points.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                return Err(NurbsError::PointNotFinite {
                    field: "control_points",
                    index: format!("[{i}]"),
                    x: p.x,
                    y: p.y,
                    z: p.z,
                });
            }
        }
        if let Some(w) = &weights {
            if w.len() != points.len() {
                return Err(NurbsError::WeightCount {
                    field: "weights",
                    expected: points.len(),
                    got: w.len(),
                });
            }
            for (i, &value) in w.iter().enumerate() {
                if !(value.is_finite() && value > 0.0) {
                    return Err(NurbsError::BadWeight {
                        field: "weights",
                        index: format!("[{i}]"),
                        value,
                    });
                }
            }
        }
        let weights = match weights {
            Some(w) => Some(normalized_weights(w, "weights")?),
            None => None,
        };
        if let Some(w) = &weights {
            for (i, (p, &wi)) in points.iter().zip(w).enumerate() {
                if !(p.coords * wi).iter().all(|c| c.is_finite()) {
                    return Err(NurbsError::HomogeneousOverflow {
                        field: "weights",
                        index: format!("[{i}]"),
                        weight: wi,
                    });
                }
            }
        }
        let rational = weights
            .as_ref()
            .is_some_and(|w| w.iter().any(|&x| x != w[0]));
        let cpw = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let w = weights.as_ref().map_or(1.0, |w| w[i]);
                Vector4::new(p.x * w, p.y * w, p.z * w, w)
            })
            .collect();
        Ok(Self {
            degree,
            knots,
            cpw,
            rational,
        })
    }

    /// Like [`NurbsCurve::try_new`] for data known to be valid.
    ///
    /// # Panics
    /// If the data is invalid; the message is the [`NurbsError`].
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: Vec<Point3<f64>>,
        weights: Option<Vec<f64>>,
    ) -> Self {
        match Self::try_new(degree, knots, points, weights) {
            Ok(c) => c,
            Err(e) => panic!("invalid NURBS curve: {e}"),
        }
    }

    /// Builds a curve from homogeneous control points `(w x, w y, w z, w)` without checking.
    /// The caller guarantees what [`NurbsCurve::try_new`] checks (used after knot insertion,
    /// splitting and reversal, which preserve validity).
    pub fn from_homogeneous_unchecked(
        degree: usize,
        knots: Vec<f64>,
        cpw: Vec<Vector4<f64>>,
    ) -> Self {
        let rational = cpw.iter().any(|c| c.w != cpw[0].w);
        Self {
            degree,
            knots,
            cpw,
            rational,
        }
    }

    /// The degree `p`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The full knot vector.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The homogeneous control points `(w x, w y, w z, w)`.
    pub fn homogeneous_points(&self) -> &[Vector4<f64>] {
        &self.cpw
    }

    /// The number of control points.
    pub fn len(&self) -> usize {
        self.cpw.len()
    }

    /// Always false: a valid curve has at least `degree + 1` control points.
    pub fn is_empty(&self) -> bool {
        self.cpw.is_empty()
    }

    /// The control points (projected from homogeneous form).
    pub fn control_points(&self) -> Vec<Point3<f64>> {
        self.cpw.iter().map(project).collect()
    }

    /// The weights.
    pub fn weights(&self) -> Vec<f64> {
        self.cpw.iter().map(|c| c.w).collect()
    }

    /// True if the weights are not all equal (a curve with equal weights is polynomial).
    pub fn is_rational(&self) -> bool {
        self.rational
    }

    /// The parameter domain `[knots[p], knots[len - p - 1]]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.degree], self.knots[self.cpw.len()])
    }

    /// The index of the knot span that holds `t` (see [`knots::find_span`]).
    #[inline]
    pub fn span(&self, t: f64) -> usize {
        knots::find_span(self.degree, &self.knots, self.cpw.len(), t)
    }

    /// The non-empty knot spans inside the domain as `(span index, start, end)`.
    pub fn spans(&self) -> Vec<(usize, f64, f64)> {
        (self.degree..self.cpw.len())
            .filter(|&i| self.knots[i] < self.knots[i + 1])
            .map(|i| (i, self.knots[i], self.knots[i + 1]))
            .collect()
    }

    #[inline]
    fn clamp(&self, t: f64) -> f64 {
        let (a, b) = self.domain();
        if t.is_nan() {
            a
        } else {
            t.clamp(a, b)
        }
    }

    /// The point `C(t)`. Parameters outside the domain (and NaN) are clamped to it.
    #[inline]
    pub fn point(&self, t: f64) -> Point3<f64> {
        // Scratch arrays sized for the degree: clearing 25-entry arrays would cost more than
        // the arithmetic for the common degrees.
        match self.degree {
            0..=3 => self.point_m::<4>(t),
            4..=7 => self.point_m::<8>(t),
            _ => self.point_m::<MAX_ORDER>(t),
        }
    }

    #[inline]
    fn point_m<const M: usize>(&self, t: f64) -> Point3<f64> {
        crate::work::tick();
        let t = self.clamp(t);
        let span = self.span(t);
        let mut n = [0.0; M];
        basis_funs_m(span, t, self.degree, &self.knots, &mut n);
        let mut acc = Vector4::zeros();
        let first = span - self.degree;
        for (j, nj) in n.iter().enumerate().take(self.degree + 1) {
            acc += self.cpw[first + j] * *nj;
        }
        project(&acc)
    }

    /// Homogeneous derivatives `A^(k)` (k = 0..=n, with `A^(0)` the point) written to `out`.
    /// Orders above the degree are zero.
    #[inline]
    fn homogeneous_derivs(&self, t: f64, n: usize, out: &mut [Vector4<f64>]) {
        match self.degree {
            0..=3 => self.homogeneous_derivs_m::<4>(t, n, out),
            4..=7 => self.homogeneous_derivs_m::<8>(t, n, out),
            _ => self.homogeneous_derivs_m::<MAX_ORDER>(t, n, out),
        }
    }

    #[inline]
    fn homogeneous_derivs_m<const M: usize>(&self, t: f64, n: usize, out: &mut [Vector4<f64>]) {
        crate::work::tick();
        let p = self.degree;
        let t = self.clamp(t);
        let span = self.span(t);
        let nd = n.min(p);
        let mut ders = [[0.0; M]; M];
        ders_basis_funs_m(span, t, p, nd, &self.knots, &mut ders[..]);
        let first = span - p;
        for (k, o) in out.iter_mut().enumerate().take(n + 1) {
            *o = Vector4::zeros();
            if k <= nd {
                for j in 0..=p {
                    *o += self.cpw[first + j] * ders[k][j];
                }
            }
        }
    }

    /// Cartesian derivatives from homogeneous ones: A4.2 for rational curves; for equal
    /// weights `w` the weight's derivatives vanish and `C^(k) = A^(k) / w`.
    #[inline]
    fn cartesian_derivs(&self, a: &[Vector4<f64>], c: &mut [Vector3<f64>]) {
        if self.rational {
            rational_from_homogeneous(a, c);
        } else {
            let inv = 1.0 / a[0].w;
            for (ck, ak) in c.iter_mut().zip(a) {
                *ck = ak.xyz() * inv;
            }
        }
    }

    /// The point and derivatives `C, C', ..., C^(n)` at `t` (index 0 is the point as a vector),
    /// for any order `n`: rational derivatives from the homogeneous ones by The NURBS Book
    /// A4.2, `C^(k) = (A^(k) - sum_{i=1..k} binom(k, i) w^(i) C^(k-i)) / w`.
    pub fn derivatives(&self, t: f64, n: usize) -> Vec<Vector3<f64>> {
        let mut a = vec![Vector4::zeros(); n + 1];
        self.homogeneous_derivs(t, n, &mut a);
        let mut c = vec![Vector3::zeros(); n + 1];
        self.cartesian_derivs(&a, &mut c);
        c
    }

    /// The point, first and second derivative at `t`, without allocating.
    #[inline]
    pub fn eval_d2(&self, t: f64) -> (Point3<f64>, Vector3<f64>, Vector3<f64>) {
        let mut a = [Vector4::zeros(); 3];
        self.homogeneous_derivs(t, 2, &mut a);
        let mut c = [Vector3::zeros(); 3];
        self.cartesian_derivs(&a, &mut c);
        (Point3::from(c[0]), c[1], c[2])
    }

    /// The point and first derivative at `t`, without allocating.
    #[inline]
    pub fn eval_d1(&self, t: f64) -> (Point3<f64>, Vector3<f64>) {
        let mut a = [Vector4::zeros(); 2];
        self.homogeneous_derivs(t, 1, &mut a);
        let mut c = [Vector3::zeros(); 2];
        self.cartesian_derivs(&a, &mut c);
        (Point3::from(c[0]), c[1])
    }

    /// The point and the first three derivatives at `t`, without allocating.
    pub fn eval_d3(&self, t: f64) -> [Vector3<f64>; 4] {
        let mut a = [Vector4::zeros(); 4];
        self.homogeneous_derivs(t, 3, &mut a);
        let mut c = [Vector3::zeros(); 4];
        self.cartesian_derivs(&a, &mut c);
        c
    }

    /// The unit tangent at `t`, or `None` where the first derivative vanishes (a cusp or
    /// repeated control points); see [`NurbsCurve::tangent_limit`] for the one-sided limit.
    pub fn tangent(&self, t: f64) -> Option<Vector3<f64>> {
        let (_, d1) = self.eval_d1(t);
        let n = d1.norm();
        (n > 0.0 && n.is_finite()).then(|| d1 / n)
    }

    /// The unit tangent at `t`, taking the limit from the lowest non-vanishing derivative where
    /// `C'(t) = 0` (the direction in which the curve leaves `C(t)` for increasing `t`).
    pub fn tangent_limit(&self, t: f64) -> Option<Vector3<f64>> {
        let d = self.derivatives(t, self.degree.max(1));
        let scale = self.size().max(1e-300);
        for v in d.iter().skip(1) {
            let n = v.norm();
            if n > 1e-12 * scale {
                return Some(v / n);
            }
        }
        None
    }

    /// Curvature `|C' x C''| / |C'|^3` at `t`; 0 where the first derivative vanishes.
    #[inline]
    pub fn curvature(&self, t: f64) -> f64 {
        let (_, d1, d2) = self.eval_d2(t);
        curvature_of(&d1, &d2)
    }

    /// The derivative of curvature with respect to arc length, `dk/ds`, at `t`:
    /// with `a = C' x C''`, `dk/dt = (a . (C' x C''')) / (|a| |C'|^3) - 3 |a| (C' . C'') / |C'|^5`
    /// and `dk/ds = (dk/dt) / |C'|`. Zero where the curve is straight or `C' = 0`.
    pub fn curvature_derivative(&self, t: f64) -> f64 {
        let [_, d1, d2, d3] = self.eval_d3(t);
        let s = d1.norm();
        let a = d1.cross(&d2);
        let an = a.norm();
        if s == 0.0 || an == 0.0 {
            return 0.0;
        }
        let dk_dt = a.dot(&d1.cross(&d3)) / (an * s.powi(3)) - 3.0 * an * d1.dot(&d2) / s.powi(5);
        dk_dt / s
    }

    /// The Frenet frame at `t`, or `None` where it is undefined (zero speed or zero curvature).
    pub fn frenet_frame(&self, t: f64) -> Option<FrenetFrame> {
        let (_, d1, d2) = self.eval_d2(t);
        let s = d1.norm();
        let b = d1.cross(&d2);
        let bn = b.norm();
        if s == 0.0 || bn <= 1e-14 * s * d2.norm() {
            return None;
        }
        let tangent = d1 / s;
        let binormal = b / bn;
        Some(FrenetFrame {
            tangent,
            normal: binormal.cross(&tangent),
            binormal,
        })
    }

    /// The parameters strictly inside the domain where the curve may be only C0: the interior
    /// knots of multiplicity >= degree. A discretizer must put a cutting point on each.
    pub fn c0_breaks(&self) -> Vec<f64> {
        knots::interior_knots(self.degree, &self.knots, self.cpw.len())
            .into_iter()
            .filter(|&(_, m)| m >= self.degree)
            .map(|(u, _)| u)
            .collect()
    }

    /// The axis-aligned box `(min, max)` of the control points, which contains the curve
    /// (convex-hull property, all weights > 0).
    pub fn bounding_box(&self) -> (Point3<f64>, Point3<f64>) {
        hull_box(&self.cpw)
    }

    /// The diagonal of the control-point bounding box: the curve's size, for relative
    /// tolerances.
    pub fn size(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).norm()
    }

    /// True if the curve ends where it starts (to `1e-12` of its size).
    pub fn is_closed(&self) -> bool {
        let (a, b) = self.domain();
        (self.point(a) - self.point(b)).norm() <= 1e-12 * self.size().max(f64::MIN_POSITIVE)
    }

    /// The same curve traversed backwards over the same domain `[a, b]`:
    /// `reversed.point(a + b - t) == self.point(t)`.
    pub fn reversed(&self) -> Self {
        let m = self.knots.len();
        // Reflect about the domain (not the first and last knot, which differ from the domain
        // ends for unclamped knot vectors) so that the domain is kept.
        let (a, b) = self.domain();
        // `a + b - k`, but exact at the domain ends and kept on the right side of them under
        // rounding, so that the mirrored knot vector is sorted and has the same domain.
        let mirror = |k: f64| {
            if k == a {
                b
            } else if k == b {
                a
            } else if k < a {
                (a + b - k).max(b)
            } else if k > b {
                (a + b - k).min(a)
            } else {
                (a + b - k).clamp(a, b)
            }
        };
        let knots = (0..m).map(|i| mirror(self.knots[m - 1 - i])).collect();
        let cpw = self.cpw.iter().rev().copied().collect();
        Self::from_homogeneous_unchecked(self.degree, knots, cpw)
    }

    /// Inserts the knot `u` `times` times (The NURBS Book A5.1); the curve's shape and
    /// parametrisation are unchanged.
    ///
    /// # Errors
    /// [`NurbsError::ParameterOutsideDomain`] if `u` is not inside the domain, and
    /// [`NurbsError::InsertionTooMany`] if the multiplicity would exceed the degree.
    pub fn insert_knot(&self, u: f64, times: usize) -> Result<Self> {
        let (a, b) = self.domain();
        if !(u >= a && u <= b) {
            return Err(NurbsError::ParameterOutsideDomain {
                value: u,
                start: a,
                end: b,
            });
        }
        let p = self.degree;
        let s = knots::multiplicity(&self.knots, u);
        if times == 0 {
            return Ok(self.clone());
        }
        if s + times > p {
            return Err(NurbsError::InsertionTooMany {
                value: u,
                times,
                degree: p,
            });
        }
        // k: the index with knots[k] <= u < knots[k + 1], as A5.1 requires. It may lie beyond
        // the domain's last span when u is the domain end of an unclamped knot vector: the
        // copies of u then sit at k - s + 1 ..= k, and a knot > u exists because s + r <= p.
        let np = self.cpw.len() - 1;
        let mut k = p;
        while self.knots[k + 1] <= u {
            k += 1;
        }
        let r = times;
        let up = &self.knots;
        let mut uq = Vec::with_capacity(up.len() + r);
        uq.extend_from_slice(&up[..=k]);
        uq.extend(std::iter::repeat_n(u, r));
        uq.extend_from_slice(&up[k + 1..]);
        let mut qw = vec![Vector4::zeros(); np + 1 + r];
        qw[..=(k - p)].copy_from_slice(&self.cpw[..=(k - p)]);
        qw[(k - s + r)..=(np + r)].copy_from_slice(&self.cpw[(k - s)..=np]);
        let mut rw: Vec<Vector4<f64>> = (0..=(p - s)).map(|i| self.cpw[k - p + i]).collect();
        let mut l = k - p;
        for j in 1..=r {
            l = k - p + j;
            for i in 0..=(p - j - s) {
                let alpha = (u - up[l + i]) / (up[i + k + 1] - up[l + i]);
                rw[i] = rw[i + 1] * alpha + rw[i] * (1.0 - alpha);
            }
            qw[l] = rw[0];
            qw[k + r - j - s] = rw[p - j - s];
        }
        if l + 1 < k - s {
            qw[(l + 1)..(k - s)].copy_from_slice(&rw[1..(k - s - l)]);
        }
        Ok(Self::from_homogeneous_unchecked(p, uq, qw))
    }

    /// Splits the curve at `t` (strictly inside the domain) into two curves whose union is
    /// this one: the first on `[start, t]`, the second on `[t, end]`, both clamped at `t`.
    ///
    /// # Errors
    /// [`NurbsError::ParameterOutsideDomain`] unless `start < t < end`.
    pub fn split(&self, t: f64) -> Result<(Self, Self)> {
        let (a, b) = self.domain();
        if !(t > a && t < b) {
            return Err(NurbsError::ParameterOutsideDomain {
                value: t,
                start: a,
                end: b,
            });
        }
        let p = self.degree;
        let s = knots::multiplicity(&self.knots, t);
        let full = if s < p {
            self.insert_knot(t, p - s)?
        } else {
            self.clone()
        };
        // Now t has multiplicity >= p; the point shared by both halves is the control point
        // just before the first copy of t beyond the first p.
        let first = full
            .knots
            .iter()
            .position(|&k| k == t)
            .expect("t was inserted");
        let mult = knots::multiplicity(&full.knots, t);
        // Left: knots up to and including p copies of t, then one more t for clamping.
        let mut left_knots: Vec<f64> = full.knots[..first].to_vec();
        left_knots.extend(std::iter::repeat_n(t, p + 1));
        let n_left = left_knots.len() - p - 1;
        let left_cpw = full.cpw[..n_left].to_vec();
        let mut right_knots: Vec<f64> = std::iter::repeat_n(t, p + 1).collect();
        right_knots.extend_from_slice(&full.knots[first + mult..]);
        let n_right = right_knots.len() - p - 1;
        let right_cpw = full.cpw[full.cpw.len() - n_right..].to_vec();
        Ok((
            Self::from_homogeneous_unchecked(p, left_knots, left_cpw),
            Self::from_homogeneous_unchecked(p, right_knots, right_cpw),
        ))
    }
}

/// Scales weights by a power of two (exact: the curve is unchanged, since a NURBS is invariant
/// under scaling all its weights) so that the largest lies in `[1, 2)`, unless it already lies
/// in `[2^-64, 2^64]`. Subnormal weights (only a few significant bits, and `w x` loses more)
/// become normal numbers with the same value ratios.
///
/// # Errors
/// [`NurbsError::WeightRatio`] if the smallest weight would fall below
/// [`MIN_NORMALISED_WEIGHT`], i.e. the largest is more than about `2^970` (1e292) times the
/// smallest: the homogeneous coordinates would lose the precision that evaluation and the
/// discretizer's rounding margin assume.
pub fn normalized_weights(mut w: Vec<f64>, field: &'static str) -> Result<Vec<f64>> {
    let (mut imax, mut imin) = (0, 0);
    for (i, &x) in w.iter().enumerate() {
        if x > w[imax] {
            imax = i;
        }
        if x < w[imin] {
            imin = i;
        }
    }
    let Some(&wmax) = w.get(imax) else {
        return Ok(w);
    };
    let wmin = w[imin];
    if !(wmax >= 2f64.powi(-64) && wmax <= 2f64.powi(64)) {
        // log2 is exact enough for subnormals to find the exponent; the loop fixes any off-by-one.
        let mut k = -(wmax.log2().floor() as i32);
        while scale_pow2(wmax, k) >= 2.0 {
            k -= 1;
        }
        while scale_pow2(wmax, k) < 1.0 {
            k += 1;
        }
        for x in &mut w {
            *x = scale_pow2(*x, k);
        }
    }
    if w[imin] < MIN_NORMALISED_WEIGHT {
        return Err(NurbsError::WeightRatio {
            field,
            index: format!("[{imin}]"),
            ratio: wmax / wmin,
        });
    }
    Ok(w)
}

/// The smallest weight accepted after normalisation (largest weight in `[1, 2)`): `2^-970`.
/// Below it, an underflow in a de Casteljau step (at most `2^-1074` absolute) could be more
/// than `eps` relative to the weights involved.
pub const MIN_NORMALISED_WEIGHT: f64 = f64::from_bits(53u64 << 52);

/// `x * 2^k`, in steps that never overflow or underflow the factor (exact whenever the result
/// is a normal number or `x` was subnormal and the result is not).
pub fn scale_pow2(mut x: f64, mut k: i32) -> f64 {
    while k != 0 {
        let step = k.clamp(-1000, 1000);
        x *= 2f64.powi(step);
        k -= step;
    }
    x
}

/// Projects a homogeneous point `(w x, w y, w z, w)` to `(x, y, z)`.
#[inline]
pub fn project(c: &Vector4<f64>) -> Point3<f64> {
    Point3::new(c.x / c.w, c.y / c.w, c.z / c.w)
}

/// The axis-aligned box `(min, max)` of projected homogeneous control points: with positive
/// weights it contains the curve or surface they define.
pub fn hull_box(cpw: &[Vector4<f64>]) -> (Point3<f64>, Point3<f64>) {
    let mut lo = Point3::from(Vector3::repeat(f64::INFINITY));
    let mut hi = Point3::from(Vector3::repeat(f64::NEG_INFINITY));
    for c in cpw {
        let p = project(c);
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    (lo, hi)
}

/// Curvature `|d1 x d2| / |d1|^3` from the first two derivatives; 0 if `d1 = 0`.
#[inline]
pub fn curvature_of(d1: &Vector3<f64>, d2: &Vector3<f64>) -> f64 {
    let s = d1.norm();
    if s == 0.0 || !s.is_finite() {
        return 0.0;
    }
    // `|d1 x d2| / s^3` overflows for tiny parameter ranges (knots scaled by 1e-50 give
    // `|d1| ~ 1e52`, `|d2| ~ 1e104`): divide by the speed before multiplying.
    let inv = 1.0 / s;
    (d1 * inv).cross(&(d2 * inv)).norm() * inv
}

/// Rational derivatives from homogeneous ones (The NURBS Book A4.2).
#[inline]
pub fn rational_from_homogeneous(a: &[Vector4<f64>], c: &mut [Vector3<f64>]) {
    let w0 = a[0].w;
    for k in 0..a.len() {
        let mut v = a[k].xyz();
        for i in 1..=k {
            v -= c[k - i] * (binomial(k, i) * a[i].w);
        }
        c[k] = v / w0;
    }
}

#[cfg(test)]
mod overflow_tests {
    use super::*;

    #[test]
    fn weight_times_coordinate_overflow_is_refused() {
        // 1.9 needs no normalisation, and 1.9 * 1.5e308 is not finite.
        let e = NurbsCurve::try_new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1.5e308, 0.0, 0.0)],
            Some(vec![1.0, 1.9]),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "weights[1]: weight 1.9e0 times the control point overflows double precision",
            "message names the place"
        );
    }

    #[test]
    fn huge_weights_are_normalised_instead_of_overflowing() {
        // Weights 1 and 1e200 with a point at 1e200: w x overflowed before normalisation.
        let c = NurbsCurve::try_new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![Point3::new(0.0, 0.0, 0.0), Point3::new(1e200, 0.0, 0.0)],
            Some(vec![1.0, 1e200]),
        )
        .expect("normalised weights keep w x finite");
        assert_eq!(c.point(1.0).x, 1e200, "end point exact");
        let w = c.weights();
        assert!(
            w[1] >= 1.0 && w[1] < 2.0,
            "largest weight scaled into [1, 2)"
        );
        assert_eq!(
            w[1] / w[0],
            1e200,
            "ratio kept exactly (power-of-two scaling)"
        );
    }

    #[test]
    fn subnormal_weights_are_scaled_exactly() {
        let w = normalized_weights(vec![1e-318, 0.7e-318, 1e-318], "weights").expect("ratio fine");
        assert!(w[0] >= 1.0 && w[0] < 2.0, "largest weight in [1, 2)");
        // One power of two for every weight, and scaling back gives the very same subnormals:
        // nothing was rounded on the way up.
        let k = (1000..1100)
            .find(|&k| scale_pow2(1e-318, k) == w[0])
            .expect("a power of two");
        assert_eq!(
            scale_pow2(0.7e-318, k),
            w[1],
            "same factor for every weight"
        );
        assert_eq!(
            scale_pow2(w[1], -k),
            0.7e-318,
            "exact: scales back to the input"
        );
        assert_eq!(
            scale_pow2(w[0], -k),
            1e-318,
            "exact: scales back to the input"
        );
    }

    #[test]
    fn weight_ratio_beyond_precision_is_refused() {
        let e = normalized_weights(vec![1e300, 1e-300], "weights").unwrap_err();
        assert_eq!(
            e.to_string(),
            "weights[1]: weights differ by a ratio of inf, beyond double precision",
            "names the smallest weight"
        );
        let e = normalized_weights(vec![1e300, 1e-8], "weights").unwrap_err();
        assert_eq!(
            e.to_string(),
            "weights[1]: weights differ by a ratio of 1.000e308, beyond double precision",
            "readable ratio"
        );
    }

    #[test]
    fn min_normalised_weight_is_2_to_the_minus_970() {
        assert_eq!(
            MIN_NORMALISED_WEIGHT,
            2f64.powi(-970),
            "the documented constant"
        );
    }

    #[test]
    fn curvature_survives_tiny_parameter_ranges() {
        // |d1| ~ 1e52 and |d2| ~ 1e104: the naive |d1 x d2| / |d1|^3 overflows.
        let d1 = Vector3::new(1e52, 0.0, 0.0);
        let d2 = Vector3::new(0.0, 1e104, 0.0);
        assert!((curvature_of(&d1, &d2) - 1.0).abs() < 1e-15, "curvature 1");
    }
}
