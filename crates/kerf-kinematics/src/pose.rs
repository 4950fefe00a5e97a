//! Poses (tool tip and tool axis in the workpiece frame) and machine axis vectors.

use nalgebra::{Point3, Vector3};

/// A pose `(x, y, z, i, j, k)` in the workpiece frame: the tool tip (the laser focus) and the
/// tool axis, pointing from the tip toward the head (for a laser, the outward surface normal;
/// the beam travels along `-(i, j, k)`). Millimetres.
///
/// The inverse kinematics use only the direction of `axis`, so it need not be exactly unit;
/// [`crate::solve_path`] checks that it is (within 1e-6) and normalises it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The tool tip `(x, y, z)`.
    pub position: Point3<f64>,
    /// The tool axis `(i, j, k)`.
    pub axis: Vector3<f64>,
}

impl Pose {
    /// The pose `(x, y, z, i, j, k)`.
    pub fn new(x: f64, y: f64, z: f64, i: f64, j: f64, k: f64) -> Self {
        Self {
            position: Point3::new(x, y, z),
            axis: Vector3::new(i, j, k),
        }
    }

    /// The pose from `[x, y, z, i, j, k]` (a toolpath point with its normal).
    pub fn from_array(a: [f64; 6]) -> Self {
        Self::new(a[0], a[1], a[2], a[3], a[4], a[5])
    }

    /// `[x, y, z, i, j, k]`.
    pub fn to_array(&self) -> [f64; 6] {
        let (p, u) = (self.position, self.axis);
        [p.x, p.y, p.z, u.x, u.y, u.z]
    }
}

/// One of the five axes of a machine, in the order of an axis vector `[X, Y, Z, tilt, C]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The linear X axis.
    X,
    /// The linear Y axis.
    Y,
    /// The linear Z axis.
    Z,
    /// The tilting rotary axis, `A` or `B` as the kinematic type says.
    Tilt,
    /// The C rotary axis (about z).
    C,
}

impl Axis {
    /// The five axes in file order.
    pub const ALL: [Axis; 5] = [Axis::X, Axis::Y, Axis::Z, Axis::Tilt, Axis::C];

    /// The position of the axis in `[X, Y, Z, tilt, C]`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// True for the tilt and C axes (degrees, may be continuous).
    pub fn is_rotary(self) -> bool {
        matches!(self, Axis::Tilt | Axis::C)
    }

    /// The axis' name in files: `X`, `Y`, `Z`, `tilt_name` (`A` or `B`), `C`.
    pub fn name(self, tilt_name: &'static str) -> &'static str {
        match self {
            Axis::X => "X",
            Axis::Y => "Y",
            Axis::Z => "Z",
            Axis::Tilt => tilt_name,
            Axis::C => "C",
        }
    }
}

/// Machine axis positions `[X, Y, Z, tilt, C]`: millimetres and degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Axes {
    /// X, mm.
    pub x: f64,
    /// Y, mm.
    pub y: f64,
    /// Z, mm.
    pub z: f64,
    /// The tilt axis (A or B), degrees.
    pub tilt: f64,
    /// The C axis, degrees.
    pub c: f64,
}

impl Axes {
    /// The axis vector `(x, y, z, tilt, c)` (mm, mm, mm, degrees, degrees).
    pub fn new(x: f64, y: f64, z: f64, tilt: f64, c: f64) -> Self {
        Self { x, y, z, tilt, c }
    }

    /// From `[X, Y, Z, tilt, C]`.
    pub fn from_array(a: [f64; 5]) -> Self {
        Self::new(a[0], a[1], a[2], a[3], a[4])
    }

    /// `[X, Y, Z, tilt, C]`.
    pub fn to_array(&self) -> [f64; 5] {
        [self.x, self.y, self.z, self.tilt, self.c]
    }

    /// The value of one axis.
    pub fn get(&self, axis: Axis) -> f64 {
        self.to_array()[axis.index()]
    }

    /// The linear axes `(X, Y, Z)` as a vector.
    pub fn xyz(&self) -> Vector3<f64> {
        Vector3::new(self.x, self.y, self.z)
    }

    /// The axes linearly interpolated: `self + s (other - self)`, as a controller does between
    /// two points.
    pub fn lerp(&self, other: &Axes, s: f64) -> Axes {
        let (a, b) = (self.to_array(), other.to_array());
        Axes::from_array(std::array::from_fn(|n| a[n] + s * (b[n] - a[n])))
    }

    /// The largest move of a rotary axis from `self` to `other`:
    /// `max(|d tilt|, |d C|)`, degrees.
    pub fn rotary_step(&self, other: &Axes) -> f64 {
        (other.tilt - self.tilt).abs().max((other.c - self.c).abs())
    }

    /// The rotary travel `|d tilt| + |d C|` from `self` to `other`, degrees: what the
    /// continuity rule minimises.
    pub fn rotary_travel(&self, other: &Axes) -> f64 {
        (other.tilt - self.tilt).abs() + (other.c - self.c).abs()
    }
}
