//! The certified chord-error bound.
//!
//! For a segment `[t0, t1]` with chord `A = C(t0)`, `B = C(t1)`, the curve between the two is
//! split into rational Bezier pieces (one per knot span). With positive weights, each piece is a
//! convex combination of its projected control points, so it lies in their convex hull; the
//! distance to the segment `AB` is a convex function, so its maximum over the hull is attained
//! at a control point. Hence `max_j dist(Q_j, AB)` bounds the chord error of that piece from
//! above. Subdividing a piece (de Casteljau) makes the bound converge to the true maximum; the
//! curve points found on the way (the pieces' end points) give a lower bound. The search stops
//! as soon as the bounds decide the question asked. See `docs/discretization.md`.

use kerf_nurbs::{NurbsCurve, RationalBezier};
use nalgebra::{Point3, Vector3};

/// The verdict on one segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bound {
    /// A certified upper bound of the chord error (includes the floating-point margin), or
    /// `f64::INFINITY` when the search stopped before it could certify anything below `limit`.
    pub upper: f64,
    /// The largest distance from a curve point found during the search to the chord: a lower
    /// bound of the chord error (up to rounding), and an estimate of it.
    pub lower: f64,
}

impl Bound {
    /// True if the segment is certified to meet `tolerance`.
    #[inline]
    pub fn certified(&self, tolerance: f64) -> bool {
        self.upper <= tolerance
    }
}

/// Distance from `q` to the segment `[a, b]` (to the point `a` when `a == b`).
#[inline]
pub fn dist_to_segment(q: &Point3<f64>, a: &Point3<f64>, ab: &Vector3<f64>, ab2: f64) -> f64 {
    let aq = q - a;
    if ab2 == 0.0 {
        return aq.norm();
    }
    let s = (aq.dot(ab) / ab2).clamp(0.0, 1.0);
    (aq - ab * s).norm()
}

/// Reusable work space of [`chord_error_with`], so that a walk along a curve allocates once.
#[derive(Debug, Default, Clone)]
pub struct Scratch {
    pieces: Vec<Piece>,
}

#[derive(Debug, Clone, Copy)]
struct Piece {
    bez: RationalBezier,
    upper: f64,
}

struct Chord {
    a: Point3<f64>,
    ab: Vector3<f64>,
    ab2: f64,
}

impl Chord {
    #[inline]
    fn dist(&self, q: &Point3<f64>) -> f64 {
        dist_to_segment(q, &self.a, &self.ab, self.ab2)
    }

    /// Upper bound over a piece's hull, and the distances of its two end points (curve points).
    #[inline]
    fn piece(&self, bez: &RationalBezier) -> (f64, f64) {
        let h = bez.homogeneous();
        let mut upper = 0.0f64;
        for c in h {
            let q = Point3::new(c.x / c.w, c.y / c.w, c.z / c.w);
            upper = upper.max(self.dist(&q));
        }
        let last = h[h.len() - 1];
        let end = self.dist(&Point3::new(
            last.x / last.w,
            last.y / last.w,
            last.z / last.w,
        ));
        (upper, end)
    }
}

/// Certifies the chord error of the curve on `[t0, t1]` against the chord `C(t0) C(t1)`.
///
/// `a` and `b` must be the points the caller will output for `t0` and `t1` (normally
/// `curve.point(t0)` and `curve.point(t1)`). The search refines until one of:
/// - the upper bound is `<= limit` and the lower bound is `>= want_lower` (or cannot rise any
///   more): returns the bounds;
/// - the lower bound exceeds `limit`: the segment certainly fails; `upper` is then the
///   current (larger) bound;
/// - the refinement budget is spent: `upper` is the bound reached (possibly `> limit`).
///
/// The floating-point margin `64 (p + 1) eps * scale` (scale: the largest coordinate
/// magnitude involved) is added to the upper bound, so the bound covers the rounding of the
/// Bezier extraction and of the distance computation.
pub fn chord_error(
    curve: &NurbsCurve,
    t0: f64,
    t1: f64,
    a: &Point3<f64>,
    b: &Point3<f64>,
    limit: f64,
    want_lower: f64,
) -> Bound {
    chord_error_with(
        &mut Scratch::default(),
        curve,
        t0,
        t1,
        a,
        b,
        limit,
        want_lower,
    )
}

/// [`chord_error`] with caller-provided work space.
#[allow(clippy::too_many_arguments)]
pub fn chord_error_with(
    scratch: &mut Scratch,
    curve: &NurbsCurve,
    t0: f64,
    t1: f64,
    a: &Point3<f64>,
    b: &Point3<f64>,
    limit: f64,
    want_lower: f64,
) -> Bound {
    let chord = Chord {
        a: *a,
        ab: b - a,
        ab2: (b - a).norm_squared(),
    };
    let mut scale = a.coords.amax().max(b.coords.amax());
    let pieces = &mut scratch.pieces;
    pieces.clear();
    let mut lower = 0.0f64;
    curve.for_each_bezier_piece(t0, t1, |bez| {
        let (upper, end) = chord.piece(bez);
        for c in bez.homogeneous() {
            scale = scale.max((c.xyz() / c.w).amax());
        }
        lower = lower.max(end);
        pieces.push(Piece { bez: *bez, upper });
    });
    let margin = 64.0 * (curve.degree() + 1) as f64 * f64::EPSILON * scale.max(1e-300);
    let budget = 48 + 4 * pieces.len();
    let mut steps = 0;
    loop {
        // The piece with the largest bound decides the global bound.
        let mut worst = 0;
        let mut upper = 0.0f64;
        for (i, p) in pieces.iter().enumerate() {
            if p.upper > upper {
                upper = p.upper;
                worst = i;
            }
        }
        // A NaN distance (overflowing homogeneous coordinates) must never look like 0.
        if pieces.iter().any(|p| p.upper.is_nan()) || lower.is_nan() {
            return Bound {
                upper: f64::INFINITY,
                lower: if lower.is_nan() { f64::INFINITY } else { lower },
            };
        }
        let upper_m = upper + margin;
        if lower > limit {
            return Bound {
                upper: upper_m.max(lower),
                lower,
            };
        }
        // Refining further cannot move the estimate by more than the gap.
        let tight = upper - lower <= 0.002 * limit;
        let decided = upper_m <= limit && (lower >= want_lower || upper_m < want_lower || tight);
        if decided || steps >= budget {
            return Bound {
                upper: upper_m,
                lower,
            };
        }
        steps += 1;
        // Split the worst piece in place: its copy at the end becomes the right half.
        pieces.push(pieces[worst]);
        let last = pieces.len() - 1;
        let (head, tail) = pieces.split_at_mut(last);
        let (l, r) = (&mut head[worst], &mut tail[0]);
        l.bez.subdivide_in_place(&mut r.bez, 0.5);
        let (ul, el) = chord.piece(&l.bez);
        let (ur, _) = chord.piece(&r.bez);
        lower = lower.max(el);
        l.upper = ul;
        r.upper = ur;
    }
}
