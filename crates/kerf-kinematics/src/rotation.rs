//! Elementary rotations and the orientation model shared by the four machine types.
//!
//! Every type of `kerf.machine/1` orients the tool as `u = Rz(sc C) R(st t) ez`, with `R` the
//! elementary rotation about x (tilt A) or y (tilt B) and `sc`, `st` signs (`+1` or `-1`):
//! the heads with `sc = st = +1`, the A/C table with `sc = st = -s`, the B head on a C table
//! with `sc = c_sign`, `st = b_sign`. [`Orientation`] solves that for `(t, C)` once for all of
//! them; a fifth type with another structure implements its own orientation.

use nalgebra::{Point3, Vector3};

use crate::pose::{Axes, Pose};

/// `(sin, cos)` of an angle in degrees.
#[inline]
pub(crate) fn sin_cos_deg(degrees: f64) -> (f64, f64) {
    degrees.to_radians().sin_cos()
}

/// `Rx(angle) v`, with `(s, c)` the sine and cosine of the angle.
#[inline]
pub(crate) fn rot_x(v: &Vector3<f64>, (s, c): (f64, f64)) -> Vector3<f64> {
    Vector3::new(v.x, c * v.y - s * v.z, s * v.y + c * v.z)
}

/// `Ry(angle) v`.
#[inline]
pub(crate) fn rot_y(v: &Vector3<f64>, (s, c): (f64, f64)) -> Vector3<f64> {
    Vector3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

/// `Rz(angle) v`.
#[inline]
pub(crate) fn rot_z(v: &Vector3<f64>, (s, c): (f64, f64)) -> Vector3<f64> {
    Vector3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

/// The inverse (transpose) of a rotation given by `(s, c)`: the rotation by minus the angle.
#[inline]
pub(crate) fn inv((s, c): (f64, f64)) -> (f64, f64) {
    (-s, c)
}

/// The axis the tilt turns about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TiltAbout {
    /// Tilt A: about x.
    X,
    /// Tilt B: about y.
    Y,
}

/// `u = Rz(c_sign C) R_tilt(tilt_sign t) ez`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Orientation {
    pub(crate) about: TiltAbout,
    pub(crate) tilt_sign: f64,
    pub(crate) c_sign: f64,
}

impl Orientation {
    /// The head types: `u = Rz(C) R(t) ez`.
    pub(crate) const fn head(about: TiltAbout) -> Self {
        Self {
            about,
            tilt_sign: 1.0,
            c_sign: 1.0,
        }
    }

    /// `R(tilt) v` for this model's tilt axis, `(s, c)` of the signed tilt angle.
    #[inline]
    pub(crate) fn rot_tilt(&self, v: &Vector3<f64>, sc: (f64, f64)) -> Vector3<f64> {
        match self.about {
            TiltAbout::X => rot_x(v, sc),
            TiltAbout::Y => rot_y(v, sc),
        }
    }

    /// The angles `(tilt, C)` in degrees with their sines and cosines.
    #[inline]
    pub(crate) fn at(&self, tilt: f64, c: f64) -> Angles {
        Angles {
            tilt,
            c,
            a: sin_cos_deg(self.tilt_sign * tilt),
            g: sin_cos_deg(self.c_sign * c),
        }
    }

    /// The tool axis `Rz(gamma) R(a) ez`: `R_x(a) ez = (0, -sin a, cos a)`,
    /// `R_y(a) ez = (sin a, 0, cos a)`.
    #[inline]
    pub(crate) fn axis(&self, angles: &Angles) -> Vector3<f64> {
        let (sa, ca) = angles.a;
        let tilted = match self.about {
            TiltAbout::X => Vector3::new(0.0, -sa, ca),
            TiltAbout::Y => Vector3::new(sa, 0.0, ca),
        };
        rot_z(&tilted, angles.g)
    }

    /// Both solutions `(t, C)` and `(-t, C + 180)` for the tool axis `u` (any length), degrees.
    ///
    /// The unsigned tilt is `a = atan2(hypot(i, j), k)` in `[0, 180]`, well conditioned
    /// everywhere (unlike `acos(k)`, whose derivative blows up at the pole); the azimuth
    /// `gamma` solves `Rz(gamma) R(a) ez = u`: for a tilt about x,
    /// `(sin a sin g, -sin a cos g) = (i, j)`, so `gamma = atan2(i, -j)`; about y,
    /// `(sin a cos g, sin a sin g) = (i, j)`, so `gamma = atan2(j, i)`. At the pole
    /// (`i = j = 0`) `gamma` is whatever `atan2(0, 0)` gives: any value is a solution there.
    ///
    /// The sines and cosines come from the components of `u` (no trigonometric call beyond the
    /// two `atan2`): `sin a = h / |u|`, `cos a = k / |u|` with `h = hypot(i, j)`, and
    /// `(sin g, cos g) = (i, -j) / h` (about x) or `(j, i) / h` (about y). The second solution
    /// negates `sin a` and both of `sin g`, `cos g` (`gamma + 180`).
    #[inline]
    pub(crate) fn solve(&self, u: &Vector3<f64>) -> [Angles; 2] {
        let h = u.x.hypot(u.y);
        let n = h.hypot(u.z);
        let (gy, gx) = match self.about {
            TiltAbout::X => (u.x, -u.y),
            TiltAbout::Y => (u.y, u.x),
        };
        let gamma = gy.atan2(gx);
        let g = if h > 0.0 {
            (gy / h, gx / h)
        } else {
            gamma.sin_cos()
        };
        let a = if n > 0.0 {
            (h / n, u.z / n)
        } else {
            (0.0, 1.0)
        };
        // tilt_sign and c_sign are +-1, so multiplying is dividing.
        let t = self.tilt_sign * h.atan2(u.z).to_degrees();
        let c = self.c_sign * gamma.to_degrees();
        [
            Angles { tilt: t, c, a, g },
            Angles {
                tilt: -t,
                c: c + 180.0,
                a: (-a.0, a.1),
                g: (-g.0, -g.1),
            },
        ]
    }

    /// The tilt (degrees, in `(-180, 180]`) that brings the tool axis closest to `u` when C is
    /// fixed at `c` degrees: the maximiser of `u . axis(t, c)`. For a tilt about x,
    /// `axis = (sin a sin g, -sin a cos g, cos a)`, so `u . axis = sin a (i sin g - j cos g) +
    /// k cos a`, largest at `a = atan2(i sin g - j cos g, k)`; about y, `a = atan2(i cos g +
    /// j sin g, k)`.
    #[inline]
    pub(crate) fn tilt_for_c(&self, u: &Vector3<f64>, c: f64) -> Angles {
        let g = sin_cos_deg(self.c_sign * c);
        let (sg, cg) = g;
        let lateral = match self.about {
            TiltAbout::X => u.x * sg - u.y * cg,
            TiltAbout::Y => u.x * cg + u.y * sg,
        };
        let n = lateral.hypot(u.z);
        let a = if n > 0.0 {
            (lateral / n, u.z / n)
        } else {
            (0.0, 1.0)
        };
        Angles {
            tilt: self.tilt_sign * lateral.atan2(u.z).to_degrees(),
            c,
            a,
            g,
        }
    }

    /// The one body of every type's [`crate::Kinematics::inverse`]: both solutions of the
    /// tool axis ([`Orientation::solve`]), each placed at the tip by the type's `place`.
    #[inline]
    pub(crate) fn inverse(
        &self,
        pose: &Pose,
        place: impl Fn(&Point3<f64>, &Angles) -> Axes,
    ) -> [Axes; 2] {
        self.solve(&pose.axis).map(|s| place(&pose.position, &s))
    }

    /// The one body of every type's [`crate::Kinematics::inverse_with_c`]: the tilt for C
    /// fixed at `c` degrees ([`Orientation::tilt_for_c`]), placed at the tip by `place`.
    #[inline]
    pub(crate) fn inverse_with_c(
        &self,
        pose: &Pose,
        c: f64,
        place: impl Fn(&Point3<f64>, &Angles) -> Axes,
    ) -> Axes {
        place(&pose.position, &self.tilt_for_c(&pose.axis, c))
    }
}

/// A tilt and a C (degrees) with the sine and cosine of the signed angles `tilt_sign tilt`
/// (`a`) and `c_sign C` (`g`), so that the kinematics need no further trigonometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Angles {
    pub(crate) tilt: f64,
    pub(crate) c: f64,
    pub(crate) a: (f64, f64),
    pub(crate) g: (f64, f64),
}

/// The angle (radians, in `[0, pi/2]`) between the line of the tool axis `u` and the z axis,
/// well conditioned near both ends.
#[inline]
pub(crate) fn angle_to_z_line(u: &Vector3<f64>) -> f64 {
    u.x.hypot(u.y).atan2(u.z.abs())
}

/// The angle (radians) between two vectors, well conditioned for small and large angles.
#[inline]
pub(crate) fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotations_are_right_handed() {
        let q = sin_cos_deg(90.0);
        let (ex, ey, ez) = (Vector3::x(), Vector3::y(), Vector3::z());
        assert!((rot_z(&ex, q) - ey).norm() < 1e-15, "Rz(90) x = y");
        assert!((rot_x(&ey, q) - ez).norm() < 1e-15, "Rx(90) y = z");
        assert!((rot_y(&ez, q) - ex).norm() < 1e-15, "Ry(90) z = x");
    }

    #[test]
    fn solve_round_trips_every_model() {
        let u = Vector3::new(0.3, -0.5, 0.7).normalize();
        for about in [TiltAbout::X, TiltAbout::Y] {
            for tilt_sign in [1.0, -1.0] {
                for c_sign in [1.0, -1.0] {
                    let o = Orientation {
                        about,
                        tilt_sign,
                        c_sign,
                    };
                    for s in o.solve(&u) {
                        let back = o.axis(&o.at(s.tilt, s.c));
                        assert!((back - u).norm() < 1e-15, "{o:?} {s:?}: {back}");
                        assert!((o.axis(&s) - u).norm() < 1e-15, "{o:?} {s:?}: trig-free");
                        let fixed = o.tilt_for_c(&u, s.c);
                        assert!((fixed.tilt - s.tilt).abs() < 1e-12, "tilt for C");
                        assert!((o.axis(&fixed) - u).norm() < 1e-15, "tilt for C: axis");
                    }
                }
            }
        }
    }
}
