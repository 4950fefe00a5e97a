//! Contours on a thin wall through the sheet: the beam runs along the wall.
//!
//! A CAD file may name, as the face a contour lies on, not the sheet's flat face but the wall
//! the cut leaves: a hole's cylinder, a slot's rounded end, the sheet's edge face, as wide as
//! the sheet is thick. Its normal lies in the sheet's plane, so taken as the tool axis it
//! points the beam along the sheet. The laser that makes such a wall runs through the sheet
//! along the wall, across the contour: the wall's own direction `w = n x t` (unit normal `n`,
//! unit tangent `t` of the contour). And since the wall is the face the cut leaves on the
//! part, its outward normal points away from the part's material: the scrap lies on the side
//! `n` points to (the hole's inside, the outline's outside).

use nalgebra::{Point3, Vector3};

use crate::{Pose, Side};

/// A contour whose surface is a wall at most `max_wall_mm` wide across it ([`wall_axis`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Wall {
    /// The cutting points with the tool axis along the wall (unit), pointing away from the
    /// wall, toward the face of the sheet the contour lies on.
    pub poses: Vec<Pose>,
    /// The scrap side with these tool axes (`left` is `axis x tangent`): the side the wall's
    /// normal points to.
    pub scrap: Side,
    /// How wide the surface is across the contour, at most: the largest extent of its hull
    /// (control net, or mesh vertices) along the wall's direction at any cutting point, mm.
    pub width_mm: f64,
}

/// The least `|n x t|` at a cutting point for the wall's direction to be defined there (the
/// normal within about 6 degrees of the tangent has none).
const MIN_CROSS: f64 = 0.1;

/// How far (radians) the surface's normal may turn across the wall: a wall through the sheet
/// is straight across (a cylinder's or a plane's rulings); a fillet or a rounded edge is not.
const MAX_TURN_RAD: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// At how many cutting points (spread along the contour) the straightness across is looked at.
const STRAIGHT_POINTS: usize = 16;

/// Whether the contour `poses` (cutting points with the surface's unit outward normals, in
/// order) lies on a thin wall through the sheet: the surface, whose hull (a NURBS surface's
/// control points, a mesh's vertices: the surface lies in their convex hull) is `hull`, is at
/// most `max_wall_mm` wide along the wall direction `w = n x t` at every cutting point (the
/// hull's extent along `w`, an upper bound of the surface's). Then the tool axis becomes `+-w`,
/// the sign putting the head on the side where less of the wall lies (toward the face of the
/// sheet that holds the contour), and the scrap is the side the normal points to: with the
/// axis `a = s w`, `a x t = -s n`, so `Right` for `s = +1` and `Left` for `s = -1`.
///
/// The wall must also be straight across: `normal_near(q)` (the surface's unit normal at its
/// point nearest `q`, either orientation) at the points `p + k (width / 4) w`, `k = +-1 .. +-4`, from up to 16
/// cutting points `p` spread along the contour, stays within 5 degrees of the normal at `p`
/// (a cylinder or a plane through the sheet; a fillet or a rounded edge turns across).
///
/// `None` where it is not such a wall: wider than `max_wall_mm`, not straight across, fewer than
/// two points, a point whose normal is (nearly) along the tangent, directions `w` that disagree
/// along the contour (their sum shorter than half their count), or non-finite values.
///
/// What the width cannot tell: a bend narrower than `max_wall_mm` (its rulings run across the
/// contour too) would be taken for a wall.
pub fn wall_axis(
    hull: &[Point3<f64>],
    poses: &[Pose],
    max_wall_mm: f64,
    normal_near: &dyn Fn(&Point3<f64>) -> Option<Vector3<f64>>,
) -> Option<Wall> {
    let n = poses.len();
    if n < 2 || hull.is_empty() || !max_wall_mm.is_finite() || max_wall_mm <= 0.0 {
        return None;
    }
    let pts: Vec<Point3<f64>> = poses.iter().map(|p| p.position).collect();
    let closed = (pts[0] - pts[n - 1]).norm() <= 1e-6;
    let mut dirs = Vec::with_capacity(n);
    for i in 0..n {
        // Central difference; at the ends of an open contour one-sided, of a closed one across
        // the seam.
        let (a, b) = match (i, closed) {
            (0, true) => (pts[n - 2], pts[1]),
            (0, false) => (pts[0], pts[1]),
            (k, true) if k == n - 1 => (pts[n - 2], pts[1]),
            (k, false) if k == n - 1 => (pts[n - 2], pts[n - 1]),
            (k, _) => (pts[k - 1], pts[k + 1]),
        };
        let t = (b - a).try_normalize(1e-12)?;
        let nn = poses[i].axis.try_normalize(1e-12)?;
        let w = nn.cross(&t);
        if w.norm().is_nan() || w.norm() < MIN_CROSS {
            return None;
        }
        dirs.push((w.normalize(), nn, t));
    }
    let sum: Vector3<f64> = dirs.iter().map(|d| d.0).sum();
    if sum.norm().is_nan() || sum.norm() < 0.5 * n as f64 {
        return None;
    }
    // The hull's extent along each point's wall direction, and how much of it lies on either
    // side of the contour.
    let mut width: f64 = 0.0;
    let (mut above, mut below) = (0.0, 0.0);
    for (p, (w, _, _)) in pts.iter().zip(&dirs) {
        let (lo, hi) = hull
            .iter()
            .map(|q| q.coords.dot(w))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        let at = p.coords.dot(w);
        width = width.max(hi - lo);
        above += (hi - at).max(0.0);
        below += (at - lo).max(0.0);
    }
    if width.is_nan() || width > max_wall_mm {
        return None;
    }
    // Straight across: the normal does not turn along w.
    let picked = STRAIGHT_POINTS.min(n);
    for j in 0..picked {
        let i = if picked > 1 {
            j * (n - 1) / (picked - 1)
        } else {
            0
        };
        let (w, nn, _) = &dirs[i];
        for k in [-4, -3, -2, -1, 1, 2, 3, 4] {
            let q = pts[i] + w * (width * f64::from(k) / 4.0);
            // The normal's line (a surface's orientation does not matter here).
            let m = normal_near(&q)?;
            let turn = m.dot(nn).abs().min(1.0).acos();
            if turn.is_nan() || turn > MAX_TURN_RAD {
                return None;
            }
        }
    }
    let s = if above <= below { 1.0 } else { -1.0 };
    let poses = pts
        .iter()
        .zip(&dirs)
        .map(|(&position, (w, _, _))| Pose {
            position,
            axis: s * w,
        })
        .collect();
    Some(Wall {
        poses,
        scrap: if s > 0.0 { Side::Right } else { Side::Left },
        width_mm: width,
    })
}
