//! `fork-head`: the double swing head of paper 002 (C primary, A or B tilting).
//!
//! `u = Rz(C) R_tilt(s t) ez`, `P = XYZ + Rz(C) (d + R_tilt(s t) (tx, ty, -L))`: the machine's
//! X, Y, Z is the C axis' reference point; `d` goes from it (in the C-rotated frame) to the
//! tilt axis, and the tool tip sits `L` below the tilt axis, shifted sideways by
//! `tool_lateral = (tx, ty)`; `s` is the optional `tilt_sign` (+1 by default, -1 for a tilt
//! that turns the other way, as LinuxCNC's `5axiskins` B).
//!
//! Inverse: the tilt and C from the tool axis (as for every type), then
//! `XYZ = P - Rz(C) (d + R_tilt(s t) (tx, ty, -L))`.

use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use crate::error::{KinematicsError, Result};
use crate::kinematics::{Kinematics, Parameter};
use crate::params::{finite, non_negative, KinematicsType, Params};
use crate::pose::{Axes, Pose};
use crate::rotation::{rot_z, Angles, Orientation, TiltAbout};

/// The registry entry.
pub(crate) const TYPE: KinematicsType = KinematicsType {
    name: "fork-head",
    parse: |p: &mut Params<'_>| {
        let tilt = match p.string("tilt")? {
            "A" => ForkTilt::A,
            "B" => ForkTilt::B,
            other => {
                return Err(KinematicsError::doc(
                    "kinematics.tilt",
                    format!("expected \"A\" or \"B\", found {other:?}"),
                ))
            }
        };
        let l = p.number("L")?;
        let d = p.numbers::<3>("d")?;
        let lateral = p.numbers::<2>("tool_lateral")?;
        let tilt_sign = p.optional_number("tilt_sign")?.unwrap_or(1.0);
        Ok(Arc::new(
            ForkHead::try_new(tilt, l, Vector3::from(d), lateral)?.with_tilt_sign(tilt_sign)?,
        ))
    },
};

/// The tilt axis of a fork head.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForkTilt {
    /// A: the tilt turns about x.
    A,
    /// B: the tilt turns about y.
    B,
}

/// A double swing head: C on the machine, the tilt (A or B) carried by C, the tool on the
/// tilt.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForkHead {
    orientation: Orientation,
    /// The pivot length: from the tilt axis down to the tool tip (mm, >= 0).
    pub l: f64,
    /// From the C reference point to the tilt axis, in the C-rotated frame (mm).
    pub d: Vector3<f64>,
    /// The tool tip's sideways offset `(tx, ty)` in the tilted frame (mm).
    pub tool_lateral: [f64; 2],
}

impl ForkHead {
    /// A fork head with the given tilt axis, pivot length, axis offset and lateral offset.
    ///
    /// # Errors
    /// [`crate::KinematicsError::Document`] naming the parameter (`kinematics.L`,
    /// `kinematics.d`, `kinematics.tool_lateral`) if `L` is negative or a value is not finite.
    pub fn try_new(
        tilt: ForkTilt,
        l: f64,
        d: Vector3<f64>,
        tool_lateral: [f64; 2],
    ) -> Result<Self> {
        non_negative("L", l)?;
        for v in d.iter() {
            finite("d", *v)?;
        }
        for v in tool_lateral {
            finite("tool_lateral", v)?;
        }
        let about = match tilt {
            ForkTilt::A => TiltAbout::X,
            ForkTilt::B => TiltAbout::Y,
        };
        Ok(Self {
            orientation: Orientation::head(about),
            l,
            d,
            tool_lateral,
        })
    }

    /// The same head with its tilt turning the other way for `sign` -1 (`tilt_sign`: `u =
    /// Rz(C) R_tilt(-t) ez`); +1 is the default.
    ///
    /// # Errors
    /// [`crate::KinematicsError::Document`] naming `kinematics.tilt_sign` unless `sign` is +1
    /// or -1.
    pub fn with_tilt_sign(mut self, sign: f64) -> Result<Self> {
        crate::params::sign("tilt_sign", sign)?;
        self.orientation.tilt_sign = sign;
        Ok(self)
    }

    /// The tilt's direction sign (`tilt_sign`, +1 or -1).
    pub fn tilt_sign(&self) -> f64 {
        self.orientation.tilt_sign
    }

    /// `Rz(C) (d + R_tilt(s t) (tx, ty, -L))`: from X, Y, Z to the tip.
    #[inline]
    fn offset(&self, s: &Angles) -> Vector3<f64> {
        let tool = Vector3::new(self.tool_lateral[0], self.tool_lateral[1], -self.l);
        let local = self.d + self.orientation.rot_tilt(&tool, s.a);
        rot_z(&local, s.g)
    }

    #[inline]
    fn place(&self, p: &Point3<f64>, s: &Angles) -> Axes {
        let m = p - self.offset(s);
        Axes::new(m.x, m.y, m.z, s.tilt, s.c)
    }
}

impl Kinematics for ForkHead {
    fn type_name(&self) -> &'static str {
        TYPE.name
    }

    fn tilt_name(&self) -> &'static str {
        match self.orientation.about {
            TiltAbout::X => "A",
            TiltAbout::Y => "B",
        }
    }

    fn forward(&self, axes: &Axes) -> Pose {
        let angles = self.orientation.at(axes.tilt, axes.c);
        Pose {
            position: Point3::from(axes.xyz() + self.offset(&angles)),
            axis: self.orientation.axis(&angles),
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
        // The tip's distance from the tilt axis: the part of (tx, ty, -L) across it.
        match self.orientation.about {
            TiltAbout::X => self.tool_lateral[1].hypot(self.l),
            TiltAbout::Y => self.tool_lateral[0].hypot(self.l),
        }
    }

    fn parameters(&self) -> Vec<(&'static str, Parameter)> {
        let mut params = vec![
            ("tilt", self.tilt_name().into()),
            ("L", self.l.into()),
            ("d", vec![self.d.x, self.d.y, self.d.z].into()),
            ("tool_lateral", self.tool_lateral.to_vec().into()),
        ];
        // Optional: written only where it is not the default, so files without it round-trip.
        if self.tilt_sign() != 1.0 {
            params.push(("tilt_sign", self.tilt_sign().into()));
        }
        params
    }
}
