//! The offset path put together from its certified chords: smooth joins kept, outside corners
//! swung round on an arc about the corner, inside corners cut back to where the two sides'
//! offsets cross, and the whole path checked for crossing itself (a feature narrower than the
//! kerf).

use nalgebra::{Point3, Vector2, Vector3};

use super::{nlerp, slide, ArcPiece, Context, CurvePiece, Node, OffsetPath, Piece, Seg};
use crate::{Pose, ProcessError, Result};

/// How many chords on each side of an inside corner the cut-back searches for the crossing.
const TRIM_WINDOW: usize = 256;

/// Tangents closer than this (radians) join smoothly; each chord keeps `r SMOOTH_RAD` of the
/// tolerance for the gap such a join leaves.
pub(super) const SMOOTH_RAD: f64 = 1e-6;

struct Builder<'c, 'a> {
    ctx: &'c Context<'a>,
    nodes: Vec<Node>,
    pieces: Vec<Piece>,
    bound: f64,
    proven: bool,
    outside: usize,
    inside: usize,
    material: f64,
    arc_points: usize,
}

/// Joins the chords into the offset path.
pub(super) fn assemble(
    ctx: &Context<'_>,
    segs: Vec<Seg>,
    inserted: usize,
    closing_tight: bool,
) -> Result<OffsetPath> {
    let mut b = Builder {
        ctx,
        nodes: vec![segs[0].start],
        pieces: Vec::with_capacity(segs.len() + 16),
        bound: 0.0,
        proven: true,
        outside: 0,
        inside: 0,
        material: 0.0,
        arc_points: 0,
    };
    b.push(&segs[0], None, None);
    let mut i = 1;
    while i < segs.len() {
        let last = *b.nodes.last().expect("one node at least");
        let next = segs[i].start;
        let join = if segs[i].after_tight {
            Join::Inside
        } else {
            b.junction(&last, &next)
        };
        match join {
            Join::Smooth(gap) => {
                b.bound = b.bound.max(segs[i].bound + gap);
                b.push(&segs[i], None, None);
                i += 1;
            }
            Join::Outside => {
                b.arc(&last, &next)?;
                b.push(&segs[i], None, None);
                i += 1;
            }
            Join::Inside => {
                i = b.trim_forward(&segs, i)?;
            }
        }
        b.budget()?;
    }
    if ctx.input.closed {
        b.close(closing_tight)?;
        b.budget()?;
    }
    if b.nodes.len() < 2 {
        return Err(ctx.refuse(
            "the inside corners' cut-backs leave nothing of the path: the contour is smaller than the kerf".into(),
        ));
    }
    let crossing_checked = crossing(ctx, &b.nodes, ctx.input.closed)?;
    let poses = b
        .nodes
        .iter()
        .map(|n| Pose {
            position: n.pos,
            axis: n.axis,
        })
        .collect();
    let source = b.nodes.iter().map(|n| n.source).collect();
    Ok(OffsetPath {
        poses,
        source,
        side: ctx.input.scrap,
        offset_mm: ctx.r,
        max_chord_error_mm: b.bound,
        proven: b.proven,
        outside_corners: b.outside,
        inside_corners: b.inside,
        max_corner_material_mm: b.material,
        inserted: inserted + b.arc_points,
        crossing_checked,
        pieces: b.pieces,
        r: ctx.r,
    })
}

enum Join {
    Smooth(f64),
    Outside,
    Inside,
}

impl Builder<'_, '_> {
    fn budget(&self) -> Result<()> {
        if self.nodes.len() > self.ctx.max_points {
            return Err(self.ctx.refuse(format!(
                "the offset path needs more than {} points (the point budget)",
                self.ctx.max_points
            )));
        }
        Ok(())
    }

    /// Appends a chord (from `from` instead of its start where given, to `to` instead of its
    /// end where given, each with the chord fraction it sits at).
    fn push(&mut self, seg: &Seg, from: Option<(Node, f64)>, to: Option<(Node, f64)>) {
        let mut piece = seg.piece.clone();
        if let Some((x, mu)) = from {
            self.cut_start(&mut piece, mu, &x);
        }
        let end = match to {
            Some((x, lambda)) => {
                self.cut_end(&mut piece, lambda, &x);
                x
            }
            None => seg.end,
        };
        // A chord cut back at an inside corner: on a flat contour the crossing lies on both
        // chords and the chord's proof holds. Elsewhere the crossing `x` may sit off the chord
        // `Q0 Q1`; every point of the exact offset past the cut is within the chord's bound `b`
        // of `lerp(Q0, Q1, lambda)` with `lambda >= lambda_c` (the contour's chord fraction at
        // the cut), and the segments `[lerp(Q0, Q1, lambda_c), Q1]` and `[x, Q1]` are at most
        // `|x - lerp(Q0, Q1, lambda_c)|` apart point for point; the path adds the end's own
        // offset `e`. So `b + that + |e|` bounds the cut piece, proven where `b` was.
        let (bound, proven) = if (from.is_some() || to.is_some()) && self.ctx.flat.is_none() {
            let (c0, c1) = (seg.start.c, seg.end.c);
            let (q0, q1) = (seg.start.pos, seg.end.pos);
            let chord = c1 - c0;
            let along = |t: f64| {
                let l = chord.norm_squared();
                if l > 0.0 {
                    ((self.ctx.input.curve.point(t) - c0).dot(&chord) / l).clamp(0.0, 1.0)
                } else {
                    0.0
                }
            };
            let off = |x: &Node, t: f64| (x.pos - (q0 + (q1 - q0) * along(t))).norm();
            let mut b = seg.bound;
            if let Some((x, _)) = &from {
                b += off(x, piece.t0) + piece.e0.norm();
            }
            if let Some((x, _)) = &to {
                b += off(x, piece.t1) + piece.e1.norm();
            }
            if seg.proven && b <= self.ctx.tol {
                (b, true)
            } else {
                let start = from.map_or(seg.start, |(x, _)| x);
                let ends = piece.e0.norm().max(piece.e1.norm());
                (
                    (self.ctx.measure(&start, &end, &piece) + ends).max(seg.bound),
                    false,
                )
            }
        } else {
            (seg.bound, seg.proven)
        };
        self.bound = self.bound.max(bound);
        self.proven &= proven;
        self.pieces.push(Piece::Curve(piece));
        self.nodes.push(end);
    }

    fn cut_start(&self, piece: &mut CurvePiece, mu: f64, x: &Node) {
        piece.t0 += (piece.t1 - piece.t0) * mu;
        piece.a0 = nlerp(&piece.a0, &piece.a1, mu);
        piece.m0 = nlerp(&piece.m0, &piece.m1, mu);
        piece.e0 = x.pos
            - self
                .ctx
                .exact_or(piece.t0, &piece.a0, &piece.m0, piece.slide, x.pos);
    }

    fn cut_end(&self, piece: &mut CurvePiece, lambda: f64, x: &Node) {
        piece.t1 = piece.t0 + (piece.t1 - piece.t0) * lambda;
        piece.a1 = nlerp(&piece.a0, &piece.a1, lambda);
        piece.m1 = nlerp(&piece.m0, &piece.m1, lambda);
        piece.e1 = x.pos
            - self
                .ctx
                .exact_or(piece.t1, &piece.a1, &piece.m1, piece.slide, x.pos);
    }

    /// How the path ending at `last` joins the one starting at `next` (the same contour
    /// point).
    fn junction(&self, last: &Node, next: &Node) -> Join {
        let turn = last.tangent.angle(&next.tangent);
        let gap = (next.pos - last.pos).norm();
        if turn <= SMOOTH_RAD {
            return Join::Smooth(gap);
        }
        let cross = last.tangent.cross(&next.tangent).dot(&next.axis);
        if self.ctx.sigma * cross > 0.0 {
            Join::Inside
        } else {
            Join::Outside
        }
    }

    /// An arc of radius r about the corner from `last`'s offset to `next`'s, in the plane
    /// across the axis, in chords within the tolerance.
    fn arc(&mut self, last: &Node, next: &Node) -> Result<()> {
        self.outside += 1;
        let ctx = self.ctx;
        let axis = next.axis;
        // The offset turns with the tangent: outside a corner that is away from the scrap, so
        // about -s a.
        let s = -axis * ctx.sigma;
        let d0 = (last.d - axis * last.d.dot(&axis))
            .try_normalize(0.0)
            .unwrap_or(last.d);
        let d1 = next.d;
        let mut theta = d0.angle(&d1);
        // The long way round when the tangent turned by more than half a turn the other way.
        if d0.cross(&d1).dot(&s) < 0.0 {
            theta = 2.0 * std::f64::consts::PI - theta;
        }
        let slides = last_slides(next, ctx);
        // The slide onto the surface stretches by at most 1 / (a . m).
        let cos = if slides {
            axis.dot(&next.m).clamp(0.17, 1.0)
        } else {
            1.0
        };
        // A chord of angle delta is r (1 - cos(delta / 2)) from its arc.
        let ratio = (ctx.tol * cos * 0.999 / ctx.r).min(1.0);
        let delta_max = (2.0 * (1.0 - ratio).acos()).clamp(1e-6, std::f64::consts::FRAC_PI_4);
        let k = ((theta / delta_max).ceil() as usize).max(1);
        if k > ctx.max_points {
            return Err(ctx.refuse(format!(
                "a corner arc needs {k} points, more than the point budget"
            )));
        }
        let step = theta / k as f64;
        let c = next.c;
        // r (1 - cos(step / 2)) = 2 r sin^2(step / 4), through the slide's stretch.
        let arc_bound = ctx.r * 2.0 * (step / 4.0).sin().powi(2) / cos * (1.0 + 1e-12);
        self.bound = self.bound.max(arc_bound);
        let mut d = d0;
        for j in 1..=k {
            let piece = ArcPiece {
                c,
                d0: d,
                s,
                theta: step,
                axis,
                m: next.m,
                slide: slides,
            };
            self.pieces.push(Piece::Arc(piece));
            if j == k {
                self.nodes.push(*next);
            } else {
                let th = step * j as f64;
                d = d0 * th.cos() + s.cross(&d0) * th.sin();
                let pos = slide(&(c + d * ctx.r), &c, &axis, &next.m, slides);
                let tangent = s.cross(&d);
                self.nodes.push(Node {
                    pos,
                    axis,
                    m: next.m,
                    source: last.source,
                    c,
                    tangent,
                    d,
                });
                self.arc_points += 1;
            }
        }
        Ok(())
    }

    /// Cuts back an inside corner before `segs[i]`: finds where the offset so far (its last
    /// chords) crosses the chords to come, ends the path there and goes on along the chord it
    /// crosses. Returns the index of the next chord to append.
    fn trim_forward(&mut self, segs: &[Seg], i: usize) -> Result<usize> {
        self.inside += 1;
        let corner = segs[i].start;
        let frame = Frame::across(&corner.axis);
        let np = self.pieces.len();
        let back = |bd: usize| -> Option<(Point3<f64>, Point3<f64>)> {
            (bd < np).then(|| (self.nodes[np - 1 - bd].pos, self.nodes[np - bd].pos))
        };
        let fwd = |fd: usize| -> Option<(Point3<f64>, Point3<f64>)> {
            segs.get(i + fd).map(|s| (s.start.pos, s.end.pos))
        };
        let Some((bd, fd, lambda, mu)) = search(&frame, back, fwd) else {
            return Err(self.no_meeting(&corner));
        };
        let j = i + fd;
        let x = self.end_at_crossing(&frame, np - 1 - bd, lambda, &corner);
        // And on along the chord it crossed.
        self.push(&segs[j], Some((x, mu)), None);
        Ok(j + 1)
    }

    /// Ends the path at the crossing on piece `b` (fraction `lambda`), dropping what follows;
    /// returns the crossing.
    fn end_at_crossing(&mut self, frame: &Frame, b: usize, lambda: f64, corner: &Node) -> Node {
        let x = self.meeting(frame, b, lambda, corner);
        self.nodes.truncate(b + 1);
        let piece = self.pieces.remove(b);
        self.pieces.truncate(b);
        let cut = self.end_piece(piece, lambda, &x);
        self.pieces.push(cut);
        self.nodes.push(x);
        x
    }

    /// The crossing point on piece `b` at fraction `lambda`, with what it leaves in the corner.
    fn meeting(&mut self, frame: &Frame, b: usize, lambda: f64, corner: &Node) -> Node {
        let (p, q) = (self.nodes[b], self.nodes[b + 1]);
        let pos = p.pos + (q.pos - p.pos) * lambda;
        let left = (frame.project(&pos) - frame.project(&corner.c)).norm() - self.ctx.r;
        self.material = self.material.max(left);
        Node {
            pos,
            axis: nlerp(&p.axis, &q.axis, lambda),
            m: nlerp(&p.m, &q.m, lambda),
            source: p.source + (q.source - p.source) * lambda,
            c: corner.c,
            tangent: q.tangent,
            d: q.d,
        }
    }

    fn end_piece(&self, piece: Piece, lambda: f64, x: &Node) -> Piece {
        match piece {
            Piece::Curve(mut c) => {
                self.cut_end(&mut c, lambda, x);
                Piece::Curve(c)
            }
            _ => Piece::Line,
        }
    }

    fn start_piece(&self, piece: Piece, mu: f64, x: &Node) -> Piece {
        match piece {
            Piece::Curve(mut c) => {
                self.cut_start(&mut c, mu, x);
                Piece::Curve(c)
            }
            _ => Piece::Line,
        }
    }

    fn no_meeting(&self, corner: &Node) -> ProcessError {
        let c = corner.c;
        self.ctx.refuse(format!(
            "at ({:.3}, {:.3}, {:.3}) the offsets of an inside corner's two sides do not meet within {TRIM_WINDOW} chords: a feature there is narrower than the kerf",
            c.x, c.y, c.z
        ))
    }

    /// Joins a closed path's end to its start (as an inside corner where a tight stretch was
    /// left out between them).
    fn close(&mut self, tight: bool) -> Result<()> {
        let first = self.nodes[0];
        let last = *self.nodes.last().expect("nodes");
        let join = if tight {
            Join::Inside
        } else {
            self.junction(&last, &first)
        };
        match join {
            Join::Smooth(gap) => {
                self.bound += gap;
                let n = self.nodes.len();
                self.nodes[n - 1] = Node {
                    source: last.source,
                    ..first
                };
            }
            Join::Outside => {
                self.arc(&last, &first)?;
                let n = self.nodes.len();
                self.nodes[n - 1].source = last.source;
            }
            Join::Inside => {
                self.inside += 1;
                let frame = Frame::across(&first.axis);
                let np = self.pieces.len();
                let nodes = &self.nodes;
                // Back from the end, forward from the start, never the same piece.
                let back = |bd: usize| -> Option<(Point3<f64>, Point3<f64>)> {
                    (bd < np / 2).then(|| (nodes[np - 1 - bd].pos, nodes[np - bd].pos))
                };
                let fwd = |fd: usize| -> Option<(Point3<f64>, Point3<f64>)> {
                    (fd < np / 2).then(|| (nodes[fd].pos, nodes[fd + 1].pos))
                };
                let Some((bd, fd, lambda, mu)) = search(&frame, back, fwd) else {
                    return Err(self.no_meeting(&first));
                };
                // Where the crossing lies on the front piece, in the contour's parameter.
                let front_source = self.nodes[fd].source
                    + (self.nodes[fd + 1].source - self.nodes[fd].source) * mu;
                let x = self.end_at_crossing(&frame, np - 1 - bd, lambda, &first);
                // The start: drop what comes before the crossing on piece fd.
                let front = self.pieces.drain(..=fd).next_back().expect("piece fd");
                self.nodes.drain(..=fd);
                let start = Node {
                    source: front_source,
                    ..x
                };
                let cut = self.start_piece(front, mu, &start);
                self.pieces.insert(0, cut);
                self.nodes.insert(0, start);
                // The end's crossing is the same point.
                let n = self.nodes.len();
                self.nodes[n - 1].pos = start.pos;
            }
        }
        Ok(())
    }
}

/// Whether the tip slides onto the surface at this node.
fn last_slides(node: &Node, ctx: &Context<'_>) -> bool {
    ctx.input.surface_normals.is_some() && node.axis.dot(&node.m) > 0.17
}

/// The plane across an axis.
struct Frame {
    e1: Vector3<f64>,
    e2: Vector3<f64>,
}

impl Frame {
    fn across(axis: &Vector3<f64>) -> Self {
        let helper = if axis.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = helper.cross(axis).normalize();
        let e2 = axis.cross(&e1);
        Self { e1, e2 }
    }

    fn project(&self, p: &Point3<f64>) -> Vector2<f64> {
        Vector2::new(p.coords.dot(&self.e1), p.coords.dot(&self.e2))
    }
}

/// The nearest crossing (fewest chords back plus forward) of a chord going back from a corner
/// and one going forward, within [`TRIM_WINDOW`] each: `(back depth, forward depth, fraction
/// along the back chord, fraction along the forward chord)`.
fn search(
    frame: &Frame,
    back: impl Fn(usize) -> Option<(Point3<f64>, Point3<f64>)>,
    fwd: impl Fn(usize) -> Option<(Point3<f64>, Point3<f64>)>,
) -> Option<(usize, usize, f64, f64)> {
    for total in 0..2 * TRIM_WINDOW {
        for bd in 0..=total.min(TRIM_WINDOW - 1) {
            let fd = total - bd;
            if fd >= TRIM_WINDOW {
                continue;
            }
            let (Some((p, q)), Some((a, b))) = (back(bd), fwd(fd)) else {
                continue;
            };
            if let Some((l, m)) = crossing_of(
                frame.project(&p),
                frame.project(&q),
                frame.project(&a),
                frame.project(&b),
            ) {
                return Some((bd, fd, l, m));
            }
        }
    }
    None
}

/// Where segments `p q` and `a b` cross: the fractions along each, or `None` (parallel or
/// apart).
fn crossing_of(
    p: Vector2<f64>,
    q: Vector2<f64>,
    a: Vector2<f64>,
    b: Vector2<f64>,
) -> Option<(f64, f64)> {
    let r = q - p;
    let s = b - a;
    let denom = r.perp(&s);
    if denom == 0.0 || !denom.is_finite() {
        return None;
    }
    let w = a - p;
    let l = w.perp(&s) / denom;
    let m = w.perp(&r) / denom;
    ((0.0..=1.0).contains(&l) && (0.0..=1.0).contains(&m)).then_some((l, m))
}

/// Checks that the path does not cross itself, projected along its mean axis (where every
/// axis lies within 60 degrees of it; otherwise returns `false`, not checked). Chords are
/// binned on a grid of cells about one chord long; the pairs tested are counted against a
/// budget of 64 per chord (a path that needs more is reported as not checked).
fn crossing(ctx: &Context<'_>, nodes: &[Node], closed: bool) -> Result<bool> {
    let n = nodes.len();
    if n < 4 {
        return Ok(true);
    }
    let mean: Vector3<f64> = nodes.iter().map(|p| p.axis).sum();
    let Some(mean) = mean.try_normalize(1e-12) else {
        return Ok(false);
    };
    if nodes.iter().any(|p| p.axis.dot(&mean) < 0.5) {
        return Ok(false);
    }
    let frame = Frame::across(&mean);
    let pts: Vec<Vector2<f64>> = nodes.iter().map(|p| frame.project(&p.pos)).collect();
    let m = n - 1;
    let mut lens: Vec<f64> = (0..m).map(|k| (pts[k + 1] - pts[k]).norm()).collect();
    lens.sort_by(f64::total_cmp);
    let (lo, hi) = pts.iter().fold(
        (
            Vector2::repeat(f64::INFINITY),
            Vector2::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    );
    let extent = (hi - lo).max().max(1e-9);
    // Cells about a median chord long, at most 4 m of them.
    let cell = lens[m / 2]
        .max(extent / (4.0 * m as f64).sqrt())
        .max(extent * 1e-9);
    let nx = ((hi.x - lo.x) / cell).floor() as usize + 1;
    let ny = ((hi.y - lo.y) / cell).floor() as usize + 1;
    let mut grid: std::collections::HashMap<(usize, usize), Vec<usize>> =
        std::collections::HashMap::new();
    let cell_of = |p: &Vector2<f64>| {
        (
            (((p.x - lo.x) / cell).floor() as usize).min(nx - 1),
            (((p.y - lo.y) / cell).floor() as usize).min(ny - 1),
        )
    };
    let budget = 64 * m + 10_000;
    let mut work = 0usize;
    for k in 0..m {
        let (c0, c1) = (cell_of(&pts[k]), cell_of(&pts[k + 1]));
        let cells = (c1.0.abs_diff(c0.0) + 1) * (c1.1.abs_diff(c0.1) + 1);
        work += cells;
        if work > budget {
            return Ok(false);
        }
        for x in c0.0.min(c1.0)..=c0.0.max(c1.0) {
            for y in c0.1.min(c1.1)..=c0.1.max(c1.1) {
                grid.entry((x, y)).or_default().push(k);
            }
        }
    }
    let adjacent = |a: usize, b: usize| {
        a.abs_diff(b) <= 1 || (closed && (a == 0 && b == m - 1 || b == 0 && a == m - 1))
    };
    for list in grid.values() {
        for (ia, &a) in list.iter().enumerate() {
            for &b in &list[ia + 1..] {
                work += 1;
                if work > budget {
                    return Ok(false);
                }
                if adjacent(a, b) {
                    continue;
                }
                if let Some((l, _)) = crossing_of(pts[a], pts[a + 1], pts[b], pts[b + 1]) {
                    let at = nodes[a].pos + (nodes[a + 1].pos - nodes[a].pos) * l;
                    let wide = (nodes[a].c - nodes[b].c).norm();
                    return Err(ctx.refuse(format!(
                        "the offset path crosses itself at ({:.3}, {:.3}, {:.3}): the contour there is narrower than the kerf (its sides {wide:.4} mm apart, the kerf {} mm)",
                        at.x, at.y, at.z, ctx.kerf
                    )));
                }
            }
        }
    }
    Ok(true)
}
