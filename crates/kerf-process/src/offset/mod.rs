//! Kerf compensation in the computer: the beam's path offset by half the kerf toward the scrap,
//! so that the beam's edge, not its centre, runs on the contour (docs/process.md, "Kerf
//! compensation").
//!
//! At a contour point `C` with tangent `T` and tool axis `a`, the beam's centre goes to
//! `Q = C + r s normalize(a x T)` (`r` half the kerf, `s = +1` for scrap on the left, `-1` on
//! the right): at right angles to both the path and the beam, as Sinumerik's `CUT3DC` defines
//! it. The beam is a cylinder of radius `r` about the line through `Q` along `a`, and that
//! line passes `r` from `C`: the cylinder touches the line through `C` along `a`, so the cut
//! edge runs through `C` whatever the tilt. Where the surface's normal `m` is not the axis (a
//! tilted beam), `Q` slides along the beam line onto the surface's tangent plane at `C`,
//! `Q' = Q - a ((Q - C) . m) / (a . m)`: the same beam, its tip on the surface.
//!
//! Corners: where two stretches meet at an angle, the stretch ends' offsets differ. Turning
//! away from the scrap (an outside corner), the beam swings round the corner on an arc of
//! radius `r` about it (the cut edge keeps the sharp corner); turning toward the scrap (an
//! inside corner), both offset polylines are cut back to where they cross, so that no stretch
//! runs into the part (the beam, being round, leaves a radius `r` of material in the corner,
//! reported). A rounding tighter than `r` toward the scrap, where the offset would run
//! backwards, is left out and cut back the same way; a loop with nothing left is refused.
//!
//! The certificate: on a flat contour at a fixed tool axis every chord of the offset is proven
//! within the tolerance of the exact offset curve (the contour's own proven chord error plus
//! the offset's term `r (1 - cos alpha)`, [`bound`]); elsewhere (curved surfaces, turning tool
//! axes) by the contour's chord error plus `r sup|W''| / 8` along the chord ([`curved`]),
//! halving a chord up to [`MAX_PROOF_SPLITS`] times more to find the proof; where none is
//! found the distance is measured at 15 points inside the chord, and the path says so
//! ([`OffsetPath::proven`]).

mod bound;
mod corner;
mod curved;

use kerf_discretize::chord_error;
use kerf_nurbs::{NurbsCurve, Segment};
use nalgebra::{Point3, Vector3, Vector4};

use crate::{Pose, ProcessError, Result, Side};

/// How to offset: the kerf width and the tolerance the offset path keeps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct OffsetOptions {
    /// The kerf width, mm: the path moves half of it toward the scrap.
    pub kerf_width_mm: f64,
    /// The largest distance from any chord of the offset path to the exact offset curve, mm
    /// (the discretizer's chord tolerance).
    pub tolerance_mm: f64,
    /// The most points one offset path may hold (the bisection and the corner arcs stop
    /// there with an error): a work budget.
    pub max_points: usize,
}

impl OffsetOptions {
    /// The largest kerf width accepted, mm (a plasma kerf is a few millimetres; beyond this
    /// the number is a mistake, not a kerf).
    pub const MAX_KERF_WIDTH_MM: f64 = 20.0;

    /// Options for a kerf of `kerf_width_mm` kept within `tolerance_mm`, with a budget of
    /// 1,000,000 points per path.
    pub fn new(kerf_width_mm: f64, tolerance_mm: f64) -> Self {
        Self {
            kerf_width_mm,
            tolerance_mm,
            max_points: 1_000_000,
        }
    }

    /// With another point budget per path.
    pub fn with_max_points(mut self, max_points: usize) -> Self {
        self.max_points = max_points;
        self
    }

    /// Checks the ranges: a kerf in `(0, MAX_KERF_WIDTH_MM]`, a positive finite tolerance, a
    /// budget of at least 2 points.
    ///
    /// # Errors
    /// [`ProcessError::BadOption`].
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, reason| {
            Err(ProcessError::BadOption {
                name,
                value,
                reason,
            })
        };
        if !(self.kerf_width_mm > 0.0 && self.kerf_width_mm <= Self::MAX_KERF_WIDTH_MM) {
            return bad(
                "kerf_width_mm",
                self.kerf_width_mm,
                "must be > 0 and <= 20 mm",
            );
        }
        if !(self.tolerance_mm > 0.0 && self.tolerance_mm.is_finite()) {
            return bad(
                "tolerance_mm",
                self.tolerance_mm,
                "must be positive and finite",
            );
        }
        if self.max_points < 2 {
            return bad("max_points", self.max_points as f64, "must be at least 2");
        }
        Ok(())
    }
}

/// One contour to offset: the exact curve, its cutting points with the tool axes, and the
/// scrap side.
#[derive(Debug, Clone, Copy)]
pub struct OffsetInput<'a> {
    /// The contour's id (for messages).
    pub id: &'a str,
    /// The exact curve.
    pub curve: &'a NurbsCurve,
    /// The curve parameter of every cutting point (strictly increasing; every C0 break of the
    /// curve among them, as the discretizer puts them).
    pub params: &'a [f64],
    /// The cutting points with their tool axes (the axis pointing from the tip toward the
    /// head), one per parameter.
    pub poses: &'a [Pose],
    /// The surface's unit normal at each cutting point where it is not the tool axis (a tilted
    /// beam): the tip slides along the beam onto the tangent plane there. `None`: the axis is
    /// the normal, or the beam runs along a wall and stays where the offset puts it.
    pub surface_normals: Option<&'a [[f64; 3]]>,
    /// The side of the contour the beam moves to.
    pub scrap: Side,
    /// True for a closed contour (its last cutting point repeats the first).
    pub closed: bool,
}

/// The offset path of one contour: the beam's tip in order, with the exact curve between its
/// points ([`OffsetPath::point_at`]) and what the offset found.
#[derive(Debug, Clone)]
pub struct OffsetPath {
    /// The tip points with the tool axes, in the contour's direction; a closed contour's last
    /// point repeats its first.
    pub poses: Vec<Pose>,
    /// The contour parameter each point comes from (non-decreasing; the points of a corner
    /// arc share the corner's).
    pub source: Vec<f64>,
    /// The side the path moved to.
    pub side: Side,
    /// How far it moved: half the kerf, mm.
    pub offset_mm: f64,
    /// The largest distance from a chord of the path to the exact offset curve, mm: proven
    /// where [`OffsetPath::proven`], else measured.
    pub max_chord_error_mm: f64,
    /// True if every chord's distance is proven: on a flat contour at a fixed tool axis by the
    /// tangents' cone, elsewhere by a bound of the offset direction's second derivative (a
    /// chord where that fails, even halved three times more, is measured).
    pub proven: bool,
    /// Corners swung round on an arc (turning away from the scrap).
    pub outside_corners: usize,
    /// Corners where the offsets were cut back to their crossing (turning toward the scrap).
    pub inside_corners: usize,
    /// The largest radius of material an inside corner keeps (the beam is round), mm.
    pub max_corner_material_mm: f64,
    /// Points added to keep the tolerance (bisection and corner arcs).
    pub inserted: usize,
    /// True if the path was checked for crossing itself (its tool axes lie within 60 degrees of
    /// their mean, so that it can be projected along it).
    pub crossing_checked: bool,
    pieces: Vec<Piece>,
    r: f64,
}

impl OffsetPath {
    /// The tip at path parameter `u` in `[0, poses.len() - 1]` (point `k` at `u = k`): on the
    /// exact offset curve along a stretch (with the chord ends' own rounding spread linearly),
    /// on the arc at a corner, on the straight line where an inside corner was cut back.
    pub fn point_at(&self, u: f64, curve: &NurbsCurve) -> Point3<f64> {
        let n = self.poses.len();
        if n == 1 || !u.is_finite() {
            return self.poses[0].position;
        }
        let u = u.clamp(0.0, (n - 1) as f64);
        let k = (u.floor() as usize).min(n - 2);
        let f = u - k as f64;
        let (p0, p1) = (self.poses[k].position, self.poses[k + 1].position);
        if f == 1.0 {
            return p1;
        }
        match &self.pieces[k] {
            Piece::Line => p0 + (p1 - p0) * f,
            // The ends are the points themselves (at a corner the curve's tangent is
            // one-sided).
            _ if f == 0.0 => p0,
            Piece::Curve(c) => {
                let t = c.t0 + (c.t1 - c.t0) * f;
                let a = nlerp(&c.a0, &c.a1, f);
                let m = nlerp(&c.m0, &c.m1, f);
                let q = exact(curve, t, &a, &m, self.r * self.side.sign(), c.slide)
                    .map_or(p0 + (p1 - p0) * f, |q| q.0);
                q + c.e0 * (1.0 - f) + c.e1 * f
            }
            Piece::Arc(a) => {
                let th = a.theta * f;
                let d = a.d0 * th.cos() + a.s.cross(&a.d0) * th.sin();
                slide(&(a.c + d * self.r), &a.c, &a.axis, &a.m, a.slide)
            }
        }
    }

    /// The index of the point the path reaches at contour parameter `t` (the first whose
    /// source is at or after it), for a start pinned on the contour.
    pub fn index_of_source(&self, t: f64) -> usize {
        self.source
            .partition_point(|&s| s < t)
            .min(self.poses.len() - 1)
    }
}

/// What lies between two points of an offset path.
#[derive(Debug, Clone)]
enum Piece {
    /// The exact offset of the contour on `[t0, t1]`.
    Curve(CurvePiece),
    /// An arc about a corner.
    Arc(ArcPiece),
    /// A straight line: what is left of a corner arc cut back at an inside corner.
    Line,
}

#[derive(Debug, Clone)]
struct CurvePiece {
    t0: f64,
    t1: f64,
    a0: Vector3<f64>,
    a1: Vector3<f64>,
    m0: Vector3<f64>,
    m1: Vector3<f64>,
    slide: bool,
    /// The ends' distance from the exact offset (the chord ends' rounding, or the point where
    /// an inside corner cut the chord back).
    e0: Vector3<f64>,
    e1: Vector3<f64>,
}

#[derive(Debug, Clone)]
struct ArcPiece {
    c: Point3<f64>,
    d0: Vector3<f64>,
    /// The rotation axis (`+-a`).
    s: Vector3<f64>,
    theta: f64,
    axis: Vector3<f64>,
    m: Vector3<f64>,
    slide: bool,
}

/// A point of the offset path while it is built.
#[derive(Debug, Clone, Copy)]
struct Node {
    pos: Point3<f64>,
    axis: Vector3<f64>,
    m: Vector3<f64>,
    source: f64,
    /// The contour point it is offset from.
    c: Point3<f64>,
    /// The contour's unit tangent there (one-sided at a corner).
    tangent: Vector3<f64>,
    /// The unit offset direction (`s normalize(a x T)`).
    d: Vector3<f64>,
}

/// One chord of the offset, certified.
#[derive(Debug, Clone)]
struct Seg {
    start: Node,
    end: Node,
    piece: CurvePiece,
    bound: f64,
    proven: bool,
    /// A stretch tighter than half the kerf was left out just before this chord: it joins the
    /// path as an inside corner does.
    after_tight: bool,
}

/// Offsets one contour by half the kerf toward its scrap side.
///
/// # Errors
/// [`ProcessError::BadOption`] for options out of range, [`ProcessError::BadContour`] for
/// inconsistent input, [`ProcessError::Compensation`] where the contour cannot be offset: a
/// radius of curvature toward the scrap below half the kerf (a loop smaller than the kerf), an
/// inside corner whose sides' offsets never meet or a path that crosses itself (a feature
/// narrower than the kerf), a stretch along the tool axis, the point budget spent.
pub fn offset(input: &OffsetInput<'_>, options: &OffsetOptions) -> Result<OffsetPath> {
    options.validate()?;
    let bad = |reason: String| ProcessError::BadContour {
        id: input.id.to_string(),
        reason,
    };
    let n = input.poses.len();
    if n < 2 || input.params.len() != n {
        return Err(bad(format!(
            "{} cutting points with {} parameters; an offset needs two or more, one parameter each",
            n,
            input.params.len()
        )));
    }
    if let Some(m) = input.surface_normals {
        if m.len() != n {
            return Err(bad(format!(
                "{} surface normals for {n} cutting points",
                m.len()
            )));
        }
    }
    if input.params.windows(2).any(|w| !bound::exceeds(w[1], w[0])) {
        return Err(bad("the cutting points' parameters must increase".into()));
    }
    if !input.poses.iter().all(Pose::is_finite) {
        return Err(bad("a cutting point holds a non-finite value".into()));
    }
    let unit = |v: [f64; 3]| {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        (n - 1.0).abs() <= 1e-6
    };
    if let Some(i) = input.poses.iter().position(|p| !unit(p.axis.into())) {
        return Err(bad(format!(
            "cutting point {i}: the tool axis is not a unit vector"
        )));
    }
    if let Some(i) = input
        .surface_normals
        .and_then(|m| m.iter().position(|v| !unit(*v)))
    {
        return Err(bad(format!("surface normal {i} is not a unit vector")));
    }
    if input.closed {
        let (a, b) = (input.poses[0].position, input.poses[n - 1].position);
        // As `LeadOptions::closed_tolerance_mm` has it by default.
        if (a - b).norm() > 1e-6 {
            return Err(bad(
                "closed, but its last cutting point is not its first".into()
            ));
        }
    }
    let ctx = Context::new(input, options);
    let mut segs: Vec<Seg> = Vec::with_capacity(n);
    let mut inserted = 0usize;
    let mut tight = Tight::default();
    for i in 0..n - 1 {
        let before = segs.len();
        ctx.segment(i, &mut segs, &mut tight, options.max_points)?;
        // Chords of zero length (a repeated cutting point) or left out add none.
        inserted += (segs.len() - before).saturating_sub(1);
    }
    if segs.is_empty() {
        return Err(match tight.tightest {
            Some((radius, t)) => ctx.small_radius(t, radius),
            None => ctx.refuse("every chord of the contour has zero length".into()),
        });
    }
    // A stretch left out at the end (or the start) of a closed contour joins its ends.
    let closing_tight = input.closed && (tight.pending || segs[0].after_tight);
    corner::assemble(&ctx, segs, inserted, closing_tight).map_err(|e| match (e, tight.tightest) {
        // Nothing left once cut back: the contour is a loop smaller than the kerf.
        (ProcessError::Compensation { reason, .. }, Some((radius, t)))
            if reason.contains("leave nothing") =>
        {
            ctx.small_radius(t, radius)
        }
        (e, _) => e,
    })
}

/// The geometry shared by a contour's segments.
struct Context<'a> {
    input: &'a OffsetInput<'a>,
    r: f64,
    sigma: f64,
    tol: f64,
    kerf: f64,
    max_points: usize,
    /// The contour's size (its control points' box diagonal), for the rounding allowances.
    size: f64,
    /// The flat case: the fixed axis, the surface normal, the contour projected along the axis,
    /// the cosine between axis and normal.
    flat: Option<Flat>,
}

struct Flat {
    axis: Vector3<f64>,
    origin: Point3<f64>,
    projected: NurbsCurve,
    cos: f64,
}

impl<'a> Context<'a> {
    fn new(input: &'a OffsetInput<'a>, options: &OffsetOptions) -> Self {
        let r = 0.5 * options.kerf_width_mm;
        Self {
            input,
            r,
            sigma: input.scrap.sign(),
            tol: options.tolerance_mm,
            kerf: options.kerf_width_mm,
            max_points: options.max_points,
            size: input.curve.size(),
            flat: flat(input),
        }
    }

    fn refuse(&self, reason: String) -> ProcessError {
        ProcessError::Compensation {
            id: self.input.id.to_string(),
            kerf_width_mm: self.kerf,
            reason,
        }
    }

    fn axis(&self, i: usize) -> Vector3<f64> {
        let p = &self.input.poses[i];
        p.axis.try_normalize(0.0).unwrap_or_else(Vector3::z)
    }

    fn normal(&self, i: usize) -> (Vector3<f64>, bool) {
        match self.input.surface_normals {
            Some(m) => (
                Vector3::from(m[i])
                    .try_normalize(0.0)
                    .unwrap_or_else(|| self.axis(i)),
                true,
            ),
            None => (self.axis(i), false),
        }
    }

    /// The node offset from the contour at `t` with the tangent `tangent`.
    fn node(
        &self,
        t: f64,
        c: Point3<f64>,
        tangent: Vector3<f64>,
        axis: Vector3<f64>,
        m: Vector3<f64>,
        slides: bool,
    ) -> Result<Node> {
        let d = (axis.cross(&tangent) * self.sigma)
            .try_normalize(1e-9)
            .ok_or_else(|| {
                self.refuse(format!(
                    "at ({:.3}, {:.3}, {:.3}) the contour runs along the tool axis: no direction to offset in",
                    c.x, c.y, c.z
                ))
            })?;
        Ok(Node {
            pos: slide(&(c + d * self.r), &c, &axis, &m, slides),
            axis,
            m,
            source: t,
            c,
            tangent,
            d,
        })
    }

    /// Offsets the chords of contour segment `i`, bisected until each is within the
    /// tolerance, onto `out`.
    fn segment(
        &self,
        i: usize,
        out: &mut Vec<Seg>,
        tight: &mut Tight,
        max_points: usize,
    ) -> Result<()> {
        let input = self.input;
        let curve = input.curve;
        let (t0, t1) = (input.params[i], input.params[i + 1]);
        let c0 = input.poses[i].position;
        let c1 = input.poses[i + 1].position;
        if (c1 - c0).norm() == 0.0 {
            return Ok(());
        }
        let (a0, a1) = (self.axis(i), self.axis(i + 1));
        let ((m0, slides), (m1, _)) = (self.normal(i), self.normal(i + 1));
        // (t0, t1, point at t0, point at t1, fraction of the segment at each end), depth, the
        // halvings made only to find a proof.
        let mut stack = vec![((t0, 0.0, c0), (t1, 1.0, c1), 0u32, 0u32)];
        while let Some(((ta, fa, ca), (tb, fb, cb), depth, extra)) = stack.pop() {
            let (aa, ab) = (nlerp(&a0, &a1, fa), nlerp(&a0, &a1, fb));
            let (ma, mb) = (nlerp(&m0, &m1, fa), nlerp(&m0, &m1, fb));
            let (ta_dir, tb_dir) = end_tangents(curve, ta, tb).ok_or_else(|| {
                self.refuse(format!(
                    "the contour has no tangent between parameters {ta} and {tb}"
                ))
            })?;
            let start = self.node(ta, ca, ta_dir, aa, ma, slides)?;
            let end = self.node(tb, cb, tb_dir, ab, mb, slides)?;
            let piece = CurvePiece {
                t0: ta,
                t1: tb,
                a0: aa,
                a1: ab,
                m0: ma,
                m1: mb,
                slide: slides,
                // The nodes are the exact offset at the chord's ends (with the one-sided
                // tangents there).
                e0: Vector3::zeros(),
                e1: Vector3::zeros(),
            };
            let verdict = self.certify(&start, &end, &piece, extra < MAX_PROOF_SPLITS)?;
            if let Verdict::Tight(radius, at) = verdict {
                tight.pending = true;
                if tight.tightest.is_none_or(|(r, _)| radius < r) {
                    tight.tightest = Some((radius, at));
                }
                continue;
            }
            let ok = match verdict {
                // Room for a smooth join's gap (tangents within SMOOTH_RAD: r SMOOTH_RAD).
                Verdict::Proven(b) | Verdict::Measured(b) => {
                    b <= self.tol - corner::SMOOTH_RAD * self.r
                }
                Verdict::Split | Verdict::SplitAt(_) | Verdict::ProofSplit | Verdict::Tight(..) => {
                    false
                }
            };
            if ok || depth >= 40 {
                let (bound, proven) = match verdict {
                    Verdict::Proven(b) => (b, true),
                    Verdict::Measured(b) => (b, false),
                    Verdict::Split
                    | Verdict::SplitAt(_)
                    | Verdict::ProofSplit
                    | Verdict::Tight(..) => (self.measure(&start, &end, &piece), false),
                };
                // NaN is refused too.
                if bound.is_nan() || bound > self.tol {
                    return Err(self.refuse(format!(
                        "the offset between contour parameters {ta} and {tb} stays {bound:.3e} mm from its chords after 40 halvings (tolerance {} mm)",
                        self.tol
                    )));
                }
                out.push(Seg {
                    start,
                    end,
                    piece,
                    bound,
                    proven,
                    after_tight: std::mem::take(&mut tight.pending),
                });
                if out.len() > max_points {
                    return Err(self.refuse(format!(
                        "the offset path needs more than {max_points} points (the point budget)"
                    )));
                }
                continue;
            }
            // Halved, or split at a knot where the contour is only C1 (the axes' fraction is
            // affine in the parameter).
            let (tm, extra) = match verdict {
                Verdict::SplitAt(k) => (k, extra),
                Verdict::ProofSplit => (0.5 * (ta + tb), extra + 1),
                _ => (0.5 * (ta + tb), extra),
            };
            let fm = fa + (fb - fa) * (tm - ta) / (tb - ta);
            let cm = curve.point(tm);
            // Right half first off the stack: push it first.
            stack.push(((tm, fm, cm), (tb, fb, cb), depth + 1, extra));
            stack.push(((ta, fa, ca), (tm, fm, cm), depth + 1, extra));
        }
        Ok(())
    }

    fn exact_or(
        &self,
        t: f64,
        a: &Vector3<f64>,
        m: &Vector3<f64>,
        slides: bool,
        fallback: Point3<f64>,
    ) -> Point3<f64> {
        exact(self.input.curve, t, a, m, self.r * self.sigma, slides).map_or(fallback, |q| q.0)
    }

    /// The chord error of one offset chord against the exact offset. `may_split`: a chord the
    /// measurement already keeps within the tolerance may still be halved to find a proof.
    fn certify(
        &self,
        start: &Node,
        end: &Node,
        piece: &CurvePiece,
        may_split: bool,
    ) -> Result<Verdict> {
        let chord_c = end.c - start.c;
        let chord_q = end.pos - start.pos;
        if !bound::exceeds(chord_q.dot(&chord_c), 0.0) {
            // The offset runs backwards: the radius of curvature toward the scrap is below r,
            // unless the chord is long enough to hide it (then halve it).
            let tm = 0.5 * (piece.t0 + piece.t1);
            if let Some(radius) = self.radius_toward_scrap(tm, &start.axis) {
                if radius < self.r {
                    return Ok(Verdict::Tight(radius, tm));
                }
            }
            return Ok(Verdict::Split);
        }
        if let Some(flat) = &self.flat {
            let project = |p: &Point3<f64>| p - flat.axis * (p - flat.origin).dot(&flat.axis);
            let (p0, p1) = (project(&start.c), project(&end.c));
            let Some(u) = (p1 - p0).try_normalize(0.0) else {
                return Ok(Verdict::Split);
            };
            let Some(cone) =
                bound::tangent_cone(&flat.projected, piece.t0, piece.t1, &u, &flat.axis)
            else {
                return Ok(Verdict::Split);
            };
            // The offset advances along u where 1 - s k r > 0: proven by the curvature bound,
            // or by a turn away from the scrap everywhere.
            let monotone = cone.kappa_max * self.r < 1.0 || cone.turn * self.sigma < 0.0;
            if !monotone {
                let tm = 0.5 * (piece.t0 + piece.t1);
                if let Some(radius) = self.radius_toward_scrap(tm, &start.axis) {
                    if radius < self.r {
                        return Ok(Verdict::Tight(radius, tm));
                    }
                }
                return Ok(Verdict::Split);
            }
            let term = bound::offset_term(self.r, cone.alpha);
            let limit = self.tol * flat.cos - term;
            if !bound::exceeds(limit, 0.0) {
                return Ok(Verdict::Split);
            }
            let e = chord_error(&flat.projected, piece.t0, piece.t1, &p0, &p1, limit, 0.0).upper;
            // The chord ends' own rounding (a few ulps of the coordinates).
            let ends =
                8.0 * f64::EPSILON * (start.pos.coords.amax() + end.pos.coords.amax() + self.r);
            // The translation and subdivision of the pieces round at the coordinates' size,
            // and the contour may leave the plane by the 1e-9 the flat test allows.
            let size = self.size;
            let coords = flat.origin.coords.amax() + start.c.coords.amax() + end.c.coords.amax();
            let rounding = 64.0 * f64::EPSILON * (coords + size) + 2e-9 * size.max(1.0);
            let b = (e + term) / flat.cos + ends + rounding;
            return Ok(if b <= self.tol {
                Verdict::Proven(b)
            } else {
                Verdict::Split
            });
        }
        // Curved or turning: proven by the second-derivative bound where it holds
        // ([`curved`]), else the exact offset measured against the chord.
        let tm = 0.5 * (piece.t0 + piece.t1);
        if let Some(radius) = self.radius_toward_scrap(tm, &start.axis) {
            if radius < self.r {
                return Err(self.small_radius(tm, radius));
            }
        }
        let room = self.tol - corner::SMOOTH_RAD * self.r;
        let proof = curved::bound(&curved::Chord {
            curve: self.input.curve,
            t0: piece.t0,
            t1: piece.t1,
            c0: start.c,
            c1: end.c,
            a0: piece.a0,
            a1: piece.a1,
            m0: piece.m0,
            m1: piece.m1,
            slide: piece.slide,
            r: self.r,
            size: self.size,
            limit: room,
        });
        if let curved::Proof::Bound(b) = proof {
            if b <= room {
                return Ok(Verdict::Proven(b));
            }
        }
        let measured = self.measure(start, end, piece);
        // NaN is not within.
        let within = measured <= room;
        Ok(match proof {
            curved::Proof::SplitAt(k) if may_split || !within => Verdict::SplitAt(k),
            _ if may_split && within => Verdict::ProofSplit,
            _ => Verdict::Measured(measured),
        })
    }

    /// The largest distance of 15 points of the exact offset inside the chord from it.
    fn measure(&self, start: &Node, end: &Node, piece: &CurvePiece) -> f64 {
        let seg = Segment::between(&start.pos, &end.pos);
        (1..16)
            .map(|k| {
                let f = k as f64 / 16.0;
                let t = piece.t0 + (piece.t1 - piece.t0) * f;
                let a = nlerp(&piece.a0, &piece.a1, f);
                let m = nlerp(&piece.m0, &piece.m1, f);
                exact(
                    self.input.curve,
                    t,
                    &a,
                    &m,
                    self.r * self.sigma,
                    piece.slide,
                )
                .map_or(f64::INFINITY, |q| seg.distance_to(&q.0))
            })
            // A NaN distance stays NaN, and fails every comparison with the tolerance.
            .fold(0.0, |m: f64, d| {
                if d.is_nan() || m.is_nan() {
                    f64::NAN
                } else {
                    m.max(d)
                }
            })
    }

    /// The radius of curvature at `t` of the contour seen along `axis`, where it turns toward
    /// the scrap; `None` where it turns away or runs straight.
    fn radius_toward_scrap(&self, t: f64, axis: &Vector3<f64>) -> Option<f64> {
        let (_, d1, d2) = self.input.curve.eval_d2(t);
        let d1p = d1 - axis * d1.dot(axis);
        let turn = d1.cross(&d2).dot(axis) * self.sigma;
        let speed = d1p.norm();
        (turn > 0.0 && speed > 0.0).then(|| speed.powi(3) / turn)
    }

    fn small_radius(&self, t: f64, radius: f64) -> ProcessError {
        let c = self.input.curve.point(t);
        self.refuse(format!(
            "at ({:.3}, {:.3}, {:.3}) the contour bends toward the scrap with a radius of {radius:.4} mm, smaller than half the kerf ({:.4} mm), and nothing of it is left once cut back: a loop smaller than the kerf cannot be cut to size",
            c.x, c.y, c.z, self.r
        ))
    }
}

/// How many times a chord the measurement keeps within the tolerance may be halved to find a
/// proof of its bound (each halving doubles the points there).
const MAX_PROOF_SPLITS: u32 = 3;

enum Verdict {
    Proven(f64),
    Measured(f64),
    Split,
    /// Split at this knot inside the chord, where the contour is only C1 (the curved proof
    /// needs the offset's direction once continuously differentiable along a chord).
    SplitAt(f64),
    /// Measured within the tolerance but not proven: halved to find a proof (at most
    /// [`MAX_PROOF_SPLITS`] times).
    ProofSplit,
    /// The contour bends toward the scrap tighter than half the kerf here (radius, where):
    /// the offset runs backwards, and the chord is left out: the offsets on either side are
    /// cut back to their crossing, as at an inside corner.
    Tight(f64, f64),
}

/// The stretches left out for bending toward the scrap tighter than half the kerf.
#[derive(Debug, Default)]
struct Tight {
    /// A stretch was left out since the last chord kept.
    pending: bool,
    /// The tightest radius met and where (its parameter).
    tightest: Option<(f64, f64)>,
}

/// The flat case, when it holds: every tool axis the same (to 1e-9), every surface normal the
/// same, the contour's control points in one plane across that normal (to 1e-9 of its size),
/// the beam tilted less than 80 degrees from the normal.
fn flat(input: &OffsetInput<'_>) -> Option<Flat> {
    let axes: Vec<Vector3<f64>> = input.poses.iter().map(|p| p.axis.normalize()).collect();
    let axis = axes[0];
    if axes.iter().any(|a| (a - axis).norm() > 1e-9) {
        return None;
    }
    let m = match input.surface_normals {
        Some(ms) => {
            let m = Vector3::from(ms[0]).try_normalize(0.0)?;
            if ms
                .iter()
                .any(|q| (Vector3::from(*q).normalize() - m).norm() > 1e-9)
            {
                return None;
            }
            m
        }
        None => axis,
    };
    let cos = axis.dot(&m);
    if !bound::exceeds(cos, 0.17) {
        return None;
    }
    let cps = input.curve.control_points();
    let origin = cps[0];
    let size = input.curve.size().max(1.0);
    if cps.iter().any(|p| (p - origin).dot(&m).abs() > 1e-9 * size) {
        return None;
    }
    let cpw: Vec<Vector4<f64>> = input
        .curve
        .homogeneous_points()
        .iter()
        .map(|h| {
            let w = h.w;
            let along = (h.xyz() - origin.coords * w).dot(&axis);
            let xyz = h.xyz() - axis * along;
            Vector4::new(xyz.x, xyz.y, xyz.z, w)
        })
        .collect();
    let projected = NurbsCurve::from_homogeneous_unchecked(
        input.curve.degree(),
        input.curve.knots().to_vec(),
        cpw,
    );
    Some(Flat {
        axis,
        origin,
        projected,
        cos,
    })
}

/// The exact offset point at `t` (`signed_r = s r`), with the contour point.
fn exact(
    curve: &NurbsCurve,
    t: f64,
    a: &Vector3<f64>,
    m: &Vector3<f64>,
    signed_r: f64,
    slides: bool,
) -> Option<(Point3<f64>, Point3<f64>)> {
    let (c, d1) = curve.eval_d1(t);
    let d = a.cross(&d1).try_normalize(0.0)?;
    Some((slide(&(c + d * signed_r), &c, a, m, slides), c))
}

/// `q` moved along the beam `a` onto the plane through `c` across `m` (where `slides`, and the
/// beam is within 80 degrees of `m`).
fn slide(
    q: &Point3<f64>,
    c: &Point3<f64>,
    a: &Vector3<f64>,
    m: &Vector3<f64>,
    slides: bool,
) -> Point3<f64> {
    let am = a.dot(m);
    if !slides || !bound::exceeds(am, 0.17) {
        return *q;
    }
    q - a * ((q - c).dot(m) / am)
}

/// The unit tangents of the curve leaving `t0` and arriving at `t1` (one-sided: at a C0
/// break the side of `[t0, t1]`), from the end edges of the Bezier pieces.
fn end_tangents(curve: &NurbsCurve, t0: f64, t1: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
    let mut first: Option<Vector3<f64>> = None;
    let mut last: Option<Vector3<f64>> = None;
    curve.for_each_bezier_piece(t0, t1, |b| {
        let pts: Vec<Point3<f64>> = b.control_points().collect();
        let scale = pts.iter().map(|p| (p - pts[0]).norm()).fold(0.0, f64::max);
        let tiny = 1e-14 * scale.max(f64::MIN_POSITIVE);
        if first.is_none() {
            first = pts
                .windows(2)
                .map(|w| w[1] - w[0])
                .find(|e| e.norm() > tiny)
                .map(|e| e.normalize());
        }
        if let Some(e) = pts
            .windows(2)
            .rev()
            .map(|w| w[1] - w[0])
            .find(|e| e.norm() > tiny)
        {
            last = Some(e.normalize());
        }
    });
    Some((first?, last?))
}

/// Normalized linear interpolation of two unit vectors.
fn nlerp(a: &Vector3<f64>, b: &Vector3<f64>, f: f64) -> Vector3<f64> {
    if f <= 0.0 {
        return *a;
    }
    if f >= 1.0 {
        return *b;
    }
    (a * (1.0 - f) + b * f).try_normalize(0.0).unwrap_or(*a)
}
