//! IGES entities as exact NURBS curves and kerf's surface geometry, in mm in model space:
//! each entity is built in its definition space, moved by its transformation matrix (124,
//! chained through the matrices' own matrices) and scaled to mm once at the top.

use std::cell::Cell;
use std::f64::consts::TAU;

use kerf_nurbs::{NurbsCurve, NurbsSurface};
use kerf_step::cad::{self, Charge, Frame, Geometry};
use nalgebra::{Matrix3, Point3, Vector3};

use crate::error::{IgesError, Result};
use crate::parser::{Entry, Iges, Token};

/// The deepest nesting of composites in composites, and of matrices on matrices.
pub(crate) const MAX_DEPTH: usize = 32;

/// The counter of a budget.
fn slot(what: Charge) -> usize {
    match what {
        Charge::Segments => 0,
        Charge::CurvePoints => 1,
        Charge::SurfacePoints => 2,
        _ => 3,
    }
}

/// The name of an entity type, for messages.
pub(crate) fn kind_name(ty: i64) -> &'static str {
    match ty {
        100 => "circular arc",
        102 => "composite curve",
        104 => "conic arc",
        106 => "copious data",
        108 => "plane",
        110 => "line",
        116 => "point",
        118 => "ruled surface",
        120 => "surface of revolution",
        122 => "tabulated cylinder",
        124 => "transformation matrix",
        126 => "rational B-spline curve",
        128 => "rational B-spline surface",
        130 => "offset curve",
        140 => "offset surface",
        141 => "boundary",
        142 => "curve on a parametric surface",
        143 => "bounded surface",
        144 => "trimmed surface",
        186 => "manifold solid B-rep object",
        190 => "plane surface",
        192 => "right circular cylindrical surface",
        194 => "right circular conical surface",
        196 => "spherical surface",
        198 => "toroidal surface",
        212 => "general note",
        308 => "subfigure definition",
        314 => "colour definition",
        402 => "associativity instance",
        406 => "property",
        408 => "singular subfigure instance",
        502 => "vertex list",
        504 => "edge list",
        508 => "loop",
        510 => "face",
        514 => "shell",
        _ => "entity",
    }
}

/// An affine map `x -> r x + t`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Affine {
    r: Matrix3<f64>,
    t: Vector3<f64>,
}

impl Affine {
    pub(crate) fn identity() -> Self {
        Self {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }

    pub(crate) fn scale(s: f64) -> Self {
        Self {
            r: Matrix3::identity() * s,
            t: Vector3::zeros(),
        }
    }

    /// `self` after `inner`.
    fn after(&self, inner: &Affine) -> Affine {
        Affine {
            r: self.r * inner.r,
            t: self.r * inner.t + self.t,
        }
    }

    fn point(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.r * p.coords + self.t)
    }

    fn vector(&self, v: &Vector3<f64>) -> Vector3<f64> {
        self.r * v
    }

    fn is_identity(&self) -> bool {
        self.r == Matrix3::identity() && self.t == Vector3::zeros()
    }

    /// The map's uniform scale if it is a similarity (rotation, mirror and scale alike in
    /// every direction), within 1e-9.
    fn similarity_scale(&self) -> Option<f64> {
        let g = self.r.transpose() * self.r;
        let s2 = g.trace() / 3.0;
        ((g - Matrix3::identity() * s2).abs().max() <= 1e-9 * s2.max(1e-300) && s2 > 0.0)
            .then(|| s2.sqrt())
    }

    /// The same curve moved by the map (exact: an affine map of a NURBS curve is the curve of
    /// the mapped control points with the same weights); the evaluator's refusal where the
    /// moved points are not finite (a matrix of 1e300).
    pub(crate) fn curve(&self, c: &NurbsCurve) -> std::result::Result<NurbsCurve, String> {
        if self.is_identity() {
            return Ok(c.clone());
        }
        let pts: Vec<Point3<f64>> = c.control_points().iter().map(|p| self.point(p)).collect();
        NurbsCurve::try_new(
            c.degree(),
            c.knots().to_vec(),
            pts,
            c.is_rational().then(|| c.weights()),
        )
        .map_err(|x| format!("moved by its matrices and units: {x}"))
    }

    fn surface(&self, s: &NurbsSurface) -> std::result::Result<NurbsSurface, String> {
        let pts: Vec<Vec<Point3<f64>>> = s
            .control_points()
            .iter()
            .map(|row| row.iter().map(|p| self.point(p)).collect())
            .collect();
        NurbsSurface::try_new(
            s.degree_u(),
            s.degree_v(),
            s.knots_u().to_vec(),
            s.knots_v().to_vec(),
            pts,
            s.is_rational().then(|| s.weights()),
        )
        .map_err(|e| e.to_string())
    }
}

use kerf_step::cad::ParamBox;

/// The entity table with the units and the budgets.
pub(crate) struct Reader<'a> {
    pub(crate) iges: &'a Iges,
    /// File units to mm (with the model space scale).
    pub(crate) to_mm: Affine,
    spent: [Cell<u64>; 4],
}

impl<'a> Reader<'a> {
    pub(crate) fn new(iges: &'a Iges, mm_per_unit: f64) -> Self {
        Self {
            iges,
            to_mm: Affine::scale(mm_per_unit),
            spent: Default::default(),
        }
    }

    pub(crate) fn spent(&self, what: Charge) -> u64 {
        self.spent[slot(what)].get()
    }

    pub(crate) fn charge(&self, e: &Entry, what: Charge, n: usize) -> Result<()> {
        let cell = &self.spent[slot(what)];
        let total = cell.get().saturating_add(n as u64);
        cell.set(total);
        if total > what.limit() {
            return Err(IgesError::Budget {
                what: what.what().into(),
                limit: what.limit(),
                place: format!("D{} ({} {})", e.de, e.ty, kind_name(e.ty)),
            });
        }
        Ok(())
    }

    /// The entry at directory entry `de`, or an error on `from` naming the dangling pointer.
    pub(crate) fn get(&self, from: &Entry, de: i64, what: &str) -> Result<&'a Entry> {
        usize::try_from(de)
            .ok()
            .and_then(|d| self.iges.entry(d))
            .ok_or_else(|| {
                err(
                    from,
                    format!("{what} points at directory entry {de}, which is not in the file"),
                )
            })
    }

    /// [`Reader::get`], refused unless the entity is of type `ty`: `{what} D12 is a 110
    /// (line), not a 124`.
    ///
    /// # Errors
    /// As [`Reader::get`], and [`IgesError`] at `from` for another type.
    pub(crate) fn get_typed(
        &self,
        from: &Entry,
        de: i64,
        what: &str,
        ty: i64,
    ) -> Result<&'a Entry> {
        let e = self.get(from, de, what)?;
        if e.ty != ty {
            return Err(err(
                from,
                format!(
                    "{what} D{} is a {} ({}), not a {ty}",
                    e.de,
                    e.ty,
                    kind_name(e.ty)
                ),
            ));
        }
        Ok(e)
    }

    /// The entity's own transformation (its matrix, chained through the matrices' own).
    fn transform(&self, e: &Entry) -> Result<Affine> {
        let mut out = Affine::identity();
        let mut ptr = e.transform;
        let mut from = e;
        for _ in 0..=MAX_DEPTH {
            if ptr == 0 {
                return Ok(out);
            }
            let m = self.get_typed(from, ptr, "its transformation matrix", 124)?;
            let v = reals(m, 0, 12, "matrix")?;
            let a = Affine {
                r: Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]),
                t: Vector3::new(v[3], v[7], v[11]),
            };
            out = a.after(&out);
            ptr = m.transform;
            from = m;
        }
        Err(err(
            e,
            format!("its transformation matrices chain more than {MAX_DEPTH} deep (a cycle?)"),
        ))
    }

    /// A curve entity as its segments in model space (mm), each with its entity's name; the
    /// matrices of the entities that hold it (`within`, innermost first: a 142's, then its
    /// 144's) applied after its own.
    pub(crate) fn curve(&self, e: &Entry, within: &[&Entry]) -> Result<Vec<(NurbsCurve, String)>> {
        let t = self.outer(within)?;
        self.curve_at(e, 0)?
            .into_iter()
            .map(|(c, n)| Ok((t.curve(&c).map_err(|x| err(e, x))?, n)))
            .collect()
    }

    /// The segments of a parameter-space curve (a 142's B): its own matrix applied, no unit
    /// scale (parameters have none).
    pub(crate) fn parameter_curve(&self, e: &Entry) -> Result<Vec<(NurbsCurve, String)>> {
        self.curve_at(e, 0)
    }

    /// `to_mm` after the matrices of `within` (innermost first).
    fn outer(&self, within: &[&Entry]) -> Result<Affine> {
        let mut t = Affine::identity();
        for w in within {
            t = self.transform(w)?.after(&t);
        }
        Ok(self.to_mm.after(&t))
    }

    /// A curve entity as one curve in the space of whoever refers to it (its own matrix
    /// applied, not yet in mm): a composite's segments joined.
    fn one_curve(&self, from: &Entry, e: &Entry, what: &str) -> Result<NurbsCurve> {
        let segs: Vec<NurbsCurve> = self.curve_at(e, 0)?.into_iter().map(|s| s.0).collect();
        cad::join_one(&segs, 1e-9).ok_or_else(|| {
            err(
                from,
                format!("its {what} D{} does not join into one curve", e.de),
            )
        })
    }

    /// The segments of a curve entity in the space of whoever refers to it (its own matrix
    /// applied, not yet in mm).
    fn curve_at(&self, e: &Entry, depth: usize) -> Result<Vec<(NurbsCurve, String)>> {
        if depth > MAX_DEPTH {
            return Err(err(
                e,
                format!("composite curves nest more than {MAX_DEPTH} deep (a cycle?)"),
            ));
        }
        let name = format!("D{}", e.de);
        let local: Vec<(NurbsCurve, String)> = match e.ty {
            110 => {
                if e.form != 0 {
                    return Err(err(
                        e,
                        "an unbounded line (form 1 or 2) is not a contour".to_string(),
                    ));
                }
                let v = reals(e, 0, 6, "end points")?;
                let a = Point3::new(v[0], v[1], v[2]);
                let b = Point3::new(v[3], v[4], v[5]);
                let c = NurbsCurve::line(a, b).map_err(|x| err(e, x.to_string()))?;
                vec![(c, name)]
            }
            100 => vec![(self.arc(e)?, name)],
            104 => vec![(self.conic(e)?, name)],
            106 => vec![(self.copious(e)?, name)],
            126 => vec![(self.bspline_curve(e)?, name)],
            102 => {
                let n = count(e, 0, "number of segments", e.params.len())?;
                self.charge(e, Charge::Segments, n)?;
                let mut out = Vec::with_capacity(n);
                for k in 0..n {
                    let de = int(e, 1 + k, "segment")?;
                    let s = self.get(e, de, &format!("segment {}", k + 1))?;
                    if s.ty == 116 {
                        continue; // a point in a composite joins nothing
                    }
                    out.extend(self.curve_at(s, depth + 1).map_err(|x| match x {
                        // The work budget's error stays what it is, wherever it trips.
                        x @ IgesError::Budget { .. } => x,
                        x => err(e, format!("segment {} (D{}): {x}", k + 1, s.de)),
                    })?);
                }
                out
            }
            ty => {
                return Err(err(
                    e,
                    format!(
                        "type {ty} ({}) is not a curve kerf reads (lines 110, arcs 100, conics 104, copious data 106, B-splines 126, composites 102 are)",
                        kind_name(ty)
                    ),
                ))
            }
        };
        let t = self.transform(e)?;
        local
            .into_iter()
            .map(|(c, n)| Ok((t.curve(&c).map_err(|x| err(e, x))?, n)))
            .collect()
    }

    /// 100: counter-clockwise in the plane `z = ZT` from the start to the end point about
    /// the centre; a start equal to the end is the full circle.
    fn arc(&self, e: &Entry) -> Result<NurbsCurve> {
        let v = reals(e, 0, 7, "centre and end points")?;
        let (zt, cx, cy, sx, sy, ex, ey) = (v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
        let r = (sx - cx).hypot(sy - cy);
        if !(r > 0.0) {
            return Err(err(
                e,
                "the start point is the centre (radius 0)".to_string(),
            ));
        }
        let a1 = (sy - cy).atan2(sx - cx);
        let a2 = (ey - cy).atan2(ex - cx);
        let closed = (ex - sx).hypot(ey - sy) <= 1e-9 * r.max(1.0);
        let mut sweep = a2 - a1;
        while sweep <= 0.0 {
            sweep += TAU;
        }
        if closed {
            sweep = TAU;
        }
        NurbsCurve::arc(
            Point3::new(cx, cy, zt),
            Vector3::x(),
            Vector3::y(),
            r,
            a1,
            sweep,
        )
        .map_err(|x| err(e, x.to_string()))
    }

    /// 104: the conic `A x^2 + B xy + C y^2 + D x + E y + F = 0` in the plane `z = ZT` from the
    /// start to the end point: an ellipse (form 1) counter-clockwise, a hyperbola (form 2) or
    /// parabola (form 3) along its branch.
    fn conic(&self, e: &Entry) -> Result<NurbsCurve> {
        let v = reals(e, 0, 11, "coefficients and end points")?;
        match e.form {
            1 => self.ellipse(e, &v),
            2 | 3 => open_conic(e, &v),
            f => Err(err(
                e,
                format!("form {f} is not a conic form (1 ellipse, 2 hyperbola, 3 parabola)"),
            )),
        }
    }

    /// 104 form 1 (see [`Reader::conic`]).
    fn ellipse(&self, e: &Entry, v: &[f64]) -> Result<NurbsCurve> {
        let (a, b, c, d, ee, f, zt) = (v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
        // Centre: the gradient vanishes.
        let det = 4.0 * a * c - b * b;
        if !(det > 0.0) {
            return Err(err(
                e,
                "the coefficients are not an ellipse's (4AC - B^2 <= 0)".into(),
            ));
        }
        let x0 = (b * ee - 2.0 * c * d) / det;
        let y0 = (b * d - 2.0 * a * ee) / det;
        let f0 = a * x0 * x0 + b * x0 * y0 + c * y0 * y0 + d * x0 + ee * y0 + f;
        let th = 0.5 * b.atan2(a - c);
        let (s, co) = th.sin_cos();
        let a1 = a * co * co + b * co * s + c * s * s;
        let c1 = a * s * s - b * co * s + c * co * co;
        let (rx2, ry2) = (-f0 / a1, -f0 / c1);
        if !(rx2 > 0.0 && ry2 > 0.0) {
            return Err(err(e, "the coefficients describe no real ellipse".into()));
        }
        let (rx, ry) = (rx2.sqrt(), ry2.sqrt());
        let ax = Vector3::new(co, s, 0.0);
        let ay = Vector3::new(-s, co, 0.0);
        let centre = Point3::new(x0, y0, zt);
        let angle = |x: f64, y: f64| {
            let d = Vector3::new(x - x0, y - y0, 0.0);
            (d.dot(&ay) / ry).atan2(d.dot(&ax) / rx)
        };
        let t1 = angle(v[7], v[8]);
        let t2 = angle(v[9], v[10]);
        let closed = (v[9] - v[7]).hypot(v[10] - v[8]) <= 1e-9 * rx.max(1.0);
        let mut sweep = t2 - t1;
        while sweep <= 0.0 {
            sweep += TAU;
        }
        if closed {
            sweep = TAU;
        }
        // The unit circle's arc, stretched onto the ellipse (exact: an affine map).
        let unit = NurbsCurve::arc(Point3::origin(), Vector3::x(), Vector3::y(), 1.0, t1, sweep)
            .map_err(|x| err(e, x.to_string()))?;
        let stretch = Affine {
            r: Matrix3::from_columns(&[ax * rx, ay * ry, Vector3::z()]),
            t: centre.coords,
        };
        stretch.curve(&unit).map_err(|x| err(e, x))
    }

    /// 106 forms 11, 12, 13 (open) and 63 (closed): the points as a polyline.
    fn copious(&self, e: &Entry) -> Result<NurbsCurve> {
        if !matches!(e.form, 11..=13 | 63) {
            return Err(err(
                e,
                format!(
                    "form {} is not a curve (points, centre lines, section or witness lines); forms 11, 12, 13 and 63 are polylines",
                    e.form
                ),
            ));
        }
        let ip = int(e, 0, "interpretation flag")?;
        let n = count(e, 1, "number of points", e.params.len())?;
        self.charge(e, Charge::CurvePoints, n)?;
        let mut pts: Vec<Point3<f64>> = Vec::with_capacity(n + 1);
        match ip {
            1 => {
                let zt = real(e, 2, "ZT")?;
                let v = reals(e, 3, 2 * n, "points")?;
                pts.extend(v.chunks(2).map(|p| Point3::new(p[0], p[1], zt)));
            }
            2 | 3 => {
                let stride = if ip == 2 { 3 } else { 6 };
                let v = reals(e, 2, stride * n, "points")?;
                pts.extend(v.chunks(stride).map(|p| Point3::new(p[0], p[1], p[2])));
            }
            _ => {
                return Err(err(
                    e,
                    format!("interpretation flag {ip} (1, 2 or 3 expected)"),
                ))
            }
        }
        pts.dedup_by(|a, b| (*a - *b).norm() == 0.0);
        if e.form == 63 && pts.len() > 1 && pts[0] != pts[pts.len() - 1] {
            pts.push(pts[0]);
        }
        NurbsCurve::polyline(&pts).map_err(|x| err(e, x.to_string()))
    }

    /// 126: the B-spline over `[V0, V1]`.
    fn bspline_curve(&self, e: &Entry) -> Result<NurbsCurve> {
        let k = count(e, 0, "upper index K", e.params.len())?;
        let m = count(e, 1, "degree M", 64)?;
        let polynomial = int(e, 4, "PROP3")? == 1;
        let n = k + 1;
        self.charge(e, Charge::CurvePoints, n)?;
        let nk = n + m + 1;
        let knots = reals(e, 6, nk, "knots")?;
        let weights = reals(e, 6 + nk, n, "weights")?;
        let xyz = reals(e, 6 + nk + n, 3 * n, "control points")?;
        let range = reals(e, 6 + nk + 4 * n, 2, "parameter range V0, V1")?;
        let pts: Vec<Point3<f64>> = xyz
            .chunks(3)
            .map(|p| Point3::new(p[0], p[1], p[2]))
            .collect();
        let c = NurbsCurve::try_new(m, knots, pts, (!polynomial).then_some(weights))
            .map_err(|x| err(e, x.to_string()))?;
        restrict(e, &c, range[0], range[1])
    }

    /// A surface entity as kerf's geometry in model space (mm), with its natural parameter
    /// box where it has one (not a plane): the boundary of an untrimmed surface.
    /// `within`: the entities that hold it, whose matrices apply after its own (a 144's).
    pub(crate) fn surface(
        &self,
        e: &Entry,
        within: &[&Entry],
    ) -> Result<(Geometry, Option<ParamBox>)> {
        let t = self.outer(within)?.after(&self.transform(e)?);
        match e.ty {
            128 => {
                let s = t.surface(&self.bspline_surface(e)?).map_err(|x| err(e, x))?;
                let b = (s.domain_u(), s.domain_v());
                Ok((Geometry::Nurbs(s), Some(b)))
            }
            108 => {
                let v = reals(e, 0, 4, "coefficients A, B, C, D")?;
                let n = Vector3::new(v[0], v[1], v[2]);
                let nn = n.norm_squared();
                if !(nn > 0.0) {
                    return Err(err(e, "its normal (A, B, C) is zero".into()));
                }
                let z = n / nn.sqrt();
                let origin = Point3::from(n * (v[3] / nn));
                let x = perpendicular(&z);
                Ok((plane_frame(e, &t, origin, x, z.cross(&x))?, None))
            }
            120 => {
                let similar = t.similarity_scale().is_some();
                if !similar {
                    return Err(err(e, "its matrix is not a rotation, mirror or uniform scale: a surface of revolution stays one only under those".into()));
                }
                let axis_e = self.get(e, int(e, 0, "axis")?, "its axis")?;
                if axis_e.ty != 110 {
                    return Err(err(e, format!("its axis D{} is not a line (110)", axis_e.de)));
                }
                let axis_c = t
                    .curve(&self.one_curve(e, axis_e, "axis")?)
                    .map_err(|x| err(e, x))?;
                let gen = self.get(e, int(e, 1, "generatrix")?, "its generatrix")?;
                let profile = t
                    .curve(&self.one_curve(e, gen, "generatrix")?)
                    .map_err(|x| err(e, x))?;
                let ends = axis_c.control_points();
                let (p0, p1) = (ends[0], ends[ends.len() - 1]);
                let mut axis = p1 - p0;
                if !(axis.norm() > 0.0) {
                    return Err(err(e, "its axis has zero length".into()));
                }
                axis /= axis.norm();
                // A mirror turns the sense of rotation about the mapped axis round.
                if t.r.determinant() < 0.0 {
                    axis = -axis;
                }
                let sa = real(e, 2, "start angle")?;
                let ta = real(e, 3, "end angle")?;
                let v = profile.domain();
                let g = Geometry::revolution(profile, p0, axis)
                    .ok_or_else(|| err(e, "the generatrix lies on the axis".into()))?;
                Ok((g, Some(((sa, ta), v))))
            }
            122 => {
                let dir_e = self.get(e, int(e, 0, "directrix")?, "its directrix")?;
                let c = self.one_curve(e, dir_e, "directrix")?;
                let l = reals(e, 1, 3, "generatrix end point")?;
                // The generatrix runs from the directrix's start to L (in the 122's space).
                let start = c.point(c.domain().0);
                let d = t.vector(&(Point3::new(l[0], l[1], l[2]) - start));
                let len = d.norm();
                if !(len > 0.0) {
                    return Err(err(e, "its generatrix has zero length".into()));
                }
                let c = t.curve(&c).map_err(|x| err(e, x))?;
                let u = c.domain();
                Ok((Geometry::Extrusion(c, d / len), Some((u, (0.0, len)))))
            }
            190 => {
                // Location point (116) and normal (123); form 1 adds the reference direction
                // (x) of its parametrization.
                let xyz = |what: &str, i: usize, ty: i64| -> Result<Vector3<f64>> {
                    let p = self.get_typed(e, int(e, i, what)?, &format!("its {what}"), ty)?;
                    let v = reals(p, 0, 3, what)?;
                    Ok(Vector3::new(v[0], v[1], v[2]))
                };
                let origin = Point3::from(xyz("location", 0, 116)?);
                let n = xyz("normal", 1, 123)?;
                if !(n.norm() > 0.0) {
                    return Err(err(e, "its normal is zero".into()));
                }
                let z = n.normalize();
                let x = if e.form == 1 {
                    let r = xyz("reference direction", 2, 123)?;
                    let r = r - z * z.dot(&r);
                    if !(r.norm() > 1e-12) {
                        return Err(err(e, "its reference direction is along its normal".into()));
                    }
                    r.normalize()
                } else {
                    perpendicular(&z)
                };
                Ok((plane_frame(e, &t, origin, x, z.cross(&x))?, None))
            }
            192..=198 => Err(err(
                e,
                "an analytic surface of the B-rep form (192-198) is not read: export trimmed surfaces (144)".into(),
            )),
            ty => Err(err(
                e,
                format!(
                    "type {ty} ({}) is not a surface kerf reads (128, 108, 120, 122 are)",
                    kind_name(ty)
                ),
            )),
        }
    }

    /// 128 in its definition space.
    fn bspline_surface(&self, e: &Entry) -> Result<NurbsSurface> {
        let k1 = count(e, 0, "upper index K1", e.params.len())?;
        let k2 = count(e, 1, "upper index K2", e.params.len())?;
        let m1 = count(e, 2, "degree M1", 64)?;
        let m2 = count(e, 3, "degree M2", 64)?;
        let polynomial = int(e, 6, "PROP3")? == 1;
        let (nu, nv) = (k1 + 1, k2 + 1);
        let n = nu
            .checked_mul(nv)
            .ok_or_else(|| err(e, "too many control points".into()))?;
        self.charge(e, Charge::SurfacePoints, n)?;
        let (nku, nkv) = (nu + m1 + 1, nv + m2 + 1);
        let mut at = 9;
        let ku = reals(e, at, nku, "knots S")?;
        at += nku;
        let kv = reals(e, at, nkv, "knots T")?;
        at += nkv;
        let w = reals(e, at, n, "weights")?;
        at += n;
        let xyz = reals(e, at, 3 * n, "control points")?;
        at += 3 * n;
        let range = reals(e, at, 4, "parameter range U0, U1, V0, V1")?;
        // The first index (u) runs fastest.
        let pts: Vec<Vec<Point3<f64>>> = (0..nu)
            .map(|a| {
                (0..nv)
                    .map(|b| {
                        let i = 3 * (a + nu * b);
                        Point3::new(xyz[i], xyz[i + 1], xyz[i + 2])
                    })
                    .collect()
            })
            .collect();
        let ws: Vec<Vec<f64>> = (0..nu)
            .map(|a| (0..nv).map(|b| w[a + nu * b]).collect())
            .collect();
        let s = NurbsSurface::try_new(m1, m2, ku, kv, pts, (!polynomial).then_some(ws))
            .map_err(|x| err(e, x.to_string()))?;
        // Restricted to [U0, U1] x [V0, V1] where that is inside the knots' domain.
        let (a, b) = s.domain_u();
        let (c, d) = s.domain_v();
        let u = (range[0].max(a), range[1].min(b));
        let v = (range[2].max(c), range[3].min(d));
        if (u, v) == ((a, b), (c, d)) || !(u.1 > u.0 && v.1 > v.0) {
            return Ok(s);
        }
        Geometry::Nurbs(s)
            .to_nurbs(u, v)
            .map_err(|x| err(e, format!("parameter range: {x}")))
    }
}

/// A unit vector at right angles to unit `z`: the coordinate axis least along it, made
/// perpendicular.
fn perpendicular(z: &Vector3<f64>) -> Vector3<f64> {
    let i = (0..3)
        .min_by(|&a, &b| z[a].abs().total_cmp(&z[b].abs()))
        .unwrap_or(0);
    let ei = Vector3::ith(i, 1.0);
    (ei - z * z.dot(&ei)).normalize()
}

/// The plane through `origin` with unit axes `x`, `y` (in the entity's space) moved by `t`;
/// refused where `t` does not keep the axes at right angles.
fn plane_frame(
    e: &Entry,
    t: &Affine,
    origin: Point3<f64>,
    x: Vector3<f64>,
    y: Vector3<f64>,
) -> Result<Geometry> {
    let (x1, y1) = (t.vector(&x), t.vector(&y));
    let (nx, ny) = (x1.norm(), y1.norm());
    if !(nx > 0.0 && ny > 0.0) || (x1 / nx).dot(&(y1 / ny)).abs() > 1e-9 {
        return Err(err(
            e,
            "its matrix does not keep the plane's axes at right angles".into(),
        ));
    }
    let (x1, y1) = (x1 / nx, y1 / ny);
    Ok(Geometry::Plane(Frame {
        origin: t.point(&origin),
        x: x1,
        y: y1,
        z: x1.cross(&y1),
    }))
}

/// 104 forms 2 and 3: the hyperbola or parabola arc between the start and end points as one
/// rational quadratic, which is exact: a rational quadratic with given ends `P0`, `P2` and
/// end tangents meeting at `P1` is a conic, and one more point fixes which. That point is where
/// the conic crosses the line from the chord's middle `M` to `P1`: the curve's middle is
/// `(M + w P1) / (1 + w)`, so with `s` the root in (0, 1) of `Q(M + s (P1 - M)) = 0`, the
/// middle weight is `w = s / (1 - s)` (1 for a parabola, above 1 for a hyperbola). Refused
/// where an end point is off the conic, the tangents do not meet ahead of both ends, or no
/// root lies in (0, 1) (the ends are on two branches).
fn open_conic(e: &Entry, v: &[f64]) -> Result<NurbsCurve> {
    let (a, b, c, d, ee, f, zt) = (v[0], v[1], v[2], v[3], v[4], v[5], v[6]);
    let q = |x: f64, y: f64| a * x * x + b * x * y + c * y * y + d * x + ee * y + f;
    let grad = |x: f64, y: f64| (2.0 * a * x + b * y + d, b * x + 2.0 * c * y + ee);
    let p0 = (v[7], v[8]);
    let p2 = (v[9], v[10]);
    for (name, p) in [("start", p0), ("end", p2)] {
        let g = grad(p.0, p.1);
        let gn = g.0.hypot(g.1);
        // First-order distance from the conic.
        let off = q(p.0, p.1).abs() / gn.max(1e-300);
        if !(gn > 0.0) || !(off <= cad::ON_GEOMETRY_TOLERANCE_MM) {
            return Err(err(
                e,
                format!(
                    "its {name} point ({}, {}) is {off:.3e} off the conic",
                    p.0, p.1
                ),
            ));
        }
    }
    // The tangents (perpendicular to the gradients) and where they meet.
    let (g0, g2) = (grad(p0.0, p0.1), grad(p2.0, p2.1));
    let (t0, t2) = ((-g0.1, g0.0), (-g2.1, g2.0));
    let den = t0.0 * t2.1 - t0.1 * t2.0;
    if !(den.abs() > 1e-12 * (t0.0.hypot(t0.1) * t2.0.hypot(t2.1))) {
        return Err(err(
            e,
            "its end tangents are parallel: no single arc joins them".into(),
        ));
    }
    let (rx, ry) = (p2.0 - p0.0, p2.1 - p0.1);
    let k = (rx * t2.1 - ry * t2.0) / den;
    let p1 = (p0.0 + k * t0.0, p0.1 + k * t0.1);
    let m = (0.5 * (p0.0 + p2.0), 0.5 * (p0.1 + p2.1));
    let dv = (p1.0 - m.0, p1.1 - m.1);
    // Q(M + s d) = q0 + q1 s + q2 s^2.
    let q0 = q(m.0, m.1);
    let gm = grad(m.0, m.1);
    let q1 = gm.0 * dv.0 + gm.1 * dv.1;
    let q2 = a * dv.0 * dv.0 + b * dv.0 * dv.1 + c * dv.1 * dv.1;
    let roots: Vec<f64> = if q2.abs() <= 1e-15 * (q1.abs() + q0.abs()) {
        vec![-q0 / q1]
    } else {
        let disc = q1 * q1 - 4.0 * q2 * q0;
        if disc < 0.0 {
            vec![]
        } else {
            let r = disc.sqrt();
            // The numerically stable pair.
            let t = -0.5 * (q1 + q1.signum() * r);
            vec![t / q2, q0 / t]
        }
    };
    let Some(sm) = roots
        .into_iter()
        .filter(|s| *s > 0.0 && *s < 1.0 && s.is_finite())
        .min_by(|x, y| x.total_cmp(y))
    else {
        return Err(err(
            e,
            "its start and end points are not joined by one branch of the conic".into(),
        ));
    };
    let w = sm / (1.0 - sm);
    NurbsCurve::try_new(
        2,
        vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
        vec![
            Point3::new(p0.0, p0.1, zt),
            Point3::new(p1.0, p1.1, zt),
            Point3::new(p2.0, p2.1, zt),
        ],
        Some(vec![1.0, w, 1.0]),
    )
    .map_err(|x| err(e, x.to_string()))
}

/// The curve on `[v0, v1]` when that lies inside its domain and is not the whole of it.
fn restrict(e: &Entry, c: &NurbsCurve, v0: f64, v1: f64) -> Result<NurbsCurve> {
    let (a, b) = c.domain();
    let span = (b - a).max(1e-300);
    let near = |x: f64, y: f64| (x - y).abs() <= 1e-9 * span.max(1.0);
    let lo = if near(v0, a) { a } else { v0.max(a) };
    let hi = if near(v1, b) { b } else { v1.min(b) };
    if !(hi > lo) {
        return Err(err(
            e,
            format!(
                "its parameter range [{v0}, {v1}] is empty inside the knots' domain [{a}, {b}]"
            ),
        ));
    }
    if lo == a && hi == b {
        return cad::sub_curve(c, a, b).map_err(|x| err(e, x.to_string()));
    }
    cad::sub_curve(c, lo, hi).map_err(|x| err(e, x.to_string()))
}

/// An error on entity `e`.
pub(crate) fn err(e: &Entry, message: String) -> IgesError {
    IgesError::Entity {
        de: e.de,
        kind: format!("{} {}", e.ty, kind_name(e.ty)),
        message,
    }
}

fn param<'e>(e: &'e Entry, i: usize, what: &str) -> Result<&'e Token> {
    e.params.get(i).ok_or_else(|| {
        err(
            e,
            format!(
                "parameter {} ({what}) is missing: the entity has {} parameters",
                i + 1,
                e.params.len()
            ),
        )
    })
}

/// Parameter `i` (0-based, after the type) as an integer; empty is 0.
pub(crate) fn int(e: &Entry, i: usize, what: &str) -> Result<i64> {
    match param(e, i, what)? {
        Token::Empty => Ok(0),
        Token::Raw(s) => s
            .parse::<i64>()
            .ok()
            .or_else(|| {
                // A real with an integral value, as some writers put counts.
                parse_real(s)
                    .filter(|x| x.fract() == 0.0 && x.abs() < 9e15)
                    .map(|x| x as i64)
            })
            .ok_or_else(|| {
                err(
                    e,
                    format!("parameter {} ({what}): {s:?} is not an integer", i + 1),
                )
            }),
        Token::Text(_) => Err(err(
            e,
            format!("parameter {} ({what}): a string, not an integer", i + 1),
        )),
    }
}

/// Parameter `i` as a count from 0 to `max`.
fn count(e: &Entry, i: usize, what: &str, max: usize) -> Result<usize> {
    let n = int(e, i, what)?;
    usize::try_from(n)
        .ok()
        .filter(|&n| n <= max)
        .ok_or_else(|| {
            err(
                e,
                format!("parameter {} ({what}) is {n}: 0 to {max} expected", i + 1),
            )
        })
}

fn parse_real(s: &str) -> Option<f64> {
    let s: String = s
        .chars()
        .map(|c| if c == 'D' || c == 'd' { 'E' } else { c })
        .collect();
    s.parse::<f64>().ok()
}

/// Parameter `i` as a finite real; empty is 0.
pub(crate) fn real(e: &Entry, i: usize, what: &str) -> Result<f64> {
    match param(e, i, what)? {
        Token::Empty => Ok(0.0),
        Token::Raw(s) => parse_real(s).filter(|x| x.is_finite()).ok_or_else(|| {
            err(
                e,
                format!("parameter {} ({what}): {s:?} is not a finite number", i + 1),
            )
        }),
        Token::Text(_) => Err(err(
            e,
            format!("parameter {} ({what}): a string, not a number", i + 1),
        )),
    }
}

/// `n` reals from parameter `i` on (the count was checked against the entity's length by
/// the caller's budget or here).
fn reals(e: &Entry, i: usize, n: usize, what: &str) -> Result<Vec<f64>> {
    if i.saturating_add(n) > e.params.len() {
        return Err(err(
            e,
            format!(
                "{what}: {n} numbers from parameter {} run past the entity's {} parameters",
                i + 1,
                e.params.len()
            ),
        ));
    }
    (i..i + n).map(|k| real(e, k, what)).collect()
}
