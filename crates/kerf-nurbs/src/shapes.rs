//! Exact shape constructors: lines, polylines, circles and arcs as curves; planes, cylinders,
//! spheres and surfaces of revolution as surfaces. Conics are the rational quadratic arcs of
//! Piegl and Tiller (A7.1), surfaces of revolution their A8.1; `docs/nurbs.md` section 13 gives
//! the construction.

use std::f64::consts::{FRAC_PI_2, TAU};

use nalgebra::{Point3, Vector3};

use crate::{NurbsCurve, NurbsError, NurbsSurface, Result};

/// Relative size below which a vector counts as zero, or two unit vectors as parallel.
const DEGENERATE: f64 = 1e-12;

fn bad(field: &'static str, reason: String) -> NurbsError {
    NurbsError::BadShape { field, reason }
}

fn finite_point(field: &'static str, p: &Point3<f64>) -> Result<()> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(bad(field, format!("must be finite (got {p:?})")))
    }
}

fn unit(field: &'static str, v: &Vector3<f64>) -> Result<Vector3<f64>> {
    if !v.iter().all(|c| c.is_finite()) {
        return Err(bad(field, format!("must be finite (got {v:?})")));
    }
    let n = v.norm();
    if n == 0.0 || !n.is_finite() {
        return Err(bad(field, format!("must be a non-zero vector (got {v:?})")));
    }
    Ok(v / n)
}

fn positive(field: &'static str, x: f64) -> Result<f64> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(bad(field, format!("must be finite and > 0 (got {x})")))
    }
}

/// `y` made orthogonal to the unit vector `x` and normalised (Gram-Schmidt).
fn orthogonal(field: &'static str, x: &Vector3<f64>, y: &Vector3<f64>) -> Result<Vector3<f64>> {
    let y = unit(field, y)?;
    let r = y - x * x.dot(&y);
    if r.norm() <= DEGENERATE {
        return Err(bad(
            field,
            format!("must not be parallel to the other axis (got {y:?})"),
        ));
    }
    Ok(r.normalize())
}

/// A unit vector perpendicular to the unit vector `n`: `n x e` normalised, with `e` the
/// coordinate axis least aligned with `n` (ties go to x, then y).
fn perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let a = n.abs();
    let e = if a.x <= a.y && a.x <= a.z {
        Vector3::x()
    } else if a.y <= a.z {
        Vector3::y()
    } else {
        Vector3::z()
    };
    n.cross(&e).normalize()
}

fn sweep(field: &'static str, s: f64) -> Result<f64> {
    if s.is_finite() && s != 0.0 && s.abs() <= TAU * (1.0 + 4.0 * f64::EPSILON) {
        Ok(s.clamp(-TAU, TAU))
    } else {
        Err(bad(
            field,
            format!("must satisfy 0 < |sweep| <= 2 pi (got {s} rad)"),
        ))
    }
}

/// The rational quadratic arc of A7.1 in the unit frame `(x, y)` about the origin, radius 1:
/// homogeneous-free `(points, weights)` and the knot vector on `[0, 1]`.
fn unit_arc(start_rad: f64, sweep_rad: f64) -> (Vec<(f64, f64)>, Vec<f64>, Vec<f64>) {
    let n = ((sweep_rad.abs() / FRAC_PI_2) - 1e-12)
        .ceil()
        .clamp(1.0, 4.0) as usize;
    let d = sweep_rad / n as f64;
    let w1 = (d / 2.0).cos();
    let mut pts = Vec::with_capacity(2 * n + 1);
    let mut weights = Vec::with_capacity(2 * n + 1);
    let at = |a: f64, r: f64| (r * a.cos(), r * a.sin());
    pts.push(at(start_rad, 1.0));
    weights.push(1.0);
    for k in 0..n {
        let a0 = start_rad + d * k as f64;
        pts.push(at(a0 + d / 2.0, 1.0 / w1));
        weights.push(w1);
        pts.push(at(a0 + d, 1.0));
        weights.push(1.0);
    }
    if sweep_rad.abs() == TAU {
        pts[2 * n] = pts[0]; // closed exactly, not up to the rounding of cos/sin
    }
    let mut knots = vec![0.0; 3];
    for k in 1..n {
        let t = k as f64 / n as f64;
        knots.extend([t, t]);
    }
    knots.extend([1.0; 3]);
    (pts, weights, knots)
}

impl NurbsCurve {
    /// The straight segment from `a` to `b`: degree 1, two control points, knots
    /// `[0, 0, 1, 1]`, so `point(t) = a + t (b - a)`.
    ///
    /// Errors ([`NurbsError::BadShape`]): a non-finite point, or `a == b`.
    pub fn line(a: Point3<f64>, b: Point3<f64>) -> Result<Self> {
        Self::polyline(&[a, b])
    }

    /// The polyline through `points`: degree 1 with the points as control points, so the
    /// curve passes through each of them with a C0 corner there. The knots are the cumulative
    /// chord lengths divided by the total length (domain `[0, 1]`), so the parameter is
    /// proportional to arc length on every segment.
    ///
    /// Errors ([`NurbsError::BadShape`], field `points`): fewer than two points, a non-finite
    /// point, or a point equal to the one before it (a zero-length segment).
    pub fn polyline(points: &[Point3<f64>]) -> Result<Self> {
        if points.len() < 2 {
            return Err(bad(
                "points",
                format!("a polyline needs at least 2 points (got {})", points.len()),
            ));
        }
        for (i, p) in points.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                return Err(bad(
                    "points",
                    format!("point {i} must be finite (got {p:?})"),
                ));
            }
        }
        let mut cumulative = vec![0.0];
        for i in 1..points.len() {
            let l = (points[i] - points[i - 1]).norm();
            if l == 0.0 {
                return Err(bad(
                    "points",
                    format!("point {i} repeats point {} (a zero-length segment)", i - 1),
                ));
            }
            cumulative.push(cumulative[i - 1] + l);
        }
        let total = cumulative[points.len() - 1];
        if !total.is_finite() {
            return Err(bad("points", "the total length overflows".to_string()));
        }
        let mut knots = vec![0.0];
        knots.extend(cumulative.iter().map(|s| s / total));
        *knots.last_mut().expect("two or more") = 1.0;
        knots.push(1.0);
        Self::try_new(1, knots, points.to_vec(), None)
    }

    /// The full circle of `radius` about `center` in the plane through it perpendicular to
    /// `normal`, counter-clockwise seen from the tip of `normal`.
    ///
    /// The standard 9-point rational quadratic: its control points are the corners and edge
    /// mid-points of the square circumscribed about the circle, weights 1 at the mid-points
    /// (which lie on the circle) and `1/sqrt 2` at the corners, knots
    /// `[0, 0, 0, 1/4, 1/4, 1/2, 1/2, 3/4, 3/4, 1, 1, 1]`: **domain `[0, 1]`**, one quarter
    /// per knot span (the parameter is not proportional to angle inside a quarter). It starts
    /// at `center + radius x` with `x = normal x e` normalised, `e` the coordinate axis least
    /// aligned with `normal`; use [`NurbsCurve::arc`] to choose the start.
    ///
    /// Errors ([`NurbsError::BadShape`]): non-finite input, a zero `normal`, a radius that is
    /// not finite and > 0.
    pub fn circle(center: Point3<f64>, normal: Vector3<f64>, radius: f64) -> Result<Self> {
        let n = unit("normal", &normal)?;
        let x = perpendicular(&n);
        Self::arc(center, x, n.cross(&x), radius, 0.0, TAU)
    }

    /// The circular arc `center + radius (cos a x + sin a y)` for `a` from `start_rad` to
    /// `start_rad + sweep_rad` (a negative sweep turns from `y` towards `-x`), exactly, as
    /// Piegl-Tiller A7.1 builds it: the fewest rational quadratic segments of at most 90 degrees
    /// each (`n = ceil(|sweep| / 90 deg)`, 1 to 4). Segment `k` has end points on the circle
    /// (weight 1) and middle control point at the intersection of their tangents, at distance
    /// `radius / cos(d/2)` from the centre at the mid angle, weight `cos(d/2)`, `d = sweep / n`.
    /// Interior knots are double (`k/n`, C0 in the control net, C1 and G2 on the curve);
    /// domain `[0, 1]`. A sweep of exactly `2 pi` closes the curve exactly.
    ///
    /// `x_axis` is normalised; `y_axis` only fixes the plane and the sense of rotation (its
    /// component orthogonal to `x_axis` is used).
    ///
    /// Errors ([`NurbsError::BadShape`]): non-finite input, a zero axis, parallel axes, a
    /// radius not > 0, a sweep outside `0 < |sweep| <= 2 pi`.
    pub fn arc(
        center: Point3<f64>,
        x_axis: Vector3<f64>,
        y_axis: Vector3<f64>,
        radius: f64,
        start_rad: f64,
        sweep_rad: f64,
    ) -> Result<Self> {
        finite_point("center", &center)?;
        let x = unit("x_axis", &x_axis)?;
        let y = orthogonal("y_axis", &x, &y_axis)?;
        let r = positive("radius", radius)?;
        if !start_rad.is_finite() {
            return Err(bad(
                "start_rad",
                format!("must be finite (got {start_rad})"),
            ));
        }
        let sweep_rad = sweep("sweep_rad", sweep_rad)?;
        let (pts, weights, knots) = unit_arc(start_rad, sweep_rad);
        let poles = pts
            .iter()
            .map(|&(a, b)| center + x * (r * a) + y * (r * b))
            .collect();
        Self::try_new(2, knots, poles, Some(weights))
    }
}

impl NurbsSurface {
    /// The rectangle `origin + s u_len u + t v_len v` for `(s, t)` in `[0, 1]^2`, `u` and `v`
    /// the normalised axes: a bilinear patch (degree 1 x 1, four corners, knots
    /// `[0, 0, 1, 1]` both ways), so the parameter is proportional to distance along each
    /// axis. Its normal `Su x Sv` is `u x v` normalised. The axes need not be orthogonal
    /// (skew axes give a parallelogram), only not parallel.
    ///
    /// Errors ([`NurbsError::BadShape`]): non-finite input, a zero or parallel axis, a length
    /// not > 0.
    pub fn plane(
        origin: Point3<f64>,
        u_axis: Vector3<f64>,
        v_axis: Vector3<f64>,
        u_len: f64,
        v_len: f64,
    ) -> Result<Self> {
        finite_point("origin", &origin)?;
        let u = unit("u_axis", &u_axis)? * positive("u_len", u_len)?;
        let v = unit("v_axis", &v_axis)? * positive("v_len", v_len)?;
        if u.normalize().cross(&v.normalize()).norm() <= DEGENERATE {
            return Err(bad(
                "v_axis",
                format!("must not be parallel to u_axis (got {v_axis:?})"),
            ));
        }
        let k = || vec![0.0, 0.0, 1.0, 1.0];
        let net = vec![vec![origin, origin + v], vec![origin + u, origin + u + v]];
        Self::try_new(1, 1, k(), k(), net, None)
    }

    /// The lateral surface of the cylinder of `radius` whose axis runs from `axis_origin` for
    /// `height` along `axis_dir`: the line at `axis_origin + radius x` (`x` as in
    /// [`NurbsCurve::circle`] for the normal `axis_dir`) revolved a full turn with
    /// [`NurbsSurface::revolve`]. `u` goes round (the 9-point circle, domain `[0, 1]`), `v`
    /// along the axis (degree 1, `[0, 1]`, proportional to height); the normal `Su x Sv`
    /// points radially outwards.
    ///
    /// Errors ([`NurbsError::BadShape`]): non-finite input, a zero `axis_dir`, a radius or
    /// height not > 0.
    pub fn cylinder(
        axis_origin: Point3<f64>,
        axis_dir: Vector3<f64>,
        radius: f64,
        height: f64,
    ) -> Result<Self> {
        finite_point("axis_origin", &axis_origin)?;
        let a = unit("axis_dir", &axis_dir)?;
        let r = positive("radius", radius)?;
        let h = positive("height", height)?;
        let foot = axis_origin + perpendicular(&a) * r;
        let line = NurbsCurve::line(foot, foot + a * h)?;
        Self::revolve(&line, axis_origin, a, TAU)
    }

    /// The sphere of `radius` about `center`: the half circle from the south pole
    /// `center - radius z` through `center + radius x` to the north pole (two 90-degree
    /// rational quadratic segments) revolved a full turn about the z axis through `center`
    /// with [`NurbsSurface::revolve`]. `u` goes round (domain `[0, 1]`), `v` from pole to pole
    /// (`[0, 1]`); the edges `v = 0` and `v = 1` are collapsed to the poles, where
    /// [`NurbsSurface::normal`] takes its limit. The normal points radially outwards.
    ///
    /// Errors ([`NurbsError::BadShape`]): a non-finite centre, a radius not finite and > 0.
    pub fn sphere(center: Point3<f64>, radius: f64) -> Result<Self> {
        finite_point("center", &center)?;
        let r = positive("radius", radius)?;
        let half = NurbsCurve::arc(
            center,
            Vector3::x(),
            Vector3::z(),
            r,
            -FRAC_PI_2,
            std::f64::consts::PI,
        )?;
        Self::revolve(&half, center, Vector3::z(), TAU)
    }

    /// The surface swept by `profile` turning `sweep_rad` about the axis through
    /// `axis_origin` along `axis_dir` (right-handed: counter-clockwise seen from the tip of
    /// `axis_dir`), exactly, as Piegl-Tiller A8.1 builds it. Each control point `P_j` (weight
    /// `w_j`) of the profile, at distance `r_j` from the axis with foot `O_j`, becomes the
    /// control polygon of the arc of radius `r_j` about `O_j` in the plane perpendicular to the
    /// axis ([`NurbsCurve::arc`]'s construction: the fewest segments of at most 90 degrees),
    /// with weights `w_j` times the arc's; points on the axis stay put. `u` is the direction of
    /// rotation (degree 2, domain `[0, 1]`), `v` the profile's (its degree, knots and domain).
    /// The normal `Su x Sv` is `(axis x radial) x profile tangent`: for a profile running
    /// along `+axis_dir` at positive radius it points away from the axis.
    ///
    /// Errors ([`NurbsError::BadShape`]): non-finite input, a zero `axis_dir`, a sweep outside
    /// `0 < |sweep| <= 2 pi`, or a profile whose every control point lies on the axis (the
    /// surface would be a line).
    pub fn revolve(
        profile: &NurbsCurve,
        axis_origin: Point3<f64>,
        axis_dir: Vector3<f64>,
        sweep_rad: f64,
    ) -> Result<Self> {
        finite_point("axis_origin", &axis_origin)?;
        let a = unit("axis_dir", &axis_dir)?;
        let sweep_rad = sweep("sweep_rad", sweep_rad)?;
        let (arc, arc_w, knots_u) = unit_arc(0.0, sweep_rad);
        let points = profile.control_points();
        let weights = profile.weights();
        let scale = profile.size().max(f64::MIN_POSITIVE);
        let mut net = vec![Vec::with_capacity(points.len()); arc.len()];
        let mut net_w = vec![Vec::with_capacity(points.len()); arc.len()];
        let mut off_axis = false;
        for (p, w) in points.iter().zip(&weights) {
            let foot = axis_origin + a * (p - axis_origin).dot(&a);
            let radial = p - foot;
            let r = radial.norm();
            // x: the radial direction; y = a x x. A point on the axis (r = 0) stays put.
            let (x, y) = if r > DEGENERATE * scale {
                off_axis = true;
                let x = radial / r;
                (x, a.cross(&x))
            } else {
                (Vector3::zeros(), Vector3::zeros())
            };
            for (i, &(c, s)) in arc.iter().enumerate() {
                net[i].push(if r > DEGENERATE * scale {
                    foot + x * (r * c) + y * (r * s)
                } else {
                    *p
                });
                net_w[i].push(w * arc_w[i]);
            }
        }
        if !off_axis {
            return Err(bad(
                "profile",
                "every control point lies on the axis (the surface would be a line)".to_string(),
            ));
        }
        let weights = (profile.is_rational() || arc_w.iter().any(|&w| w != 1.0)).then_some(net_w);
        Self::try_new(
            2,
            profile.degree(),
            knots_u,
            profile.knots().to_vec(),
            net,
            weights,
        )
    }
}
