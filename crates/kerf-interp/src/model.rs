//! What the interpolator needs from a machine: [`AxisModel`], with [`AxisLimits`].
//!
//! The interpolator moves the tool tip along lines and arcs in the workpiece frame and the two
//! rotary axes in proportion to the distance travelled (paper 000, eq 4 and 9-12). Every cycle
//! it asks the machine model for the linear axes that put the tip where it must be with the
//! rotary axes where they are ([`AxisModel::linear_axes`]; paper 000 eq 16 for its head). The
//! block ends come from the inverse kinematics ([`AxisModel::inverse`]), which chooses the
//! solution and the turn of a continuous C for continuity.
//!
//! kerf's machines (`kerf.machine/1`, four types) live in `kerf-kinematics`;
//! [`crate::MachineModel`] adapts them. The trait keeps the interpolator's needs in one small
//! place (and lets a controller plug in its own kinematics); [`PaperAcHead`], the head of paper 000,
//! is a self-contained reference implementation for tests, examples and benches.

use kerf_kinematics::{nearest_solution, Axes};
use nalgebra::{Point3, Vector3};

use crate::error::{positive, InterpError, Result};

/// Per-axis limits of a machine, in the order `[X, Y, Z, tilt, C]`.
///
/// Units are **per second**: mm/s and deg/s for velocities, mm/s^2 and deg/s^2 for
/// accelerations. `kerf.machine/1` gives velocities per minute; use
/// [`AxisLimits::from_machine_units`] to convert.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisLimits {
    /// `[min, max]` of each axis, `None` for a continuous (unlimited) axis.
    pub range: [Option<[f64; 2]>; 5],
    /// Largest speed of each axis, mm/s or deg/s.
    pub max_velocity: [f64; 5],
    /// Largest acceleration of each axis, mm/s^2 or deg/s^2.
    pub max_acceleration: [f64; 5],
    /// Largest jerk of each axis, mm/s^3 or deg/s^3 (`max_jerk` of `kerf.machine/1`); `None`:
    /// the plan is acceleration-limited, with `Some` it is jerk-limited (S-curve) on every axis.
    pub max_jerk: Option<[f64; 5]>,
}

/// The slack of [`AxisLimits::contains`]: a value this far past a range's end (mm or
/// degrees) is still inside (a solution or set-point on the limit, rounded).
pub const RANGE_SLACK: f64 = 1e-9;

impl AxisLimits {
    /// True when `v` lies in axis `k`'s range, [`RANGE_SLACK`] allowed past either end
    /// (always for a continuous axis; never for NaN on a limited one).
    pub fn contains(&self, k: usize, v: f64) -> bool {
        self.range[k].is_none_or(|[lo, hi]| v >= lo - RANGE_SLACK && v <= hi + RANGE_SLACK)
    }

    /// True when every axis of `q` lies in its range ([`AxisLimits::contains`]).
    pub fn contain(&self, q: &Axes) -> bool {
        (0..5).all(|k| self.contains(k, q[k]))
    }

    /// Limits from the units of `kerf.machine/1`: velocities in mm/min or deg/min (divided by
    /// 60 here), accelerations in mm/s^2 or deg/s^2.
    ///
    /// # Errors
    /// [`InterpError::BadParameter`] if a velocity or acceleration is not finite and > 0, or a
    /// range is not finite with `min <= max`.
    pub fn from_machine_units(
        range: [Option<[f64; 2]>; 5],
        max_velocity_per_min: [f64; 5],
        max_acceleration: [f64; 5],
    ) -> Result<Self> {
        let mut v = [0.0; 5];
        for k in 0..5 {
            v[k] = positive("max_velocity", max_velocity_per_min[k])? / 60.0;
        }
        let limits = Self {
            range,
            max_velocity: v,
            max_acceleration,
            max_jerk: None,
        };
        limits.validate()?;
        Ok(limits)
    }

    /// Checks every limit.
    ///
    /// # Errors
    /// [`InterpError::BadParameter`] as in [`AxisLimits::from_machine_units`].
    pub fn validate(&self) -> Result<()> {
        for k in 0..5 {
            positive("max_velocity", self.max_velocity[k])?;
            positive("max_acceleration", self.max_acceleration[k])?;
            if let Some(j) = self.max_jerk {
                positive("max_jerk", j[k])?;
            }
            if let Some([lo, hi]) = self.range[k] {
                if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                    return Err(InterpError::BadParameter {
                        name: "range",
                        value: lo,
                        reason: "must be finite with min <= max",
                    });
                }
            }
        }
        Ok(())
    }
}

/// A five-axis machine as the interpolator sees it.
///
/// Axis vectors are `[X, Y, Z, tilt, C]`: mm and degrees, as in `kerf.machine/1`.
pub trait AxisModel {
    /// The machine's name, written in the header of G-code programs.
    fn name(&self) -> &str;

    /// The names of the five axes in order, e.g. `["X", "Y", "Z", "A", "C"]` (the CSV header
    /// and the G-code words).
    fn axis_names(&self) -> [&str; 5];

    /// The axis limits (per second).
    fn limits(&self) -> &AxisLimits;

    /// Inverse kinematics: the axes that put the tip at `tip` with tool axis `axis` (unit,
    /// from the tip toward the head). Among the solutions, the one nearest `previous` (least
    /// rotary travel, continuous C turned to the nearest multiple of 360) within the limits;
    /// at the pole C keeps its previous value.
    ///
    /// # Errors
    /// [`InterpError::Kinematics`] (with `index` 0; callers set the point index) when no
    /// solution is within the limits.
    fn inverse(
        &self,
        tip: &Point3<f64>,
        axis: &Vector3<f64>,
        previous: Option<&Axes>,
    ) -> Result<Axes>;

    /// The linear axes `[X, Y, Z]` that put the tip at `tip` when the rotary axes stand at
    /// `tilt` and `c` (degrees). Called once per interpolation cycle: keep it cheap.
    fn linear_axes(&self, tip: &Point3<f64>, tilt: f64, c: f64) -> [f64; 3];

    /// The tool axis (unit, workpiece frame) when the rotary axes stand at `tilt` and `c`.
    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64>;

    /// Forward kinematics: the tip (workpiece frame) when the axes stand at `q`.
    ///
    /// The default inverts [`AxisModel::linear_axes`]: for fixed rotary axes every rigid
    /// five-axis machine places its linear axes as `XYZ = M tip + o` with `M` a rotation, so
    /// `o` is the image of the origin, `M`'s columns the images of the unit vectors less `o`,
    /// and `tip = M^T (XYZ - o)` (four calls). A model with its own forward kinematics should
    /// say so.
    fn tip(&self, q: &Axes) -> Point3<f64> {
        let (tilt, c) = (q.tilt, q.c);
        let at = |p: Point3<f64>| Vector3::from(self.linear_axes(&p, tilt, c));
        let o = at(Point3::origin());
        let m = nalgebra::Matrix3::from_columns(&[
            at(Point3::new(1.0, 0.0, 0.0)) - o,
            at(Point3::new(0.0, 1.0, 0.0)) - o,
            at(Point3::new(0.0, 0.0, 1.0)) - o,
        ]);
        Point3::from(m.transpose() * (Vector3::new(q[0], q[1], q[2]) - o))
    }

    /// The `kerf.machine/1` machine behind the model, if there is one: dialects for a
    /// controller that runs its own kinematics ([`crate::Dialect::LinuxcncTcp`]) need its type
    /// and parameters to name the controller's kinematics module. `None` by default.
    fn machine(&self) -> Option<&kerf_kinematics::Machine> {
        None
    }
}

/// A reference to a model is the model (so that `&dyn AxisModel`, passed as `&&dyn
/// AxisModel`, goes wherever a sized model does).
impl<T: AxisModel + ?Sized> AxisModel for &T {
    fn name(&self) -> &str {
        (**self).name()
    }

    fn axis_names(&self) -> [&str; 5] {
        (**self).axis_names()
    }

    fn limits(&self) -> &AxisLimits {
        (**self).limits()
    }

    fn inverse(
        &self,
        tip: &Point3<f64>,
        axis: &Vector3<f64>,
        previous: Option<&Axes>,
    ) -> Result<Axes> {
        (**self).inverse(tip, axis, previous)
    }

    fn linear_axes(&self, tip: &Point3<f64>, tilt: f64, c: f64) -> [f64; 3] {
        (**self).linear_axes(tip, tilt, c)
    }

    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64> {
        (**self).tool_axis(tilt, c)
    }

    fn tip(&self, q: &Axes) -> Point3<f64> {
        (**self).tip(q)
    }

    fn machine(&self) -> Option<&kerf_kinematics::Machine> {
        (**self).machine()
    }
}

/// Paper 000's laser head (`kerf.machine/1` type `ac-head`): `u = Rz(C) Rx(A) ez`,
/// `XYZ = P + r_a u - r_c (cos C, sin C, 0)` (paper 000 eq 16).
///
/// A reference implementation for tests, examples and benches; kerf's machines, all four
/// types, come from `kerf-kinematics`.
#[derive(Debug, Clone, PartialEq)]
pub struct PaperAcHead {
    /// Machine name.
    pub name: String,
    /// Rotation radius of A, mm.
    pub r_a: f64,
    /// Rotation radius of C, mm.
    pub r_c: f64,
    /// Limits (per second).
    pub limits: AxisLimits,
    /// A pose whose tool axis is within this angle (degrees) of +z counts as at the pole, where
    /// C keeps its previous value (`formats.md`: `pole_tolerance`, default 1e-6 rad,
    /// [`kerf_kinematics::DEFAULT_POLE_TOLERANCE_DEG`]).
    pub pole_tolerance_deg: f64,
}

impl PaperAcHead {
    /// The example machine of `formats.md` ("paper-000 laser head": `r_a` 180, `r_c` 95,
    /// X +-1500, Y +-800, Z -100..600, A +-135, C continuous; 60/60/30 m/min, 36000 deg/min;
    /// 10/10/8 m/s^2, 20000 deg/s^2).
    pub fn paper_000() -> Self {
        let limits = AxisLimits::from_machine_units(
            [
                Some([-1500.0, 1500.0]),
                Some([-800.0, 800.0]),
                Some([-100.0, 600.0]),
                Some([-135.0, 135.0]),
                None,
            ],
            [60000.0, 60000.0, 30000.0, 36000.0, 36000.0],
            [10000.0, 10000.0, 8000.0, 20000.0, 20000.0],
        )
        .unwrap_or_else(|_| unreachable!("constant limits are valid"));
        Self {
            name: "paper-000 laser head".to_string(),
            r_a: 180.0,
            r_c: 95.0,
            limits,
            pole_tolerance_deg: kerf_kinematics::DEFAULT_POLE_TOLERANCE_DEG,
        }
    }
}

impl AxisModel for PaperAcHead {
    fn name(&self) -> &str {
        &self.name
    }

    fn axis_names(&self) -> [&str; 5] {
        ["X", "Y", "Z", "A", "C"]
    }

    fn limits(&self) -> &AxisLimits {
        &self.limits
    }

    fn inverse(
        &self,
        tip: &Point3<f64>,
        axis: &Vector3<f64>,
        previous: Option<&Axes>,
    ) -> Result<Axes> {
        let kin = |reason: String| InterpError::unreachable(reason);
        let n = axis.norm();
        if !(n.is_finite() && (n - 1.0).abs() < 1e-6 && tip.coords.iter().all(|v| v.is_finite())) {
            return Err(kin(format!("tool axis must be a unit vector (norm {n})")));
        }
        let u = axis / n;
        let (prev_a, prev_c) = previous.map_or((0.0, 0.0), |p| (p[3], p[4]));
        // u = (sin A sin C, -sin A cos C, cos A): A = acos(k), C = atan2(i, -j); the second
        // solution is (-A, C + 180).
        let a = u.z.clamp(-1.0, 1.0).acos().to_degrees();
        let sin_a = (u.x * u.x + u.y * u.y).sqrt();
        let candidates: Vec<(f64, f64)> =
            if sin_a.atan2(u.z.abs()) < self.pole_tolerance_deg.to_radians() && u.z > 0.0 {
                vec![(0.0, prev_c)]
            } else {
                let c = u.x.atan2(-u.y).to_degrees();
                vec![(a, c), (-a, c + 180.0)]
            };
        // X, Y, Z do not depend on whole turns of A or C: placed once per solution, the turns
        // chosen by kerf-kinematics' one rule.
        let solutions = candidates.into_iter().map(|(a, c)| {
            let [x, y, z] = self.linear_axes(tip, a, c);
            Axes::new(x, y, z, a, c)
        });
        let previous = Axes::new(0.0, 0.0, 0.0, prev_a, prev_c);
        nearest_solution(solutions, &previous, |q| self.limits.contain(q))
            .ok_or_else(|| kin("no solution within the axis ranges".into()))
    }

    #[inline]
    fn linear_axes(&self, tip: &Point3<f64>, tilt: f64, c: f64) -> [f64; 3] {
        let (sa, ca) = tilt.to_radians().sin_cos();
        let (sc, cc) = c.to_radians().sin_cos();
        [
            tip.x + self.r_a * sa * sc - self.r_c * cc,
            tip.y - self.r_a * sa * cc - self.r_c * sc,
            tip.z + self.r_a * ca,
        ]
    }

    #[inline]
    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64> {
        let (sa, ca) = tilt.to_radians().sin_cos();
        let (sc, cc) = c.to_radians().sin_cos();
        Vector3::new(sa * sc, -sa * cc, ca)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_eq16_and_inverse_round_trip() {
        let m = PaperAcHead::paper_000();
        let tip = Point3::new(10.0, -20.0, 5.0);
        let u = m.tool_axis(30.0, 40.0);
        let q = m.inverse(&tip, &u, None).expect("reachable");
        assert!((q[3] - 30.0).abs() < 1e-9, "A {}", q[3]);
        assert!((q[4] - 40.0).abs() < 1e-9, "C {}", q[4]);
        // Eq 16 by hand.
        let (a, c) = (30f64.to_radians(), 40f64.to_radians());
        let x = 10.0 + 180.0 * a.sin() * c.sin() - 95.0 * c.cos();
        let y = -20.0 - 180.0 * a.sin() * c.cos() - 95.0 * c.sin();
        let z = 5.0 + 180.0 * a.cos();
        assert!((q[0] - x).abs() < 1e-9 && (q[1] - y).abs() < 1e-9 && (q[2] - z).abs() < 1e-9);
    }

    #[test]
    fn continuity_picks_second_solution_and_turn() {
        let m = PaperAcHead::paper_000();
        let tip = Point3::origin();
        let u = m.tool_axis(-20.0, 370.0 + 180.0);
        let prev = Axes::new(0.0, 0.0, 0.0, -19.0, 545.0);
        let q = m.inverse(&tip, &u, Some(&prev)).expect("reachable");
        assert!((q[3] + 20.0).abs() < 1e-9, "A {}", q[3]);
        assert!((q[4] - 550.0).abs() < 1e-9, "C {}", q[4]);
        // At the pole C stays.
        let q = m.inverse(&tip, &Vector3::z(), Some(&prev)).expect("pole");
        assert_eq!(q[4], 545.0, "C kept at the pole");
    }

    #[test]
    fn bad_limits_and_axes_are_errors() {
        assert!(AxisLimits::from_machine_units([None; 5], [f64::NAN; 5], [1.0; 5]).is_err());
        assert!(AxisLimits::from_machine_units([None; 5], [1.0; 5], [0.0; 5]).is_err());
        let m = PaperAcHead::paper_000();
        let e = m.inverse(&Point3::origin(), &Vector3::new(0.0, 0.0, 2.0), None);
        assert!(matches!(e, Err(InterpError::Kinematics { .. })), "{e:?}");
    }
}
