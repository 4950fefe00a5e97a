//! [`CurvePoint`]: the one trait through which the later stages evaluate a path's curve (the
//! kinematics' inserted poses, the arc fit's curve test, a cut's contour or its kerf offset),
//! whatever the curve is: a [`NurbsCurve`], a closure, or a composite the pipeline builds.

use nalgebra::Point3;

use crate::NurbsCurve;

/// A curve evaluated at a parameter, mm.
///
/// Implemented by [`NurbsCurve`] (its [`NurbsCurve::point`]) and by every sized
/// `Fn(f64) -> Point3<f64>`, so a caller passes `&|t: f64| ...` (the parameter's type named: a
/// trait object gives the closure no type to infer it from) where a curve is wanted, and an
/// existing `f: &dyn Fn(f64) -> Point3<f64>` as `&f` (a reference to a `Fn` is one). Where paths are solved in parallel
/// (`kerf_kinematics::PathCurve`) the curve must also be `Sync`.
pub trait CurvePoint {
    /// The point at parameter `t`, which the caller keeps within the curve's domain.
    fn point_at(&self, t: f64) -> Point3<f64>;
}

impl CurvePoint for NurbsCurve {
    fn point_at(&self, t: f64) -> Point3<f64> {
        self.point(t)
    }
}

impl<F: Fn(f64) -> Point3<f64>> CurvePoint for F {
    fn point_at(&self, t: f64) -> Point3<f64> {
        self(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_nurbs_curve_and_a_closure_evaluate_alike() {
        let c = NurbsCurve::try_new(
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 4.0, 6.0)],
            None,
        )
        .expect("a line");
        // The line's own closed form, independent of the evaluator.
        let f = |t: f64| Point3::new(2.0 * t, 4.0 * t, 6.0 * t);
        // A caller's own trait object is a curve too.
        let g: &dyn Fn(f64) -> Point3<f64> = &f;
        let curves: [&dyn CurvePoint; 3] = [&c, &f, &g];
        for k in curves {
            for t in [0.0, 0.25, 0.7, 1.0] {
                assert!((k.point_at(t) - f(t)).norm() < 1e-15, "at {t}");
            }
        }
    }
}
