//! kerf's machines (`kerf.machine/1`, from `kerf-kinematics`) as [`AxisModel`]s, and
//! [`Station`]s from kerf-kinematics' solved paths.
//!
//! ```
//! use kerf_interp::{AxisModel, MachineModel};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/machines/ac_head.json");
//! let model = MachineModel::new(kerf_kinematics::Machine::read(path).unwrap())?;
//! assert_eq!(model.axis_names(), ["X", "Y", "Z", "A", "C"]);
//! assert_eq!(model.limits().max_velocity[0], 1000.0, "60000 mm/min = 1000 mm/s");
//! # Ok::<(), kerf_interp::InterpError>(())
//! ```

use kerf_kinematics::{nearest_solution, Axes, Machine, Pose, SolvedPath};
use nalgebra::{Point3, Vector3};

use crate::block::Station;
use crate::error::{InterpError, Result};
use crate::model::{AxisLimits, AxisModel};

/// A `kerf.machine/1` machine (any of the four kinematic types) as the interpolator sees it.
#[derive(Debug, Clone)]
pub struct MachineModel {
    /// The machine.
    pub machine: Machine,
    /// A tool axis within this angle (degrees) of the C axis is at the pole, where C keeps its
    /// previous value ([`AxisModel::inverse`] only; kerf-kinematics' `solve_path` has its own
    /// option). Default 1e-6 rad, as `formats.md` ([`kerf_kinematics::DEFAULT_POLE_TOLERANCE_DEG`]).
    pub pole_tolerance_deg: f64,
    limits: AxisLimits,
}

impl MachineModel {
    /// Wraps `machine`; its velocities (per minute in the file) become per second.
    ///
    /// # Errors
    /// [`InterpError::BadParameter`] for limits that are not finite and > 0 (a machine read by
    /// kerf-kinematics has none).
    pub fn new(machine: Machine) -> Result<Self> {
        let range = machine.limits.map(|r| r.map(|r| [r.min, r.max]));
        let mut limits =
            AxisLimits::from_machine_units(range, machine.max_velocity, machine.max_acceleration)?;
        limits.max_jerk = machine.max_jerk;
        limits.validate()?;
        Ok(Self {
            machine,
            pole_tolerance_deg: kerf_kinematics::DEFAULT_POLE_TOLERANCE_DEG,
            limits,
        })
    }
}

impl AxisModel for MachineModel {
    fn name(&self) -> &str {
        &self.machine.name
    }

    fn axis_names(&self) -> [&str; 5] {
        self.machine.axis_names()
    }

    fn limits(&self) -> &AxisLimits {
        &self.limits
    }

    /// Both solutions of the kinematics (at the pole: the one keeping the previous C), chosen
    /// by kerf-kinematics' one rule ([`kerf_kinematics::nearest_solution`]: the turns nearest
    /// the previous axes, the least rotary travel within the ranges). kerf-kinematics' `solve_path`
    /// does this along a whole path with more care (look-ahead at the ranges, inserted points);
    /// prefer its output with [`stations_from_solved`].
    fn inverse(
        &self,
        tip: &Point3<f64>,
        axis: &Vector3<f64>,
        previous: Option<&Axes>,
    ) -> Result<Axes> {
        let k = &self.machine.kinematics;
        let n = axis.norm();
        if !(n.is_finite() && (n - 1.0).abs() < 1e-6 && tip.coords.iter().all(|v| v.is_finite())) {
            return Err(InterpError::unreachable(format!(
                "tool axis must be a unit vector (norm {n})"
            )));
        }
        let pose = Pose {
            position: *tip,
            axis: *axis,
        };
        let (prev_t, prev_c) = previous.map_or((0.0, 0.0), |p| (p[3], p[4]));
        let candidates: Vec<Axes> = if k.pole_angle(axis) <= self.pole_tolerance_deg.to_radians() {
            vec![k.inverse_with_c(&pose, prev_c)]
        } else {
            k.inverse(&pose).to_vec()
        };
        let previous = Axes::new(0.0, 0.0, 0.0, prev_t, prev_c);
        nearest_solution(candidates, &previous, |q| self.limits.contain(q))
            .ok_or_else(|| InterpError::unreachable("no solution within the axis ranges"))
    }

    /// The forward kinematics give the tool axis of `(tilt, c)`; `inverse_with_c` at that C
    /// returns the same tilt and places X, Y, Z for the tip. Two trait calls per cycle: a
    /// `place(tip, tilt, c)` on kerf-kinematics' `Kinematics` trait would save the first.
    #[inline]
    fn linear_axes(&self, tip: &Point3<f64>, tilt: f64, c: f64) -> [f64; 3] {
        let k = &self.machine.kinematics;
        let u = k.forward(&Axes::new(0.0, 0.0, 0.0, tilt, c)).axis;
        let q = k.inverse_with_c(
            &Pose {
                position: *tip,
                axis: u,
            },
            c,
        );
        [q.x, q.y, q.z]
    }

    fn tool_axis(&self, tilt: f64, c: f64) -> Vector3<f64> {
        self.machine
            .kinematics
            .forward(&Axes::new(0.0, 0.0, 0.0, tilt, c))
            .axis
    }

    /// kerf-kinematics' forward kinematics.
    fn tip(&self, q: &Axes) -> Point3<f64> {
        self.machine.kinematics.forward(q).position
    }

    fn machine(&self) -> Option<&Machine> {
        Some(&self.machine)
    }
}

/// Stations from a path solved by kerf-kinematics (its continuity, ranges, pole handling and
/// points inserted against the non-linearity error). Cutting points get their curve parameter
/// from `params` (the toolpath's, one per cutting point), inserted points none (the arc fit then
/// tests the polyline there).
///
/// # Errors
/// [`InterpError::LengthMismatch`] when `params` does not have one entry per cutting point.
pub fn stations_from_solved(solved: &SolvedPath, params: Option<&[f64]>) -> Result<Vec<Station>> {
    if let Some(p) = params {
        let cutting = solved.source.iter().flatten().count();
        let needed = solved.source.iter().flatten().max().map_or(0, |m| m + 1);
        if p.len() < needed {
            return Err(InterpError::LengthMismatch {
                what: "params",
                got: p.len(),
                expected: cutting,
            });
        }
    }
    Ok(solved
        .poses
        .iter()
        .zip(&solved.axes)
        .zip(&solved.source)
        .map(|((pose, a), src)| Station {
            tip: pose.position,
            axis: pose.axis,
            param: params.zip(*src).map(|(ps, i)| ps[i]),
            axes: *a,
        })
        .collect())
}

/// Stations from a `kerf.axes/1` path in the file's arrays: `positions[n]` (`[X, Y, Z, tilt,
/// C]`) reaches `poses[n]` (`[x, y, z, i, j, k]`); no curve parameters (the file has none).
///
/// # Errors
/// [`InterpError::LengthMismatch`] when the two arrays differ in length.
pub fn stations_from_axes(positions: &[[f64; 5]], poses: &[[f64; 6]]) -> Result<Vec<Station>> {
    if positions.len() != poses.len() {
        return Err(InterpError::LengthMismatch {
            what: "positions",
            got: positions.len(),
            expected: poses.len(),
        });
    }
    Ok(positions
        .iter()
        .zip(poses)
        .map(|(q, p)| {
            let pose = Pose::from_array(*p);
            Station {
                tip: pose.position,
                axis: pose.axis,
                param: None,
                axes: Axes::from_array(*q),
            }
        })
        .collect())
}
