//! STEP surfaces as exact NURBS surfaces in mm over a chosen parameter rectangle: planes,
//! cylinders, cones, spheres, tori, linear extrusions and revolutions are built from rational
//! quadratic arcs; B-spline surfaces (rational or not) are cut to the rectangle by knot
//! insertion. Each analytic surface has a natural parametrization (the one Open CASCADE
//! uses, so `Su x Sv` points the same way) and an inverse map from points to parameters,
//! used to find a face's parameter range from its boundary.

use std::f64::consts::{PI, TAU};

use kerf_nurbs::{NurbsCurve, NurbsSurface};

use nalgebra::{Point3, Vector3, Vector4};

use crate::curves::{arc_homogeneous, basis, expand_knots, sub_curve, Basis};
use crate::error::Result;
use crate::model::{
    boolean, err, geometry_err, int, list, real, reals, refs, Charge, Frame, Model,
};
use crate::parser::{Instance, Value};

/// A surface with its natural parametrization (the one Open CASCADE gives it, so that
/// `Su x Sv` points the same way): what a face lies on, before it is cut to the face.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum Geometry {
    /// `O + u x + v y`.
    Plane(Frame),
    /// `O + r (cos u x + sin u y) + v z`.
    Cylinder(Frame, f64),
    /// `O + (r + v tan a)(cos u x + sin u y) + v z` (v along the axis; Open CASCADE measures
    /// v along the generatrix, which is the same surface with v scaled by cos a).
    Cone(Frame, f64, f64),
    /// `O + r cos v (cos u x + sin u y) + r sin v z`.
    Sphere(Frame, f64),
    /// `O + (R + r cos v)(cos u x + sin u y) + r sin v z`.
    Torus(Frame, f64, f64),
    /// `C(u) + v d` (d unit).
    Extrusion(NurbsCurve, Vector3<f64>),
    /// `C(v)` turned by angle u about the axis through `origin` along unit `axis`; `x0` is the
    /// radial direction of the profile (u = 0).
    Revolution {
        /// The profile.
        profile: NurbsCurve,
        /// A point on the axis.
        origin: Point3<f64>,
        /// Unit axis.
        axis: Vector3<f64>,
        /// Unit radial direction of the profile.
        x0: Vector3<f64>,
    },
    /// A B-spline surface over its own domain.
    Nurbs(NurbsSurface),
    /// `basis + distance n` (`n` the basis's unit normal `Su x Sv / |Su x Sv|`) where the
    /// basis has no exact NURBS offset (a B-spline surface, an extrusion, a revolution), over
    /// the basis's parameters: [`Geometry::to_nurbs_bounded`] approximates it with a proven
    /// bound ([`NurbsSurface::offset`]).
    Offset {
        /// The surface offset.
        basis: Box<Geometry>,
        /// The distance along its normal, mm.
        distance: f64,
    },
}

/// What is proven about a face's surface where it approximates the file's.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Approximation {
    /// The largest distance, mm, between a point of the surface and the point of the file's it
    /// stands for (the same point of the basis offset; the parameters are the basis's NURBS
    /// ones, mirrored where the face is reversed).
    pub position_mm: f64,
    /// The largest angle, rad, between their normals at such points.
    pub normal_rad: f64,
    /// The work the approximation took, in cells of a bicubic polynomial surface
    /// ([`kerf_nurbs::OffsetSurface::work`]): charged to the reader's budget as
    /// [`crate::cad::PROJECTIONS_PER_OFFSET_CELL`] projections each.
    pub work: usize,
}

/// Which parameters are angles (periodic with period 2 pi).
impl Geometry {
    /// The surface swept by `profile` turned about the axis through `origin` along unit
    /// `axis`, angle 0 at the profile (its radial direction taken from the control point
    /// farthest from the axis); `None` if the profile lies on the axis (no area).
    pub fn revolution(
        profile: NurbsCurve,
        origin: Point3<f64>,
        axis: Vector3<f64>,
    ) -> Option<Self> {
        let x0 = profile
            .control_points()
            .iter()
            .map(|q| {
                let d = q - origin;
                d - axis * d.dot(&axis)
            })
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .filter(|r| r.norm() > 1e-12)
            .map(|r| r.normalize())?;
        Some(Geometry::Revolution {
            profile,
            origin,
            axis,
            x0,
        })
    }

    /// `(u periodic, v periodic)`.
    pub(crate) fn periodic(&self) -> (bool, bool) {
        match self {
            Geometry::Plane(_) | Geometry::Extrusion(..) | Geometry::Nurbs(_) => (false, false),
            Geometry::Cylinder(..) | Geometry::Cone(..) | Geometry::Sphere(..) => (true, false),
            Geometry::Revolution { .. } => (true, false),
            Geometry::Torus(..) => (true, true),
            Geometry::Offset { basis, .. } => basis.periodic(),
        }
    }

    /// A short name for reports.
    pub(crate) fn kind(&self) -> &'static str {
        match self {
            Geometry::Plane(_) => "plane",
            Geometry::Cylinder(..) => "cylinder",
            Geometry::Cone(..) => "cone",
            Geometry::Sphere(..) => "sphere",
            Geometry::Torus(..) => "torus",
            Geometry::Extrusion(..) => "extrusion",
            Geometry::Revolution { .. } => "revolution",
            Geometry::Nurbs(_) => "b-spline",
            Geometry::Offset { basis, .. } => match **basis {
                Geometry::Nurbs(_) => "offset b-spline",
                Geometry::Extrusion(..) => "offset extrusion",
                Geometry::Revolution { .. } => "offset revolution",
                _ => "offset surface",
            },
        }
    }

    /// The B-spline surface whose domain bounds the parameters: the surface itself, or the
    /// basis of its offset.
    pub(crate) fn nurbs_domain(&self) -> Option<&NurbsSurface> {
        match self {
            Geometry::Nurbs(s) => Some(s),
            Geometry::Offset { basis, .. } => basis.nurbs_domain(),
            _ => None,
        }
    }

    /// The natural parameters of (a point near) `p`; angles in `(-pi, pi]`.
    ///
    /// `warm` serves a run of nearby points (the samples along an edge): a B-spline surface's
    /// projection starts from the previous point's parameters in `warm` (Newton's method,
    /// walking across cells) and takes the local minimum it reaches where that is within
    /// [`WARM_ACCEPT_MM`] of `p`, the global search otherwise; `warm` then holds this point's
    /// parameters (`&mut None` for a lone point). A global search for each of an edge's 181
    /// samples was most of the reading time of a file of B-spline faces (15 s of 15.6 s on a
    /// 277-face impeller).
    pub(crate) fn params_near(&self, p: &Point3<f64>, warm: &mut Option<(f64, f64)>) -> (f64, f64) {
        self.params_at(p, warm, 0.0)
    }

    /// [`Geometry::params_near`] for a point `offset` mm from the surface along its normal:
    /// the foot on the basis of a point of its offset is the point it was offset from (where
    /// the offset does not fold over), so an offset surface's parameters are its basis's.
    fn params_at(&self, p: &Point3<f64>, warm: &mut Option<(f64, f64)>, offset: f64) -> (f64, f64) {
        match self {
            Geometry::Nurbs(s) => {
                let pr = foot_near(s, p, warm, offset.abs());
                (pr.u, pr.v)
            }
            Geometry::Offset { basis, distance } => basis.params_at(p, warm, offset + distance),
            _ => self.params_cold(p),
        }
    }

    /// [`Geometry::params_near`] without a start.
    fn params_cold(&self, p: &Point3<f64>) -> (f64, f64) {
        let ang = |f: &Frame, d: &Vector3<f64>| d.dot(&f.y).atan2(d.dot(&f.x));
        match self {
            Geometry::Plane(f) => {
                let d = p - f.origin;
                (d.dot(&f.x), d.dot(&f.y))
            }
            Geometry::Cylinder(f, _) | Geometry::Cone(f, _, _) => {
                let d = p - f.origin;
                (ang(f, &d), d.dot(&f.z))
            }
            Geometry::Sphere(f, _) => {
                let d = p - f.origin;
                let rho = (d.dot(&f.x).powi(2) + d.dot(&f.y).powi(2)).sqrt();
                (ang(f, &d), d.dot(&f.z).atan2(rho))
            }
            Geometry::Torus(f, big, _) => {
                let d = p - f.origin;
                let rho = (d.dot(&f.x).powi(2) + d.dot(&f.y).powi(2)).sqrt();
                (ang(f, &d), d.dot(&f.z).atan2(rho - big))
            }
            Geometry::Extrusion(c, dir) => {
                // Slide p along the direction onto the plane through C(start) normal to dir,
                // then find the curve point whose projection is nearest.
                let (a, _) = c.domain();
                let base = c.point(a);
                let q = p - dir * (p - base).dot(dir);
                let flat = flatten(c, dir, &base);
                let u = flat.closest_point(&q).t;
                (u, (p - c.point(u)).dot(dir))
            }
            Geometry::Revolution {
                profile,
                origin,
                axis,
                x0,
            } => {
                let d = p - origin;
                let y0 = axis.cross(x0);
                let u = d.dot(&y0).atan2(d.dot(x0));
                // Turn p back by -u into the profile's half-plane, then project on the profile.
                let h = d.dot(axis);
                let rho = (d - axis * h).norm();
                let q = origin + axis * h + x0 * rho;
                (u, profile.closest_point(&q).t)
            }
            Geometry::Nurbs(s) => {
                let pr = s.closest_point(p, None);
                (pr.u, pr.v)
            }
            Geometry::Offset { basis, .. } => basis.params_cold(p),
        }
    }

    /// The exact NURBS surface over `[u0, u1] x [v0, v1]` of the natural parameters.
    ///
    /// # Errors
    /// [`SurfaceRangeError::Empty`] for an empty (or NaN) range,
    /// [`SurfaceRangeError::Nurbs`] where the range leaves a B-spline's domain or the
    /// surface cannot be built (the NURBS error kept as the source).
    pub fn to_nurbs(
        &self,
        u: (f64, f64),
        v: (f64, f64),
    ) -> std::result::Result<NurbsSurface, SurfaceRangeError> {
        self.to_nurbs_bounded(u, v).map(|(s, _)| s)
    }

    /// [`Geometry::to_nurbs`] with what is proven where the surface is approximated: an
    /// [`Geometry::Offset`] is its basis over the range offset by [`NurbsSurface::offset`]
    /// within [`OFFSET_APPROXIMATION_MM`], with the bounds it proves (exact surfaces: `None`).
    ///
    /// # Errors
    /// As [`Geometry::to_nurbs`], and [`SurfaceRangeError::Offset`] where the offset is not
    /// built (it folds over, the normal vanishes, the budget runs out).
    pub fn to_nurbs_bounded(
        &self,
        u: (f64, f64),
        v: (f64, f64),
    ) -> std::result::Result<(NurbsSurface, Option<Approximation>), SurfaceRangeError> {
        if let Geometry::Offset { basis, distance } = self {
            let (b, inner) = basis.to_nurbs_bounded(u, v)?;
            let o = b.offset(
                *distance,
                &kerf_nurbs::SurfaceOffsetOptions::new(OFFSET_APPROXIMATION_MM),
            )?;
            // The basis is exact (offsets of offsets add their distances), so `inner` is None;
            // were it not, the bounds would add.
            let (p0, n0, w0) =
                inner.map_or((0.0, 0.0, 0), |a| (a.position_mm, a.normal_rad, a.work));
            return Ok((
                o.surface,
                Some(Approximation {
                    position_mm: o.position_bound_mm + p0,
                    normal_rad: o.normal_bound_rad + n0,
                    work: o.work + w0,
                }),
            ));
        }
        if !(u.1 > u.0) {
            return Err(SurfaceRangeError::Empty { direction: 'u' });
        }
        if !(v.1 > v.0) {
            return Err(SurfaceRangeError::Empty { direction: 'v' });
        }
        let s = match self {
            Geometry::Plane(f) => {
                let corner = |a: f64, b: f64| f.origin + f.x * a + f.y * b;
                NurbsSurface::try_new(
                    1,
                    1,
                    vec![u.0, u.0, u.1, u.1],
                    vec![v.0, v.0, v.1, v.1],
                    vec![
                        vec![corner(u.0, v.0), corner(u.0, v.1)],
                        vec![corner(u.1, v.0), corner(u.1, v.1)],
                    ],
                    None,
                )
            }
            Geometry::Cylinder(f, r) => revolve_profile(f, u, &line_profile(*r, v.0, *r, v.1)),
            Geometry::Cone(f, r, a) => {
                let t = a.tan();
                revolve_profile(f, u, &line_profile(r + v.0 * t, v.0, r + v.1 * t, v.1))
            }
            Geometry::Sphere(f, r) => revolve_profile(f, u, &circle_profile(0.0, *r, v)),
            Geometry::Torus(f, big, r) => revolve_profile(f, u, &circle_profile(*big, *r, v)),
            Geometry::Extrusion(c, d) => {
                let c = sub_curve(c, u.0, u.1)?;
                let p = c.degree();
                let rows: Vec<Vec<Point3<f64>>> = c
                    .control_points()
                    .iter()
                    .map(|q| vec![q + d * v.0, q + d * v.1])
                    .collect();
                let w = c.weights();
                NurbsSurface::try_new(
                    p,
                    1,
                    c.knots().to_vec(),
                    vec![v.0, v.0, v.1, v.1],
                    rows,
                    Some(w.iter().map(|&x| vec![x, x]).collect()),
                )
            }
            Geometry::Revolution {
                profile,
                origin,
                axis,
                x0,
            } => {
                let c = sub_curve(profile, v.0, v.1)?;
                revolution(origin, axis, x0, u, &c)
            }
            Geometry::Nurbs(s) => cut(s, u, v),
            Geometry::Offset { .. } => unreachable!("offsets are built above"),
        };
        Ok((s?, None))
    }
}

/// Why [`Geometry::to_nurbs`] has no surface for a parameter range.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SurfaceRangeError {
    /// The range is empty in one direction (a face whose boundary has no extent there).
    #[error("empty parameter range of the face: {direction}")]
    Empty {
        /// `'u'` or `'v'`.
        direction: char,
    },
    /// The NURBS surface could not be cut or built over the range (the NURBS error as the
    /// source).
    #[error("{0}")]
    Nurbs(#[from] kerf_nurbs::NurbsError),
    /// The offset of a surface could not be approximated over the range (the reason as the
    /// source).
    #[error("the offset of its surface: {0}")]
    Offset(#[from] kerf_nurbs::SurfaceOffsetError),
}

/// Projects a curve along `dir` onto the plane through `base` normal to `dir` (same knots
/// and weights), for the inverse map of an extrusion.
fn flatten(c: &NurbsCurve, dir: &Vector3<f64>, base: &Point3<f64>) -> NurbsCurve {
    let cpw = c
        .homogeneous_points()
        .iter()
        .map(|h| {
            let p = Point3::new(h.x / h.w, h.y / h.w, h.z / h.w);
            let q = p - dir * (p - base).dot(dir);
            Vector4::new(q.x * h.w, q.y * h.w, q.z * h.w, h.w)
        })
        .collect();
    NurbsCurve::from_homogeneous_unchecked(c.degree(), c.knots().to_vec(), cpw)
}

/// A profile in the (radial, axial) half-plane: homogeneous `(w rho, w h, 0, w)`, with knots.
struct Profile {
    degree: usize,
    knots: Vec<f64>,
    cpw: Vec<Vector4<f64>>,
}

fn line_profile(rho0: f64, h0: f64, rho1: f64, h1: f64) -> Profile {
    Profile {
        degree: 1,
        knots: vec![h0, h0, h1, h1],
        cpw: vec![
            Vector4::new(rho0, h0, 0.0, 1.0),
            Vector4::new(rho1, h1, 0.0, 1.0),
        ],
    }
}

/// The circle of radius `r` centred at radial distance `big` in the profile plane, from angle
/// `v.0` to `v.1` (angle 0 points radially outward, pi/2 along the axis).
fn circle_profile(big: f64, r: f64, v: (f64, f64)) -> Profile {
    let (knots, cpw) = arc_homogeneous(v.0, v.1);
    let scale = (v.1 - v.0) / knots[knots.len() - 1];
    Profile {
        degree: 2,
        knots: knots.iter().map(|k| v.0 + k * scale).collect(),
        cpw: cpw
            .iter()
            .map(|h| Vector4::new(big * h.w + r * h.x, r * h.y, 0.0, h.w))
            .collect(),
    }
}

/// The surface swept by a profile turned about the frame's z axis from angle `u.0` to `u.1`:
/// control points `O + rho_j Q_i + h_j z`, weights `w_i w_j`, where `Q_i` are the control
/// points of the unit arc in the frame's xy plane (The NURBS Book A8.1).
fn revolve_profile(f: &Frame, u: (f64, f64), prof: &Profile) -> kerf_nurbs::Result<NurbsSurface> {
    let (uk, arc) = arc_homogeneous(u.0, u.1);
    let scale = (u.1 - u.0) / uk[uk.len() - 1];
    let uk: Vec<f64> = uk.iter().map(|k| u.0 + k * scale).collect();
    let mut cpw = Vec::with_capacity(arc.len() * prof.cpw.len());
    for a in &arc {
        let (qx, qy, wa) = (a.x / a.w, a.y / a.w, a.w);
        for p in &prof.cpw {
            let (rho, h, wp) = (p.x / p.w, p.y / p.w, p.w);
            let q = f.origin + (f.x * qx + f.y * qy) * rho + f.z * h;
            let w = wa * wp;
            cpw.push(Vector4::new(q.x * w, q.y * w, q.z * w, w));
        }
    }
    surface_from_h(
        2,
        prof.degree,
        uk,
        prof.knots.clone(),
        arc.len(),
        prof.cpw.len(),
        &cpw,
    )
}

/// A general surface of revolution of a 3D profile about an axis.
fn revolution(
    origin: &Point3<f64>,
    axis: &Vector3<f64>,
    _x0: &Vector3<f64>,
    u: (f64, f64),
    c: &NurbsCurve,
) -> kerf_nurbs::Result<NurbsSurface> {
    let (uk, arc) = arc_homogeneous(u.0, u.1);
    let scale = (u.1 - u.0) / uk[uk.len() - 1];
    let uk: Vec<f64> = uk.iter().map(|k| u.0 + k * scale).collect();
    let prof = c.homogeneous_points();
    let mut cpw = Vec::with_capacity(arc.len() * prof.len());
    for a in &arc {
        let (qx, qy, wa) = (a.x / a.w, a.y / a.w, a.w);
        for h in prof {
            let p = Point3::new(h.x / h.w, h.y / h.w, h.z / h.w);
            let d = p - origin;
            let along = d.dot(axis);
            let radial = d - axis * along;
            let rho = radial.norm();
            let centre = origin + axis * along;
            let q = if rho > 0.0 {
                let x = radial / rho;
                let y = axis.cross(&x);
                centre + (x * qx + y * qy) * rho
            } else {
                centre
            };
            let w = wa * h.w;
            cpw.push(Vector4::new(q.x * w, q.y * w, q.z * w, w));
        }
    }
    surface_from_h(
        2,
        c.degree(),
        uk,
        c.knots().to_vec(),
        arc.len(),
        prof.len(),
        &cpw,
    )
}

/// A NURBS surface from a homogeneous net stored row by row (`cpw[a * nv + b]`).
fn surface_from_h(
    du: usize,
    dv: usize,
    ku: Vec<f64>,
    kv: Vec<f64>,
    nu: usize,
    nv: usize,
    cpw: &[Vector4<f64>],
) -> kerf_nurbs::Result<NurbsSurface> {
    let mut pts = Vec::with_capacity(nu);
    let mut w = Vec::with_capacity(nu);
    for a in 0..nu {
        let row = &cpw[a * nv..(a + 1) * nv];
        pts.push(
            row.iter()
                .map(|h| Point3::new(h.x / h.w, h.y / h.w, h.z / h.w))
                .collect(),
        );
        w.push(row.iter().map(|h| h.w).collect());
    }
    NurbsSurface::try_new(du, dv, ku, kv, pts, Some(w))
}

/// A NURBS surface cut to `[u0, u1] x [v0, v1]` by knot insertion, row by row.
fn cut(s: &NurbsSurface, u: (f64, f64), v: (f64, f64)) -> kerf_nurbs::Result<NurbsSurface> {
    let (nu, nv) = s.net_size();
    // Along u for every column b.
    let mut cols: Vec<NurbsCurve> = Vec::with_capacity(nv);
    for b in 0..nv {
        let h: Vec<Vector4<f64>> = (0..nu).map(|a| s.homogeneous_point(a, b)).collect();
        let c = NurbsCurve::from_homogeneous_unchecked(s.degree_u(), s.knots_u().to_vec(), h);
        cols.push(sub_curve(&c, u.0, u.1)?);
    }
    let nu2 = cols[0].len();
    let ku = cols[0].knots().to_vec();
    // Along v for every new row a.
    let mut rows: Vec<NurbsCurve> = Vec::with_capacity(nu2);
    for a in 0..nu2 {
        let h: Vec<Vector4<f64>> = cols.iter().map(|c| c.homogeneous_points()[a]).collect();
        let c = NurbsCurve::from_homogeneous_unchecked(s.degree_v(), s.knots_v().to_vec(), h);
        rows.push(sub_curve(&c, v.0, v.1)?);
    }
    let nv2 = rows[0].len();
    let kv = rows[0].knots().to_vec();
    let cpw: Vec<Vector4<f64>> = rows
        .iter()
        .flat_map(|r| r.homogeneous_points().iter().copied())
        .collect();
    surface_from_h(s.degree_u(), s.degree_v(), ku, kv, nu2, nv2, &cpw)
}

/// Reads a face's surface entity, with the sense of its normal: `true` where the entity's
/// `Su x Sv` is the opposite of the returned geometry's (a `RECTANGULAR_TRIMMED_SURFACE` that
/// reverses one of its two directions). `RECTANGULAR_TRIMMED_SURFACE` is its basis (the face's
/// boundary cuts it); `OFFSET_SURFACE` is exact where its basis is a plane, cylinder, cone,
/// sphere or torus, a [`Geometry::Offset`] to approximate otherwise ([`offset`]).
pub(crate) fn sensed_geometry(m: &Model<'_>, inst: &Instance) -> Result<(Geometry, bool)> {
    sensed_at(m, inst, 0)
}

/// The distance, mm, within which the offset of a B-spline surface is approximated (a hundredth
/// of the default on-surface tolerance): the bound proven is added to the on-surface tolerance
/// of every contour on the face.
pub const OFFSET_APPROXIMATION_MM: f64 = 1e-4;

/// The deepest nesting of trimmed and offset surfaces read.
const MAX_SURFACE_NESTING: usize = 16;

/// How near a B-spline surface a warm-started projection's point must be for
/// [`Geometry::params_near`] to take it without the global search, mm: the geometry tolerance
/// within which a face's edges must lie on it anyway. Along an edge, the walk from the previous
/// sample's foot follows the edge across the surface; the global search is for an edge's first
/// sample and for samples the walk loses (it stops short or lands farther than this).
pub(crate) const WARM_ACCEPT_MM: f64 = crate::curves::ON_GEOMETRY_TOLERANCE_MM;

/// The foot of `p` on `s` for a run of nearby points on the surface, or `offset` mm off it
/// along its normal (the samples along an edge of the surface or of its offset): Newton's
/// method from the previous foot in `warm`, taken where it ends within [`WARM_ACCEPT_MM`] of
/// `offset` from `p`, the global search otherwise (and always without a start); `warm` then
/// holds this foot's parameters.
pub(crate) fn foot_near(
    s: &NurbsSurface,
    p: &Point3<f64>,
    warm: &mut Option<(f64, f64)>,
    offset: f64,
) -> kerf_nurbs::SurfaceProjection {
    let mut pr = s.closest_point(p, *warm);
    if warm.is_some() && !((pr.distance - offset).abs() <= WARM_ACCEPT_MM) {
        pr = s.closest_point(p, None);
    }
    *warm = Some((pr.u, pr.v));
    pr
}

fn sensed_at(m: &Model<'_>, inst: &Instance, depth: usize) -> Result<(Geometry, bool)> {
    if depth > MAX_SURFACE_NESTING {
        return Err(err(
            inst,
            format!("trimmed and offset surfaces nest more than {MAX_SURFACE_NESTING} deep"),
        ));
    }
    if let Some(p) = inst.record("RECTANGULAR_TRIMMED_SURFACE") {
        let basis = m.param_ref(inst, p, 1)?;
        let (g, flipped) = sensed_at(m, &basis, depth + 1)?;
        let usense = boolean(inst, p.get(6), "usense")?;
        let vsense = boolean(inst, p.get(7), "vsense")?;
        // Reversing one direction turns `Su x Sv` round; reversing both keeps it.
        return Ok((g, flipped ^ (usense != vsense)));
    }
    if let Some(p) = inst.record("OFFSET_SURFACE") {
        let basis = m.param_ref(inst, p, 1)?;
        let (g, flipped) = sensed_at(m, &basis, depth + 1)?;
        let d = m.length(inst, p.get(2), "distance")?;
        // Along the basis entity's own normal, which is the geometry's turned round where
        // `flipped`.
        let d = if flipped { -d } else { d };
        return Ok((offset(g, d).map_err(|why| err(inst, why))?, flipped));
    }
    Ok((geometry(m, inst)?, false))
}

/// The surface at distance `d` along the unit normal `Su x Sv / |Su x Sv|` of `g`, exactly:
/// a plane moves along its normal; a cylinder, sphere or torus tube changes its radius by `d`
/// (their natural normal points outward); a cone `O + (r + v tan a)(cos u x + sin u y) + v z`,
/// whose unit normal is `cos a radial - sin a z`, becomes the cone of radius `r + d / cos a` at
/// its placement with the same angle (the point `P + d n` has height `v - d sin a` and radius
/// `r + v tan a + d cos a = r + (v - d sin a) tan a + d / cos a`). The offset of a B-spline
/// surface, an extrusion or a revolution is not rational: it is [`Geometry::Offset`], which
/// [`Geometry::to_nurbs_bounded`] approximates over the face's range once that is known (an
/// offset of such an offset adds the distances: the normal is the same). An offset that leaves
/// no surface (a radius at or below zero) is refused with the reason.
pub(crate) fn offset(g: Geometry, d: f64) -> std::result::Result<Geometry, String> {
    let radius = |r: f64, what: &str| {
        if r > 0.0 && r.is_finite() {
            Ok(r)
        } else {
            Err(format!(
                "offsetting the {what} by {d} mm leaves a radius of {r} mm: no surface"
            ))
        }
    };
    Ok(match g {
        Geometry::Plane(f) => Geometry::Plane(Frame {
            origin: f.origin + f.z * d,
            ..f
        }),
        Geometry::Cylinder(f, r) => Geometry::Cylinder(f, radius(r + d, "cylinder")?),
        Geometry::Cone(f, r, a) => {
            let r1 = r + d / a.cos();
            if !(r1 >= 0.0) {
                return Err(format!(
                    "offsetting the cone by {d} mm moves its apex past its placement (radius {r1} mm there): not read"
                ));
            }
            Geometry::Cone(f, r1, a)
        }
        Geometry::Sphere(f, r) => Geometry::Sphere(f, radius(r + d, "sphere")?),
        Geometry::Torus(f, big, r) => Geometry::Torus(f, big, radius(r + d, "torus tube")?),
        Geometry::Offset { basis, distance } => Geometry::Offset {
            basis,
            distance: distance + d,
        },
        basis @ (Geometry::Nurbs(_) | Geometry::Extrusion(..) | Geometry::Revolution { .. }) => {
            Geometry::Offset {
                basis: Box::new(basis),
                distance: d,
            }
        }
    })
}

/// Reads a supported surface entity.
pub(crate) fn geometry(m: &Model<'_>, inst: &Instance) -> Result<Geometry> {
    let positive = |x: f64, what: &str| {
        if x > 0.0 && x.is_finite() {
            Ok(x)
        } else {
            Err(err(inst, format!("{what} must be > 0, found {x}")))
        }
    };
    if let Some(p) = inst.record("PLANE") {
        return Ok(Geometry::Plane(m.placement(&m.param_ref(inst, p, 1)?)?));
    }
    if let Some(p) = inst.record("CYLINDRICAL_SURFACE") {
        let f = m.placement(&m.param_ref(inst, p, 1)?)?;
        let r = positive(m.length(inst, p.get(2), "radius")?, "radius")?;
        return Ok(Geometry::Cylinder(f, r));
    }
    if let Some(p) = inst.record("CONICAL_SURFACE") {
        let f = m.placement(&m.param_ref(inst, p, 1)?)?;
        let r = m.length(inst, p.get(2), "radius")?;
        let a = real(inst, p.get(3), "semi_angle")? * m.units.rad_per_angle;
        if !(r >= 0.0) || !(a.abs() < PI / 2.0) || a == 0.0 {
            return Err(err(
                inst,
                format!("radius {r} must be >= 0 and the semi-angle {a} rad in (0, pi/2)"),
            ));
        }
        return Ok(Geometry::Cone(f, r, a));
    }
    if let Some(p) = inst.record("SPHERICAL_SURFACE") {
        let f = m.placement(&m.param_ref(inst, p, 1)?)?;
        let r = positive(m.length(inst, p.get(2), "radius")?, "radius")?;
        return Ok(Geometry::Sphere(f, r));
    }
    if let Some(p) = inst.record("TOROIDAL_SURFACE") {
        let f = m.placement(&m.param_ref(inst, p, 1)?)?;
        let big = positive(m.length(inst, p.get(2), "major_radius")?, "major_radius")?;
        let r = positive(m.length(inst, p.get(3), "minor_radius")?, "minor_radius")?;
        return Ok(Geometry::Torus(f, big, r));
    }
    if let Some(p) = inst.record("SURFACE_OF_LINEAR_EXTRUSION") {
        let c = whole_curve(m, &m.param_ref(inst, p, 1)?)?;
        let (d, _) = m.vector(&m.param_ref(inst, p, 2)?)?;
        return Ok(Geometry::Extrusion(c, d));
    }
    if let Some(p) = inst.record("SURFACE_OF_REVOLUTION") {
        let profile = whole_curve(m, &m.param_ref(inst, p, 1)?)?;
        let ax = &m.param_ref(inst, p, 2)?;
        let ap = m.rec(ax, "AXIS1_PLACEMENT")?;
        let origin = m.point(&m.param_ref(ax, ap, 1)?)?;
        let axis = match ap.get(2) {
            Some(crate::parser::Value::Ref(_)) => m.direction(&m.param_ref(ax, ap, 2)?)?,
            _ => Vector3::z(),
        };
        return Geometry::revolution(profile, origin, axis)
            .ok_or_else(|| err(inst, "the profile lies on the axis"));
    }
    if inst.is("B_SPLINE_SURFACE_WITH_KNOTS") || inst.is("B_SPLINE_SURFACE") {
        return bspline_surface(m, inst).map(Geometry::Nurbs);
    }
    Err(err(inst, "surface type not supported (planes, cylinders, cones, spheres, tori, extrusions, revolutions and B-spline surfaces are)"))
}

/// A curve used whole as the profile of a swept surface: bounded curves as they are, conics
/// as the full turn from angle 0, lines over a long stretch.
fn whole_curve(m: &Model<'_>, inst: &Instance) -> Result<NurbsCurve> {
    if inst.is("TRIMMED_CURVE") {
        return crate::curves::trimmed(m, inst);
    }
    match basis(m, inst)? {
        Basis::Nurbs(c) => Ok(c),
        b @ Basis::Conic { .. } => b.piece(inst, 0.0, TAU),
        Basis::Line { .. } => Err(err(
            inst,
            "an unbounded line as a swept profile is not supported",
        )),
    }
}

fn bspline_surface(m: &Model<'_>, inst: &Instance) -> Result<NurbsSurface> {
    let (head, krec) = if let Some(b) = inst.record("B_SPLINE_SURFACE") {
        (b, inst.record("B_SPLINE_SURFACE_WITH_KNOTS"))
    } else {
        let k = m.rec(inst, "B_SPLINE_SURFACE_WITH_KNOTS")?;
        (k.get(1..).unwrap_or(&[]), Some(k.get(8..).unwrap_or(&[])))
    };
    let krec = krec.ok_or_else(|| err(inst, "a B-spline surface without knots"))?;
    let du = int(inst, head.first(), "u_degree")?;
    let dv = int(inst, head.get(1), "v_degree")?;
    let rows = list(inst, head.get(2), "control_points_list")?;
    let count: usize = rows
        .iter()
        .map(|r| match r {
            Value::List(l) => l.len(),
            _ => 1,
        })
        .sum();
    m.charge(inst, Charge::SurfacePoints, count)?;
    let mut net = Vec::with_capacity(rows.len());
    for (a, row) in rows.iter().enumerate() {
        let ids = refs(inst, Some(row), &format!("control_points_list[{a}]"))?;
        net.push(
            ids.into_iter()
                .map(|id| m.point(&m.get(inst, id)?))
                .collect::<Result<Vec<_>>>()?,
        );
    }
    if krec.len() < 4 {
        return Err(err(inst, "expected u and v knot multiplicities and knots"));
    }
    let ku = expand_knots(inst, &[krec[0].clone(), krec[2].clone()])?;
    let kv = expand_knots(inst, &[krec[1].clone(), krec[3].clone()])?;
    let weights = match inst.record("RATIONAL_B_SPLINE_SURFACE") {
        Some(r) => {
            let w = list(inst, r.first(), "weights_data")?;
            Some(
                w.iter()
                    .enumerate()
                    .map(|(a, row)| reals(inst, Some(row), &format!("weights_data[{a}]")))
                    .collect::<Result<Vec<_>>>()?,
            )
        }
        None => None,
    };
    NurbsSurface::try_new(du, dv, ku, kv, net, weights).map_err(|e| geometry_err(inst, e))
}

/// The smallest interval covering the angles `a` (any values) on the circle: the complement
/// of the largest gap between neighbours, returned with `start <= end <= start + 2 pi`. If
/// the largest gap is below `full_turn_gap`, the whole turn starting at the gap.
pub(crate) fn angle_range(a: &[f64], full_turn_gap: f64) -> (f64, f64) {
    let mut s: Vec<f64> = a.iter().map(|x| x.rem_euclid(TAU)).collect();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return (0.0, TAU);
    }
    let mut best = (s[0] + TAU - s[s.len() - 1], s.len() - 1);
    for i in 0..s.len() - 1 {
        let g = s[i + 1] - s[i];
        if g > best.0 {
            best = (g, i);
        }
    }
    let (gap, i) = best;
    let start = s[(i + 1) % s.len()];
    if gap < full_turn_gap {
        return (start, start + TAU);
    }
    let mut end = s[i];
    if end < start {
        end += TAU;
    }
    (start, end)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        let z = Vector3::new(0.3, -0.2, 1.0).normalize();
        let x = crate::model::default_x(&z);
        Frame {
            origin: Point3::new(1.0, -2.0, 0.5),
            x,
            y: z.cross(&x),
            z,
        }
    }

    fn analytic(g: &Geometry, u: f64, v: f64) -> (Point3<f64>, Vector3<f64>) {
        let f = match g {
            Geometry::Cylinder(f, _)
            | Geometry::Cone(f, ..)
            | Geometry::Sphere(f, _)
            | Geometry::Torus(f, ..) => *f,
            _ => unreachable!("analytic surfaces only"),
        };
        let (c, s) = (u.cos(), u.sin());
        let radial = f.x * c + f.y * s;
        let (p, n) = match g {
            Geometry::Cylinder(_, r) => (f.origin + radial * *r + f.z * v, radial),
            Geometry::Cone(_, r, a) => {
                let n = (radial - f.z * a.tan()).normalize();
                (f.origin + radial * (r + v * a.tan()) + f.z * v, n)
            }
            Geometry::Sphere(_, r) => {
                let n = radial * v.cos() + f.z * v.sin();
                (f.origin + n * *r, n)
            }
            Geometry::Torus(_, big, r) => {
                let n = radial * v.cos() + f.z * v.sin();
                (f.origin + radial * *big + n * *r, n)
            }
            _ => unreachable!("analytic surfaces only"),
        };
        (p, n)
    }

    #[test]
    fn analytic_surfaces_are_exact_and_outward() {
        let cases = [
            (Geometry::Cylinder(frame(), 3.0), (0.2, 5.5), (-1.0, 2.0)),
            (Geometry::Cone(frame(), 2.0, 0.4), (-3.0, 1.0), (0.0, 3.0)),
            (Geometry::Sphere(frame(), 4.0), (0.0, TAU), (-1.2, 1.5)),
            (Geometry::Torus(frame(), 6.0, 1.5), (1.0, 4.0), (-2.5, 3.0)),
        ];
        for (g, u, v) in &cases {
            let s = g.to_nurbs(*u, *v).expect("converts");
            let (ua, ub) = s.domain_u();
            let (va, vb) = s.domain_v();
            for i in 0..=20 {
                for j in 0..=20 {
                    let (a, b) = (
                        ua + (ub - ua) * i as f64 / 20.0,
                        va + (vb - va) * j as f64 / 20.0,
                    );
                    let p = s.point(a, b);
                    let (pu, pv) = g.params_near(&p, &mut None);
                    let (q, n) = analytic(g, pu, pv);
                    assert!(
                        (p - q).norm() < 1e-11,
                        "{}: point off the surface by {}",
                        g.kind(),
                        (p - q).norm()
                    );
                    if let Some(sn) = s.normal(a, b) {
                        assert!(
                            sn.dot(&n) > 1.0 - 1e-9,
                            "{}: normal {sn:?} vs analytic {n:?}",
                            g.kind()
                        );
                    }
                }
            }
            // The corners map to the requested range.
            let (pu, pv) = g.params_near(&s.point(ua, va), &mut None);
            assert!(
                (pu - u.0).rem_euclid(TAU).min((u.0 - pu).rem_euclid(TAU)) < 1e-9,
                "{} u start",
                g.kind()
            );
            assert!(
                (pv - v.0).abs() < 1e-9 || g.periodic().1,
                "{} v start",
                g.kind()
            );
        }
    }

    /// Along a boundary, each B-spline projection starts from the previous sample's foot: it
    /// finds the foot the global search finds, the exact one, on a multi-cell rational surface
    /// (a torus patch as a B-spline face) for a curve across many cells, on the surface,
    /// 0.05 mm off it along the normal and on its offset by 0.5 mm; and it is the warm path that finds it, counted in
    /// surface evaluations (kerf-nurbs' `eval-counter`): a small part of what the global
    /// searches of the same samples cost.
    #[test]
    fn warm_started_parameters_along_an_edge_are_the_global_ones() {
        let torus = Geometry::Torus(frame(), 6.0, 1.5)
            .to_nurbs((0.3, 5.0), (-2.0, 2.5))
            .expect("converts");
        let (ua, ub) = torus.domain_u();
        let (va, vb) = torus.domain_v();
        let g = Geometry::Nurbs(torus.clone());
        // 0.5 mm off is read as a point of the surface's offset by 0.5 mm (its parameters are
        // the basis's, the warm foot accepted 0.5 mm away).
        let offset = Geometry::Offset {
            basis: Box::new(g.clone()),
            distance: 0.5,
        };
        for off in [0.0, 0.05, 0.5] {
            let g = if off == 0.5 { &offset } else { &g };
            let samples: Vec<(f64, f64, Point3<f64>)> = (0..=180)
                .map(|k| {
                    let t = k as f64 / 180.0;
                    let (a, b) = (ua + (ub - ua) * t, va + (vb - va) * (0.1 + 0.8 * t * t));
                    let n = torus.normal(a, b).expect("regular");
                    (a, b, torus.point(a, b) + n * off)
                })
                .collect();
            let mut warm = None;
            let (warm_feet, warm_work) = kerf_nurbs::counted(|| {
                samples
                    .iter()
                    .map(|(_, _, p)| g.params_near(p, &mut warm))
                    .collect::<Vec<_>>()
            });
            let (cold_feet, cold_work) = kerf_nurbs::counted(|| {
                samples
                    .iter()
                    .map(|(_, _, p)| {
                        let c = torus.closest_point(p, None);
                        (c.u, c.v)
                    })
                    .collect::<Vec<_>>()
            });
            for (k, ((a, b, _), (wf, cf))) in samples
                .iter()
                .zip(warm_feet.iter().zip(&cold_feet))
                .enumerate()
            {
                // The foot of a point on the normal (within the tube's 1.5 mm radius) is
                // (a, b) itself: both searches must find it (to 1e-8, or 1e-7 where the
                // point is 0.5 mm off and the distance's minimum is flatter).
                let tol = if off == 0.5 { 1e-7 } else { 1e-8 };
                for (what, (x, y)) in [("warm", wf), ("global", cf)] {
                    assert!(
                        (x - a).abs() < tol && (y - b).abs() < tol,
                        "sample {k}, {off} mm off: {what} ({x}, {y}), foot ({a}, {b})"
                    );
                }
            }
            let (w, c) = (
                warm_work.expect("kerf-nurbs' eval-counter is on in these tests"),
                cold_work.expect("counter"),
            );
            assert!(
                8 * w < c,
                "{off} mm off: the warm walk took {w} evaluations, the global searches {c}"
            );
        }
    }

    #[test]
    fn offsets_that_leave_no_surface_are_refused_and_free_form_ones_approximated() {
        let cyl = Geometry::Cylinder(frame(), 3.0);
        let e = offset(cyl, -3.0).expect_err("radius 0");
        assert!(e.contains("leaves a radius of 0 mm"), "{e}");
        let cone = Geometry::Cone(frame(), 1.0, 0.5);
        assert!(offset(cone, -2.0)
            .expect_err("past the apex")
            .contains("apex"));
        let s = NurbsSurface::try_new(
            1,
            1,
            vec![0.0, 0.0, 1.0, 1.0],
            vec![0.0, 0.0, 1.0, 1.0],
            vec![
                vec![Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 1.0, 0.0)],
                vec![Point3::new(1.0, 0.0, 0.0), Point3::new(1.0, 1.0, 0.2)],
            ],
            None,
        )
        .expect("surface");
        // A B-spline surface's offset, offset again: one offset by the sum, approximated over
        // the range asked for, with its bounds.
        let g = offset(
            offset(Geometry::Nurbs(s.clone()), 1.0).expect("offset"),
            0.5,
        )
        .expect("offset");
        assert!(
            matches!(&g, Geometry::Offset { distance, .. } if *distance == 1.5),
            "{g:?}"
        );
        let (a, bound) = g
            .to_nurbs_bounded((0.25, 1.0), (0.0, 0.5))
            .expect("approximated");
        let bound = bound.expect("the bounds");
        assert!(bound.position_mm <= OFFSET_APPROXIMATION_MM, "{bound:?}");
        assert_eq!(
            (a.domain_u(), a.domain_v()),
            ((0.25, 1.0), (0.0, 0.5)),
            "the range asked for"
        );
        let (p, su, sv) = s.eval_d1(0.6, 0.3);
        let exact = p + su.cross(&sv).normalize() * 1.5;
        assert!(
            (a.point(0.6, 0.3) - exact).norm() <= bound.position_mm,
            "within the bound of S + 1.5 n"
        );
        // An extrusion of a circle of radius 10 about z: its offset by 2 is the radius-12
        // cylinder (`C' x z` points outward); by -12 it folds over and is refused.
        let circle = NurbsCurve::circle(Point3::origin(), Vector3::z(), 10.0).expect("circle");
        let ext = Geometry::Extrusion(circle, Vector3::z());
        let (c12, bound) = offset(ext.clone(), 2.0)
            .expect("offset")
            .to_nurbs_bounded((0.0, 1.0), (-3.0, 4.0))
            .expect("approximated");
        let bound = bound.expect("the bounds");
        for k in 0..=40 {
            let q = c12.point(k as f64 / 40.0, 1.5);
            assert!(
                (q.x.hypot(q.y) - 12.0).abs() <= bound.position_mm
                    && (q.z - 1.5).abs() <= bound.position_mm,
                "on the radius-12 cylinder: {q}"
            );
        }
        let fold = offset(ext, -12.0)
            .expect("offset")
            .to_nurbs_bounded((0.0, 1.0), (0.0, 1.0));
        assert!(
            matches!(
                fold,
                Err(SurfaceRangeError::Offset(
                    kerf_nurbs::SurfaceOffsetError::Folds { .. }
                ))
            ),
            "{fold:?}"
        );
    }

    /// An empty range is a typed error naming its direction, with the reader's message.
    #[test]
    fn an_empty_range_is_a_typed_error() {
        let cyl = Geometry::Cylinder(frame(), 3.0);
        for (u, v, dir) in [((0.0, 1.0), (2.0, 2.0), 'v'), ((1.0, 1.0), (0.0, 2.0), 'u')] {
            match cyl.to_nurbs(u, v) {
                Err(e @ SurfaceRangeError::Empty { direction }) => {
                    assert_eq!(direction, dir);
                    assert_eq!(
                        e.to_string(),
                        format!("empty parameter range of the face: {dir}")
                    );
                }
                other => panic!("{other:?}"),
            }
        }
        assert!(cyl.to_nurbs((0.0, 1.0), (f64::NAN, 2.0)).is_err(), "NaN");
    }

    #[test]
    fn angle_ranges() {
        let (a, b) = angle_range(&[0.1, 0.5, 1.0], 0.1);
        assert!(
            (a - 0.1).abs() < 1e-15 && (b - 1.0).abs() < 1e-15,
            "simple range {a} {b}"
        );
        let (a, b) = angle_range(&[-0.5, 0.5], 0.1);
        assert!(
            (a - (TAU - 0.5)).abs() < 1e-12 && (b - (TAU + 0.5)).abs() < 1e-12,
            "wrap {a} {b}"
        );
        let pts: Vec<f64> = (0..100).map(|k| k as f64 * TAU / 100.0).collect();
        let (a, b) = angle_range(&pts, 0.1);
        assert!((b - a - TAU).abs() < 1e-12, "full turn");
    }
}
