//! A curve translated to a local origin, exactly, so that floating-point rounding in its
//! evaluation is relative to the curve's size and not to its distance from the origin.
//!
//! A curve 10 mm long placed 1e6 mm from the origin evaluates with errors of about
//! `eps * 1e6 ~ 2e-10` mm in global coordinates, far more than `eps` times its size. Every
//! computation that must resolve errors near the curve's own scale (the discretizer's
//! certificate, the checker's measurement) works on `C(t) - O` instead, with `O` chosen so that
//! the translation of the control points introduces no rounding at all (`docs/nurbs.md`,
//! "Local origin").

use nalgebra::{Point3, Vector3, Vector4};

use crate::NurbsCurve;

/// The curve `C(t) - O` and the origin `O`.
///
/// `O` is the centre of the control points' box rounded to a multiple of a power of two
/// `g >= ` the box's extent; then every coordinate difference `P_i - O` is exact (checked with
/// TwoSum; if any were inexact, `O = 0` and the curve is the original). The homogeneous control
/// points are rebuilt from the exact differences and the weights, so the local curve's rounding
/// is that of its own small coordinates.
#[derive(Debug, Clone)]
pub struct LocalCurve {
    curve: NurbsCurve,
    origin: Vector3<f64>,
    representation_mm: f64,
    magnitudes: Vec<f64>,
    max_coordinate: f64,
    unit_weights: bool,
}

impl LocalCurve {
    /// Translates `curve` to its local origin (one pass over the control points).
    pub fn new(curve: &NurbsCurve) -> Self {
        let hom = curve.homogeneous_points();
        // The control points as the file gives them: (w P) / w, the curve's own projection.
        let point = |c: &Vector4<f64>| crate::project(c).coords;
        let (lo, hi) = curve.bounding_box();
        let extent = (hi - lo).amax();
        let centre = (lo.coords + hi.coords) * 0.5;
        let g = if extent > 0.0 && extent.is_finite() {
            2f64.powi(extent.log2().ceil() as i32)
        } else {
            1.0
        };
        let mut origin = centre.map(|c| (c / g).round() * g);
        if !origin.iter().all(|c| c.is_finite()) {
            origin = Vector3::zeros();
        }
        // One pass: the translated homogeneous points, whether every translation is exact,
        // the largest coordinate, and the weights' kinds.
        let mut cpw = Vec::with_capacity(hom.len());
        let mut magnitudes = Vec::with_capacity(hom.len());
        let (mut exact, mut max_coordinate) = (true, 0.0f64);
        let (mut powers_of_two, mut unit_weights) = (true, true);
        for c in hom {
            let (p, w) = (point(c), c.w);
            let mut d = Vector3::zeros();
            for k in 0..3 {
                let (v, ok) = exact_diff(p[k], origin[k]);
                d[k] = v;
                exact &= ok;
            }
            cpw.push(Vector4::new(d.x * w, d.y * w, d.z * w, w));
            magnitudes.push(d.amax());
            max_coordinate = max_coordinate.max(p.amax());
            powers_of_two &= is_power_of_two(w);
            unit_weights &= w == 1.0;
        }
        if !exact {
            origin = Vector3::zeros();
            for ((q, m), c) in cpw.iter_mut().zip(&mut magnitudes).zip(hom) {
                let (p, w) = (point(c), c.w);
                *q = Vector4::new(p.x * w, p.y * w, p.z * w, w);
                *m = p.amax();
            }
        }
        let representation_mm = if powers_of_two {
            0.0
        } else {
            4.0 * f64::EPSILON * max_coordinate
        };
        Self {
            curve: NurbsCurve::from_homogeneous_unchecked(
                curve.degree(),
                curve.knots().to_vec(),
                cpw,
            ),
            origin,
            representation_mm,
            magnitudes,
            max_coordinate,
            unit_weights,
        }
    }

    /// The translated curve `C(t) - O`: same degree, knots, weights and domain.
    pub fn curve(&self) -> &NurbsCurve {
        &self.curve
    }

    /// The translated curve, moved out (no copy).
    pub fn into_curve(self) -> NurbsCurve {
        self.curve
    }

    /// The local origin `O` (zero when no exact translation exists).
    pub fn origin(&self) -> Vector3<f64> {
        self.origin
    }

    /// `p - O`: a point of the global frame in the local one (rounded relative to `|p - O|`).
    pub fn to_local(&self, p: &Point3<f64>) -> Point3<f64> {
        p - self.origin
    }

    /// How far (mm) the stored curve may lie from the curve of the file it was read from:
    /// `4 eps max |P_i|_inf` when some weight is not a power of two (the control points are
    /// kept as `w P`, so `P` is recovered within two ulps), else 0. A bound proven about the
    /// file's curve and a measurement on the stored one may differ by this much.
    pub fn representation_mm(&self) -> f64 {
        self.representation_mm
    }

    /// `|P_i - O|_inf` for each control point `i` (`P_i` as the file gives it, `(w P) / w`):
    /// exact, since the translation is. The rounding of every convex combination of control
    /// points is bounded by these magnitudes.
    pub fn magnitudes(&self) -> &[f64] {
        &self.magnitudes
    }

    /// `max_i |P_i|_inf` in the global frame (mm): one ulp of it is the resolution of a
    /// point written in global coordinates.
    pub fn max_coordinate(&self) -> f64 {
        self.max_coordinate
    }

    /// Whether every weight is exactly 1 (a polynomial curve): every homogeneous weight a
    /// convex combination of the control points produces is then exactly 1.
    pub fn unit_weights(&self) -> bool {
        self.unit_weights
    }
}

/// `a - b` and whether it is exact (Knuth's TwoSum error term is zero).
fn exact_diff(a: f64, b: f64) -> (f64, bool) {
    let s = a - b;
    let bb = s - a;
    let err = (a - (s - bb)) + (-b - bb);
    (s, err == 0.0)
}

/// Whether `w` is an exact power of two (normal or subnormal), read from its bits: then `w x`
/// and `(w x) / w` are exact for every normal `x`.
pub fn is_power_of_two(w: f64) -> bool {
    if !(w > 0.0 && w.is_finite()) {
        return false;
    }
    let bits = w.to_bits();
    let mantissa = bits & ((1u64 << 52) - 1);
    if bits >> 52 == 0 {
        mantissa.is_power_of_two()
    } else {
        mantissa == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn far_control_points_translate_exactly() {
        // A cubic 1e6 mm away: the local curve is the original moved by -O, bit for bit at
        // the control points, and O sits within the box's extent of its centre.
        let pts = vec![
            Point3::new(1e6 + 0.1, -2e6 + 0.3, 7.0),
            Point3::new(1e6 + 3.7, -2e6 + 1.9, 7.5),
            Point3::new(1e6 + 5.2, -2e6 - 0.4, 8.25),
            Point3::new(1e6 + 9.9, -2e6 + 0.8, 6.0),
        ];
        let c = NurbsCurve::new(
            3,
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            pts.clone(),
            None,
        );
        let l = LocalCurve::new(&c);
        let o = l.origin();
        assert!(o.x != 0.0 && o.y != 0.0, "translated: {o}");
        for (p, q) in pts.iter().zip(l.curve().control_points()) {
            assert_eq!(q.coords + o, p.coords, "exact translation");
        }
        assert_eq!(l.representation_mm(), 0.0, "unit weights are exact");
        // The local curve evaluates with errors of its own size: compare with the original
        // curve at points where both are exact enough to agree within global rounding.
        let t = 0.37;
        let global = c.point(t);
        let local = l.curve().point(t) + o;
        assert!((global - local).norm() < 1e-9, "{global} vs {local}");
    }

    #[test]
    fn representation_term_only_for_weights_off_powers_of_two() {
        let pts = vec![
            Point3::new(100.0, 0.0, 0.0),
            Point3::new(100.0, 100.0, 0.0),
            Point3::new(0.0, 100.0, 0.0),
        ];
        let knots = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let pow2 = NurbsCurve::new(2, knots.clone(), pts.clone(), Some(vec![1.0, 0.5, 1.0]));
        assert_eq!(
            LocalCurve::new(&pow2).representation_mm(),
            0.0,
            "powers of two"
        );
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let arc = NurbsCurve::new(2, knots, pts, Some(vec![1.0, h, 1.0]));
        let rep = LocalCurve::new(&arc).representation_mm();
        assert_eq!(rep, 4.0 * f64::EPSILON * 100.0, "4 eps max |P|");
    }

    #[test]
    fn powers_of_two_read_from_the_bits() {
        for k in -1074..1024 {
            assert!(is_power_of_two(crate::scale_pow2(1.0, k)), "2^{k}");
        }
        // The value log2().fract() == 0 accepted although it is not a power of two.
        assert!(
            !is_power_of_two(2f64.powi(-5) * (1.0 + f64::EPSILON)),
            "2^-5 (1 + eps)"
        );
        for w in [0.0, -1.0, 3.0, 0.75, f64::NAN, f64::INFINITY] {
            assert!(!is_power_of_two(w), "{w}");
        }
    }
}
