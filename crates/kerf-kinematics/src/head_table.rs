//! `head-table`: a B swing head over a C rotary table.
//!
//! `tip = XYZ + Ry(b B) (0, 0, -L)`, `P = c_point + Rz(c C) (tip - c_point)`,
//! `u = Rz(c C) Ry(b B) ez`, with `b = b_sign`, `c = c_sign` (+1 or -1).
//!
//! Inverse: the tilt and C from the tool axis, then
//! `tip = c_point + Rz(-c C) (P - c_point)`, `XYZ = tip - Ry(b B) (0, 0, -L)`.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use crate::error::Result;
use crate::kinematics::{Kinematics, Parameter};
use crate::params::{finite, non_negative, sign, KinematicsType, Params};
use crate::pose::{Axes, Pose};
use crate::rotation::{inv, rot_y, rot_z, Angles, Orientation, TiltAbout};

/// The registry entry.
pub(crate) const TYPE: KinematicsType = KinematicsType {
    name: "head-table",
    parse: |p: &mut Params<'_>| {
        let l = p.number("L")?;
        let c_point = p.numbers::<3>("c_point")?;
        let b_sign = p.number("b_sign")?;
        let c_sign = p.number("c_sign")?;
        Ok(Arc::new(HeadTable::try_new(
            l,
            Vector3::from(c_point),
            b_sign,
            c_sign,
        )?))
    },
};

/// A B head (the tool tilts) over a C table (the part turns).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadTable {
    /// The pivot length: from the B axis down to the tool tip (mm, >= 0).
    pub l: f64,
    /// The C table's centre, machine coordinates (mm).
    pub c_point: Vector3<f64>,
    orientation: Orientation,
}

impl HeadTable {
    /// The head-table machine.
    ///
    /// # Errors
    /// [`crate::KinematicsError::Document`] naming the parameter if `L` is negative, a value is
    /// not finite, or a sign is not +1 or -1.
    pub fn try_new(l: f64, c_point: Vector3<f64>, b_sign: f64, c_sign: f64) -> Result<Self> {
        non_negative("L", l)?;
        for v in c_point.iter() {
            finite("c_point", *v)?;
        }
        sign("b_sign", b_sign)?;
        sign("c_sign", c_sign)?;
        Ok(Self {
            l,
            c_point,
            orientation: Orientation {
                about: TiltAbout::Y,
                tilt_sign: b_sign,
                c_sign,
            },
        })
    }

    /// The B axis direction sign.
    pub fn b_sign(&self) -> f64 {
        self.orientation.tilt_sign
    }

    /// The C axis direction sign.
    pub fn c_sign(&self) -> f64 {
        self.orientation.c_sign
    }

    #[inline]
    fn place(&self, p: &Point3<f64>, s: &Angles) -> Axes {
        let tip = self.c_point + rot_z(&(p.coords - self.c_point), inv(s.g));
        let m = tip - rot_y(&Vector3::new(0.0, 0.0, -self.l), s.a);
        Axes::new(m.x, m.y, m.z, s.tilt, s.c)
    }
}

impl Kinematics for HeadTable {
    fn type_name(&self) -> &'static str {
        TYPE.name
    }

    fn tilt_name(&self) -> &'static str {
        "B"
    }

    fn forward(&self, axes: &Axes) -> Pose {
        let s = self.orientation.at(axes.tilt, axes.c);
        let tip = axes.xyz() + rot_y(&Vector3::new(0.0, 0.0, -self.l), s.a);
        let p = self.c_point + rot_z(&(tip - self.c_point), s.g);
        Pose {
            position: Point3::from(p),
            axis: self.orientation.axis(&s),
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
        self.l
    }

    fn parameters(&self) -> Vec<(&'static str, Parameter)> {
        let q = self.c_point;
        vec![
            ("L", self.l.into()),
            ("c_point", vec![q.x, q.y, q.z].into()),
            ("b_sign", self.b_sign().into()),
            ("c_sign", self.c_sign().into()),
        ]
    }
}
