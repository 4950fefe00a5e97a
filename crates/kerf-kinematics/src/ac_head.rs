//! `ac-head`: the five-axis laser head of paper 000 (Huang et al., HUST 1993).
//!
//! A about x, C about z, both on the head; rotation radii `r_a` (from the focus up the tool
//! axis to the A axis) and `r_c` (from the C axis to the A axis' foot, sideways). With
//! `u = Rz(C) Rx(A) ez = (sin A sin C, -sin A cos C, cos A)`:
//!
//! `XYZ = P + r_a u - r_c (cos C, sin C, 0)` (paper 000 eq 16).
//!
//! Inverse: `A = atan2(hypot(i, j), k)`, `C = atan2(i, -j)`, then XYZ by the same formula;
//! the other solution is `(-A, C + 180)` (derivation and worked values in
//! `docs/kinematics.md`).

use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use crate::error::Result;
use crate::kinematics::{Kinematics, Parameter};
use crate::params::{non_negative, KinematicsType};
use crate::pose::{Axes, Pose};
use crate::rotation::{Angles, Orientation, TiltAbout};

/// The registry entry.
pub(crate) const TYPE: KinematicsType = KinematicsType {
    name: "ac-head",
    parse: |p| {
        let r_a = p.number("r_a")?;
        let r_c = p.number("r_c")?;
        Ok(Arc::new(AcHead::try_new(r_a, r_c)?))
    },
};

const ORIENTATION: Orientation = Orientation::head(TiltAbout::X);

/// The A/C laser head of paper 000.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AcHead {
    /// The A rotation radius: distance from the focus, along the tool axis, to the A axis
    /// (mm, >= 0).
    pub r_a: f64,
    /// The C rotation radius: the sideways offset of the A axis from the C axis (mm, >= 0).
    pub r_c: f64,
}

impl AcHead {
    /// The head with radii `r_a` and `r_c`.
    ///
    /// # Errors
    /// [`crate::KinematicsError::Document`] (`kinematics.r_a: must be finite and >= 0 ...`) if
    /// a radius is negative or not finite.
    pub fn try_new(r_a: f64, r_c: f64) -> Result<Self> {
        non_negative("r_a", r_a)?;
        non_negative("r_c", r_c)?;
        Ok(Self { r_a, r_c })
    }

    /// X, Y, Z for the tip `p` at the angles `s`.
    #[inline]
    fn place(&self, p: &Point3<f64>, s: &Angles) -> Axes {
        let u = ORIENTATION.axis(s);
        let (sc, cc) = s.g;
        let m = p.coords + self.r_a * u - self.r_c * Vector3::new(cc, sc, 0.0);
        Axes::new(m.x, m.y, m.z, s.tilt, s.c)
    }
}

impl Kinematics for AcHead {
    fn type_name(&self) -> &'static str {
        TYPE.name
    }

    fn tilt_name(&self) -> &'static str {
        "A"
    }

    fn forward(&self, axes: &Axes) -> Pose {
        let angles = ORIENTATION.at(axes.tilt, axes.c);
        let u = ORIENTATION.axis(&angles);
        let (s, c) = angles.g;
        let p = axes.xyz() - self.r_a * u + self.r_c * Vector3::new(c, s, 0.0);
        Pose {
            position: Point3::from(p),
            axis: u,
        }
    }

    fn inverse(&self, pose: &Pose) -> [Axes; 2] {
        ORIENTATION.inverse(pose, |p, s| self.place(p, s))
    }

    fn inverse_with_c(&self, pose: &Pose, c: f64) -> Axes {
        ORIENTATION.inverse_with_c(pose, c, |p, s| self.place(p, s))
    }

    fn pivot_length(&self) -> f64 {
        // The A axis is along x through the head point; at C = 0 the r_c offset is along x
        // too, so the tip is r_a from the A axis.
        self.r_a
    }

    fn parameters(&self) -> Vec<(&'static str, Parameter)> {
        vec![("r_a", self.r_a.into()), ("r_c", self.r_c.into())]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_000_equation_16() {
        // x_m = x + r_a sin a sin c - r_c cos c, y_m = y - r_a sin a cos c - r_c sin c,
        // z_m = z + r_a cos a, checked at an arbitrary angle pair.
        let head = AcHead::try_new(180.0, 95.0).unwrap();
        let (a, c) = (37.0_f64, -121.0_f64);
        let p = Point3::new(12.0, -7.0, 3.0);
        let m = head.place(&p, &ORIENTATION.at(a, c));
        let (ar, cr) = (a.to_radians(), c.to_radians());
        let expected = [
            p.x + 180.0 * ar.sin() * cr.sin() - 95.0 * cr.cos(),
            p.y - 180.0 * ar.sin() * cr.cos() - 95.0 * cr.sin(),
            p.z + 180.0 * ar.cos(),
        ];
        for (got, want) in [m.x, m.y, m.z].into_iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        let back = head.forward(&m);
        assert!((back.position - p).norm() < 1e-12, "forward undoes place");
    }
}
