//! The [`Kinematics`] trait: forward and inverse kinematics of one machine type.

use std::fmt;

use nalgebra::Vector3;

use crate::pose::{Axes, Pose};
use crate::rotation::angle_to_z_line;

/// Forward and inverse kinematics of one kinematic type of `kerf.machine/1`, with its
/// parameters.
///
/// Angles are degrees at this boundary (as in the files). Implementations must be pure and
/// allocation-free in [`Kinematics::forward`], [`Kinematics::inverse`] and
/// [`Kinematics::inverse_with_c`]; they are called millions of times per path.
///
/// To add a machine type: one new file implementing this trait and a `TYPE` entry, and one
/// line in the registry (`src/registry.rs`).
pub trait Kinematics: fmt::Debug + Send + Sync {
    /// The `kinematics.type` of the machine file, e.g. `"ac-head"`.
    fn type_name(&self) -> &'static str;

    /// The name of the tilt axis, `"A"` or `"B"`.
    fn tilt_name(&self) -> &'static str;

    /// The pose (tool tip and unit tool axis in the workpiece frame) that the axes put the tool
    /// in: exactly the formula of `docs/formats.md`.
    fn forward(&self, axes: &Axes) -> Pose;

    /// Both inverse solutions of `pose`: `[(t, C), (-t, C + 180)]` with `t` and `C` from
    /// `atan2` (so `C` of the first in `(-180, 180]` up to the type's sign convention), and
    /// X, Y, Z placing the tip exactly at `pose.position`. Only the direction of `pose.axis`
    /// matters. At the pole (axis parallel to C) C is arbitrary; the path solver then uses
    /// [`Kinematics::inverse_with_c`] instead.
    fn inverse(&self, pose: &Pose) -> [Axes; 2];

    /// The axes with C fixed at `c` (degrees): the tilt bringing the tool axis closest to
    /// `pose.axis`, and X, Y, Z placing the tip exactly at `pose.position`. Used at the pole,
    /// where C keeps its previous value; the tool axis is then off by the angle between
    /// `pose.axis` and the C axis at most.
    fn inverse_with_c(&self, pose: &Pose, c: f64) -> Axes;

    /// The pivot length (mm): the distance from the tool tip to the tilt axis (for tables,
    /// from the C table's rotation point to the tilt axis, an estimate of the part's distance
    /// from it). The tip error of a tool-axis error `angle` (radians) is about
    /// `pivot_length * angle`.
    fn pivot_length(&self) -> f64;

    /// The angle (radians, in `[0, pi/2]`) between the line of the tool axis `axis` and the C
    /// axis, in the workpiece frame: a pose is at the pole when this is within the pole
    /// tolerance. The default is for a C axis along z, which holds for all four types of
    /// `kerf.machine/1`.
    fn pole_angle(&self, axis: &Vector3<f64>) -> f64 {
        angle_to_z_line(axis)
    }

    /// The parameters as written in the `kinematics` object of a machine file (without
    /// `type`), in the order of `docs/formats.md`: typed values, which the machine file's
    /// writer ([`crate::Machine::to_json`]) turns into JSON (the maths does not speak JSON).
    fn parameters(&self) -> Vec<(&'static str, Parameter)>;
}

/// One parameter of a machine type, typed (lengths in mm; the meaning of each is documented
/// on the machine type and in `docs/formats.md`).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Parameter {
    /// A number (a length in mm, a sign, an offset).
    Number(f64),
    /// A list of numbers (a point or a vector in mm, a lateral offset).
    Numbers(Vec<f64>),
    /// A name (the tilt axis, `A` or `B`).
    Name(&'static str),
    /// A yes/no switch.
    Flag(bool),
}

impl From<f64> for Parameter {
    fn from(v: f64) -> Self {
        Parameter::Number(v)
    }
}

impl From<Vec<f64>> for Parameter {
    fn from(v: Vec<f64>) -> Self {
        Parameter::Numbers(v)
    }
}

impl From<&'static str> for Parameter {
    fn from(v: &'static str) -> Self {
        Parameter::Name(v)
    }
}

impl From<bool> for Parameter {
    fn from(v: bool) -> Self {
        Parameter::Flag(v)
    }
}
