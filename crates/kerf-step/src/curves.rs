//! STEP curves as exact NURBS curves in mm: lines, circles and ellipses (rational quadratic
//! arcs), polylines, B-splines (rational or not, clamped here if the file's knots are not),
//! trimmed curves (with their sense) and the 3D curve of surface curves.

use kerf_nurbs::NurbsCurve;
use nalgebra::{Point3, Vector3, Vector4};

use crate::error::Result;
use crate::model::{
    boolean, err, geometry_err, int, list, real, reals, refs, Charge, Frame, Model,
};
use crate::parser::{Instance, Value};

/// A STEP curve before trimming: what it is and how to cut a piece of it.
pub(crate) enum Basis {
    /// `P + t * V` (V = unit direction times magnitude).
    Line {
        /// Point at t = 0, mm.
        origin: Point3<f64>,
        /// Direction times magnitude, mm per parameter unit.
        step: Vector3<f64>,
    },
    /// `C + rx cos(t) x + ry sin(t) y`, t in radians.
    Conic {
        /// The placement.
        frame: Frame,
        /// Semi-axis along x, mm.
        rx: f64,
        /// Semi-axis along y, mm.
        ry: f64,
    },
    /// A bounded curve already in NURBS form (B-spline, polyline), with its own parameter.
    Nurbs(NurbsCurve),
}

impl Basis {
    /// Whether the curve is periodic (conics, period 2 pi).
    pub(crate) fn periodic(&self) -> bool {
        matches!(self, Basis::Conic { .. })
    }

    /// The parameter of the point nearest `p` (for trims given as points).
    pub(crate) fn param_of(&self, p: &Point3<f64>) -> f64 {
        match self {
            Basis::Line { origin, step } => (p - origin).dot(step) / step.norm_squared(),
            Basis::Conic { frame, rx, ry } => {
                let d = p - frame.origin;
                (d.dot(&frame.y) / ry).atan2(d.dot(&frame.x) / rx)
            }
            Basis::Nurbs(c) => c.closest_point(p).t,
        }
    }

    /// The point at parameter `t`.
    pub(crate) fn point_at(&self, t: f64) -> Point3<f64> {
        match self {
            Basis::Line { origin, step } => origin + step * t,
            Basis::Conic { frame, rx, ry } => {
                frame.origin + frame.x * (rx * t.cos()) + frame.y * (ry * t.sin())
            }
            Basis::Nurbs(c) => c.point(t),
        }
    }

    /// The piece from parameter `t1` to `t2` as a NURBS curve, running from `t1` to `t2`
    /// (so `t1 > t2` gives the reversed piece). For conics `t2` may exceed `t1` by up to 2 pi
    /// or fall short of it by as much; the caller chooses the turn.
    pub(crate) fn piece(&self, inst: &Instance, t1: f64, t2: f64) -> Result<NurbsCurve> {
        if !(t1.is_finite() && t2.is_finite()) || t1 == t2 {
            return Err(err(
                inst,
                format!("empty or non-finite parameter range [{t1}, {t2}]"),
            ));
        }
        match self {
            Basis::Line { origin, step } => {
                let a = origin + step * t1;
                let b = origin + step * t2;
                let far = |p: &Point3<f64>| !p.iter().all(|x| x.abs() <= crate::model::MAX_MM);
                if far(&a) || far(&b) {
                    return Err(err(
                        inst,
                        format!(
                            "the line from parameter {t1:e} to {t2:e} ends beyond the {:e} mm kerf accepts",
                            crate::model::MAX_MM
                        ),
                    ));
                }
                let len = (b - a).norm();
                if !(len > 0.0) {
                    return Err(err(inst, "zero-length line piece"));
                }
                NurbsCurve::try_new(1, vec![0.0, 0.0, len, len], vec![a, b], None)
                    .map_err(|e| geometry_err(inst, e))
            }
            Basis::Conic { frame, rx, ry } => Ok(conic_arc(frame, *rx, *ry, t1, t2)),
            Basis::Nurbs(c) => {
                let (lo, hi) = (t1.min(t2), t1.max(t2));
                let (da, db) = c.domain();
                let tol = 1e-9 * (db - da).abs().max(1.0);
                if lo < da - tol || hi > db + tol {
                    return Err(err(
                        inst,
                        format!("trim [{lo}, {hi}] outside the curve's domain [{da}, {db}]"),
                    ));
                }
                let piece = sub_curve(c, lo.max(da), hi.min(db))
                    .map_err(|e| err(inst, format!("cannot trim: {e}")))?;
                Ok(if t1 > t2 { piece.reversed() } else { piece })
            }
        }
    }
}

/// Reads any supported curve entity as a [`Basis`].
pub(crate) fn basis(m: &Model<'_>, inst: &Instance) -> Result<Basis> {
    basis_at(m, inst, 0)
}

/// The deepest chain of curves referring to curves (surface curve to its 3D curve, composite to
/// composite) followed; deeper chains are cycles or garbage.
const MAX_CURVE_DEPTH: usize = 16;

fn basis_at(m: &Model<'_>, inst: &Instance, depth: usize) -> Result<Basis> {
    if depth > MAX_CURVE_DEPTH {
        return Err(err(
            inst,
            format!("curves refer to curves more than {MAX_CURVE_DEPTH} deep (a cycle?)"),
        ));
    }
    if let Some(p) = inst.record("LINE") {
        let origin = m.point(&m.param_ref(inst, p, 1)?)?;
        let (d, mag) = m.vector(&m.param_ref(inst, p, 2)?)?;
        return Ok(Basis::Line {
            origin,
            step: d * mag,
        });
    }
    if let Some(p) = inst.record("CIRCLE") {
        let frame = m.placement(&m.param_ref(inst, p, 1)?)?;
        let r = m.length(inst, p.get(2), "radius")?;
        if !(r > 0.0) {
            return Err(err(inst, format!("radius must be > 0, found {r}")));
        }
        return Ok(Basis::Conic {
            frame,
            rx: r,
            ry: r,
        });
    }
    if let Some(p) = inst.record("ELLIPSE") {
        let frame = m.placement(&m.param_ref(inst, p, 1)?)?;
        let rx = m.length(inst, p.get(2), "semi_axis_1")?;
        let ry = m.length(inst, p.get(3), "semi_axis_2")?;
        if !(rx > 0.0 && ry > 0.0) {
            return Err(err(
                inst,
                format!("semi-axes must be > 0, found {rx}, {ry}"),
            ));
        }
        return Ok(Basis::Conic { frame, rx, ry });
    }
    if let Some(p) = inst.record("POLYLINE") {
        let ids = refs(inst, p.get(1), "points")?;
        m.charge(inst, Charge::CurvePoints, ids.len())?;
        let pts = ids
            .into_iter()
            .map(|id| m.point(&m.get(inst, id)?))
            .collect::<Result<Vec<_>>>()?;
        if pts.len() < 2 {
            return Err(err(inst, "a polyline needs at least 2 points"));
        }
        let n = pts.len();
        let mut knots = vec![0.0];
        knots.extend((0..n).map(|k| k as f64));
        knots.push((n - 1) as f64);
        return NurbsCurve::try_new(1, knots, pts, None)
            .map(Basis::Nurbs)
            .map_err(|e| geometry_err(inst, e));
    }
    if inst.is("B_SPLINE_CURVE_WITH_KNOTS") || inst.is("BEZIER_CURVE") {
        return bspline(m, inst).map(Basis::Nurbs);
    }
    if let Some(p) = inst
        .record("SURFACE_CURVE")
        .or_else(|| inst.record("SEAM_CURVE"))
        .or_else(|| inst.record("INTERSECTION_CURVE"))
    {
        return basis_at(m, &m.param_ref(inst, p, 1)?, depth + 1);
    }
    if inst.is("TRIMMED_CURVE") || inst.is("COMPOSITE_CURVE") {
        return Err(err(
            inst,
            "a bounded curve cannot be the basis of another here",
        ));
    }
    Err(err(inst, "curve type not supported (lines, circles, ellipses, polylines, B-splines, trimmed and composite curves are)"))
}

/// A `B_SPLINE_CURVE_WITH_KNOTS` (simple, or complex with `RATIONAL_B_SPLINE_CURVE`), or a
/// `BEZIER_CURVE`, in mm, clamped.
fn bspline(m: &Model<'_>, inst: &Instance) -> Result<NurbsCurve> {
    // In the simple form every attribute sits in one record; in the complex form the
    // B_SPLINE_CURVE record holds (degree, points, form, closed, self_intersect) and
    // B_SPLINE_CURVE_WITH_KNOTS (multiplicities, knots, spec).
    let (head, knot_rec): (&[Value], Option<&[Value]>) =
        if let Some(b) = inst.record("B_SPLINE_CURVE") {
            (b, inst.record("B_SPLINE_CURVE_WITH_KNOTS"))
        } else if let Some(k) = inst.record("B_SPLINE_CURVE_WITH_KNOTS") {
            (k.get(1..).unwrap_or(&[]), Some(k.get(6..).unwrap_or(&[])))
        } else {
            let b = m.rec(inst, "BEZIER_CURVE")?;
            (b.get(1..).unwrap_or(&[]), None)
        };
    let degree = int(inst, head.first(), "degree")?;
    if degree == 0 || degree > kerf_nurbs::MAX_DEGREE {
        return Err(err(
            inst,
            format!(
                "degree must be 1..={}, found {degree}",
                kerf_nurbs::MAX_DEGREE
            ),
        ));
    }
    let ids = refs(inst, head.get(1), "control_points_list")?;
    m.charge(inst, Charge::CurvePoints, ids.len())?;
    let pts = ids
        .into_iter()
        .map(|id| m.point(&m.get(inst, id)?))
        .collect::<Result<Vec<_>>>()?;
    let knots = match knot_rec {
        Some(k) => expand_knots(inst, k)?,
        None => {
            let mut k = vec![0.0; degree + 1];
            k.extend(vec![1.0; degree + 1]);
            k
        }
    };
    let weights = match inst.record("RATIONAL_B_SPLINE_CURVE") {
        Some(r) => Some(reals(inst, r.first(), "weights_data")?),
        None => None,
    };
    let c = NurbsCurve::try_new(degree, knots, pts, weights).map_err(|e| geometry_err(inst, e))?;
    clamp(&c).map_err(|e| err(inst, format!("cannot clamp: {e}")))
}

/// Multiplicities and distinct knots to the full knot vector.
pub(crate) fn expand_knots(inst: &Instance, k: &[Value]) -> Result<Vec<f64>> {
    let mult = list(inst, k.first(), "knot_multiplicities")?;
    let vals = reals(inst, k.get(1), "knots")?;
    if mult.len() != vals.len() {
        return Err(err(
            inst,
            format!(
                "{} knot multiplicities for {} knots",
                mult.len(),
                vals.len()
            ),
        ));
    }
    let mut out = Vec::new();
    for (i, (mv, &v)) in mult.iter().zip(&vals).enumerate() {
        let n = int(inst, Some(mv), &format!("knot_multiplicities[{i}]"))?;
        if n > 64 {
            return Err(err(inst, format!("knot multiplicity {n} is absurd")));
        }
        out.extend(std::iter::repeat_n(v, n));
    }
    Ok(out)
}

/// The curve on `[a, b]` (inside its domain), clamped at both ends.
///
/// # Errors
/// What knot insertion refuses (a parameter outside the domain).
pub fn sub_curve(c: &NurbsCurve, a: f64, b: f64) -> kerf_nurbs::Result<NurbsCurve> {
    let (da, db) = c.domain();
    let mut c = clamp(c)?;
    if b < db {
        c = c.split(b)?.0;
    }
    if a > da {
        c = c.split(a)?.1;
    }
    Ok(c)
}

/// The same curve with end knots of multiplicity degree + 1 (unclamped vectors, as written
/// for periodic curves, are clamped by knot insertion at the domain ends).
pub(crate) fn clamp(c: &NurbsCurve) -> kerf_nurbs::Result<NurbsCurve> {
    let c = clamp_start(c)?;
    Ok(clamp_start(&c.reversed())?.reversed())
}

fn clamp_start(c: &NurbsCurve) -> kerf_nurbs::Result<NurbsCurve> {
    let p = c.degree();
    let k = c.knots();
    let a = k[p];
    if k[..=p].iter().all(|&x| x == a) {
        return Ok(c.clone());
    }
    let s = k.iter().filter(|&&x| x == a).count();
    let full = if s < p {
        c.insert_knot(a, p - s)?
    } else {
        c.clone()
    };
    let fk = full.knots();
    let first = fk.iter().position(|&x| x == a).unwrap_or(0);
    let mult = fk.iter().filter(|&&x| x == a).count();
    let mut knots: Vec<f64> = std::iter::repeat_n(a, p + 1).collect();
    knots.extend_from_slice(&fk[first + mult..]);
    let n = knots.len() - p - 1;
    let cpw = full.homogeneous_points();
    let cpw = cpw[cpw.len() - n..].to_vec();
    Ok(NurbsCurve::from_homogeneous_unchecked(p, knots, cpw))
}

/// The conic arc from angle `t1` to `t2` (radians, either order) as rational quadratic pieces
/// of at most 90 degrees (The NURBS Book A7.1, mapped affinely for an ellipse); parameter
/// `rx * |angle - t1|` roughly (the knots sit at the pieces' ends).
pub(crate) fn conic_arc(frame: &Frame, rx: f64, ry: f64, t1: f64, t2: f64) -> NurbsCurve {
    let (knots, cpw) = arc_homogeneous(t1, t2);
    let scale = rx.max(ry);
    let pts: Vec<Vector4<f64>> = cpw
        .iter()
        .map(|h| {
            let w = h.w;
            let p = frame.origin + frame.x * (rx * h.x / w) + frame.y * (ry * h.y / w);
            Vector4::new(p.x * w, p.y * w, p.z * w, w)
        })
        .collect();
    let knots = knots.iter().map(|k| k * scale).collect();
    NurbsCurve::from_homogeneous_unchecked(2, knots, pts)
}

/// The unit circle arc from `t1` to `t2` in homogeneous form `(w cos, w sin, 0, w)`, with
/// knots over `[0, |t2 - t1|]`.
pub(crate) fn arc_homogeneous(t1: f64, t2: f64) -> (Vec<f64>, Vec<Vector4<f64>>) {
    let sweep = t2 - t1;
    let n = ((sweep.abs() / std::f64::consts::FRAC_PI_2) - 1e-9)
        .ceil()
        .max(1.0) as usize;
    let d = sweep / n as f64;
    let w1 = (d / 2.0).cos();
    let mut cpw = Vec::with_capacity(2 * n + 1);
    let mut knots = vec![0.0; 3];
    for i in 0..n {
        let a = t1 + d * i as f64;
        let b = if i + 1 == n {
            t2
        } else {
            t1 + d * (i + 1) as f64
        };
        let mid = 0.5 * (a + b);
        if i == 0 {
            cpw.push(Vector4::new(a.cos(), a.sin(), 0.0, 1.0));
        }
        // Middle control point at distance 1 / cos(d/2) with weight cos(d/2): in homogeneous
        // form exactly (cos mid, sin mid, 0, cos(d/2)).
        cpw.push(Vector4::new(mid.cos(), mid.sin(), 0.0, w1));
        cpw.push(Vector4::new(b.cos(), b.sin(), 0.0, 1.0));
        let k = sweep.abs() * (i + 1) as f64 / n as f64;
        if i + 1 == n {
            knots.extend([k; 3]);
        } else {
            knots.extend([k; 2]);
        }
    }
    (knots, cpw)
}

/// A `TRIMMED_CURVE` as the NURBS piece it describes, oriented as Open CASCADE's
/// `Geom_TrimmedCurve(basis, trim_1, trim_2, sense)` does: for a bounded basis the piece covers
/// `[min, max]` of the trims and runs backwards when `(trim_1 < trim_2) != sense`; for a conic
/// it is the arc from trim_1 counter-clockwise to trim_2, reversed when sense is false.
pub(crate) fn trimmed(m: &Model<'_>, inst: &Instance) -> Result<NurbsCurve> {
    let p = m.rec(inst, "TRIMMED_CURVE")?;
    let base_inst = &m.param_ref(inst, p, 1)?;
    let b = basis(m, base_inst)?;
    let sense = boolean(inst, p.get(4), "sense_agreement")?;
    let prefer_point = matches!(p.get(5), Some(Value::Enum(e)) if e == "CARTESIAN");
    let t1 = trim_param(m, inst, &b, p.get(2), prefer_point, "trim_1")?;
    let t2 = trim_param(m, inst, &b, p.get(3), prefer_point, "trim_2")?;
    oriented_piece(inst, &b, t1, t2, sense)
}

/// The piece of `b` between trims `t1`, `t2` with sense, as [`trimmed`] describes.
pub(crate) fn oriented_piece(
    inst: &Instance,
    b: &Basis,
    t1: f64,
    t2: f64,
    sense: bool,
) -> Result<NurbsCurve> {
    if b.periodic() {
        let tau = 2.0 * std::f64::consts::PI;
        if !(t1.is_finite() && t2.is_finite()) {
            return Err(err(inst, format!("non-finite trim parameters {t1}, {t2}")));
        }
        // Angles reduced to one turn, then the end in (t1, t1 + 2 pi]: equal trims mean the
        // whole turn.
        let (t1, t2) = (t1.rem_euclid(tau), t2.rem_euclid(tau));
        let mut e = t1 + (t2 - t1).rem_euclid(tau);
        if e <= t1 + 1e-12 {
            e += tau;
        }
        let c = b.piece(inst, t1, e)?;
        return Ok(if sense { c } else { c.reversed() });
    }
    let c = b.piece(inst, t1.min(t2), t1.max(t2))?;
    Ok(if (t1 < t2) != sense { c.reversed() } else { c })
}

fn trim_param(
    m: &Model<'_>,
    inst: &Instance,
    b: &Basis,
    v: Option<&Value>,
    prefer_point: bool,
    what: &str,
) -> Result<f64> {
    let items = list(inst, v, what)?;
    let mut param = None;
    let mut point = None;
    for it in items {
        match it {
            Value::Typed(t, inner) if t == "PARAMETER_VALUE" => {
                param = Some(real(inst, Some(inner), what)?);
            }
            Value::Real(_) | Value::Int(_) => param = Some(real(inst, Some(it), what)?),
            Value::Ref(id) => point = Some(m.point(&m.get(inst, *id)?)?),
            _ => {}
        }
    }
    let angle = if b.periodic() {
        m.units.rad_per_angle
    } else {
        1.0
    };
    // A trim given as a point must lie on its curve: its projection is where the piece ends,
    // and a point far off (a circle's centre, another curve's end) would cut a silently wrong
    // piece.
    let on_curve = |p: Point3<f64>| -> Result<f64> {
        let t = b.param_of(&p);
        let off = (b.point_at(t) - p).norm();
        if off.is_finite() && off <= ON_GEOMETRY_TOLERANCE_MM {
            Ok(t)
        } else {
            Err(err(
                inst,
                format!(
                    "{what}: the trim point ({:.6}, {:.6}, {:.6}) lies {off:.6} mm off its curve (at most {ON_GEOMETRY_TOLERANCE_MM} mm)",
                    p.x, p.y, p.z
                ),
            ))
        }
    };
    match (param, point) {
        (Some(_), Some(p)) if prefer_point => on_curve(p),
        (Some(t), _) => Ok(t * angle),
        (None, Some(p)) => on_curve(p),
        (None, None) => Err(err(
            inst,
            format!("{what} has neither a parameter nor a point"),
        )),
    }
}

/// How far a point the file puts on a curve or a surface (a trim point on its curve, an edge
/// on its face) may lie from it, mm: above the edge tolerances CAD files carry (0.01-0.07 mm),
/// far below a point that belongs elsewhere.
pub const ON_GEOMETRY_TOLERANCE_MM: f64 = 0.1;

/// Any bounded curve entity as one NURBS curve per segment (a composite gives its segments,
/// senses applied; others one). Full conics give the closed curve starting at angle 0.
///
/// A contour is a path, so each `COMPOSITE_CURVE` and each `COMPOSITE_CURVE_SEGMENT` may
/// occur once in its expansion: one used again (a composite listing a segment twice, or
/// reaching a sub-composite along two branches) is refused, naming both places. That bounds
/// the expansion by the file's own entities (a "billion laughs" DAG of composites would
/// otherwise grow exponentially with its depth), and the segments produced count against
/// [`Charge::Segments`].
pub(crate) fn bounded_segments(m: &Model<'_>, inst: &Instance) -> Result<Vec<(NurbsCurve, u64)>> {
    let mut used = std::collections::HashMap::new();
    segments_at(m, inst, 0, &mut used)
}

fn segments_at(
    m: &Model<'_>,
    inst: &Instance,
    depth: usize,
    used: &mut std::collections::HashMap<u64, u64>,
) -> Result<Vec<(NurbsCurve, u64)>> {
    if depth > MAX_CURVE_DEPTH {
        return Err(err(
            inst,
            format!("composite curves nested more than {MAX_CURVE_DEPTH} deep (a cycle?)"),
        ));
    }
    if let Some(p) = inst.record("COMPOSITE_CURVE") {
        let segs = refs(inst, p.get(1), "segments")?;
        if segs.is_empty() {
            return Err(err(inst, "a composite curve with no segment"));
        }
        let mut out = Vec::with_capacity(segs.len().min(1024));
        for (k, sid) in segs.into_iter().enumerate() {
            if let Some(first) = used.insert(sid, inst.id) {
                return Err(err(
                    inst,
                    format!(
                        "segment {} (#{sid}) is already used by #{first} in this contour: a contour runs each segment once",
                        k + 1
                    ),
                ));
            }
            let seg = &m.get(inst, sid)?;
            let sp = m.rec(seg, "COMPOSITE_CURVE_SEGMENT").map_err(|_| {
                err(
                    inst,
                    format!(
                        "segment {} (#{sid}) is not a COMPOSITE_CURVE_SEGMENT",
                        k + 1
                    ),
                )
            })?;
            let same = boolean(seg, sp.get(1), "same_sense")?;
            let parent = &m.param_ref(seg, sp, 2)?;
            if parent.is("COMPOSITE_CURVE") {
                if let Some(first) = used.insert(parent.id, sid) {
                    return Err(err(
                        inst,
                        format!(
                            "segment {} (#{sid}) reaches composite #{} again (first through #{first}): a contour runs each piece once",
                            k + 1,
                            parent.id
                        ),
                    ));
                }
            }
            let pieces = segments_at(m, parent, depth + 1, used).map_err(|e| match e {
                e @ crate::error::StepError::Budget { .. } => e,
                e => err(inst, format!("segment {} (#{sid}): {e}", k + 1)),
            })?;
            if same {
                out.extend(pieces);
            } else {
                out.extend(pieces.into_iter().rev().map(|(c, id)| (c.reversed(), id)));
            }
        }
        return Ok(out);
    }
    m.charge(inst, Charge::Segments, 1)?;
    if inst.is("TRIMMED_CURVE") {
        return Ok(vec![(trimmed(m, inst)?, inst.id)]);
    }
    let b = basis(m, inst)?;
    match &b {
        Basis::Line { .. } => Err(err(inst, "an unbounded line is not a contour (trim it)")),
        Basis::Conic { .. } => Ok(vec![(
            b.piece(inst, 0.0, 2.0 * std::f64::consts::PI)?,
            inst.id,
        )]),
        Basis::Nurbs(c) => Ok(vec![(c.clone(), inst.id)]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame {
            origin: Point3::new(1.0, 2.0, 3.0),
            x: Vector3::x(),
            y: Vector3::y(),
            z: Vector3::z(),
        }
    }

    #[test]
    fn arcs_lie_on_the_circle_and_end_where_asked() {
        for (t1, t2) in [
            (0.0, 1.0),
            (0.3, 6.0),
            (2.0, -1.5),
            (0.0, 2.0 * std::f64::consts::PI),
        ] {
            let c = conic_arc(&frame(), 5.0, 5.0, t1, t2);
            let (a, b) = c.domain();
            for k in 0..=200 {
                let t = a + (b - a) * k as f64 / 200.0;
                let r = (c.point(t) - frame().origin).norm();
                assert!(
                    (r - 5.0).abs() < 1e-12,
                    "radius {r} at {t} for arc {t1}..{t2}"
                );
            }
            let start = frame().origin + Vector3::new(t1.cos(), t1.sin(), 0.0) * 5.0;
            let end = frame().origin + Vector3::new(t2.cos(), t2.sin(), 0.0) * 5.0;
            assert!((c.point(a) - start).norm() < 1e-12, "start");
            assert!((c.point(b) - end).norm() < 1e-12, "end");
            // Direction: the midpoint parameter lands at the mid angle.
            let mid = c.point(0.5 * (a + b)) - frame().origin;
            let want = 0.5 * (t1 + t2);
            let got = mid.y.atan2(mid.x);
            let diff = (got - want).rem_euclid(2.0 * std::f64::consts::PI);
            assert!(!(1.0..=5.28).contains(&diff), "mid angle {got} vs {want}");
        }
    }

    #[test]
    fn ellipse_points_satisfy_the_equation() {
        let c = conic_arc(&frame(), 4.0, 1.5, 0.2, 5.0);
        let (a, b) = c.domain();
        for k in 0..=100 {
            let d = c.point(a + (b - a) * k as f64 / 100.0) - frame().origin;
            let e = (d.x / 4.0).powi(2) + (d.y / 1.5).powi(2);
            assert!((e - 1.0).abs() < 1e-12, "ellipse equation {e}");
        }
    }

    #[test]
    fn clamping_an_unclamped_curve_keeps_its_shape() {
        let pts: Vec<Point3<f64>> = (0..6)
            .map(|i| Point3::new(i as f64, ((i * 7) % 3) as f64, 0.0))
            .collect();
        let knots: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let c = NurbsCurve::new(3, knots, pts, None);
        let cc = clamp(&c).expect("clamp");
        assert_eq!(cc.domain(), c.domain(), "domain kept");
        for k in 0..=50 {
            let t = 3.0 + 3.0 * k as f64 / 50.0;
            assert!(
                (cc.point(t) - c.point(t)).norm() < 1e-12,
                "same point at {t}"
            );
        }
        let kk = cc.knots();
        assert!(kk[..4].iter().all(|&x| x == 3.0), "clamped start {kk:?}");
        assert!(
            kk[kk.len() - 4..].iter().all(|&x| x == 6.0),
            "clamped end {kk:?}"
        );
    }
}
