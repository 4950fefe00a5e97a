//! `table-table`: a tilting A table carrying a C rotary table (LinuxCNC `xyzac-trt`).
//!
//! `q_c = rot_point`, `q_a = q_c + (0, y_offset, z_offset)`, `T = XYZ - (0, 0, tool_offset)`,
//! `s = -1` if `conventional` else `+1`:
//!
//! `P = q_c + Rz(sC)^T [(q_a - q_c) + Rx(sA)^T (T - q_a)]`, `u = Rz(sC)^T Rx(sA)^T ez`.
//!
//! Inverse: `u = Rz(-sC) Rx(-sA) ez` is the common orientation model with both signs `-s`;
//! solving the position equation for `T`:
//! `T = q_a + Rx(sA) [Rz(sC) (P - q_c) - (q_a - q_c)]`, `XYZ = T + (0, 0, tool_offset)`.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use crate::error::Result;
use crate::kinematics::{Kinematics, Parameter};
use crate::params::{finite, KinematicsType, Params};
use crate::pose::{Axes, Pose};
use crate::rotation::{inv, rot_x, rot_z, sin_cos_deg, Angles, Orientation, TiltAbout};

/// The registry entry.
pub(crate) const TYPE: KinematicsType = KinematicsType {
    name: "table-table",
    parse: |p: &mut Params<'_>| {
        let rot_point = p.numbers::<3>("rot_point")?;
        let y_offset = p.number("y_offset")?;
        let z_offset = p.number("z_offset")?;
        let tool_offset = p.number("tool_offset")?;
        let conventional = p.boolean("conventional")?;
        Ok(Arc::new(TableTable::try_new(
            Vector3::from(rot_point),
            y_offset,
            z_offset,
            tool_offset,
            conventional,
        )?))
    },
};

/// An A trunnion carrying a C rotary table; the tool does not turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableTable {
    /// `q_c`: the C table's rotation point, machine coordinates (mm).
    pub rot_point: Vector3<f64>,
    /// The A axis' y offset from `q_c` (mm).
    pub y_offset: f64,
    /// The A axis' z offset from `q_c` (mm).
    pub z_offset: f64,
    /// The tool length: the tip is this far below X, Y, Z (mm).
    pub tool_offset: f64,
    /// LinuxCNC's `conventional_directions`: `s = -1` if true, else `+1`.
    pub conventional: bool,
    orientation: Orientation,
}

impl TableTable {
    /// The table-table with these LinuxCNC `xyzac-trt` parameters.
    ///
    /// # Errors
    /// [`crate::KinematicsError::Document`] naming the parameter if a value is not finite.
    pub fn try_new(
        rot_point: Vector3<f64>,
        y_offset: f64,
        z_offset: f64,
        tool_offset: f64,
        conventional: bool,
    ) -> Result<Self> {
        for v in rot_point.iter() {
            finite("rot_point", *v)?;
        }
        finite("y_offset", y_offset)?;
        finite("z_offset", z_offset)?;
        finite("tool_offset", tool_offset)?;
        let s = self::s(conventional);
        Ok(Self {
            rot_point,
            y_offset,
            z_offset,
            tool_offset,
            conventional,
            orientation: Orientation {
                about: TiltAbout::X,
                tilt_sign: -s,
                c_sign: -s,
            },
        })
    }

    /// `q_a - q_c`.
    #[inline]
    fn a_offset(&self) -> Vector3<f64> {
        Vector3::new(0.0, self.y_offset, self.z_offset)
    }

    #[inline]
    fn s(&self) -> f64 {
        s(self.conventional)
    }

    /// X, Y, Z for the tip `p` at the angles `s`. The model's signed angles are `-s A` and
    /// `-s C`, so `Rx(sA)` and `Rz(sC)` are their inverses.
    #[inline]
    fn place(&self, p: &Point3<f64>, angles: &Angles) -> Axes {
        let (qc, qa_qc) = (self.rot_point, self.a_offset());
        let in_table = rot_z(&(p.coords - qc), inv(angles.g)) - qa_qc;
        let t = qc + qa_qc + rot_x(&in_table, inv(angles.a));
        Axes::new(t.x, t.y, t.z + self.tool_offset, angles.tilt, angles.c)
    }
}

/// `-1` if conventional, else `+1`.
fn s(conventional: bool) -> f64 {
    if conventional {
        -1.0
    } else {
        1.0
    }
}

impl Kinematics for TableTable {
    fn type_name(&self) -> &'static str {
        TYPE.name
    }

    fn tilt_name(&self) -> &'static str {
        "A"
    }

    fn forward(&self, axes: &Axes) -> Pose {
        let s = self.s();
        let (qc, qa_qc) = (self.rot_point, self.a_offset());
        // (sin, cos) of sA and sC, the angles of the formula.
        let (ra, rc) = (sin_cos_deg(s * axes.tilt), sin_cos_deg(s * axes.c));
        let t = axes.xyz() - Vector3::new(0.0, 0.0, self.tool_offset);
        let inner = qa_qc + rot_x(&(t - qc - qa_qc), inv(ra));
        let p = qc + rot_z(&inner, inv(rc));
        let u = rot_z(&rot_x(&Vector3::z(), inv(ra)), inv(rc));
        Pose {
            position: Point3::from(p),
            axis: u,
        }
    }

    fn inverse(&self, pose: &Pose) -> [Axes; 2] {
        self.orientation.inverse(pose, |p, s| self.place(p, s))
    }

    fn inverse_with_c(&self, pose: &Pose, c: f64) -> Axes {
        self.orientation
            .inverse_with_c(pose, c, |p, s| self.place(p, s))
    }

    fn pivot_length(&self) -> f64 {
        // The C table's rotation point's distance from the A axis: a part on the C table turns
        // on about this radius when A moves.
        self.y_offset.hypot(self.z_offset)
    }

    fn parameters(&self) -> Vec<(&'static str, Parameter)> {
        let q = self.rot_point;
        vec![
            ("rot_point", vec![q.x, q.y, q.z].into()),
            ("y_offset", self.y_offset.into()),
            ("z_offset", self.z_offset.into()),
            ("tool_offset", self.tool_offset.into()),
            ("conventional", self.conventional.into()),
        ]
    }
}
