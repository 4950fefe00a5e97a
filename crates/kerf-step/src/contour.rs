//! Joining the segments of a contour into one NURBS curve: degrees raised to the highest
//! (exactly, piece by piece in Bezier form), each segment reparametrized over its arc length,
//! a C0 knot (multiplicity = degree) at every join, gaps below the threshold closed by moving
//! the two end poles to their midpoint, and the contour opened at larger gaps.

use kerf_nurbs::NurbsCurve;
use nalgebra::Vector4;

/// Gaps up to this (mm) are rounding in the file, not gaps: closed like the others, but not
/// counted as closed gaps in the report (the largest move still includes them).
pub(crate) const ROUNDING_GAP: f64 = 1e-9;

/// One joined contour: the curve and what joining did.
#[derive(Debug, Clone)]
pub(crate) struct Joined {
    /// The curve (clamped, parameter roughly arc length in mm).
    pub(crate) curve: NurbsCurve,
    /// The largest distance a pole was moved to close a gap, mm (0 if none was).
    pub(crate) largest_move: f64,
    /// The gaps closed, as (segment index before the gap, gap in mm).
    pub(crate) closed: Vec<(usize, f64)>,
}

/// The outcome of joining a list of segments.
#[derive(Debug, Clone, Default)]
pub(crate) struct JoinResult {
    /// The contours, in order; more than one where a gap above the threshold opened it.
    pub(crate) contours: Vec<Joined>,
    /// The gaps that opened the contour, as (segment before, segment after, gap in mm).
    pub(crate) opened: Vec<(usize, usize, f64)>,
    /// Segments of zero length, dropped.
    pub(crate) dropped: Vec<usize>,
}

/// Joins `segments` (in traversal order) as the module describes; `close_below` is the gap
/// threshold in mm. With `closed` the contour is meant to return to its start and a gap there
/// below the threshold is closed too.
pub(crate) fn join(segments: &[NurbsCurve], close_below: f64, closed: bool) -> JoinResult {
    let mut out = JoinResult::default();
    let kept: Vec<usize> = (0..segments.len())
        .filter(|&k| {
            let ok = segments[k].arc_length() > 0.0;
            if !ok {
                out.dropped.push(k);
            }
            ok
        })
        .collect();
    if kept.is_empty() {
        return out;
    }
    // Split into runs at large gaps.
    let mut runs: Vec<Vec<usize>> = vec![vec![kept[0]]];
    for w in kept.windows(2) {
        let gap = gap_between(&segments[w[0]], &segments[w[1]]);
        if gap > close_below {
            out.opened.push((w[0], w[1], gap));
            runs.push(vec![w[1]]);
        } else if let Some(r) = runs.last_mut() {
            r.push(w[1]);
        }
    }
    let whole = runs.len() == 1;
    for run in runs {
        let pieces: Vec<&NurbsCurve> = run.iter().map(|&k| &segments[k]).collect();
        let close_loop = closed && whole && {
            let g = gap_between(pieces[pieces.len() - 1], pieces[0]);
            g > 0.0 && g <= close_below
        };
        let (curve, largest_move, gaps) = assemble(&pieces, close_loop);
        out.contours.push(Joined {
            curve,
            largest_move,
            closed: gaps
                .into_iter()
                .map(|(i, g)| (run[i.min(run.len() - 1)], g))
                .collect(),
        });
    }
    out
}

fn gap_between(a: &NurbsCurve, b: &NurbsCurve) -> f64 {
    let end = a.point(a.domain().1);
    let start = b.point(b.domain().0);
    (end - start).norm()
}

/// Segments in Bezier-compatible clamped form of one degree: (knots, homogeneous points).
fn elevated(c: &NurbsCurve, q: usize) -> (Vec<f64>, Vec<Vector4<f64>>) {
    let c = crate::curves::clamp(c).unwrap_or_else(|_| c.clone());
    let p = c.degree();
    if p == q {
        return (c.knots().to_vec(), c.homogeneous_points().to_vec());
    }
    let (a, b) = c.domain();
    let pieces = c.bezier_pieces(a, b).unwrap_or_default();
    let mut knots = vec![a; q + 1];
    let mut cpw: Vec<Vector4<f64>> = Vec::new();
    for (i, piece) in pieces.iter().enumerate() {
        let mut h: Vec<Vector4<f64>> = piece.homogeneous().to_vec();
        while h.len() - 1 < q {
            h = elevate_once(&h);
        }
        if i == 0 {
            cpw.extend_from_slice(&h);
        } else {
            cpw.extend_from_slice(&h[1..]);
        }
        if i + 1 < pieces.len() {
            knots.extend(std::iter::repeat_n(piece.t1, q));
        }
    }
    knots.extend(std::iter::repeat_n(b, q + 1));
    (knots, cpw)
}

/// Degree elevation of a Bezier curve by one: `Q_i = i/(p+1) P_{i-1} + (1 - i/(p+1)) P_i`.
fn elevate_once(h: &[Vector4<f64>]) -> Vec<Vector4<f64>> {
    let p = h.len() - 1;
    (0..=p + 1)
        .map(|i| {
            let a = i as f64 / (p + 1) as f64;
            let left = if i > 0 {
                h[i - 1] * a
            } else {
                Vector4::zeros()
            };
            let right = if i <= p {
                h[i] * (1.0 - a)
            } else {
                Vector4::zeros()
            };
            left + right
        })
        .collect()
}

/// Joins pieces whose consecutive gaps are all within the threshold. Returns the curve, the
/// largest pole move and the closed gaps (index of the piece before the gap, gap).
fn assemble(pieces: &[&NurbsCurve], close_loop: bool) -> (NurbsCurve, f64, Vec<(usize, f64)>) {
    let q = pieces.iter().map(|c| c.degree()).max().unwrap_or(1);
    let mut knots: Vec<f64> = Vec::new();
    let mut cpw: Vec<Vector4<f64>> = Vec::new();
    let mut s = 0.0;
    let mut largest_move: f64 = 0.0;
    let mut gaps = Vec::new();
    for (k, c) in pieces.iter().enumerate() {
        let (kn, mut h) = elevated(c, q);
        let (a, b) = (kn[q], kn[kn.len() - q - 1]);
        let len = c.arc_length().max(f64::MIN_POSITIVE);
        let map = |t: f64| {
            if t == b {
                s + len
            } else {
                s + (t - a) / (b - a) * len
            }
        };
        if k == 0 {
            knots.extend(std::iter::repeat_n(s, q + 1));
            knots.extend(kn[q + 1..kn.len() - q - 1].iter().map(|&t| map(t)));
            cpw.extend_from_slice(&h);
        } else {
            // Scale the segment's homogeneous points so that its first weight equals the
            // previous last weight (the curve is unchanged), then share that pole.
            let prev = cpw[cpw.len() - 1];
            let f = prev.w / h[0].w;
            for x in &mut h {
                *x *= f;
            }
            let pe = prev.xyz() / prev.w;
            let ps = h[0].xyz() / h[0].w;
            let gap = (pe - ps).norm();
            if gap > ROUNDING_GAP {
                gaps.push((k - 1, gap));
            }
            largest_move = largest_move.max(gap / 2.0);
            let mid = (pe + ps) / 2.0;
            let last = cpw.len() - 1;
            cpw[last] = Vector4::new(mid.x * prev.w, mid.y * prev.w, mid.z * prev.w, prev.w);
            knots.extend(std::iter::repeat_n(s, q));
            knots.extend(kn[q + 1..kn.len() - q - 1].iter().map(|&t| map(t)));
            cpw.extend_from_slice(&h[1..]);
        }
        s += len;
    }
    knots.extend(std::iter::repeat_n(s, q + 1));
    if close_loop {
        let n = cpw.len() - 1;
        let (a, b) = (cpw[0], cpw[n]);
        let pa = a.xyz() / a.w;
        let pb = b.xyz() / b.w;
        let gap = (pa - pb).norm();
        let mid = (pa + pb) / 2.0;
        cpw[0] = Vector4::new(mid.x * a.w, mid.y * a.w, mid.z * a.w, a.w);
        cpw[n] = Vector4::new(mid.x * b.w, mid.y * b.w, mid.z * b.w, b.w);
        if gap > ROUNDING_GAP {
            gaps.push((pieces.len() - 1, gap));
        }
        largest_move = largest_move.max(gap / 2.0);
    }
    (
        NurbsCurve::from_homogeneous_unchecked(q, knots, cpw),
        largest_move,
        gaps,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn line(a: [f64; 3], b: [f64; 3]) -> NurbsCurve {
        NurbsCurve::new(1, vec![0.0, 0.0, 1.0, 1.0], vec![a.into(), b.into()], None)
    }

    #[test]
    fn joins_lines_and_an_arc_exactly_with_c0_knots() {
        let arc = crate::curves::conic_arc(
            &crate::model::Frame {
                origin: Point3::new(10.0, 5.0, 0.0),
                x: nalgebra::Vector3::x(),
                y: nalgebra::Vector3::y(),
                z: nalgebra::Vector3::z(),
            },
            5.0,
            5.0,
            -std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
        );
        let segs = vec![
            line([0.0, 0.0, 0.0], [10.0, 0.0, 0.0]),
            arc.clone(),
            line([10.0, 10.0, 0.0], [0.0, 10.0, 0.0]),
        ];
        let r = join(&segs, 0.1, false);
        assert_eq!(r.contours.len(), 1, "one contour");
        let c = &r.contours[0].curve;
        assert_eq!(c.degree(), 2, "raised to the arc's degree");
        let total = 10.0 + 5.0 * std::f64::consts::PI + 10.0;
        assert!(
            (c.domain().1 - total).abs() < 1e-9,
            "parameter = arc length at the joins"
        );
        assert!(
            (c.arc_length() - total).abs() < 1e-9,
            "length {}",
            c.arc_length()
        );
        // Every point of the arc part is on the circle.
        for k in 0..=100 {
            let t = 10.0 + 5.0 * std::f64::consts::PI * k as f64 / 100.0;
            let d = (c.point(t) - Point3::new(10.0, 5.0, 0.0)).norm();
            assert!((d - 5.0).abs() < 1e-12, "on the circle: {d}");
        }
        let breaks = c.c0_breaks();
        assert!(
            breaks.iter().any(|&b| (b - 10.0).abs() < 1e-9),
            "C0 at the first join {breaks:?}"
        );
        assert_eq!(r.contours[0].largest_move, 0.0, "no gap");
    }

    #[test]
    fn small_gaps_close_large_gaps_open() {
        let segs = vec![
            line([0.0, 0.0, 0.0], [10.0, 0.0, 0.0]),
            line([10.0, 0.04, 0.0], [10.0, 10.0, 0.0]),
            line([10.5, 10.0, 0.0], [0.0, 10.0, 0.0]),
        ];
        let r = join(&segs, 0.1, false);
        assert_eq!(r.contours.len(), 2, "opened at the 0.5 mm gap");
        assert_eq!(r.opened.len(), 1, "one opening");
        assert!((r.opened[0].2 - 0.5).abs() < 1e-12, "gap reported");
        let first = &r.contours[0];
        assert!(
            (first.largest_move - 0.02).abs() < 1e-12,
            "move = half the gap"
        );
        let c = &first.curve;
        let joint = c.point(c.domain().0 + 10.0);
        assert!(
            (joint - Point3::new(10.0, 0.02, 0.0)).norm() < 1e-12,
            "shared pole at the midpoint: {joint:?}"
        );
    }

    #[test]
    fn elevation_keeps_rational_shape() {
        let arc = crate::curves::conic_arc(
            &crate::model::Frame {
                origin: Point3::origin(),
                x: nalgebra::Vector3::x(),
                y: nalgebra::Vector3::y(),
                z: nalgebra::Vector3::z(),
            },
            3.0,
            3.0,
            0.0,
            2.5,
        );
        let (k, h) = elevated(&arc, 4);
        let e = NurbsCurve::from_homogeneous_unchecked(4, k, h);
        let (a, b) = e.domain();
        for i in 0..=100 {
            let r = e.point(a + (b - a) * i as f64 / 100.0).coords.norm();
            assert!((r - 3.0).abs() < 1e-12, "elevated arc on the circle: {r}");
        }
    }
}
