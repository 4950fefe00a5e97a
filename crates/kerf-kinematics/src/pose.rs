//! Machine axis vectors. The pose (tool tip and tool axis in the workpiece frame) is
//! [`kerf_format::Pose`], re-exported here: one pose type from the normals to the G-code.

use nalgebra::Vector3;

pub use kerf_format::Pose;

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

    /// The five values in the order `[X, Y, Z, tilt, C]`.
    pub fn iter(&self) -> impl Iterator<Item = f64> {
        self.to_array().into_iter()
    }

    /// True when all five values are finite.
    pub fn is_finite(&self) -> bool {
        self.iter().all(f64::is_finite)
    }

    /// `f` applied to every axis value (as `array::map`).
    pub fn map(&self, f: impl FnMut(f64) -> f64) -> Axes {
        Axes::from_array(self.to_array().map(f))
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

/// `axes[k]`: the axis at position `k` of `[X, Y, Z, tilt, C]` ([`Axis::index`]), for loops
/// over all five axes.
///
/// # Panics
/// For `k >= 5`, like an array.
impl std::ops::Index<usize> for Axes {
    type Output = f64;

    fn index(&self, k: usize) -> &f64 {
        match k {
            0 => &self.x,
            1 => &self.y,
            2 => &self.z,
            3 => &self.tilt,
            4 => &self.c,
            _ => panic!("axis index {k} out of range (five axes)"),
        }
    }
}

/// `axes[k] = v`: sets the axis at position `k` of `[X, Y, Z, tilt, C]`.
///
/// # Panics
/// For `k >= 5`, like an array.
impl std::ops::IndexMut<usize> for Axes {
    fn index_mut(&mut self, k: usize) -> &mut f64 {
        match k {
            0 => &mut self.x,
            1 => &mut self.y,
            2 => &mut self.z,
            3 => &mut self.tilt,
            4 => &mut self.c,
            _ => panic!("axis index {k} out of range (five axes)"),
        }
    }
}

impl From<[f64; 5]> for Axes {
    fn from(a: [f64; 5]) -> Self {
        Axes::from_array(a)
    }
}

impl From<Axes> for [f64; 5] {
    fn from(a: Axes) -> Self {
        a.to_array()
    }
}
