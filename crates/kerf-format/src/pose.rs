//! The pose: a cutting point and its tool axis, the one pose type of every stage (the normals
//! produce it, the process plans with it, the kinematics solve it). Files hold it as the array
//! `[x, y, z, i, j, k]` (`kerf.toolpath/1`, `kerf.axes/1`): [`Pose::from_array`] and
//! [`Pose::to_array`] are the only conversions.

use nalgebra::{Point3, Vector3};

/// A pose `(x, y, z, i, j, k)` in the workpiece frame: the tool tip (the laser focus) and the
/// tool axis, pointing from the tip toward the head (for a laser, the outward surface normal;
/// the beam travels along `-(i, j, k)`). Millimetres.
///
/// The inverse kinematics use only the direction of `axis`, so it need not be exactly unit;
/// `kerf_kinematics::solve_path` checks that it is (within 1e-6) and normalises it.
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

    /// The pose at `position` with the tool axis `axis`.
    pub fn at(position: Point3<f64>, axis: Vector3<f64>) -> Self {
        Self { position, axis }
    }

    /// The pose from `[x, y, z, i, j, k]` (a toolpath point with its normal).
    pub fn from_array(a: [f64; 6]) -> Self {
        Self::new(a[0], a[1], a[2], a[3], a[4], a[5])
    }

    /// True when all six numbers are finite.
    pub fn is_finite(&self) -> bool {
        self.position
            .iter()
            .chain(self.axis.iter())
            .all(|v| v.is_finite())
    }

    /// `[x, y, z, i, j, k]`.
    pub fn to_array(&self) -> [f64; 6] {
        let (p, u) = (self.position, self.axis);
        [p.x, p.y, p.z, u.x, u.y, u.z]
    }
}
