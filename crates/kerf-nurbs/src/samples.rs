//! Seeded sample curves for tests, examples and benchmarks: the same input on every machine
//! and every run, so that counts and timings can be compared.

use nalgebra::Point3;

use crate::NurbsCurve;

/// A small deterministic generator (64-bit LCG, top 53 bits) of numbers in `[0, 1)`.
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// A generator with this seed.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next number in `[0, 1)`.
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `count` smooth random curves of `degree`: clamped, uniform simple knots, unit weights,
/// `degree + 9` control points marching along x (`20 i + U[0, 10)`, `U[0, 60)`, `U[0, 20)` mm),
/// so each is about 200 mm long and curved like a free-form cut contour.
///
/// ```
/// let a = kerf_nurbs::smooth_random_curves(3, 4, 7);
/// let b = kerf_nurbs::smooth_random_curves(3, 4, 7);
/// assert_eq!(a, b, "seeded: the same curves every time");
/// ```
pub fn smooth_random_curves(degree: usize, count: usize, seed: u64) -> Vec<NurbsCurve> {
    let mut rnd = Lcg::new(seed);
    (0..count)
        .map(|_| {
            let n = degree + 9;
            let pts: Vec<Point3<f64>> = (0..n)
                .map(|i| {
                    let x = 20.0 * i as f64 + 10.0 * rnd.next_f64();
                    Point3::new(x, 60.0 * rnd.next_f64(), 20.0 * rnd.next_f64())
                })
                .collect();
            let mut knots = vec![0.0; degree + 1];
            let inner = n - degree - 1;
            knots.extend((1..=inner).map(|i| i as f64 / (inner + 1) as f64));
            knots.extend(vec![1.0; degree + 1]);
            NurbsCurve::new(degree, knots, pts, None)
        })
        .collect()
}
