//! The [`Kinematics`] trait: forward and inverse kinematics of one machine type.

use std::fmt;

use nalgebra::Vector3;
use serde_json::Value;

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
    /// in: exactly the formula of `shared/formats.md`.
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
    /// `type`), in the order of `shared/formats.md`.
    fn parameters(&self) -> Vec<(&'static str, Value)>;
}
