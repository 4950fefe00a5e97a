//! Surface normals for cutting points: `(x, y, z)` becomes `(x, y, z, i, j, k)`.
//!
//! The laser beam stands normal to the part, so every cutting point gets the unit normal of the
//! surface that carries its curve: a NURBS surface ([`NurbsNormals`], `Su x Sv` at the closest
//! point, warm-started from the previous point) or a triangle mesh ([`MeshNormals`], parry3d's
//! `TriMesh` with crease-aware smooth normals). [`orient`] also
//!
//! - rejects a curve that does not lie on its surface (`on_surface_tolerance_mm`),
//! - inserts cutting points (on the curve) until neighbouring normals differ by at most
//!   `max_normal_step_deg`, re-certifying every new segment so the chord-error guarantee holds,
//! - refuses a normal that reverses between neighbouring points (inconsistent orientation),
//!   and reports normal jumps that insertion cannot remove (a curve crossing a sharp mesh edge).
//!
//! `docs/normals.md` has the details.

mod error;
mod mesh;
mod surface;

pub use error::{NormalsError, Result};
pub use mesh::{MeshNormals, DEFAULT_CREASE_ANGLE_DEG, MAX_MESH_COORDINATE_MM};
pub use surface::{Hint, NormalSource, NurbsNormals, Projection};

use kerf_discretize::{discretize_range, Discretization, Options};
use kerf_discretize::{Certifier, Scratch};
use kerf_format::Pose;
use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3};

/// Options of the normals stage. Lengths in mm, angles in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct NormalOptions {
    /// A cutting point farther than this from its surface is an error. Default 0.01 mm.
    pub on_surface_tolerance_mm: f64,
    /// The largest angle between the normals of neighbouring cutting points; points are
    /// inserted until it holds, degrees (strictly between 0 and 180). Default 1.
    pub max_normal_step_deg: f64,
    /// Refuse a curve that needs more inserted points than this (a count). Default 1,000,000.
    pub max_inserted: usize,
}

impl Default for NormalOptions {
    fn default() -> Self {
        Self {
            on_surface_tolerance_mm: 0.01,
            max_normal_step_deg: 1.0,
            max_inserted: 1_000_000,
        }
    }
}

impl NormalOptions {
    /// Sets [`on_surface_tolerance_mm`](Self::on_surface_tolerance_mm): a cutting point
    /// farther than this from its surface is an error.
    pub fn with_on_surface_tolerance_mm(mut self, on_surface_tolerance_mm: f64) -> Self {
        self.on_surface_tolerance_mm = on_surface_tolerance_mm;
        self
    }

    /// Sets [`max_normal_step_deg`](Self::max_normal_step_deg): the largest angle between
    /// the normals of neighbouring cutting points.
    pub fn with_max_normal_step_deg(mut self, max_normal_step_deg: f64) -> Self {
        self.max_normal_step_deg = max_normal_step_deg;
        self
    }

    /// Sets [`max_inserted`](Self::max_inserted): refuse a curve that needs more inserted
    /// points than this.
    pub fn with_max_inserted(mut self, max_inserted: usize) -> Self {
        self.max_inserted = max_inserted;
        self
    }

    /// Checks every option.
    ///
    /// # Errors
    /// [`NormalsError::BadOption`] naming the first bad option.
    pub fn validate(&self) -> Result<()> {
        if !(self.on_surface_tolerance_mm.is_finite() && self.on_surface_tolerance_mm > 0.0) {
            return Err(NormalsError::BadOption {
                name: "on_surface_tolerance_mm",
                value: self.on_surface_tolerance_mm,
                reason: "must be finite and > 0",
            });
        }
        if !(self.max_normal_step_deg > 0.0 && self.max_normal_step_deg < 180.0) {
            return Err(NormalsError::BadOption {
                name: "max_normal_step_deg",
                value: self.max_normal_step_deg,
                reason: "must lie strictly between 0 and 180 degrees",
            });
        }
        Ok(())
    }
}

/// Cutting points with their normals, and the certified chord-error bound of the polyline
/// through them.
///
/// The points, parameters, normals and bound are private and read through accessors: an
/// `Oriented` comes only from [`orient`] or [`Oriented::vertical`], both of which start from a
/// [`Discretization`] (itself only made by the discretizer or
/// [`Discretization::certify`]), so [`Oriented::max_chord_error`] is always a proven bound for
/// exactly these points and cannot be set by hand.
#[derive(Debug, Clone, PartialEq)]
pub struct Oriented {
    params: Vec<f64>,
    points: Vec<Point3<f64>>,
    normals: Vec<Vector3<f64>>,
    max_chord_error: f64,
    /// How many points were inserted for the normal step (and the re-certification).
    pub inserted: usize,
    /// The largest distance from a cutting point to the surface, mm.
    pub max_surface_distance: f64,
    /// The largest angle between neighbouring normals, radians.
    pub max_normal_angle: f64,
    /// Parameters where the normal jumps by more than the step however close the points are
    /// (the curve crosses a sharp edge of the surface): the head must turn in place there.
    pub jumps: Vec<f64>,
}

impl Oriented {
    /// The points of `disc` with the tool axis +z at every one (flat 2D cutting with a
    /// vertical beam: a curve without a surface). The bound is the discretization's own.
    pub fn vertical(disc: &Discretization) -> Self {
        Self {
            params: disc.params().to_vec(),
            points: disc.points().to_vec(),
            normals: vec![Vector3::z(); disc.points().len()],
            max_chord_error: disc.max_chord_error(),
            inserted: 0,
            max_surface_distance: 0.0,
            max_normal_angle: 0.0,
            jumps: Vec::new(),
        }
    }

    /// An empty result to be filled by [`orient`], starting from the bound of `disc`.
    fn start(disc: &Discretization) -> Self {
        let n = disc.params().len();
        Self {
            params: Vec::with_capacity(n),
            points: Vec::with_capacity(n),
            normals: Vec::with_capacity(n),
            max_chord_error: disc.max_chord_error(),
            inserted: 0,
            max_surface_distance: 0.0,
            max_normal_angle: 0.0,
            jumps: Vec::new(),
        }
    }

    /// Curve parameters, strictly increasing (the discretization's plus inserted ones).
    pub fn params(&self) -> &[f64] {
        &self.params
    }

    /// The points `C(t)`, mm.
    pub fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    /// The unit normals, one per point.
    pub fn normals(&self) -> &[Vector3<f64>] {
        &self.normals
    }

    /// Certified chord-error bound over all segments (the discretization's and every segment
    /// that inserted points made), mm.
    pub fn max_chord_error(&self) -> f64 {
        self.max_chord_error
    }

    /// Each point with its normal as the tool axis.
    pub fn poses(&self) -> Vec<Pose> {
        self.points
            .iter()
            .zip(&self.normals)
            .map(|(&position, &axis)| Pose { position, axis })
            .collect()
    }
}

#[derive(Debug, Clone, Copy)]
struct Sample {
    t: f64,
    p: Point3<f64>,
    /// The normal written for the point: at a degenerate foot, the limit along the curve from
    /// before `t` (from after it at the curve's start).
    n: Vector3<f64>,
    /// The normal the curve leaves the point with (the limit from after `t`): differs from `n`
    /// only at a degenerate foot such as a cone's apex.
    n_after: Vector3<f64>,
    hint: Hint,
}

/// A warm-started projection farther than this from the surface (or than the on-surface
/// tolerance, if smaller) is redone from scratch, mm: kerf's default on-surface tolerance.
const RESCUE_ABOVE_MM: f64 = 0.01;

struct Ctx<'a> {
    curve: &'a NurbsCurve,
    /// Built once per curve: re-certifying an inserted segment costs no pass over the curve.
    cert: Certifier<'a>,
    scratch: Scratch,
    surface: &'a dyn NormalSource,
    dopts: &'a Options,
    nopts: &'a NormalOptions,
    min_dt: f64,
    out: Oriented,
}

impl Ctx<'_> {
    fn sample(&mut self, t: f64, p: Point3<f64>, hint: Hint) -> Result<Sample> {
        let mut pr = self.surface.project(&p, hint);
        let degenerate = self.surface.is_degenerate(pr.hint);
        // Redone globally above the tolerance or 0.01 mm, whichever is smaller: a curve allowed
        // a looser tolerance of its own (a CAD edge, up to 0.1 mm) still gets its nearest
        // surface point, not a warm start's local minimum.
        let rescue = self.nopts.on_surface_tolerance_mm.min(RESCUE_ABOVE_MM);
        if hint != Hint::None
            && (pr.distance > rescue || (degenerate && pr.distance > 1e-6 * rescue))
        {
            // A warm start can settle in a local minimum, or stay on a collapsed edge the
            // point has left: decide globally, keep the closer.
            let global = self.surface.project(&p, Hint::None);
            if global.distance < pr.distance {
                pr = global;
            }
        }
        if pr.distance > self.nopts.on_surface_tolerance_mm || pr.distance.is_nan() {
            return Err(NormalsError::OffSurface {
                t,
                distance: pr.distance,
                tolerance: self.nopts.on_surface_tolerance_mm,
            });
        }
        self.out.max_surface_distance = self.out.max_surface_distance.max(pr.distance);
        let mut n = pr.normal.ok_or(NormalsError::NoNormal { t })?;
        let mut n_after = n;
        let mut hint = pr.hint;
        if self.surface.is_degenerate(pr.hint) {
            // At a collapsed edge or apex the normal is the limit along the curve, on the side
            // the curve is on: from before t for the point itself, from after t for what
            // follows (and for the warm start of the next point).
            let (da, db) = self.curve.domain();
            let step = 1e-6 * (db - da);
            let before = (t > da).then(|| {
                let s = (t - step).max(da);
                self.surface.normal_from(pr.hint, &self.curve.point(s))
            });
            let after = (t < db).then(|| {
                let s = (t + step).min(db);
                self.surface.normal_from(pr.hint, &self.curve.point(s))
            });
            if let Some(Some((nb, _))) = before {
                n = nb;
            }
            if let Some(Some((na, h))) = after {
                n_after = na;
                hint = h;
                if before.is_none() {
                    n = na;
                }
            } else {
                n_after = n;
            }
        }
        Ok(Sample {
            t,
            p,
            n,
            n_after,
            hint,
        })
    }

    fn push(&mut self, s: &Sample) {
        self.out.params.push(s.t);
        self.out.points.push(s.p);
        self.out.normals.push(s.n);
    }

    /// Emits the segment `(a, b]`: splits it until the normal step holds; `certified` says
    /// whether `[a, b]` already carries the chord-error guarantee.
    fn segment(&mut self, a: Sample, b: Sample, certified: bool) -> Result<()> {
        let angle = a.n_after.angle(&b.n);
        let tm = 0.5 * (a.t + b.t);
        if angle > self.nopts.max_normal_step_deg.to_radians() {
            // Stop splitting when the interval is tiny, or so close to the float spacing that
            // its midpoint is no longer strictly inside (large parameter values).
            if b.t - a.t <= self.min_dt || !(a.t < tm && tm < b.t) {
                if a.n_after.dot(&b.n) < 0.0 {
                    return Err(NormalsError::Reversed {
                        t: a.t,
                        angle: angle.to_degrees(),
                    });
                }
                self.out.jumps.push(a.t);
                return self.finish(a, b, certified);
            }
            if self.out.inserted >= self.nopts.max_inserted {
                return Err(NormalsError::TooManyInserted {
                    limit: self.nopts.max_inserted,
                });
            }
            let m = self.sample(tm, self.curve.point(tm), a.hint)?;
            self.out.inserted += 1;
            self.segment(a, m, false)?;
            return self.segment(m, b, false);
        }
        self.finish(a, b, certified)
    }

    /// Certifies `[a, b]` if needed (re-discretizing it when a split made it worse), then
    /// pushes `b`.
    fn finish(&mut self, a: Sample, b: Sample, certified: bool) -> Result<()> {
        if !certified {
            let tol = self.dopts.tolerance_mm;
            let bound = self
                .cert
                .chord_error(&mut self.scratch, a.t, b.t, &a.p, &b.p, tol, 0.0);
            if bound.upper > tol {
                let d = discretize_range(self.curve, a.t, b.t, self.dopts)?;
                let mut prev = a;
                let last = d.params().len() - 1;
                for i in 1..last {
                    let s = self.sample(d.params()[i], d.points()[i], prev.hint)?;
                    self.out.inserted += 1;
                    self.segment(prev, s, true)?;
                    prev = s;
                }
                self.out.max_chord_error = self.out.max_chord_error.max(d.max_chord_error());
                return self.segment(prev, b, true);
            }
            self.out.max_chord_error = self.out.max_chord_error.max(bound.upper);
        }
        let angle = a.n_after.angle(&b.n);
        self.out.max_normal_angle = self.out.max_normal_angle.max(angle);
        self.push(&b);
        Ok(())
    }
}

/// Gives every cutting point of `disc` (a discretization of `curve` with options `dopts`) the
/// unit normal of `surface`, inserting points where neighbouring normals differ by more than
/// `nopts.max_normal_step_deg`.
///
/// # Errors
/// [`NormalsError::OffSurface`] naming the parameter and distance, [`NormalsError::NoNormal`],
/// [`NormalsError::Reversed`], [`NormalsError::TooManyInserted`], [`NormalsError::BadOption`],
/// and discretizer errors from re-certification.
pub fn orient(
    curve: &NurbsCurve,
    disc: &Discretization,
    surface: &dyn NormalSource,
    dopts: &Options,
    nopts: &NormalOptions,
) -> Result<Oriented> {
    nopts.validate()?;
    let (da, db) = curve.domain();
    let mut ctx = Ctx {
        curve,
        cert: Certifier::new(curve),
        scratch: Scratch::default(),
        surface,
        dopts,
        nopts,
        min_dt: (1e-9 * (db - da)).max(8.0 * f64::EPSILON * da.abs().max(db.abs())),
        out: Oriented::start(disc),
    };
    let Some((&t0, &p0)) = disc.params().first().zip(disc.points().first()) else {
        return Ok(ctx.out);
    };
    let mut prev = ctx.sample(t0, p0, Hint::None)?;
    ctx.push(&prev);
    for i in 1..disc.params().len() {
        let s = ctx.sample(disc.params()[i], disc.points()[i], prev.hint)?;
        ctx.segment(prev, s, true)?;
        if s.n.angle(&s.n_after) > ctx.nopts.max_normal_step_deg.to_radians() {
            // The normal jumps at a degenerate point of the surface (a cone's apex): the head
            // turns in place there; no insertion can remove it.
            ctx.out.jumps.push(s.t);
        }
        prev = s;
    }
    Ok(ctx.out)
}
